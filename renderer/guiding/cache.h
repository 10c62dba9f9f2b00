/* One irradiance cache's directional distribution (thesis 4.2.3, 5.1): a photon
 * histogram over an octahedral map turned into a pdf with a floor, an alias
 * table for O(1) texel choice, sampling (Algorithm 2) and the pdf of any
 * direction (5.1.2). Sampling picks a texel with the alias table (Walker /
 * Vose) and a point uniformly in the texel's (a, b) square, so the
 * solid-angle density is pdf(w) = P[texel(w)] * res^2 / (2 |w|_1^3) (w unit;
 * d(a,b)/d(omega) = 2 / |w|_1^3), exactly what sampling does; the pdf table
 * stores P * res^2 / 2 per texel, with P re-derived from the alias table
 * (docs/guiding.md). */
#ifndef IRIS_RENDERER_GUIDING_CACHE_H
#define IRIS_RENDERER_GUIDING_CACHE_H

#include <stdbool.h>
#include <stdint.h>
#include <math.h>

#include "core/math.h"
#include "renderer/guiding/octmap.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum iris_splat_mode {
  IRIS_SPLAT_NEAREST = 0, /* thesis: the whole energy into the photon's texel */
  IRIS_SPLAT_BILINEAR     /* the thesis's TODO: shared among the 4 nearest texel centres */
} iris_splat_mode;

/* Adds a photon arriving from local direction `wi` (pointing away from the
 * surface, towards where the photon came from) with `energy` to histogram
 * `hist` [map->texel_count]. Photons from below a hemisphere map are ignored;
 * returns whether the photon was used. */
bool iris_cache_splat(const iris_octmap *map, float *hist, iris_vec3 wi, float energy,
                      iris_splat_mode mode);

/* One alias-table column: texel i keeps itself with probability q (a uniform
 * u in [0,1) picks column floor(u n), keeps it when the fraction is < q) and
 * otherwise goes to `alias`. */
typedef struct iris_cache_alias {
  float q;
  uint32_t alias;
} iris_cache_alias;

/* Turns histogram `hist` into the cache tables (thesis 4.2.3.1): normalise to a
 * discrete distribution over texels, raise values below `floor` to `floor`,
 * renormalise; build the alias table (Vose, in double) and set pdf[i] =
 * P[i] * res^2 / 2 (multiply by iris_cache_density_factor(w) for a density)
 * with P[i] re-derived from the float alias table, so that pdf and sampling
 * agree. Returns false (tables untouched) when the histogram is empty. */
bool iris_cache_build_tables(const iris_octmap *map, const float *hist, float floor, float *pdf,
                             iris_cache_alias *alias);

/* Samples a local direction (Algorithm 2): texel by the alias table from u0,
 * then (u1, u2) uniformly in the texel's map square (no trigonometry).
 * *pdf_out is the solid-angle density of the returned direction. */
iris_vec3 iris_cache_sample(const iris_octmap *map, const float *pdf, const iris_cache_alias *alias,
                            float u0, float u1, float u2, float *pdf_out);
/* 1 / |w|_1^3 for w normalised: the factor that turns a texel's pdf-table
 * entry into the solid-angle density at w (any non-zero length). */
float iris_cache_density_factor(iris_vec3 w);
/* Solid-angle density with which iris_cache_sample returns local direction w
 * (0 below a hemisphere map). */
float iris_cache_pdf(const iris_octmap *map, const float *pdf, iris_vec3 w);

/* The texel of UNIT local direction w in a res-map (sphere or hemisphere;
 * -1 below a hemisphere map), *sub its sub-cell of a 4 x 4 split of the texel
 * (refine.h; row-major in texel coordinates) and *factor = 1 / |w|_1^3,
 * without square roots or libm calls (the render-time pdf lookup). The texel
 * is the fine cell's divided by 4: scaling by a power of two commutes with
 * rounding, so it is exactly the texel of the unsplit map. */
static inline int32_t iris_cache_cell(int res, bool sphere, iris_vec3 w, float *factor, int *sub) {
  if (!sphere && w.z < 0.0f) return -1;
  const float inv = 1.0f / (fabsf(w.x) + fabsf(w.y) + fabsf(w.z));
  *factor = inv * inv * inv;
  const float x = w.x * inv, y = w.y * inv, h = 2.0f * (float)res; /* 0.5 res texels, x 4 sub-cells */
  const int fres = 4 * res;
  int i = (int)((x - y + 1.0f) * h), j = (int)((x + y + 1.0f) * h);
  if (w.z < 0.0f) i = (int)((1.0f - (x - y)) * h); /* lower half, mirrored in a */
  i = i < 0 ? 0 : (i >= fres ? fres - 1 : i);
  j = j < 0 ? 0 : (j >= fres ? fres - 1 : j);
  *sub = (j & 3) * 4 + (i & 3);
  i >>= 2;
  j >>= 2;
  if (w.z < 0.0f) i += res;
  return j * (sphere ? 2 * res : res) + i;
}
static inline int32_t iris_cache_texel(int res, bool sphere, iris_vec3 w, float *factor) {
  int sub;
  return iris_cache_cell(res, sphere, w, factor, &sub);
}
/* As iris_cache_sample / iris_cache_pdf with the texels refined where
 * slot[texel] > 0: sub-table slot - 1 of `sub` (refine.h). slot NULL: none. */
iris_vec3 iris_cache_sample_refined(const iris_octmap *map, const float *pdf, const iris_cache_alias *alias,
                                    const uint8_t *slot, const float *sub, float u0, float u1, float u2,
                                    float *pdf_out);
float iris_cache_pdf_refined(const iris_octmap *map, const float *pdf, const uint8_t *slot, const float *sub,
                             iris_vec3 w);
#ifdef __cplusplus
}
#endif
#endif
