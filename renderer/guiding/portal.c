/* Portals: see portal.h and docs/guiding.md, "Portals". */
#include "renderer/guiding/portal.h"

#include <math.h>
#include <string.h>

#include "core/rng.h"
#include "renderer/accel.h"

/* Slack of the inside test in the density: a direction drawn at the
 * rectangle's edge must not get density 0 from rounding; the rim this adds
 * (1e-4 of each half-axis) is never drawn. */
#define PORTAL_RIM 1e-4f

float iris_portal_pdf(const iris_portal *p, iris_vec3 x, iris_vec3 wi) {
  const iris_vec3 nrm = iris_cross(p->u, p->v);
  const float nl = iris_length(nrm), uu = iris_dot(p->u, p->u), vv = iris_dot(p->v, p->v);
  if (!(nl > 0.0f)) return 0.0f;
  const iris_vec3 nn = iris_scale(nrm, 1.0f / nl);
  const float dn = iris_dot(wi, nn);
  if (!(fabsf(dn) > 1e-7f)) return 0.0f;
  const float t = iris_dot(iris_sub(p->o, x), nn) / dn;
  if (!(t > 0.0f)) return 0.0f;
  const iris_vec3 d = iris_sub(iris_madd(x, wi, t), p->o);
  const float a = iris_dot(d, p->u) / uu, b = iris_dot(d, p->v) / vv;
  if (!(fabsf(a) <= 1.0f + PORTAL_RIM && fabsf(b) <= 1.0f + PORTAL_RIM)) return 0.0f;
  const float area = 4.0f * sqrtf(uu) * sqrtf(vv);
  return t * t / (area * fabsf(dn));
}

iris_vec3 iris_portal_sample(const iris_portal *p, iris_vec3 x, float u1, float u2) {
  iris_vec3 q = iris_add(p->o, iris_add(iris_scale(p->u, 2.0f * u1 - 1.0f), iris_scale(p->v, 2.0f * u2 - 1.0f)));
  return iris_normalize(iris_sub(q, x));
}

bool iris_portal_faces(const iris_portal *p, iris_vec3 side, iris_vec3 x, iris_vec3 n) {
  const iris_vec3 nrm = iris_cross(p->u, p->v);
  const float nl = iris_length(nrm);
  if (!(nl > 0.0f)) return false;
  const float sx = iris_dot(iris_sub(x, p->o), nrm) / nl, ss = iris_dot(iris_sub(side, p->o), nrm) / nl;
  /* a millimetre off the plane at least: from the plane itself every direction
   * to the rectangle grazes it */
  if (!(sx * ss > 0.0f) || !(fabsf(sx) > 1e-3f)) return false;
  return iris_dot(iris_sub(p->o, x), n) > 0.0f;
}

/* Probe i of an 8 x 8 stratified grid, jittered by the hash stream h
 * (advanced): its cell coordinates plus jitter, each in [0, 8). */
static void stratum(uint64_t *h, int i, float *ca, float *cb) {
  *h = iris_mix64(*h + 0x9e3779b97f4a7c15ULL);
  *ca = (float)(i % 8) + iris_u64_to_unit(*h);
  *cb = (float)(i / 8) + iris_u64_to_unit(iris_mix64(*h ^ 0x5bd1e995ULL));
}

typedef struct probe {
  iris_vec3 d, h, ng; /* direction, hit point and its normal turned towards the probe */
  float t;            /* hit distance; INFINITY: escaped */
} probe;

/* The first hit of a probe from the cache at c (normal n) along d. */
static bool probe_hit(const struct iris_accel *accel, iris_vec3 c, iris_vec3 n, iris_vec3 d, iris_hit *hit) {
  iris_ray ray;
  ray.o = iris_offset_origin(c, n, d);
  ray.d = d;
  ray.tmin = 0.0f;
  ray.tmax = INFINITY;
  return iris_accel_intersect(accel, &ray, hit);
}

