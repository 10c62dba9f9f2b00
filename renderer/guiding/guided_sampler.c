/* Rendering with the guide (thesis 5.1-5.2): Algorithm 1's pick of the tied
 * caches, their pdf, and the one-sample MIS direction sampler
 * (iris_guiding_sampler) with its per-vertex hooks; docs/guiding.md. The
 * guide is built in guiding.c. */
#include "renderer/guiding/guiding.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "renderer/guiding/vertex.h"

#define TIE_EPS 1e-4f
/* the largest pdf table guided_prepare loads ahead (an 8 x 8 hemisphere map) */
#define IRIS_GUIDE_PREFETCH_BYTES 256u

int iris_guiding_pick(const iris_guiding *g, iris_vec3 p, iris_vec3 n, uint32_t ids[IRIS_GUIDING_PICK_K]) {
  if (g->cache_count == 0) return 0;
  uint32_t near[IRIS_GUIDING_PICK_K];
  float d2[IRIS_GUIDING_PICK_K], cosv[IRIS_GUIDING_PICK_K];
  /* The grid answers for p's cell centre (O(1)); without a grid (a handful of
   * caches) the kd-tree answers for p itself. */
  uint32_t m = g->grid.n[0] ? iris_pick_grid_query(&g->grid, p, near)
                            : iris_kdtree_knn(&g->tree, p, IRIS_GUIDING_PICK_K, g->pick_radius2, near, d2);
  float best = -2.0f;
  for (uint32_t i = 0; i < m; ++i) {
    cosv[i] = iris_dot(g->caches[near[i]].frame.n, n);
    best = iris_fmaxf(best, cosv[i]);
  }
  if (!(best > g->params.cos_min)) return 0;
  int count = 0;
  for (uint32_t i = 0; i < m; ++i)
    if (cosv[i] >= best - TIE_EPS) ids[count++] = near[i];
  return count;
}

float iris_guiding_cache_pdf(const iris_guiding *g, const uint32_t *ids, int m, iris_vec3 wi) {
  float sum = 0.0f;
  for (int i = 0; i < m; ++i) {
    const iris_cache *c = &g->caches[ids[i]];
    const iris_octmap *map = c->sphere ? &g->sphere : &g->hemi;
    sum += g->refine_slot ? iris_cache_pdf_refined(map, g->pdf + c->table, g->refine_slot + c->table,
                                                   iris_guiding_sub(g, c), iris_frame_to_local(&c->frame, wi))
                          : iris_cache_pdf(map, g->pdf + c->table, iris_frame_to_local(&c->frame, wi));
  }
  return m > 0 ? sum / (float)m : 0.0f;
}

