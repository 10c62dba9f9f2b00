/* Glint photons and the spot a vertex sees: glints.h, docs/guiding.md "Glints". */
#include "renderer/guiding/glints.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "core/cancel.h"
#include "core/parallel.h"
#include "core/rng.h"

#define BLOCK_PATHS 4096u
#define MAX_BOUNCES 8
/* Stream that keeps glint photons' numbers apart from the photons' and the camera's. */
#define GLINT_STREAM 0x676c696e74ULL
/* Targets kept (every k-th of the smooth points, in path order), and the
 * neighbour whose distance is a target's jitter radius. */
#define MAX_TARGETS 65536u
#define TARGET_NEIGHBOUR 4u
/* Two glint photons come from one spot when their smooth points lie within
 * SLIDE of their landing points' distance (a glint seen from a nearby point
 * leaves the surface about that much nearer: half on a flat mirror, less on
 * a convex one) plus HAIR of the path from the surface (the light's own
 * width, a glossy lobe's blur); a spot holds its points plus SLIDE of their
 * distance to the vertex. */
#define SLIDE 0.5f
#define HAIR 0.01f
#define FACING_COS 0.9f

typedef struct glint_block {
  iris_glint_photon *items;
  size_t count, cap, at;
  bool oom;
} glint_block;

typedef struct trace_ctx {
  const iris_guide_setup *setup;
  const iris_vec3 *targets;
  const float *reach; /* jitter radius per target */
  uint32_t target_count;
  uint64_t paths;
  glint_block *blocks;
  iris_glint_photon *all;
} trace_ctx;

static void push(glint_block *b, const iris_glint_photon *g) {
  if (b->oom) return;
  if (b->count == b->cap) {
    size_t cap = b->cap ? 2 * b->cap : 1024;
    iris_glint_photon *n = realloc(b->items, cap * sizeof *n);
    if (!n) {
      b->oom = true;
      return;
    }
    b->items = n;
    b->cap = cap;
  }
  b->items[b->count++] = *g;
}

