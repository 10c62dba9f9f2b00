/* The tests' way to render a scene with chosen parameters and get the image
 * and its stats: iris_test_params fills the parameters most tests choose (the
 * rest keep their defaults), iris_test_attach_guide adds the guiding provider,
 * and iris_test_render* run iris_render and hand back the result (film and
 * stats), the pixel means, the mean over the image or the image itself. On
 * failure they print "render failed: <message>" and return false (the caller
 * CHECKs the result). Header-only: the tests link the renderer, tests/common's
 * library does not. */
#ifndef IRIS_TESTS_RENDER_RUN_H
#define IRIS_TESTS_RENDER_RUN_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "film_stats.h"
#include "renderer/guiding/guiding.h"
#include "renderer/render.h"

/* The defaults with the image size, samples per pixel, method
 * (IRIS_METHOD_COUNT: the scene's) and seed set. */
static inline iris_render_params iris_test_params(int width, int height, int spp, iris_method method,
                                                  uint64_t seed) {
  iris_render_params p = iris_render_params_default();
  p.width = width;
  p.height = height;
  p.spp = spp;
  p.method = method;
  p.seed = seed;
  return p;
}

/* Guides the guided methods (p->method set first) with iris's guiding
 * provider and the options gp, which must outlive the render. The others get
 * no guide: auto without one renders mis. */
static inline void iris_test_attach_guide(iris_render_params *p, const iris_guiding_params *gp) {
  if (!iris_method_uses_guiding(p->method)) return;
  p->guide = &iris_guiding_provider;
  p->guide_options = gp;
}

/* Renders s with p into r (the caller destroys r). */
static inline bool iris_test_render(const iris_scene *s, const iris_render_params *p, iris_render_result *r) {
  iris_error err;
  iris_error_clear(&err);
  if (iris_render(s, p, r, &err) != IRIS_OK) {
    fprintf(stderr, "render failed: %s\n", err.message);
    return false;
  }
  return true;
}

/* Renders and keeps each pixel's mean, row by row (p->width x p->height). */
static inline bool iris_test_render_pixels(const iris_scene *s, const iris_render_params *p, iris_vec3 *pixels) {
  iris_render_result r;
  if (!iris_test_render(s, p, &r)) return false;
  for (int y = 0; y < r.film.height; y++)
    for (int x = 0; x < r.film.width; x++) {
      iris_vec3 v;
      iris_film_pixel(&r.film, x, y, &pixels[(size_t)y * (size_t)r.film.width + (size_t)x], &v);
    }
  iris_render_result_destroy(&r);
  return true;
}

/* Renders and gives the mean of the pixel means over the image and its
 * variance (film_stats.h's region over the whole film); var may be NULL. */
static inline bool iris_test_render_mean(const iris_scene *s, const iris_render_params *p, double mean[3],
                                         double var[3]) {
  iris_render_result r;
  if (!iris_test_render(s, p, &r)) return false;
  double v[3];
  region(&r.film, 0, 0, r.film.width, r.film.height, mean, var ? var : v);
  iris_render_result_destroy(&r);
  return true;
}

/* Renders and converts the film to an image (with the variance channels when
 * asked; the caller destroys the image). */
static inline bool iris_test_render_image(const iris_scene *s, const iris_render_params *p, bool variance,
                                          iris_image *out) {
  iris_render_result r;
  if (!iris_test_render(s, p, &r)) return false;
  iris_error err;
  iris_error_clear(&err);
  bool ok = iris_film_to_image(&r.film, variance, out, &err) == IRIS_OK;
  if (!ok) fprintf(stderr, "film to image failed: %s\n", err.message);
  iris_render_result_destroy(&r);
  return ok;
}

/* iris_test_render of w x h pixels, spp samples, with a method, a light
 * sampler, a thread count, a seed and a guide provider (NULL: none). */
static inline bool iris_test_render_light(const iris_scene *s, iris_method m, iris_light_sampler ls, int threads,
                                          int w, int h, int spp, uint64_t seed, const iris_guide_provider *guide,
                                          iris_render_result *r) {
  iris_render_params p = iris_test_params(w, h, spp, m, seed);
  p.threads = threads;
  p.light_sampler = ls;
  p.guide = guide;
  return iris_test_render(s, &p, r);
}

#endif
