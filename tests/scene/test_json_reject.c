/* scene.json_reject: hand-corrupted scene JSON files are rejected with the
 * right status and a message `FILE[:LINE]: element: message` naming the file
 * and the element; harmless oddities (unknown keys, fields that do not apply)
 * only warn. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/fileio.h"
#include "core/log.h"
#include "fixture.h"
#include "scene/scene.h"

static char dir[512];
static char good_json[700];
static char *good_text;

/* A small valid scene: two meshes, two materials, one texture, one camera, one light. */
static void write_good_scene(void) {
  iris_error err;
  iris_error_clear(&err);
  iris_scene *s = iris_scene_create();
  char png[700];
  snprintf(png, sizeof png, "%s/t.png", dir);
  static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  fixture_write(png, sig, 8);
  iris_texture t;
  memset(&t, 0, sizeof t);
  t.path = iris_strdup(png);
  strcpy(t.mime, "image/png");
  iris_scene_add_texture(s, &t);
  iris_material m = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  m.name = iris_strdup("red");
  m.color[1] = m.color[2] = 0.1f;
  m.color_texture = 0;
  iris_scene_add_material(s, &m);
  m = iris_material_default(IRIS_MATERIAL_GLOSSY);
  m.name = iris_strdup("shiny");
  m.roughness = 0.25f;
  iris_scene_add_material(s, &m);
  iris_mesh a = fixture_cube("box", true, false, false), b = fixture_cube("box2", false, false, false);
  a.material = 0;
  b.material = 1;
  iris_scene_add_mesh(s, &a);
  iris_scene_add_mesh(s, &b);
  iris_instance inst = {0, iris_mat4_identity()};
  iris_scene_add_instance(s, &inst);
  inst.mesh = 1;
  inst.transform.m[1][3] = 2.0f;
  iris_scene_add_instance(s, &inst);
  iris_camera c;
  memset(&c, 0, sizeof c);
  c.name = iris_strdup("cam");
  c.to_world = iris_mat4_look_at(iris_v3(0, 1, 5), iris_v3(0, 1, 0), iris_v3(0, 1, 0));
  c.yfov = 0.5f;
  iris_scene_add_camera(s, &c);
  iris_light l;
  memset(&l, 0, sizeof l);
  l.type = IRIS_LIGHT_POINT;
  l.color[0] = l.color[1] = l.color[2] = 1;
  l.intensity = 10;
  iris_scene_add_light(s, &l);
  snprintf(good_json, sizeof good_json, "%s/scene.json", dir);
  CHECK_OK(iris_scene_write(s, good_json, &err), &err);
  iris_scene_destroy(s);
  good_text = fixture_slurp(good_json, NULL);
}

/* Writes the good scene with `from` replaced by `to` as bad.json (sharing the
 * good scene's mesh files) and checks the load error. */
static void expect(const char *from, const char *to, iris_status status, const char *element,
                   const char *message) {
  char bad[700];
  snprintf(bad, sizeof bad, "%s/bad.json", dir);
  fixture_write(bad, good_text, strlen(good_text));
  if (from && !iris_check_record(fixture_replace(bad, from, to), __FILE__, __LINE__,
                                 "fixture text '%s' not found in the good scene", from))
    return;
  iris_error err;
  iris_error_clear(&err);
  iris_scene *s = NULL;
  iris_status st = iris_scene_load(bad, &s, &err);
  char msg[1400];
  iris_error_format(&err, msg, sizeof msg);
  iris_check_record(st == status, __FILE__, __LINE__, "'%s' -> '%s': status %s, expected %s (%s)", from, to,
                    iris_status_name(st), iris_status_name(status), msg);
  iris_check_record(st == IRIS_OK || s == NULL, __FILE__, __LINE__, "scene returned on failure");
  if (st != IRIS_OK) {
    iris_check_record(strstr(msg, ".json") || strstr(msg, ".irmesh") || strstr(msg, ".png"), __FILE__, __LINE__,
                      "'%s' -> '%s': message names no file: %s", from, to, msg);
    iris_check_record(!element || strstr(msg, element), __FILE__, __LINE__, "'%s' -> '%s': message lacks '%s': %s",
                      from, to, element ? element : "", msg);
    iris_check_record(!message || strstr(msg, message), __FILE__, __LINE__, "'%s' -> '%s': message lacks '%s': %s",
                      from, to, message ? message : "", msg);
  }
  iris_scene_destroy(s);
}