/* Probe k's hit lies on the plane of probe j's (facing alike, within 1% of j's distance). */
static bool coplanar(const probe *pr, int j, int k) {
  return isfinite(pr[k].t) && iris_dot(pr[k].ng, pr[j].ng) > 0.95f &&
         fabsf(iris_dot(iris_sub(pr[k].h, pr[j].h), pr[j].ng)) < 0.01f * pr[j].t + 1e-3f;
}

/* a unit vector perpendicular to n, from the world axis least aligned with it */
static iris_vec3 perpendicular(iris_vec3 n) {
  float ax = fabsf(n.x), ay = fabsf(n.y), az = fabsf(n.z);
  iris_vec3 w = ax <= ay && ax <= az ? iris_v3(1, 0, 0) : ay <= az ? iris_v3(0, 1, 0) : iris_v3(0, 0, 1);
  return iris_normalize(iris_cross(n, w));
}

bool iris_portal_find(const struct iris_accel *accel, iris_vec3 c, iris_vec3 n, iris_vec3 axis, float cos_max,
                      uint64_t seed, iris_portal_brightness bright, void *bright_ctx, iris_portal *out) {
  memset(out, 0, sizeof *out);
  if (!(cos_max > -1.0f && cos_max < 1.0f)) return false;
  const float omc_max = 1.0f - cos_max;
  const iris_frame f = iris_frame_from_normal(axis);
  probe pr[IRIS_PORTAL_PROBES];
  int count = 0;
  uint64_t h = seed;
  for (int i = 0; i < IRIS_PORTAL_PROBES; ++i) {
    float ca, cb;
    stratum(&h, i, &ca, &cb);
    const float u1 = ca / 8.0f, u2 = cb / 8.0f;
    const float omc = u1 * omc_max, cosv = 1.0f - omc, sinv = sqrtf(fmaxf(0.0f, omc * (2.0f - omc)));
    const float phi = 2.0f * (float)IRIS_PI * u2;
    const iris_vec3 d = iris_normalize(iris_frame_to_world(&f, iris_v3(sinv * cosf(phi), sinv * sinf(phi), cosv)));
    if (!(iris_dot(d, n) > 0.05f)) continue;
    iris_hit hit;
    probe *q = &pr[count++];
    q->d = d;
    q->t = INFINITY;
    if (probe_hit(accel, c, n, d, &hit)) {
      iris_interaction si;
      iris_accel_interaction(accel, d, &hit, &si);
      q->t = hit.t;
      q->h = si.p;
      q->ng = iris_dot(si.ng, d) > 0.0f ? iris_neg(si.ng) : si.ng;
    }
  }
  /* The wall: of the planes at least 4 hits lie on, the one the most probes
   * pass (cross in front of it, land beyond it); the first found of equals. */
  int best_pass = 0, best_j = -1;
  iris_vec3 po = iris_v3(0, 0, 0), pn = iris_v3(0, 0, 0);
  bool taken[IRIS_PORTAL_PROBES] = {false};
  for (int j = 0; j < count; ++j) {
    if (!isfinite(pr[j].t) || taken[j]) continue;
    int on = 0;
    iris_vec3 o = iris_v3(0, 0, 0), nsum = iris_v3(0, 0, 0);
    for (int k = 0; k < count; ++k)
      if (coplanar(pr, j, k))
        taken[k] = true, on++, o = iris_add(o, pr[k].h), nsum = iris_add(nsum, pr[k].ng);
    if (on < 4) continue;
    o = iris_scale(o, 1.0f / (float)on);
    nsum = iris_normalize(nsum);
    int passing_here = 0;
    for (int k = 0; k < count; ++k) {
      const float dn = iris_dot(pr[k].d, nsum);
      const float tc = dn < -1e-6f ? iris_dot(iris_sub(o, c), nsum) / dn : -1.0f;
      passing_here += tc > 0.0f && (!isfinite(pr[k].t) || pr[k].t > 1.02f * tc + 1e-3f);
    }
    if (passing_here > best_pass) best_pass = passing_here, po = o, pn = nsum, best_j = j;
  }
  if (best_pass < 4) return false; /* (a plane is a candidate only with >= 4 hits) */
  bool on_wall[IRIS_PORTAL_PROBES]; /* the hits on the chosen wall */
  for (int k = 0; k < count; ++k)
    on_wall[k] = coplanar(pr, best_j, k);
  /* Where the probes cross that plane, and which pass it to land beyond. */
  const iris_vec3 e1 = perpendicular(pn), e2 = iris_cross(pn, e1);
  float a[IRIS_PORTAL_PROBES], b[IRIS_PORTAL_PROBES];
  bool pass[IRIS_PORTAL_PROBES], crosses[IRIS_PORTAL_PROBES];
  float a0 = INFINITY, a1 = -INFINITY, b0 = INFINITY, b1 = -INFINITY, dist = 0.0f;
  int passing = 0;
  for (int k = 0; k < count; ++k) {
    const float dn = iris_dot(pr[k].d, pn);
    const float tc = dn < -1e-6f ? iris_dot(iris_sub(po, c), pn) / dn : -1.0f;
    crosses[k] = tc > 0.0f;
    pass[k] = false;
    if (!crosses[k]) continue;
    const iris_vec3 q = iris_sub(iris_madd(c, pr[k].d, tc), po);
    a[k] = iris_dot(q, e1);
    b[k] = iris_dot(q, e2);
    pass[k] = !isfinite(pr[k].t) || pr[k].t > 1.02f * tc + 1e-3f;
    if (!pass[k]) continue;
    passing++;
    dist += tc;
    a0 = fminf(a0, a[k]), a1 = fmaxf(a1, a[k]), b0 = fminf(b0, b[k]), b1 = fmaxf(b1, b[k]);
  }
  if (passing < 4) return false;
  /* widened by half the probes' spacing where they cross */
  const float margin = 0.5f * sqrtf(2.0f * (float)IRIS_PI * omc_max / (float)IRIS_PORTAL_PROBES) * dist / (float)passing;
  a0 -= margin, a1 += margin, b0 -= margin, b1 += margin;
  int inside = 0, inside_pass = 0;
  for (int k = 0; k < count; ++k)
    if (crosses[k] && a[k] >= a0 && a[k] <= a1 && b[k] >= b0 && b[k] <= b1) inside++, inside_pass += pass[k];
  if (2 * inside_pass < inside) return false;
  /* An opening in the wall: the wall's hits lie on at least two of its four
   * sides (the probes may see only a corner of the wall around a door), and
   * the cone's axis passes through it or near it, within half its size (not a
   * gap beside an object the light only grazes). */
  {
    bool side[4] = {false, false, false, false};
    float w0 = INFINITY, w1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY; /* the wall's hits' extent */
    for (int k = 0; k < count; ++k) {
      if (!crosses[k] || pass[k] || !on_wall[k]) continue;
      w0 = fminf(w0, a[k]), w1 = fmaxf(w1, a[k]), v0 = fminf(v0, b[k]), v1 = fmaxf(v1, b[k]);
      const bool in_a = a[k] >= a0 && a[k] <= a1, in_b = b[k] >= b0 && b[k] <= b1;
      if (in_b && a[k] < a0) side[0] = true;
      if (in_b && a[k] > a1) side[1] = true;
      if (in_a && b[k] < b0) side[2] = true;
      if (in_a && b[k] > b1) side[3] = true;
    }
    if (side[0] + side[1] + side[2] + side[3] < 2) return false;
    /* a hole in a wall is smaller than the wall the probes saw around it */
    if (!((a1 - a0) * (b1 - b0) <= (w1 - w0) * (v1 - v0))) return false;
    const float dn = iris_dot(axis, pn);
    if (!(dn < -1e-6f)) return false;
    const iris_vec3 q = iris_sub(iris_madd(c, axis, iris_dot(iris_sub(po, c), pn) / dn), po);
    const float qa = iris_dot(q, e1), qb = iris_dot(q, e2);
    const float ha = 0.5f * (a1 - a0), hb = 0.5f * (b1 - b0);
    if (!(qa >= a0 - ha && qa <= a1 + ha && qb >= b0 - hb && qb <= b1 + hb)) return false;
  }
  /* Again with as many probes through points stratified over that rectangle:
   * its edges to a cell of an 8 x 8 grid over it, then half a cell wider. */
  {
    const float da = (a1 - a0) / 8.0f, db = (b1 - b0) / 8.0f;
    float c0 = INFINITY, c1 = -INFINITY, d0 = INFINITY, d1 = -INFINITY;
    int through = 0, lit_n = 0, wall_n = 0;
    double lit = 0.0, wall = 0.0;
    for (int i = 0; i < IRIS_PORTAL_PROBES; ++i) {
      float ca, cb;
      stratum(&h, i, &ca, &cb);
      const float qa = a0 + da * ca, qb = b0 + db * cb;
      const iris_vec3 target = iris_add(po, iris_add(iris_scale(e1, qa), iris_scale(e2, qb)));
      const iris_vec3 d = iris_normalize(iris_sub(target, c));
      if (!(iris_dot(d, n) > 0.0f)) continue;
      const float dn = iris_dot(d, pn);
      if (!(dn < -1e-6f)) continue;
      const float tc = iris_dot(iris_sub(po, c), pn) / dn;
      if (!(tc > 0.0f)) continue;
      iris_hit hit;
      const bool hits = probe_hit(accel, c, n, d, &hit);
      if (hits && bright) {
        iris_interaction si;
        iris_accel_interaction(accel, d, &hit, &si);
        const float b = bright(bright_ctx, si.p, iris_dot(si.ng, d) > 0.0f ? iris_neg(si.ng) : si.ng);
        if (hit.t > 1.02f * tc + 1e-3f) lit += b, lit_n++;
        else wall += b, wall_n++;
      }
      if (hits && !(hit.t > 1.02f * tc + 1e-3f)) continue;
      through++;
      c0 = fminf(c0, qa), c1 = fmaxf(c1, qa), d0 = fminf(d0, qb), d1 = fmaxf(d1, qb);
    }
    if (through < 4) return false;
    /* the light came through it: what lies beyond outshines the wall */
    if (bright && (lit_n < 4 || !(lit / lit_n >= IRIS_PORTAL_CONTRAST * (wall_n ? wall / wall_n : 0.0)) ||
                   !(lit > 0.0)))
      return false;
    a0 = fmaxf(a0, c0 - 0.5f * da), a1 = fminf(a1, c1 + 0.5f * da);
    b0 = fmaxf(b0, d0 - 0.5f * db), b1 = fminf(b1, d1 + 0.5f * db);
  }
  iris_portal p;
  p.o = iris_add(po, iris_add(iris_scale(e1, 0.5f * (a0 + a1)), iris_scale(e2, 0.5f * (b0 + b1))));
  p.u = iris_scale(e1, 0.5f * (a1 - a0));
  p.v = iris_scale(e2, 0.5f * (b1 - b0));
  /* narrower than the cone, or the cone's own map does as well */
  const iris_vec3 to = iris_sub(p.o, c);
  const float d2 = iris_dot(to, to);
  const float omega = 4.0f * (0.5f * (a1 - a0)) * (0.5f * (b1 - b0)) * fabsf(iris_dot(to, pn)) / (d2 * sqrtf(d2));
  if (!(d2 > 0.0f) || !(omega <= 0.7f * 2.0f * (float)IRIS_PI * omc_max)) return false;
  *out = p;
  return true;
}

