/* Adaptive sampling: image passes that give each pixel the samples its own
 * noise needs (docs/rendering.md, "Adaptive sampling").
 *
 * Rounds. Every round first decides each pixel's target sample count, then
 * renders the missing samples of the pixels below their target. No pixel's
 * count is decided from its own image samples, so its mean stays an unbiased
 * estimate (stopping a pixel on its own noisy estimate, as Cycles does, is
 * not: `decide_on_image` does that, for the tests that show the bias). The
 * decisions come from one of two sources:
 * - scouts (a noise threshold alone, or the freeze rule): uniform samples
 *   with a seed of their own that never enter the image, taken after each
 *   round over the window and a 1-pixel halo, about 1/9 of the samples; a
 *   window then decides as the whole frame does;
 * - the neighbours (relmse under a budget: a time or a target error): each
 *   full-frame pixel has a rank 0..8, its place on a 3x3 lattice, and its
 *   target comes from the image samples of the pixels of higher rank within
 *   2 pixels inside the window; the top rank, with none above it, samples
 *   uniformly. Counts then depend only on samples of higher ranks, whose
 *   counts depend only on ranks higher still: never, through any chain of
 *   rounds, on the pixel's own samples. (Two colours, each deciding from the
 *   other, are biased: a firefly raises its neighbours' counts, their larger
 *   counts raise its own in the next round, and the firefly is diluted;
 *   render.adaptive measured it.) Each rank has its own share of each
 *   round's budget and its own multiplier, and the rounds' budgets follow
 *   what was planned, not what was taken. No scouts, and the decisions see
 *   all the image samples (budgets are global, so a window never equalled
 *   the whole frame there anyway).
 *
 * Two rules set the targets:
 * - freeze (Cycles' rule): a pixel needs the samples at which its predicted
 *   Cycles error falls below the noise threshold; it keeps sampling while it
 *   or one of its 8 neighbours needs more.
 * - relmse (iris's default): each round's samples go where one more sample
 *   lowers the image's relMSE most: targets proportional to the pixel's
 *   sqrt(sum_c var_c / (mean_c^2 + eps)) pooled (root mean square) over its
 *   3x3 neighbourhood's scouts, or its higher-ranked neighbours' image
 *   samples, so
 *   that the image's estimated relMSE falls fastest; with a noise threshold,
 *   no pixel is taken past the count the threshold asks for. */
#ifndef IRIS_RENDERER_ADAPTIVE_H
#define IRIS_RENDERER_ADAPTIVE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "renderer/camera.h"
#include "renderer/film.h"
#include "renderer/integrator.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum iris_adaptive_rule {
  IRIS_ADAPTIVE_OFF = 0, /* every pixel the same samples */
  IRIS_ADAPTIVE_FREEZE,  /* Cycles' rule: stop a pixel (and its neighbours) at the threshold */
  IRIS_ADAPTIVE_RELMSE,  /* samples where they lower the image's relMSE most */
  IRIS_ADAPTIVE_RULE_COUNT
} iris_adaptive_rule;

const char *iris_adaptive_rule_name(iris_adaptive_rule r);
bool iris_adaptive_rule_parse(const char *s, iris_adaptive_rule *out);

/* Cycles 3.4's automatic minimum samples for a noise threshold:
 * max(4, ceil(16 / T^0.3)) (64 at 0.01). Without a threshold (only a target
 * error or a time budget) the minimum is IRIS_ADAPTIVE_MIN_SPP_NO_THRESHOLD. */
#define IRIS_ADAPTIVE_MIN_SPP_NO_THRESHOLD 16
int iris_adaptive_auto_min_spp(double noise_threshold);

/* Memory adaptive sampling adds per pixel of the window, at most: the scout
 * film (sums, squares, count: 52 bytes; none when deciding from the
 * neighbours) and the per-pixel plans (take, first, need, weight, target,
 * scouts' take and first: 44), for the memory estimate. */
#define IRIS_ADAPTIVE_BYTES_PER_PIXEL 96.0

/* The relMSE denominator offset and the share of largest per-pixel errors
 * dropped, as `iris bench` measures against a reference (validate/metrics.h). */
