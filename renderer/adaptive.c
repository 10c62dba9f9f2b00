/* Adaptive sampling rounds (renderer/adaptive.h). */
#include "renderer/adaptive.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/cancel.h"
#include "core/log.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "renderer/camera_path.h"
#include "renderer/light_trace.h"

#define TILE 8
#define SQRT_2_OVER_PI 0.79788456080286535588 /* E|Z| of a standard normal */
/* Cycles 3.4 multiplies the user's noise threshold by 5 before comparing
 * (intern/cycles/scene/integrator.cpp, get_adaptive_sampling). */
#define CYCLES_THRESHOLD_SCALE 5.0
/* Scouts: at least this many per pixel, and an eighth of what the pixel's
 * own target asks for, so that scouting costs about 1/9 of the samples once
 * past the first round. (16 first-round scouts cost a third of a 4-second
 * sky-room render and bought nothing: measured, docs/rendering.md.) */
#define SCOUT_MIN 8
#define SCOUT_SHARE 8
/* Seed of the scout samples: a stream of their own, independent of the image's. */
#define SCOUT_SALT 0x5c0a75ULL
/* The first rounds: at least this many paths each, so that threads keep busy. */
#define ROUND_PATHS (1u << 17)
/* Deciding from the neighbours: the frame's pixels get ranks 0..RANKS-1 on a
 * 3x3 lattice, and a pixel's count comes from the image samples of the
 * pixels of higher rank within RANK_REACH of it (renderer/adaptive.h). */
#define RANKS 9
#define RANK_REACH 2

static const char *const RULE_NAMES[IRIS_ADAPTIVE_RULE_COUNT] = {"off", "freeze", "relmse"};

const char *iris_adaptive_rule_name(iris_adaptive_rule r) {
  return (unsigned)r < IRIS_ADAPTIVE_RULE_COUNT ? RULE_NAMES[r] : "?";
}

bool iris_adaptive_rule_parse(const char *s, iris_adaptive_rule *out) {
  for (int i = 0; i < IRIS_ADAPTIVE_RULE_COUNT; i++)
    if (strcmp(s, RULE_NAMES[i]) == 0) {
      *out = (iris_adaptive_rule)i;
      return true;
    }
  return false;
}

const char *iris_adaptive_stop_name(const iris_adaptive_outcome *o) {
  return o->reached_target ? "target" : o->converged ? "threshold" : o->interrupted ? "interrupted" : "cap";
}

int iris_adaptive_auto_min_spp(double t) {
  if (!(t > 0.0)) t = 0.01;
  int m = (int)ceil(16.0 / pow(t, 0.3));
  return m < 4 ? 4 : m;
}

double iris_adaptive_cycles_error(const double mean[3], const double var_of_mean[3]) {
  double d = 0.0, s = 0.0;
  for (int c = 0; c < 3; c++) {
    d += sqrt(var_of_mean[c] > 0.0 ? var_of_mean[c] : 0.0);
    s += mean[c];
  }
  return SQRT_2_OVER_PI * d / (1e-4 + sqrt(s > 0.0 ? s : 0.0));
}

