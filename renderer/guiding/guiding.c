/* Guiding preprocess (thesis 4.2): cache placement and filling, the glints'
 * and the portals' build, the pick grid. The budget and the skip rules are in
 * rules.c, the guided direction sampler in guided_sampler.c, the guide's
 * description and iris_render's provider in provider.c; docs/guiding.md. */
#include "renderer/guiding/guiding.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/cancel.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "renderer/guiding/photons.h"
#include "renderer/guiding/rules.h"
#include "renderer/guiding/train.h"

#define CAMERA_SAMPLE_INDEX 0x63616d6361636865ULL /* streams apart from pixels and photons */
#define MAX_SPECULAR_CHAIN 8
/* Photons whose surface normal differs more than this from the cache's (the
 * other side of a thin wall, the neighbouring wall in a corner) are not
 * splatted: their directions describe another surface's hemisphere. */
#define PHOTON_NORMAL_COS IRIS_GUIDING_PHOTON_NORMAL_COS

iris_guiding_params iris_guiding_params_default(void) {
  iris_guiding_params p;
  memset(&p, 0, sizeof p);
  p.pdf_floor = -1.0f;
  p.alpha_max = -1.0f; /* auto: 0.5 with light sampling, 0.7 without (thesis: 0.9); docs/guiding.md */
  p.cos_min = 0.9f;
  p.splat = IRIS_SPLAT_BILINEAR; /* thesis: nearest; measured in docs/guiding.md */
  p.direct_photons = -1;
  p.adjoint_rr = true;
  p.train_spp = -1;
  p.learn_alpha = true;
  p.train_prior = 200.0f; /* a path sample weighs as much as a photon (k = 200); docs/guiding.md */
  p.train_all_light = false;
  p.pilot_paths = -1;
  p.sky_regions = -1;
  p.sky_probes = -1;
  p.sky_beta = -1.0f;
  p.refine = -1;
  p.lamp_glass = true;
  p.glints = true;
  p.portals = true;
  p.light_samples = true;
  p.light_min = IRIS_GUIDING_LIGHT_MIN;
  return p;
}

/* ---- cache placement ----------------------------------------------------- */

typedef struct camera_ctx {
  const iris_guide_setup *setup;
  int stride, cols, rows;
  iris_guide_seed_point *out; /* rows * cols */
} camera_ctx;

static void camera_rows(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  camera_ctx *c = ctx;
  const iris_guide_setup *s = c->setup;
  for (uint64_t r = begin; r < end; ++r) {
    for (int col = 0; col < c->cols; ++col) {
      iris_guide_seed_point *sp_out = &c->out[r * (uint64_t)c->cols + (uint64_t)col];
      memset(sp_out, 0, sizeof *sp_out);
      float fx = (float)(col * c->stride) + 0.5f * (float)c->stride;
      float fy = (float)((int)r * c->stride) + 0.5f * (float)c->stride;
      iris_sampler rng = iris_sampler_start(s->seed, r * (uint64_t)c->cols + (uint64_t)col, CAMERA_SAMPLE_INDEX);
      iris_ray ray = iris_pinhole_ray(s->camera, fx, fy);
      /* Follow specular chains to the first non-specular hit (thesis 4.2.2). */
      for (int depth = 0; depth <= MAX_SPECULAR_CHAIN; ++depth) {
        iris_sampler_set_bounce(&rng, depth);
        iris_hit hit;
        if (!iris_accel_intersect(s->accel, &ray, &hit)) break;
        iris_interaction si;
        iris_accel_interaction(s->accel, ray.d, &hit, &si);
        iris_shading_point sp;
        iris_integrator_shade(s->integrator, &si, iris_normalize(iris_neg(ray.d)), depth, &sp);
        if (!sp.delta) {
          sp_out->p = si.p;
          sp_out->n = sp.frame.n;
          sp_out->valid = 1;
          sp_out->transmits = (sp.lobes & IRIS_LOBE_TRANSMISSION) ? 1 : 0;
          break;
        }
        iris_direction_sample ds;
        if (!iris_integrator_sample_bsdf(&sp, &rng, &ds)) break;
        ray = iris_spawn_ray(&sp.si, ds.wi);
      }
    }
  }
}

iris_guide_seed_point *iris_guiding_camera_points(const iris_guide_setup *s, int stride, int *cols, int *rows,
                                                  size_t *valid) {
  camera_ctx cc = {s, stride, (s->camera->width + stride - 1) / stride, (s->camera->height + stride - 1) / stride, NULL};
  *cols = cc.cols;
  *rows = cc.rows;
  *valid = 0;
  cc.out = malloc(sizeof(iris_guide_seed_point) * (size_t)cc.cols * (size_t)cc.rows);
  if (!cc.out) return NULL;
  iris_parallel_for((uint64_t)cc.rows, 1, s->threads, camera_rows, &cc);
  for (size_t i = 0; i < (size_t)cc.cols * (size_t)cc.rows; ++i) *valid += cc.out[i].valid;
  return cc.out;
}

/* ---- filling -------------------------------------------------------------- */

/* Photon normal groups: the photon tree is a forest with one tree per cell of
 * an octahedral grid over the photons' normals, and a cache searches only the
 * groups whose normals can pass its filter, so it no longer wades through the
 * photons of the surfaces around it (the door: 17 of 18 photons within a
 * cache's k-th distance had the wrong normal). Each group's cone (axis, widest
 * angle of its photons, from the data) decides conservatively; the filter
 * still decides each photon, so the answer is the same as searching all. */
#define NORMAL_GRID 6
#define NORMAL_GROUPS (NORMAL_GRID * NORMAL_GRID + 1) /* the last: normals not unit, always searched */

static uint32_t normal_group(iris_vec3 n) {
  float l1 = fabsf(n.x) + fabsf(n.y) + fabsf(n.z), l2 = iris_dot(n, n);
  if (!(fabsf(l2 - 1.0f) <= 1e-4f) || !(l1 > 0.0f)) return NORMAL_GROUPS - 1;
  float u = n.x / l1, v = n.y / l1;
  if (n.z < 0.0f) {
    float fu = (1.0f - fabsf(v)) * (u >= 0.0f ? 1.0f : -1.0f), fv = (1.0f - fabsf(u)) * (v >= 0.0f ? 1.0f : -1.0f);
    u = fu;
    v = fv;
  }
  int iu = (int)((u * 0.5f + 0.5f) * NORMAL_GRID), iv = (int)((v * 0.5f + 0.5f) * NORMAL_GRID);
  iu = iu < 0 ? 0 : (iu >= NORMAL_GRID ? NORMAL_GRID - 1 : iu);
  iv = iv < 0 ? 0 : (iv >= NORMAL_GRID ? NORMAL_GRID - 1 : iv);
  return (uint32_t)(iv * NORMAL_GRID + iu);
}

typedef struct normal_cone {
  double axis[3]; /* the cell's centre direction */
  double min_dot; /* a cache normal with dot(n, axis) below this cannot use the group's photons */
  uint32_t count;
} normal_cone;

