/* Scenes and files built by the scene tests themselves (no importer needed). */
#ifndef IRIS_TESTS_SCENE_FIXTURE_H
#define IRIS_TESTS_SCENE_FIXTURE_H

#include <stdbool.h>
#include <stddef.h>

#include "scene/scene.h"

/* An owned mesh: a unit cube [0,1]^3 of 8 vertices and 12 triangles, with the
 * optional attributes requested. */
iris_mesh fixture_cube(const char *name, bool normals, bool uvs, bool colors);
/* A single-triangle mesh. */
iris_mesh fixture_triangle(const char *name);
/* Every feature of the format at least once: all material types with
 * non-default values, an in-memory and a file texture (written into dir),
 * two cameras, all light types, environment and render settings. */
iris_scene *fixture_rich_scene(const char *dir);

/* Whole file into a malloc'ed buffer (NULL if unreadable). */
char *fixture_slurp(const char *path, size_t *size);
bool fixture_write(const char *path, const void *data, size_t size);
/* True when the files have identical bytes. */
bool fixture_same_file(const char *a, const char *b);
/* Replaces the first occurrence of `from` with `to` in a text file. */
bool fixture_replace(const char *path, const char *from, const char *to);

#endif
