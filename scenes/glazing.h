/* Built-in scenes of light through glass (issue 31; docs/guiding.md,
 * "Refinement"): `sky-room-glazed`, the sky-room with a closed 2 cm glass slab
 * in its window; `sky-room-pane`, the same with a single glass quad as artists
 * often model a pane; `lamp-shade`, a bulb inside a 5-sided amber glass shade
 * (open below) hanging in a dark room. Light sampling cannot see through the
 * glass (no NEE through refraction): the sun's patch, the window's light and
 * the lamp's light on the walls come only through BSDF-sampled or guided
 * directions. */
#ifndef IRIS_SCENES_GLAZING_H
#define IRIS_SCENES_GLAZING_H
#include "core/error.h"
#include "scene/scene.h"
#ifdef __cplusplus
extern "C" {
#endif
iris_status iris_sky_room_glazed_build(iris_scene *scene);
iris_status iris_sky_room_pane_build(iris_scene *scene);
iris_status iris_lamp_shade_build(iris_scene *scene);
#ifdef __cplusplus
}
#endif
#endif