/* Mean and per-sample variance of a film pixel (index i). */
static void pixel_stats(const iris_film *f, size_t i, double mean[3], double var[3]) {
  double n = f->count[i];
  for (int c = 0; c < 3; c++) {
    double mu = n > 0 ? f->sum[3 * i + c] / n : 0.0;
    double s2 = n > 1 ? (f->sum2[3 * i + c] - n * mu * mu) / (n - 1.0) : 0.0;
    mean[c] = mu;
    var[c] = s2 > 0.0 ? s2 : 0.0;
  }
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

double iris_adaptive_film_error(const iris_film *film) {
  size_t n = (size_t)film->width * (size_t)film->height;
  if (n == 0) return 0.0;
  double *e = malloc(n * sizeof *e);
  if (!e) return -1.0;
  for (size_t i = 0; i < n; i++) {
    double m[3], v[3], r = 0.0;
    pixel_stats(film, i, m, v);
    double cnt = film->count[i];
    if (cnt > 1)
      for (int c = 0; c < 3; c++) r += v[c] / cnt / (m[c] * m[c] + IRIS_ADAPTIVE_EPS);
    e[i] = r / 3.0;
  }
  qsort(e, n, sizeof *e, cmp_double);
  size_t keep = n - (size_t)floor(IRIS_ADAPTIVE_DROP * (double)n);
  double s = 0.0;
  for (size_t i = 0; i < keep; i++) s += e[i];
  free(e);
  return keep ? s / (double)keep : 0.0;
}

/* ---- sample passes ---------------------------------------------------------- */

typedef struct pass_ctx {
  const iris_integrator *it;
  const iris_pinhole *cam;
  iris_film *film;
  uint64_t seed, offset;
  int x0, y0, x1, y1; /* the film's window */
  int tiles_x;
  const uint32_t *take;  /* samples to add per film pixel */
  const uint32_t *first; /* first sample index per film pixel (before offset) */
  iris_path_stats *stats;
} pass_ctx;

static void pass_tiles(void *vctx, uint64_t begin, uint64_t end, int thread) {
  pass_ctx *c = (pass_ctx *)vctx;
  iris_path_stats local = {0};
  const int fw = c->x1 - c->x0;
  for (uint64_t t = begin; t < end; t++) {
    /* a stop request ends a round within a tile (rounds can be long); the
     * counts stay true, and a count cut by a signal is no function of the
     * samples, so the image stays unbiased */
    if (iris_cancel_requested()) break;
    int tx = c->x0 + (int)(t % (uint64_t)c->tiles_x) * TILE;
    int ty = c->y0 + (int)(t / (uint64_t)c->tiles_x) * TILE;
    for (int y = ty; y < ty + TILE && y < c->y1; y++)
      for (int x = tx; x < tx + TILE && x < c->x1; x++) {
        size_t i = (size_t)(y - c->y0) * (size_t)fw + (size_t)(x - c->x0);
        uint64_t s0 = c->offset + c->first[i];
        for (uint64_t s = s0; s < s0 + c->take[i]; s++)
          iris_film_add(c->film, x - c->x0, y - c->y0, iris_camera_path(c->it, c->cam, c->seed, x, y, s, &local));
      }
  }
  iris_path_stats_add(&c->stats[thread], &local);
}

static void run_pass(pass_ctx *c, int threads) {
  c->tiles_x = (c->x1 - c->x0 + TILE - 1) / TILE;
  int tiles_y = (c->y1 - c->y0 + TILE - 1) / TILE;
  uint64_t tiles = (uint64_t)c->tiles_x * (uint64_t)tiles_y;
  iris_parallel_for(tiles, 1, threads, pass_tiles, c);
}

/* ---- the rounds ------------------------------------------------------------- */

typedef struct state {
  const iris_adaptive_job *job;
  int W, H;              /* image window */
  int hx0, hy0, hx1, hy1; /* scout window: the image window and a 1-pixel halo inside the frame */
  int HW, HH;
  iris_film scout;
  uint32_t *scout_take, *scout_first;
  uint32_t *take, *first;
  double *need;     /* per scout pixel: samples its threshold asks for (freeze, threshold) */
  double *weight;   /* per scout pixel: sqrt(sum_c var_c / (mean_c^2 + eps) / 3) */
  double *target;   /* per image pixel: this round's target count */
  uint32_t train;   /* training samples every film pixel held at the start */
  int min_spp;
  bool neighbours;  /* decide from higher-ranked pixels' image samples, no scouts */
  uint32_t *order;  /* deciding from the neighbours: image pixels by rank, */
  size_t rank_start[RANKS + 1]; /* rank r at order[rank_start[r] .. rank_start[r + 1]) */
  uint64_t light_owed; /* light tracing: image paths times paths per index, not yet traced (x window pixels) */
  iris_status light_status;
  iris_error *err;
} state;

/* Rank of full-frame pixel (x, y): its place on a 3x3 lattice. */
static int rank_of(int x, int y) { return x % 3 + 3 * (y % 3); }

/* The statistics the decisions are made from at scout-window pixel (hx, hy):
 * the scouts', or the image's (deciding from the neighbours, or, for the
 * biased test variant, on the pixel's own samples; a halo pixel outside the
 * window reads the nearest image pixel, which the neighbours' pooling never
 * uses: pool3 keeps to the window). */
static void decision_stats(const state *s, int hx, int hy, double mean[3], double var[3], double *n) {
  const iris_adaptive_job *j = s->job;
  if (s->neighbours || j->params.decide_on_image) {
    int x = hx + s->hx0 - j->x0, y = hy + s->hy0 - j->y0;
    if (x < 0) x = 0;
    if (y < 0) y = 0;
    if (x >= s->W) x = s->W - 1;
    if (y >= s->H) y = s->H - 1;
    size_t i = (size_t)y * (size_t)s->W + (size_t)x;
    pixel_stats(j->film, i, mean, var);
    *n = j->film->count[i];
    return;
  }
  size_t i = (size_t)hy * (size_t)s->HW + (size_t)hx;
  pixel_stats(&s->scout, i, mean, var);
  *n = s->scout.count[i];
}

/* need and weight of every scout pixel from its own statistics alone. */
static void per_pixel_needs(state *s) {
  const double T = s->job->params.noise_threshold;
  for (int y = 0; y < s->HH; y++)
    for (int x = 0; x < s->HW; x++) {
      double m[3], v[3], n;
      decision_stats(s, x, y, m, v, &n);
      size_t i = (size_t)y * (size_t)s->HW + (size_t)x;
      double w = 0.0, sd = 0.0, sum = 0.0;
      for (int c = 0; c < 3; c++) {
        w += v[c] / (m[c] * m[c] + IRIS_ADAPTIVE_EPS);
        sd += sqrt(v[c]);
        sum += m[c];
      }
      s->weight[i] = sqrt(w / 3.0);
      if (T > 0.0) {
        /* Cycles' error at N samples, sqrt(2/pi) sd / sqrt(N) / (1e-4 + sqrt(sum)),
         * below 5 T */
        double k = SQRT_2_OVER_PI * sd / (CYCLES_THRESHOLD_SCALE * T * (1e-4 + sqrt(sum > 0 ? sum : 0)));
        s->need[i] = k * k;
      } else {
        s->need[i] = INFINITY;
      }
    }
}

/* A scout-pixel field pooled around image pixel (x, y): its maximum, or its
 * root mean square (`rms`), over the 3x3 neighbourhood inside the scout
 * window. Deciding from the neighbours: over the image pixels of higher rank
 * within RANK_REACH inside the window (never the pixel itself, nor a pixel
 * whose count depends on its samples); -1 where there are none (the top
 * rank, or a tiny window). */
static double pool3(const state *s, const double *f, int x, int y, bool rms) {
  int hx = x + s->job->x0 - s->hx0, hy = y + s->job->y0 - s->hy0;
  const int reach = s->neighbours ? RANK_REACH : 1;
  const int rank = rank_of(x + s->job->x0, y + s->job->y0);
  double m = 0.0;
  int k = 0;
  for (int dy = -reach; dy <= reach; dy++)
    for (int dx = -reach; dx <= reach; dx++) {
      int qx = hx + dx, qy = hy + dy;
      if (qx < 0 || qy < 0 || qx >= s->HW || qy >= s->HH) continue;
      if (s->neighbours && (x + dx < 0 || y + dy < 0 || x + dx >= s->W || y + dy >= s->H ||
                            rank_of(x + dx + s->job->x0, y + dy + s->job->y0) <= rank))
        continue;
      double v = f[(size_t)qy * (size_t)s->HW + (size_t)qx];
      if (rms)
        m += v * v;
      else if (v > m)
        m = v;
      k++;
    }
  if (s->neighbours && k == 0) return -1.0;
  return !rms ? m : k ? sqrt(m / k) : 0.0;
}

/* Sum over the pixels of `rank` (-1: all) of what targets C * weight
 * (clamped) would add. */
static double relmse_added(const state *s, double C, const double *cap_need, int rank) {
  const iris_adaptive_job *j = s->job;
  double add = 0.0;
  size_t n = (size_t)s->W * (size_t)s->H;
  size_t a = rank >= 0 ? s->rank_start[rank] : 0, b = rank >= 0 ? s->rank_start[rank + 1] : n;
  for (size_t k = a; k < b; k++) {
    size_t i = rank >= 0 ? s->order[k] : k;
    double t = C * s->target[i]; /* target[] holds the pooled weight here */
    if (t < s->min_spp) t = s->min_spp;
    if (cap_need && t > cap_need[i]) t = cap_need[i];
    if (t > j->spp_cap) t = j->spp_cap;
    double have = j->film->count[i];
    if (t > have) add += t - have;
  }
  return add;
}

/* This round's targets (s->target, whole samples) for a round of at most
 * `budget` samples (<= 0: no limit, the threshold decides). Returns the
 * samples the round will take. */
static double plan_round(state *s, double budget, double *cmul) {
  const iris_adaptive_job *j = s->job;
  const iris_adaptive_params *p = &j->params;
  size_t n = (size_t)s->W * (size_t)s->H;
  per_pixel_needs(s);
  double *need3 = NULL;
  if (p->noise_threshold > 0.0) {
    need3 = malloc(n * sizeof *need3);
    if (!need3) return -1.0;
    for (int y = 0; y < s->H; y++)
      for (int x = 0; x < s->W; x++) {
        double t = pool3(s, s->need, x, y, false);
        if (t < 0.0) t = INFINITY; /* nothing to decide from: no cap but spp_cap */
        need3[(size_t)y * (size_t)s->W + (size_t)x] = t < s->min_spp ? s->min_spp : ceil(t);
      }
  }
  if (p->rule == IRIS_ADAPTIVE_FREEZE) {
    for (size_t i = 0; i < n; i++) s->target[i] = need3 ? need3[i] : j->spp_cap;
  } else {
    for (int y = 0; y < s->H; y++)
      for (int x = 0; x < s->W; x++) s->target[(size_t)y * (size_t)s->W + (size_t)x] = pool3(s, s->weight, x, y, true);
    /* Deciding from the neighbours, a pixel with nothing to decide from (the
     * top rank: uniform) takes its rank's mean weight, and each rank has its
     * own share of the budget and its own C: one C over all pixels would hang
     * a pixel's count on its own samples through the other ranks' targets. */
    const int ranks = s->neighbours ? RANKS : 1;
    for (int r = 0; r < ranks && s->neighbours; r++) {
      double sum = 0.0;
      size_t k = 0;
      for (size_t q = s->rank_start[r]; q < s->rank_start[r + 1]; q++)
        if (s->target[s->order[q]] >= 0.0) sum += s->target[s->order[q]], k++;
      const double fill = k && sum > 0.0 ? sum / (double)k : 1.0;
      for (size_t q = s->rank_start[r]; q < s->rank_start[r + 1]; q++)
        if (s->target[s->order[q]] < 0.0) s->target[s->order[q]] = fill;
    }
    /* the largest C whose targets fit the budget (bisection) */
    double cs[RANKS];
    for (int r = 0; r < RANKS; r++) cs[r] = 1e30; /* no budget: the threshold alone caps */
    for (int r = 0; r < ranks && budget > 0.0; r++) {
      const int which = s->neighbours ? r : -1;
      const double members = which < 0 ? (double)n : (double)(s->rank_start[r + 1] - s->rank_start[r]);
      const double b = budget * members / (double)n;
      if (!(members > 0)) continue;
      double lo = 0.0, hi = 1.0;
      while (relmse_added(s, hi, need3, which) < b && hi < 1e30) hi *= 4.0;
      for (int it = 0; it < 60; it++) {
        double mid = 0.5 * (lo + hi);
        if (relmse_added(s, mid, need3, which) <= b)
          lo = mid;
        else
          hi = mid;
      }
      cs[r] = lo;
    }
    *cmul = cs[0];
    for (int r = 0; r < ranks; r++) { /* each rank's pixels, or (one rank) all */
      const size_t a = s->neighbours ? s->rank_start[r] : 0, b = s->neighbours ? s->rank_start[r + 1] : n;
      for (size_t q = a; q < b; q++) {
        const size_t i = s->neighbours ? s->order[q] : q;
        double t = cs[r] * s->target[i];
        if (t < s->min_spp) t = s->min_spp;
        if (need3 && t > need3[i]) t = need3[i];
        s->target[i] = t;
      }
    }
  }
  double total = 0.0;
  for (size_t i = 0; i < n; i++) {
    double t = s->target[i];
    if (t > j->spp_cap) t = j->spp_cap;
    t = floor(t);
    double have = j->film->count[i];
    /* at most double a pixel per round: early scouts are few */
    double step = have > s->min_spp ? have : s->min_spp;
    double k = t > have ? t - have : 0.0;
    if (k > step) k = step;
    s->take[i] = (uint32_t)k;
    s->first[i] = j->film->count[i] - s->train;
    total += k;
  }
  free(need3);
  return total;
}

/* Scouts up to max(SCOUT_MIN, own need / SCOUT_SHARE) per scout pixel. */
static double plan_scouts(state *s, double cmul) {
  const iris_adaptive_job *j = s->job;
  size_t n = (size_t)s->HW * (size_t)s->HH;
  double total = 0.0;
  int cap = j->spp_cap / SCOUT_SHARE;
  if (cap < SCOUT_MIN) cap = SCOUT_MIN;
  for (size_t i = 0; i < n; i++) {
    double own = j->params.rule == IRIS_ADAPTIVE_FREEZE ? s->need[i] : cmul * s->weight[i];
    if (j->params.noise_threshold > 0.0 && own > s->need[i]) own = s->need[i];
    double want = own / SCOUT_SHARE;
    if (!(want >= SCOUT_MIN)) want = SCOUT_MIN; /* also NaN */
    if (want > cap) want = cap;
    double have = s->scout.count[i];
    double k = want > have ? floor(want - have) : 0.0;
    if (k > have && have > 0) k = have; /* at most double */
    s->scout_take[i] = (uint32_t)k;
    s->scout_first[i] = s->scout.count[i];
    total += k;
  }
  return total;
}

static void run_scouts(state *s) {
  const iris_adaptive_job *j = s->job;
  pass_ctx c = {j->it, j->cam, &s->scout, iris_hash4(j->seed, SCOUT_SALT, 0, 0), j->sample_offset,
                s->hx0, s->hy0, s->hx1, s->hy1, 0, s->scout_take, s->scout_first, j->stats};
  run_pass(&c, j->threads);
}

static uint64_t total_paths(const iris_adaptive_job *j) {
  uint64_t p = 0;
  for (int i = 0; i < j->threads; i++) p += j->stats[i].paths;
  return p;
}

static void run_image(state *s) {
  const iris_adaptive_job *j = s->job;
  pass_ctx c = {j->it, j->cam, j->film, j->seed, j->sample_offset, j->x0, j->y0, j->x1, j->y1, 0,
                s->take, s->first, j->stats};
  const uint64_t before = total_paths(j);
  run_pass(&c, j->threads);
  iris_light_trace *lt = j->light_trace;
  if (!lt || s->light_status != IRIS_OK) return;
  /* light paths per image sample as in a whole-frame render: per_index for
   * each sample of every pixel of the frame, so per_index / window pixels
   * per sample here (the remainder carried to the next round) */
  const uint64_t pixels = (uint64_t)s->W * (uint64_t)s->H;
  s->light_owed += (total_paths(j) - before) * lt->per_index;
  const uint64_t count = s->light_owed / pixels;
  s->light_owed -= count * pixels;
  s->light_status = iris_light_trace_run(lt, j->it, lt->next, count, j->film, s->err);
  lt->next += count;
}

/* The first round's image samples under a time budget: every pixel the same
 * samples, in passes of about ROUND_PATHS paths, up to the minimum or until
 * the next pass would overrun the budget (at least one pass). Returns true
 * when the budget stopped it. */
static bool uniform_passes(state *s, double t0, uint64_t *image_paths, double *sec_per_path) {
  const iris_adaptive_job *j = s->job;
  const size_t n = (size_t)s->W * (size_t)s->H;
  uint32_t chunk = (uint32_t)(ROUND_PATHS / n);
  if (chunk < 1) chunk = 1;
  for (bool first = true;; first = false) {
    const uint32_t have = j->film->count[0]; /* uniform so far */
    if (have >= (uint32_t)s->min_spp) return false;
    uint32_t c = chunk;
    if (have + c > (uint32_t)s->min_spp) c = (uint32_t)s->min_spp - have;
    double elapsed = iris_time_now() - t0;
    if (!first && elapsed + *sec_per_path * (double)c * (double)n > j->budget) return true;
    if (iris_cancel_requested()) return false; /* the round loop sees it */
    for (size_t i = 0; i < n; i++) {
      s->take[i] = c;
      s->first[i] = have - s->train;
    }
    double tr = iris_time_now();
    uint64_t before = total_paths(j);
    run_image(s);
    uint64_t done = total_paths(j) - before;
    *image_paths += done;
    if (done) *sec_per_path = (iris_time_now() - tr) / (double)done;
  }
}

static void state_free(state *s) {
  iris_film_destroy(&s->scout);
  free(s->scout_take);
  free(s->scout_first);
  free(s->take);
  free(s->first);
  free(s->need);
  free(s->weight);
  free(s->target);
  free(s->order);
}

iris_status iris_adaptive_run(const iris_adaptive_job *j, iris_adaptive_outcome *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  const iris_adaptive_params *p = &j->params;
  state s;
  memset(&s, 0, sizeof s);
  s.job = j;
  s.err = err;
  s.light_status = IRIS_OK;
  s.W = j->x1 - j->x0;
  s.H = j->y1 - j->y0;
  s.hx0 = j->x0 > 0 ? j->x0 - 1 : 0;
  s.hy0 = j->y0 > 0 ? j->y0 - 1 : 0;
  s.hx1 = j->x1 < j->cam->width ? j->x1 + 1 : j->x1;
  s.hy1 = j->y1 < j->cam->height ? j->y1 + 1 : j->y1;
  s.HW = s.hx1 - s.hx0;
  s.HH = s.hy1 - s.hy0;
  s.train = j->film->count[0];
  /* relmse under a budget (a time or a target error): decisions from the
   * image samples of the other colour, no scouts (renderer/adaptive.h) */
  s.neighbours = p->rule == IRIS_ADAPTIVE_RELMSE && !p->decide_on_image && (j->budget > 0.0 || p->target_error > 0.0);
  /* Cycles' automatic minimum with a threshold; without one (a target error
   * or a time budget deciding) the decisions start after it */
  s.min_spp = p->min_spp > 0                ? p->min_spp
              : p->noise_threshold > 0.0    ? iris_adaptive_auto_min_spp(p->noise_threshold)
                                            : IRIS_ADAPTIVE_MIN_SPP_NO_THRESHOLD;
  if (s.min_spp > j->spp_cap) s.min_spp = j->spp_cap;
  const size_t n = (size_t)s.W * (size_t)s.H, hn = (size_t)s.HW * (size_t)s.HH;
  if (!s.neighbours) {
    iris_status st = iris_film_create(&s.scout, s.HW, s.HH, err);
    if (st != IRIS_OK) return st;
  }
  s.scout_take = calloc(hn, sizeof *s.scout_take);
  s.scout_first = calloc(hn, sizeof *s.scout_first);
  s.take = calloc(n, sizeof *s.take);
  s.first = calloc(n, sizeof *s.first);
  s.need = calloc(hn, sizeof *s.need);
  s.weight = calloc(hn, sizeof *s.weight);
  s.target = calloc(n, sizeof *s.target);
  if (s.neighbours && (s.order = malloc(n * sizeof *s.order)) != NULL) {
    /* image pixels by rank (a counting sort) */
    size_t count[RANKS] = {0};
    for (int y = 0; y < s.H; y++)
      for (int x = 0; x < s.W; x++) count[rank_of(x + j->x0, y + j->y0)]++;
    s.rank_start[0] = 0;
    for (int r = 0; r < RANKS; r++) s.rank_start[r + 1] = s.rank_start[r] + count[r];
    size_t at[RANKS];
    memcpy(at, s.rank_start, sizeof at);
    for (int y = 0; y < s.H; y++)
      for (int x = 0; x < s.W; x++) s.order[at[rank_of(x + j->x0, y + j->y0)]++] = (uint32_t)((size_t)y * (size_t)s.W + (size_t)x);
  }
  if (!s.scout_take || !s.scout_first || !s.take || !s.first || !s.need || !s.weight || !s.target ||
      (s.neighbours && !s.order)) {
    state_free(&s);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory (adaptive sampling)");
  }
  const double t0 = iris_time_now();
  double sec_per_path = 0.0, cmul = 0.0;
  uint64_t scout_paths = 0, image_paths = 0;
  double error = -1.0, planned = 0.0;
  for (int round = 0;; round++) {
    if (iris_cancel_requested()) {
      out->interrupted = true;
      break;
    }
    double elapsed = iris_time_now() - t0;
    /* this round's budget in paths: the first rounds fixed, then half of
     * what was done (deciding from the neighbours, what was planned: what the
     * rounds took depends on the samples), within what the time budget still
     * allows */
    double done = s.neighbours && round > 0 ? planned : (double)image_paths;
    double budget = done / 2.0 > ROUND_PATHS || p->rounds > 0 ? done / 2.0 : ROUND_PATHS;
    if (j->budget > 0.0 && round > 0) {
      double left = j->budget - elapsed;
      double fit = sec_per_path > 0.0 ? left / sec_per_path / (s.neighbours ? 1.0 : 1.0 + 1.0 / SCOUT_SHARE) : budget;
      if (fit < 0.02 * budget + 1.0) break; /* the budget is spent */
      if (fit < budget) budget = fit;
    }
    double scout_n = 0.0;
    bool spent = false; /* the budget ran out in the first round's uniform passes */
    if (round == 0) {
      /* uniform first round: min spp of image samples and SCOUT_MIN scouts;
       * under a time budget the image samples go in uniform passes that stop
       * when the next would overrun it (counts fixed in advance: no bias) */
      if (j->budget > 0.0) spent = uniform_passes(&s, t0, &image_paths, &sec_per_path);
      for (size_t i = 0; i < n; i++) {
        uint32_t have = j->film->count[i];
        s.take[i] = have < (uint32_t)s.min_spp && !spent ? (uint32_t)s.min_spp - have : 0;
        s.first[i] = have - s.train;
      }
      for (size_t i = 0; i < hn; i++) {
        s.scout_take[i] = s.neighbours ? 0 : SCOUT_MIN;
        s.scout_first[i] = 0;
      }
      scout_n = s.neighbours ? 0.0 : (double)hn * SCOUT_MIN;
    } else {
      /* freeze and threshold-capped rounds: no path budget; relmse: the budget */
      bool budgeted = p->rule == IRIS_ADAPTIVE_RELMSE && !(p->noise_threshold > 0.0 && j->budget <= 0.0 &&
                                                           !(p->target_error > 0.0));
      double planned = plan_round(&s, budgeted ? budget : 0.0, &cmul);
      if (planned < 0.0) {
        state_free(&s);
        return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory (adaptive sampling)");
      }
      if (planned < 1.0) {
        /* nothing left to do: converged (threshold) or every pixel at the cap */
        bool capped_all = true;
        for (size_t i = 0; i < n && capped_all; i++) capped_all = j->film->count[i] >= (uint32_t)j->spp_cap;
        out->converged = !capped_all || p->noise_threshold > 0.0;
        out->capped = capped_all && !(p->noise_threshold > 0.0);
        break;
      }
      scout_n = s.neighbours ? 0.0 : plan_scouts(&s, cmul);
      if (j->budget > 0.0 && planned > budget * 1.05 && p->rule == IRIS_ADAPTIVE_FREEZE) {
        /* freeze under a time budget: scale every pixel's step down alike */
        double f = budget / planned;
        for (size_t i = 0; i < n; i++) s.take[i] = (uint32_t)ceil(s.take[i] * f);
      }
    }
    double tr = iris_time_now();
    uint64_t before = total_paths(j);
    run_image(&s);
    uint64_t mid = total_paths(j);
    if (!p->decide_on_image && scout_n > 0.0 && !spent) run_scouts(&s);
    uint64_t after = total_paths(j);
    image_paths += mid - before;
    scout_paths += after - mid;
    planned = round == 0 ? (double)image_paths : planned + budget;
    if (s.light_status != IRIS_OK) {
      state_free(&s);
      return s.light_status;
    }
    double dt = iris_time_now() - tr;
    if (after > before) sec_per_path = dt / (double)(after - before);
    out->rounds = round + 1;
    error = iris_adaptive_film_error(j->film);
    size_t active = 0;
    for (size_t i = 0; i < n; i++) active += s.take[i] > 0;
    if (j->progress) {
      double spp = 0.0;
      for (size_t i = 0; i < n; i++) spp += j->film->count[i];
      iris_adaptive_progress pr = {round + 1, spp / (double)n, (double)active / (double)n, error,
                                   iris_time_now() - t0, -1.0};
      if (j->budget > 0.0) pr.eta = j->budget - pr.elapsed > 0 ? j->budget - pr.elapsed : 0.0;
      j->progress(j->progress_ctx, &pr);
    }
    if (p->target_error > 0.0 && error >= 0.0 && error <= p->target_error) {
      out->reached_target = true;
      break;
    }
    if (spent || (p->rounds > 0 && round >= p->rounds)) break;
  }
  out->error_estimate = error >= 0.0 ? error : iris_adaptive_film_error(j->film);
  double spp = 0.0;
  out->spp_min = INT32_MAX;
  for (size_t i = 0; i < n; i++) {
    uint32_t c = j->film->count[i];
    spp += c;
    if ((int)c < out->spp_min) out->spp_min = (int)c;
    if ((int)c > out->spp_max) out->spp_max = (int)c;
  }
  out->spp_mean = spp / (double)n;
  double sc = 0.0;
  for (size_t i = 0; i < hn && s.scout.count; i++) sc += s.scout.count[i];
  out->scout_spp_mean = sc / (double)hn;
  out->paths = image_paths + scout_paths;
  out->scout_paths = scout_paths;
  if (!out->reached_target && !out->converged && !out->interrupted) out->capped = true;
  state_free(&s);
  return IRIS_OK;
}
