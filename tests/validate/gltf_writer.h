/* A minimal glTF 2.0 writer for tests: triangle meshes (POSITION, NORMAL,
 * uint32 indices) in one external .bin, each mesh one primitive with one
 * material given as raw JSON, one node per mesh, an optional camera node. */
#ifndef IRIS_TESTS_VALIDATE_GLTF_WRITER_H
#define IRIS_TESTS_VALIDATE_GLTF_WRITER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct gw_mesh {
  float *pos, *nrm;
  uint32_t *idx;
  uint32_t nv, nt, cap_v, cap_t;
  int material;
} gw_mesh;

typedef struct gltf_writer {
  gw_mesh meshes[64];
  int mesh_count;
  const char *materials[32]; /* JSON objects, borrowed */
  int material_count;
  bool has_camera;
  float cam_pos[3], cam_rot[4], cam_yfov, cam_aspect;
} gltf_writer;

int gw_material(gltf_writer *w, const char *json);
/* Starts a mesh with material m and returns its index. */
int gw_mesh_begin(gltf_writer *w, int material);
/* Quad p0, p0+u, p0+u+v, p0+v (front = CCW = u x v), split in n x n cells. */
void gw_quad(gltf_writer *w, int mesh, const float p0[3], const float u[3], const float v[3], int n);
/* Axis-aligned box, outward (inward = false) or inward-facing faces. */
void gw_box(gltf_writer *w, int mesh, const float lo[3], const float hi[3], bool inward, int n);
/* UV sphere with smooth outward normals. */
void gw_sphere(gltf_writer *w, int mesh, const float c[3], float r, int rings, int segments);
void gw_camera(gltf_writer *w, const float pos[3], const float quat_xyzw[4], float yfov, float aspect);
/* Writes path (.gltf) and path's stem + ".bin"; returns 0 on success. Frees the meshes. */
int gw_write(gltf_writer *w, const char *path);

#endif
