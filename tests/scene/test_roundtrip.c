/* scene.roundtrip: write -> load gives back every value bit for bit (floats
 * included, through the JSON's shortest decimals), and write -> load -> write
 * reproduces every file byte for byte. */
#include <float.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/fileio.h"
#include "fixture.h"
#include "scene/scene.h"

static char dir[512];

/* Bitwise float equality, except that -0 and +0 are the same number (JSON
 * cannot tell them apart). */
static bool same_floats(const float *a, const float *b, size_t n) {
  if (!a || !b) return a == b;
  for (size_t i = 0; i < n; i++) {
    if (a[i] == 0.0f && b[i] == 0.0f) continue;
    if (memcmp(&a[i], &b[i], sizeof(float)) != 0) return false;
  }
  return true;
}

static bool same_str(const char *a, const char *b) { return (!a && !b) || (a && b && strcmp(a, b) == 0); }

static void compare_scenes(const iris_scene *a, const iris_scene *b) {
  CHECK_EQ_STR(a->units, b->units);
  CHECK_EQ_INT(a->texture_count, b->texture_count);
  CHECK_EQ_INT(a->material_count, b->material_count);
  CHECK_EQ_INT(a->mesh_count, b->mesh_count);
  CHECK_EQ_INT(a->instance_count, b->instance_count);
  CHECK_EQ_INT(a->camera_count, b->camera_count);
  CHECK_EQ_INT(a->light_count, b->light_count);
  for (size_t i = 0; i < a->texture_count && i < b->texture_count; i++) {
    const iris_texture *x = &a->textures[i], *y = &b->textures[i];
    CHECK(same_str(x->name, y->name));
    CHECK_EQ_STR(x->mime, y->mime);
    CHECK_EQ_INT(x->wrap_s, y->wrap_s);
    CHECK_EQ_INT(x->wrap_t, y->wrap_t);
    CHECK_EQ_INT(x->nearest, y->nearest);
    CHECK_EQ_INT(x->uv_set, y->uv_set);
    CHECK_EQ_INT(x->has_transform, y->has_transform);
    if (x->has_transform && y->has_transform) {
      CHECK(same_floats(x->offset, y->offset, 2));
      CHECK(same_floats(&x->rotation, &y->rotation, 1));
      CHECK(same_floats(x->scale, y->scale, 2));
    }
  }
  for (size_t i = 0; i < a->material_count && i < b->material_count; i++) {
    const iris_material *x = &a->materials[i], *y = &b->materials[i];
    CHECK(same_str(x->name, y->name));
    CHECK_EQ_INT(x->type, y->type);
    CHECK(same_floats(x->color, y->color, 3));
    CHECK_EQ_INT(x->color_texture, y->color_texture);
    CHECK(same_floats(x->emission, y->emission, 3));
    CHECK_EQ_INT(x->emission_texture, y->emission_texture);
    CHECK_EQ_INT(x->emission_two_sided, y->emission_two_sided);
    CHECK_EQ_INT(x->normal_texture, y->normal_texture);
    CHECK(same_floats(&x->normal_scale, &y->normal_scale, 1));
    CHECK_EQ_INT(x->double_sided, y->double_sided);
    if (x->type != IRIS_MATERIAL_DIFFUSE) CHECK(same_floats(&x->roughness, &y->roughness, 1));
    if (x->type == IRIS_MATERIAL_GLASS || x->type == IRIS_MATERIAL_GLTF) CHECK(same_floats(&x->ior, &y->ior, 1));
    if (x->type == IRIS_MATERIAL_GLTF) {
      CHECK(same_floats(&x->metallic, &y->metallic, 1));
      CHECK_EQ_INT(x->metallic_roughness_texture, y->metallic_roughness_texture);
      CHECK(same_floats(&x->specular, &y->specular, 1));
      CHECK(same_floats(x->specular_color, y->specular_color, 3));
      CHECK(same_floats(&x->transmission, &y->transmission, 1));
      CHECK(same_floats(&x->anisotropy, &y->anisotropy, 1));
      CHECK(same_floats(&x->anisotropy_rotation, &y->anisotropy_rotation, 1));
      CHECK_EQ_INT(x->anisotropy_texture, y->anisotropy_texture);
    }
  }
  for (size_t i = 0; i < a->mesh_count && i < b->mesh_count; i++) {
    const iris_mesh *x = &a->meshes[i], *y = &b->meshes[i];
    CHECK(same_str(x->name, y->name));
    CHECK_EQ_INT(x->material, y->material);
    CHECK_EQ_INT(x->vertex_count, y->vertex_count);
    CHECK_EQ_INT(x->triangle_count, y->triangle_count);
    if (x->vertex_count != y->vertex_count || x->triangle_count != y->triangle_count) continue;
    size_t nv = x->vertex_count;
    /* Mesh files are binary: even -0 survives, so compare raw bytes. */
    CHECK(memcmp(x->positions, y->positions, 12 * nv) == 0);
    CHECK((!x->normals && !y->normals) || (x->normals && y->normals && memcmp(x->normals, y->normals, 12 * nv) == 0));
    CHECK((!x->uvs && !y->uvs) || (x->uvs && y->uvs && memcmp(x->uvs, y->uvs, 8 * nv) == 0));
    CHECK((!x->colors && !y->colors) || (x->colors && y->colors && memcmp(x->colors, y->colors, 12 * nv) == 0));
    CHECK((!x->uvs1 && !y->uvs1) || (x->uvs1 && y->uvs1 && memcmp(x->uvs1, y->uvs1, 8 * nv) == 0));
    CHECK((!x->tangents && !y->tangents) ||
          (x->tangents && y->tangents && memcmp(x->tangents, y->tangents, 16 * nv) == 0));
    CHECK(memcmp(x->indices, y->indices, 12 * (size_t)x->triangle_count) == 0);
  }
  for (size_t i = 0; i < a->instance_count && i < b->instance_count; i++) {
    CHECK_EQ_INT(a->instances[i].mesh, b->instances[i].mesh);
    CHECK(same_floats(&a->instances[i].transform.m[0][0], &b->instances[i].transform.m[0][0], 16));
  }
  for (size_t i = 0; i < a->camera_count && i < b->camera_count; i++) {
    const iris_camera *x = &a->cameras[i], *y = &b->cameras[i];
    CHECK(same_str(x->name, y->name));
    CHECK(same_floats(&x->to_world.m[0][0], &y->to_world.m[0][0], 16));
    CHECK(same_floats(&x->yfov, &y->yfov, 1));
    CHECK(same_floats(&x->aspect, &y->aspect, 1));
  }
  for (size_t i = 0; i < a->light_count && i < b->light_count; i++) {
    const iris_light *x = &a->lights[i], *y = &b->lights[i];
    CHECK(same_str(x->name, y->name));
    CHECK_EQ_INT(x->type, y->type);
    CHECK(same_floats(x->color, y->color, 3));
    CHECK(same_floats(&x->intensity, &y->intensity, 1));
    if (x->type != IRIS_LIGHT_DIRECTIONAL) CHECK(same_floats(x->position, y->position, 3));
    if (x->type != IRIS_LIGHT_POINT) CHECK(same_floats(x->direction, y->direction, 3));
    CHECK(same_floats(&x->range, &y->range, 1));
    if (x->type == IRIS_LIGHT_SPOT) {
      CHECK(same_floats(&x->inner_cone, &y->inner_cone, 1));
      CHECK(same_floats(&x->outer_cone, &y->outer_cone, 1));
    }
  }
  CHECK_EQ_INT(a->has_environment, b->has_environment);
  CHECK(same_floats(a->environment, b->environment, 3));
  CHECK_EQ_INT(a->render.width, b->render.width);
  CHECK_EQ_INT(a->render.height, b->render.height);
  CHECK_EQ_INT(a->render.spp, b->render.spp);
  CHECK_EQ_INT(a->render.max_depth, b->render.max_depth);
  CHECK_EQ_STR(a->render.method, b->render.method);
  CHECK_EQ_INT(a->render.has_seed, b->render.has_seed);
  CHECK(a->render.seed == b->render.seed);
}