/* ---- joining the caches' rectangles ---------------------------------------- */

/* The unit normal of p's plane turned towards `side`. */
static iris_vec3 facing_normal(const iris_portal *p, iris_vec3 side) {
  iris_vec3 nrm = iris_normalize(iris_cross(p->u, p->v));
  return iris_dot(iris_sub(side, p->o), nrm) < 0.0f ? iris_neg(nrm) : nrm;
}

/* p's extent along the unit axes e1, e2 of a plane through o. */
static void extent(const iris_portal *p, iris_vec3 o, iris_vec3 e1, iris_vec3 e2, float box[4]) {
  const iris_vec3 d = iris_sub(p->o, o);
  const float ca = iris_dot(d, e1), cb = iris_dot(d, e2);
  const float ra = fabsf(iris_dot(p->u, e1)) + fabsf(iris_dot(p->v, e1));
  const float rb = fabsf(iris_dot(p->u, e2)) + fabsf(iris_dot(p->v, e2));
  box[0] = ca - ra, box[1] = ca + ra, box[2] = cb - rb, box[3] = cb + rb;
}

bool iris_portal_join(iris_portal *a, iris_vec3 side_a, const iris_portal *b, iris_vec3 side_b) {
  if (!iris_portal_present(a) || !iris_portal_present(b)) return false;
  const iris_vec3 na = facing_normal(a, side_a), nb = facing_normal(b, side_b);
  if (!(iris_dot(na, nb) > 0.995f)) return false; /* within ~6 degrees, facing the same side */
  const float size = sqrtf(fmaxf(iris_dot(a->u, a->u), iris_dot(a->v, a->v)));
  if (!(fabsf(iris_dot(iris_sub(b->o, a->o), na)) < 1e-3f + 0.02f * size)) return false; /* in a's plane */
  const iris_vec3 e1 = iris_normalize(a->u), e2 = iris_normalize(a->v);
  float ba[4], bb[4];
  extent(a, a->o, e1, e2, ba);
  extent(b, a->o, e1, e2, bb);
  /* they overlap, or come within a tenth of the larger one's size of each other */
  const float gap = 0.1f * fmaxf(fmaxf(ba[1] - ba[0], ba[3] - ba[2]), fmaxf(bb[1] - bb[0], bb[3] - bb[2]));
  if (bb[0] > ba[1] + gap || bb[1] < ba[0] - gap || bb[2] > ba[3] + gap || bb[3] < ba[2] - gap) return false;
  const float a0 = fminf(ba[0], bb[0]), a1 = fmaxf(ba[1], bb[1]), b0 = fminf(ba[2], bb[2]), b1 = fmaxf(ba[3], bb[3]);
  a->o = iris_add(a->o, iris_add(iris_scale(e1, 0.5f * (a0 + a1)), iris_scale(e2, 0.5f * (b0 + b1))));
  a->u = iris_scale(e1, 0.5f * (a1 - a0));
  a->v = iris_scale(e2, 0.5f * (b1 - b0));
  return true;
}

