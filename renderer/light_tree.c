/* The light tree; see light_tree.h and docs/rendering.md, "Light tree". */
#include "renderer/light_tree.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

/* ---- bounds ---------------------------------------------------------------- */

/* cos(max(theta_a - theta_b, 0)) and sin(max(theta_a - theta_b, 0)) from the
 * sines and cosines (pbrt-v4, LightBounds::Importance). */
static float cos_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
  if (cos_a > cos_b) return 1.0f;
  return cos_a * cos_b + sin_a * sin_b;
}
static float sin_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
  if (cos_a > cos_b) return 0.0f;
  return sin_a * cos_b - cos_a * sin_b;
}

static inline float maxf(float a, float b) { return a > b ? a : b; }

static void store_node(iris_light_tree_node *nd, const iris_light_bounds *b) {
  memset(nd, 0, sizeof *nd);
  iris_v3_store(b->lo, nd->lo);
  iris_v3_store(b->hi, nd->hi);
  nd->radius = 0.5f * iris_length(iris_sub(b->hi, b->lo));
  iris_v3_store(b->w, nd->w);
  nd->cos_o = b->cos_o;
  nd->sin_o = iris_safe_sqrt(1.0f - b->cos_o * b->cos_o);
  nd->cos_e = b->cos_e;
  nd->phi = b->phi;
  nd->flags = b->two_sided ? IRIS_LIGHT_NODE_TWO_SIDED : 0u;
}

/* Importance of a cluster (pbrt-v4's LightBounds::Importance, with two
 * changes: the distance is clamped to the bounding sphere's radius squared
 * rather than its length, and the receiver's cosine is signed, so a cluster
 * wholly behind the surface gets 0). */
static inline float node_importance(const iris_light_tree_node *nd, iris_vec3 p, iris_vec3 n) {
  float phi = nd->phi;
  if (!(phi > 0.0f)) return 0.0f;
  iris_vec3 to_p = iris_v3(p.x - 0.5f * (nd->lo[0] + nd->hi[0]), p.y - 0.5f * (nd->lo[1] + nd->hi[1]),
                           p.z - 0.5f * (nd->lo[2] + nd->hi[2]));
  float dist2 = iris_dot(to_p, to_p);
  float r = nd->radius, r2 = r * r;
  if (!(dist2 > r2)) { /* inside the bounding sphere: the box's half-spaces decide */
    /* one-sided emitters of one normal emit nothing to p behind all of them */
    if (nd->cos_o >= 1.0f && nd->cos_e >= 0.0f && !(nd->flags & IRIS_LIGHT_NODE_TWO_SIDED)) {
      float front = nd->w[0] * (p.x - (nd->w[0] > 0.0f ? nd->lo[0] : nd->hi[0])) +
                    nd->w[1] * (p.y - (nd->w[1] > 0.0f ? nd->lo[1] : nd->hi[1])) +
                    nd->w[2] * (p.z - (nd->w[2] > 0.0f ? nd->lo[2] : nd->hi[2]));
      if (front <= 0.0f) return 0.0f;
    }
    /* nor to a receiver whose hemisphere holds none of the box */
    if (n.x != 0.0f || n.y != 0.0f || n.z != 0.0f) {
      float above = n.x * ((n.x > 0.0f ? nd->hi[0] : nd->lo[0]) - p.x) +
                    n.y * ((n.y > 0.0f ? nd->hi[1] : nd->lo[1]) - p.y) +
                    n.z * ((n.z > 0.0f ? nd->hi[2] : nd->lo[2]) - p.z);
      if (above <= 0.0f) return 0.0f;
    }
    float imp = phi / maxf(r2, FLT_MIN);
    return imp > 0.0f ? (imp < FLT_MAX ? imp : FLT_MAX) : 0.0f;
  }
  float inv_d = 1.0f / sqrtf(dist2);
  iris_vec3 wi = iris_scale(to_p, inv_d); /* from the cluster to p */
  /* theta_b: the half angle of the bounding sphere seen from p */
  float sin_b = r * inv_d;
  float cos_b = iris_safe_sqrt(1.0f - sin_b * sin_b);
  /* the emitters' normals: the smallest angle between a normal and a direction to p */
  float cos_w = nd->w[0] * wi.x + nd->w[1] * wi.y + nd->w[2] * wi.z;
  if (nd->flags & IRIS_LIGHT_NODE_TWO_SIDED) cos_w = fabsf(cos_w);
  float sin_w = iris_safe_sqrt(1.0f - cos_w * cos_w);
  float cos_x = cos_sub_clamped(sin_w, cos_w, nd->sin_o, nd->cos_o);
  float sin_x = sin_sub_clamped(sin_w, cos_w, nd->sin_o, nd->cos_o);
  float cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
  if (cos_p <= nd->cos_e) return 0.0f;
  float imp = phi * cos_p / dist2;
  if (n.x != 0.0f || n.y != 0.0f || n.z != 0.0f) { /* the receiver's cosine, bounded */
    float cos_i = -iris_dot(wi, n);
    float sin_i = iris_safe_sqrt(1.0f - cos_i * cos_i);
    float cos_pi = cos_sub_clamped(sin_i, cos_i, sin_b, cos_b);
    if (cos_pi <= 0.0f) return 0.0f;
    imp *= cos_pi;
  }
  if (!(imp > 0.0f)) return 0.0f; /* NaN too */
  return imp < FLT_MAX ? imp : FLT_MAX;
}

