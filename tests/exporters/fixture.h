/* Scenes and helpers shared by the exporter tests: axis-aligned quads on the
 * z = 0 plane seen by a camera looking straight down, so that every pixel's
 * expected value can be computed independently, plus running external tools. */
#ifndef IRIS_TESTS_EXPORTERS_FIXTURE_H
#define IRIS_TESTS_EXPORTERS_FIXTURE_H

#include <stdbool.h>
#include <stddef.h>

#include "scene/scene.h"

/* A quad centred at (cx, cy, cz), half sizes hx, hy, facing +z (front = CCW
 * seen from +z) or -z. uvs: (0,0) at the top-left corner seen from +z (glTF
 * convention), colors: one colour for all four vertices (NULL: none). */
typedef struct fixture_quad {
  float cx, cy, cz, hx, hy;
  bool facing_down;
  bool normals, uvs;
  const float *normal; /* with normals: this (unit) shading normal instead of +-z */
  const float *color; /* per-vertex colour or NULL */
  int32_t material;
} fixture_quad;
int32_t fixture_add_quad(iris_scene *scene, const char *name, const fixture_quad *q);
/* Adds an instance of mesh with a translation. */
void fixture_add_instance(iris_scene *scene, int32_t mesh, float tx, float ty, float tz);

/* Camera at (0, 0, height) looking down -z with +y up, whose view of the z = 0
 * plane is exactly [-half, half] vertically. */
void fixture_add_top_camera(iris_scene *scene, float height, float half, float aspect);
/* World point on z = 0 seen through film position (fx, fy) in pixels of a
 * w x h image for that camera (fx, fy from the top-left corner). */
void fixture_film_to_plane(float fx, float fy, int w, int h, float half, float aspect, float *x,
                           float *y);

/* Adds a 2x2 RGB PNG of `texels` (top-left, top-right, bottom-left, bottom-right)
 * held in memory, as glTF-embedded images are (the exporter writes it out);
 * `dir` holds the temporary file. Returns its index (aborts on failure). */
int32_t fixture_add_png_texture(iris_scene *scene, const char *dir, const char *name, const float texels[4][3],
                                bool nearest);

/* Full path of an executable found in PATH, or false. */
bool fixture_find_tool(const char *name, char *out, size_t size);
/* Runs a shell command; its stdout+stderr go to `log` (may be NULL). Returns
 * the exit status (-1 when it could not run). */
int fixture_run(const char *command, const char *log);
/* Malloc'ed contents of a text file (NULL if unreadable). */
char *fixture_read_text(const char *path);

#endif
