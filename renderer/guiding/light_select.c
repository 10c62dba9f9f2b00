/* Learned light selection: light_select.h, docs/guiding.md "Learned light selection". */
#include "renderer/guiding/light_select.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/cancel.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "renderer/guiding/guiding.h"
#include "renderer/guiding/kdtree.h"

/* A photon straight from a light, as the tables read it. */
typedef struct direct_photon {
  iris_vec3 p, n, wi;
  float energy;
  uint32_t leaf;
} direct_photon;

typedef struct accept_ctx {
  const direct_photon *dp;
  iris_vec3 n;
  bool sphere;
} accept_ctx;

/* The caches' own photon filter (guiding.c): not from below the cache's
 * hemisphere, not from a surface facing otherwise (the far side of a wall). */
static bool accept_photon(void *ctx, uint32_t id) {
  const accept_ctx *a = ctx;
  const direct_photon *ph = &a->dp[id];
  if (iris_dot(ph->n, a->n) < IRIS_GUIDING_PHOTON_NORMAL_COS) return false;
  return a->sphere || iris_dot(ph->wi, a->n) > 0.0f;
}

uint32_t iris_light_select_leaf_of(const iris_light_tree *t, uint32_t light) {
  if (light >= t->light_count) return UINT32_MAX;
  if (t->node_of_light[light] != UINT32_MAX) return t->node_of_light[light];
  for (size_t k = 0; k < t->infinite_count; ++k)
    if (t->infinite[k] == light) return IRIS_LIGHT_SELECT_INFINITE | (uint32_t)k;
  return UINT32_MAX;
}

/* A slot's light: the leaf's by power (v in [0, 1)), or the infinite light. */
static uint32_t slot_light(const iris_light_tree *t, uint32_t leaf, double v) {
  if (leaf & IRIS_LIGHT_SELECT_INFINITE) return t->infinite[leaf & ~IRIS_LIGHT_SELECT_INFINITE];
  return iris_light_tree_leaf_choose(t, leaf, v);
}

typedef struct leaf_energy {
  uint32_t leaf;
  double energy;
} leaf_energy;

static int by_leaf(const void *a, const void *b) {
  const leaf_energy *x = a, *y = b;
  return x->leaf < y->leaf ? -1 : x->leaf > y->leaf;
}
/* brightest first; equal energies by leaf (a total order: the same tables for any qsort) */
static int by_energy(const void *a, const void *b) {
  const leaf_energy *x = a, *y = b;
  if (x->energy != y->energy) return x->energy > y->energy ? -1 : 1;
  return x->leaf < y->leaf ? -1 : x->leaf > y->leaf;
}

static void mark_near(iris_light_select *sel);

typedef struct build_ctx {
  iris_light_select *sel;
  const iris_lights *lights;
  uint64_t seed;
  const direct_photon *dp;
  iris_kdtree tree;
  uint32_t k;
  float max_d2;
  uint32_t **ids;
  float **d2;
  leaf_energy **sums;
} build_ctx;

/* The share of the tree's light samples at a cache whose shadow ray hits
 * something: IRIS_LIGHT_SELECT_PROBES samples of the tree at the cache's
 * position and normal, numbers from a hash of (seed, cache, probe). */
