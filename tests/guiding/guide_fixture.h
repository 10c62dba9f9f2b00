/* Builds a guide for a scene outside iris_render, as the guiding tests need
 * it: a 48x36 camera, the scene's accel, textures and lights (freed again:
 * the guide keeps none of them), the guide setup of a render of `spp`
 * samples with the sobol sampler. NULL (and a message) when anything fails. */
#ifndef IRIS_TESTS_GUIDING_GUIDE_FIXTURE_H
#define IRIS_TESTS_GUIDING_GUIDE_FIXTURE_H

#include <stdio.h>
#include <string.h>

#include "renderer/accel.h"
#include "renderer/guiding/guiding.h"
#include "renderer/lights.h"
#include "renderer/render.h"
#include "renderer/texture.h"

static inline iris_guiding *test_guide_build(const iris_scene *s, iris_method method, iris_guiding_params gp,
                                             uint64_t seed, int threads, int spp) {
  iris_error err;
  iris_error_clear(&err);
  iris_pinhole cam;
  iris_accel *acc = NULL;
  iris_textures tx;
  iris_lights lights;
  memset(&tx, 0, sizeof tx);
  memset(&lights, 0, sizeof lights);
  iris_guiding *g = NULL;
  if (iris_pinhole_setup(s, NULL, 48, 36, &cam, &err) == IRIS_OK && iris_accel_build(s, &acc, &err) == IRIS_OK &&
      iris_textures_load(s, &tx, &err) == IRIS_OK && iris_lights_build(s, acc, &tx, &lights, &err) == IRIS_OK) {
    iris_integrator it = iris_integrator_default(s, acc, &lights, &tx);
    it.method = method;
    gp.use_nee = iris_method_uses_nee(method);
    iris_guide_setup gs = {s, acc, &lights, &tx, &cam, &it, seed, threads, NULL, spp, 0.0, IRIS_SAMPLER_SOBOL, false, NULL, NULL, 0.0, NULL, {0, 0, 0, 0}, false};
    if (iris_guiding_build(&gs, &gp, &g, &err) != IRIS_OK) fprintf(stderr, "build failed: %s\n", err.message);
  } else {
    fprintf(stderr, "scene set-up failed: %s\n", err.message);
  }
  iris_lights_destroy(&lights);
  iris_textures_destroy(&tx);
  iris_accel_destroy(acc);
  return g;
}

#endif
