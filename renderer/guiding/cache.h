/* One irradiance cache's directional distribution (thesis 4.2.3, 5.1): a photon
 * histogram over an octahedral map turned into a pdf with a floor, its CDF,
 * sampling (Algorithm 2, uniform in solid angle inside the texel) and the pdf
 * of any direction (5.1.2). Sampling picks a texel by the CDF and a point
 * uniformly in the texel's (a, b) square, so the solid-angle density is
 * pdf(w) = P[texel(w)] * res^2 / (2 |w|_1^3) (w unit; d(a,b)/d(omega) =
 * 2 / |w|_1^3), exactly what sampling does; the pdf table stores
 * P * res^2 / 2 per texel (docs/guiding.md). */
#ifndef IRIS_RENDERER_GUIDING_CACHE_H
#define IRIS_RENDERER_GUIDING_CACHE_H

#include <stdbool.h>
#include <stdint.h>

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

/* Turns histogram `hist` into the cache tables (thesis 4.2.3.1): normalise to a
 * discrete distribution over texels, raise values below `floor` to `floor`,
 * renormalise; cdf[i] = P[0..i] (cdf[last] = 1) and pdf[i] = P[i] /
 * solid_angle[i], with P[i] recomputed as cdf differences so that pdf and
 * sampling agree to the last bit, and pdf[i] = P[i] * res^2 / 2 (multiply by
 * iris_cache_density_factor(w) for a density). Returns false (tables untouched) when the
 * histogram is empty. */
bool iris_cache_build_tables(const iris_octmap *map, const float *hist, float floor, float *pdf,
                             float *cdf);

/* Samples a local direction (Algorithm 2): texel by binary search of u0 in the
 * CDF, then (u1, u2) uniformly in the texel's map square (no trigonometry).
 * *pdf_out is the solid-angle density of the returned direction. */
iris_vec3 iris_cache_sample(const iris_octmap *map, const float *pdf, const float *cdf, float u0,
                            float u1, float u2, float *pdf_out);
/* 1 / |w|_1^3 for w normalised: the factor that turns a texel's pdf-table
 * entry into the solid-angle density at w (any non-zero length). */
float iris_cache_density_factor(iris_vec3 w);
/* Solid-angle density with which iris_cache_sample returns local direction w
 * (0 below a hemisphere map). */
float iris_cache_pdf(const iris_octmap *map, const float *pdf, iris_vec3 w);

#ifdef __cplusplus
}
#endif
#endif
