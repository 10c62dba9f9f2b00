/* tools_import.cli: `iris import` and `iris info` as a user runs them: exit
 * codes, messages naming the offending argument or file, no output file on
 * any failure, --help, --quiet, merging, --camera, and CLI round trips of the
 * real assets (whose counts come from shared/assets/README.md).
 * Usage: test_tools_import_cli IRIS_BINARY ASSETS_DIR */
#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "check.h"
#include "cli_run.h"
#include "core/fileio.h"
#include "core/log.h"
#include "scene/scene.h"

static const char *iris_bin;
static const char *assets;
static char dir[512];
static char out_text[1 << 16], err_text[1 << 16];

/* Runs `iris ARGS` in the test folder; returns the exit code and fills
 * out_text/err_text. */
static int run(const char *args) {
  return iris_test_run_cli(dir, iris_bin, args, out_text, sizeof out_text, err_text, sizeof err_text);
}

static bool exists(const char *name) { return iris_test_file_exists(dir, name); }

#define EXPECT_RUN(args, code, needle)                                                          \
  do {                                                                                           \
    int rc_ = run(args);                                                                         \
    iris_check_record(rc_ == (code), __FILE__, __LINE__, "iris %s: exit %d, expected %d; stderr: %s", \
                      args, rc_, code, err_text);                                               \
    if (needle)                                                                                  \
      iris_check_record(strstr(err_text, needle ? needle : "") || strstr(out_text, needle ? needle : ""), \
                        __FILE__, __LINE__, "iris %s: output lacks '%s'; stderr: %s", args,       \
                        needle ? needle : "", err_text);                                          \
  } while (0)