static void trace_glint(const trace_ctx *c, uint64_t index, glint_block *out) {
  const iris_guide_setup *s = c->setup;
  iris_sampler rng = iris_sampler_start(s->seed, GLINT_STREAM, index);
  const float ut = iris_sampler_get(&rng, 0), us = iris_sampler_get(&rng, 1), u0 = iris_sampler_get(&rng, 2),
              u1 = iris_sampler_get(&rng, 3), uj0 = iris_sampler_get(&rng, 4), uj1 = iris_sampler_get(&rng, 5),
              uj2 = iris_sampler_get(&rng, 6);
  uint32_t ti = (uint32_t)(ut * (float)c->target_count);
  if (ti >= c->target_count) ti = c->target_count - 1;
  /* a point in the ball around the target: the smooth surface near where photons met it */
  const float z = 1.0f - 2.0f * uj0, rxy = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 6.2831853f * uj1;
  const float rad = c->reach[ti] * cbrtf(uj2);
  const iris_vec3 t = iris_add(c->targets[ti], iris_scale(iris_v3(rxy * cosf(phi), rxy * sinf(phi), z), rad));
  iris_light_sample ls;
  if (!iris_lights_sample(s->lights, t, iris_v3(0.0f, 0.0f, 0.0f), us, u0, u1, &ls)) return;
  const float weight = iris_avg3(ls.L) / (ls.delta ? 1.0f : ls.pdf);
  if (!(weight > 0.0f) || !isfinite(weight)) return;
  iris_ray ray;
  if (isfinite(ls.dist)) {
    iris_vec3 d = iris_sub(t, ls.p);
    const float len = iris_length(d);
    if (!(len > 0.0f)) return;
    ray.d = iris_scale(d, 1.0f / len);
    ray.o = ls.delta ? ls.p : iris_offset_origin(ls.p, ls.n, ray.d);
  } else { /* from outside the scene's bounding sphere, along the light's direction */
    const float far = iris_length(iris_sub(t, s->lights->center)) + 2.0f * s->lights->radius + 1.0f;
    ray.o = iris_add(t, iris_scale(ls.wi, far));
    ray.d = iris_neg(ls.wi);
  }
  ray.tmin = 0.0f;
  ray.tmax = INFINITY;
  iris_vec3 beta = iris_v3(1.0f, 1.0f, 1.0f), y = t;
  const iris_vec3 d0 = ray.d;
  bool smooth_seen = false, reflected = false;
  for (int bounce = 0; bounce < MAX_BOUNCES; ++bounce) {
    iris_sampler_set_bounce(&rng, bounce + 1);
    iris_hit hit;
    if (!iris_accel_intersect(s->accel, &ray, &hit)) return;
    iris_interaction si;
    iris_accel_interaction(s->accel, ray.d, &hit, &si);
    const iris_vec3 wo = iris_normalize(iris_neg(ray.d));
    iris_shading_point sp;
    iris_integrator_shade(s->integrator, &si, wo, bounce, &sp);
    if (!iris_photon_smooth(&sp)) {
      /* landed: a glint if a smooth surface sent it here, not straight on
       * through a slab of glass (iris_photon.glint) */
      if (!smooth_seen) return;
      if (!reflected && iris_dot(iris_normalize(d0), iris_normalize(ray.d)) > IRIS_PHOTON_STRAIGHT_COS) return;
      const float e = weight * iris_avg3(beta);
      if (!(e > 0.0f) || !isfinite(e)) return;
      iris_glint_photon g = {si.p, sp.frame.n, y, e};
      push(out, &g);
      return;
    }
    smooth_seen = true;
    y = si.p;
    iris_direction_sample ds;
    if (!iris_integrator_sample_bsdf(&sp, &rng, &ds)) return;
    if ((sp.lobes & IRIS_LOBE_TRANSMISSION) && !(ds.lobe & IRIS_LOBE_TRANSMISSION))
      return; /* what glass reflects is faint (iris_photon.glint) */
    reflected |= !(ds.lobe & IRIS_LOBE_TRANSMISSION);
    const float cosv = fabsf(iris_dot(ds.wi, sp.frame.n));
    beta = iris_scale(iris_mul(beta, iris_scale(ds.f, cosv)), 1.0f / ds.pdf);
    if (!iris_isfinite3(beta) || !(iris_max3(beta) > 0.0f)) return;
    ray = iris_spawn_ray(&sp.si, ds.wi);
  }
}

static void trace_blocks(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  trace_ctx *c = ctx;
  for (uint64_t b = begin; b < end; ++b) {
    if (iris_cancel_requested()) return;
    uint64_t lo = b * BLOCK_PATHS, hi = lo + BLOCK_PATHS < c->paths ? lo + BLOCK_PATHS : c->paths;
    for (uint64_t i = lo; i < hi; ++i) trace_glint(c, i, &c->blocks[b]);
  }
}

static void copy_blocks(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  trace_ctx *c = ctx;
  for (uint64_t b = begin; b < end; ++b)
    if (c->blocks[b].count) memcpy(c->all + c->blocks[b].at, c->blocks[b].items, c->blocks[b].count * sizeof *c->all);
}

typedef struct reach_ctx {
  const iris_kdtree *tree;
  const iris_vec3 *targets;
  float *reach;
} reach_ctx;

static void reach_of(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  reach_ctx *c = ctx;
  uint32_t ids[TARGET_NEIGHBOUR + 1];
  float d2[TARGET_NEIGHBOUR + 1];
  for (uint64_t i = begin; i < end; ++i) {
    uint32_t n = iris_kdtree_knn(c->tree, c->targets[i], TARGET_NEIGHBOUR + 1, INFINITY, ids, d2);
    c->reach[i] = n > 1 ? sqrtf(d2[n - 1]) : 0.0f;
  }
}