static double hidden_share(const build_ctx *c, const iris_cache *cache, uint64_t index) {
  const iris_lights *L = c->lights;
  int valid = 0, hidden = 0;
  for (int k = 0; k < IRIS_LIGHT_SELECT_PROBES; ++k) {
    uint64_t h = iris_hash4(c->seed, index, (uint64_t)k, 0x11947ULL);
    float u = (float)((h >> 40) * 0x1p-24), u0 = (float)(((h >> 16) & 0xffffffu) * 0x1p-24);
    float u1 = (float)(iris_mix64(h) >> 40) * 0x1p-24f;
    iris_light_choice ch = {0, 0.0f, true};
    if (!iris_light_tree_sample(L->tree, cache->p, cache->frame.n, u, &ch.light, &ch.pmf_group)) continue;
    iris_light_sample ls;
    if (!iris_lights_sample_choice(L, cache->p, &ch, u0, u1, &ls)) continue;
    if (!(iris_dot(ls.wi, cache->frame.n) > 0.0f) && !cache->sphere) continue;
    iris_ray r;
    if (isfinite(ls.dist) && !ls.delta) {
      r = iris_spawn_ray_to(cache->p, cache->frame.n, ls.p, ls.n);
    } else {
      r.o = iris_offset_origin(cache->p, cache->frame.n, ls.wi);
      r.d = ls.wi;
      r.tmin = 0.0f;
      r.tmax = isfinite(ls.dist) ? ls.dist * (1.0f - 1e-5f) : INFINITY;
    }
    valid++;
    hidden += iris_accel_occluded(L->accel, &r);
  }
  return valid ? (double)hidden / (double)valid : 0.0;
}

/* A table from (leaf, weight) pairs, leaves repeated: sums them by leaf, keeps
 * the IRIS_LIGHT_SELECT_SLOTS heaviest and writes their CDF into s; returns
 * the slots used (0 when nothing weighs). Reorders sums. */
static uint32_t write_table(leaf_energy *sums, uint32_t n, iris_light_select_slot *s) {
  qsort(sums, n, sizeof *sums, by_leaf);
  uint32_t leaves = 0;
  for (uint32_t j = 0; j < n; ++j) {
    if (leaves > 0 && sums[leaves - 1].leaf == sums[j].leaf) sums[leaves - 1].energy += sums[j].energy;
    else sums[leaves++] = sums[j];
  }
  qsort(sums, leaves, sizeof *sums, by_energy);
  uint32_t used = leaves < IRIS_LIGHT_SELECT_SLOTS ? leaves : IRIS_LIGHT_SELECT_SLOTS;
  double total = 0.0, acc = 0.0;
  for (uint32_t j = 0; j < used; ++j) total += sums[j].energy;
  if (!(total > 0.0)) return 0;
  for (uint32_t j = 0; j < used; ++j) {
    acc += sums[j].energy;
    s[j].leaf = sums[j].leaf;
    s[j].cdf = j + 1 == used ? 1.0f : (float)(acc / total);
  }
  return used;
}

static void learn_caches(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  build_ctx *c = ctx;
  iris_light_select *sel = c->sel;
  uint32_t *ids = c->ids[thread_index];
  float *d2 = c->d2[thread_index];
  leaf_energy *sums = c->sums[thread_index];
  for (uint64_t i = begin; i < end; ++i) {
    if (iris_cancel_requested()) return;
    const iris_cache *cache = &sel->g->caches[i];
    accept_ctx a = {c->dp, cache->frame.n, cache->sphere != 0};
    uint32_t n = iris_kdtree_knn_if(&c->tree, cache->p, c->k, c->max_d2, accept_photon, &a, ids, d2);
    for (uint32_t j = 0; j < n; ++j) {
      sums[j].leaf = c->dp[ids[j]].leaf;
      sums[j].energy = c->dp[ids[j]].energy;
    }
    uint32_t used = write_table(sums, n, &sel->slots[i * IRIS_LIGHT_SELECT_SLOTS]);
    if (n < IRIS_LIGHT_SELECT_MIN_PHOTONS) used = 0;
    sel->photon_count[i] = (uint8_t)used;
    /* Where the tree's choice is rarely hidden, the table has nothing to add
     * (and its noise to lose): the tree alone. */
    if (used && hidden_share(c, cache, i) < IRIS_LIGHT_SELECT_HIDDEN_MIN) used = 0;
    sel->count[i] = (uint8_t)used;
  }
}

size_t iris_light_select_bytes(size_t caches) {
  return caches * (1 + IRIS_LIGHT_SELECT_SLOTS * sizeof(iris_light_select_slot));
}