static iris_mesh cube(void) {
  static const float pos[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  static const uint32_t idx[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                   2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3};
  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.vertex_count = 8;
  m.triangle_count = 12;
  m.positions = malloc(sizeof pos);
  memcpy(m.positions, pos, sizeof pos);
  m.indices = malloc(sizeof idx);
  memcpy(m.indices, idx, sizeof idx);
  m.material = -1;
  m.owned = true;
  return m;
}

/* a.json: a cube (emissive material) instanced twice, camera "front";
 * b.json: a cube with a glossy material, cameras "left" and "top". */
static void build_inputs(void) {
  iris_error err;
  iris_error_clear(&err);
  char path[700];
  iris_scene *a = iris_scene_create();
  iris_material m = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  m.name = iris_strdup("lamp");
  m.emission[0] = m.emission[1] = m.emission[2] = 5.0f;
  iris_scene_add_material(a, &m);
  iris_mesh c = cube();
  c.material = 0;
  iris_scene_add_mesh(a, &c);
  iris_instance inst = {0, iris_mat4_identity()};
  iris_scene_add_instance(a, &inst);
  inst.transform.m[0][3] = -3.0f;
  iris_scene_add_instance(a, &inst);
  iris_camera cam;
  memset(&cam, 0, sizeof cam);
  cam.name = iris_strdup("front");
  cam.to_world = iris_mat4_look_at(iris_v3(0, 0, 10), iris_v3(0, 0, 0), iris_v3(0, 1, 0));
  cam.yfov = 0.5f;
  iris_scene_add_camera(a, &cam);
  snprintf(path, sizeof path, "%s/a.json", dir);
  CHECK_OK(iris_scene_write(a, path, &err), &err);
  iris_scene_destroy(a);

  iris_scene *b = iris_scene_create();
  m = iris_material_default(IRIS_MATERIAL_GLOSSY);
  iris_scene_add_material(b, &m);
  c = cube();
  c.material = 0;
  iris_scene_add_mesh(b, &c);
  inst.mesh = 0;
  inst.transform = iris_mat4_identity();
  inst.transform.m[1][3] = 5.0f;
  iris_scene_add_instance(b, &inst);
  cam.name = iris_strdup("left");
  cam.to_world = iris_mat4_look_at(iris_v3(-10, 0, 0), iris_v3(0, 0, 0), iris_v3(0, 1, 0));
  iris_scene_add_camera(b, &cam);
  cam.name = iris_strdup("top");
  cam.to_world = iris_mat4_look_at(iris_v3(0, 10, 0), iris_v3(0, 0, 0), iris_v3(0, 0, -1));
  iris_scene_add_camera(b, &cam);
  snprintf(path, sizeof path, "%s/b.json", dir);
  CHECK_OK(iris_scene_write(b, path, &err), &err);
  iris_scene_destroy(b);

  /* corrupt.json: a copy of a.json whose mesh file has an index out of range
   * (checksum fixed up is not needed: a flipped byte fails the checksum). */
  snprintf(path, sizeof path, "%s/corrupt.meshes", dir);
  iris_mkdir_p(path, NULL);
  char cmd[2400];
  snprintf(cmd, sizeof cmd,
           "cd '%s' && sed 's/a.meshes/corrupt.meshes/' a.json > corrupt.json && cp a.meshes/0.irmesh corrupt.meshes/0.irmesh && "
           "printf '\\377' | dd of=corrupt.meshes/0.irmesh bs=1 seek=200 conv=notrunc 2>/dev/null",
           dir);
  CHECK(system(cmd) == 0);
  /* unknown.json: a.json with an unknown key (a warning, not an error). */
  snprintf(cmd, sizeof cmd, "cd '%s' && sed 's/\"units\":/\"comment\": \"hi\", \"units\":/' a.json > unknown.json", dir);
  CHECK(system(cmd) == 0);
}

static void test_usage(void) {
  EXPECT_RUN("import --help", 0, "Usage: iris import");
  EXPECT_RUN("info --help", 0, "Usage: iris info");
  EXPECT_RUN("import", 2, "no input file");
  EXPECT_RUN("import a.json", 2, "missing --output");
  EXPECT_RUN("import a.json -o out.txt", 2, "'out.txt' must end in .json");
  CHECK(!exists("out.txt"));
  EXPECT_RUN("import a.json -o out.json --bogus", 2, "unknown option '--bogus'");
  EXPECT_RUN("import a.json -o out.json -x", 2, "unknown option '-x'");
  EXPECT_RUN("import a.json -o", 2, "'-o' needs a value");
  EXPECT_RUN("import a.json -o out.json -o out2.json", 2, "--output given twice");
  EXPECT_RUN("import a.json --camera x --camera y -o out.json", 2, "--camera given twice");
  EXPECT_RUN("import missing.obj -o out.json", 2, "missing.obj");
  EXPECT_RUN("import a.json scene.xyz -o out.json", 2, "'scene.xyz'");
  EXPECT_RUN("import a.json -o a.json", 2, "also an input");
  EXPECT_RUN("import a.json -o ./a.json", 2, "also an input");
  EXPECT_RUN("import a.json -o nodir/out.json", 2, "'nodir' does not exist");
  CHECK(!exists("out.json") && !exists("out2.json") && !exists("out.meshes"));
  EXPECT_RUN("info", 2, "no input file");
  EXPECT_RUN("info a.json b.json", 2, "unexpected argument 'b.json'");
  EXPECT_RUN("info missing.json", 2, "missing.json");
  EXPECT_RUN("info --frobnicate a.json", 2, "unknown option '--frobnicate'");
}

static void test_bad_input(void) {
  EXPECT_RUN("import corrupt.json -o out.json", 2, "corrupt.meshes/0.irmesh");
  CHECK(strstr(err_text, "iris: ") == err_text);
  CHECK(!exists("out.json") && !exists("out.meshes"));
  /* A bad second input: nothing is written either. */
  EXPECT_RUN("import a.json corrupt.json -o out.json", 2, "checksum");
  CHECK(!exists("out.json") && !exists("out.meshes"));
  EXPECT_RUN("info corrupt.json", 2, "corrupt.meshes/0.irmesh");
  EXPECT_RUN("import a.json --camera nope -o out.json", 2, "no camera named 'nope'");
  CHECK(strstr(err_text, "'front'") != NULL);
  CHECK(!exists("out.json"));
  /* glTF: an out-of-range extension factor and a texCoord set the primitive lacks
   * (one triangle, data URI buffer): one line "iris: FILE: ...", exit 2, no output. */
  static const char *const head =
      "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/"
      "octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}],\"bufferViews\":[{\"buffer\":0,"
      "\"byteLength\":36}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":"
      "\"VEC3\"}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
      "\"nodes\":[{\"mesh\":0}],";
  const struct {
    const char *file, *materials, *needle;
  } bad[] = {
      {"sheen.gltf", "\"materials\":[{\"extensions\":{\"KHR_materials_sheen\":{\"sheenRoughnessFactor\":2}}}]}",
       "sheen.gltf: material 0: KHR_materials_sheen sheenRoughnessFactor 2 is not in [0, 1]"},
      {"texcoord.gltf",
       "\"images\":[{\"uri\":\"data:image/png;base64,iVBORw0KGgo=\"}],\"textures\":[{\"source\":0}],"
       "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"texCoord\":1}}}]}",
       "has no TEXCOORD_1"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    char path[700];
    snprintf(path, sizeof path, "%s/%s", dir, bad[i].file);
    FILE *f = fopen(path, "w");
    if (!CHECK(f != NULL)) continue;
    fprintf(f, "%s%s", head, bad[i].materials);
    fclose(f);
    char args[200];
    snprintf(args, sizeof args, "import %s -o gltf-out.json", bad[i].file);
    EXPECT_RUN(args, 2, bad[i].needle);
    const char *nl = strchr(err_text, '\n');
    CHECK(strstr(err_text, "iris: ") == err_text && nl && nl[1] == '\0'); /* exactly one line */
    CHECK(!exists("gltf-out.json") && !exists("gltf-out.meshes"));
  }
  /* A folder is never a scene file: refused by name, and a built-in scene's
   * name still means the built-in where a folder of that name is at hand. */
  char folder[700];
  snprintf(folder, sizeof folder, "%s/a-folder", dir);
  if (CHECK(mkdir(folder, 0755) == 0)) {
    EXPECT_RUN("render a-folder --spp 1 -o folder-out.exr", 2, "'a-folder' is a folder, not a scene file");
    CHECK(!exists("folder-out.exr"));
    EXPECT_RUN("import a-folder -o folder-out.json", 2, "'a-folder' is not an .obj");
    rmdir(folder);
  }
  snprintf(folder, sizeof folder, "%s/cornell-box", dir);
  if (CHECK(mkdir(folder, 0755) == 0)) {
    EXPECT_RUN("render cornell-box --spp 1 --width 16 --height 16 --quiet -o builtin.exr", 0, NULL);
    CHECK(exists("builtin.exr"));
    rmdir(folder);
  }
}

static void test_quiet(void) {
  EXPECT_RUN("import unknown.json -o q1.json", 0, "unknown key 'comment'");
  EXPECT_RUN("import unknown.json -o q2.json --quiet", 0, NULL);
  CHECK_EQ_STR(err_text, "");
  EXPECT_RUN("info -q unknown.json", 0, NULL);
  CHECK_EQ_STR(err_text, "");
}

/* Merged scene: 2 meshes, 3 instances, 36 world triangles (3 cubes of 12),
 * 24 emissive (the two instances of the lamp cube), 3 cameras. */
static void test_merge_and_info(void) {
  EXPECT_RUN("import a.json b.json -o merged.json --camera top", 0, "wrote merged.json");
  CHECK(exists("merged.json") && exists("merged.meshes/0.irmesh") && exists("merged.meshes/1.irmesh"));
  char path[700];
  snprintf(path, sizeof path, "%s/merged.json", dir);
  iris_error err;
  iris_error_clear(&err);
  iris_scene *s = NULL;
  CHECK_OK(iris_scene_load(path, &s, &err), &err);
  if (s) {
    CHECK_EQ_INT(s->mesh_count, 2);
    CHECK_EQ_INT(s->instance_count, 3);
    CHECK_EQ_INT(s->instances[2].mesh, 1);
    CHECK_EQ_INT(s->meshes[1].material, 1);
    CHECK_EQ_INT(s->materials[1].type, IRIS_MATERIAL_GLOSSY);
    CHECK_EQ_INT(s->camera_count, 3);
    CHECK(s->camera_count == 3 && strcmp(s->cameras[0].name, "top") == 0 &&
          strcmp(s->cameras[1].name, "front") == 0 && strcmp(s->cameras[2].name, "left") == 0);
    iris_scene_destroy(s);
  }
  EXPECT_RUN("info merged.json", 0, "instances    3 (36 triangles in the world, 24 emissive)");
  CHECK(strstr(out_text, "[0] lamp: emission 5 5 5"));
  CHECK(strstr(out_text, "bounds       min -3 0 0, max 1 6 1"));
  CHECK(strstr(out_text, "[0] top: yfov 28.65 deg"));
  EXPECT_RUN("info --json merged.json", 0, NULL);
  cJSON *j = cJSON_Parse(out_text);
  CHECK(j != NULL);
  if (j) {
    const cJSON *inst = cJSON_GetObjectItem(j, "instances"), *meshes = cJSON_GetObjectItem(j, "meshes");
    CHECK_EQ_INT(cJSON_GetObjectItem(inst, "world_triangles")->valuedouble, 36);
    CHECK_EQ_INT(cJSON_GetObjectItem(meshes, "count")->valuedouble, 2);
    CHECK_EQ_INT(cJSON_GetObjectItem(meshes, "vertices")->valuedouble, 16);
    /* 2 meshes x (8 vertices x 12 bytes + 12 triangles x 12 bytes) */
    CHECK_EQ_INT(cJSON_GetObjectItem(meshes, "bytes")->valuedouble, 2 * (96 + 144));
    CHECK_EQ_INT(cJSON_GetArraySize(cJSON_GetObjectItem(j, "cameras")), 3);
    const cJSON *mats = cJSON_GetObjectItem(j, "materials");
    CHECK_EQ_INT(cJSON_GetObjectItem(mats, "glossy")->valuedouble, 1);
    CHECK_EQ_INT(cJSON_GetArraySize(cJSON_GetObjectItem(mats, "emissive")), 1);
    cJSON_Delete(j);
  }
}

/* The real assets, when their importers are built (they are linked into
 * iris, so they are): counts from shared/assets/README.md. */
static void test_assets(void) {
  char args[2000];
  snprintf(args, sizeof args, "import -q '%s/obj/cornell-box-mcguire/CornellBox-Original.obj' -o r1/cb.json", assets);
  char p[700];
  snprintf(p, sizeof p, "%s/r1", dir);
  iris_mkdir_p(p, NULL);
  snprintf(p, sizeof p, "%s/r2", dir);
  iris_mkdir_p(p, NULL);
  EXPECT_RUN(args, 0, NULL);
  EXPECT_RUN("info --json r1/cb.json", 0, NULL);
  cJSON *j = cJSON_Parse(out_text);
  CHECK(j != NULL);
  if (j) {
    /* 18 quads -> 36 triangles; light quad -> 2 emissive triangles with Ke 17 12 4. */
    CHECK_EQ_INT(cJSON_GetObjectItem(cJSON_GetObjectItem(j, "instances"), "world_triangles")->valuedouble, 36);
    CHECK_EQ_INT(cJSON_GetObjectItem(cJSON_GetObjectItem(j, "instances"), "emissive_world_triangles")->valuedouble, 2);
    const cJSON *em = cJSON_GetArrayItem(cJSON_GetObjectItem(cJSON_GetObjectItem(j, "materials"), "emissive"), 0);
    const cJSON *e = cJSON_GetObjectItem(em, "emission");
    CHECK(e && cJSON_GetArrayItem(e, 0)->valuedouble == 17.0 && cJSON_GetArrayItem(e, 1)->valuedouble == 12.0 &&
          cJSON_GetArrayItem(e, 2)->valuedouble == 4.0);
    const cJSON *b = cJSON_GetObjectItem(j, "bounds");
    CHECK_NEAR(cJSON_GetArrayItem(cJSON_GetObjectItem(b, "min"), 0)->valuedouble, -1.02, 1e-6);
    CHECK_NEAR(cJSON_GetArrayItem(cJSON_GetObjectItem(b, "max"), 1)->valuedouble, 1.99, 1e-6);
    CHECK_NEAR(cJSON_GetArrayItem(cJSON_GetObjectItem(b, "min"), 2)->valuedouble, -1.04, 1e-6);
    cJSON_Delete(j);
  }
  /* CLI round trip: importing the written scene again reproduces its files. */
  EXPECT_RUN("import -q r1/cb.json -o r2/cb.json", 0, NULL);
  char a[800], b2[800];
  snprintf(a, sizeof a, "%s/r1/cb.json", dir);
  snprintf(b2, sizeof b2, "%s/r2/cb.json", dir);
  char cmd[4000];
  snprintf(cmd, sizeof cmd, "cmp -s '%s' '%s' && cd '%s' && diff -r r1/cb.meshes r2/cb.meshes >/dev/null", a, b2, dir);
  CHECK(system(cmd) == 0);

  /* A textured glTF: the texture reference survives the round trip. */
  snprintf(args, sizeof args, "import -q '%s/gltf/BoxTextured/glTF/BoxTextured.gltf' -o r1/bt.json", assets);
  EXPECT_RUN(args, 0, NULL);
  EXPECT_RUN("import -q r1/bt.json -o r2/bt.json", 0, NULL);
  snprintf(cmd, sizeof cmd, "cd '%s' && cmp -s r1/bt.json r2/bt.json && grep -q CesiumLogoFlat.png r2/bt.json", dir);
  CHECK(system(cmd) == 0);
  EXPECT_RUN("info r2/bt.json", 0, "textures     1");

  /* Must-reject file: a required extension iris cannot decode (KHR_texture_basisu); nothing written. */
  snprintf(args, sizeof args, "import '%s/basisu-required.gltf' -o basisu.json", IRIS_GLTF_TEST_DATA);
  EXPECT_RUN(args, 2, "KHR_texture_basisu");
  CHECK(!exists("basisu.json"));
  /* Compressed data that lies: one line naming the file and the primitive / image, exit 2, nothing written. */
  snprintf(args, sizeof args, "import '%s/bad-draco-count.glb' -o bad.json", IRIS_GLTF_TEST_DATA);
  EXPECT_RUN(args, 2, "mesh 0 primitive 0: KHR_draco_mesh_compression");
  CHECK(strchr(err_text, '\n') == strrchr(err_text, '\n')); /* one line */
  snprintf(args, sizeof args, "import '%s/bad-meshopt-corrupt.glb' -o bad.json", IRIS_GLTF_TEST_DATA);
  EXPECT_RUN(args, 2, "bufferView 2: EXT_meshopt_compression");
  CHECK(strchr(err_text, '\n') == strrchr(err_text, '\n')); /* one line */
  snprintf(args, sizeof args, "import '%s/bad-webp-truncated.glb' -o bad.json", IRIS_GLTF_TEST_DATA);
  EXPECT_RUN(args, 2, "image 0: WebP decoding failed");
  CHECK(strchr(err_text, '\n') == strrchr(err_text, '\n')); /* one line */
  CHECK(!exists("bad.json") && !exists("bad.meshes"));
  /* Draco (formerly the must-reject example) imports. */
  snprintf(args, sizeof args, "import -q '%s/bad/gltf/Box-Draco-must-reject/Box.gltf' -o draco.json", assets);
  EXPECT_RUN(args, 0, NULL);
  CHECK(exists("draco.json"));
}

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: %s IRIS_BINARY ASSETS_DIR\n", argv[0]);
    return 2;
  }
  static char bin[1024];
  if (argv[1][0] != '/' && getcwd(bin, 512)) /* the commands run in the test folder */
    snprintf(bin + strlen(bin), sizeof bin - strlen(bin), "/%s", argv[1]);
  else
    snprintf(bin, sizeof bin, "%s", argv[1]);
  iris_bin = bin;
  assets = argv[2];
  if (iris_test_tmpdir(dir, sizeof dir, "tools-import") != 0) return TEST_SKIP("no temp dir");
  iris_log_set_level(IRIS_LOG_QUIET);
  build_inputs();
  test_usage();
  test_bad_input();
  test_quiet();
  test_merge_and_info();
  test_assets();
  int rc = TEST_SUMMARY();
  if (rc == 0) iris_test_rmtree(dir);
  return rc;
}
