/* Training passes (docs/guiding.md, "Training"): after the photon caches are
 * built, camera paths traced with the guide record, at every vertex a cache
 * served, the radiance that actually arrived along the direction the path
 * continued in. Between passes each cache's tables are rebuilt from its
 * photons and these samples, and its BSDF-vs-cache selection probability is
 * chosen to minimise the estimated second moment of the one-sample MIS
 * estimator. Training paths use their own sample indices over the whole
 * frame, so every node of a partitioned render builds the same guide, and
 * their samples are merged in tile order, so the guide does not depend on the
 * thread count. Training images are discarded. */
#ifndef IRIS_RENDERER_GUIDING_TRAIN_H
#define IRIS_RENDERER_GUIDING_TRAIN_H

#include <stdbool.h>
#include <stdint.h>

#include "core/error.h"
#include "renderer/guiding/guiding.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Candidate selection probabilities: 0.05, 0.15, ..., 0.95. */
#define IRIS_ALPHA_GRID 10
static inline float iris_alpha_grid_value(int j) { return 0.05f + 0.1f * (float)j; }

/* Second-moment estimates of the one-sample MIS estimator
 * F_a = h / ((1 - a) p_b + a p_c) for each grid value a, from samples drawn
 * with density q: E_q[F_a^2 q_a / q] = E_q[h^2 / (q_a q)] (docs/guiding.md). */
typedef struct iris_alpha_learner {
  double m[IRIS_ALPHA_GRID];
  uint32_t n;
} iris_alpha_learner;

/* One sample: integrand h (BSDF x cos x incident radiance), its sampling
 * density q, the BSDF and cache densities of the same direction. */
void iris_alpha_learner_add(iris_alpha_learner *l, float h, float q, float pb, float pc);
/* The grid value with the least estimated second moment (the smallest on
 * ties), or `fallback` with fewer than `min_samples` samples or none non-zero. */
float iris_alpha_learner_best(const iris_alpha_learner *l, float fallback, uint32_t min_samples);

/* Training schedule: the total training samples per pixel for a render of
 * `spp` samples (spp > 0), and the samples per pixel of iteration i (doubling,
 * the last one cut to the total). */
int iris_guiding_train_budget(int spp);
int iris_guiding_train_iteration_spp(int iteration, int done, int total);

/* Runs the training passes on a built, not skipped guide (g->params.train_spp:
 * > 0 samples per pixel, < 0 from setup->spp / setup->time_budget). Keeps the
 * photon histograms in g->photon_hist until done, then frees them. */
iris_status iris_guiding_train(iris_guiding *g, const iris_guide_setup *setup, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
