/* Mesh processing shared by the OBJ and PLY importers, behind a C interface
 * (meshproc.cpp is the only C++ here): polygon triangulation by ear clipping,
 * angle-weighted vertex normals, degenerate-triangle removal and optional
 * welding. OpenMesh provides the halfedge reference for the normals (see
 * docs/import-obj-ply.md, "Mesh processing", for what runs where and why). */
#ifndef IRIS_IMPORTERS_MESHPROC_H
#define IRIS_IMPORTERS_MESHPROC_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Polygons larger than this are fan-triangulated (ear clipping is O(n^2) per
 * polygon and a hostile file could otherwise stall the import). */
#define IRIS_POLYGON_EAR_CLIP_MAX 4096u

/* Reusable scratch space for iris_polygon_triangulate (one per importer call). */
typedef struct iris_polygon_triangulator iris_polygon_triangulator;
iris_polygon_triangulator *iris_polygon_triangulator_create(void);
void iris_polygon_triangulator_destroy(iris_polygon_triangulator *t);

/* Triangulates one polygon of n >= 3 corners; corner i sits at
 * positions[3 * corners[i]]. Writes n - 2 triangles as corner numbers
 * (0..n-1, the polygon's winding kept) to tris (room for 3 * (n - 2)) and
 * returns n - 2, or 0 when out of memory. Quads are split along 0-2 unless
 * that diagonal lies outside (concave quad); larger polygons are ear-clipped
 * in the plane of their Newell normal, which handles concave polygons and
 * keyholes (repeated vertices). Zero-area output is left for
 * iris_mesh_remove_degenerate. */
uint32_t iris_polygon_triangulate(iris_polygon_triangulator *t, const float *positions,
                                  const uint32_t *corners, uint32_t n, uint32_t *tris);

/* Adds, for every triangle, its unit face normal times the corner angle to
 * accum[3 * v] of each of its three vertices (angle-weighted normals, Thürmer &
 * Wüthrich 1998). Degenerate triangles add nothing. */
void iris_normals_accumulate(const float *positions, const uint32_t *indices,
                             size_t triangle_count, float *accum);
/* Normalises accumulated normals in place; a zero sum (vertex used by no
 * non-degenerate triangle) becomes (0, 0, 1). */
void iris_normals_normalize(float *normals, size_t vertex_count);

/* The same angle-weighted normals computed on an OpenMesh halfedge mesh (sector
 * angles from OpenMesh). Returns false when OpenMesh refuses a triangle
 * (non-manifold input), in which case `normals` is unspecified. Used by the
 * tests as an independent reference and by bench/import to measure the cost. */
bool iris_normals_openmesh(const float *positions, size_t vertex_count, const uint32_t *indices,
                           size_t triangle_count, float *normals);

/* Removes triangles with a repeated vertex index or an exactly zero area,
 * compacting indices in place; returns the number removed. */
uint32_t iris_mesh_remove_degenerate(const float *positions, uint32_t *indices,
                                     uint32_t *triangle_count);

/* Merges vertices whose position, normal, uv and colour are all bitwise equal
 * and drops unreferenced vertices; arrays are compacted in place (mesh must own
 * them). Returns the number of vertices removed, or -1 when out of memory. */
int64_t iris_mesh_weld(iris_mesh *mesh);

/* The importers' last step for one mesh (whose arrays it owns): drop
 * degenerate triangles, compute normals when absent and `compute_normals`,
 * weld when `weld`. Returns false when out of memory. */
bool iris_mesh_finish(iris_mesh *mesh, bool compute_normals, bool weld,
                      uint32_t *degenerate_removed);

#ifdef __cplusplus
}
#endif
#endif
