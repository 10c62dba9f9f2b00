/* The pinhole perspective camera: from a scene camera (vertical field of view,
 * looks along its local -Z with +Y up, as glTF and Blender) or framed
 * automatically around the scene bounds. Film coordinates are pixels with x to
 * the right and y down, (0, 0) the top-left corner of the image. */
#ifndef IRIS_RENDERER_CAMERA_H
#define IRIS_RENDERER_CAMERA_H

#include <stdbool.h>

#include "core/error.h"
#include "core/math.h"
#include "renderer/accel.h"
#include "scene/framing.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Kept for callers of the old names; the values live in scene/framing.h. */
#define IRIS_CAMERA_DEFAULT_HEIGHT IRIS_FRAMING_DEFAULT_HEIGHT
#define IRIS_CAMERA_AUTO_YFOV IRIS_FRAMING_AUTO_YFOV

typedef struct iris_pinhole {
  iris_vec3 origin;
  iris_vec3 right, up, forward; /* unit world vectors */
  float tan_half_yfov;
  float aspect;                 /* width / height of the film */
  int width, height;
  float yfov;                   /* radians */
  bool automatic;               /* framed from the bounds, not from the scene */
  char name[64];
} iris_pinhole;

/* Picks the scene camera called `name` (the first of that name; NULL: the
 * first camera; none in the scene: auto-framing) and resolves the resolution
 * (iris_framing_resolve_size: width/height <= 0 come from the scene's render
 * settings, then from the camera's aspect ratio, IRIS_FRAMING_DEFAULT_HEIGHT
 * pixels high as the last resort). */
iris_status iris_pinhole_setup(const iris_scene *scene, const char *name, int width, int height,
                               iris_pinhole *out, iris_error *err);

/* Primary ray through film position (fx, fy) in pixels; d is unit length. */
iris_ray iris_pinhole_ray(const iris_pinhole *cam, float fx, float fy);

#ifdef __cplusplus
}
#endif
#endif