iris_status iris_light_select_build(iris_light_select *sel, const iris_guiding *g, const iris_lights *lights,
                                    const iris_photon_map *photons, int k, uint64_t seed, int threads,
                                    iris_error *err) {
  memset(sel, 0, sizeof *sel);
  sel->beta = IRIS_LIGHT_SELECT_BETA;
  if (!lights->tree || g->cache_count == 0 || k <= 0) return IRIS_OK;
  const iris_light_tree *t = lights->tree;
  size_t nd = 0;
  for (size_t i = 0; i < photons->count; ++i) {
    const iris_photon *ph = &photons->photons[i];
    nd += ph->bounce == 0 && iris_light_select_leaf_of(t, ph->light) != UINT32_MAX;
  }
  if (nd == 0 || nd > UINT32_MAX) return IRIS_OK;
  build_ctx c;
  memset(&c, 0, sizeof c);
  c.sel = sel;
  c.lights = lights;
  c.seed = seed;
  c.k = (uint32_t)k;
  /* pick_radius2 is (3 x the caches' spacing)^2 (guiding.c) */
  c.max_d2 = IRIS_LIGHT_SELECT_RADIUS * IRIS_LIGHT_SELECT_RADIUS * g->pick_radius2 / 9.0f;
  direct_photon *dp = malloc(sizeof *dp * nd);
  sel->count = calloc(g->cache_count, 1);
  sel->photon_count = calloc(g->cache_count, 1);
  sel->slots = calloc(g->cache_count * IRIS_LIGHT_SELECT_SLOTS, sizeof *sel->slots);
  if (threads <= 0) threads = iris_parallel_default_threads();
  c.ids = calloc((size_t)threads, sizeof *c.ids);
  c.d2 = calloc((size_t)threads, sizeof *c.d2);
  c.sums = calloc((size_t)threads, sizeof *c.sums);
  bool ok = dp && sel->count && sel->photon_count && sel->slots && c.ids && c.d2 && c.sums;
  for (int i = 0; ok && i < threads; ++i) {
    c.ids[i] = malloc(sizeof(uint32_t) * (size_t)k);
    c.d2[i] = malloc(sizeof(float) * (size_t)k);
    c.sums[i] = malloc(sizeof(leaf_energy) * (size_t)k);
    ok = c.ids[i] && c.d2[i] && c.sums[i];
  }
  iris_status st = ok ? IRIS_OK
                      : iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding",
                                       "out of memory for the learned light selection");
  if (st == IRIS_OK) {
    size_t at = 0;
    for (size_t i = 0; i < photons->count; ++i) {
      const iris_photon *ph = &photons->photons[i];
      const uint32_t leaf = ph->bounce == 0 ? iris_light_select_leaf_of(t, ph->light) : UINT32_MAX;
      if (leaf == UINT32_MAX) continue;
      dp[at++] = (direct_photon){ph->p, ph->n, ph->wi, ph->energy, leaf};
    }
    c.dp = dp;
    st = iris_kdtree_build_threads(&c.tree, &dp[0].p, sizeof *dp, (uint32_t)nd, threads, err);
  }
  if (st == IRIS_OK) {
    sel->g = g;
    sel->tree = t;
    sel->cache_count = g->cache_count;
    sel->direct_photons = nd;
    iris_parallel_for(g->cache_count, 64, threads, learn_caches, &c);
    if (iris_cancel_requested()) st = iris_cancel_error(err);
    for (size_t i = 0; i < g->cache_count; ++i) sel->learned_caches += sel->count[i] > 0;
    mark_near(sel);
  }
  iris_kdtree_destroy(&c.tree);
  for (int i = 0; i < threads; ++i) {
    if (c.ids) free(c.ids[i]);
    if (c.d2) free(c.d2[i]);
    if (c.sums) free(c.sums[i]);
  }
  free(c.ids);
  free(c.d2);
  free(c.sums);
  free(dp);
  if (st != IRIS_OK) iris_light_select_destroy(sel);
  return st;
}

