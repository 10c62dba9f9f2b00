/* One camera path: sample s of a pixel, jittered in the pixel by the sampler's
 * pixel dimensions, traced by the integrator. Shared by the uniform passes
 * (render.c) and the adaptive rounds (adaptive.c), so that a pixel's sample s
 * is the same path whichever of them takes it. Private to renderer/. */
#ifndef IRIS_RENDERER_CAMERA_PATH_H
#define IRIS_RENDERER_CAMERA_PATH_H

#include <stdint.h>

#include "renderer/camera.h"
#include "renderer/integrator.h"
#include "core/rng.h"

static inline iris_vec3 iris_camera_path(const iris_integrator *it, const iris_pinhole *cam, uint64_t seed, int x,
                                         int y, uint64_t s, iris_path_stats *stats) {
  uint64_t pixel = (uint64_t)y * (uint64_t)cam->width + (uint64_t)x;
  iris_sampler rng = iris_sampler_start_kind(it->sampler, seed, pixel, s);
  float ux, uy;
  iris_sampler_get2(&rng, IRIS_DIM_PIXEL, &ux, &uy);
  iris_ray ray = iris_pinhole_ray(cam, (float)x + ux, (float)y + uy);
  return iris_integrator_radiance(it, ray, &rng, stats);
}

/* dst += src, counter by counter. */
static inline void iris_path_stats_add(iris_path_stats *dst, const iris_path_stats *src) {
  dst->paths += src->paths;
  dst->rays += src->rays;
  dst->shadow_rays += src->shadow_rays;
  dst->nan_count += src->nan_count;
}

#endif