static void guided_prepare(void *ctx, iris_shading_point *sp) {
  const iris_guiding *g = ctx;
  iris_guide_vertex_state *v = (iris_guide_vertex_state *)sp->guide.bytes;
  /* cache-sampling probability alpha = min(roughness, alpha_max), 0 at a delta
   * BSDF (roughness 0); the roughness is kept for the learned alpha below */
  const float rough = sp->delta ? 0.0f : iris_bsdf_guiding_roughness(&sp->bsdf); /* INFINITY for diffuse */
  v->alpha = iris_fminf(rough, g->params.alpha_max);
  v->m = v->alpha > 0.0f ? iris_guiding_pick(g, sp->si.p, sp->frame.n, v->ids) : 0;
  if (v->m == 0) v->alpha = 0.0f;
  v->radiance = -1.0f;
  v->sky = 0.0f;
  v->lamp = 0.0f;
  v->light = 1.0f;
  v->pane = 0xff;
  v->glint = 0.0f;
  v->spot = (iris_guide_lamp){{0.0f, 0.0f, 0.0f}, 0.0f};
  v->portal = 0.0f;
  v->portal_of = 0xff;
  v->portal_faces = 0;
  v->p = sp->si.p;
  if (v->m > 0) {
    /* Learned selection probabilities (training, docs/guiding.md): the tied
     * caches' mean replaces alpha_max; a glossy lobe's roughness still caps it. */
    float r = 0.0f, a = 0.0f, sky = 0.0f, lamp = 0.0f, light = 0.0f, pane = 0.0f, glint = 0.0f;
    int learned = 0;
    for (int i = 0; i < v->m; ++i) {
      const iris_cache *c = &g->caches[v->ids[i]];
      r += c->radiance;
      /* the sky through a pane: the plane of the tied cache with the largest share */
      if (c->pane_share > pane) pane = c->pane_share, v->pane = (uint8_t)i;
      sky += c->pane_share;
      light = iris_fmaxf(light, c->light); /* any tied cache that saw light arrive keeps it sampled */
      sky += c->sky_through;
      for (int k = 0; k < IRIS_CACHE_LAMPS; ++k) lamp += c->lamp_share[k];
      glint += c->glint_share;
      if (c->alpha >= 0.0f) a += c->alpha, learned++;
    }
    v->radiance = r / (float)v->m;
    v->light = light;
    /* Sky behind glass: the share of the tied caches' photon energy that came
     * straight through glass from the map, which the map's own density finds
     * (the sun within its texels) and light sampling cannot reach. */
    v->sky = g->env ? sky / (float)v->m : 0.0f;
    /* Lamps behind glass: the same for light that came straight through
     * glass from a lamp, which the lamp's cone finds; one mixture with the
     * sky's (the shares are of the same photons: they sum to at most 1). */
    v->lamp = iris_fminf(lamp / (float)v->m, 1.0f - v->sky);
    /* Glints: where the tied caches lie among glint photons, the spot the
     * vertex's nearest ones left (glints.h), if they agree on one. */
    if (glint > 0.0f && iris_glints_spot(&g->glints, v->p, sp->frame.n, &v->spot))
      v->glint = iris_fmaxf(0.0f, iris_fminf(glint / (float)v->m, 1.0f - v->sky - v->lamp));
    const float a_free = learned == v->m ? a / (float)v->m : g->params.alpha_max;
    if (learned == v->m) v->alpha = iris_fminf(rough, a_free);
    /* Behind glass, the lobe's roughness caps only the caches' part: their
     * texels cannot follow a glossy lobe, but the map through glass and a
     * lamp's cone are exact directions that stand in for light sampling,
     * which cannot cross glass. At a glossy vertex they keep at least the
     * probability a diffuse vertex has without training (alpha_max; the
     * training's alpha, learned for the guide's mixture as a whole, is often
     * far lower there). Glints keep the cap: light sampling still reaches
     * their light. docs/guiding.md, "Glass seen from glossy vertices". */
    const float exact = v->sky + v->lamp;
    const float a_exact = isfinite(rough) ? iris_fmaxf(a_free, g->params.alpha_max) : a_free;
    if (exact > 0.0f && a_exact > v->alpha) {
      const float total = v->alpha * (1.0f - exact) + a_exact * exact;
      v->sky *= a_exact / total;
      v->lamp *= a_exact / total;
      v->glint *= v->alpha / total; /* its probability alpha * glint unchanged */
      v->alpha = total;
    }
    /* Portals: at a diffuse vertex that sees the front of one of its tied
     * caches' openings, the heaviest such one, drawn before the rest. */
    if (v->alpha > 0.0f && (sp->lobes & IRIS_LOBE_DIFFUSE)) { /* weights only where the build found portals */
      float best = 0.0f;
      for (int i = 0; i < v->m; ++i) {
        const iris_cache *c = &g->caches[v->ids[i]];
        if (!(c->portal_weight > 0.0f) || !iris_portal_faces(&c->portal, c->p, v->p, sp->frame.n)) continue;
        v->portal_faces |= (uint8_t)(1u << i);
        if (c->portal_weight > best) best = c->portal_weight, v->portal_of = (uint8_t)i;
      }
      if (v->portal_of != 0xff) v->portal = IRIS_PORTAL_SHARE;
    }
  }
  /* The pdf tables of the tied caches are needed after this vertex's shadow
   * ray (the light sample's mixture pdf): start loading them now so the ray
   * hides the memory latency — where a table is a few cache lines (an 8 x 8
   * hemisphere's 256 bytes). A 16 x 16 map's 1 KB, or a sphere's, per tied
   * cache is 16+ lines of which the density reads one: loading them all cost
   * more than it hid. Not the alias tables: sampling reads one entry
   * (docs/guiding.md, "Cost of a guided-nee sample"). */
  for (int i = 0; i < v->m; ++i) {
    const iris_cache *ci = &g->caches[v->ids[i]];
    const size_t bytes = (ci->sphere ? g->sphere.texel_count : g->hemi.texel_count) * sizeof(float);
    if (bytes > IRIS_GUIDE_PREFETCH_BYTES) continue;
    const char *pdf = (const char *)(g->pdf + ci->table);
    for (size_t b = 0; b < bytes; b += 64) __builtin_prefetch(pdf + b);
  }
  for (int i = 0; i < v->m; ++i) {
    const iris_cache *ci = &g->caches[v->ids[i]];
    v->same_as[i] = (uint8_t)i;
    for (int j = 0; j < i; ++j) {
      const iris_cache *cj = &g->caches[v->ids[j]];
      if (cj->sphere == ci->sphere && memcmp(&cj->frame, &ci->frame, sizeof ci->frame) == 0) {
        v->same_as[i] = (uint8_t)j;
        break;
      }
    }
  }
}

