/* `--method auto`'s race of mis against guided-nee (method_race.h). */
#include "renderer/method_race.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/cancel.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "renderer/bsdf.h"
#include "renderer/camera_path.h"

/* The guide's operations, counted per thread by wrappers around the guided
 * integrator's direction sampler (integer sums: deterministic). */
static _Thread_local uint64_t tl_prepares, tl_calls;

typedef struct counted_guide {
  iris_direction_sampler inner;
} counted_guide;

static bool counted_sample(void *ctx, const iris_shading_point *sp, iris_sampler *rng, iris_direction_sample *out) {
  const counted_guide *c = ctx;
  tl_calls++;
  return c->inner.sample(c->inner.ctx, sp, rng, out);
}
static float counted_pdf(void *ctx, const iris_shading_point *sp, iris_vec3 wi) {
  const counted_guide *c = ctx;
  tl_calls++;
  return c->inner.pdf(c->inner.ctx, sp, wi);
}
static void counted_prepare(void *ctx, iris_shading_point *sp) {
  const counted_guide *c = ctx;
  tl_prepares++;
  c->inner.prepare(c->inner.ctx, sp);
}
static float counted_radiance(void *ctx, const iris_shading_point *sp) {
  const counted_guide *c = ctx;
  return c->inner.radiance_estimate(c->inner.ctx, sp);
}
static void counted_prefetch(void *ctx, iris_vec3 p) {
  const counted_guide *c = ctx;
  c->inner.prefetch(c->inner.ctx, p);
}
static int counted_environment(void *ctx, const struct iris_envmap *env, const iris_shading_point *sp, float u0,
                               float u1, iris_vec3 *wi, float *pdf, float *s, float *t) {
  const counted_guide *c = ctx;
  tl_calls++;
  return c->inner.sample_environment(c->inner.ctx, env, sp, u0, u1, wi, pdf, s, t);
}
static float counted_scale(void *ctx, const struct iris_envmap *env, const iris_guide_vertex *v, iris_vec3 wi, float s,
                           float t, float *add) {
  const counted_guide *c = ctx;
  tl_calls++;
  return c->inner.environment_scale(c->inner.ctx, env, v, wi, s, t, add);
}
static float counted_light(void *ctx, const iris_shading_point *sp) {
  const counted_guide *c = ctx;
  return c->inner.light_probability(c->inner.ctx, sp);
}

static iris_direction_sampler counting(counted_guide *c) {
  const iris_direction_sampler *g = &c->inner;
  iris_direction_sampler w = {c,
                              g->sample ? counted_sample : NULL,
                              g->pdf ? counted_pdf : NULL,
                              g->prepare ? counted_prepare : NULL,
                              g->radiance_estimate ? counted_radiance : NULL,
                              g->prefetch ? counted_prefetch : NULL,
                              g->sample_environment ? counted_environment : NULL,
                              g->environment_scale ? counted_scale : NULL,
                              g->light_probability ? counted_light : NULL,
                              NULL,   /* the opening and the sky's window are read before the race, */
                              NULL};  /* not during it */
  return w;
}

typedef struct race_thread {
  iris_path_stats stats;
  uint64_t prepares, calls;
  char pad[64];
} race_thread;

typedef struct race_ctx {
  const iris_integrator *it;
  const iris_pinhole *cam;
  uint64_t seed;
  int stride, cols; /* the grid: pixel (stride i + stride/2, stride j + stride/2) */
  uint64_t s0, s1;    /* the round's sample indices */
  double *sum, *sum2; /* 3 per race pixel */
  race_thread *threads;
} race_ctx;