float iris_light_bounds_importance(const iris_light_bounds *b, iris_vec3 p, iris_vec3 n) {
  if (b->infinite) return b->phi > 0.0f ? b->phi : 0.0f;
  iris_light_tree_node nd;
  store_node(&nd, b);
  return node_importance(&nd, p, n);
}

/* Angle between unit vectors, accurate near 0 and pi. */
static float angle_between(iris_vec3 a, iris_vec3 b) {
  if (iris_dot(a, b) < 0.0f) return IRIS_PI - 2.0f * asinf(fminf(1.0f, 0.5f * iris_length(iris_add(a, b))));
  return 2.0f * asinf(fminf(1.0f, 0.5f * iris_length(iris_sub(b, a))));
}

/* Smallest cone holding two cones (pbrt-v4's DirectionCone Union), widened by
 * 1e-4 rad against rounding so it stays a bound. */
static void cone_union(iris_vec3 wa, float cos_a, iris_vec3 wb, float cos_b, iris_vec3 *w, float *cos_o) {
  float ta = acosf(iris_clampf(cos_a, -1.0f, 1.0f)), tb = acosf(iris_clampf(cos_b, -1.0f, 1.0f));
  float td = angle_between(wa, wb);
  if (fminf(td + tb, IRIS_PI) <= ta) {
    *w = wa;
    *cos_o = cos_a;
    return;
  }
  if (fminf(td + ta, IRIS_PI) <= tb) {
    *w = wb;
    *cos_o = cos_b;
    return;
  }
  float to = 0.5f * (ta + td + tb);
  iris_vec3 wr = iris_cross(wa, wb);
  if (to >= IRIS_PI || !(iris_dot(wr, wr) > 0.0f)) {
    *w = wa;
    *cos_o = -1.0f;
    return;
  }
  wr = iris_normalize(wr);
  float tr = to - ta; /* turn wa towards wb about wr by tr (Rodrigues, wr . wa = 0) */
  *w = iris_normalize(iris_add(iris_scale(wa, cosf(tr)), iris_scale(iris_cross(wr, wa), sinf(tr))));
  *cos_o = to + 1e-4f >= IRIS_PI ? -1.0f : cosf(to + 1e-4f);
}

static void bounds_union(iris_light_bounds *a, const iris_light_bounds *b) {
  if (!(a->phi > 0.0f)) {
    *a = *b;
    return;
  }
  a->lo = iris_v3(fminf(a->lo.x, b->lo.x), fminf(a->lo.y, b->lo.y), fminf(a->lo.z, b->lo.z));
  a->hi = iris_v3(fmaxf(a->hi.x, b->hi.x), fmaxf(a->hi.y, b->hi.y), fmaxf(a->hi.z, b->hi.z));
  cone_union(a->w, a->cos_o, b->w, b->cos_o, &a->w, &a->cos_o);
  a->cos_e = fminf(a->cos_e, b->cos_e);
  a->phi += b->phi;
  a->two_sided = a->two_sided || b->two_sided;
}

/* ---- build ----------------------------------------------------------------- */

typedef struct item {
  iris_light_bounds b;
  iris_vec3 c; /* centroid */
  uint32_t light;
} item;

typedef struct builder {
  iris_light_tree *t;
  size_t next;
  size_t next_leaf_light;
  float leaf_radius; /* a cluster's node this small may be a leaf */
} builder;

#define BUCKETS 12
#define SAH_MAX_DEPTH 30 /* deeper: median splits, so no path is longer than 62 */

static float axis(iris_vec3 v, int d) { return d == 0 ? v.x : (d == 1 ? v.y : v.z); }

