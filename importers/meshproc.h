/* Mesh processing shared by the OBJ and PLY importers, behind a C interface
 * (meshproc.cpp is the only C++ here): angle-weighted vertex normals,
 * degenerate-triangle removal and optional welding; polygon triangulation is
 * in triangulate.h (C), included here for the importers. OpenMesh provides
 * the halfedge reference for the normals (see docs/import-obj-ply.md, "Mesh
 * processing", for what runs where and why). */
#ifndef IRIS_IMPORTERS_MESHPROC_H
#define IRIS_IMPORTERS_MESHPROC_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "importers/triangulate.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

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