iris_status iris_glints_trace(const iris_guide_setup *setup, const iris_photon_map *map, uint64_t paths,
                              iris_glints *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  if (map->smooth_count == 0 || paths == 0 || setup->lights->count == 0) return IRIS_OK;
  /* the targets: every stride-th smooth point, in path order */
  const size_t stride = (map->smooth_count + MAX_TARGETS - 1) / MAX_TARGETS;
  const uint32_t nt = (uint32_t)((map->smooth_count + stride - 1) / stride);
  iris_vec3 *targets = malloc(nt * sizeof *targets);
  float *reach = malloc(nt * sizeof *reach);
  const uint64_t nblocks = (paths + BLOCK_PATHS - 1) / BLOCK_PATHS;
  glint_block *blocks = calloc(nblocks, sizeof *blocks);
  iris_kdtree ttree;
  memset(&ttree, 0, sizeof ttree);
  iris_status st = targets && reach && blocks ? IRIS_OK
                                              : iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding",
                                                               "out of memory for glint photons");
  if (st == IRIS_OK) {
    for (uint32_t i = 0; i < nt; ++i) targets[i] = map->smooth[(size_t)i * stride];
    st = iris_kdtree_build_threads(&ttree, targets, sizeof *targets, nt, setup->threads, err);
  }
  if (st == IRIS_OK) {
    reach_ctx rc = {&ttree, targets, reach};
    iris_parallel_for(nt, 256, setup->threads, reach_of, &rc);
    trace_ctx c = {setup, targets, reach, nt, paths, blocks, NULL};
    iris_parallel_for(nblocks, 1, setup->threads, trace_blocks, &c);
    if (iris_cancel_requested()) st = iris_cancel_error(err);
    size_t total = 0;
    bool oom = false;
    for (uint64_t b = 0; b < nblocks; ++b) blocks[b].at = total, total += blocks[b].count, oom |= blocks[b].oom;
    if (st == IRIS_OK && (oom || total > UINT32_MAX))
      st = iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for glint photons");
    if (st == IRIS_OK && total > 0) {
      out->photons = malloc(total * sizeof *out->photons);
      if (!out->photons) st = iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for glint photons");
      else {
        c.all = out->photons;
        iris_parallel_for(nblocks, 1, setup->threads, copy_blocks, &c);
        out->count = (uint32_t)total;
      }
    }
  }
  for (uint64_t b = 0; blocks && b < nblocks; ++b) free(blocks[b].items);
  free(blocks);
  free(targets);
  free(reach);
  iris_kdtree_destroy(&ttree);
  out->paths = paths;
  if (st == IRIS_OK) st = iris_glints_index(out, setup->threads, err);
  if (st != IRIS_OK) iris_glints_destroy(out);
  return st;
}

/* What the query's filter reads of a glint photon, kept in the tree's order
 * next to its position (iris_kdtree_set_payload): n and y, adjacent in
 * iris_glint_photon, so the filter does not chase the photon array. */
typedef struct glint_dirs {
  iris_vec3 n, y;
} glint_dirs;
_Static_assert(offsetof(iris_glint_photon, y) == offsetof(iris_glint_photon, n) + sizeof(iris_vec3) &&
                   sizeof(glint_dirs) == 2 * sizeof(iris_vec3),
               "glint_dirs mirrors iris_glint_photon's n, y");

iris_status iris_glints_index(iris_glints *gl, int threads, iris_error *err) {
  iris_kdtree_destroy(&gl->tree);
  if (gl->count == 0) return IRIS_OK;
  iris_status st = iris_kdtree_build_threads(&gl->tree, &gl->photons[0].p, sizeof *gl->photons, gl->count, threads, err);
  if (st == IRIS_OK)
    st = iris_kdtree_set_payload(&gl->tree, &gl->photons[0].n, sizeof *gl->photons, sizeof(glint_dirs), threads, err);
  return st;
}