#define IRIS_ADAPTIVE_EPS 0.01
#define IRIS_ADAPTIVE_DROP 0.001

typedef struct iris_adaptive_params {
  iris_adaptive_rule rule;
  double noise_threshold; /* Cycles' scale (Blender's default 0.01); 0: none */
  int min_spp;            /* image samples every pixel gets first; 0: automatic (above) */
  double target_error;    /* stop once the image's estimated relMSE is at most this; 0: none */
  bool decide_on_image;   /* tests only: decide from the image's own samples (biased) */
  int rounds;             /* tests only: stop after this many rounds past the first, each
                             adding half the samples so far (no floor of paths); 0: none */
} iris_adaptive_params;

/* Where a round stands, for the progress line. */
typedef struct iris_adaptive_progress {
  int round;
  double spp_mean;      /* image samples per pixel so far (training samples included) */
  double active_share;  /* share of pixels that took samples in this round */
  double error_estimate; /* estimated relMSE of the image (IRIS_ADAPTIVE_EPS, DROP) */
  double elapsed, eta;  /* seconds since the passes started; eta < 0: not known */
} iris_adaptive_progress;

typedef struct iris_adaptive_job {
  const iris_integrator *it;
  const iris_pinhole *cam; /* cam->width/height is the frame */
  iris_film *film;         /* covers the window; may hold training samples already */
  uint64_t seed, sample_offset;
  int x0, y0, x1, y1;      /* the window in full-frame pixels */
  int threads;
  iris_path_stats *stats;  /* one per thread */
  int spp_cap;             /* most image samples of a pixel, training samples included */
  double budget;           /* seconds for the passes; <= 0: none */
  void (*progress)(void *ctx, const iris_adaptive_progress *p);
  void *progress_ctx;
  iris_adaptive_params params;
  /* Light tracing (light_trace.h; NULL: none): after each round's image
   * samples, light paths in proportion to them, as many per sample as a
   * whole-frame render traces, their indices on from its `next`. */
  struct iris_light_trace *light_trace;
} iris_adaptive_job;

typedef struct iris_adaptive_outcome {
  int rounds;
  double spp_mean;        /* mean samples per pixel in the film */
  int spp_min, spp_max;
  double scout_spp_mean;  /* scout samples per pixel (not in the image) */
  double error_estimate;  /* the image's estimated relMSE at the end */
  bool converged;         /* every pixel reached its threshold target (freeze / threshold) */
  bool reached_target;    /* target_error > 0 and reached */
  bool capped;            /* stopped by spp_cap or the budget before the target/threshold */
  bool interrupted;       /* stopped by a cancel request */
  uint64_t paths;         /* image and scout paths traced */
  uint64_t scout_paths;
} iris_adaptive_outcome;

/* Why the rounds stopped: "target", "threshold", "interrupted" or "cap". */
const char *iris_adaptive_stop_name(const iris_adaptive_outcome *o);

/* Runs the rounds until the threshold / target is met, the cap or the budget
 * is reached, or a cancel request (core/cancel.h). At least one round runs. */
iris_status iris_adaptive_run(const iris_adaptive_job *job, iris_adaptive_outcome *out, iris_error *err);

/* The image's estimated relMSE from a film's per-pixel variance of the mean:
 * mean over pixels of (1/3) sum_c var_c / (mean_c^2 + IRIS_ADAPTIVE_EPS),
 * the largest IRIS_ADAPTIVE_DROP share of pixels dropped (as the bench's
 * metric drops the largest errors). Pixels with fewer than 2 samples count 0. */
double iris_adaptive_film_error(const iris_film *film);

/* The Cycles-scale noise of a pixel's mean from its mean and variance of the
 * mean per channel: sqrt(2/pi) sum_c sqrt(var_c) / (1e-4 + sqrt(sum_c mean_c)),
 * the expected value of Cycles 3.4's |full - half buffer| error; a pixel
 * converges at error < 5 T (Cycles scales its threshold by 5). */
double iris_adaptive_cycles_error(const double mean[3], const double var_of_mean[3]);

#ifdef __cplusplus
}
#endif
#endif
