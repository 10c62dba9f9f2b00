/* Tangent frames for tangent-space normal maps, generated the way the glTF
 * specification asks ("client implementations SHOULD calculate tangents using
 * default MikkTSpace algorithms", glTF 2.0 section 3.7.2.1): a small C
 * implementation of MikkTSpace's default path (Mikkelsen 2008, "Simulation of
 * Wrinkled Surfaces Revisited"), documented in docs/import-gltf.md. */
#ifndef IRIS_IMPORTERS_TANGENTS_H
#define IRIS_IMPORTERS_TANGENTS_H

#include <stdbool.h>
#include <stdint.h>

#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Fills mesh->tangents (allocated here, 4 floats per vertex: unit tangent
 * along +u, w = +1 or -1 the bitangent sign with B = w (N x T)) from the
 * positions, normals (required) and the uv set `uv_set` (0: uvs, 1: uvs1;
 * required), with glTF's v-down uvs. Vertices that faces of both uv
 * orientations share (a mirror seam) are split, so *split (may be NULL) gets
 * the number of vertices added; every attribute array is grown accordingly.
 * Returns false when out of memory (the mesh is then unchanged) or when the
 * mesh lacks normals or that uv set. */
bool iris_mesh_generate_tangents(iris_mesh *mesh, int uv_set, uint32_t *split);

#ifdef __cplusplus
}
#endif
#endif
