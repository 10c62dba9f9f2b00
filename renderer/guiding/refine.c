/* Refinement of concentrated texels (refine.h; docs/guiding.md, "Refinement"). */
#include "renderer/guiding/refine.h"

#include <math.h>
#include <string.h>

#include "renderer/guiding/cache.h"

_Static_assert(IRIS_REFINE_S == 4, "iris_cache_cell splits texels 4 x 4");

/* A texel is split when its sub-cells hold at least this many photons'
 * worth (effective count) and their second moment, noise removed, is this
 * many times a uniform texel's (docs/guiding.md, "Refinement"). */
#ifndef REFINE_MIN_SAMPLES /* overridable at build time for measurements */
#define REFINE_MIN_SAMPLES 4.0
#endif
#ifndef REFINE_MIN_CONCENTRATION
#define REFINE_MIN_CONCENTRATION 2.0
#endif

int32_t iris_refine_fine_cell(const iris_octmap *map, iris_vec3 d) {
  float l2 = sqrtf(d.x * d.x + d.y * d.y + d.z * d.z), factor;
  int sub;
  if (!(l2 > 0.0f)) return -1;
  int32_t t = iris_cache_cell(map->res, map->sphere, iris_scale(d, 1.0f / l2), &factor, &sub);
  return t < 0 ? -1 : t * IRIS_REFINE_SUB + sub;
}

bool iris_refine_splat(const iris_octmap *map, float *fine, float *sq, iris_vec3 wi, float energy) {
  if (!(energy > 0.0f) || !isfinite(energy)) return false;
  int32_t c = iris_refine_fine_cell(map, wi);
  if (c < 0) return false;
  fine[c] += energy;
  if (sq) sq[c / IRIS_REFINE_SUB] += energy * energy;
  return true;
}

int iris_refine_build(const iris_octmap *map, const double *prob, const float *fine, const float *sq, int max,
                      float mix, uint8_t *slot, float *sub) {
  const uint32_t n = map->texel_count;
  memset(slot, 0, n);
  if (max <= 0) return 0;
  if (max > IRIS_REFINE_MAX) max = IRIS_REFINE_MAX;
  /* Candidates: probable texels whose sub-cells are concentrated, in order
   * of probability (ties by index: deterministic). */
  uint32_t best[IRIS_REFINE_MAX];
  int count = 0;
  for (uint32_t t = 0; t < n; ++t) {
    if (!(prob[t] >= 2.0 / (double)n)) continue;
    const float *f = fine + (size_t)t * IRIS_REFINE_SUB;
    double s = 0.0, s2 = 0.0;
    for (int k = 0; k < IRIS_REFINE_SUB; ++k) s += f[k] > 0.0f ? f[k] : 0.0f;
    if (!(s > 0.0)) continue;
    for (int k = 0; k < IRIS_REFINE_SUB; ++k) {
      double p = (f[k] > 0.0f ? f[k] : 0.0f) / s;
      s2 += p * p;
    }
    /* n_eff samples from a uniform texel give E[sum p^2] = 1/16 + (15/16) / n_eff:
     * only what exceeds that noise counts as concentration. */
    double neff = sq && sq[t] > 0.0f ? s * s / (double)sq[t] : 1e30;
    if (neff < REFINE_MIN_SAMPLES) continue;
    double conc = (s2 - (1.0 - 1.0 / IRIS_REFINE_SUB) / neff) * IRIS_REFINE_SUB;
    if (conc < REFINE_MIN_CONCENTRATION) continue; /* near uniform: a sub-table would only add noise */
    int at = count < max ? count++ : max;
    if (at == max && !(prob[t] > prob[best[max - 1]])) continue;
    if (at == max) at = max - 1;
    while (at > 0 && prob[t] > prob[best[at - 1]]) {
      best[at] = best[at - 1];
      --at;
    }
    best[at] = t;
  }
  for (int j = 0; j < count; ++j) {
    const float *f = fine + (size_t)best[j] * IRIS_REFINE_SUB;
    float *m = sub + (size_t)j * IRIS_REFINE_SUB;
    double s = 0.0, q[IRIS_REFINE_SUB], qs = 0.0;
    for (int k = 0; k < IRIS_REFINE_SUB; ++k) s += f[k] > 0.0f ? f[k] : 0.0f;
    for (int k = 0; k < IRIS_REFINE_SUB; ++k) {
      q[k] = (1.0 - mix) * (f[k] > 0.0f ? f[k] : 0.0f) / s + mix / IRIS_REFINE_SUB;
      qs += q[k];
    }
    for (int k = 0; k < IRIS_REFINE_SUB; ++k) m[k] = (float)(q[k] / qs * IRIS_REFINE_SUB);
    slot[best[j]] = (uint8_t)(j + 1);
  }
  return count;
}

bool iris_refine_train_add(const iris_octmap *map, const uint8_t *slot, float *acc, uint32_t *count, iris_vec3 wl,
                           float value) {
  float l2 = sqrtf(wl.x * wl.x + wl.y * wl.y + wl.z * wl.z), factor;
  int k;
  if (!(value > 0.0f) || !isfinite(value) || !(l2 > 0.0f)) return false;
  int32_t t = iris_cache_cell(map->res, map->sphere, iris_scale(wl, 1.0f / l2), &factor, &k);
  if (t < 0 || !slot[t]) return false;
  acc[(size_t)(slot[t] - 1) * IRIS_REFINE_SUB + k] += value;
  count[slot[t] - 1]++;
  return true;
}

void iris_refine_train_rebuild(const iris_octmap *map, const uint8_t *slot, const float *photon_prob,
                               const float *photon_sub, const float *acc, const uint32_t *count, double prior,
                               float mix, float *sub) {
  for (uint32_t t = 0; t < map->texel_count; ++t) {
    if (!slot[t]) continue;
    const size_t j = (size_t)(slot[t] - 1);
    const float *a = acc + j * IRIS_REFINE_SUB, *ph = photon_sub + j * IRIS_REFINE_SUB;
    double s = 0.0;
    for (int k = 0; k < IRIS_REFINE_SUB; ++k) s += a[k];
    if (!(s > 0.0) || !isfinite(s) || count[j] == 0) continue;
    /* a path sample weighs as a photon: the texel held prior x P(texel) of them */
    double lambda = (double)count[j] / ((double)count[j] + prior * (double)photon_prob[t]);
    for (int k = 0; k < IRIS_REFINE_SUB; ++k)
      sub[j * IRIS_REFINE_SUB + k] =
          (float)((1.0 - lambda) * ph[k] +
                  lambda * IRIS_REFINE_SUB * ((1.0 - mix) * a[k] / s + (double)mix / IRIS_REFINE_SUB));
  }
}
