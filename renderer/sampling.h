/* Shared sample warps: each maps uniform numbers in [0,1)^k to a point or
 * direction and sits next to the density it produces (solid angle for
 * directions, area for disks, probability for discrete choices). Used by the
 * BSDFs, the light sampler and the guiding caches; tests/bsdf checks each one
 * with the chi-square harness. */
#ifndef IRIS_RENDERER_SAMPLING_H
#define IRIS_RENDERER_SAMPLING_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "core/math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Point on the unit disk, Shirley-Chiu concentric map (area density 1/pi). */
void iris_sample_concentric_disk(float u0, float u1, float *x, float *y);
static inline float iris_sample_concentric_disk_pdf(void) { return IRIS_INV_PI; }

/* Cosine-weighted direction around +z (Malley: concentric disk lifted). */
iris_vec3 iris_sample_cosine_hemisphere(float u0, float u1);
static inline float iris_sample_cosine_hemisphere_pdf(float cos_theta) {
  return cos_theta > 0.0f ? cos_theta * IRIS_INV_PI : 0.0f;
}

/* Uniform direction on the +z hemisphere. */
iris_vec3 iris_sample_uniform_hemisphere(float u0, float u1);
static inline float iris_sample_uniform_hemisphere_pdf(float cos_theta) {
  return cos_theta >= 0.0f ? IRIS_INV_2PI : 0.0f;
}

/* Uniform direction on the whole sphere. */
iris_vec3 iris_sample_uniform_sphere(float u0, float u1);
static inline float iris_sample_uniform_sphere_pdf(void) { return IRIS_INV_4PI; }

/* Uniform direction in the cone around +z with cos(half angle) = cos_max
 * (also the spherical cap subtended by a sphere light). cos_max in [-1, 1). */
iris_vec3 iris_sample_uniform_cone(float u0, float u1, float cos_max);
float iris_sample_uniform_cone_pdf(float cos_theta, float cos_max);

/* Uniform point on a triangle as barycentrics (b0, b1), b2 = 1 - b0 - b1
 * (Heitz 2019 low-distortion map); area density 1 / triangle area. */
void iris_sample_uniform_triangle(float u0, float u1, float *b0, float *b1);

/* Solid angle subtended from the origin by the triangle with vertices at a,
 * b, c relative to it (Van Oosterom and Strackee 1983), in [0, 2 pi]. */
float iris_spherical_triangle_area(iris_vec3 a, iris_vec3 b, iris_vec3 c);
/* Direction uniform in the solid angle of that triangle (Arvo 1995, "Stratified
 * sampling of spherical triangles"; the formulation of pbrt-v4), density
 * 1 / iris_spherical_triangle_area. a, b, c need not be unit. False when the
 * triangle is degenerate as seen from the origin. u0 picks the sub-triangle
 * by area, u1 the point along its arc, so a stratified (u0, u1) gives
 * stratified directions. */
bool iris_sample_spherical_triangle(iris_vec3 a, iris_vec3 b, iris_vec3 c, float u0, float u1,
                                    iris_vec3 *wi);

/* Discrete distribution over n weights (a tabulated CDF). Negative and
 * non-finite weights count as 0; if all are 0 the choice is uniform.
 * Sampling inverts the CDF through a guide table (Chen & Asau 1974): bucket
 * floor(u * guide_count) starts the search at the last entry whose CDF is at
 * most the bucket's lower end, so a sample costs O(1) expected steps instead
 * of a binary search, and returns exactly what the binary search would. */
typedef struct iris_distrib1d {
  float *cdf;      /* n + 1 entries, cdf[0] = 0, cdf[n] = 1 (owned) */
  float *func;     /* n weights as given, sanitised (owned) */
  size_t count;
  double total;    /* sum of weights, 0 when the fallback to uniform is used */
  uint32_t *guide; /* guide_count entries (owned; NULL for small tables) */
  size_t guide_count;
} iris_distrib1d;

iris_status iris_distrib1d_create(iris_distrib1d *d, const float *weights, size_t count,
                                  iris_error *err);
void iris_distrib1d_destroy(iris_distrib1d *d);
/* Picks an index with probability weight/total; *pmf gets that probability and
 * *u_remapped (optional) a fresh uniform number in [0,1) from what is left of u. */
size_t iris_distrib1d_sample(const iris_distrib1d *d, float u, float *pmf, float *u_remapped);
float iris_distrib1d_pmf(const iris_distrib1d *d, size_t index);

#ifdef __cplusplus
}
#endif
#endif