/* pbrt-v4's surface area orientation heuristic (BVHLightSampler::EvaluateCost):
 * power x the normal cone's measure x the box's area, Kr penalising thin
 * slices. Extents are floored so clusters of points still compare. */
static double split_cost(const iris_light_bounds *b, iris_vec3 parent_diag, int dim, float floor_extent) {
  float to = acosf(iris_clampf(b->cos_o, -1.0f, 1.0f)), te = acosf(iris_clampf(b->cos_e, -1.0f, 1.0f));
  float tw = fminf(to + te, IRIS_PI);
  float so = iris_safe_sqrt(1.0f - b->cos_o * b->cos_o);
  double m = 2.0 * IRIS_PI * (1.0 - b->cos_o) +
             0.5 * IRIS_PI * (2.0 * tw * so - cos(to - 2.0 * tw) - 2.0 * to * so + b->cos_o);
  double kr = iris_max3(parent_diag) / fmax(axis(parent_diag, dim), floor_extent);
  double dx = fmax(b->hi.x - b->lo.x, floor_extent), dy = fmax(b->hi.y - b->lo.y, floor_extent),
         dz = fmax(b->hi.z - b->lo.z, floor_extent);
  return b->phi * m * kr * 2.0 * (dx * dy + dy * dz + dz * dx);
}

static size_t choose_split(item *it, size_t n, const iris_light_bounds *all) {
  iris_vec3 cmin = it[0].c, cmax = it[0].c;
  for (size_t i = 1; i < n; i++) {
    cmin = iris_v3(fminf(cmin.x, it[i].c.x), fminf(cmin.y, it[i].c.y), fminf(cmin.z, it[i].c.z));
    cmax = iris_v3(fmaxf(cmax.x, it[i].c.x), fmaxf(cmax.y, it[i].c.y), fmaxf(cmax.z, it[i].c.z));
  }
  iris_vec3 diag = iris_sub(all->hi, all->lo);
  float floor_extent = fmaxf(1e-3f * iris_max3(diag), FLT_MIN);
  double best = INFINITY;
  int best_dim = -1, best_split = 0;
  for (int d = 0; d < 3; d++) {
    float lo = axis(cmin, d), hi = axis(cmax, d);
    if (!(hi > lo)) continue;
    iris_light_bounds bucket[BUCKETS];
    memset(bucket, 0, sizeof bucket);
    for (size_t i = 0; i < n; i++) {
      int k = (int)(BUCKETS * ((axis(it[i].c, d) - lo) / (hi - lo)));
      k = k < 0 ? 0 : (k >= BUCKETS ? BUCKETS - 1 : k);
      bounds_union(&bucket[k], &it[i].b);
    }
    for (int s = 1; s < BUCKETS; s++) {
      iris_light_bounds left, right;
      memset(&left, 0, sizeof left);
      memset(&right, 0, sizeof right);
      for (int k = 0; k < s; k++) bounds_union(&left, &bucket[k]);
      for (int k = s; k < BUCKETS; k++) bounds_union(&right, &bucket[k]);
      if (!(left.phi > 0.0f) || !(right.phi > 0.0f)) continue;
      double c = split_cost(&left, diag, d, floor_extent) + split_cost(&right, diag, d, floor_extent);
      if (c < best) {
        best = c;
        best_dim = d;
        best_split = s;
      }
    }
  }
  if (best_dim < 0) return n / 2; /* every centroid at one point: halve the list */
  float lo = axis(cmin, best_dim), hi = axis(cmax, best_dim);
  size_t mid = 0;
  for (size_t i = 0; i < n; i++) {
    int k = (int)(BUCKETS * ((axis(it[i].c, best_dim) - lo) / (hi - lo)));
    k = k < 0 ? 0 : (k >= BUCKETS ? BUCKETS - 1 : k);
    if (k < best_split) {
      item tmp = it[i];
      it[i] = it[mid];
      it[mid++] = tmp;
    }
  }
  return mid > 0 && mid < n ? mid : n / 2;
}

