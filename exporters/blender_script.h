/* Internal to exporters/: the pieces of a Blender script that blender.c and
 * blender_import.c share (the Python prelude of blender_prelude.c and the
 * literal writers of blender.c). */
#ifndef IRIS_EXPORTERS_BLENDER_SCRIPT_H
#define IRIS_EXPORTERS_BLENDER_SCRIPT_H

#include <stdio.h>

#include "exporters/export.h"
#include "scene/scene.h"

/* The fixed Python prelude: argument parsing, materials, meshes, world,
 * camera, fair-comparison settings and main(). */
void iris_blender_put_prelude(FILE *fp);
/* A Python bytes literal holding exactly the bytes of s. */
void iris_blender_put_bytes(FILE *fp, const char *s);
/* A Python tuple of three floats (exact float round trip). */
void iris_blender_put_vec3(FILE *fp, const float *v);
/* WORLD = None, dict(color=(r, g, b)) or dict(map=PATH, strength=S, rotation=DEG):
 * what the prelude's build_world(sc, WORLD) reads. */
void iris_blender_put_world(FILE *fp, const iris_scene *scene);
/* CAMERA = dict(...) for the view (clip range from the scene's bounds). */
void iris_blender_put_camera(FILE *fp, const iris_scene *scene, const iris_export_view *view);

#endif
