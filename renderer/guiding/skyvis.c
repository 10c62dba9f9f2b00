/* Sky visibility per cache (skyvis.h; docs/guiding.md, "Sky visibility"). */
#include "renderer/guiding/skyvis.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/cancel.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "renderer/guiding/guiding.h"

#define SKYVIS_STREAM 0x736b7976697355ULL /* the probes' hash stream */
/* Share of the sky a cache faces (weighted by the map and the cosine) that it
 * must see for the map's own sampling to serve it: then at most half of the
 * map's light samples there are lost, and the mixture's cost is not worth it
 * (docs/guiding.md, "Sky visibility"). */
#define SKYVIS_OPEN 0.5
/* Share of the caches that must see part of the sky for the mixture to be used. */
#define SKYVIS_MIN_PART 0.1

/* Frees the tables; the counts stay. */
static void drop_tables(iris_skyvis *sv) {
  iris_envmap_regions_destroy(&sv->regions);
  free(sv->cdf);
  free(sv->sees);
  sv->cdf = NULL;
  sv->sees = NULL;
  sv->region_count = 0;
  sv->memory_bytes = 0;
}

void iris_skyvis_destroy(iris_skyvis *sv) {
  drop_tables(sv);
  memset(sv, 0, sizeof *sv);
}

typedef struct probe_ctx {
  iris_skyvis *sv;
  const iris_envmap *env;
  const iris_cache *caches;
  const iris_accel *accel;
  int probes;
  uint64_t seed;
  uint64_t *probes_by_thread, *escaped_by_thread; /* [threads * 8]: a cache line each */
} probe_ctx;

/* Cache i: per region, the map's probability times the mean over the probes
 * of visibility x |cos| (one-sided caches: directions below the surface count
 * 0 and trace nothing), then the CDF of those weights. */
static void probe_caches(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  probe_ctx *c = ctx;
  iris_skyvis *sv = c->sv;
  const iris_envmap_regions *R = &sv->regions;
  uint64_t traced = 0, escaped = 0;
  for (uint64_t i = begin; i < end; ++i) {
    if (iris_cancel_requested()) break;
    const iris_cache *cache = &c->caches[i];
    const iris_vec3 n = cache->frame.n;
    float *row = &sv->cdf[i * (size_t)sv->region_count];
    double acc = 0.0, open = 0.0; /* open: the same weights as if nothing blocked the probes */
    for (int b = 0; b < sv->region_count; ++b) {
      double w = 0.0;
      if (R->prob[b] > 0.0f) {
        uint64_t h = iris_hash4(c->seed, SKYVIS_STREAM ^ i, (uint64_t)b, 0);
        const float jitter = iris_u64_to_unit(h);
        double seen = 0.0, facing = 0.0;
        for (int k = 0; k < c->probes; ++k) {
          h = iris_mix64(h + 0x9e3779b97f4a7c15ULL);
          float u0 = ((float)k + jitter) / (float)c->probes, u1 = iris_u64_to_unit(h);
          if (!(u0 < 1.0f)) u0 = IRIS_ONE_MINUS_EPSILON;
          iris_vec3 d;
          float pdf, s, t;
          if (!iris_envmap_sample_region(c->env, R, b, u0, u1, &d, &pdf, &s, &t)) continue;
          float cosv = iris_dot(d, n);
          if (!cache->sphere && !(cosv > 0.0f)) continue;
          facing += fabs((double)cosv);
          iris_ray ray;
          ray.o = iris_offset_origin(cache->p, n, d);
          ray.d = d;
          ray.tmin = 0.0f;
          ray.tmax = INFINITY;
          traced++;
          if (iris_accel_occluded(c->accel, &ray)) continue;
          escaped++;
          seen += fabs((double)cosv);
        }
        w = (double)R->prob[b] * seen / (double)c->probes;
        open += (double)R->prob[b] * facing / (double)c->probes;
      }
      acc += w;
      row[b] = (float)acc;
    }
    /* A cache that saw at least half of the sky its side of the surface
     * faces adds little to the map's own sampling but its cost: it takes the
     * map, as one that saw nothing does. */
    sv->sees[i] = acc > 0.0 ? (acc < SKYVIS_OPEN * open ? IRIS_SKYVIS_PART : IRIS_SKYVIS_OPEN) : IRIS_SKYVIS_NONE;
    if (acc > 0.0) {
      for (int b = 0; b < sv->region_count; ++b) row[b] = (float)((double)row[b] / acc);
      /* the last region with weight ends at exactly 1 */
      for (int b = sv->region_count - 1; b >= 0 && row[b] >= 1.0f - 1e-6f; --b) row[b] = 1.0f;
    }
  }
  c->probes_by_thread[8 * (size_t)thread_index] += traced;
  c->escaped_by_thread[8 * (size_t)thread_index] += escaped;
}