static uint32_t build_node(builder *B, item *it, size_t n, int depth, uint64_t bits) {
  uint32_t index = (uint32_t)B->next++;
  iris_light_bounds all = it[0].b;
  for (size_t i = 1; i < n; i++) bounds_union(&all, &it[i].b);
  iris_light_tree_node *nd = &B->t->nodes[index];
  store_node(nd, &all);
  bool leaf = n == 1;
  if (!leaf && n <= IRIS_LIGHT_LEAF_MAX && it[0].b.cluster != UINT32_MAX && nd->radius <= B->leaf_radius) {
    leaf = true;
    for (size_t i = 1; i < n; i++) leaf = leaf && it[i].b.cluster == it[0].b.cluster;
  }
  if (leaf) {
    iris_light_tree *t = B->t;
    nd->flags |= IRIS_LIGHT_NODE_LEAF;
    nd->index = (uint32_t)B->next_leaf_light;
    nd->flags |= (uint32_t)n << 8;
    double sum = 0.0, acc = 0.0;
    for (size_t i = 0; i < n; i++) sum += it[i].b.phi;
    for (size_t i = 0; i < n; i++) {
      uint32_t l = it[i].light;
      acc += it[i].b.phi;
      t->leaf_lights[B->next_leaf_light] = l;
      t->leaf_cdf[B->next_leaf_light++] = i + 1 == n ? 1.0f : (float)(acc / sum);
      t->pmf_in_leaf[l] = (float)(it[i].b.phi / sum);
      t->bits[l] = bits;
      t->node_of_light[l] = index;
    }
    return index;
  }
  size_t mid = depth < SAH_MAX_DEPTH ? choose_split(it, n, &all) : n / 2;
  build_node(B, it, mid, depth + 1, bits);
  uint32_t second = build_node(B, it + mid, n - mid, depth + 1, bits | (1ull << depth));
  B->t->nodes[index].index = second;
  return index;
}

/* Lane k of wide node w holds binary node nd, reached by the branches
 * `path` (bit j: the second child at the j-th step) of `len` steps. */
static void wide_lane(const iris_light_tree *t, iris_light_tree_wide *w, int k, const iris_light_tree_node *nd,
                      uint32_t path, uint32_t len) {
  for (int a = 0; a < 3; a++) {
    w->lo[a][k] = nd->lo[a];
    w->hi[a][k] = nd->hi[a];
    w->w[a][k] = nd->w[a];
  }
  w->radius[k] = nd->radius;
  w->cos_o[k] = nd->cos_o;
  w->sin_o[k] = nd->sin_o;
  w->cos_e[k] = nd->cos_e;
  w->phi[k] = nd->phi;
  w->phi_r2[k] = nd->phi / fmaxf(nd->radius * nd->radius, FLT_MIN);
  bool two = nd->flags & IRIS_LIGHT_NODE_TWO_SIDED;
  w->two_sided[k] = two ? 1.0f : 0.0f;
  w->one_normal[k] = nd->cos_o >= 1.0f && nd->cos_e >= 0.0f && !two ? 1.0f : 0.0f;
  w->node[k] = (uint32_t)(nd - t->nodes);
  w->path[k] = (uint8_t)path;
  w->len[k] = (uint8_t)len;
}

/* The lanes under binary node c, reached by `path` of `len` steps: c itself
 * once it is a leaf or IRIS_LIGHT_WIDE_LEVELS steps down, else its children's. */
static void wide_gather(const iris_light_tree *t, iris_light_tree_wide *w, uint32_t *lane_node, int *k, uint32_t c,
                        uint32_t path, uint32_t len) {
  const iris_light_tree_node *nd = &t->nodes[c];
  if ((nd->flags & IRIS_LIGHT_NODE_LEAF) || len == IRIS_LIGHT_WIDE_LEVELS) {
    lane_node[*k] = c;
    wide_lane(t, w, (*k)++, nd, path, len);
    return;
  }
  wide_gather(t, w, lane_node, k, c + 1, path, len + 1);
  wide_gather(t, w, lane_node, k, nd->index, path | 1u << len, len + 1);
}

/* The wide node of binary interior node i (see iris_light_tree_wide),
 * depth first; returns its index. */
static uint32_t build_wide(iris_light_tree *t, uint32_t i) {
  uint32_t at = (uint32_t)t->wide_count++;
  memset(&t->wide[at], 0, sizeof t->wide[at]);
  uint32_t lane_node[IRIS_LIGHT_WIDE];
  int k = 0;
  wide_gather(t, &t->wide[at], lane_node, &k, i + 1, 0u, 1u);
  wide_gather(t, &t->wide[at], lane_node, &k, t->nodes[i].index, 1u, 1u);
  for (int j = 0; j < k; j++) {
    uint32_t g = lane_node[j];
    uint32_t child = (t->nodes[g].flags & IRIS_LIGHT_NODE_LEAF) ? IRIS_LIGHT_WIDE_LEAF | g : build_wide(t, g);
    t->wide[at].child[j] = child;
  }
  return at;
}

