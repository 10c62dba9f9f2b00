/* The tests' way to render: iris_render with the given parameters; on failure
 * it prints "render failed: <message>" and returns false (the caller CHECKs
 * the result). */
#ifndef IRIS_TESTS_RENDER_RUN_H
#define IRIS_TESTS_RENDER_RUN_H

#include <stdbool.h>
#include <stdio.h>

#include "renderer/render.h"

static inline bool iris_test_render(const iris_scene *s, const iris_render_params *p, iris_render_result *r) {
  iris_error err;
  iris_error_clear(&err);
  if (iris_render(s, p, r, &err) != IRIS_OK) {
    fprintf(stderr, "render failed: %s\n", err.message);
    return false;
  }
  return true;
}

/* iris_test_render of w x h pixels, spp samples, with a method, a light
 * sampler, a thread count, a seed and a guide provider (NULL: none). */
static inline bool iris_test_render_light(const iris_scene *s, iris_method m, iris_light_sampler ls, int threads,
                                          int w, int h, int spp, uint64_t seed, const iris_guide_provider *guide,
                                          iris_render_result *r) {
  iris_render_params p = iris_render_params_default();
  p.width = w;
  p.height = h;
  p.spp = spp;
  p.method = m;
  p.seed = seed;
  p.threads = threads;
  p.light_sampler = ls;
  p.guide = guide;
  return iris_test_render(s, &p, r);
}

#endif