/* The portal's part of the density: the rest of the mixture (pdf) has 1 - portal of it. */
static inline float with_portal(const iris_guiding *g, const iris_guide_vertex_state *v, float pdf, iris_vec3 wi) {
  if (!(v->portal > 0.0f)) return pdf;
  const iris_portal *p = &g->caches[v->ids[v->portal_of]].portal;
  return (1.0f - v->portal) * pdf + v->portal * iris_portal_pdf(p, v->p, wi);
}

/* A direction drawn by the guide's strategy: the BSDF's value and the mixture's density. */
static bool guided_finish(const iris_guiding *g, const iris_shading_point *sp, const iris_guide_vertex_state *v,
                          float alpha, iris_vec3 wi, iris_direction_sample *out) {
  iris_vec3 wi_local = iris_frame_to_local(&sp->frame, wi);
  out->wi = wi;
  out->f = iris_integrator_bsdf_eval(sp, wi);
  out->pdf = with_portal(g, v,
                         (1.0f - alpha) * iris_integrator_bsdf_pdf(sp, wi) + alpha * iris_guide_vertex_guide_pdf(g, v, wi),
                         wi);
  out->delta = false;
  bool reflect = wi_local.z * sp->wo_local.z > 0.0f;
  out->lobe = (reflect ? IRIS_LOBE_REFLECTION : IRIS_LOBE_TRANSMISSION) |
              ((sp->lobes & IRIS_LOBE_DIFFUSE) ? IRIS_LOBE_DIFFUSE : IRIS_LOBE_GLOSSY);
  return out->pdf > 0.0f && iris_max3(out->f) > 0.0f;
}

