/* scene.model: appenders, defaults, merging (indices remapped), bounds and
 * triangle counts against hand-computed values, and iris_scene_validate
 * rejecting each broken invariant with the element named. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "fixture.h"
#include "scene/scene.h"

static void test_defaults(void) {
  iris_material m = iris_material_default(IRIS_MATERIAL_GLASS);
  CHECK_EQ_INT(m.type, IRIS_MATERIAL_GLASS);
  CHECK(m.color[0] == 0.8f && m.color[1] == 0.8f && m.color[2] == 0.8f);
  CHECK(m.roughness == 0.5f && m.ior == 1.5f && m.specular == 1.0f && m.metallic == 0.0f);
  CHECK(m.specular_color[0] == 1.0f && m.specular_color[2] == 1.0f);
  CHECK(m.color_texture == -1 && m.metallic_roughness_texture == -1 && m.emission_texture == -1);
  CHECK(m.emission[0] == 0.0f && m.emission_two_sided && !m.double_sided && m.name == NULL);
  iris_scene *s = iris_scene_create();
  CHECK_EQ_STR(s->units, "m");
  CHECK_EQ_INT(s->render.max_depth, -1);
  for (int i = 0; i < 100; i++) {
    iris_material x = iris_material_default(IRIS_MATERIAL_DIFFUSE);
    x.name = iris_strdup("n");
    CHECK_EQ_INT(iris_scene_add_material(s, &x), i);
  }
  CHECK_EQ_INT(s->material_count, 100);
  char *d = iris_strdup("abc");
  CHECK_EQ_STR(d, "abc");
  free(d);
  CHECK(iris_strdup(NULL) == NULL);
  iris_scene_destroy(s);
  iris_scene_destroy(NULL);
}

/* Cube [0,1]^3 translated by (10, 0, 0) and scaled by 2 about the origin:
 * bounds and counts follow by hand. */
static void test_bounds_and_counts(void) {
  iris_scene *s = iris_scene_create();
  iris_mesh cube = fixture_cube("c", false, false, false);
  iris_scene_add_mesh(s, &cube);
  iris_mesh tri = fixture_triangle("t");
  iris_scene_add_mesh(s, &tri);
  iris_instance a = {0, iris_mat4_identity()};
  a.transform.m[0][3] = 10.0f;
  iris_scene_add_instance(s, &a);
  iris_instance b = {0, iris_mat4_identity()};
  b.transform.m[0][0] = b.transform.m[1][1] = b.transform.m[2][2] = 2.0f;
  iris_scene_add_instance(s, &b);
  iris_vec3 lo, hi;
  CHECK(iris_scene_bounds(s, &lo, &hi));
  CHECK(lo.x == 0.0f && lo.y == 0.0f && lo.z == 0.0f);
  CHECK(hi.x == 11.0f && hi.y == 2.0f && hi.z == 2.0f);
  CHECK_EQ_INT(iris_scene_triangle_count(s), 24);
  /* The triangle mesh is not instanced: it neither counts nor bounds. */
  iris_instance c = {1, iris_mat4_identity()};
  iris_scene_add_instance(s, &c);
  CHECK_EQ_INT(iris_scene_triangle_count(s), 25);
  CHECK(iris_scene_bounds(s, &lo, &hi));
  CHECK(hi.x == 1e5f && lo.y == -2.5f);
  iris_scene_destroy(s);
}

