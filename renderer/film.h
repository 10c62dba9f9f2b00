/* The film: a 1-pixel box filter (each sample counts only for the pixel it
 * was taken in, as Cycles' BOX filter), with per-pixel sums of the samples
 * and of their squares in double, giving the mean and the variance of the
 * mean. Each pixel is written by one thread at a time, so no locks. */
#ifndef IRIS_RENDERER_FILM_H
#define IRIS_RENDERER_FILM_H

#include <stdbool.h>
#include <stdint.h>

#include "core/error.h"
#include "core/image.h"
#include "core/math.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct iris_film {
  int width, height;
  double *sum;   /* 3 per pixel */
  double *sum2;  /* 3 per pixel */
  uint32_t *count; /* samples per pixel */
  /* Light tracing (renderer/light_trace.h), NULL without it: per pixel the
   * sums of what light paths added and of its squares (a path adds to one
   * pixel at most), and how many paths were traced. A pixel's value is its
   * samples' mean plus light_sum / light_paths, an estimator of its own. */
  double *light_sum, *light_sum2;
  double light_paths;
} iris_film;

iris_status iris_film_create(iris_film *film, int width, int height, iris_error *err);
void iris_film_destroy(iris_film *film);

/* Adds one (finite) sample to pixel (x, y). */
static inline void iris_film_add(iris_film *film, int x, int y, iris_vec3 L) {
  size_t i = (size_t)y * (size_t)film->width + (size_t)x;
  double r = L.x, g = L.y, b = L.z;
  film->sum[3 * i] += r;
  film->sum[3 * i + 1] += g;
  film->sum[3 * i + 2] += b;
  film->sum2[3 * i] += r * r;
  film->sum2[3 * i + 1] += g * g;
  film->sum2[3 * i + 2] += b * b;
  film->count[i]++;
}

/* Gives the film its light-path sums (zero). */
iris_status iris_film_light_paths_enable(iris_film *film, iris_error *err);

/* Adds what one light path brought to pixel i (row-major in the film). */
static inline void iris_film_add_light_path(iris_film *film, uint32_t i, const float c[3]) {
  for (int k = 0; k < 3; k++) {
    film->light_sum[3 * (size_t)i + (size_t)k] += c[k];
    film->light_sum2[3 * (size_t)i + (size_t)k] += (double)c[k] * (double)c[k];
  }
}

/* Mean of pixel (x, y) and the variance of that mean (sample variance / n;
 * 0 with fewer than two samples), with light tracing's part added to both. */
void iris_film_pixel(const iris_film *film, int x, int y, iris_vec3 *mean, iris_vec3 *var);

/* Image with channels R, G, B and, when `variance`, var.R, var.G, var.B. */
iris_status iris_film_to_image(const iris_film *film, bool variance, iris_image *out,
                               iris_error *err);
/* The same, and with `counts` a last channel "spp": each pixel's sample count
 * (exact in float up to 2^24). */
iris_status iris_film_to_image_counts(const iris_film *film, bool variance, bool counts, iris_image *out,
                                      iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