static bool bounds_usable(const iris_light_bounds *b) {
  if (!(b->phi > 0.0f) || !isfinite(b->phi)) return false;
  if (b->infinite) return true;
  return iris_isfinite3(b->lo) && iris_isfinite3(b->hi) && iris_isfinite3(b->w) && isfinite(b->cos_o) &&
         isfinite(b->cos_e);
}

iris_status iris_light_tree_build(const iris_light_bounds *lights, size_t count, float leaf_radius,
                                  iris_light_tree *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  if (count >= UINT32_MAX / 2)
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "%zu lights are too many for the light tree", count);
  out->light_count = count;
  size_t finite = 0, infinite = 0;
  for (size_t i = 0; i < count; i++) {
    if (!bounds_usable(&lights[i])) continue;
    if (lights[i].infinite)
      infinite++;
    else
      finite++;
  }
  out->bits = calloc(count ? count : 1, sizeof *out->bits);
  out->node_of_light = malloc(sizeof *out->node_of_light * (count ? count : 1));
  out->infinite = malloc(sizeof *out->infinite * (infinite ? infinite : 1));
  out->infinite_phi = malloc(sizeof *out->infinite_phi * (infinite ? infinite : 1));
  out->leaf_lights = malloc(sizeof *out->leaf_lights * (finite ? finite : 1));
  out->leaf_cdf = malloc(sizeof *out->leaf_cdf * (finite ? finite : 1));
  out->pmf_in_leaf = calloc(count ? count : 1, sizeof *out->pmf_in_leaf);
  out->nodes = aligned_alloc(64, sizeof *out->nodes * (finite ? 2 * finite - 1 : 1));
  item *items = malloc(sizeof *items * (finite ? finite : 1));
  if (!out->leaf_lights || !out->leaf_cdf || !out->pmf_in_leaf || !out->bits || !out->node_of_light || !out->infinite || !out->infinite_phi || !out->nodes || !items) {
    free(items);
    iris_light_tree_destroy(out);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for the light tree");
  }
  size_t f = 0;
  for (size_t i = 0; i < count; i++) {
    out->node_of_light[i] = UINT32_MAX;
    const iris_light_bounds *b = &lights[i];
    if (!bounds_usable(b)) continue;
    if (b->infinite) {
      out->infinite[out->infinite_count] = (uint32_t)i;
      out->infinite_phi[out->infinite_count++] = b->phi;
      out->infinite_sum += b->phi;
      continue;
    }
    items[f].b = *b;
    items[f].b.w = iris_normalize(b->w);
    items[f].b.cos_o = iris_clampf(b->cos_o, -1.0f, 1.0f);
    items[f].b.cos_e = iris_clampf(b->cos_e, -1.0f, 1.0f);
    items[f].c = iris_scale(iris_add(b->lo, b->hi), 0.5f);
    items[f].light = (uint32_t)i;
    f++;
  }
  if (f > 0) {
    builder B = {out, 0, 0, leaf_radius};
    build_node(&B, items, f, 0, 0);
    out->node_count = B.next;
    if (!(out->nodes[0].flags & IRIS_LIGHT_NODE_LEAF)) {
      out->wide = aligned_alloc(64, sizeof *out->wide * out->node_count);
      if (!out->wide) {
        free(items);
        iris_light_tree_destroy(out);
        return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for the light tree");
      }
      build_wide(out, 0);
    }
  }
  free(items);
  return IRIS_OK;
}

void iris_light_tree_destroy(iris_light_tree *t) {
  if (!t) return;
  free(t->nodes);
  free(t->wide);
  free(t->leaf_lights);
  free(t->leaf_cdf);
  free(t->pmf_in_leaf);
  free(t->bits);
  free(t->node_of_light);
  free(t->infinite);
  free(t->infinite_phi);
  memset(t, 0, sizeof *t);
}

/* ---- sampling and its pmf ----------------------------------------------------- */

/* Probability of choosing among the infinite lights at (p, n): their summed
 * importance against the root's. */
static double infinite_share(const iris_light_tree *t, iris_vec3 p, iris_vec3 n) {
  if (t->infinite_count == 0) return 0.0;
  if (t->node_count == 0) return 1.0;
  double root = node_importance(&t->nodes[0], p, n);
  return t->infinite_sum / (t->infinite_sum + root);
}

/* node_importance for the four lanes of a wide node at once, the same
 * formula without branches: both the inside and the outside case are
 * computed and one is kept. SSE where the compiler has it (every x86-64),
 * else node_importance lane by lane. */