static void test_merge(void) {
  iris_error err;
  iris_error_clear(&err);
  iris_scene *dst = iris_scene_create();
  iris_scene *src = iris_scene_create();
  iris_texture t;
  memset(&t, 0, sizeof t);
  t.data = malloc(4);
  memcpy(t.data, "\x89PNG", 4);
  t.data_size = 4;
  strcpy(t.mime, "image/png");
  iris_scene_add_texture(dst, &t);
  iris_material m = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  iris_scene_add_material(dst, &m);
  iris_mesh a = fixture_cube("a", false, false, false);
  a.material = 0;
  iris_scene_add_mesh(dst, &a);
  iris_instance ia = {0, iris_mat4_identity()};
  iris_scene_add_instance(dst, &ia);

  t.data = malloc(4);
  memcpy(t.data, "\x89PNG", 4);
  iris_scene_add_texture(src, &t);
  m = iris_material_default(IRIS_MATERIAL_GLTF);
  m.color_texture = 0;
  m.emission_texture = 0;
  iris_scene_add_material(src, &m);
  m = iris_material_default(IRIS_MATERIAL_GLOSSY);
  iris_scene_add_material(src, &m);
  iris_mesh b = fixture_cube("b", false, false, false), c = fixture_triangle("c");
  b.material = 1;
  c.material = -1;
  iris_scene_add_mesh(src, &b);
  iris_scene_add_mesh(src, &c);
  iris_instance ib = {1, iris_mat4_identity()};
  iris_scene_add_instance(src, &ib);
  iris_camera cam;
  memset(&cam, 0, sizeof cam);
  cam.name = iris_strdup("cam");
  cam.to_world = iris_mat4_identity();
  cam.yfov = 1.0f;
  iris_scene_add_camera(src, &cam);
  src->has_environment = true;
  src->environment[1] = 0.5f;
  src->render.spp = 16;

  CHECK_OK(iris_scene_merge(dst, src, &err), &err);
  CHECK_EQ_INT(dst->texture_count, 2);
  CHECK_EQ_INT(dst->material_count, 3);
  CHECK_EQ_INT(dst->mesh_count, 3);
  CHECK_EQ_INT(dst->instance_count, 2);
  CHECK_EQ_INT(dst->camera_count, 1);
  CHECK_EQ_INT(dst->materials[1].color_texture, 1);
  CHECK_EQ_INT(dst->materials[1].emission_texture, 1);
  CHECK_EQ_INT(dst->materials[1].metallic_roughness_texture, -1);
  CHECK_EQ_INT(dst->meshes[1].material, 2);
  CHECK_EQ_INT(dst->meshes[2].material, -1);
  CHECK_EQ_INT(dst->instances[1].mesh, 2);
  CHECK_EQ_STR(dst->meshes[2].name, "c");
  CHECK(dst->has_environment && dst->environment[1] == 0.5f);
  CHECK_EQ_INT(dst->render.spp, 16);
  CHECK_OK(iris_scene_validate(dst, "merged", &err), &err);
  CHECK_EQ_INT(iris_scene_triangle_count(dst), 13);

  /* Different units refuse to merge (and src is consumed either way). */
  iris_scene *cm = iris_scene_create();
  strcpy(cm->units, "cm");
  iris_error_clear(&err);
  CHECK(iris_scene_merge(dst, cm, &err) == IRIS_ERR_INVALID);
  CHECK(strstr(err.message, "'cm'") != NULL);
  CHECK_EQ_INT(dst->mesh_count, 3);
  iris_scene_destroy(dst);
}

/* Builds a small valid scene, breaks one thing, expects `element: message`. */
typedef void (*breaker)(iris_scene *s);
static void expect_invalid(const char *what, breaker brk, const char *element, const char *message) {
  iris_scene *s = iris_scene_create();
  iris_texture t;
  memset(&t, 0, sizeof t);
  t.path = iris_strdup("/nonexistent/is/fine/for/validate.png");
  strcpy(t.mime, "image/png");
  iris_scene_add_texture(s, &t);
  iris_material m = iris_material_default(IRIS_MATERIAL_GLTF);
  m.color_texture = 0;
  iris_scene_add_material(s, &m);
  iris_mesh mesh = fixture_cube("c", true, true, true);
  mesh.material = 0;
  iris_scene_add_mesh(s, &mesh);
  iris_instance inst = {0, iris_mat4_identity()};
  iris_scene_add_instance(s, &inst);
  iris_camera cam;
  memset(&cam, 0, sizeof cam);
  cam.to_world = iris_mat4_identity();
  cam.yfov = 0.7f;
  iris_scene_add_camera(s, &cam);
  iris_light l;
  memset(&l, 0, sizeof l);
  l.type = IRIS_LIGHT_SPOT;
  l.intensity = 1;
  l.direction[2] = -1;
  l.inner_cone = 0.1f;
  l.outer_cone = 0.5f;
  iris_scene_add_light(s, &l);
  iris_error err;
  iris_error_clear(&err);
  if (!brk) {
    CHECK_OK(iris_scene_validate(s, "x.json", &err), &err);
  } else {
    brk(s);
    iris_status st = iris_scene_validate(s, "x.json", &err);
    char msg[1400];
    iris_error_format(&err, msg, sizeof msg);
    char want[300];
    snprintf(want, sizeof want, "x.json: %s: %s", element, message);
    iris_check_record(st == IRIS_ERR_INVALID && strstr(msg, want) == msg, __FILE__, __LINE__,
                      "%s: got [%s] (%s), want prefix [%s]", what, msg, iris_status_name(st), want);
  }
  iris_scene_destroy(s);
}