static void race_pixels(void *vctx, uint64_t begin, uint64_t end, int thread) {
  race_ctx *c = vctx;
  iris_path_stats local = {0};
  const uint64_t p0 = tl_prepares, c0 = tl_calls;
  const int half = c->stride / 2;
  for (uint64_t i = begin; i < end; i++) {
    int x = (int)(i % (uint64_t)c->cols) * c->stride + half;
    int y = (int)(i / (uint64_t)c->cols) * c->stride + half;
    double s[3], s2[3];
    memcpy(s, &c->sum[3 * i], sizeof s);
    memcpy(s2, &c->sum2[3 * i], sizeof s2);
    for (uint64_t k = c->s0; k < c->s1; k++) {
      iris_vec3 L = iris_camera_path(c->it, c->cam, c->seed, x, y, k, &local);
      const double v[3] = {L.x, L.y, L.z};
      for (int ch = 0; ch < 3; ch++) {
        s[ch] += v[ch];
        s2[ch] += v[ch] * v[ch];
      }
    }
    memcpy(&c->sum[3 * i], s, sizeof s);
    memcpy(&c->sum2[3 * i], s2, sizeof s2);
  }
  iris_path_stats_add(&c->threads[thread].stats, &local);
  c->threads[thread].prepares += tl_prepares - p0;
  c->threads[thread].calls += tl_calls - c0;
}

static int cmp_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

void iris_race_neighbour_mean(const double *means, int cols, int rows, int x, int y, double ref[3]) {
  int nb = 0;
  ref[0] = ref[1] = ref[2] = 0.0;
  for (int dy = -1; dy <= 1; dy++)
    for (int dx = -1; dx <= 1; dx++) {
      const int xx = x + dx, yy = y + dy;
      if ((dx == 0 && dy == 0) || xx < 0 || yy < 0 || xx >= cols || yy >= rows) continue;
      const double *b = means + 3 * ((size_t)yy * (size_t)cols + (size_t)xx);
      for (int ch = 0; ch < 3; ch++) ref[ch] += b[ch];
      nb++;
    }
  const double *self = means + 3 * ((size_t)y * (size_t)cols + (size_t)x);
  for (int ch = 0; ch < 3; ch++) ref[ch] = nb > 0 ? ref[ch] / nb : self[ch];
}

double iris_race_term(const double var[3], const double ref[3]) {
  double r = 0.0;
  for (int ch = 0; ch < 3; ch++) r += var[ch] / (ref[ch] * ref[ch] + 0.01);
  return r / 3.0;
}

double iris_race_trimmed_mean(double *terms, size_t n, double *tail_share) {
  const size_t keep = n - (size_t)(IRIS_RACE_TRIM * (double)n);
  qsort(terms, n, sizeof *terms, cmp_double);
  double kept = 0.0, all = 0.0;
  for (size_t i = 0; i < n; i++) {
    if (i < keep) kept += terms[i];
    all += terms[i];
  }
  if (tail_share) *tail_share = all > 0.0 ? 1.0 - kept / all : 0.0;
  return keep > 0 ? kept / (double)keep : 0.0;
}

static double luminance(const double *v) { return 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2]; }

bool iris_race_scene_has_smooth_lobes(const iris_scene *s) {
  const float smooth = IRIS_BSDF_MIN_ROUGHNESS;
  for (size_t i = 0; s && i < s->material_count; i++) {
    const iris_material *m = &s->materials[i];
    switch (m->type) {
      case IRIS_MATERIAL_GLOSSY:
      case IRIS_MATERIAL_GLASS:
        if (m->roughness <= smooth) return true;
        break;
      case IRIS_MATERIAL_GLTF: /* a roughness texture may hold smooth texels */
        if (m->roughness <= smooth || m->metallic_roughness_texture >= 0) return true;
        if (m->clearcoat > 0.0f && (m->clearcoat_roughness <= smooth || m->clearcoat_roughness_texture >= 0))
          return true;
        break;
      default: break;
    }
  }
  return false;
}

/* A few pixels hold the variance and the scene has smooth lobes (below). */
static bool race_unmeasurable(const iris_race_outcome *o, const iris_scene *scene) {
  const double tail = o->tail_share[0] > o->tail_share[1] ? o->tail_share[0] : o->tail_share[1];
  return tail > IRIS_RACE_TAIL_MAX && iris_race_scene_has_smooth_lobes(scene);
}

/* log(speedup) in standard errors; +-infinity where a racer has no variance
 * at all (the other wins), 0 where neither has. */
