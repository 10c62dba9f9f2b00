/* Directional refinement of a cache's octahedral map where its incident light
 * is concentrated (docs/guiding.md, "Refinement"): up to `max` texels per cache
 * are split into IRIS_REFINE_S x IRIS_REFINE_S sub-cells with their own
 * conditional distribution, the rest stay one texel. A texel's slot byte says
 * whether it is refined (0: no; j: the cache's j-th sub-table); a sub-table
 * holds the sub-cells' density multipliers m_k = S^2 P(k | texel) (mean 1), so
 * the density of a direction in sub-cell k of a refined texel is the coarse
 * density times m_k. Sampling picks the texel by the alias table, the sub-cell
 * by m_k, and a point uniformly in the sub-cell's (a, b) square: the Jacobian
 * of cache.h is unchanged. */
#ifndef IRIS_RENDERER_GUIDING_REFINE_H
#define IRIS_RENDERER_GUIDING_REFINE_H
#include <stdbool.h>
#include <stdint.h>
#include "renderer/guiding/octmap.h"
#ifdef __cplusplus
extern "C" {
#endif

#define IRIS_REFINE_S 4 /* sub-cells per texel side (cache.h's iris_cache_cell assumes 4) */
#define IRIS_REFINE_SUB (IRIS_REFINE_S * IRIS_REFINE_S) /* sub-cells per texel */
#define IRIS_REFINE_MAX 8                            /* most refined texels per cache */
#define IRIS_REFINE_MIX 0.2f /* share of uniform in a refined texel's sub-cells (docs/guiding.md) */

/* Index of the fine cell (texel * IRIS_REFINE_SUB + sub-cell, the sub-cell
 * row-major in (u, v) texel coordinates) of local direction d, -1 below a
 * hemisphere map. */
int32_t iris_refine_fine_cell(const iris_octmap *map, iris_vec3 d);

/* Adds a photon (or a training sample) of `energy` from local direction wi
 * to a fine histogram [map->texel_count * IRIS_REFINE_SUB] (nearest cell),
 * and energy^2 to sq[texel] (NULL: not kept). */
bool iris_refine_splat(const iris_octmap *map, float *fine, float *sq, iris_vec3 wi, float energy);

/* Chooses which texels to refine from the coarse probabilities `prob`
 * [texel_count] (normalised), the fine histogram and its squares `sq`
 * [texel_count] (NULL: no noise correction): texels with P >= 2 / n whose
 * sub-cells are concentrated beyond what the samples' noise explains, the
 * `max` most probable. Writes slot[texel_count] (0 or 1..max) and sub[max *
 * IRIS_REFINE_SUB] (m_k, a fraction `mix` of uniform mixed in, m_k > 0).
 * Returns the number refined. */
int iris_refine_build(const iris_octmap *map, const double *prob, const float *fine, const float *sq, int max,
                      float mix, uint8_t *slot, float *sub);

/* Training (train.c): a path sample of `value` (Li cos / q) at local
 * direction wl goes to its sub-cell's accumulator acc[max * SUB] and counts in
 * count[max] when its texel is refined. */
bool iris_refine_train_add(const iris_octmap *map, const uint8_t *slot, float *acc, uint32_t *count, iris_vec3 wl,
                           float value);
/* New sub-tables for one cache's refined texels: the photons' multipliers
 * (photon_sub) mixed with the path samples' (a fraction `mix` uniform) with
 * weight n / (n + prior P_photon(texel)), as the coarse tables are. Texels
 * without samples keep theirs. */
void iris_refine_train_rebuild(const iris_octmap *map, const uint8_t *slot, const float *photon_prob,
                               const float *photon_sub, const float *acc, const uint32_t *count, double prior,
                               float mix, float *sub);

/* Sub-cell choice for a refined texel from u in [0,1): returns k and remaps
 * *u to a uniform number in [0,1) (the position inside the sub-cell). */
static inline int iris_refine_pick(const float *m, float *u) {
  float x = *u * (float)IRIS_REFINE_SUB, c = 0.0f;
  int k = 0;
  for (; k < IRIS_REFINE_SUB - 1; ++k) {
    if (x < c + m[k]) break;
    c += m[k];
  }
  float r = m[k] > 0.0f ? (x - c) / m[k] : 0.0f;
  *u = r < 0.0f ? 0.0f : (r >= 1.0f ? IRIS_ONE_MINUS_EPSILON : r);
  return k;
}

#ifdef __cplusplus
}
#endif
#endif