#define GROUP_EXCLUDED UINT32_MAX /* direct photons with light sampling: not in the tree */
#define GROUP_CHUNK 16384u

typedef struct group_ctx {
  const iris_photon *ph;
  size_t count;
  bool direct;       /* keep bounce-0 photons */
  uint32_t *group;   /* per photon */
  double (*cmin)[NORMAL_GROUPS]; /* per chunk: min over its photons of cos(photon n, axis) */
  uint32_t (*n)[NORMAL_GROUPS];  /* per chunk: photons per group */
  const normal_cone *cones;
} group_ctx;

/* Groups and per-chunk cone data (a minimum and a count: the same for any
 * split into threads). */
static void group_chunks(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  group_ctx *c = ctx;
  for (uint64_t ch = begin; ch < end; ++ch) {
    double *cmin = c->cmin[ch];
    uint32_t *n = c->n[ch];
    for (int g = 0; g < NORMAL_GROUPS; ++g) cmin[g] = 1.0, n[g] = 0;
    size_t lo = ch * GROUP_CHUNK, hi = lo + GROUP_CHUNK < c->count ? lo + GROUP_CHUNK : c->count;
    for (size_t i = lo; i < hi; ++i) {
      const iris_photon *ph = &c->ph[i];
      if (!c->direct && ph->bounce == 0) {
        c->group[i] = GROUP_EXCLUDED;
        continue;
      }
      uint32_t g = normal_group(ph->n);
      c->group[i] = g;
      n[g]++;
      const double *ax = c->cones[g].axis;
      double nx = ph->n.x, ny = ph->n.y, nz = ph->n.z, nl = sqrt(nx * nx + ny * ny + nz * nz);
      double d = nl > 0.0 ? (nx * ax[0] + ny * ax[1] + nz * ax[2]) / nl : -1.0;
      cmin[g] = d < cmin[g] ? d : cmin[g];
    }
  }
}

/* Assigns photons to groups (GROUP_EXCLUDED: left out) and builds the cones. */
static bool group_photons(const iris_photon *ph, size_t count, bool direct, int threads, uint32_t *group,
                          normal_cone *cones) {
  memset(cones, 0, sizeof(normal_cone) * NORMAL_GROUPS);
  for (int g = 0; g < NORMAL_GROUPS - 1; ++g) { /* the cell centre's direction */
    double u = ((g % NORMAL_GRID) + 0.5) / NORMAL_GRID * 2.0 - 1.0, v = ((g / NORMAL_GRID) + 0.5) / NORMAL_GRID * 2.0 - 1.0;
    double z = 1.0 - fabs(u) - fabs(v), x = u, y = v;
    if (z < 0.0) {
      x = (1.0 - fabs(v)) * (u >= 0.0 ? 1.0 : -1.0);
      y = (1.0 - fabs(u)) * (v >= 0.0 ? 1.0 : -1.0);
    }
    double l = sqrt(x * x + y * y + z * z);
    cones[g].axis[0] = x / l, cones[g].axis[1] = y / l, cones[g].axis[2] = z / l;
  }
  size_t chunks = (count + GROUP_CHUNK - 1) / GROUP_CHUNK;
  group_ctx c = {ph, count, direct, group, malloc(sizeof(double[NORMAL_GROUPS]) * (chunks ? chunks : 1)),
                 malloc(sizeof(uint32_t[NORMAL_GROUPS]) * (chunks ? chunks : 1)), cones};
  if (!c.cmin || !c.n) {
    free(c.cmin);
    free(c.n);
    return false;
  }
  iris_parallel_for(chunks, 1, threads, group_chunks, &c);
  double cmin[NORMAL_GROUPS];
  for (int g = 0; g < NORMAL_GROUPS; ++g) cmin[g] = 1.0;
  for (size_t ch = 0; ch < chunks; ++ch)
    for (int g = 0; g < NORMAL_GROUPS; ++g) {
      cones[g].count += c.n[ch][g];
      cmin[g] = c.cmin[ch][g] < cmin[g] ? c.cmin[ch][g] : cmin[g];
    }
  free(c.cmin);
  free(c.n);
  /* Usable: angle(cache n, photon n) <= acos(PHOTON_NORMAL_COS); so the cache
   * normal lies within that + the group's widest angle (+ 1e-3 rad for float
   * rounding and normals a hair off unit length) of the axis. */
  const double pi = 3.14159265358979323846;
  for (int g = 0; g < NORMAL_GROUPS; ++g) {
    double reach = acos((double)PHOTON_NORMAL_COS) + acos(fmax(-1.0, fmin(1.0, cmin[g]))) + 1e-3;
    cones[g].min_dot = g == NORMAL_GROUPS - 1 || reach >= pi ? -INFINITY : cos(reach);
  }
  return true;
}

/* The groups a cache with normal n searches, best aligned first; how many. */
static uint32_t select_groups(const normal_cone *cones, iris_vec3 n, uint32_t *out) {
  double nx = n.x, ny = n.y, nz = n.z, nl = sqrt(nx * nx + ny * ny + nz * nz);
  bool all = !(fabs(nl - 1.0) <= 1e-4); /* a normal off unit length: its filter is not the cone's */
  double key[NORMAL_GROUPS];
  uint32_t m = 0;
  for (uint32_t g = 0; g < NORMAL_GROUPS; ++g) {
    const normal_cone *c = &cones[g];
    if (!c->count) continue;
    double d = (nx * c->axis[0] + ny * c->axis[1] + nz * c->axis[2]) / nl;
    if (!all && !(d >= c->min_dot)) continue;
    uint32_t j = m++;
    while (j > 0 && key[j - 1] < d) {
      key[j] = key[j - 1];
      out[j] = out[j - 1];
      --j;
    }
    key[j] = d;
    out[j] = g;
  }
  return m;
}

typedef struct fill_ctx {
  iris_guiding *g;
  const iris_lights *lights;
  const iris_photon_map *photons;
  const iris_kdtree *photon_tree;
  const normal_cone *cones; /* NORMAL_GROUPS */
  uint32_t k;
  float **hist;     /* per thread, sphere-map sized */
  uint32_t **ids;   /* per thread, 2 * k: ids, then tree slots */
  float **d2;       /* per thread, k */
  float **fine;     /* per thread, sphere-map sized: fine histogram (refine.h), squares, probabilities (double) */
  float *cluster;   /* per cache, PORTAL_CLUSTER_FLOATS: the indirect light's cone (indirect_cluster) */
  struct cluster_photon **cph; /* per thread, k: the cache's indirect photons for it */
} fill_ctx;

/* The photons a cache can use: on a surface facing like the cache's (not the
 * other side of a thin wall, not the neighbouring wall of a corner) and, for
 * hemisphere caches, arriving from above. The k nearest are searched among
 * these only, so a cache next to a brightly lit thin wall still gets k. */
typedef struct photon_filter {
  iris_vec3 n;
  bool sphere;
} photon_filter;

