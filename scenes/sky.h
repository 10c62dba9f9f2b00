/* Built-in scenes lit only by the HDR sky of ../shared/assets/env
 * (immenstadter_horn_1k.hdr, found through the IRIS_SHARED_DIR the build was
 * configured with; a scene whose map is missing fails to render, naming it):
 * `env-objects`, a diffuse and a glossy sphere on a ground plane under the open
 * sky (the methods' and Cycles' agreement test), `env-spheres`, a diffuse and
 * three metal spheres of rising roughness on a ground under the open sky (the
 * environment benchmark against Cycles), and `sky-room`, a closed room
 * lit through one window by the sky and its sun (the guiding benchmark of an
 * environment-lit scene, docs/benchmarks.md). */
#ifndef IRIS_SCENES_SKY_H
#define IRIS_SCENES_SKY_H

#include "core/error.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The map the sky scenes use (an absolute path fixed at build time). */
const char *iris_sky_map_path(void);
iris_status iris_sky_objects_build(iris_scene *scene);
iris_status iris_sky_spheres_build(iris_scene *scene);
iris_status iris_sky_room_build(iris_scene *scene);
iris_status iris_sky_room_corner_build(iris_scene *scene);

#ifdef __cplusplus
}
#endif
#endif