float iris_portal_share(const struct iris_accel *accel, const iris_portal *p, iris_vec3 c, iris_vec3 n, uint64_t seed,
                        iris_portal_density pdf, void *pdf_ctx, float *reach) {
  const float area = 4.0f * iris_length(p->u) * iris_length(p->v);
  const iris_vec3 nrm = iris_normalize(iris_cross(p->u, p->v));
  double share = 0.0;
  int through = 0;
  uint64_t h = seed;
  for (int i = 0; i < IRIS_PORTAL_PROBES; ++i) {
    float ca, cb;
    stratum(&h, i, &ca, &cb);
    const float u1 = ca / 8.0f, u2 = cb / 8.0f;
    const iris_vec3 target = iris_add(p->o, iris_add(iris_scale(p->u, 2.0f * u1 - 1.0f), iris_scale(p->v, 2.0f * u2 - 1.0f)));
    const iris_vec3 to = iris_sub(target, c);
    const float tc = iris_length(to);
    if (!(tc > 0.0f)) continue;
    const iris_vec3 d = iris_scale(to, 1.0f / tc);
    const float cosp = fabsf(iris_dot(d, nrm));
    if (!(iris_dot(d, n) > 0.0f) || !(cosp > 1e-4f)) continue;
    iris_hit hit;
    if (probe_hit(accel, c, n, d, &hit) && !(hit.t > 1.02f * tc + 1e-3f)) continue;
    through++;
    /* the map's density over the portal's: tc^2 / (area cos) per direction */
    share += (double)pdf(pdf_ctx, d) * (double)area * (double)cosp / ((double)tc * (double)tc);
  }
  *reach = (float)through / (float)IRIS_PORTAL_PROBES;
  return (float)(share / IRIS_PORTAL_PROBES);
}