/* sel->near from the tables (after every change of count). */
static void mark_near(iris_light_select *sel) {
  free(sel->near);
  sel->near = NULL;
  const iris_pick_grid *grid = &sel->g->grid;
  if (!grid->n[0] || !grid->id_count || !sel->count) return;
  sel->near = calloc(grid->id_count, 1);
  if (!sel->near) return; /* the caches are read instead */
  for (size_t c = 0; c < grid->cells; ++c) {
    const uint32_t a = grid->answer[c], n = a >> 29, at = a & 0x1fffffffu;
    uint8_t any = 0;
    for (uint32_t i = 0; i < n; ++i) any |= sel->count[grid->ids[at + i]] > 0;
    if (n) sel->near[at] = any;
  }
}

void iris_light_select_destroy(iris_light_select *sel) {
  free(sel->near);
  free(sel->count);
  free(sel->photon_count);
  free(sel->slots);
  float beta = sel->beta;
  memset(sel, 0, sizeof *sel);
  sel->beta = beta;
}

void iris_light_select_nee_add(iris_light_select_nee *slots, uint32_t leaf, float value) {
  uint32_t h = (uint32_t)(iris_mix64(leaf) % IRIS_LIGHT_SELECT_NEE_SLOTS);
  for (uint32_t k = 0; k < IRIS_LIGHT_SELECT_NEE_SLOTS; ++k) {
    iris_light_select_nee *e = &slots[(h + k) % IRIS_LIGHT_SELECT_NEE_SLOTS];
    if (e->leaf1 == 0) e->leaf1 = leaf + 1;
    if (e->leaf1 == leaf + 1) {
      e->sum += (double)value;
      return;
    }
  }
}

void iris_light_select_learn_nee(iris_light_select *sel, const iris_light_select_nee *nee, const uint32_t *tries,
                                 const uint32_t *lit) {
  if (!sel->count || !sel->photon_count) return;
  leaf_energy sums[IRIS_LIGHT_SELECT_SLOTS + IRIS_LIGHT_SELECT_NEE_SLOTS];
  sel->learned_caches = sel->nee_caches = 0;
  for (size_t i = 0; i < sel->cache_count; ++i) {
    iris_light_select_slot *s = &sel->slots[i * IRIS_LIGHT_SELECT_SLOTS];
    const iris_light_select_nee *e = &nee[i * IRIS_LIGHT_SELECT_NEE_SLOTS];
    double total = 0.0;
    for (uint32_t k = 0; k < IRIS_LIGHT_SELECT_NEE_SLOTS; ++k) total += e[k].sum;
    if (tries[i] < IRIS_LIGHT_SELECT_NEE_MIN || !(total > 0.0) || !isfinite(total)) {
      sel->learned_caches += sel->count[i] > 0;
      continue;
    }
    const uint32_t photon = sel->photon_count[i];
    const double lambda = photon ? (double)tries[i] / ((double)tries[i] + IRIS_LIGHT_SELECT_NEE_PRIOR) : 1.0;
    uint32_t n = 0;
    for (uint32_t k = 0; k < photon; ++k)
      sums[n++] = (leaf_energy){s[k].leaf, (1.0 - lambda) * (double)(s[k].cdf - (k ? s[k - 1].cdf : 0.0f))};
    for (uint32_t k = 0; k < IRIS_LIGHT_SELECT_NEE_SLOTS; ++k)
      if (e[k].leaf1 && e[k].sum > 0.0) sums[n++] = (leaf_energy){e[k].leaf1 - 1, lambda * e[k].sum / total};
    uint32_t used = write_table(sums, n, s);
    /* the tree's own light samples at the cache's vertices: how many were hidden */
    const double hidden = 1.0 - (double)lit[i] / (double)tries[i];
    if (hidden < IRIS_LIGHT_SELECT_HIDDEN_MIN) used = 0;
    sel->count[i] = (uint8_t)used;
    sel->learned_caches += used > 0;
    sel->nee_caches += used > 0;
  }
  free(sel->photon_count);
  sel->photon_count = NULL;
  mark_near(sel);
}

