/* Rooms along a corridor: the hidden-lamps scene of learned light selection
 * (docs/guiding.md "Learned light selection", docs/benchmarks.md). A corridor
 * 32 m long, 2 m wide and 3 m high with 8 rooms of 4 m x 4 m on each side,
 * each behind a wall with a 1.4 m x 2.2 m doorway and lit by its own 2 x 2
 * ceiling lamps (0.4 m squares facing down, four powers); 4 dim lamps light
 * the corridor. The camera stands at one end of the corridor and looks along
 * it into the doorways. From any point only one room's lamps (and a few seen
 * through doorways) are visible: most of the 68 lamps are hidden. */
#ifndef IRIS_SCENES_ROOMS_H
#define IRIS_SCENES_ROOMS_H

#include "core/error.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

iris_status iris_rooms_scene_build(iris_scene *s);

#ifdef __cplusplus
}
#endif
#endif
