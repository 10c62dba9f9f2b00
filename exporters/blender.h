/* Blender exporter: writes a Python script for Blender 3.4 that builds the
 * whole scene from an empty file (meshes, Cycles node materials, lights,
 * camera, world) and renders it with the fair-comparison Cycles settings
 * (docs/export.md). Mesh arrays go to a sidecar binary file next to the
 * script, or are embedded in it (base64) when params->embed_meshes is set. */
#ifndef IRIS_EXPORTERS_BLENDER_H
#define IRIS_EXPORTERS_BLENDER_H

#include "exporters/export.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Writes `script_path` (and "<stem>.meshes.bin" / "<stem>.textures/" next to
 * it), all atomically. The script's usage:
 *   blender -b --factory-startup --python-exit-code 1 -P SCRIPT -- --output OUT.exr
 *           [--spp N] [--threads T] [--seed S] [--width W --height H] [--max-bounces B]
 *           [--adaptive-threshold T [--adaptive-min-samples N]] [--time-limit SECONDS]
 * (fixed spp by default; --adaptive-threshold 0.01 is Cycles as Blender users
 * run it, --spp then the per-pixel cap) and it prints "IRIS_BLENDER build_seconds=.. render_seconds=.. ..." on stdout. */
iris_status iris_export_blender(const iris_scene *scene, const char *script_path,
                                const iris_export_params *params, iris_error *err);

/* Writes a script that imports `import_path` (a .gltf/.glb) with Blender's own
 * glTF importer instead of building iris's scene, then sets the world
 * (scene->environment), the camera (resolved from params exactly as
 * iris_export_blender, rotated into Blender's Z-up axes as the importer rotates
 * the geometry) and the same fair-comparison settings. Extra script flag
 * `--inventory FILE.json`: what the importer created (materials, cameras,
 * lights, units, triangle count, bounds in glTF axes). */
iris_status iris_export_blender_import(const iris_scene *scene, const char *import_path,
                                       const char *script_path, const iris_export_params *params,
                                       iris_error *err);

/* Path of the sidecar mesh file for a script path ("a/scene.py" -> "a/scene.meshes.bin"). */
void iris_blender_sidecar_path(const char *script_path, char *out, size_t size);

#ifdef __cplusplus
}
#endif
#endif