bool iris_light_select_attach(iris_light_select *sel, const iris_guiding *g, const iris_lights *lights) {
  const iris_light_tree *t = lights->tree;
  if (!t || sel->cache_count != g->cache_count || !(sel->beta >= 0.0f && sel->beta < 1.0f)) return false;
  for (size_t i = 0; i < sel->cache_count; ++i) {
    const iris_light_select_slot *s = &sel->slots[i * IRIS_LIGHT_SELECT_SLOTS];
    if (sel->count[i] > IRIS_LIGHT_SELECT_SLOTS) return false;
    float prev = 0.0f;
    for (uint32_t k = 0; k < sel->count[i]; ++k) {
      const uint32_t leaf = s[k].leaf;
      if (leaf & IRIS_LIGHT_SELECT_INFINITE) {
        if ((leaf & ~IRIS_LIGHT_SELECT_INFINITE) >= t->infinite_count) return false;
      } else if (leaf >= t->node_count || !(t->nodes[leaf].flags & IRIS_LIGHT_NODE_LEAF)) {
        return false;
      }
      if (!(s[k].cdf >= prev && s[k].cdf <= 1.0f)) return false;
      prev = s[k].cdf;
    }
    if (sel->count[i] && prev != 1.0f) return false;
  }
  sel->g = g;
  sel->tree = t;
  mark_near(sel);
  return true;
}

/* The tied caches at (p, n) that learned something; 0 where the mixture is the tree alone. */
static int learned_caches(const iris_light_select *sel, iris_vec3 p, iris_vec3 n, uint32_t ids[IRIS_GUIDING_PICK_K]) {
  if (!sel->count || (n.x == 0.0f && n.y == 0.0f && n.z == 0.0f)) return 0;
  if (sel->near) { /* the grid cell's caches: none with a table, nothing to read */
    const iris_pick_grid *grid = &sel->g->grid;
    float fx = (p.x - grid->lo[0]) * grid->inv_cell, fy = (p.y - grid->lo[1]) * grid->inv_cell,
          fz = (p.z - grid->lo[2]) * grid->inv_cell;
    if (!(fx >= 0.0f && fy >= 0.0f && fz >= 0.0f)) return 0;
    int ix = (int)fx, iy = (int)fy, iz = (int)fz;
    if (ix >= grid->n[0] || iy >= grid->n[1] || iz >= grid->n[2]) return 0;
    const uint32_t a = grid->answer[((size_t)iz * (size_t)grid->n[1] + (size_t)iy) * (size_t)grid->n[0] + (size_t)ix];
    if ((a >> 29) == 0 || !sel->near[a & 0x1fffffffu]) return 0;
  }
  uint32_t all[IRIS_GUIDING_PICK_K];
  int m = iris_guiding_pick(sel->g, p, n, all), kept = 0;
  for (int j = 0; j < m; ++j)
    if (sel->count[all[j]]) ids[kept++] = all[j];
  return kept;
}

/* The learned probability of leaf `leaf` at cache c. */
static float slot_probability(const iris_light_select *sel, uint32_t c, uint32_t leaf) {
  const iris_light_select_slot *s = &sel->slots[(size_t)c * IRIS_LIGHT_SELECT_SLOTS];
  for (uint32_t j = 0; j < sel->count[c]; ++j)
    if (s[j].leaf == leaf) return s[j].cdf - (j ? s[j - 1].cdf : 0.0f);
  return 0.0f;
}

/* THE probability of `light` at a point whose tied caches are ids[0..m) and
 * whose tree probability is tree_pmf: the sampler and the pmf both end here. */
