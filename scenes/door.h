/* The `door` scene: the hard indirect case for the guiding benchmark. Two
 * rooms joined by a narrow door; the light hangs under the ceiling of the
 * room the camera cannot see, so everything the camera sees is lit through
 * the door by light that has bounced at least once (docs/guiding.md). */
#ifndef IRIS_SCENES_DOOR_H
#define IRIS_SCENES_DOOR_H

#include "core/error.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Appends the door scene's materials, geometry and camera to an empty scene. */
iris_status iris_door_scene_build(iris_scene *scene);

#ifdef __cplusplus
}
#endif
#endif
