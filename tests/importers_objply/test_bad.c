/* shared/assets/bad/{obj,ply}: every REJECT file fails with an error record
 * naming the file (and the line where the README's defect is), every
 * TOLERATE file loads or fails without crashing (ASan build: no invalid access). */
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "core/log.h"
#include "objply_util.h"

typedef struct bad_case {
  const char *file;
  bool must_reject;
  long line;           /* expected error line, 0 = not checked */
  const char *message; /* substring of the message, NULL = not checked */
} bad_case;

static const bad_case cases[] = {
    /* README table "bad/": defect -> expected */
    {"obj/assimp/malformed.obj", true, 0, "index"},                 /* indices 12 and 0 with 8 vertices */
    {"obj/assimp/empty.obj", true, 0, "empty"},                     /* 0 bytes */
    {"obj/assimp/malformed2.obj", false, 0, NULL},                  /* empty f, unknown usemtl: tolerate */
    {"obj/tinyobjloader/invalid-face-definition.obj", false, 0, NULL}, /* 1- and 2-corner faces */
    {"obj/tinyobjloader/invalid-relative-vertex-index.obj", true, 1, "relative vertex index"},
    {"obj/tinyobjloader/invalid-relative-texture-index.obj", true, 2, "texture coordinate"},
    {"obj/tinyobjloader/issue-140-zero-face-idx.obj", true, 16, "index 0"},
    {"obj/tinyobjloader/test-nan.obj", true, 12, "non-finite"},     /* line 12: 'v nan -nan nan' */
    {"ply/assimp/crash-30d6d0f7c529b3b66b4131700b7a4580cd7082df.ply", true, 7, NULL}, /* header cut at line 7 */
    {"ply/assimp/empty.ply", true, 0, "empty"},
    {"ply/assimp/issue623.ply", true, 0, "point cloud"},           /* no face element */
    {"../ply/assimp/pond.0.ply", true, 0, "point cloud"},          /* a real point cloud among the good files */
};

int main(int argc, char **argv) {
  if (argc < 2) return TEST_SKIP("usage: test_bad ASSETS_DIR");
  iris_log_set_level(IRIS_LOG_QUIET);
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    const bad_case *c = &cases[i];
    char path[1024];
    snprintf(path, sizeof path, "%s/bad/%s", argv[1], c->file);
    iris_scene *s = NULL;
    iris_error err;
    iris_status st = objply_import(path, &s, &err);
    char msg[1400];
    iris_error_format(&err, msg, sizeof msg);
    printf("%s -> %s %s\n", c->file, st == IRIS_OK ? "loaded" : "rejected", st == IRIS_OK ? "" : msg);
    if (c->must_reject) {
      CHECK(st != IRIS_OK);
      CHECK(s == NULL);
      CHECK(strstr(err.file, c->file + (c->file[0] == '.' ? 3 : 0)) != NULL);
      if (c->line) CHECK_EQ_INT(err.line, c->line);
      if (c->message) CHECK(strstr(err.message, c->message) != NULL);
    } else if (st == IRIS_OK) {
      CHECK(objply_triangles(s) > 0);
    }
    iris_scene_destroy(s);
  }
  return TEST_SUMMARY();
}
