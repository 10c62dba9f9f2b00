/* Where learned light selection has anything to learn (docs/guiding.md,
 * "Learned light selection", "Which scenes learn"): the share of the light
 * tree's own choices, at the surfaces the camera sees first, whose shadow ray
 * something blocks. Where it is small the tree already chooses lights that are
 * seen, and tables would only cost their photons and add their noise. */
#ifndef IRIS_RENDERER_LIGHT_HIDDEN_H
#define IRIS_RENDERER_LIGHT_HIDDEN_H

#include <stdint.h>

#include "renderer/accel.h"
#include "renderer/camera.h"
#include "renderer/lights.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Camera rays traced (a jittered 64 x 64 grid over the whole frame). */
#define IRIS_LIGHTS_HIDDEN_PROBES 4096
/* Below this share the scene keeps the tree alone (the caches' own rule). */
#define IRIS_LIGHTS_HIDDEN_MIN 0.15

/* The share of hidden choices among the probes whose light sample reached a
 * shadow ray (*valid of them; 0 and a share of 0 without a tree). Numbers
 * from a hash of seed and probe: the same for any thread count and any
 * window of the frame. */
double iris_lights_camera_hidden_share(const iris_lights *lights, const iris_accel *accel, const iris_pinhole *cam,
                                       uint64_t seed, int *valid);

#ifdef __cplusplus
}
#endif
#endif
