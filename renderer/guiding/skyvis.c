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
  free(sv->cache_window);
  free(sv->window_reach);
  sv->cdf = NULL;
  sv->sees = NULL;
  sv->cache_window = NULL;
  sv->window_reach = NULL;
  sv->window_count = 0;
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
  iris_portal *window; /* per cache: the opening found into its escaping probes' cone (or none) */
} probe_ctx;

#define WINDOW_STREAM 0x736b7977696eULL /* the window probes' hash stream */

/* The opening a cache sees the sky through: the cone around the mean of its
 * escaping probes (esc[0..n), weighted by |cos|) that holds them all, looked
 * into by portal.h's finder. None unless at least 4 escaped. */
static void find_window(const probe_ctx *c, size_t i, const iris_vec3 *esc, int n) {
  memset(&c->window[i], 0, sizeof c->window[i]);
  const iris_cache *cache = &c->caches[i];
  if (n < 4 || cache->sphere) return;
  iris_vec3 sum = iris_v3(0, 0, 0);
  for (int k = 0; k < n; ++k) sum = iris_add(sum, iris_scale(esc[k], fabsf(iris_dot(esc[k], cache->frame.n))));
  if (!(iris_dot(sum, sum) > 0.0f)) return;
  const iris_vec3 axis = iris_normalize(sum);
  float cos_max = 1.0f;
  for (int k = 0; k < n; ++k) cos_max = fminf(cos_max, iris_dot(esc[k], axis));
  cos_max = fmaxf(cos_max - 0.02f, -0.99f); /* the probes' own spacing: a little wider */
  iris_portal_find(c->accel, cache->p, cache->frame.n, axis, cos_max, iris_hash4(c->seed, WINDOW_STREAM, i, 0), NULL,
                   NULL, &c->window[i]);
}

/* Cache i: per region, the map's probability times the mean over the probes
 * of visibility x |cos| (one-sided caches: directions below the surface count
 * 0 and trace nothing), then the CDF of those weights. */
static void probe_caches(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  probe_ctx *c = ctx;
  iris_skyvis *sv = c->sv;
  const iris_envmap_regions *R = &sv->regions;
  uint64_t traced = 0, escaped = 0;
  iris_vec3 *esc = malloc(sizeof *esc * (size_t)sv->region_count * (size_t)c->probes);
  for (uint64_t i = begin; i < end; ++i) {
    if (iris_cancel_requested()) break;
    int n_esc = 0;
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
          if (esc) esc[n_esc++] = d;
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
    if (sv->sees[i] == IRIS_SKYVIS_PART && esc) find_window(c, i, esc, n_esc);
    else memset(&c->window[i], 0, sizeof c->window[i]);
  }
  free(esc);
  c->probes_by_thread[8 * (size_t)thread_index] += traced;
  c->escaped_by_thread[8 * (size_t)thread_index] += escaped;
}

typedef struct extend_ctx {
  iris_skyvis *sv;
  const iris_cache *caches;
  const iris_accel *accel;
  uint64_t seed;
} extend_ctx;

static float no_density(void *ctx, iris_vec3 wi) {
  (void)ctx, (void)wi;
  return 0.0f;
}

/* A cache that sees part of the sky but found no opening itself (its probes'
 * cone held more than the window, or too few probes fell on the wall) takes
 * the window it reaches best through, if at least half of the probes to
 * points on it get there (iris_portal_share's reach). */
static void extend_windows(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  const extend_ctx *c = ctx;
  iris_skyvis *sv = c->sv;
  for (uint64_t i = begin; i < end; ++i) {
    if (sv->sees[i] != IRIS_SKYVIS_PART || sv->cache_window[i] != 0xff || c->caches[i].sphere) continue;
    float best = 0.5f;
    for (int j = 0; j < sv->window_count; ++j) {
      if (!iris_portal_present(&sv->window[j])) continue;
      float reach;
      iris_portal_share(c->accel, &sv->window[j], c->caches[i].p, c->caches[i].frame.n,
                        iris_hash4(c->seed, WINDOW_STREAM, i, 1 + (uint64_t)j), no_density, NULL, &reach);
      if (reach >= best) best = reach + 1e-6f, sv->cache_window[i] = (uint8_t)j;
    }
  }
}

/* With several windows, which ones each cache with a window reaches (the
 * same probes as extend_windows: at least half get there), its own always. */
