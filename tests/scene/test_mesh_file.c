/* scene.mesh_file: the binary mesh layout matches docs/format.md byte for
 * byte (checked with an independent little-endian decoder here), and every
 * kind of corruption is rejected with the file and element in the message. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "check.h"
#include "core/fileio.h"
#include "fixture.h"
#include "scene/scene.h"

static char dir[512];

static uint32_t rd32(const unsigned char *p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static void wr32(unsigned char *p, uint32_t v) {
  for (int i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (8 * i));
}
/* Recomputes the payload checksum so that a corruption reaches the later checks. */
static void fix_crc(unsigned char *file, size_t size) {
  if (size >= 64) wr32(file + 24, (uint32_t)crc32(0, file + 64, (uInt)(size - 64)));
}

/* The documented layout, decoded independently of mesh_file.c. */
static void test_layout(void) {
  iris_error err;
  iris_error_clear(&err);
  iris_mesh m = fixture_cube("c", true, false, true);
  char path[700];
  snprintf(path, sizeof path, "%s/cube.irmesh", dir);
  CHECK_OK(iris_mesh_write_file(&m, path, &err), &err);
  size_t n = 0;
  unsigned char *f = (unsigned char *)fixture_slurp(path, &n);
  CHECK(f != NULL);
  if (!f) return;
  /* 64-byte header + 8 vertices * (12 positions + 12 normals + 12 colours) + 12 triangles * 12. */
  CHECK_EQ_INT(n, 64 + 8 * 36 + 12 * 12);
  CHECK(memcmp(f, "IRISMESH", 8) == 0);
  CHECK_EQ_INT(rd32(f + 8), 1);
  CHECK_EQ_INT(rd32(f + 12), 1 | 4);
  CHECK_EQ_INT(rd32(f + 16), 8);
  CHECK_EQ_INT(rd32(f + 20), 12);
  CHECK_EQ_INT(rd32(f + 24), (uint32_t)crc32(0, f + 64, (uInt)(n - 64)));
  int reserved_zero = 1;
  for (int i = 28; i < 64; i++) reserved_zero &= f[i] == 0;
  CHECK(reserved_zero);
  CHECK(memcmp(f + 64, m.positions, 96) == 0);
  CHECK(memcmp(f + 64 + 96, m.normals, 96) == 0);
  CHECK(memcmp(f + 64 + 192, m.colors, 96) == 0);
  CHECK(memcmp(f + 64 + 288, m.indices, 144) == 0);

  /* Reading back through a map gives borrowed arrays with the same values. */
  iris_file_map map;
  CHECK_OK(iris_file_map_open(path, &map, &err), &err);
  iris_mesh r;
  CHECK_OK(iris_mesh_read_map(&map, path, &r, &err), &err);
  CHECK_EQ_INT(r.vertex_count, 8);
  CHECK_EQ_INT(r.triangle_count, 12);
  CHECK(!r.owned && r.uvs == NULL && r.normals && r.colors);
  CHECK(r.positions && memcmp(r.positions, m.positions, 96) == 0);
  CHECK(r.indices && memcmp(r.indices, m.indices, 144) == 0);
  CHECK_EQ_INT(r.material, -1);
  iris_file_map_close(&map);
  free(f);
  iris_scene *s = iris_scene_create(); /* frees the cube */
  iris_scene_add_mesh(s, &m);
  iris_scene_destroy(s);
}

typedef struct corruption {
  const char *what;
  iris_status status;
  const char *element; /* expected in the message */
  const char *message; /* expected in the message */
} corruption;

/* Writes `bytes` to a file, reads it as a mesh and checks the error. */
static void expect_reject(const unsigned char *bytes, size_t size, const corruption *c) {
  char path[700];
  snprintf(path, sizeof path, "%s/bad.irmesh", dir);
  fixture_write(path, bytes, size);
  iris_error err;
  iris_error_clear(&err);
  iris_file_map map;
  iris_status st = iris_file_map_open(path, &map, &err);
  CHECK_OK(st, &err);
  iris_mesh m;
  st = iris_mesh_read_map(&map, path, &m, &err);
  char msg[1400];
  iris_error_format(&err, msg, sizeof msg);
  iris_check_record(st == c->status, __FILE__, __LINE__, "%s: status %s, expected %s (%s)", c->what,
                    iris_status_name(st), iris_status_name(c->status), msg);
  iris_check_record(strstr(msg, path) == msg, __FILE__, __LINE__, "%s: message does not start with the file: %s", c->what, msg);
  iris_check_record(!c->element || strstr(msg, c->element), __FILE__, __LINE__, "%s: message lacks '%s': %s",
                    c->what, c->element ? c->element : "", msg);
  iris_check_record(!c->message || strstr(msg, c->message), __FILE__, __LINE__, "%s: message lacks '%s': %s",
                    c->what, c->message ? c->message : "", msg);
  iris_file_map_close(&map);
}