size_t iris_glints_bytes(size_t count) {
  return count * (sizeof(iris_glint_photon) + 3 * sizeof(float) + sizeof(uint32_t) + 1);
}

void iris_glints_destroy(iris_glints *gl) {
  free(gl->photons);
  iris_kdtree_destroy(&gl->tree);
  memset(gl, 0, sizeof *gl);
}

typedef struct accept_ctx {
  iris_vec3 x, n;
} accept_ctx;

/* On a surface facing like the vertex's, from a smooth point above it. */
static bool accept(void *ctx, const void *payload) {
  const accept_ctx *a = ctx;
  glint_dirs g;
  memcpy(&g, payload, sizeof g);
  return iris_dot(g.n, a->n) >= FACING_COS && iris_dot(iris_sub(g.y, a->x), a->n) > 0.0f;
}

bool iris_glints_spot(const iris_glints *gl, iris_vec3 x, iris_vec3 n, iris_guide_lamp *spot) {
  if (gl->count == 0 || !(gl->radius2 > 0.0f)) return false;
  uint32_t ids[IRIS_GLINT_K];
  float d2[IRIS_GLINT_K];
  accept_ctx a = {x, n};
  const uint32_t m = iris_kdtree_knn_payload_if(&gl->tree, x, IRIS_GLINT_K, gl->radius2, accept, &a, ids, d2, NULL);
  if (m < IRIS_GLINT_MIN) return false;
  /* A bright glint is many photons from one spot; dim light off the same
   * surface (the sky in a mirror) comes from anywhere on it. Photon j agrees
   * with photon i when their smooth points lie no farther apart than SLIDE
   * of their landing points' distance (plus a hair): the anchor is the photon
   * most others agree with (the nearest among equals). */
  const iris_glint_photon *ph[IRIS_GLINT_K];
  for (uint32_t j = 0; j < m; ++j) ph[j] = &gl->photons[ids[j]];
  uint32_t anchor = 0, best = 0;
  bool member[IRIS_GLINT_K];
  for (uint32_t i = 0; i < m; ++i) {
    uint32_t agree = 0;
    for (uint32_t j = 0; j < m; ++j)
      agree += iris_length(iris_sub(ph[j]->y, ph[i]->y)) <= SLIDE * iris_length(iris_sub(ph[j]->p, ph[i]->p)) +
                                                               HAIR * iris_length(iris_sub(ph[i]->p, ph[i]->y));
    if (agree > best) best = agree, anchor = i;
  }
  if (best < IRIS_GLINT_MIN) return false;
  double cx = 0.0, cy = 0.0, cz = 0.0;
  for (uint32_t j = 0; j < m; ++j) {
    member[j] = iris_length(iris_sub(ph[j]->y, ph[anchor]->y)) <=
                SLIDE * iris_length(iris_sub(ph[j]->p, ph[anchor]->p)) +
                    HAIR * iris_length(iris_sub(ph[anchor]->p, ph[anchor]->y));
    if (member[j]) cx += ph[j]->y.x, cy += ph[j]->y.y, cz += ph[j]->y.z;
  }
  const iris_vec3 c = iris_v3((float)(cx / best), (float)(cy / best), (float)(cz / best));
  /* every member's point, plus SLIDE of its landing point's distance to x */
  float r = 0.0f;
  for (uint32_t j = 0; j < m; ++j)
    if (member[j]) r = fmaxf(r, iris_length(iris_sub(ph[j]->y, c)) + SLIDE * sqrtf(d2[j]));
  r += HAIR * iris_length(iris_sub(c, x));
  const iris_vec3 dc = iris_sub(c, x);
  if (!(r > 0.0f) || !isfinite(r) || !(iris_dot(dc, dc) > r * r)) return false;
  spot->center = c;
  spot->radius = r;
  return true;
}
