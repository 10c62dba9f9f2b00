/* Built-in scenes generated in code, with the published numbers (docs/rendering.md,
 * "Built-in scenes"): `cornell-box` (Bitterli's Cornell box) and `veach-mis`
 * (Veach's four-light multiple-importance-sampling scene), `door` (two rooms
 * joined by a narrow door, lit from the room the camera cannot see: the
 * guiding benchmark, scenes/door.h). Also small analytic
 * scenes for tests: `furnace-diffuse`, `furnace-glossy` (albedo-1 spheres under
 * a uniform sky of radiance 1) and `inside-sphere` (a sphere of radiance 1 seen
 * from inside). The failure-stability scenes `stress-*` (scenes/stress/stress.h,
 * docs/stability.md). */
#ifndef IRIS_SCENES_BUILTIN_H
#define IRIS_SCENES_BUILTIN_H

#include <stdbool.h>
#include <stddef.h>

#include "core/error.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* NULL-terminated list of the built-in scene names. */
const char *const *iris_builtin_names(void);
bool iris_builtin_exists(const char *name);
/* Creates the named scene (IRIS_ERR_USAGE for an unknown name). */
iris_status iris_builtin_create(const char *name, iris_scene **out, iris_error *err);

/* Appends a UV sphere with `segments` around and segments / 2 from pole to
 * pole (vertices on the sphere, shared, smooth normals, outward winding) and
 * an identity instance. Returns the mesh index or -1 when out of memory. */
int32_t iris_builtin_add_sphere(iris_scene *scene, iris_vec3 center, float radius, int segments,
                                int32_t material, const char *name);
/* Appends a diffuse material of colour (r, g, b) emitting emission x tint
 * (one-sided); returns its index or -1 when out of memory. */
int32_t iris_builtin_add_diffuse(iris_scene *scene, const char *name, float r, float g, float b, float emission,
                                 const float tint[3]);
/* Appends four lamp materials "lamp_1" .. "lamp_8" (grey 0.8) emitting
 * base x 1, 2, 4, 8 x tint into lamp[4]; false when out of memory. */
bool iris_builtin_add_lamps(iris_scene *scene, float base, const float tint[3], int32_t lamp[4]);
/* Appends the parallelogram c + s*a + t*b, (s, t) in [-1, 1]^2, split into
 * n x n quads, and an identity instance; the front face is on the side of
 * cross(a, b). */
int32_t iris_builtin_add_quad(iris_scene *scene, iris_vec3 c, iris_vec3 a, iris_vec3 b, int n,
                              int32_t material, const char *name);

#ifdef __cplusplus
}
#endif
#endif