#if defined(__SSE2__)
#include <emmintrin.h>
static inline __m128 sel4(__m128 m, __m128 a, __m128 b) { return _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b)); }
static inline __m128 sqrt0(__m128 v) { return _mm_sqrt_ps(_mm_max_ps(v, _mm_setzero_ps())); } /* NaN -> 0 */
static void importance4(const iris_light_tree_wide *w, int o, iris_vec3 p, iris_vec3 n, float *out) {
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), half = _mm_set1_ps(0.5f);
  const __m128 px = _mm_set1_ps(p.x), py = _mm_set1_ps(p.y), pz = _mm_set1_ps(p.z);
  const __m128 nx = _mm_set1_ps(n.x), ny = _mm_set1_ps(n.y), nz = _mm_set1_ps(n.z);
  const bool has_n = n.x != 0.0f || n.y != 0.0f || n.z != 0.0f;
  __m128 lx = _mm_load_ps(w->lo[0] + o), ly = _mm_load_ps(w->lo[1] + o), lz = _mm_load_ps(w->lo[2] + o);
  __m128 hx = _mm_load_ps(w->hi[0] + o), hy = _mm_load_ps(w->hi[1] + o), hz = _mm_load_ps(w->hi[2] + o);
  __m128 wx = _mm_load_ps(w->w[0] + o), wy = _mm_load_ps(w->w[1] + o), wz = _mm_load_ps(w->w[2] + o);
  __m128 phi = _mm_load_ps(w->phi + o), r = _mm_load_ps(w->radius + o), r2 = _mm_mul_ps(r, r);
  __m128 tx = _mm_sub_ps(px, _mm_mul_ps(half, _mm_add_ps(lx, hx)));
  __m128 ty = _mm_sub_ps(py, _mm_mul_ps(half, _mm_add_ps(ly, hy)));
  __m128 tz = _mm_sub_ps(pz, _mm_mul_ps(half, _mm_add_ps(lz, hz)));
  __m128 dist2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(tx, tx), _mm_mul_ps(ty, ty)), _mm_mul_ps(tz, tz));
  /* inside the bounding sphere: the box's half-spaces */
  __m128 front = _mm_add_ps(
      _mm_add_ps(_mm_mul_ps(wx, _mm_sub_ps(px, sel4(_mm_cmpgt_ps(wx, zero), lx, hx))),
                 _mm_mul_ps(wy, _mm_sub_ps(py, sel4(_mm_cmpgt_ps(wy, zero), ly, hy)))),
      _mm_mul_ps(wz, _mm_sub_ps(pz, sel4(_mm_cmpgt_ps(wz, zero), lz, hz))));
  __m128 in_dead = _mm_and_ps(_mm_cmpgt_ps(_mm_load_ps(w->one_normal + o), zero), _mm_cmple_ps(front, zero));
  if (has_n) {
    __m128 above = _mm_add_ps(
        _mm_add_ps(_mm_mul_ps(nx, _mm_sub_ps(sel4(_mm_cmpgt_ps(nx, zero), hx, lx), px)),
                   _mm_mul_ps(ny, _mm_sub_ps(sel4(_mm_cmpgt_ps(ny, zero), hy, ly), py))),
        _mm_mul_ps(nz, _mm_sub_ps(sel4(_mm_cmpgt_ps(nz, zero), hz, lz), pz)));
    in_dead = _mm_or_ps(in_dead, _mm_cmple_ps(above, zero));
  }
  __m128 in_imp = _mm_andnot_ps(in_dead, _mm_load_ps(w->phi_r2 + o));
  /* outside: the cone bounds */
  __m128 d2 = _mm_max_ps(dist2, _mm_set1_ps(FLT_MIN));
  __m128 inv_d = _mm_div_ps(one, _mm_sqrt_ps(d2));
  __m128 ux = _mm_mul_ps(tx, inv_d), uy = _mm_mul_ps(ty, inv_d), uz = _mm_mul_ps(tz, inv_d);
  __m128 sin_b = _mm_mul_ps(r, inv_d);
  __m128 cos_b = sqrt0(_mm_sub_ps(one, _mm_mul_ps(sin_b, sin_b)));
  __m128 cos_w = _mm_add_ps(_mm_add_ps(_mm_mul_ps(wx, ux), _mm_mul_ps(wy, uy)), _mm_mul_ps(wz, uz));
  __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  cos_w = sel4(_mm_cmpgt_ps(_mm_load_ps(w->two_sided + o), zero), _mm_and_ps(cos_w, abs_mask), cos_w);
  __m128 sin_w = sqrt0(_mm_sub_ps(one, _mm_mul_ps(cos_w, cos_w)));
  __m128 cos_o = _mm_load_ps(w->cos_o + o), sin_o = _mm_load_ps(w->sin_o + o);
  __m128 in_cone = _mm_cmpgt_ps(cos_w, cos_o);
  __m128 cos_x = sel4(in_cone, one, _mm_add_ps(_mm_mul_ps(cos_w, cos_o), _mm_mul_ps(sin_w, sin_o)));
  __m128 sin_x = sel4(in_cone, zero, _mm_sub_ps(_mm_mul_ps(sin_w, cos_o), _mm_mul_ps(cos_w, sin_o)));
  __m128 cos_p = sel4(_mm_cmpgt_ps(cos_x, cos_b), one, _mm_add_ps(_mm_mul_ps(cos_x, cos_b), _mm_mul_ps(sin_x, sin_b)));
  __m128 out_dead = _mm_cmple_ps(cos_p, _mm_load_ps(w->cos_e + o));
  __m128 out_imp = _mm_mul_ps(_mm_mul_ps(phi, cos_p), _mm_mul_ps(inv_d, inv_d));
  if (has_n) {
    __m128 cos_i = _mm_sub_ps(zero, _mm_add_ps(_mm_add_ps(_mm_mul_ps(ux, nx), _mm_mul_ps(uy, ny)), _mm_mul_ps(uz, nz)));
    __m128 sin_i = sqrt0(_mm_sub_ps(one, _mm_mul_ps(cos_i, cos_i)));
    __m128 cos_pi =
        sel4(_mm_cmpgt_ps(cos_i, cos_b), one, _mm_add_ps(_mm_mul_ps(cos_i, cos_b), _mm_mul_ps(sin_i, sin_b)));
    out_dead = _mm_or_ps(out_dead, _mm_cmple_ps(cos_pi, zero));
    out_imp = _mm_mul_ps(out_imp, cos_pi);
  }
  out_imp = _mm_andnot_ps(out_dead, out_imp);
  __m128 imp = sel4(_mm_cmpgt_ps(dist2, r2), out_imp, in_imp);
  /* phi > 0 and imp > 0 (false for NaN), at most FLT_MAX */
  imp = _mm_and_ps(_mm_and_ps(_mm_cmpgt_ps(phi, zero), _mm_cmpgt_ps(imp, zero)), _mm_min_ps(imp, _mm_set1_ps(FLT_MAX)));
  _mm_storeu_ps(out, imp);
}
static void wide_importance(const iris_light_tree *t, const iris_light_tree_wide *w, iris_vec3 p, iris_vec3 n,
                            float out[IRIS_LIGHT_WIDE]) {
  (void)t;
  for (int o = 0; o < IRIS_LIGHT_WIDE; o += 4) importance4(w, o, p, n, out + o);
}
#else
/* Without SSE: each lane's binary node through the scalar function. */
static void wide_importance(const iris_light_tree *t, const iris_light_tree_wide *w, iris_vec3 p, iris_vec3 n,
                            float out[IRIS_LIGHT_WIDE]) {
  for (int k = 0; k < IRIS_LIGHT_WIDE; k++) out[k] = w->phi[k] > 0.0f ? node_importance(&t->nodes[w->node[k]], p, n) : 0.0f;
}
#endif

