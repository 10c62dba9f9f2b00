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

#endif