/* What the filter and the splatting read of a photon, kept in the photon
 * tree's order next to its position (iris_kdtree_set_payload), so neither
 * chases the photon array: its n, wi and energy, adjacent in iris_photon. */
typedef struct photon_dirs {
  iris_vec3 n, wi;
  float energy;
} photon_dirs;

static bool photon_usable(void *ctx, const void *payload) {
  const photon_filter *f = ctx;
  photon_dirs ph;
  memcpy(&ph, payload, sizeof ph);
  if (iris_dot(ph.n, f->n) < PHOTON_NORMAL_COS) return false;
  return f->sphere || iris_dot(ph.wi, f->n) > 0.0f;
}

/* A cache's photon energy that came straight through glass from each lamp
 * (emitter group; "Lamps behind glass"), in the order the groups were met. */
typedef struct lamp_sums {
  bool on;
  uint32_t n;
  uint32_t group[IRIS_GUIDING_LAMP_GROUPS];
  double energy[IRIS_GUIDING_LAMP_GROUPS];
} lamp_sums;

static void lamp_add(lamp_sums *l, const iris_guiding *g, uint32_t group, float energy) {
  if (group >= g->lamp_count || !(g->lamps[group].radius > 0.0f)) return; /* no sphere to aim at */
  uint32_t i = 0;
  while (i < l->n && l->group[i] != group) ++i;
  if (i == l->n) l->group[l->n++] = group, l->energy[i] = 0.0;
  l->energy[i] += energy;
}

/* The brightest IRIS_CACHE_LAMPS groups' shares of the cache's photon
 * energy (ties to the lower group: the same for any photon order). */
static void lamp_shares(const lamp_sums *l, double power, iris_cache *cache) {
  bool taken[IRIS_GUIDING_LAMP_GROUPS] = {false};
  for (int k = 0; k < IRIS_CACHE_LAMPS; ++k) {
    cache->lamp_share[k] = 0.0f;
    cache->lamp[k] = 0;
    int best = -1;
    for (uint32_t i = 0; i < l->n; ++i) {
      if (taken[i]) continue;
      if (best < 0 || l->energy[i] > l->energy[best] ||
          (l->energy[i] == l->energy[best] && l->group[i] < l->group[best]))
        best = (int)i;
    }
    if (best < 0 || !(power > 0.0)) continue;
    taken[best] = true;
    cache->lamp_share[k] = (float)(l->energy[best] / power);
    cache->lamp[k] = (uint8_t)l->group[best];
  }
}

/* ---- the indirect light's cone (portals) ----------------------------------- */

#define PORTAL_CLUSTER_FLOATS 5 /* axis x, y, z, cos of the cone, share of the indirect energy */
#define PORTAL_CLUSTER_COS 0.82f /* photons within ~35 degrees of the axis make the cluster */
#define PORTAL_CLUSTER_Q 0.9f    /* the cone holds this much of the cluster's energy */
#define PORTAL_MIN_WEIGHT 0.3f   /* a cluster with less of the indirect energy looks for no portal */
#define PORTAL_MIN_PHOTONS 16    /* ... nor one of fewer indirect photons */

typedef struct cluster_photon {
  iris_vec3 wi;
  float energy;
} cluster_photon;

/* The dominant direction of a cache's indirect photons (those a light
 * sample cannot stand in for): the energy-weighted mean of those within
 * PORTAL_CLUSTER_COS of the previous mean, three times from the mean of all;
 * the cone around it holding PORTAL_CLUSTER_Q of their energy (bisection on
 * the cosine); out = {axis, cos, share of all indirect energy}, share 0 when
 * there is no such cluster. */
static void indirect_cluster(const cluster_photon *ph, uint32_t n, float out[PORTAL_CLUSTER_FLOATS]) {
  memset(out, 0, sizeof(float) * PORTAL_CLUSTER_FLOATS);
  if (n < PORTAL_MIN_PHOTONS) return;
  double ax = 0.0, ay = 0.0, az = 0.0, total = 0.0;
  for (uint32_t j = 0; j < n; ++j) {
    ax += ph[j].energy * ph[j].wi.x, ay += ph[j].energy * ph[j].wi.y, az += ph[j].energy * ph[j].wi.z;
    total += ph[j].energy;
  }
  if (!(total > 0.0)) return;
  iris_vec3 axis = iris_v3((float)ax, (float)ay, (float)az);
  double in = 0.0;
  for (int it = 0; it < 3; ++it) {
    if (!(iris_dot(axis, axis) > 0.0f)) return;
    axis = iris_normalize(axis);
    ax = ay = az = in = 0.0;
    for (uint32_t j = 0; j < n; ++j)
      if (iris_dot(ph[j].wi, axis) >= PORTAL_CLUSTER_COS) {
        ax += ph[j].energy * ph[j].wi.x, ay += ph[j].energy * ph[j].wi.y, az += ph[j].energy * ph[j].wi.z;
        in += ph[j].energy;
      }
    if (!(in > 0.0)) return;
    axis = iris_v3((float)ax, (float)ay, (float)az);
  }
  if (!(iris_dot(axis, axis) > 0.0f)) return;
  axis = iris_normalize(axis);
  double cluster = 0.0;
  for (uint32_t j = 0; j < n; ++j)
    if (iris_dot(ph[j].wi, axis) >= PORTAL_CLUSTER_COS) cluster += ph[j].energy;
  if (!(cluster > 0.0)) return;
  float lo = PORTAL_CLUSTER_COS, hi = 1.0f; /* the largest cosine whose cone holds Q */
  for (int it = 0; it < 20; ++it) {
    const float mid = 0.5f * (lo + hi);
    double e = 0.0;
    for (uint32_t j = 0; j < n; ++j)
      if (iris_dot(ph[j].wi, axis) >= mid) e += ph[j].energy;
    if (e >= PORTAL_CLUSTER_Q * cluster) lo = mid;
    else hi = mid;
  }
  out[0] = axis.x, out[1] = axis.y, out[2] = axis.z;
  out[3] = lo;
  out[4] = (float)(cluster / total);
}