static void test_rich_scene(void) {
  iris_error err;
  iris_error_clear(&err);
  iris_scene *s = fixture_rich_scene(dir);
  CHECK(s != NULL);
  if (!s) return;
  char a_json[700], a_dir[600];
  snprintf(a_dir, sizeof a_dir, "%s/a", dir);
  snprintf(a_json, sizeof a_json, "%s/scene.json", a_dir);
  CHECK_OK(iris_scene_write(s, a_json, &err), &err);

  iris_scene *loaded = NULL;
  CHECK_OK(iris_scene_load(a_json, &loaded, &err), &err);
  if (!loaded) {
    iris_scene_destroy(s);
    return;
  }
  compare_scenes(s, loaded);
  CHECK_EQ_STR(loaded->source_path, a_json);

  /* The in-memory JPEG became a file next to the JSON with the same bytes. */
  char path[800];
  snprintf(path, sizeof path, "%s/scene.textures/0.jpg", a_dir);
  size_t n = 0;
  char *bytes = fixture_slurp(path, &n);
  CHECK(bytes && n == s->textures[0].data_size && memcmp(bytes, s->textures[0].data, n) == 0);
  free(bytes);
  CHECK(loaded->textures[0].path && loaded->textures[0].path[0] == '/');
  CHECK(loaded->textures[0].path && strstr(loaded->textures[0].path, "/a/scene.textures/0.jpg"));
  CHECK(loaded->textures[1].path && strstr(loaded->textures[1].path, "/assets/wood.png"));
  CHECK(loaded->textures[1].data == NULL && loaded->textures[0].data == NULL);
  /* Loaded meshes are borrowed from memory maps. */
  CHECK(!loaded->meshes[0].owned);

  /* The JSON is readable: the look-at camera is written as position/target/up,
   * 0.8 as "0.8", the 2^64-ish seed as a string. */
  char *json = fixture_slurp(a_json, NULL);
  CHECK(json && strstr(json, "\"position\":\t[0, 1, 6.8]"));
  CHECK(json && strstr(json, "\"target\":\t[0, 1, 0]"));
  CHECK(json && strstr(json, "\"to_world\""));
  CHECK(json && strstr(json, "\"yfov_deg\":\t19.5"));
  CHECK(json && strstr(json, "\"seed\":\t\"18446744073709551557\""));
  CHECK(json && strstr(json, "\"roughness\":\t0.05,"));
  CHECK(json && !strstr(json, "0.800000011920929"));
  free(json);

  /* load -> write over the same files reproduces every byte. */
  const char *files[] = {"scene.json", "scene.meshes/0.irmesh", "scene.meshes/1.irmesh",
                         "scene.meshes/2.irmesh", "scene.textures/0.jpg"};
  char *before[5];
  size_t before_n[5];
  for (int i = 0; i < 5; i++) {
    snprintf(path, sizeof path, "%s/%s", a_dir, files[i]);
    before[i] = fixture_slurp(path, &before_n[i]);
    CHECK(before[i] != NULL);
  }
  CHECK_OK(iris_scene_write(loaded, a_json, &err), &err);
  for (int i = 0; i < 5; i++) {
    snprintf(path, sizeof path, "%s/%s", a_dir, files[i]);
    size_t m = 0;
    char *after = fixture_slurp(path, &m);
    if (!iris_check_record(after && before[i] && m == before_n[i] && memcmp(after, before[i], m) == 0,
                           __FILE__, __LINE__, "%s differs after load -> write", files[i]))
      fprintf(stderr, "--- before:\n%s\n--- after:\n%s\n", i == 0 ? before[i] : "(binary)", i == 0 && after ? after : "(binary)");
    free(after);
    free(before[i]);
  }

  /* A second folder: the mesh files are identical, the scene loads equal. */
  char b_json[700];
  snprintf(b_json, sizeof b_json, "%s/b/scene.json", dir);
  CHECK_OK(iris_scene_write(loaded, b_json, &err), &err);
  for (int i = 1; i <= 3; i++) {
    char pa[800], pb[800];
    snprintf(pa, sizeof pa, "%s/%s", a_dir, files[i]);
    snprintf(pb, sizeof pb, "%s/b/%s", dir, files[i]);
    CHECK(fixture_same_file(pa, pb));
  }
  /* Rewriting a smaller scene under the same name removes the stale mesh files. */
  iris_scene *small = iris_scene_create();
  iris_mesh tri = fixture_triangle("t");
  iris_scene_add_mesh(small, &tri);
  char stale[800];
  snprintf(stale, sizeof stale, "%s/b/scene.meshes/1.irmesh", dir);
  CHECK(iris_path_exists(stale));
  char c_json[700];
  snprintf(c_json, sizeof c_json, "%s/b/scene.json", dir);
  CHECK_OK(iris_scene_write(small, c_json, &err), &err);
  CHECK(!iris_path_exists(stale));
  stale[strlen(stale) - 8] = '0';
  CHECK(iris_path_exists(stale));
  iris_scene_destroy(small);
  CHECK_OK(iris_scene_write(loaded, b_json, &err), &err);

  iris_scene *again = NULL;
  CHECK_OK(iris_scene_load(b_json, &again, &err), &err);
  if (again) compare_scenes(s, again);
  iris_scene_destroy(again);
  iris_scene_destroy(loaded);
  iris_scene_destroy(s);
}

