/* What a scene is seen through, shared by the renderer and the exporters so
 * that `iris render` and an export frame the same picture: which camera, the
 * film size, and the automatic camera for scenes without one. */
#ifndef IRIS_SCENE_FRAMING_H
#define IRIS_SCENE_FRAMING_H

#include <stdint.h>

#include "core/math.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Height used when neither the caller nor the scene gives a resolution. */
#define IRIS_FRAMING_DEFAULT_HEIGHT 512
/* Vertical field of view of the automatic camera (radians, 40 degrees). */
#define IRIS_FRAMING_AUTO_YFOV 0.6981317f

/* Index of the first camera called `name`, or -1 when there is none. */
int32_t iris_scene_find_camera(const iris_scene *scene, const char *name);

/* Film size: width/height <= 0 come from the scene's render settings (when
 * both are unset), then from the aspect ratio of `camera` (NULL: automatic
 * camera) or of the render settings, IRIS_FRAMING_DEFAULT_HEIGHT pixels high
 * as the last resort; at least 1 x 1. */
void iris_framing_resolve_size(const iris_scene *scene, const iris_camera *camera, int width,
                               int height, int *out_width, int *out_height);

/* The automatic camera for a film of `aspect` (width / height): on +Z of the
 * scene's bounding sphere (a unit cube when the scene has no bounds), looking
 * along -Z with +Y up, IRIS_FRAMING_AUTO_YFOV high, just far enough for the
 * sphere to fill the narrower field of view. */
iris_vec3 iris_framing_auto_origin(const iris_scene *scene, float aspect);

#ifdef __cplusplus
}
#endif
#endif