static void test_rejects(void) {
  /* The good scene itself loads. */
  expect(NULL, NULL, IRIS_OK, NULL, NULL);
  /* Syntax: the line is reported. */
  expect("\"units\":\t\"m\",", "\"units\":\t\"m\"", IRIS_ERR_PARSE, "bad.json:5:", "JSON syntax error near '\"cameras\"");
  expect("\"version\":\t1,", "\"version\":\t1,,", IRIS_ERR_PARSE, "bad.json:3:", "syntax");
  /* Top level. */
  expect("\"format\":\t\"iris-scene\",", "", IRIS_ERR_INVALID, "bad.json", "missing required key 'format'");
  expect("iris-scene", "gltf", IRIS_ERR_PARSE, NULL, "expected 'iris-scene'");
  expect("\"version\":\t1,", "\"version\":\t2,", IRIS_ERR_UNSUPPORTED, NULL, "version 2");
  expect("\"version\":\t1,", "\"version\":\t\"1\",", IRIS_ERR_INVALID, NULL, "'version' must be an integer");
  expect("\"units\":\t\"m\",", "\"units\":\t\"m\", \"units\": \"cm\",", IRIS_ERR_INVALID, NULL, "duplicate key 'units'");
  expect("\"meshes\":\t[", "\"meshes\":\t{\"a\":[", IRIS_ERR_PARSE, NULL, NULL); /* unbalanced -> syntax */
  /* Meshes. */
  expect("\"file\":\t\"scene.meshes/0.irmesh\",", "", IRIS_ERR_INVALID, "meshes[0]", "missing required key 'file'");
  expect("scene.meshes/1.irmesh", "scene.meshes/7.irmesh", IRIS_ERR_IO, "7.irmesh", "cannot open");
  expect("\"vertices\":\t8,", "\"vertices\":\t\"8\",", IRIS_ERR_INVALID, "meshes[0]", "'vertices' must be an integer");
  expect("\"vertices\":\t8,", "\"vertices\":\t9,", IRIS_ERR_INVALID, "meshes[0]", "'vertices' is 9 but");
  expect("\"vertices\":\t8,", "\"vertices\":\t8.5,", IRIS_ERR_INVALID, "meshes[0]", "integer");
  expect("\"triangles\":\t12,", "\"triangles\":\t-12,", IRIS_ERR_INVALID, "meshes[0]", "integer");
  expect("[\"normals\"]", "[]", IRIS_ERR_INVALID, "meshes[0]", "'attributes' do not match");
  expect("[\"normals\"]", "[\"tangents\"]", IRIS_ERR_INVALID, "meshes[0]", "attributes");
  expect("\"material\":\t1,", "\"material\":\t2,", IRIS_ERR_INVALID, "meshes[1]", "material 2 out of range (material count 2)");
  expect("\"material\":\t1,", "\"material\":\t-2,", IRIS_ERR_INVALID, "meshes[1]", "integer");
  expect("\"material\":\t1,", "\"material\":\tnull,", IRIS_ERR_INVALID, "meshes[1]", "integer");
  expect("\"meshes\":\t[", "\"meshes\":\t[3, ", IRIS_ERR_INVALID, "meshes[0]", "expected an object");
  expect("\"meshes\":\t[", "\"meshes\":\t\"none\", \"x\": [", IRIS_ERR_INVALID, NULL, "'meshes' must be an array");
  /* Instances. */
  expect("\"mesh\":\t1", "\"mesh\":\t2", IRIS_ERR_INVALID, "instances[1]", "mesh 2 out of range (mesh count 2)");
  expect("\"mesh\":\t0", "\"mesh\":\t0, \"transform\": [1, 0, 0]", IRIS_ERR_INVALID, "instances[0]", "array of 16 numbers");
  expect("\"mesh\":\t0", "\"mesh\":\t0, \"transform\": [1,0,0,0, 0,1,0,0, 0,0,1,1e39, 0,0,0,1]", IRIS_ERR_INVALID,
         "instances[0]", "not a finite 32-bit float");
  expect("\"mesh\":\t0", "\"mesh\":\t0, \"transform\": [1,0,0,0, 0,1,0,0, 0,0,1,1e999, 0,0,0,1]", IRIS_ERR_INVALID,
         "instances[0]", "not a finite");
  /* Materials and textures. */
  expect("\"type\":\t\"glossy\"", "\"type\":\t\"velvet\"", IRIS_ERR_INVALID, "materials[1]", "'velvet'");
  expect("\"type\":\t\"glossy\",", "", IRIS_ERR_INVALID, "materials[1]", "missing required key 'type'");
  expect("\"roughness\":\t0.25", "\"roughness\":\t1.25", IRIS_ERR_INVALID, "materials[1]", "roughness 1.25 outside [0, 1]");
  expect("\"roughness\":\t0.25", "\"roughness\":\ttrue", IRIS_ERR_INVALID, "materials[1]", "'roughness' must be a number");
  expect("\"color_texture\":\t0", "\"color_texture\":\t1", IRIS_ERR_INVALID, "materials[0]", "color_texture 1 out of range");
  expect("\"color\":\t[0.8, 0.1, 0.1]", "\"color\":\t[0.8, 0.1]", IRIS_ERR_INVALID, "materials[0]", "array of 3 numbers");
  expect("\"color\":\t[0.8, 0.1, 0.1]", "\"color\":\t[0.8, -0.1, 0.1]", IRIS_ERR_INVALID, "materials[0]", "non-negative");
  /* KHR_materials_anisotropy fields: strength in [0, 1], rotation a finite float. */
  expect("\"type\":\t\"glossy\"", "\"type\":\t\"gltf\", \"anisotropy\": 1.5", IRIS_ERR_INVALID, "materials[1]",
         "anisotropy 1.5 outside [0, 1]");
  expect("\"type\":\t\"glossy\"", "\"type\":\t\"gltf\", \"anisotropy_rotation\": 1e39", IRIS_ERR_INVALID,
         "materials[1]", "anisotropy_rotation");
  expect("\"type\":\t\"glossy\"", "\"type\":\t\"gltf\", \"anisotropy_texture\": 7", IRIS_ERR_INVALID,
         "materials[1]", "anisotropy_texture 7 out of range");
  expect("\"t.png\"", "\"missing.png\"", IRIS_ERR_IO, "textures[0]", "cannot find texture file");
  expect("\"t.png\"", "\"scene.json\"", IRIS_ERR_UNSUPPORTED, "textures[0]", "not a PNG or JPEG");
  /* Cameras and lights. */
  expect("\"yfov_deg\":\t", "\"yfov_deg\":\t180, \"x\":", IRIS_ERR_INVALID, "cameras[0]", "yfov_deg 180 outside (0, 180)");
  expect("\"target\":\t[0, 1, 0]", "\"target\":\t[0, 1, 5]", IRIS_ERR_INVALID, "cameras[0]", "'target' equals 'position'");
  expect("\"target\":\t[0, 1, 0],", "\"to_world\": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1],", IRIS_ERR_INVALID,
         "cameras[0]", "not both");
  expect("\"type\":\t\"point\"", "\"type\":\t\"spot\"", IRIS_ERR_INVALID, "lights[0]", "missing required key 'direction'");
  expect("\"intensity\":\t10", "\"intensity\":\t-10", IRIS_ERR_INVALID, "lights[0]", "intensity -10");
}