static double race_z(const iris_race_outcome *o) {
  const double ls = log(o->speedup), se = o->log_speedup_se;
  if (!isfinite(ls) || ls == 0.0) return ls;
  return se > 0.0 ? ls / se : (ls > 0.0 ? INFINITY : -INFINITY);
}

/* Group of a race pixel for the jackknife: 16 interleaved 4 x 4 lattices, each
 * spread over the whole frame. */
#define RACE_GROUPS 16
static int race_group(uint64_t i, int cols) {
  const int x = (int)(i % (uint64_t)cols), y = (int)(i / (uint64_t)cols);
  return (x & 3) + 4 * (y & 3);
}

/* The race's statistics from the sums in `buf` (spp paths per pixel):
 * relative variances, light, cost, speedup and the jackknife standard error of
 * log(speedup) over RACE_GROUPS pixel groups (the cost taken as exact: it is a
 * count over every path). `scratch` holds 6 n doubles. */
static void race_measure(const double *buf, uint64_t n, int cols, int rows, uint64_t spp, double *scratch,
                         iris_race_outcome *out) {
  const double k = (double)spp;
  double *both = scratch, *terms = both + 3 * n, *sorted = terms + 2 * n; /* sorted: n */
  for (uint64_t i = 0; i < 3 * n; i++) {
    const uint64_t px = i / 3, ch = i % 3;
    both[i] = 0.5 * (buf[3 * px + ch] + buf[6 * n + 3 * px + ch]) / k; /* sums of mis, of guided-nee */
  }
  double light[2] = {0, 0}, dvar = 0.0;
  for (uint64_t i = 0; i < n; i++) {
    double ref[3];
    iris_race_neighbour_mean(both, cols, rows, (int)(i % (uint64_t)cols), (int)(i / (uint64_t)cols), ref);
    for (int m = 0; m < 2; m++) {
      const double *s = buf + 6 * n * (uint64_t)m + 3 * i, *s2 = s + 3 * n;
      double mean[3], var[3];
      for (int ch = 0; ch < 3; ch++) {
        mean[ch] = s[ch] / k;
        double v = (s2[ch] - s[ch] * s[ch] / k) / (k - 1.0);
        var[ch] = v > 0.0 ? v : 0.0;
      }
      terms[(uint64_t)m * n + i] = iris_race_term(var, ref);
      light[m] += luminance(mean);
      dvar += luminance(var) / k; /* the luminance's variance, channels taken as independent: a bound */
    }
  }
  /* as iris bench's relMSE, the 0.1% largest pixel terms left out; per group,
   * the kept terms' sums and counts (the cut-off is the whole race's) */
  double gsum[2][RACE_GROUPS] = {{0}}, gcount[2][RACE_GROUPS] = {{0}};
  for (int m = 0; m < 2; m++) {
    const double *t = terms + (uint64_t)m * n;
    memcpy(sorted, t, n * sizeof *sorted);
    out->relvar[m] = iris_race_trimmed_mean(sorted, n, &out->tail_share[m]);
    const size_t keep = n - (size_t)(IRIS_RACE_TRIM * (double)n);
    const double cut = keep > 0 ? sorted[keep - 1] : -1.0;
    size_t kept = 0;
    for (uint64_t i = 0; i < n && kept < keep; i++)
      if (t[i] <= cut) {
        const int g = race_group(i, cols);
        gsum[m][g] += t[i];
        gcount[m][g] += 1.0;
        kept++;
      }
  }
  const double paths = (double)n * k;
  for (int m = 0; m < 2; m++) {
    out->light[m] = light[m] / (double)n;
    out->cost[m] = ((double)out->rays[m] + IRIS_RACE_COST_SHADOW * (double)out->shadow_rays[m] +
                    IRIS_RACE_COST_PREPARE * (double)out->prepares[m] +
                    IRIS_RACE_COST_GUIDE_CALL * (double)out->guide_calls[m]) /
                   paths;
  }
  out->short_z = dvar > 0.0 ? (light[1] - light[0]) / sqrt(dvar) : 0.0;
  const double work[2] = {out->relvar[0] * out->cost[0], out->relvar[1] * out->cost[1]};
  out->speedup = work[1] > 0.0 ? work[0] / work[1] : (work[0] > 0.0 ? INFINITY : 1.0);
  /* jackknife over the groups: log of the speedup without group g */
  double all[2][2] = {{0}};
  for (int m = 0; m < 2; m++)
    for (int g = 0; g < RACE_GROUPS; g++) {
      all[m][0] += gsum[m][g];
      all[m][1] += gcount[m][g];
    }
  double l[RACE_GROUPS], lmean = 0.0;
  int used = 0;
  for (int g = 0; g < RACE_GROUPS; g++) {
    double v[2];
    bool ok = true;
    for (int m = 0; m < 2; m++) {
      const double c = all[m][1] - gcount[m][g], sm = all[m][0] - gsum[m][g];
      v[m] = c > 0.0 ? sm / c : 0.0;
      ok = ok && v[m] > 0.0;
    }
    if (!ok || gcount[0][g] + gcount[1][g] == 0.0) continue;
    l[used] = log(v[0] * out->cost[0] / (v[1] * out->cost[1]));
    lmean += l[used++];
  }
  double se = INFINITY;
  if (used >= 2) {
    lmean /= used;
    double ss = 0.0;
    for (int g = 0; g < used; g++) ss += (l[g] - lmean) * (l[g] - lmean);
    se = sqrt((double)(used - 1) / used * ss);
  }
  out->log_speedup_se = se;
}

