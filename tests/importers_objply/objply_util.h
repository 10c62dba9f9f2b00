/* Helpers for the OBJ/PLY importer tests: import + validate in one call, and
 * totals over a scene's meshes. */
#ifndef IRIS_TESTS_OBJPLY_UTIL_H
#define IRIS_TESTS_OBJPLY_UTIL_H

#include <stdint.h>

#include "importers/import.h"

/* Imports path (.obj or .ply by extension) and validates the scene like
 * iris_import_file does. */
iris_status objply_import(const char *path, iris_scene **out, iris_error *err);
/* The same from memory; ext is "obj" or "ply". */
iris_status objply_import_memory(const char *ext, const char *text, size_t size,
                                 iris_scene **out, iris_error *err);
uint64_t objply_vertices(const iris_scene *s);
uint64_t objply_triangles(const iris_scene *s);
const iris_mesh *objply_mesh_named(const iris_scene *s, const char *name);
/* Total area of a mesh's triangles and the area-weighted geometric normal sum. */
double objply_mesh_area(const iris_mesh *m, double normal_sum[3]);

#endif