static void fill_caches(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  fill_ctx *c = ctx;
  iris_guiding *g = c->g;
  float *hist = c->hist[thread_index];
  uint32_t *ids = c->ids[thread_index];
  float *d2 = c->d2[thread_index];
  for (uint64_t i = begin; i < end; ++i) {
    if (iris_cancel_requested()) return; /* the build notices and stops */
    iris_cache *cache = &g->caches[i];
    const iris_octmap *map = cache->sphere ? &g->sphere : &g->hemi;
    memset(hist, 0, sizeof(float) * map->texel_count);
    float *fine = g->refine_sub ? c->fine[thread_index] : NULL;
    float *sq = fine ? fine + IRIS_REFINE_SUB * g->sphere.texel_count : NULL;
    if (fine) memset(fine, 0, sizeof(float) * (IRIS_REFINE_SUB + 1) * g->sphere.texel_count);
    photon_filter f = {cache->frame.n, cache->sphere != 0};
    lamp_sums lamps;
    lamps.on = g->params.lamp_glass && g->lamp_count > 0;
    lamps.n = 0;
    uint32_t *slots = ids + c->k;
    uint32_t groups[NORMAL_GROUPS];
    uint32_t ng = select_groups(c->cones, cache->frame.n, groups);
    uint32_t n = iris_kdtree_knn_groups_payload_if(c->photon_tree, cache->p, c->k, INFINITY, groups, ng,
                                                   photon_usable, &f, ids, d2, slots);
    uint32_t used = 0, clustered = 0;
    cluster_photon *cph = c->cluster ? c->cph[thread_index] : NULL;
    double power = 0.0, through = 0.0, paned = 0.0, pane[4] = {0, 0, 0, 0}, indirect = 0.0, glinted = 0.0;
    for (uint32_t j = 0; j < n; ++j) {
      photon_dirs ph;
      memcpy(&ph, c->photon_tree->payload + (size_t)slots[j] * sizeof ph, sizeof ph);
      if (iris_dot(ph.n, cache->frame.n) < PHOTON_NORMAL_COS) continue;
      iris_vec3 wl = iris_frame_to_local(&cache->frame, ph.wi);
      bool u = iris_cache_splat(map, hist, wl, ph.energy, g->params.splat);
      if (u && fine) iris_refine_splat(map, fine, sq, wl, ph.energy);
      used += u;
      if (u) power += ph.energy;
      if (u && c->photons->photons[ids[j]].sky_through) through += ph.energy;
      if (u && c->photons->photons[ids[j]].pane[3] > 0.0f) {
        paned += ph.energy;
        for (int k = 0; k < 4; ++k) pane[k] += ph.energy * c->photons->photons[ids[j]].pane[k];
      }
      if (u && c->photons->photons[ids[j]].bounce > 0) {
        indirect += ph.energy;
        if (cph) cph[clustered++] = (cluster_photon){ph.wi, ph.energy};
      }
      if (u && c->photons->photons[ids[j]].glint) glinted += ph.energy;
      if (u && lamps.on && c->photons->photons[ids[j]].lamp_through)
        lamp_add(&lamps, g, c->lights->entries[c->photons->photons[ids[j]].light].group, ph.energy);
    }
    cache->photons = used;
    if (cph) indirect_cluster(cph, cache->sphere ? 0 : clustered, c->cluster + i * PORTAL_CLUSTER_FLOATS);
    cache->sky_through = g->env && power > 0.0 ? (float)(through / power) : 0.0f;
    cache->pane_share = 0.0f;
    /* the glints' share of the light the guide must find (light sampling finds
     * the direct part); build_glints keeps it where a spot is found */
    cache->glint_share = indirect > 0.0 ? (float)(glinted / indirect) : 0.0f;
    memset(cache->pane, 0, sizeof cache->pane);
    const double pn = sqrt(pane[0] * pane[0] + pane[1] * pane[1] + pane[2] * pane[2]);
    if (g->env && power > 0.0 && paned > 0.0 && pn > 0.5 * paned) { /* one plane's photons, not opposed ones */
      cache->pane_share = (float)(paned / power);
      for (int k = 0; k < 3; ++k) cache->pane[k] = (float)(pane[k] / pn);
      cache->pane[3] = (float)(pane[3] / paned);
    }
    lamp_shares(&lamps, power, cache);
    /* Photon density estimate (thesis 4.2.1's energies, absolute): irradiance =
     * sum of powers / (paths * pi r_k^2); radiance of a white diffuse surface =
     * irradiance / pi. The photons cover the disc to the k-th nearest. */
    cache->radiance = n > 0 && d2[n - 1] > 0.0f
                          ? (float)(power / ((double)c->photons->paths * 3.14159265358979 *
                                             3.14159265358979 * (double)d2[n - 1]))
                          : 0.0f;
    if (!used || !iris_cache_build_tables(map, hist, g->params.pdf_floor, g->pdf + cache->table,
                                          g->alias + cache->table))
      cache->photons = 0;
    if (fine && cache->photons) { /* split the texels where the light is concentrated */
      double *prob = (double *)(sq + g->sphere.texel_count), sum = 0.0;
      for (uint32_t t = 0; t < map->texel_count; ++t) sum += hist[t] > 0.0f ? hist[t] : 0.0f;
      for (uint32_t t = 0; t < map->texel_count; ++t) prob[t] = (hist[t] > 0.0f ? hist[t] : 0.0f) / sum;
      iris_refine_build(map, prob, fine, sq, g->params.refine, IRIS_REFINE_MIX, g->refine_slot + cache->table,
                        iris_guiding_sub(g, cache));
    } else if (g->refine_slot) {
      memset(g->refine_slot + cache->table, 0, map->texel_count);
    }
    if (g->photon_hist && cache->photons) { /* kept for training: normalised */
      double sum = 0.0;
      for (uint32_t t = 0; t < map->texel_count; ++t) sum += hist[t];
      for (uint32_t t = 0; t < map->texel_count; ++t)
        g->photon_hist[cache->table + t] = (float)(hist[t] / sum);
    }
  }
}

/* ---- glints ---------------------------------------------------------------- */

/* Glint photon paths traced when photons met smooth surfaces ("Glints"). */
#define GLINT_PATHS 65536u
#define GLINT_DENSITY_SAMPLES 4096u
#define GLINT_REACH 2.0f

static int by_float(const void *a, const void *b) {
  const float x = *(const float *)a, y = *(const float *)b;
  return x < y ? -1 : x > y;
}

/* Traces the glint photons and gives every cache where a spot is found its
 * share: the share of its indirect photon energy that its photons say came
 * off smooth reflectors, at most IRIS_GLINT_SHARE_MAX; none below
 * IRIS_GLINT_SHARE_MIN, where the spot's query would cost more than the
 * glints it finds bring. */
