/* Octahedral environment maps (Engelhardt & Dachsbacher 2008; thesis 4.1,
 * eqs. 4.1-4.2) for the irradiance caches: direction <-> texel, the exact solid
 * angle of every texel, and sampling a direction uniformly (in solid angle)
 * inside one texel. docs/guiding.md derives the formulas.
 *
 * Local frame: z is the surface normal (the thesis's y). A hemisphere map
 * covers z >= 0 with res x res texels; a sphere map is 2*res x res texels, the
 * left half the upper hemisphere and the right half the lower one, laid out so
 * that the map wraps continuously from its right edge to its left edge. */
#ifndef IRIS_RENDERER_GUIDING_OCTMAP_H
#define IRIS_RENDERER_GUIDING_OCTMAP_H

#include <stdbool.h>
#include <stdint.h>

#include "core/error.h"
#include "core/math.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IRIS_OCTMAP_MAX_RES 256

/* Layout plus the exact per-texel solid-angle table (shared by every cache of
 * the same layout). */
typedef struct iris_octmap {
  int res;             /* texels per side of one hemisphere square */
  bool sphere;         /* true: both hemispheres (2*res x res) */
  int width, height;   /* texel grid: width = res or 2*res, height = res */
  uint32_t texel_count;
  double *solid_angle; /* [texel_count], steradians, exact (Van Oosterom-Strackee) */
} iris_octmap;

/* Builds the layout and its solid-angle table. res in [1, IRIS_OCTMAP_MAX_RES]. */
iris_status iris_octmap_create(iris_octmap *map, int res, bool sphere, iris_error *err);
void iris_octmap_destroy(iris_octmap *map);

/* Continuous texel coordinates (u in [0,width), v in [0,height)) of a local
 * direction (need not be normalised, must be non-zero). Returns false for a
 * direction below the horizon (z < 0) of a hemisphere map. */
bool iris_octmap_dir_to_uv(const iris_octmap *map, iris_vec3 d, float *u, float *v);
/* Index of the texel containing direction d, or -1 (below a hemisphere map). */
int32_t iris_octmap_dir_to_texel(const iris_octmap *map, iris_vec3 d);
/* Unit direction at continuous texel coordinates (u, v). */
iris_vec3 iris_octmap_uv_to_dir(const iris_octmap *map, float u, float v);
/* Unit direction of texel `texel` at position (s, t) in [0,1]^2 inside it. */
iris_vec3 iris_octmap_texel_to_dir(const iris_octmap *map, uint32_t texel, float s, float t);

/* Samples a direction uniformly in solid angle inside a texel, from three
 * uniform numbers: the texel's image on the sphere is a spherical polygon with
 * great-circle edges, split into four spherical triangles (one per texel edge,
 * apex at the texel centre); u0 picks one by solid angle, (u1, u2) sample it
 * (Arvo 1995). The density is exactly 1 / solid_angle[texel]. */
iris_vec3 iris_octmap_sample_in_texel(const iris_octmap *map, uint32_t texel, float u0, float u1,
                                      float u2);

/* Solid angle subtended at the origin by the planar triangle (a, b, c)
 * (Van Oosterom & Strackee 1983); exposed for tests. */
double iris_octmap_triangle_solid_angle(const double a[3], const double b[3], const double c[3]);

#ifdef __cplusplus
}
#endif
#endif
