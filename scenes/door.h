/* The `door` scenes: the hard indirect cases for the guiding benchmark. Two
 * rooms joined by a narrow door; the light is in the room the camera cannot
 * see, so everything the camera sees is lit through the door. In `door` the
 * light's direct light also falls through the door onto room A's floor; in
 * `door-shielded` the light faces away from the door and room A sees only
 * light that bounced in room B (docs/guiding.md). */
#ifndef IRIS_SCENES_DOOR_H
#define IRIS_SCENES_DOOR_H

#include "core/error.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum iris_door_variant {
  IRIS_DOOR_LIT = 0, /* `door`: the light under room B's ceiling faces down; its direct light
                        falls through the door onto room A's floor, which then lights room A */
  IRIS_DOOR_SHIELDED /* `door-shielded`: the light faces room B's far wall, away from the door;
                        room A is lit only by light that bounced in room B (docs/guiding.md) */
} iris_door_variant;

/* Appends the door scene's materials, geometry and camera to an empty scene
 * (IRIS_DOOR_LIT, the built-in `door`). */
iris_status iris_door_scene_build(iris_scene *scene);
iris_status iris_door_scene_build_variant(iris_scene *scene, iris_door_variant variant);

#ifdef __cplusplus
}
#endif
#endif