float iris_light_tree_node_importance(const iris_light_tree_node *node, iris_vec3 p, iris_vec3 n) {
  return node_importance(node, p, n);
}

void iris_light_tree_wide_importance(const iris_light_tree *t, size_t wide, iris_vec3 p, iris_vec3 n,
                                     float out[IRIS_LIGHT_WIDE]) {
  wide_importance(t, &t->wide[wide], p, n, out);
}

/* THE descent, for sampling (bits == NULL: follows *u, rescaled at each
 * step) and for the pmf (follows the light's path bits): the same calls and
 * arithmetic either way. Returns the binary leaf reached, or UINT32_MAX when
 * a step on the way has nothing to give; multiplies *pmf by each branch's
 * probability (a lane's importance over the lanes' sum). */
static uint32_t descend(const iris_light_tree *t, iris_vec3 p, iris_vec3 n, double *u, const uint64_t *bits,
                        double *pmf) {
  if (!t->wide) { /* the root is a leaf */
    if (!(node_importance(&t->nodes[0], p, n) > 0.0f)) return UINT32_MAX;
    return 0;
  }
  uint32_t i = 0;
  for (int depth = 0;;) {
    const iris_light_tree_wide *w = &t->wide[i];
    float c[IRIS_LIGHT_WIDE];
    wide_importance(t, w, p, n, c);
    double sum = 0.0;
    for (int k = 0; k < IRIS_LIGHT_WIDE; k++) sum += c[k];
    if (!(sum > 0.0)) return UINT32_MAX;
    double inv = 1.0 / sum;
    int take = -1;
    if (bits) {
      uint32_t next = depth < 64 ? (uint32_t)(*bits >> depth) : 0u; /* the light's next branches */
      for (int k = 0; k < IRIS_LIGHT_WIDE && take < 0; k++)
        if (w->phi[k] > 0.0f && (next & ((1u << w->len[k]) - 1u)) == w->path[k]) take = k;
      if (take < 0) return UINT32_MAX;
    } else {
      double below = 0.0;
      int last = -1;
      for (int k = 0; k < IRIS_LIGHT_WIDE && take < 0; k++) {
        double pk = c[k] * inv;
        if (!(pk > 0.0)) continue;
        last = k;
        if (*u < below + pk) take = k;
        else below += pk;
      }
      if (take < 0) { /* rounding: u at the top of the last branch */
        take = last;
        below -= c[last] * inv;
      }
      *u = (*u - below) / (c[take] * inv);
      if (!(*u < 1.0)) *u = 0x1.fffffffffffffp-1;
      if (!(*u >= 0.0)) *u = 0.0;
    }
    double pb = c[take] * inv;
    if (!(pb > 0.0)) return UINT32_MAX;
    *pmf *= pb;
    depth += w->len[take];
    uint32_t child = w->child[take];
    if (child & IRIS_LIGHT_WIDE_LEAF) return child & ~IRIS_LIGHT_WIDE_LEAF;
    i = child;
  }
}