static float mixture_pmf(const iris_light_select *sel, const uint32_t *ids, int m, uint32_t light, float tree_pmf) {
  if (m == 0) return tree_pmf;
  float learned = 0.0f;
  uint32_t leaf = iris_light_select_leaf_of(sel->tree, light);
  if (leaf != UINT32_MAX) {
    for (int j = 0; j < m; ++j) learned += slot_probability(sel, ids[j], leaf);
    learned /= (float)m;
    if (!(leaf & IRIS_LIGHT_SELECT_INFINITE)) learned *= sel->tree->pmf_in_leaf[light]; /* an infinite light is its slot */
  }
  return (1.0f - sel->beta) * tree_pmf + sel->beta * learned;
}

bool iris_light_select_choose(const iris_light_select *sel, iris_vec3 p, iris_vec3 n, float u, uint32_t *light,
                              float *pmf) {
  uint32_t ids[IRIS_GUIDING_PICK_K];
  int m = learned_caches(sel, p, n, ids);
  *light = 0;
  *pmf = 0.0f;
  double v = u;
  if (m > 0 && v < (double)sel->beta) {
    v = v / (double)sel->beta * (double)m;
    int j = (int)v;
    if (j >= m) j = m - 1;
    v -= (double)j;
    const iris_light_select_slot *s = &sel->slots[(size_t)ids[j] * IRIS_LIGHT_SELECT_SLOTS];
    uint32_t used = sel->count[ids[j]], k = 0;
    while (k + 1 < used && !(v < (double)s[k].cdf)) k++;
    double lo = k ? (double)s[k - 1].cdf : 0.0, width = (double)s[k].cdf - lo;
    v = width > 0.0 ? (v - lo) / width : 0.0;
    if (!(v < 1.0)) v = 0x1.fffffffffffffp-1;
    if (v < 0.0) v = 0.0;
    *light = slot_light(sel->tree, s[k].leaf, v);
    *pmf = mixture_pmf(sel, ids, m, *light, iris_light_tree_pmf(sel->tree, p, n, *light));
    return *pmf > 0.0f;
  }
  if (m > 0) {
    v = (v - (double)sel->beta) / (1.0 - (double)sel->beta);
    if (!(v < 1.0)) v = 0x1.fffffffffffffp-1;
  }
  float fv = (float)v, tree_pmf;
  if (!(fv < 1.0f)) fv = IRIS_ONE_MINUS_EPSILON;
  /* Where the tree's descent ends in nothing (lights only behind the
   * surface), no light is chosen: its `light` is no sample, and naming it with
   * the mixture's pmf would count that light twice. */
  if (!iris_light_tree_sample(sel->tree, p, n, fv, light, &tree_pmf)) {
    *light = 0;
    return false;
  }
  /* iris_light_tree_sample's pmf is iris_light_tree_pmf's, bit for bit */
  *pmf = mixture_pmf(sel, ids, m, *light, tree_pmf);
  return *pmf > 0.0f;
}

float iris_light_select_pmf(const iris_light_select *sel, iris_vec3 p, iris_vec3 n, uint32_t light) {
  uint32_t ids[IRIS_GUIDING_PICK_K];
  int m = learned_caches(sel, p, n, ids);
  return mixture_pmf(sel, ids, m, light, iris_light_tree_pmf(sel->tree, p, n, light));
}

static bool hook_choose(const void *ctx, const iris_lights *L, iris_vec3 ref, iris_vec3 n, float u, uint32_t *light,
                        float *pmf) {
  (void)L;
  return iris_light_select_choose(ctx, ref, n, u, light, pmf);
}
static float hook_pmf(const void *ctx, const iris_lights *L, iris_vec3 ref, iris_vec3 n, uint32_t light) {
  (void)L;
  return iris_light_select_pmf(ctx, ref, n, light);
}

iris_light_learned iris_light_select_hooks(const iris_light_select *sel) {
  iris_light_learned h = {NULL, NULL, NULL};
  if (sel && sel->count && sel->tree && sel->learned_caches > 0) h = (iris_light_learned){sel, hook_choose, hook_pmf};
  return h;
}
