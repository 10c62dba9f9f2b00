/* libFuzzer harness for the scene format. An input starting with "IRISMESH"
 * is a binary mesh file read from memory; anything else is a scene JSON,
 * loaded from a private temp folder that also holds one valid mesh file
 * ("m.meshes/0.irmesh", a triangle) and a texture ("t.png") to refer to.
 * Scenes that load are written again, which exercises validation and the
 * writer. Loading must accept or reject without crashing, leaking or
 * allocating without bound. Seeds: tests/fuzz/corpus/scene/. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/fileio.h"
#include "core/log.h"
#include "scene/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char g_dir[256];

static void remove_files(void) {
  char p[512];
  static const char *const names[] = {"scene.json", "out.json", "out.meshes/0.irmesh", "out.meshes/1.irmesh",
                                      "out.meshes/2.irmesh", "out.meshes/3.irmesh", "m.meshes/0.irmesh", "t.png"};
  for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
    snprintf(p, sizeof p, "%s/%s", g_dir, names[i]);
    unlink(p);
  }
  snprintf(p, sizeof p, "%s/out.meshes", g_dir);
  rmdir(p);
  snprintf(p, sizeof p, "%s/m.meshes", g_dir);
  rmdir(p);
  rmdir(g_dir);
}

static int setup(void) {
  const char *root = getenv("TMPDIR");
  snprintf(g_dir, sizeof g_dir, "%s/iris-fuzz-scene-XXXXXX", root && root[0] ? root : "/tmp");
  if (!mkdtemp(g_dir)) return -1;
  atexit(remove_files);
  char p[512];
  snprintf(p, sizeof p, "%s/m.meshes", g_dir);
  if (iris_mkdir_p(p, NULL) != IRIS_OK) return -1;
  float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  uint32_t idx[3] = {0, 1, 2};
  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.vertex_count = 3;
  m.triangle_count = 1;
  m.positions = pos;
  m.indices = idx;
  snprintf(p, sizeof p, "%s/m.meshes/0.irmesh", g_dir);
  if (iris_mesh_write_file(&m, p, NULL) != IRIS_OK) return -1;
  static const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  snprintf(p, sizeof p, "%s/t.png", g_dir);
  return iris_file_write_atomic(p, png, sizeof png, NULL) == IRIS_OK ? 0 : -1;
}

static void fuzz_mesh(const uint8_t *data, size_t size) {
  /* The reader needs 4-byte alignment, as a memory map gives. */
  void *copy = malloc(size ? size : 1);
  if (!copy) return;
  memcpy(copy, data, size);
  iris_file_map map = {copy, size};
  iris_mesh mesh;
  iris_error err;
  iris_error_clear(&err);
  if (iris_mesh_read_map(&map, "fuzz.irmesh", &mesh, &err) == IRIS_OK) {
    /* Touch every index and position the reader vouched for. */
    volatile float sum = 0.0f;
    for (size_t i = 0; i < 3 * (size_t)mesh.triangle_count; i++) sum += mesh.positions[3 * (size_t)mesh.indices[i]];
    (void)sum;
  }
  free(copy);
}

static void fuzz_json(const uint8_t *data, size_t size) {
  char json[512], out[512];
  snprintf(json, sizeof json, "%s/scene.json", g_dir);
  snprintf(out, sizeof out, "%s/out.json", g_dir);
  if (iris_file_write_atomic(json, data, size, NULL) != IRIS_OK) return;
  iris_scene *scene = NULL;
  iris_error err;
  iris_error_clear(&err);
  if (iris_scene_load(json, &scene, &err) != IRIS_OK) return;
  if (scene->mesh_count <= 4 && scene->texture_count <= 4) {
    iris_error_clear(&err);
    iris_scene_write(scene, out, &err);
  }
  iris_scene_destroy(scene);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static int ready = 0;
  if (!ready) {
    iris_log_set_level(IRIS_LOG_QUIET);
    ready = setup() == 0 ? 1 : -1;
  }
  if (size >= 8 && memcmp(data, "IRISMESH", 8) == 0)
    fuzz_mesh(data, size);
  else if (ready == 1)
    fuzz_json(data, size);
  return 0;
}