static void reach_windows(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  const extend_ctx *c = ctx;
  iris_skyvis *sv = c->sv;
  for (uint64_t i = begin; i < end; ++i) {
    if (sv->cache_window[i] == 0xff) continue;
    uint16_t bits = (uint16_t)(1u << sv->cache_window[i]);
    for (int j = 0; j < sv->window_count; ++j) {
      if (j == sv->cache_window[i] || !iris_portal_present(&sv->window[j])) continue;
      float reach;
      iris_portal_share(c->accel, &sv->window[j], c->caches[i].p, c->caches[i].frame.n,
                        iris_hash4(c->seed, WINDOW_STREAM, i, 1 + (uint64_t)j), no_density, NULL, &reach);
      if (reach >= 0.5f) bits |= (uint16_t)(1u << j);
    }
    sv->window_reach[i] = bits;
  }
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
  iris_portal *window = calloc(cache_count, sizeof *window);
  if (!window) {
    free(counts);
    iris_skyvis_destroy(sv);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for the sky visibility of %zu caches",
                          cache_count);
  }
  probe_ctx c = {sv, env, caches, accel, p->probes, seed, counts, counts + 8 * (size_t)nt, window};
  iris_parallel_for(cache_count, 16, nt, probe_caches, &c);
  for (int t = 0; t < nt; ++t) {
    sv->probes += counts[8 * (size_t)t];
    sv->escaped += counts[8 * (size_t)(nt + t)];
  }
  free(counts);
  for (size_t i = 0; i < cache_count; ++i) sv->part_caches += sv->sees[i] == IRIS_SKYVIS_PART;
  if (iris_cancel_requested()) {
    free(window);
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
    free(window);
    drop_tables(sv);
    return IRIS_OK;
  }
  /* The caches' openings joined into whole windows (serially: deterministic). */
  sv->cache_window = malloc(cache_count);
  iris_vec3 *at = malloc(sizeof *at * 2 * cache_count), side[IRIS_SKYVIS_WINDOWS];
  if (sv->cache_window && at) {
    for (size_t i = 0; i < cache_count; ++i) at[i] = caches[i].p, at[cache_count + i] = caches[i].frame.n;
    sv->window_count = iris_portal_join_all(accel, window, at, at + cache_count, cache_count, sv->window, side,
                                            IRIS_SKYVIS_WINDOWS, sv->cache_window);
    /* only the wholes that stayed (tightening drops one no finder sees through) */
    uint8_t keep[IRIS_SKYVIS_WINDOWS];
    int kept = 0;
    for (int j = 0; j < sv->window_count; ++j) {
      keep[j] = iris_portal_present(&sv->window[j]) ? (uint8_t)kept : 0xff;
      if (keep[j] != 0xff) sv->window[kept++] = sv->window[j];
    }
    sv->window_count = kept;
    for (size_t i = 0; i < cache_count; ++i)
      if (sv->cache_window[i] != 0xff) sv->cache_window[i] = keep[sv->cache_window[i]];
    if (sv->window_count > 0) {
      extend_ctx e = {sv, caches, accel, seed};
      iris_parallel_for(cache_count, 16, nt, extend_windows, &e);
    }
    for (size_t i = 0; i < cache_count; ++i) sv->window_caches += sv->cache_window[i] != 0xff;
    sv->memory_bytes += cache_count;
    if (sv->window_count > 1 && (sv->window_reach = calloc(cache_count, sizeof *sv->window_reach)) != NULL) {
      extend_ctx e = {sv, caches, accel, seed};
      iris_parallel_for(cache_count, 16, nt, reach_windows, &e);
      sv->memory_bytes += cache_count * sizeof *sv->window_reach;
    }
  } else { /* no windows: the regions alone */
    free(sv->cache_window);
    sv->cache_window = NULL;
  }
  free(at);
  free(window);
  sv->built = true;
  sv->map_width = env->width;
  sv->map_height = env->height;
  sv->map_mean = env->mean_luminance;
  return IRIS_OK;
}

void iris_skyvis_describe(const iris_skyvis *sv, char *buf, size_t size) {
  if (size) buf[0] = '\0';
  char windows[96] = "";
  if (sv->window_count > 0)
    snprintf(windows, sizeof windows, " (%zu through %d window%s)", sv->window_caches, sv->window_count,
             sv->window_count == 1 ? "" : "s");
  if (sv->probed)
    snprintf(buf, size, "; sky seen from the caches: %llu probes, %.0f%% escaped, %zu caches see part of it%s%s, %.2f s",
             (unsigned long long)sv->probes,
             sv->probes ? 100.0 * (double)sv->escaped / (double)sv->probes : 0.0, sv->part_caches,
             sv->built ? "" : " (too few: the map's own sampling)", windows, sv->seconds);
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
  if (m <= 0) return sv->window_count > 0; /* a vertex no cache covers: the windows as a whole */
  for (int i = 0; i < m; ++i)
    if (sv->sees[ids[i]] == IRIS_SKYVIS_PART) return true;
  return false;
}

