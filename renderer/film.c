/* Box-filtered film with mean and variance; see film.h. */
#include "renderer/film.h"

#include <stdlib.h>
#include <string.h>

iris_status iris_film_create(iris_film *film, int width, int height, iris_error *err) {
  memset(film, 0, sizeof *film);
  if (width <= 0 || height <= 0 || (uint64_t)width * (uint64_t)height > (1ull << 28))
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "unreasonable film size %dx%d",
                          width, height);
  size_t n = (size_t)width * (size_t)height;
  film->sum = calloc(3 * n, sizeof(double));
  film->sum2 = calloc(3 * n, sizeof(double));
  film->count = calloc(n, sizeof(uint32_t));
  if (!film->sum || !film->sum2 || !film->count) {
    iris_film_destroy(film);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for a %dx%d film",
                          width, height);
  }
  film->width = width;
  film->height = height;
  return IRIS_OK;
}

iris_status iris_film_light_paths_enable(iris_film *film, iris_error *err) {
  const size_t n = (size_t)film->width * (size_t)film->height;
  film->light_sum = calloc(3 * n, sizeof(double));
  film->light_sum2 = calloc(3 * n, sizeof(double));
  film->light_paths = 0.0;
  if (film->light_sum && film->light_sum2) return IRIS_OK;
  free(film->light_sum), free(film->light_sum2);
  film->light_sum = film->light_sum2 = NULL;
  return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for light-path sums of a %dx%d film",
                        film->width, film->height);
}

void iris_film_destroy(iris_film *film) {
  if (!film) return;
  free(film->light_sum);
  free(film->light_sum2);
  free(film->sum);
  free(film->sum2);
  free(film->count);
  memset(film, 0, sizeof *film);
}

void iris_film_pixel(const iris_film *film, int x, int y, iris_vec3 *mean, iris_vec3 *var) {
  size_t i = (size_t)y * (size_t)film->width + (size_t)x;
  double n = film->count[i];
  float m[3], v[3];
  for (int c = 0; c < 3; c++) {
    double mu = n > 0 ? film->sum[3 * i + c] / n : 0.0;
    double s2 = n > 1 ? (film->sum2[3 * i + c] - n * mu * mu) / (n - 1.0) : 0.0;
    if (s2 < 0.0) s2 = 0.0; /* cancellation */
    double var = n > 1 ? s2 / n : 0.0;
    const double L = film->light_paths;
    if (film->light_sum && L > 0.0) {
      /* what one light path adds to this pixel: mean and variance of that mean */
      const double lm = film->light_sum[3 * i + c] / L;
      double ls2 = L > 1.0 ? (film->light_sum2[3 * i + c] - L * lm * lm) / (L - 1.0) : 0.0;
      if (ls2 < 0.0) ls2 = 0.0;
      mu += lm;
      var += ls2 / L;
    }
    m[c] = (float)mu;
    v[c] = (float)var;
  }
  if (mean) *mean = iris_v3(m[0], m[1], m[2]);
  if (var) *var = iris_v3(v[0], v[1], v[2]);
}

iris_status iris_film_to_image(const iris_film *film, bool variance, iris_image *out,
                               iris_error *err) {
  return iris_film_to_image_counts(film, variance, false, out, err);
}

iris_status iris_film_to_image_counts(const iris_film *film, bool variance, bool counts, iris_image *out,
                                      iris_error *err) {
  static const char *const with_var[7] = {"R", "G", "B", "var.R", "var.G", "var.B", "spp"};
  static const char *const without_var[4] = {"R", "G", "B", "spp"};
  int channels = (variance ? 6 : 3) + (counts ? 1 : 0);
  iris_status st = iris_image_create(out, film->width, film->height, channels, variance ? with_var : without_var, err);
  if (st != IRIS_OK) return st;
  for (int y = 0; y < film->height; y++)
    for (int x = 0; x < film->width; x++) {
      iris_vec3 m, v;
      iris_film_pixel(film, x, y, &m, &v);
      float *px = out->data + ((size_t)y * (size_t)film->width + (size_t)x) * (size_t)channels;
      iris_v3_store(m, px);
      if (variance) iris_v3_store(v, px + 3);
      if (counts) px[channels - 1] = (float)film->count[(size_t)y * (size_t)film->width + (size_t)x];
    }
  return IRIS_OK;
}