/* Whether one of the viewers reaches the point (s, t) of p (in half-axis
 * units) in a straight line from above its surface. */
static bool tighten_reached(const struct iris_accel *accel, const iris_portal *p, iris_vec3 nrm, float s, float t,
                            const iris_vec3 *viewer, const iris_vec3 *viewer_n, int viewers) {
  const iris_vec3 q = iris_add(p->o, iris_add(iris_scale(p->u, s), iris_scale(p->v, t)));
  for (int k = 0; k < viewers; ++k) {
    const iris_vec3 to = iris_sub(q, viewer[k]);
    const float tc = iris_length(to);
    if (!(tc > 0.0f)) continue;
    const iris_vec3 d = iris_scale(to, 1.0f / tc);
    if (!(iris_dot(d, viewer_n[k]) > 0.0f) || !(fabsf(iris_dot(d, nrm)) > 1e-3f)) continue;
    iris_hit hit;
    if (probe_hit(accel, viewer[k], viewer_n[k], d, &hit) && !(hit.t > 1.02f * tc + 1e-3f)) continue;
    return true;
  }
  return false;
}

bool iris_portal_tighten(const struct iris_accel *accel, iris_portal *p, const iris_vec3 *viewer,
                         const iris_vec3 *viewer_n, int viewers) {
  const iris_vec3 nrm = iris_normalize(iris_cross(p->u, p->v));
  float lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
  for (int i = 0; i < IRIS_PORTAL_TIGHTEN_GRID * IRIS_PORTAL_TIGHTEN_GRID; ++i) {
    const float s = 2.0f * ((float)(i % IRIS_PORTAL_TIGHTEN_GRID) + 0.5f) / IRIS_PORTAL_TIGHTEN_GRID - 1.0f;
    const float t = 2.0f * ((float)(i / IRIS_PORTAL_TIGHTEN_GRID) + 0.5f) / IRIS_PORTAL_TIGHTEN_GRID - 1.0f;
    if (s >= lo[0] && s <= hi[0] && t >= lo[1] && t <= hi[1]) continue; /* cannot widen the box */
    if (!tighten_reached(accel, p, nrm, s, t, viewer, viewer_n, viewers)) continue;
    lo[0] = fminf(lo[0], s), hi[0] = fmaxf(hi[0], s), lo[1] = fminf(lo[1], t), hi[1] = fmaxf(hi[1], t);
  }
  if (!(lo[0] <= hi[0] && lo[1] <= hi[1])) return false;
  /* Each side moved out from the last reached grid point towards the next
   * one (a grid step further, at most half a step past the rectangle) along
   * the box's middle line, by bisection to 1/256 of a step: the opening's
   * edge, where the grid alone left up to a step of it out (the door's 2 cm
   * strips at its sides: directions the portal then missed, drawn only by the
   * caches' coarse texels; docs/guiding.md, "Portals"). The last reached
   * point is kept: never past the edge, into the wall or the floor. */
  const float step = 2.0f / IRIS_PORTAL_TIGHTEN_GRID;
  for (int side = 0; side < 4; ++side) {
    const int axis = side >> 1, other = 1 - axis;
    const float dir = (side & 1) ? 1.0f : -1.0f, mid = 0.5f * (lo[other] + hi[other]);
    float in = (side & 1) ? hi[axis] : lo[axis];
    float out = fminf(fmaxf(in + dir * step, -1.0f - 0.5f * step), 1.0f + 0.5f * step);
    for (int it = 0; it < 8; ++it) {
      const float m = 0.5f * (in + out);
      const bool r = axis == 0 ? tighten_reached(accel, p, nrm, m, mid, viewer, viewer_n, viewers)
                               : tighten_reached(accel, p, nrm, mid, m, viewer, viewer_n, viewers);
      if (r) in = m;
      else out = m;
    }
    if (side & 1) hi[axis] = in;
    else lo[axis] = in;
  }
  /* a single open point still spans one grid cell */
  const float half = 1.0f / IRIS_PORTAL_TIGHTEN_GRID;
  if (hi[0] - lo[0] < 2.0f * half) lo[0] -= half, hi[0] += half;
  if (hi[1] - lo[1] < 2.0f * half) lo[1] -= half, hi[1] += half;
  const iris_vec3 o = iris_add(p->o, iris_add(iris_scale(p->u, 0.5f * (lo[0] + hi[0])), iris_scale(p->v, 0.5f * (lo[1] + hi[1]))));
  p->u = iris_scale(p->u, 0.5f * (hi[0] - lo[0]));
  p->v = iris_scale(p->v, 0.5f * (hi[1] - lo[1]));
  p->o = o;
  return true;
}