static iris_status build_glints(iris_guiding *g, const iris_guide_setup *s, const iris_photon_map *photons,
                                float spacing, iris_error *err) {
  /* no cache whose photons would give a spot its share: nothing to trace */
  bool wanted = false;
  for (size_t i = 0; i < g->cache_count && !wanted; ++i) wanted = g->caches[i].glint_share >= IRIS_GLINT_SHARE_MIN;
  iris_status st = g->params.glints && wanted ? iris_glints_trace(s, photons, GLINT_PATHS, &g->glints, err) : IRIS_OK;
  if (st != IRIS_OK || g->glints.count == 0) { /* no spot anywhere */
    for (size_t i = 0; i < g->cache_count; ++i) g->caches[i].glint_share = 0.0f;
    return st;
  }
  /* A vertex looks GLINT_REACH times as far as the median distance to the
   * IRIS_GLINT_K-th nearest glint photon among themselves (a sample of them),
   * at most the caches' spacing: wide where they are sparse, no wider. */
  const uint32_t samples = g->glints.count < GLINT_DENSITY_SAMPLES ? g->glints.count : GLINT_DENSITY_SAMPLES;
  float *dk = malloc(sizeof(float) * samples);
  if (!dk) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for glint photons");
  for (uint32_t j = 0; j < samples; ++j) {
    uint32_t ids[IRIS_GLINT_K + 1];
    float d2[IRIS_GLINT_K + 1];
    const iris_vec3 q = g->glints.photons[(uint64_t)j * g->glints.count / samples].p;
    const uint32_t n = iris_kdtree_knn(&g->glints.tree, q, IRIS_GLINT_K + 1, INFINITY, ids, d2);
    dk[j] = n ? d2[n - 1] : 0.0f;
  }
  qsort(dk, samples, sizeof *dk, by_float);
  const float median2 = dk[samples / 2];
  free(dk);
  g->glints.radius2 = fminf(GLINT_REACH * GLINT_REACH * median2, spacing * spacing);
  for (size_t i = 0; i < g->cache_count; ++i) {
    iris_cache *c = &g->caches[i];
    float taken = c->sky_through + c->pane_share;
    for (int k = 0; k < IRIS_CACHE_LAMPS; ++k) taken += c->lamp_share[k];
    iris_guide_lamp spot;
    const float want = fminf(c->glint_share, IRIS_GLINT_SHARE_MAX);
    c->glint_share = want >= IRIS_GLINT_SHARE_MIN && iris_glints_spot(&g->glints, c->p, c->frame.n, &spot)
                         ? fmaxf(0.0f, fminf(want, 1.0f - taken))
                         : 0.0f;
  }
  return IRIS_OK;
}

/* ---- portals ---------------------------------------------------------------- */

#define PORTAL_STREAM 0x706f7274616cULL /* "portal": the probes' hash stream */

typedef struct portal_ctx {
  iris_guiding *g;
  const iris_accel *accel;
  const float *cluster;
  uint64_t seed;
} portal_ctx;

/* The light leaving a surface point, by the caches Algorithm 1 picks there:
 * their radiance estimate (the indirect part where light sampling takes the
 * direct, which the comparison of two sides of an opening tolerates); 0 where
 * none serves. */
static float brightness(void *ctx, iris_vec3 p, iris_vec3 n) {
  const iris_guiding *g = ctx;
  uint32_t ids[IRIS_GUIDING_PICK_K];
  int m = iris_guiding_pick(g, p, n, ids);
  float r = 0.0f;
  for (int i = 0; i < m; ++i) r += g->caches[ids[i]].radiance;
  return m > 0 ? r / (float)m : 0.0f;
}

static void find_portals(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  const portal_ctx *c = ctx;
  for (uint64_t i = begin; i < end; ++i) {
    if (iris_cancel_requested()) return;
    iris_cache *cache = &c->g->caches[i];
    const float *k = c->cluster + i * PORTAL_CLUSTER_FLOATS;
    if (!(k[4] >= PORTAL_MIN_WEIGHT)) continue;
    if (iris_portal_find(c->accel, cache->p, cache->frame.n, iris_v3(k[0], k[1], k[2]), k[3],
                         iris_hash4(c->seed, PORTAL_STREAM, i, 0), brightness, c->g, &cache->portal))
      cache->portal_weight = k[4];
  }
}

/* At most this many joined openings (each cache's rectangle is compared
 * with each: the work stays linear in the caches). */
#define PORTAL_JOINED_MAX 64
#define PORTAL_EXTEND_TRIED 4  /* ... among this many (64 probes each): linear work in the caches */

typedef struct joined_portal {
  iris_portal p;
  iris_vec3 side; /* the first finder's position: the side it is seen from */
} joined_portal;

typedef struct extend_ctx {
  iris_guiding *g;
  const iris_accel *accel;
  uint64_t seed;
  const joined_portal *joined;
  int count;
} extend_ctx;

typedef struct share_ctx {
  const iris_guiding *g;
  uint32_t id;
} share_ctx;

static float cache_density(void *ctx, iris_vec3 wi) {
  const share_ctx *c = ctx;
  return iris_guiding_cache_pdf(c->g, &c->id, 1, wi);
}

/* A cache that found no portal of its own takes, as a candidate, the
 * joined one through which the most of its incident light came (its map's
 * share through it, iris_portal_share, the portal's weight), if any came
 * through it and at least half the probes reach the opening; of the wholes
 * facing it, the PORTAL_EXTEND_TRIED largest in its view are tried. Training
 * decides which portals stay (train.c): the map's share is no measure of
 * what the portal's samples are worth, the light through an opening being
 * the part whose paths vary most (the door: 98% of the second moment), and
 * a cache that sees the opening at a grazing angle has a small share of it
 * in its coarse texels (docs/guiding.md). */
static void extend_portals(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  const extend_ctx *c = ctx;
  for (uint64_t i = begin; i < end; ++i) {
    if (iris_cancel_requested()) return;
    iris_cache *cache = &c->g->caches[i];
    if (cache->portal_weight > 0.0f) continue;
    /* the PORTAL_EXTEND_TRIED wholes that face it and look largest from it
     * (area |cos| / distance^2 of their centre), ties to the lower index */
    int tried[PORTAL_EXTEND_TRIED], n_tried = 0;
    float size[PORTAL_EXTEND_TRIED];
    for (int j = 0; j < c->count; ++j) {
      const joined_portal *jp = &c->joined[j];
      if (!iris_portal_present(&jp->p) || !iris_portal_faces(&jp->p, jp->side, cache->p, cache->frame.n)) continue;
      const iris_vec3 to = iris_sub(jp->p.o, cache->p), nrm = iris_cross(jp->p.u, jp->p.v);
      const float d2 = iris_dot(to, to), w = 4.0f * fabsf(iris_dot(to, nrm)) / (d2 * sqrtf(d2));
      int at = n_tried < PORTAL_EXTEND_TRIED ? n_tried++ : PORTAL_EXTEND_TRIED;
      while (at > 0 && size[at - 1] < w) {
        if (at < PORTAL_EXTEND_TRIED) tried[at] = tried[at - 1], size[at] = size[at - 1];
        --at;
      }
      if (at < PORTAL_EXTEND_TRIED) tried[at] = j, size[at] = w;
    }
    share_ctx sc = {c->g, (uint32_t)i};
    float best = 0.0f;
    int best_j = -1;
    for (int t = 0; t < n_tried; ++t) {
      const int j = tried[t];
      const joined_portal *jp = &c->joined[j];
      float reach;
      const float share = iris_portal_share(c->accel, &jp->p, cache->p, cache->frame.n,
                                            iris_hash4(c->seed, PORTAL_STREAM, i, 1 + (uint64_t)j), cache_density, &sc,
                                            &reach);
      if (reach >= 0.5f && share > best) best = share, best_j = j;
    }
    if (best_j >= 0) cache->portal = c->joined[best_j].p, cache->portal_weight = fminf(best, 1.0f);
  }
}

/* The finders' rectangles that lie in one plane and overlap, joined
 * (serially, in cache order: deterministic); every finder takes its whole,
 * and so does every cache that found none but gets enough of its light
 * through a whole one (extend_portals). */