static void test_rejects(void) {
  iris_error err;
  iris_error_clear(&err);
  iris_mesh m = fixture_cube("c", false, true, false);
  char path[700];
  snprintf(path, sizeof path, "%s/good.irmesh", dir);
  CHECK_OK(iris_mesh_write_file(&m, path, &err), &err);
  size_t n = 0;
  unsigned char *good = (unsigned char *)fixture_slurp(path, &n);
  unsigned char *b = malloc(n + 64);
  CHECK(good && n == 64 + 8 * 20 + 144);
  if (!good) return;

  /* Truncations: empty, inside the header, inside the payload, one byte short. */
  size_t cuts[] = {0, 7, 63, 64, 100, n - 1};
  for (size_t i = 0; i < sizeof cuts / sizeof *cuts; i++) {
    corruption c = {"truncated", cuts[i] < 64 ? IRIS_ERR_PARSE : IRIS_ERR_PARSE,
                    cuts[i] < 64 ? "header" : NULL, cuts[i] < 64 ? "truncated header" : "needs"};
    expect_reject(good, cuts[i], &c);
  }
  /* Trailing garbage. */
  memcpy(b, good, n);
  b[n] = 0;
  expect_reject(b, n + 1, &(corruption){"trailing byte", IRIS_ERR_PARSE, NULL, "needs"});

  memcpy(b, good, n), b[0] = 'X';
  expect_reject(b, n, &(corruption){"magic", IRIS_ERR_PARSE, "header", "bad magic"});
  memcpy(b, good, n), wr32(b + 8, 2);
  expect_reject(b, n, &(corruption){"version", IRIS_ERR_UNSUPPORTED, "header", "version 2"});
  memcpy(b, good, n), wr32(b + 12, 2 | 64);
  expect_reject(b, n, &(corruption){"flags", IRIS_ERR_UNSUPPORTED, "header", "flags 0x40"});
  memcpy(b, good, n), b[40] = 1;
  expect_reject(b, n, &(corruption){"reserved", IRIS_ERR_PARSE, "header", "reserved"});
  memcpy(b, good, n), wr32(b + 16, 0);
  expect_reject(b, n, &(corruption){"no vertices", IRIS_ERR_INVALID, "header", "empty mesh"});
  memcpy(b, good, n), wr32(b + 20, 0);
  expect_reject(b, n, &(corruption){"no triangles", IRIS_ERR_INVALID, "header", "empty mesh"});
  memcpy(b, good, n), wr32(b + 16, 0xFFFFFFFFu);
  expect_reject(b, n, &(corruption){"huge vertex count", IRIS_ERR_NOMEM, "header", "absurd"});
  memcpy(b, good, n), wr32(b + 20, 0x80000000u);
  /* 2^31 triangles is at the limit: not absurd, but the size cannot match. */
  expect_reject(b, n, &(corruption){"huge triangle count", IRIS_ERR_PARSE, NULL, "needs"});
  memcpy(b, good, n), wr32(b + 16, 9);
  expect_reject(b, n, &(corruption){"count/size mismatch", IRIS_ERR_PARSE, NULL, "needs"});
  memcpy(b, good, n), b[64 + 5] ^= 0x40;
  expect_reject(b, n, &(corruption){"bad checksum", IRIS_ERR_PARSE, NULL, "checksum"});

  /* Value checks, with the checksum made consistent so they are reached. */
  float nan = NAN, inf = INFINITY;
  memcpy(b, good, n), memcpy(b + 64 + 12 * 5 + 4, &nan, 4), fix_crc(b, n);
  expect_reject(b, n, &(corruption){"NaN position", IRIS_ERR_INVALID, "vertex 5", "position is not finite"});
  memcpy(b, good, n), memcpy(b + 64 + 96 + 8 * 3, &inf, 4), fix_crc(b, n);
  expect_reject(b, n, &(corruption){"inf uv", IRIS_ERR_INVALID, "vertex 3", "uv is not finite"});
  memcpy(b, good, n), wr32(b + 64 + 160 + 4 * 7, 77), fix_crc(b, n);
  expect_reject(b, n, &(corruption){"index out of range", IRIS_ERR_INVALID, "triangle 2",
                                    "index 77 out of range (vertex count 8)"});
  memcpy(b, good, n), wr32(b + 64 + 160 + 4 * 35, 8), fix_crc(b, n);
  expect_reject(b, n, &(corruption){"index == count", IRIS_ERR_INVALID, "triangle 11", "index 8 out of range"});

  /* The unmodified bytes still load (the corruptions above were the only problem). */
  memcpy(b, good, n);
  snprintf(path, sizeof path, "%s/ok.irmesh", dir);
  fixture_write(path, b, n);
  iris_file_map map;
  CHECK_OK(iris_file_map_open(path, &map, &err), &err);
  iris_mesh r;
  CHECK_OK(iris_mesh_read_map(&map, path, &r, &err), &err);
  iris_file_map_close(&map);

  /* Writing refuses an empty mesh and leaves no file. */
  iris_mesh empty;
  memset(&empty, 0, sizeof empty);
  snprintf(path, sizeof path, "%s/empty.irmesh", dir);
  iris_error_clear(&err);
  CHECK(iris_mesh_write_file(&empty, path, &err) == IRIS_ERR_INVALID);
  CHECK(!iris_path_exists(path));

  free(b);
  free(good);
  iris_scene *s = iris_scene_create();
  iris_scene_add_mesh(s, &m);
  iris_scene_destroy(s);
}

int main(void) {
  if (iris_test_tmpdir(dir, sizeof dir, "scene-meshfile") != 0) return TEST_SKIP("no temp dir");
  test_layout();
  test_rejects();
  int rc = TEST_SUMMARY();
  if (rc == 0) iris_test_rmtree(dir);
  return rc;
}