int iris_portal_join_all(const struct iris_accel *accel, const iris_portal *parts, const iris_vec3 *finder_p,
                         const iris_vec3 *finder_n, size_t n, iris_portal *whole, iris_vec3 *side, int max,
                         uint8_t *group) {
  int count = 0;
  if (max > 255) max = 255;
  for (size_t i = 0; i < n; ++i) {
    group[i] = 0xff;
    if (!iris_portal_present(&parts[i])) continue;
    int j = 0;
    while (j < count && !iris_portal_join(&whole[j], side[j], &parts[i], finder_p[i])) ++j;
    if (j == count && count < max) whole[count] = parts[i], side[count++] = finder_p[i];
    if (j < count) group[i] = (uint8_t)j;
  }
  /* wholes that grew into each other since are one */
  for (bool merged = true; merged;) {
    merged = false;
    for (int j = 0; j < count && !merged; ++j)
      for (int k = j + 1; k < count && !merged; ++k) {
        if (!iris_portal_join(&whole[j], side[j], &whole[k], side[k])) continue;
        merged = true;
        --count;
        whole[k] = whole[count], side[k] = side[count];
        for (size_t i = 0; i < n; ++i)
          if (group[i] == k) group[i] = (uint8_t)j;
          else if (group[i] == count) group[i] = (uint8_t)k;
      }
  }
  for (int j = 0; j < count; ++j) {
    size_t members = 0, seen = 0;
    for (size_t i = 0; i < n; ++i) members += group[i] == j;
    iris_vec3 at[IRIS_PORTAL_VIEWERS], nrm[IRIS_PORTAL_VIEWERS];
    int viewers = 0;
    for (size_t i = 0; i < n && viewers < IRIS_PORTAL_VIEWERS; ++i)
      if (group[i] == j && seen++ * IRIS_PORTAL_VIEWERS >= (size_t)viewers * members)
        at[viewers] = finder_p[i], nrm[viewers++] = finder_n[i];
    if (!iris_portal_tighten(accel, &whole[j], at, nrm, viewers)) memset(&whole[j], 0, sizeof whole[j]);
  }
  return count;
}