/* Oddities that only warn: the scene still loads. */
static void test_tolerated(void) {
  iris_log_level saved = iris_log_get_level();
  iris_log_set_level(IRIS_LOG_QUIET);
  expect("\"units\":\t\"m\",", "\"units\":\t\"m\", \"comment\": \"made by hand\",", IRIS_OK, NULL, NULL);
  expect("\"roughness\":\t0.25", "\"roughness\":\t0.25, \"metallic\": 1", IRIS_OK, NULL, NULL);
  /* Optional keys may be absent: counts, attributes, the look-at up vector. */
  expect("\"vertices\":\t8,", "", IRIS_OK, NULL, NULL);
  expect(",\n\t\t\t\"up\":\t[0, 1, 0]", "", IRIS_OK, NULL, NULL);
  iris_log_set_level(saved);
}

/* A scene that fails validation is not written: no JSON file appears. */
static void test_write_refuses_invalid(void) {
  iris_scene *s = iris_scene_create();
  iris_mesh m = fixture_triangle("t");
  m.indices[2] = 3;
  iris_scene_add_mesh(s, &m);
  char path[700];
  snprintf(path, sizeof path, "%s/never/scene.json", dir);
  iris_error err;
  iris_error_clear(&err);
  CHECK(iris_scene_write(s, path, &err) == IRIS_ERR_INVALID);
  char msg[1400];
  iris_error_format(&err, msg, sizeof msg);
  CHECK(strstr(msg, "meshes[0]: index 3 out of range (vertex count 3)") != NULL);
  CHECK(!iris_path_exists(path));
  iris_scene_destroy(s);
}

int main(void) {
  if (iris_test_tmpdir(dir, sizeof dir, "scene-json") != 0) return TEST_SKIP("no temp dir");
  write_good_scene();
  if (!good_text) return TEST_SUMMARY();
  test_rejects();
  test_tolerated();
  test_write_refuses_invalid();
  free(good_text);
  int rc = TEST_SUMMARY();
  if (rc == 0) iris_test_rmtree(dir);
  return rc;
}