/* Random finite float bit patterns (denormals, huge, tiny, negative) through
 * transforms; random angles through yfov_deg and the cone degrees. */
static void test_float_exactness(void) {
  iris_error err;
  iris_error_clear(&err);
  iris_scene *s = iris_scene_create();
  iris_mesh tri = fixture_triangle(NULL);
  iris_scene_add_mesh(s, &tri);
  uint64_t state = 0x9E3779B97F4A7C15ull;
  for (int i = 0; i < 400; i++) {
    iris_instance inst;
    inst.mesh = 0;
    for (int k = 0; k < 16; k++) {
      float f;
      do {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        uint32_t bits = (uint32_t)(state >> 32);
        memcpy(&f, &bits, sizeof f);
      } while (!isfinite(f));
      inst.transform.m[k / 4][k % 4] = f;
    }
    iris_scene_add_instance(s, &inst);
  }
  for (int i = 0; i < 200; i++) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    float u = (float)((state >> 40) + 1) / (float)(1 << 24); /* (0, 1] */
    iris_camera c;
    memset(&c, 0, sizeof c);
    c.to_world = iris_mat4_identity();
    c.yfov = u * 3.1415925f;
    c.aspect = u * 3.0f;
    iris_scene_add_camera(s, &c);
    iris_light l;
    memset(&l, 0, sizeof l);
    l.type = IRIS_LIGHT_SPOT;
    l.color[0] = u;
    l.intensity = 1.0f / u;
    l.direction[1] = -1;
    l.outer_cone = u * 1.5707963f;
    l.inner_cone = l.outer_cone * u;
    iris_scene_add_light(s, &l);
  }
  char json[700];
  snprintf(json, sizeof json, "%s/floats/f.json", dir);
  CHECK_OK(iris_scene_write(s, json, &err), &err);
  iris_scene *loaded = NULL;
  CHECK_OK(iris_scene_load(json, &loaded, &err), &err);
  if (loaded) compare_scenes(s, loaded);
  iris_scene_destroy(loaded);
  iris_scene_destroy(s);
}

/* An empty scene is valid and round-trips too. */
static void test_empty(void) {
  iris_error err;
  iris_error_clear(&err);
  iris_scene *s = iris_scene_create();
  char json[700];
  snprintf(json, sizeof json, "%s/empty.json", dir);
  CHECK_OK(iris_scene_write(s, json, &err), &err);
  iris_scene *loaded = NULL;
  CHECK_OK(iris_scene_load(json, &loaded, &err), &err);
  if (loaded) compare_scenes(s, loaded);
  CHECK(!iris_scene_bounds(s, NULL, NULL));
  iris_scene_destroy(loaded);
  iris_scene_destroy(s);
}

int main(void) {
  if (iris_test_tmpdir(dir, sizeof dir, "scene-roundtrip") != 0) return TEST_SKIP("no temp dir");
  test_rich_scene();
  test_float_exactness();
  test_empty();
  int rc = TEST_SUMMARY();
  if (rc == 0) iris_test_rmtree(dir);
  return rc;
}
