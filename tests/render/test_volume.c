/* KHR_materials_volume attenuation (docs/rendering.md, "Volume attenuation"):
 * a closed cube [-1, 1]^3 of a smooth glTF material with transmission 1 and
 * ior 1 (no Fresnel, no refraction) in front of an emitter of radiance 1: a
 * camera ray crosses 2 units inside, so each channel is
 * attenuation_color^(2 / attenuation_distance): (0.5, 0.25, 1)^(2/2) here,
 * and (0.5, 0.25, 1)^(2/4) with twice the distance; without attenuation 1.
 * bsdf, nee and mis alike (the path through the cube is delta: only the
 * camera-side hit of the emitter counts). */
#include <stdlib.h>

#include "check.h"
#include "render_run.h"
#include "renderer/render.h"

static void add_mesh(iris_scene *s, const float *p, size_t nv, const uint32_t *idx, size_t nt, int32_t mat) {
  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.name = iris_strdup("m");
  m.vertex_count = (uint32_t)nv;
  m.triangle_count = (uint32_t)nt;
  m.owned = true;
  m.positions = malloc(3 * nv * sizeof(float));
  memcpy(m.positions, p, 3 * nv * sizeof(float));
  m.indices = malloc(3 * nt * sizeof(uint32_t));
  memcpy(m.indices, idx, 3 * nt * sizeof(uint32_t));
  m.material = mat;
  iris_scene_add_mesh(s, &m);
  iris_instance inst = {(uint32_t)(s->mesh_count - 1), iris_mat4_identity()};
  iris_scene_add_instance(s, &inst);
}

static iris_scene *volume_scene(float distance) {
  iris_scene *s = iris_scene_create();
  iris_material g = iris_material_default(IRIS_MATERIAL_GLTF);
  g.color[0] = g.color[1] = g.color[2] = 1.0f;
  g.roughness = 0.0f, g.transmission = 1.0f, g.ior = 1.0f;
  g.attenuation_color[0] = 0.5f, g.attenuation_color[1] = 0.25f, g.attenuation_color[2] = 1.0f;
  g.attenuation_distance = distance;
  iris_scene_add_material(s, &g);
  iris_material e = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  e.color[0] = e.color[1] = e.color[2] = 0.0f;
  e.emission[0] = e.emission[1] = e.emission[2] = 1.0f;
  iris_scene_add_material(s, &e);
  /* cube, counter-clockwise seen from outside */
  const float c[24] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1};
  const uint32_t ci[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                           2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3};
  add_mesh(s, c, 8, ci, 12, 0);
  const float q[12] = {-10, -10, -3, 10, -10, -3, 10, 10, -3, -10, 10, -3};
  const uint32_t qi[6] = {0, 1, 2, 0, 2, 3};
  add_mesh(s, q, 4, qi, 2, 1);
  iris_camera cam;
  memset(&cam, 0, sizeof cam);
  cam.name = iris_strdup("c");
  cam.to_world = iris_mat4_identity();
  cam.to_world.m[2][3] = 5.0f;
  cam.yfov = 0.02f; /* rays within 0.6 degrees of the axis: path length 2.0001 at most */
  cam.aspect = 1.0f;
  iris_scene_add_camera(s, &cam);
  return s;
}

static void check(float distance, const double want[3]) {
  iris_scene *s = volume_scene(distance);
  const iris_method methods[3] = {IRIS_METHOD_BSDF, IRIS_METHOD_NEE, IRIS_METHOD_MIS};
  for (int k = 0; k < 3; k++) {
    iris_render_params p = iris_test_params(8, 8, 4, methods[k], 0);
    double mean[3];
    if (!CHECK(iris_test_render_mean(s, &p, mean, NULL))) continue;
    printf("  distance %g %-4s: %.5f %.5f %.5f (expected %.5f %.5f %.5f)\n", (double)distance,
           iris_method_name(methods[k]), mean[0], mean[1], mean[2], want[0], want[1], want[2]);
    for (int c = 0; c < 3; c++) CHECK_NEAR(mean[c], want[c], 2e-4);
  }
  iris_scene_destroy(s);
}

int main(void) {
  const double d2[3] = {0.5, 0.25, 1.0}, d4[3] = {0.70710678, 0.5, 1.0}, none[3] = {1, 1, 1};
  check(2.0f, d2);
  check(4.0f, d4);
  check(0.0f, none);
  return iris_check_summary("render.volume");
}
