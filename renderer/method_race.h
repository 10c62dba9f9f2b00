/* `--method auto` by measurement (docs/guiding.md, "--method auto"): a short,
 * deterministic race of mis against guided-nee on a fixed grid of pixels of
 * the whole frame, after the guide is built. Each method traces the same
 * number of camera paths with its own seed (none of them enters the image),
 * more while the two are level within the race's standard error;
 * the race measures each method's relative variance per sample and its cost
 * per sample in a deterministic model (rays and guide look-ups, weighted by
 * per-operation times measured once: no clock decides), and whether one
 * method found significantly less light than the other (an estimator that is
 * short of light has paths too rare for the race to see, so its variance is
 * underestimated). guided-nee wins only by more than one standard error.
 * Private to renderer/. */
#ifndef IRIS_RENDERER_METHOD_RACE_H
#define IRIS_RENDERER_METHOD_RACE_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "renderer/camera.h"
#include "renderer/integrator.h"

/* The model's cost of one operation, in closest-hit rays (docs/guiding.md,
 * "--method auto", where they were measured). */
#define IRIS_RACE_COST_SHADOW 0.9
#define IRIS_RACE_COST_PREPARE 0.4
#define IRIS_RACE_COST_GUIDE_CALL 0.05
/* Camera paths per method: at least IRIS_RACE_PIXELS pixels of a strided grid
 * over the frame (all pixels of a smaller frame), IRIS_RACE_SPP paths each, or
 * more (up to IRIS_RACE_SPP_MAX) until the race holds IRIS_RACE_PATHS paths. */
#define IRIS_RACE_PIXELS 16384
#define IRIS_RACE_SPP 4
#define IRIS_RACE_SPP_MAX 256
#define IRIS_RACE_PATHS 32768
/* The race runs in rounds of this many paths per pixel (>= 2: each round
 * alone gives a variance); a time cap ends it after the round that reaches
 * it. Under `--time` the cap is IRIS_RACE_BUDGET_SHARE of the budget. */
#define IRIS_RACE_ROUND_SPP 2
/* After those paths the race goes on, up to IRIS_RACE_EXTEND times as many,
 * while guided-nee's speedup over mis is within IRIS_RACE_DECISIVE_Z jackknife
 * standard errors of 1 (log scale, 16 interleaved pixel groups). */
#define IRIS_RACE_EXTEND 4
#define IRIS_RACE_DECISIVE_Z 2.0
/* guided-nee renders only when its log speedup is above this many standard
 * errors (mis, the method without a guide, when the race cannot separate them) */
#define IRIS_RACE_MARGIN_Z 1.0
#define IRIS_RACE_BUDGET_SHARE 0.05
/* The share of the race's pixels with the largest terms left out of its
 * relative variance, as iris bench's relMSE leaves out the largest errors. */
#define IRIS_RACE_TRIM 0.001
/* When those pixels hold more than this share of either method's variance
 * and the scene has smooth (delta) lobes, whose light the race sees too
 * rarely (through glass, off mirrors), the race cannot measure it and
 * guided-nee (the photon rules' choice) stands. */
#define IRIS_RACE_TAIL_MAX 0.5
/* A method whose race image holds this many standard errors less light than
 * the other's loses, whatever its measured variance. */
#define IRIS_RACE_SHORT_Z 4.0

typedef struct iris_race_outcome {
  /* [0] mis, [1] guided-nee */
  double relvar[2];    /* mean over the race's pixels of (1/3) sum_c s_c^2 / (m_c^2 + 0.01):
                          the relMSE of one sample per pixel */
  double cost[2];      /* modelled cost per path, in closest-hit rays */
  double seconds[2];   /* measured (reported, never decides) */
  uint64_t rays[2], shadow_rays[2], prepares[2], guide_calls[2];
  double light[2];     /* mean luminance of the race pixels */
  double short_z;      /* (light[1] - light[0]) in standard errors: > 0 mis is short */
  uint64_t paths;      /* per method */
  uint64_t base_paths; /* per method before the race went on for want of a decision */
  double tail_share[2]; /* the share of each method's variance in the IRIS_RACE_TRIM pixels left out */
  double speedup;      /* guided-nee's efficiency over mis's (relvar x cost), before the light check */
  double log_speedup_se; /* jackknife standard error of log(speedup) */
  bool unmeasurable;   /* tail_share above IRIS_RACE_TAIL_MAX with smooth lobes: the rules' guided-nee stands */
  bool guided;         /* the winner */
} iris_race_outcome;

/* The race's statistic, for iris_method_race and for whoever checks it
 * against longer renders: the mean of `means` (3 per cell of a cols x rows
 * grid) over the 8 neighbours of cell (x, y), the cell itself left out (its
 * own value when it has no neighbour), and one pixel's term, (1/3) sum_c
 * var_c / (ref_c^2 + 0.01), var_c the variance of one sample. */
void iris_race_neighbour_mean(const double *means, int cols, int rows, int x, int y, double ref[3]);
double iris_race_term(const double var[3], const double ref[3]);
/* The mean of the n terms after leaving out the IRIS_RACE_TRIM share with the
 * largest values (sorts `terms`); *tail_share (may be NULL) gets the share of
 * the sum those held. */
double iris_race_trimmed_mean(double *terms, size_t n, double *tail_share);
/* Whether any material of the scene may have a delta lobe (roughness at or
 * below IRIS_BSDF_MIN_ROUGHNESS, or a roughness texture that may reach it). */
bool iris_race_scene_has_smooth_lobes(const iris_scene *scene);

/* Races `mis` (an integrator with method mis) against `guided` (guided-nee,
 * its guide set) on camera `cam`. Without a time cap (time_cap <= 0)
 * deterministic for a given seed and frame, whatever the thread count or the
 * window rendered; with one, the rounds run depend on the machine (as a
 * `--time` render's samples do). A stop request gives IRIS_ERR_INTERRUPTED.
 * `why` receives the reason in words ("guided-nee 1.8x mis per unit of work
 * ..."). */
iris_status iris_method_race(const iris_integrator *mis, const iris_integrator *guided, const iris_pinhole *cam,
                             uint64_t seed, int threads, double time_cap, iris_race_outcome *out, char *why,
                             size_t why_size, iris_error *err);

#endif
