/* Layout constants of the binary mesh file (docs/format.md, "Mesh files").
 * The read/write functions are declared in scene/scene.h; this header is for
 * the scene module, its tests and the fuzzer. */
#ifndef IRIS_SCENE_MESH_FILE_H
#define IRIS_SCENE_MESH_FILE_H

#include <stdint.h>

#include "scene/scene.h"

#define IRIS_MESH_MAGIC "IRISMESH"
#define IRIS_MESH_FILE_VERSION 1
#define IRIS_MESH_HEADER_SIZE 64
/* Vertex and triangle counts above this are rejected as corrupt (2^31 keeps
 * 3 * count inside int32 for Embree and makes size arithmetic trivially safe). */
#define IRIS_MESH_MAX_COUNT 0x80000000u

enum {
  IRIS_MESH_HAS_NORMALS = 1u << 0,
  IRIS_MESH_HAS_UVS = 1u << 1,
  IRIS_MESH_HAS_COLORS = 1u << 2,
  IRIS_MESH_HAS_UVS1 = 1u << 3,
  IRIS_MESH_HAS_TANGENTS = 1u << 4,
  IRIS_MESH_HAS_ALPHAS = 1u << 5,
  IRIS_MESH_ALL_FLAGS = 63u
};

/* Attribute flags of a mesh (which optional arrays are present). */
uint32_t iris_mesh_file_flags(const iris_mesh *mesh);
/* Exact file size for the given flags and counts (64-bit, cannot overflow for
 * 32-bit counts). */
uint64_t iris_mesh_file_size(uint32_t flags, uint64_t vertex_count, uint64_t triangle_count);

#endif