static void join_portals(iris_guiding *g, const iris_guide_setup *s, int threads) {
  const size_t n = g->cache_count;
  iris_portal *parts = malloc(sizeof *parts * (n ? n : 1)), whole[PORTAL_JOINED_MAX];
  iris_vec3 *at = malloc(sizeof *at * 2 * (n ? n : 1)), side[PORTAL_JOINED_MAX];
  uint8_t *group = malloc(n ? n : 1); /* whole of each cache; 0xff: none */
  if (!parts || !at || !group) { /* the finders' own rectangles stay */
    free(parts), free(at), free(group);
    return;
  }
  for (size_t i = 0; i < n; ++i) {
    const iris_cache *cache = &g->caches[i];
    if (cache->portal_weight > 0.0f) parts[i] = cache->portal;
    else memset(&parts[i], 0, sizeof parts[i]);
    at[i] = cache->p, at[n + i] = cache->frame.n;
  }
  const int count = iris_portal_join_all(s->accel, parts, at, at + n, n, whole, side, PORTAL_JOINED_MAX, group);
  joined_portal joined[PORTAL_JOINED_MAX];
  for (int j = 0; j < count; ++j) joined[j] = (joined_portal){whole[j], side[j]};
  for (size_t i = 0; i < n; ++i)
    if (group[i] != 0xff && iris_portal_present(&joined[group[i]].p)) g->caches[i].portal = joined[group[i]].p;
  free(parts), free(at), free(group);
  extend_ctx e = {g, s->accel, s->seed, joined, count};
  if (count > 0) iris_parallel_for(g->cache_count, 16, threads, extend_portals, &e);
}

/* Each cache whose indirect light mostly came from one cone looks into it
 * for an opening (portal.h), then the parts of one opening different caches
 * found are joined (join_portals). Deterministic: probes hashed from (seed,
 * cache). */
static void build_portals(iris_guiding *g, const iris_guide_setup *s, const float *cluster) {
  portal_ctx c = {g, s->accel, cluster, s->seed};
  int threads = s->threads > 0 ? s->threads : iris_parallel_default_threads();
  iris_parallel_for(g->cache_count, 16, threads, find_portals, &c);
  if (!iris_cancel_requested()) join_portals(g, s, threads);
  g->stats.portal_caches = 0;
  for (size_t i = 0; i < g->cache_count; ++i) g->stats.portal_caches += g->caches[i].portal_weight > 0.0f;
}


static int compare_float(const void *a, const void *b) {
  float x = *(const float *)a, y = *(const float *)b;
  return (x > y) - (x < y);
}

/* Search radius of Algorithm 1: caches are local estimates, so a point whose
 * 5 nearest caches are far away (a surface no camera ray or photon cache
 * reached) is better served by BSDF sampling, and bounding the search keeps
 * its cost flat there. Radius = 3x the 90th percentile, over the caches, of
 * the distance to their 5th nearest other cache. */
static float pick_radius2(const iris_guiding *g, float *spacing) {
  size_t n = g->cache_count;
  *spacing = 0.0f;
  if (n <= IRIS_GUIDING_PICK_K) return INFINITY;
  float *d = malloc(sizeof(float) * n);
  if (!d) return INFINITY;
  for (size_t i = 0; i < n; ++i) {
    uint32_t ids[IRIS_GUIDING_PICK_K + 1];
    float d2[IRIS_GUIDING_PICK_K + 1];
    uint32_t m = iris_kdtree_knn(&g->tree, g->caches[i].p, IRIS_GUIDING_PICK_K + 1, INFINITY, ids, d2);
    d[i] = m ? d2[m - 1] : 0.0f;
  }
  qsort(d, n, sizeof(float), compare_float);
  float r2 = 9.0f * d[(size_t)(0.9 * (double)(n - 1))];
  *spacing = sqrtf(d[(n - 1) / 2]); /* median distance to the 5th nearest other cache */
  free(d);
  return r2 > 0.0f ? r2 : INFINITY;
}


/* Enters a phase of the guide's build (core/cancel.h) and reports it. */
void iris_guiding_phase(const iris_guide_setup *s, const char *key, const char *what, double eta_first_image) {
  if (key) iris_phase_begin(key, what);
  if (s->phase) s->phase(s->phase_ctx, what, iris_time_now() - s->t0, eta_first_image);
}