/* The window cache `id` draws from, NULL for none. */
static inline const iris_portal *cache_window(const iris_skyvis *sv, uint32_t id) {
  return sv->cache_window && sv->cache_window[id] != 0xff ? &sv->window[sv->cache_window[id]] : NULL;
}

/* The windows cache `id` reaches (bit j: window j). */
static inline uint32_t cache_reach(const iris_skyvis *sv, uint32_t id) {
  return sv->window_reach ? sv->window_reach[id] : 0xffffu;
}

/* The probabilities at x of the windows a cache draws from, whose own window
 * is `own` and which reaches `reach` (skyvis.h): its own with
 * IRIS_SKYVIS_OWN_WINDOW, the rest among those it reaches by each one's solid
 * angle from x, area |cos| / (d^2 + area) (finite at the window itself); all
 * its own where it reaches no other or x sees none. */
static void window_probabilities(const iris_skyvis *sv, const iris_portal *own, uint32_t reach, iris_vec3 x,
                                 float *prob) {
  const int n = sv->window_count, o = (int)(own - sv->window);
  for (int j = 0; j < n; ++j) prob[j] = j == o ? 1.0f : 0.0f;
  if (reach == (1u << o)) return; /* its own alone */
  float tot = 0.0f;
  for (int j = 0; j < n; ++j) {
    const iris_portal *p = &sv->window[j];
    const iris_vec3 nrm = iris_cross(p->u, p->v), d = iris_sub(x, p->o);
    const float len = iris_length(nrm), area = 4.0f * len, d2 = iris_dot(d, d), dn = sqrtf(d2) * len;
    prob[j] = (reach >> j & 1u) && dn > 0.0f ? area * (fabsf(iris_dot(d, nrm)) / dn) / (d2 + area) : 0.0f;
    tot += prob[j];
  }
  const float a = tot > 0.0f && isfinite(tot) ? 1.0f - IRIS_SKYVIS_OWN_WINDOW : 0.0f;
  for (int j = 0; j < n; ++j) prob[j] = (j == o ? 1.0f - a : 0.0f) + (a > 0.0f ? a * prob[j] / tot : 0.0f);
}

/* The density at x of the windows' draws for a cache whose own window is
 * `own` and which reaches `reach`: sum_j P_j iris_portal_pdf(window j). */
static float windows_pdf(const iris_skyvis *sv, const iris_portal *own, uint32_t reach, iris_vec3 x, iris_vec3 d) {
  if (sv->window_count == 1) return iris_portal_pdf(own, x, d);
  float prob[IRIS_SKYVIS_WINDOWS], pdf = 0.0f;
  window_probabilities(sv, own, reach, x, prob);
  for (int j = 0; j < sv->window_count; ++j)
    if (prob[j] > 0.0f) pdf += prob[j] * iris_portal_pdf(&sv->window[j], x, d);
  return pdf;
}