iris_status iris_method_race(const iris_integrator *mis, const iris_integrator *guided, const iris_pinhole *cam,
                             uint64_t seed, int threads, double time_cap, iris_race_outcome *out, char *why,
                             size_t why_size, iris_error *err) {
  memset(out, 0, sizeof *out);
  if (threads < 1) threads = 1;
  /* the grid covers the whole frame, whatever window is rendered: every part
   * of a partitioned render runs the same race and makes the same choice */
  int stride = (int)floor(sqrt((double)cam->width * (double)cam->height / IRIS_RACE_PIXELS));
  if (stride < 1) stride = 1;
  const int cols = (cam->width + stride - 1 - stride / 2) / stride, rows = (cam->height + stride - 1 - stride / 2) / stride;
  const uint64_t n = (uint64_t)cols * (uint64_t)rows;
  /* small frames: more paths per pixel, the same paths in all */
  uint64_t spp = (IRIS_RACE_PATHS + n - 1) / n;
  if (spp < IRIS_RACE_SPP) spp = IRIS_RACE_SPP;
  if (spp > IRIS_RACE_SPP_MAX) spp = IRIS_RACE_SPP_MAX;
  const uint64_t spp_max = IRIS_RACE_EXTEND * spp;
  double *buf = calloc(12 * n, sizeof *buf), *scratch = calloc(6 * n, sizeof *scratch);
  race_thread *per = calloc((size_t)threads, sizeof *per);
  if (!buf || !per || !scratch) {
    free(buf);
    free(scratch);
    free(per);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory (the method race)");
  }
  counted_guide cg = {guided->guide};
  iris_integrator counted = *guided;
  counted.guide = counting(&cg);
  /* an independent sampler: the race measures the variance of one path */
  iris_integrator race_its[2] = {*mis, counted};
  for (int m = 0; m < 2; m++) race_its[m].sampler = IRIS_SAMPLER_INDEPENDENT;
  /* rounds of IRIS_RACE_ROUND_SPP paths per pixel, the methods in turn, until
   * spp; then on, up to spp_max, while the speedup is within
   * IRIS_RACE_DECISIVE_Z standard errors of 1 (a decision by the statistics
   * alone: the same on any thread count); under a time cap also until the
   * race has used it (after one round) */
  const double t0 = iris_time_now();
  uint64_t done = 0, measured = 0; /* the paths per pixel `out` was measured at */
  while (done < spp_max) {
    const uint64_t r = done < spp && spp - done < IRIS_RACE_ROUND_SPP ? spp - done : IRIS_RACE_ROUND_SPP;
    for (int m = 0; m < 2; m++) {
      memset(per, 0, (size_t)threads * sizeof *per);
      race_ctx c = {&race_its[m], cam, iris_hash4(seed, 0x7ace, (uint64_t)m, 31), stride, cols, done, done + r,
                    buf + 6 * n * (uint64_t)m, buf + 6 * n * (uint64_t)m + 3 * n, per};
      double t = iris_time_now();
      iris_parallel_for(n, 16, threads, race_pixels, &c);
      out->seconds[m] += iris_time_now() - t;
      for (int i = 0; i < threads; i++) {
        out->rays[m] += per[i].stats.rays;
        out->shadow_rays[m] += per[i].stats.shadow_rays;
        out->prepares[m] += per[i].prepares;
        out->guide_calls[m] += per[i].calls;
      }
      if (iris_cancel_requested()) {
        free(buf);
        free(scratch);
        free(per);
        return iris_cancel_error(err);
      }
    }
    done += r;
    if (time_cap > 0.0 && iris_time_now() - t0 >= time_cap) break;
    if (done < spp) continue;
    race_measure(buf, n, cols, rows, done, scratch, out);
    measured = done;
    if (fabs(race_z(out)) >= IRIS_RACE_DECISIVE_Z ||
        fabs(out->short_z) > IRIS_RACE_SHORT_Z || race_unmeasurable(out, mis->scene))
      break;
  }
  if (measured != done) race_measure(buf, n, cols, rows, done, scratch, out);
  out->paths = n * done;
  out->base_paths = n * (done < spp ? done : spp);
  free(buf);
  free(scratch);
  free(per);
  const double *light = out->light;
  const double shortfall = light[1] > 0.0 ? 1.0 - light[0] / light[1] : 0.0;
  const int tailed = out->tail_share[0] >= out->tail_share[1] ? 0 : 1;
  if (race_unmeasurable(out, mis->scene)) {
    /* a few pixels hold the variance, light arriving off smooth surfaces: the race
     * cannot measure it (sky-room-glazed: untrimmed ratios from 0.02x to 16x between
     * seeds); the rules' guided-nee stands. Without smooth lobes the trimmed
     * statistic is the bench's own and decides (office: 34-52% in the tail). */
    out->guided = true;
    out->unmeasurable = true;
    snprintf(why, why_size, "the race cannot tell: %.2g%% of its pixels hold %.0f%% of %s's variance; the photon rules' choice stands",
             100.0 * IRIS_RACE_TRIM, 100.0 * out->tail_share[tailed], tailed ? "guided-nee" : "mis");
  } else if (out->short_z > IRIS_RACE_SHORT_Z) {
    out->guided = true;
    snprintf(why, why_size, "the race: mis found %.0f%% less light than guided-nee (%.1f standard errors): paths too rare to measure",
             100.0 * shortfall, out->short_z);
  } else if (out->short_z < -IRIS_RACE_SHORT_Z) {
    out->guided = false;
    snprintf(why, why_size, "the race: guided-nee found %.0f%% less light than mis (%.1f standard errors): paths too rare to measure",
             100.0 * (light[0] > 0.0 ? 1.0 - light[1] / light[0] : 0.0), -out->short_z);
  } else {
    /* guided-nee must win by IRIS_RACE_MARGIN_Z standard errors: where the two
     * are level within the race's noise, mis (stress-glossy-room's race
     * measured 0.6-1.5x over seeds where long renders give 0.65-0.82x) */
    const double z = race_z(out);
    out->guided = z > IRIS_RACE_MARGIN_Z;
    snprintf(why, why_size, "the race: guided-nee %.2fx mis per unit of work, %.1f standard errors%s (relative variance %.3g against %.3g, cost %.1f against %.1f rays per path)",
             out->speedup, z, out->speedup > 1.0 && !out->guided ? ": not enough to leave mis" : "",
             out->relvar[1], out->relvar[0], out->cost[1], out->cost[0]);
  }
  return IRIS_OK;
}