static iris_status build_caches(iris_guiding *g, const iris_guide_setup *s, int stride,
                                iris_error *err) {
  iris_guiding_params *p = &g->params;
  double t0 = iris_time_now();
  iris_guiding_phase(s, "photons", "tracing photons", -1.0);
  /* the camera caches' points, which the pilot checks first (one pass for both) */
  int cols, rows;
  size_t ncam = 0;
  iris_guide_seed_point *points = iris_guiding_camera_points(s, stride, &cols, &rows, &ncam);
  if (!points)
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for %dx%d camera cache points", cols, rows);
  iris_photon_map photons;
  iris_status st = iris_guiding_pilot(g, s, ncam, &photons, err);
  if (st == IRIS_OK && !g->stats.skipped)
    st = iris_photons_trace_more(s, p->photon_lights, (uint64_t)p->photons, &photons, err);
  if (st != IRIS_OK || g->stats.skipped) {
    free(points);
    iris_photons_destroy(&photons);
    return st;
  }
  g->stats.photon_paths = photons.paths;
  g->stats.photons_stored = photons.count;
  g->stats.photons_indirect = photons.indirect;
  double t1 = iris_time_now();
  g->stats.photon_seconds = t1 - t0;
  if (photons.count == 0 && !p->force) {
    free(points);
    iris_photons_destroy(&photons);
    iris_guiding_skip(g, "no photon reached a non-specular surface");
    return IRIS_OK;
  }
  if (iris_guiding_declines(g, s, &photons)) {
    free(points);
    iris_photons_destroy(&photons);
    return IRIS_OK;
  }
  iris_guiding_phase(s, "caches", "building the irradiance caches", -1.0);
  /* Camera caches. */
  if (iris_cancel_requested()) {
    free(points);
    iris_photons_destroy(&photons);
    return iris_cancel_error(err);
  }
  if (ncam == 0 && !p->force) {
    free(points);
    iris_photons_destroy(&photons);
    iris_guiding_skip(g, "every visible surface is a perfect mirror or glass (or nothing is visible)");
    return IRIS_OK;
  }
  size_t nph = (size_t)(p->caches - (int64_t)ncam > 0 ? p->caches - (int64_t)ncam : 0);
  if (nph > photons.count) nph = photons.count;
  size_t total = ncam + nph;
  g->caches = calloc(total ? total : 1, sizeof(iris_cache));
  if (!g->caches) {
    free(points);
    iris_photons_destroy(&photons);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for %zu caches", total);
  }
  size_t at = 0, floats = 0;
  for (size_t i = 0; i < (size_t)cols * (size_t)rows; ++i) {
    if (!points[i].valid) continue;
    iris_cache *c = &g->caches[at++];
    c->p = points[i].p;
    c->frame = iris_frame_from_normal(points[i].n);
    c->sphere = points[i].transmits;
    c->from_camera = 1;
  }
  free(points);
  for (size_t i = 0; i < nph; ++i) { /* the first n photons (thesis 4.2.2) */
    iris_cache *c = &g->caches[at++];
    c->p = photons.photons[i].p;
    c->frame = iris_frame_from_normal(photons.photons[i].n);
    c->sphere = photons.photons[i].transmits;
  }
  for (size_t i = 0; i < total; ++i) {
    g->caches[i].table = (uint32_t)floats;
    floats += g->caches[i].sphere ? g->sphere.texel_count : g->hemi.texel_count;
  }
  g->pdf = malloc(sizeof(float) * (floats ? floats : 1));
  g->alias = malloc(sizeof(iris_cache_alias) * (floats ? floats : 1));
  if (p->refine > 0 && g->pdf && g->alias) {
    g->refine_slot = malloc(floats ? floats : 1);
    g->refine_sub = calloc(IRIS_REFINE_MAX * IRIS_REFINE_SUB * (floats / g->hemi.texel_count + 1), sizeof(float));
    if (!g->refine_slot || !g->refine_sub)
      st = iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for cache tables");
  }
  if (p->train_spp != 0 && g->pdf && g->alias) {
    g->photon_hist = malloc(sizeof(float) * (floats ? floats : 1));
    if (!g->photon_hist) st = iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for cache tables");
  }
  iris_kdtree ptree;
  memset(&ptree, 0, sizeof ptree);
  if (!g->pdf || !g->alias || floats > UINT32_MAX)
    st = iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for cache tables");
  /* With light sampling the direct light needs no guide: photons straight
   * from a light leave the photon tree, so every cache's k photons describe
   * the indirect light (measured in docs/guiding.md). */
  /* A sky seen through openings is the exception: light sampling of the map
   * mostly hits walls, and the direct photons are what teaches the guide
   * where the openings are (docs/guiding.md, "Budget"). */
  const bool direct = p->direct_photons > 0 ||
                      (p->direct_photons < 0 && (!p->use_nee || iris_guiding_environment_share(s->lights) >= 0.5));
  normal_cone cones[NORMAL_GROUPS];
  uint32_t *group = st == IRIS_OK ? malloc(sizeof(uint32_t) * (photons.count ? photons.count : 1)) : NULL;
  if (st == IRIS_OK && (!group || !group_photons(photons.photons, photons.count, direct, s->threads, group, cones)))
    st = iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory grouping %zu photons", photons.count);
  if (st == IRIS_OK) /* photon ids stay indices into the whole photon array */
    st = iris_kdtree_build_grouped(&ptree, &photons.photons[0].p, sizeof(iris_photon), (uint32_t)photons.count,
                                   group, NORMAL_GROUPS, s->threads, err);
  free(group);
  if (st == IRIS_OK && iris_cancel_requested()) st = iris_cancel_error(err);
  _Static_assert(offsetof(iris_photon, wi) == offsetof(iris_photon, n) + sizeof(iris_vec3) &&
                     offsetof(iris_photon, energy) == offsetof(iris_photon, wi) + sizeof(iris_vec3) &&
                     sizeof(photon_dirs) == 2 * sizeof(iris_vec3) + sizeof(float),
                 "photon_dirs mirrors iris_photon's n, wi, energy");
  if (st == IRIS_OK)
    st = iris_kdtree_set_payload(&ptree, &photons.photons[0].n, sizeof(iris_photon), sizeof(photon_dirs), s->threads,
                                 err);
  /* Fill in parallel with per-thread scratch. */
  int threads = s->threads > 0 ? s->threads : iris_parallel_default_threads();
  fill_ctx fc = {g, s->lights, &photons, &ptree, cones, (uint32_t)p->cache_k, NULL, NULL, NULL, NULL, NULL, NULL};
  if (st == IRIS_OK) {
    fc.hist = calloc((size_t)threads, sizeof(float *));
    fc.ids = calloc((size_t)threads, sizeof(uint32_t *));
    fc.d2 = calloc((size_t)threads, sizeof(float *));
    fc.fine = calloc((size_t)threads, sizeof(float *));
    fc.cph = calloc((size_t)threads, sizeof(cluster_photon *));
    if (p->portals && s->accel) fc.cluster = calloc(total * PORTAL_CLUSTER_FLOATS, sizeof(float));
    bool ok = fc.hist && fc.ids && fc.d2 && fc.fine && fc.cph && (fc.cluster || !p->portals || !s->accel);
    for (int t = 0; ok && t < threads; ++t) {
      fc.hist[t] = malloc(sizeof(float) * g->sphere.texel_count);
      fc.ids[t] = malloc(sizeof(uint32_t) * 2 * (size_t)p->cache_k);
      fc.d2[t] = malloc(sizeof(float) * (size_t)p->cache_k);
      if (fc.cluster) fc.cph[t] = malloc(sizeof(cluster_photon) * (size_t)p->cache_k);
      if (g->refine_sub)
        fc.fine[t] = malloc((sizeof(float) * (IRIS_REFINE_SUB + 1) + sizeof(double)) * g->sphere.texel_count);
      ok = fc.hist[t] && fc.ids[t] && fc.d2[t] && (!g->refine_sub || fc.fine[t]);
    }
    if (ok) {
      g->cache_count = total;
      iris_parallel_for(total, 64, threads, fill_caches, &fc);
      if (iris_cancel_requested()) st = iris_cancel_error(err);
    } else {
      st = iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory filling %zu caches", total);
    }
    for (int t = 0; t < threads; ++t) {
      if (fc.hist) free(fc.hist[t]);
      if (fc.ids) free(fc.ids[t]);
      if (fc.d2) free(fc.d2[t]);
      if (fc.fine) free(fc.fine[t]);
      if (fc.cph) free(fc.cph[t]);
    }
    free(fc.hist);
    free(fc.ids);
    free(fc.d2);
    free(fc.fine);
    free(fc.cph);
  }
  if (st == IRIS_OK) {
    /* Keep the caches that received photons; their tables stay where they are. */
    size_t kept = 0;
    for (size_t i = 0; i < total; ++i) {
      g->caches[i].alpha = -1.0f; /* until training learns it */
      g->caches[i].light = 1.0f;  /* ... and where light sampling brings nothing */
      memset(&g->caches[i].portal, 0, sizeof g->caches[i].portal);
      g->caches[i].portal_weight = 0.0f;
      if (g->caches[i].photons) {
        if (fc.cluster) /* the clusters move with their caches */
          memmove(fc.cluster + kept * PORTAL_CLUSTER_FLOATS, fc.cluster + i * PORTAL_CLUSTER_FLOATS,
                  sizeof(float) * PORTAL_CLUSTER_FLOATS);
        g->caches[kept++] = g->caches[i];
      } else {
        g->stats.empty_caches++;
      }
    }
    g->cache_count = kept;
    for (size_t i = 0; i < kept; ++i) g->stats.camera_caches += g->caches[i].from_camera;
    iris_guiding_count_refined(g);
    g->stats.caches = kept;
    if (kept == 0 && !p->force) {
      iris_guiding_skip(g, "no cache received photons");
    } else {
      st = iris_kdtree_build(&g->tree, &g->caches[0].p, sizeof(iris_cache), (uint32_t)kept, err);
      float spacing = 0.0f;
      if (st == IRIS_OK) g->pick_radius2 = pick_radius2(g, &spacing);
      if (st == IRIS_OK)
        st = iris_pick_grid_build(&g->grid, &g->tree, IRIS_GUIDING_PICK_K, g->pick_radius2, spacing,
                                  s->threads, err);
      if (st == IRIS_OK) st = build_glints(g, s, &photons, spacing, err);
      if (st == IRIS_OK && fc.cluster) build_portals(g, s, fc.cluster);
      g->stats.memory_bytes = sizeof(iris_cache) * kept + (sizeof(float) + sizeof(iris_cache_alias)) * floats +
                              (sizeof(float) * 3 + sizeof(uint32_t) + 1) * kept +
                              sizeof(double) * (g->hemi.texel_count + g->sphere.texel_count) +
                              g->grid.memory_bytes +
                              (g->refine_sub ? floats + sizeof(float) * IRIS_REFINE_MAX * IRIS_REFINE_SUB *
                                                            (floats / g->hemi.texel_count + 1)
                                             : 0) +
                              iris_glints_bytes(g->glints.count);
    }
  }
  if (st == IRIS_OK && !g->stats.skipped && s->learn_lights && g->cache_count) {
    st = iris_light_select_build(&g->lights, g, s->lights, &photons, p->cache_k, s->seed, s->threads, err);
    g->stats.memory_bytes += g->lights.count ? iris_light_select_bytes(g->cache_count) : 0;
  }
  g->stats.cache_seconds = iris_time_now() - t1;
  /* Inspection outputs need the photons (counts in the dumps): before freeing them. */
  if (st == IRIS_OK && !g->stats.skipped && p->inspect && (p->dump_dir || p->marks))
    st = p->inspect(g, s, p, &photons, &ptree, err);
  free(fc.cluster);
  iris_kdtree_destroy(&ptree);
  iris_photons_destroy(&photons); /* thesis 4.2.4: photons are not needed any more */
  return st;
}