iris_status iris_skyvis_build(iris_skyvis *sv, const struct iris_cache *caches, size_t cache_count, const iris_accel *accel,
                              const iris_envmap *env, const iris_skyvis_params *p, uint64_t seed, int threads,
                              iris_error *err) {
  memset(sv, 0, sizeof *sv);
  if (!env || cache_count == 0 || !(p->beta > 0.0f) || p->probes <= 0 || p->regions_x <= 0) return IRIS_OK;
  const double t0 = iris_time_now();
  int bx = p->regions_x, by = bx / 2 > 0 ? bx / 2 : 1;
  iris_status st = iris_envmap_regions_build(env, bx, by, &sv->regions, err);
  if (st != IRIS_OK) return st;
  sv->region_count = bx * by;
  sv->beta = p->beta > 1.0f ? 1.0f : p->beta;
  sv->cache_count = cache_count;
  sv->cdf = malloc(sizeof(float) * cache_count * (size_t)sv->region_count);
  sv->sees = calloc(cache_count, 1);
  int nt = threads > 0 ? threads : iris_parallel_default_threads();
  uint64_t *counts = calloc(16 * (size_t)nt, sizeof(uint64_t));
  if (!sv->cdf || !sv->sees || !counts) {
    free(counts);
    iris_skyvis_destroy(sv);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for the sky visibility of %zu caches",
                          cache_count);
  }
  probe_ctx c = {sv, env, caches, accel, p->probes, seed, counts, counts + 8 * (size_t)nt};
  iris_parallel_for(cache_count, 16, nt, probe_caches, &c);
  for (int t = 0; t < nt; ++t) {
    sv->probes += counts[8 * (size_t)t];
    sv->escaped += counts[8 * (size_t)(nt + t)];
  }
  free(counts);
  for (size_t i = 0; i < cache_count; ++i) sv->part_caches += sv->sees[i] == IRIS_SKYVIS_PART;
  if (iris_cancel_requested()) {
    iris_skyvis_destroy(sv);
    return iris_cancel_error(err);
  }
  sv->memory_bytes = sizeof(float) * cache_count * (size_t)sv->region_count + cache_count +
                     sizeof(float) * (size_t)bx * ((size_t)env->height + (size_t)by + (size_t)by);
  sv->seconds = iris_time_now() - t0;
  sv->probed = true;
  if ((double)sv->part_caches < SKYVIS_MIN_PART * (double)cache_count) {
    /* Nearly every cache sees all its sky or none: the map's own sampling
     * does as well, without the cost of the mixture (an open scene). */
    drop_tables(sv);
    return IRIS_OK;
  }
  sv->built = true;
  sv->map_width = env->width;
  sv->map_height = env->height;
  sv->map_mean = env->mean_luminance;
  return IRIS_OK;
}

void iris_skyvis_describe(const iris_skyvis *sv, char *buf, size_t size) {
  if (size) buf[0] = '\0';
  if (sv->probed)
    snprintf(buf, size, "; sky seen from the caches: %llu probes, %.0f%% escaped, %zu caches see part of it%s, %.2f s",
             (unsigned long long)sv->probes,
             sv->probes ? 100.0 * (double)sv->escaped / (double)sv->probes : 0.0, sv->part_caches,
             sv->built ? "" : " (too few: the map's own sampling)", sv->seconds);
}

bool iris_skyvis_serves(const iris_skyvis *sv, const iris_envmap *env) {
  return sv->built && env && env->width == sv->map_width && env->height == sv->map_height &&
         env->mean_luminance == sv->map_mean;
}