static void b_index(iris_scene *s) { s->meshes[0].indices[7] = 77; }
static void b_nan_pos(iris_scene *s) { s->meshes[0].positions[7] = NAN; }
static void b_inf_normal(iris_scene *s) { s->meshes[0].normals[4] = INFINITY; }
static void b_nan_uv(iris_scene *s) { s->meshes[0].uvs[15] = NAN; }
static void b_nan_color(iris_scene *s) { s->meshes[0].colors[0] = NAN; }
static void b_no_tris(iris_scene *s) { s->meshes[0].triangle_count = 0; }
static void b_no_verts(iris_scene *s) { s->meshes[0].vertex_count = 0; }
static void b_mesh_mat(iris_scene *s) { s->meshes[0].material = 1; }
static void b_tex_ref(iris_scene *s) { s->materials[0].color_texture = 3; }
static void b_mr_ref(iris_scene *s) { s->materials[0].metallic_roughness_texture = -2; }
static void b_rough(iris_scene *s) { s->materials[0].roughness = 1.5f; }
static void b_ior(iris_scene *s) { s->materials[0].ior = 0.0f; }
static void b_color(iris_scene *s) { s->materials[0].color[1] = NAN; }
static void b_emission(iris_scene *s) { s->materials[0].emission[2] = -1.0f; }
static void b_inst_mesh(iris_scene *s) { s->instances[0].mesh = 1; }
static void b_inst_nan(iris_scene *s) { s->instances[0].transform.m[2][3] = NAN; }
static void b_fov0(iris_scene *s) { s->cameras[0].yfov = 0.0f; }
static void b_fovpi(iris_scene *s) { s->cameras[0].yfov = IRIS_PI; }
static void b_cam_singular(iris_scene *s) { s->cameras[0].to_world.m[1][1] = 0.0f; }
static void b_cone(iris_scene *s) { s->lights[0].inner_cone = 0.6f; }
static void b_light_dir(iris_scene *s) { s->lights[0].direction[2] = 0.0f; }
static void b_tex_both(iris_scene *s) {
  s->textures[0].data = malloc(1);
  s->textures[0].data_size = 1;
}
static void b_env(iris_scene *s) {
  s->has_environment = true;
  s->environment[0] = INFINITY;
}
static void b_render(iris_scene *s) { s->render.width = -1; }

static void test_validate(void) {
  expect_invalid("valid", NULL, NULL, NULL);
  expect_invalid("index", b_index, "meshes[0]", "index 77 out of range (vertex count 8) in triangle 2");
  expect_invalid("nan position", b_nan_pos, "meshes[0]", "position of vertex 2 is not finite");
  expect_invalid("inf normal", b_inf_normal, "meshes[0]", "normal of vertex 1 is not finite");
  expect_invalid("nan uv", b_nan_uv, "meshes[0]", "uv of vertex 7 is not finite");
  expect_invalid("nan color", b_nan_color, "meshes[0]", "color of vertex 0 is not finite");
  expect_invalid("no triangles", b_no_tris, "meshes[0]", "mesh has no triangles");
  expect_invalid("no vertices", b_no_verts, "meshes[0]", "mesh has no vertices");
  expect_invalid("mesh material", b_mesh_mat, "meshes[0]", "material 1 out of range (material count 1)");
  expect_invalid("texture ref", b_tex_ref, "materials[0]", "color_texture 3 out of range (texture count 1)");
  expect_invalid("mr texture ref", b_mr_ref, "materials[0]", "metallic_roughness_texture -2 out of range");
  expect_invalid("roughness", b_rough, "materials[0]", "roughness 1.5 outside [0, 1]");
  expect_invalid("ior", b_ior, "materials[0]", "ior 0 must be finite and positive");
  expect_invalid("color", b_color, "materials[0]", "color must be finite");
  expect_invalid("emission", b_emission, "materials[0]", "emission must be finite and non-negative");
  expect_invalid("instance mesh", b_inst_mesh, "instances[0]", "mesh 1 out of range (mesh count 1)");
  expect_invalid("instance nan", b_inst_nan, "instances[0]", "transform is not finite");
  expect_invalid("fov 0", b_fov0, "cameras[0]", "yfov 0 rad outside (0, pi)");
  expect_invalid("fov pi", b_fovpi, "cameras[0]", "yfov 3.14159 rad outside (0, pi)");
  expect_invalid("singular camera", b_cam_singular, "cameras[0]", "to_world is singular");
  expect_invalid("cone", b_cone, "lights[0]", "cone angles");
  expect_invalid("light dir", b_light_dir, "lights[0]", "direction must be a non-zero vector");
  expect_invalid("texture both", b_tex_both, "textures[0]", "texture has both a file and data");
  expect_invalid("environment", b_env, "environment", "environment must be finite");
  expect_invalid("render", b_render, "render", "image size -1x0");
}

int main(void) {
  test_defaults();
  test_bounds_and_counts();
  test_merge();
  test_validate();
  return TEST_SUMMARY();
}
