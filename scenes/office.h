/* The open-plan office: the many-light scene of the light tree (issue 21,
 * docs/rendering.md "Light tree", docs/benchmarks.md). A 24 m x 24 m room
 * 3 m high under 400 small ceiling lamps (0.3 m squares facing down, one mesh
 * each) of four powers 1:2:4:8, 17 of them off; 1.5 m partitions on a 4 m grid
 * with gaps; the camera at eye height in a corner sees part of the room.
 * From any point only a handful of lamps matter. */
#ifndef IRIS_SCENES_OFFICE_H
#define IRIS_SCENES_OFFICE_H

#include "core/error.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

iris_status iris_office_scene_build(iris_scene *s);

#ifdef __cplusplus
}
#endif
#endif