/* The emitter groups' bounding spheres, which the caches' lamp shares name
 * ("Lamps behind glass"): triangle groups only (a point light cannot be hit). */
static iris_status copy_lamps(iris_guiding *g, const iris_lights *L, iris_error *err) {
  size_t n = L->group_count < IRIS_GUIDING_LAMP_GROUPS ? L->group_count : IRIS_GUIDING_LAMP_GROUPS;
  if (n == 0 || !g->params.lamp_glass) return IRIS_OK;
  g->lamps = calloc(n, sizeof *g->lamps);
  if (!g->lamps) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for lamps");
  g->lamp_count = n;
  for (size_t i = 0; i < n; ++i)
    if (L->groups[i].kind == IRIS_LIGHT_KIND_TRIANGLE && L->groups[i].radius > 0.0f)
      g->lamps[i] = (iris_guide_lamp){L->groups[i].center, L->groups[i].radius};
  return IRIS_OK;
}

iris_status iris_guiding_build(const iris_guide_setup *setup, const iris_guiding_params *params,
                               iris_guiding **out, iris_error *err) {
  iris_status st0;
  *out = NULL;
  double t0 = iris_time_now();
  iris_guiding *g = calloc(1, sizeof *g);
  if (!g) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for the guide");
  g->params = params ? *params : iris_guiding_params_default();
  if (g->params.cache_k > 100000 || g->params.photons > ((int64_t)1 << 32) ||
      g->params.caches > ((int64_t)1 << 26)) {
    free(g);
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, "guiding",
                          "guiding budget too large (photons <= 2^32, caches <= 2^26, k <= 100000)");
  }
  int stride = 1;
  g->alpha_cap = g->params.alpha_max >= 0.0f ? g->params.alpha_max : 0.95f;
  iris_guiding_choose_budget(&g->params, setup, &stride);
  g->stats.cache_res = g->params.cache_res;
  g->stats.cache_k = g->params.cache_k;
  g->stats.camera_stride = stride;
  g->stats.pdf_floor = g->params.pdf_floor;
  g->stats.pilot_share = g->stats.indirect_share = g->stats.seen_indirect_energy = g->stats.caustic_share = -1.0;
  g->env = setup->lights->envmap; /* training samples the sky behind glass */
  st0 = copy_lamps(g, setup->lights, err);
  if (st0 != IRIS_OK) {
    iris_guiding_destroy(g);
    return st0;
  }
  iris_status st = iris_octmap_create(&g->hemi, g->params.cache_res, false, err);
  if (st == IRIS_OK) st = iris_octmap_create(&g->sphere, g->params.cache_res, true, err);
  if (st == IRIS_OK) {
    if (setup->lights->count == 0 && !g->params.force) iris_guiding_skip(g, "no lights");
    else st = build_caches(g, setup, stride, err);
  }
  if (st == IRIS_OK && !g->stats.skipped && g->cache_count > 0) st = iris_guiding_build_sky(g, setup, err);
  if (st == IRIS_OK && !g->stats.skipped && g->cache_count > 0) st = iris_guiding_train(g, setup, err);
  if (st != IRIS_OK) {
    iris_guiding_destroy(g);
    return st;
  }
  g->stats.total_seconds = iris_time_now() - t0;
  g->env = NULL; /* lent for the build's training; the provider lends it for rendering */
  *out = g;
  return IRIS_OK;
}

void iris_guiding_count_refined(iris_guiding *g) {
  g->stats.refined_texels = g->stats.refined_caches = 0;
  if (!g->refine_slot) return;
  for (size_t i = 0; i < g->cache_count; ++i) {
    const iris_cache *c = &g->caches[i];
    const uint32_t n = c->sphere ? g->sphere.texel_count : g->hemi.texel_count;
    uint64_t r = 0;
    for (uint32_t t = 0; t < n; ++t) r += g->refine_slot[c->table + t] != 0;
    g->stats.refined_texels += r;
    g->stats.refined_caches += r > 0;
  }
}

void iris_guiding_destroy(iris_guiding *g) {
  if (!g) return;
  iris_skyvis_destroy(&g->sky);
  iris_light_select_destroy(&g->lights);
  iris_glints_destroy(&g->glints);
  iris_octmap_destroy(&g->hemi);
  iris_octmap_destroy(&g->sphere);
  iris_kdtree_destroy(&g->tree);
  iris_pick_grid_destroy(&g->grid);
  free(g->caches);
  free(g->pdf);
  free(g->alias);
  free(g->photon_hist);
  free(g->refine_slot);
  free(g->refine_sub);
  free(g->lamps);
  free(g);
}