static bool guided_sample(void *ctx, const iris_shading_point *sp, iris_sampler *rng,
                          iris_direction_sample *out) {
  const iris_guiding *g = ctx;
  const iris_guide_vertex_state *v = (const iris_guide_vertex_state *)sp->guide.bytes;
  const float alpha = v->alpha;
  /* Delta BSDF, no cache, bad cosine: BSDF sampling with weight 1. */
  if (!(alpha > 0.0f)) return iris_integrator_sample_bsdf(sp, rng, out);
  float u = iris_sampler_slot(rng, IRIS_SLOT_GUIDE_SELECT);
  if (v->portal > 0.0f) { /* a point on the portal, or u rescaled for the rest */
    if (u < v->portal) {
      float u1, u2;
      iris_sampler_slot2(rng, IRIS_SLOT_DIRECTION, &u1, &u2);
      return guided_finish(g, sp, v, alpha, iris_portal_sample(&g->caches[v->ids[v->portal_of]].portal, v->p, u1, u2),
                           out);
    }
    u = iris_rescale_unit(u, v->portal, 1.0f);
  }
  if (u >= alpha) {
    if (!iris_integrator_sample_bsdf(sp, rng, out)) return false;
    if (out->delta) { /* only the BSDF strategy reaches a delta lobe */
      out->pdf *= (1.0f - alpha) * (1.0f - v->portal);
      return true;
    }
    out->pdf = with_portal(g, v, (1.0f - alpha) * out->pdf + alpha * iris_guide_vertex_guide_pdf(g, v, out->wi),
                           out->wi);
    return out->pdf > 0.0f;
  }
  /* Sky behind glass: the guide's share alpha split between the map (sky) and the caches. */
  const float us = u / alpha;
  if (us < v->sky) {
    float u1, u2;
    iris_sampler_slot2(rng, IRIS_SLOT_DIRECTION, &u1, &u2);
    iris_vec3 wi;
    if (!iris_guide_vertex_sky_sample(g, v, u1, u2, &wi)) return false;
    out->aimed = true; /* as a lamp's cone below: no roulette on its way through the glass */
    return guided_finish(g, sp, v, alpha, wi, out);
  }
  if (us < v->sky + v->lamp) { /* lamps behind glass: a lamp's cone */
    float u1, u2;
    iris_vec3 wi;
    iris_sampler_slot2(rng, IRIS_SLOT_DIRECTION, &u1, &u2);
    if (!iris_guide_vertex_lamp_sample(g, v, (us - v->sky) / v->lamp, u1, u2, &wi)) return false;
    /* its throughput is small where the cone is dense: the integrator's
     * roulette must not cut it on its way through the glass */
    out->aimed = true;
    return guided_finish(g, sp, v, alpha, wi, out);
  }
  if (us < v->sky + v->lamp + v->glint) { /* a glint: the spot's cone */
    float u1, u2;
    iris_sampler_slot2(rng, IRIS_SLOT_DIRECTION, &u1, &u2);
    iris_lamp_cone cone = iris_lamp_cone_at(&v->spot, v->p);
    out->aimed = true; /* its throughput is small where the cone is dense, as a lamp's */
    return guided_finish(g, sp, v, alpha, iris_lamp_cone_sample(&cone, u1, u2), out);
  }
  /* Cache strategy: one of the tied caches, uniformly (Algorithm 1), then Algorithm 2. */
  float uc, u0, u1, u2;
  iris_sampler_slot2(rng, IRIS_SLOT_GUIDE_CACHE, &uc, &u0); /* cache, texel */
  iris_sampler_slot2(rng, IRIS_SLOT_DIRECTION, &u1, &u2);   /* position in the texel */
  int m = v->m;
  int j = (int)(uc * (float)m);
  const iris_cache *c = &g->caches[v->ids[j < m ? j : m - 1]];
  const iris_octmap *map = c->sphere ? &g->sphere : &g->hemi;
  float pdf_one;
  iris_vec3 wl = iris_cache_sample_refined(map, g->pdf + c->table, g->alias + c->table,
                                           g->refine_slot ? g->refine_slot + c->table : NULL,
                                           g->refine_slot ? iris_guiding_sub(g, c) : NULL, u0, u1, u2, &pdf_one);
  return guided_finish(g, sp, v, alpha, iris_normalize(iris_frame_to_world(&c->frame, wl)), out);
}

static float guided_pdf(void *ctx, const iris_shading_point *sp, iris_vec3 wi) {
  const iris_guiding *g = ctx;
  const iris_guide_vertex_state *v = (const iris_guide_vertex_state *)sp->guide.bytes;
  float pb = iris_integrator_bsdf_pdf(sp, wi);
  if (!(v->alpha > 0.0f)) return pb;
  return with_portal(g, v, (1.0f - v->alpha) * pb + v->alpha * iris_guide_vertex_guide_pdf(g, v, wi), wi);
}