/* P_cache(region) / P_map(region) of one cache's row. */
static inline float region_ratio(const iris_skyvis *sv, const float *row, int region) {
  float pm = sv->regions.prob[region];
  if (!(pm > 0.0f)) return 0.0f;
  float pc = row[region] - (region > 0 ? row[region - 1] : 0.0f);
  return pc / pm;
}

bool iris_skyvis_guides(const iris_skyvis *sv, const uint32_t *ids, int m) {
  if (!sv->built) return false;
  for (int i = 0; i < m; ++i)
    if (sv->sees[ids[i]] == IRIS_SKYVIS_PART) return true;
  return false;
}

float iris_skyvis_scale(const iris_skyvis *sv, const iris_envmap *env, const uint32_t *ids, int m, float s, float t) {
  if (!iris_skyvis_guides(sv, ids, m)) return 1.0f;
  const int region = iris_envmap_region_of(env, &sv->regions, s, t);
  float sum = 0.0f;
  for (int i = 0; i < m; ++i) {
    if (sv->sees[ids[i]] != IRIS_SKYVIS_PART) {
      sum += 1.0f;
      continue;
    }
    const float *row = &sv->cdf[(size_t)ids[i] * (size_t)sv->region_count];
    sum += (1.0f - sv->beta) + sv->beta * region_ratio(sv, row, region);
  }
  return sum / (float)m;
}

/* First region whose CDF end exceeds u (regions of zero weight are never returned). */
static int search_row(const float *row, int n, float u) {
  int lo = 0, hi = n - 1;
  while (lo < hi) {
    int mid = lo + (hi - lo) / 2;
    if (row[mid] > u) hi = mid;
    else lo = mid + 1;
  }
  return lo;
}

bool iris_skyvis_sample(const iris_skyvis *sv, const iris_envmap *env, const uint32_t *ids, int m, float u0,
                        float u1, iris_vec3 *d, float *pdf, float *s, float *t) {
  if (!sv->built || m <= 0) return iris_envmap_sample_st(env, u0, u1, d, pdf, s, t);
  /* Every choice from u1, the second number of the pixel's stratified pair,
   * rescaled at each step (the tied cache, its regions or the map, the region,
   * then the column within it), the row from u0 as it comes: the directions
   * drawn in one region keep the pair's stratification, and the map's row is
   * the one the path loop loaded ahead from (u0, u1) (docs/guiding.md, "Sky
   * visibility"). */
  const float um = u1 * (float)m;
  int j = (int)um;
  j = j < 0 ? 0 : j >= m ? m - 1 : j;
  /* the rest of u1, uniform in [0, 1) */
  const float ub = iris_clampf(um - (float)j, 0.0f, IRIS_ONE_MINUS_EPSILON);
  const uint32_t id = ids[j];
  float pdf_map;
  if (sv->sees[id] != IRIS_SKYVIS_PART) {
    if (!iris_envmap_sample_st(env, u0, ub, d, &pdf_map, s, t)) return false;
  } else if (ub < sv->beta) {
    const float *row = &sv->cdf[(size_t)id * (size_t)sv->region_count];
    const float ur = iris_rescale_unit(ub, 0.0f, sv->beta);
    const int region = search_row(row, sv->region_count, ur);
    const float lo = region > 0 ? row[region - 1] : 0.0f, hi = row[region];
    const float ui = hi > lo ? iris_rescale_unit(ur, lo, hi) : 0.0f;
    if (!iris_envmap_sample_region(env, &sv->regions, region, u0, ui, d, &pdf_map, s, t)) return false;
  } else {
    const float ua = iris_rescale_unit(ub, sv->beta, 1.0f);
    if (!iris_envmap_sample_st(env, u0, ua, d, &pdf_map, s, t)) return false;
  }
  /* the density of the whole strategy: the map's (of the sampled cell, as
   * iris_envmap_sample_st gives it) times the mixture's factor */
  *pdf = pdf_map * iris_skyvis_scale(sv, env, ids, m, *s, *t);
  return isfinite(*pdf) && *pdf > 0.0f;
}
