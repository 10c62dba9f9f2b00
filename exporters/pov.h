/* POV-Ray 3.7 exporter: writes an SDL scene with one mesh2 per mesh (normals,
 * UVs, per-vertex colours as texture lists), instances as objects with a
 * matrix, the camera as explicit right/up/direction vectors plus the
 * horizontal `angle`, and approximations of the materials and lights (what is
 * exact and what is not: docs/export.md). A coverage mode makes every object a
 * pure white emitter on black, for comparing silhouettes with iris. */
#ifndef IRIS_EXPORTERS_POV_H
#define IRIS_EXPORTERS_POV_H

#include "exporters/export.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Writes `pov_path` (and in-memory textures as "<stem>.textures/<i>.png|jpg"
 * next to it), atomically. Render with
 *   povray +I<pov_path> +O<out>.png +FN +W<w> +H<h> -D -V
 * using the width and height printed in the file's header comment. */
iris_status iris_export_pov(const iris_scene *scene, const char *pov_path,
                            const iris_export_params *params, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