/* Radiance still to come at a prepared vertex, per unit throughput: the tied
 * caches' estimate (irradiance / pi; the surface's albedo is left out, as in
 * the pixel estimate it is compared with), for the integrator's Russian
 * roulette. */
static float guided_radiance_estimate(void *ctx, const iris_shading_point *sp) {
  (void)ctx;
  const iris_guide_vertex_state *v = (const iris_guide_vertex_state *)sp->guide.bytes;
  return v->radiance;
}

/* Light sampling's probability at a prepared vertex (1 without caches). */
static float guided_light_probability(void *ctx, const iris_shading_point *sp) {
  (void)ctx;
  return ((const iris_guide_vertex_state *)sp->guide.bytes)->light;
}

static void guided_prefetch(void *ctx, iris_vec3 p) {
  const iris_guiding *g = ctx;
  if (g->grid.n[0]) iris_pick_grid_prefetch(&g->grid, p);
}

/* The portal most caches keep (they share the joined opening's rectangle,
 * "Portals"): the caches' portals sorted, the longest run of equal ones. */
typedef struct portal_ref {
  iris_portal portal;
  uint32_t id;
} portal_ref;

static int portal_order(const void *a, const void *b) {
  const portal_ref *pa = a, *pb = b;
  int c = memcmp(&pa->portal, &pb->portal, sizeof pa->portal);
  return c ? c : (pa->id > pb->id) - (pa->id < pb->id);
}

static bool guided_opening(void *ctx, iris_vec3 *o, iris_vec3 *n, float *size, float *share) {
  const iris_guiding *g = ctx;
  portal_ref *refs = malloc(sizeof *refs * (g->cache_count ? g->cache_count : 1));
  if (!refs) return false;
  uint32_t count = 0;
  for (size_t i = 0; i < g->cache_count; ++i)
    if (g->caches[i].portal_weight > 0.0f && iris_portal_present(&g->caches[i].portal))
      refs[count++] = (portal_ref){g->caches[i].portal, (uint32_t)i};
  qsort(refs, count, sizeof *refs, portal_order);
  uint32_t best = 0, best_at = 0;
  for (uint32_t i = 0; i < count;) {
    uint32_t j = i + 1;
    while (j < count && memcmp(&refs[j].portal, &refs[i].portal, sizeof(iris_portal)) == 0) j++;
    if (j - i > best) best = j - i, best_at = i;
    i = j;
  }
  bool found = false;
  if (best > 0) {
    const iris_portal *pt = &refs[best_at].portal;
    iris_vec3 nn = iris_cross(pt->u, pt->v);
    const float len = iris_length(nn);
    if (len > 0.0f && isfinite(len)) {
      nn = iris_scale(nn, 1.0f / len);
      int side = 0; /* the caches keeping it lie on the negative side */
      for (uint32_t i = best_at; i < best_at + best; ++i)
        side += iris_dot(iris_sub(g->caches[refs[i].id].p, pt->o), nn) < 0.0f ? 1 : -1;
      *o = pt->o;
      *n = side >= 0 ? nn : iris_neg(nn);
      *size = iris_fmaxf(iris_length(pt->u), iris_length(pt->v));
      *share = (float)best / (float)g->cache_count;
      found = true;
    }
  }
  free(refs);
  return found;
}

iris_direction_sampler iris_guiding_sampler(iris_guiding *g) {
  iris_direction_sampler s;
  memset(&s, 0, sizeof s);
  if (!g || g->stats.skipped || g->cache_count == 0) return s;
  s.ctx = g;
  s.sample = guided_sample;
  s.pdf = guided_pdf;
  s.prepare = guided_prepare;
  s.prefetch = guided_prefetch;
  if (g->params.adjoint_rr) s.radiance_estimate = guided_radiance_estimate;
  /* only where some cache samples lights less often: elsewhere the paths pay nothing */
  for (size_t i = 0; i < g->cache_count; ++i)
    if (g->caches[i].light < 1.0f) {
      s.light_probability = guided_light_probability;
      break;
    }
  iris_guiding_sky_hooks(g, &s);
  s.opening = guided_opening;
  return s;
}