uint32_t iris_light_tree_leaf_choose(const iris_light_tree *t, uint32_t leaf, double v) {
  const iris_light_tree_node *nd = &t->nodes[leaf];
  /* by power: the first cdf above v */
  const float *cdf = &t->leaf_cdf[nd->index];
  uint32_t j = 0, hi = (nd->flags >> 8) - 1;
  while (j < hi) {
    uint32_t mid = (j + hi) / 2;
    if (v < (double)cdf[mid])
      hi = mid;
    else
      j = mid + 1;
  }
  return t->leaf_lights[nd->index + j];
}

bool iris_light_tree_sample(const iris_light_tree *t, iris_vec3 p, iris_vec3 n, float u, uint32_t *light,
                            float *pmf) {
  *light = 0;
  *pmf = 0.0f;
  double pi = infinite_share(t, p, n);
  double v = u;
  if (v < pi) { /* an infinite light, in proportion to its importance */
    double target = v / pi * t->infinite_sum, acc = 0.0;
    size_t k = 0, last = 0;
    for (; k < t->infinite_count; k++) {
      if (t->infinite_phi[k] > 0.0f) last = k;
      if (acc + t->infinite_phi[k] > target) break;
      acc += t->infinite_phi[k];
    }
    if (k == t->infinite_count) k = last;
    *light = t->infinite[k];
    *pmf = (float)(pi * (t->infinite_phi[k] / t->infinite_sum));
    return *pmf > 0.0f;
  }
  if (t->node_count == 0) return false;
  v = (v - pi) / (1.0 - pi);
  if (!(v < 1.0)) v = 0x1.fffffffffffffp-1;
  double q = 1.0 - pi;
  uint32_t leaf = descend(t, p, n, &v, NULL, &q);
  if (leaf == UINT32_MAX) return false;
  *light = iris_light_tree_leaf_choose(t, leaf, v);
  *pmf = (float)(q * (double)t->pmf_in_leaf[*light]);
  return *pmf > 0.0f;
}

float iris_light_tree_pmf(const iris_light_tree *t, iris_vec3 p, iris_vec3 n, uint32_t light) {
  if (light >= t->light_count) return 0.0f;
  double pi = infinite_share(t, p, n);
  uint32_t node = t->node_of_light[light];
  if (node == UINT32_MAX) {
    for (size_t k = 0; k < t->infinite_count; k++)
      if (t->infinite[k] == light) return (float)(pi * (t->infinite_phi[k] / t->infinite_sum));
    return 0.0f;
  }
  if (!(pi < 1.0)) return 0.0f;
  double q = 1.0 - pi;
  uint32_t leaf = descend(t, p, n, NULL, &t->bits[light], &q);
  return leaf == node ? (float)(q * (double)t->pmf_in_leaf[light]) : 0.0f;
}