float iris_skyvis_scale(const iris_skyvis *sv, const iris_envmap *env, const uint32_t *ids, int m, iris_vec3 x,
                        iris_vec3 d, float s, float t, float *window) {
  *window = 0.0f;
  if (!iris_skyvis_guides(sv, ids, m)) return 1.0f;
  if (m <= 0) { /* each window alike */
    float through = 0.0f;
    for (int j = 0; j < sv->window_count; ++j) through += iris_portal_pdf(&sv->window[j], x, d);
    *window = IRIS_SKYVIS_WINDOW_SHARE * through / (float)sv->window_count;
    return 1.0f - IRIS_SKYVIS_WINDOW_SHARE;
  }
  const int region = iris_envmap_region_of(env, &sv->regions, s, t);
  float sum = 0.0f, through = 0.0f, last_pdf = 0.0f;
  const iris_portal *last = NULL;
  uint32_t last_reach = 0;
  for (int i = 0; i < m; ++i) {
    if (sv->sees[ids[i]] != IRIS_SKYVIS_PART) {
      sum += 1.0f;
      continue;
    }
    const float *row = &sv->cdf[(size_t)ids[i] * (size_t)sv->region_count];
    const float own = (1.0f - sv->beta) + sv->beta * region_ratio(sv, row, region);
    const iris_portal *w = cache_window(sv, ids[i]);
    if (w) {
      sum += (1.0f - IRIS_SKYVIS_WINDOW_SHARE) * own;
      const uint32_t reach = cache_reach(sv, ids[i]);
      if (w != last || reach != last_reach) /* tied caches mostly share them */
        last = w, last_reach = reach, last_pdf = windows_pdf(sv, w, reach, x, d);
      through += IRIS_SKYVIS_WINDOW_SHARE * last_pdf;
    } else {
      sum += own;
    }
  }
  *window = through / (float)m;
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

bool iris_skyvis_sample(const iris_skyvis *sv, const iris_envmap *env, const uint32_t *ids, int m, iris_vec3 x,
                        float u0, float u1, iris_vec3 *d, float *pdf, float *s, float *t) {
  if (!iris_skyvis_guides(sv, ids, m)) return iris_envmap_sample_st(env, u0, u1, d, pdf, s, t);
  if (m <= 0) { /* no cache: one of the windows with their share, else the map */
    float pdf_map;
    if (u1 < IRIS_SKYVIS_WINDOW_SHARE) {
      const float uw = u1 / IRIS_SKYVIS_WINDOW_SHARE * (float)sv->window_count;
      const int j = uw < (float)(sv->window_count - 1) ? (int)uw : sv->window_count - 1;
      *d = iris_portal_sample(&sv->window[j], x, u0, iris_clampf(uw - (float)j, 0.0f, IRIS_ONE_MINUS_EPSILON));
      if (!(iris_portal_pdf(&sv->window[j], x, *d) > 0.0f)) return false;
      iris_envmap_dir_to_st(env, *d, s, t);
      pdf_map = iris_envmap_pdf_st(env, *s, *t);
    } else if (!iris_envmap_sample_st(env, u0, iris_rescale_unit(u1, IRIS_SKYVIS_WINDOW_SHARE, 1.0f), d, &pdf_map, s,
                                      t)) {
      return false;
    }
    float through;
    const float scale = iris_skyvis_scale(sv, env, ids, m, x, *d, *s, *t, &through);
    *pdf = pdf_map * scale + through;
    return isfinite(*pdf) && *pdf > 0.0f;
  }
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
  float ub = iris_clampf(um - (float)j, 0.0f, IRIS_ONE_MINUS_EPSILON);
  const uint32_t id = ids[j];
  float pdf_map;
  const iris_portal *w = cache_window(sv, id);
  if (w && ub < IRIS_SKYVIS_WINDOW_SHARE) { /* a point on a window (u0 across, the rest of u1 along) */
    float uw = iris_rescale_unit(ub, 0.0f, IRIS_SKYVIS_WINDOW_SHARE);
    if (sv->window_count > 1) { /* which window: from uw too, the rest of it along */
      float prob[IRIS_SKYVIS_WINDOWS], lo = 0.0f, at = 0.0f;
      window_probabilities(sv, w, cache_reach(sv, id), x, prob);
      int wj = (int)(w - sv->window); /* its own has a probability: the last resort if rounding runs past */
      for (int k = 0; k < sv->window_count; ++k) {
        if (!(prob[k] > 0.0f)) continue;
        wj = k, lo = at;
        if (uw < at + prob[k]) break;
        at += prob[k];
      }
      uw = iris_rescale_unit(uw, lo, lo + prob[wj]);
      w = &sv->window[wj];
    }
    *d = iris_portal_sample(w, x, u0, uw);
    if (!(iris_portal_pdf(w, x, *d) > 0.0f)) return false; /* x lies in its plane */
    iris_envmap_dir_to_st(env, *d, s, t);
    pdf_map = iris_envmap_pdf_st(env, *s, *t);
  } else {
    if (w) ub = iris_rescale_unit(ub, IRIS_SKYVIS_WINDOW_SHARE, 1.0f);
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
  }
  /* the density of the whole strategy: the map's (of the sampled cell, as
   * iris_envmap_sample_st gives it) times the mixture's factor, and the windows' */
  float through;
  const float scale = iris_skyvis_scale(sv, env, ids, m, x, *d, *s, *t, &through);
  *pdf = pdf_map * scale + through;
  return isfinite(*pdf) && *pdf > 0.0f;
}
