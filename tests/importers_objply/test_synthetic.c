/* Small hand-written OBJ and PLY inputs, each aimed at one rule of
 * docs/import-obj-ply.md; expected values are worked out by hand in the comments. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "core/log.h"
#include "objply_util.h"

static iris_scene *load(const char *ext, const char *text, size_t size, iris_status *st, iris_error *err) {
  iris_scene *s = NULL;
  *st = objply_import_memory(ext, text, size, &s, err);
  return s;
}

static void expect_reject(const char *ext, const char *text, size_t size, long line, const char *needle) {
  iris_error err;
  iris_status st;
  iris_scene *s = load(ext, text, size, &st, &err);
  CHECK(st != IRIS_OK);
  CHECK(s == NULL);
  if (line) CHECK_EQ_INT(err.line, line);
  if (needle && !CHECK(strstr(err.message, needle) != NULL)) printf("  message was: %s (wanted %s)\n", err.message, needle);
  iris_scene_destroy(s);
}

static void obj_cases(void) {
  iris_error err;
  iris_status st;
  /* CRLF, tabs, trailing spaces, comments, negative v/vt/vn indices. */
  const char *a = "# comment\r\nv\t0 0 0\r\nv 1 0 0  \r\nv 1 1 0\r\n\r\nvt 0 0\r\nvt 1 0\r\nvt 1 1\r\n"
                  "vn 0 0 1\r\nf -3/-3/-1 -2/-2/-1 -1/-1/-1   \r\n";
  iris_scene *s = load("obj", a, strlen(a), &st, &err);
  CHECK_OK(st, &err);
  if (s) {
    const iris_mesh *m = &s->meshes[0];
    CHECK_EQ_INT(m->vertex_count, 3);
    CHECK_EQ_INT(m->triangle_count, 1);
    CHECK(m->uvs && m->normals);
    if (m->uvs) {
      /* vt (1,1) -> iris (1, 1-1) = (1, 0) on the third vertex */
      CHECK(m->uvs[4] == 1.0f && m->uvs[5] == 0.0f);
      CHECK(m->uvs[0] == 0.0f && m->uvs[1] == 1.0f);
    }
    CHECK_EQ_INT(m->material, -1);
    iris_scene_destroy(s);
  }
  /* A face mixing a corner with vn and corners without, outside smoothing
   * groups (found by fuzzing: the flat corners' normals were left unset). The
   * first corner keeps vn (1,0,0); the other two get the face normal (0,0,1). */
  const char *mixed = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 1 0 0\nf 1//1 2 3\n";
  s = load("obj", mixed, strlen(mixed), &st, &err);
  CHECK_OK(st, &err);
  if (s && CHECK(s->meshes[0].normals != NULL)) {
    const iris_mesh *m = &s->meshes[0];
    int with_vn = 0, flat = 0;
    for (uint32_t v = 0; v < m->vertex_count; v++) {
      const float *nv = m->normals + 3 * v;
      if (nv[0] == 1.0f && nv[1] == 0.0f && nv[2] == 0.0f) with_vn++;
      if (nv[0] == 0.0f && nv[1] == 0.0f && nv[2] == 1.0f) flat++;
    }
    CHECK_EQ_INT(with_vn, 1);
    CHECK_EQ_INT(flat, 2);
  }
  iris_scene_destroy(s);
  /* Convex pentagon (unit square + roof apex at (0.5, 1.5)): 3 triangles, area 1.25. */
  const char *b = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0.5 1.5 0\nv 0 1 0\nf 1 2 3 4 5\n";
  s = load("obj", b, strlen(b), &st, &err);
  CHECK_OK(st, &err);
  if (s) {
    double n[3];
    CHECK_EQ_INT(s->meshes[0].triangle_count, 3);
    CHECK_NEAR(objply_mesh_area(&s->meshes[0], n), 1.25, 1e-6);
    CHECK_NEAR(n[2], 1.25, 1e-6); /* all triangles counter-clockwise like the polygon */
    iris_scene_destroy(s);
  }
  /* Concave "L" hexagon, area 3: fan from vertex 0 would make a triangle outside. */
  const char *c = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 4 5 6 1 2 3\n";
  s = load("obj", c, strlen(c), &st, &err);
  CHECK_OK(st, &err);
  if (s) {
    double n[3];
    CHECK_NEAR(objply_mesh_area(&s->meshes[0], n), 3.0, 1e-6);
    CHECK_NEAR(n[2], 3.0, 1e-6);
    iris_scene_destroy(s);
  }
  /* Two materials -> two meshes; unknown materials fall back to the default. */
  const char *d = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nusemtl red\nf 1 2 3\nusemtl blue\nf 2 4 3\nusemtl red\nf 1 3 2\n";
  s = load("obj", d, strlen(d), &st, &err);
  CHECK_OK(st, &err);
  if (s) {
    CHECK_EQ_INT(s->mesh_count, 2);
    CHECK_EQ_INT(objply_triangles(s), 3);
    CHECK_EQ_INT(s->meshes[0].material, -1);
    iris_scene_destroy(s);
  }
  /* Smoothing group on: two triangles sharing an edge get computed normals;
   * 's off': none (flat, geometric normal). */
  const char *e = "s 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nf 1 2 3\nf 2 4 3\n";
  s = load("obj", e, strlen(e), &st, &err);
  CHECK_OK(st, &err);
  if (s) {
    CHECK(s->meshes[0].normals != NULL);
    CHECK_EQ_INT(s->meshes[0].vertex_count, 4);
    iris_scene_destroy(s);
  }
  const char *f = "s off\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  s = load("obj", f, strlen(f), &st, &err);
  CHECK_OK(st, &err);
  if (s) CHECK(s->meshes[0].normals == NULL);
  iris_scene_destroy(s);
  /* Degenerate faces are removed: a repeated index and a zero-area sliver. */
  const char *g = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\nf 1 2 4\n";
  s = load("obj", g, strlen(g), &st, &err);
  CHECK_OK(st, &err);
  if (s) CHECK_EQ_INT(objply_triangles(s), 1);
  iris_scene_destroy(s);

  expect_reject("obj", "", strlen(""), 0, "empty");
  expect_reject("obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", strlen("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"), 4, "out of range");
  expect_reject("obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", strlen("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n"), 4, "index 0");
  expect_reject("obj", "v 0 0 0\nv 1 0 0\nv 1.#IND 1 0\nf 1 2 3\n", strlen("v 0 0 0\nv 1 0 0\nv 1.#IND 1 0\nf 1 2 3\n"), 3, "non-finite");
  expect_reject("obj", "v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n", strlen("v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n"), 2, "non-finite");
  expect_reject("obj", "v 0 0 0\nv 1 0 0\nv 0 -nan 0\nf 1 2 3\n", strlen("v 0 0 0\nv 1 0 0\nv 0 -nan 0\nf 1 2 3\n"), 3, "non-finite");
  expect_reject("obj", "v 0 0 0\nv 1x 0 0\n", strlen("v 0 0 0\nv 1x 0 0\n"), 2, "malformed vertex");
  expect_reject("obj", "v 0 0 0\nv 1 0 0\nl 1 2\n", strlen("v 0 0 0\nv 1 0 0\nl 1 2\n"), 0, "no faces");
  expect_reject("obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/x 2 3\n", strlen("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/x 2 3\n"), 4, NULL);
  expect_reject("obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", strlen("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"), 0, "degenerate");
}

static size_t put_be_double(unsigned char *p, double v) {
  unsigned char b[8];
  memcpy(b, &v, 8);
  for (int i = 0; i < 8; i++) p[i] = b[7 - i]; /* x86 is little-endian */
  return 8;
}

static void ply_cases(void) {
  iris_error err;
  iris_status st;
  /* ASCII, faces before vertices, an extra element, a quad, uint16 and uchar
   * colours, u/v. Colour 65535 -> 1, 0 -> 0; uchar 128 -> sRGB decode
   * ((128/255 + 0.055)/1.055)^2.4 = 0.2158605. */
  const char *a =
      "ply\r\nformat ascii 1.0\r\ncomment x\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\n"
      "element vertex 4\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\n"
      "property ushort red\r\nproperty ushort green\r\nproperty uchar blue\r\nproperty float u\r\nproperty float v\r\n"
      "element edge 1\r\nproperty int vertex1\r\nproperty int vertex2\r\nend_header\r\n"
      "4 0 1 2 3\r\n0 0 0 65535 0 128 0 0\r\n1 0 0 0 0 0 1 0\r\n1 1 0 0 0 0 1 1\r\n0 1 0 0 0 0 0 1\r\n0 1\r\n";
  iris_scene *s = load("ply", a, strlen(a), &st, &err);
  CHECK_OK(st, &err);
  if (s) {
    const iris_mesh *m = &s->meshes[0];
    CHECK_EQ_INT(m->vertex_count, 4);
    CHECK_EQ_INT(m->triangle_count, 2);
    CHECK(m->colors && m->uvs);
    if (m->colors) {
      CHECK_NEAR(m->colors[0], 1.0, 1e-7);
      CHECK_NEAR(m->colors[1], 0.0, 1e-7);
      CHECK_NEAR(m->colors[2], 0.2158605, 1e-6);
    }
    if (m->uvs) CHECK(m->uvs[5] == 0.0f && m->uvs[1] == 1.0f); /* v flipped */
    iris_scene_destroy(s);
  }
  /* binary_big_endian, double coordinates, list uchar ushort. */
  unsigned char bin[512];
  const char *hdr = "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
                    "property double z\nelement face 1\nproperty list uchar ushort vertex_indices\nend_header\n";
  size_t n = strlen(hdr);
  memcpy(bin, hdr, n);
  const double xyz[9] = {0, 0, 0, 2, 0, 0, 0, 3, 0.5};
  for (int i = 0; i < 9; i++) n += put_be_double(bin + n, xyz[i]);
  const unsigned char face[7] = {3, 0, 0, 0, 1, 0, 2};
  memcpy(bin + n, face, 7);
  n += 7;
  s = load("ply", (const char *)bin, n, &st, &err);
  CHECK_OK(st, &err);
  if (s) {
    const iris_mesh *m = &s->meshes[0];
    CHECK(m->positions[3] == 2.0f && m->positions[7] == 3.0f && m->positions[8] == 0.5f);
    CHECK_EQ_INT(m->indices[2], 2);
    iris_scene_destroy(s);
  }
  /* Truncated: drop the last index byte. */
  expect_reject("ply", (const char *)bin, n - 1, 0, "truncated");
  /* Index out of range: 7 >= 3 vertices. */
  bin[n - 1] = 7;
  expect_reject("ply", (const char *)bin, n, 0, "out of range");
  bin[n - 1] = 2;
  /* NaN coordinate. */
  unsigned char nanbin[512];
  memcpy(nanbin, bin, n);
  put_be_double(nanbin + strlen(hdr) + 8, NAN);
  expect_reject("ply", (const char *)nanbin, n, 0, "not finite");
  /* Absurd counts are refused from the header, before allocating. */
  const char *huge = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
                     "property float y\nproperty float z\nelement face 4000000000\n"
                     "property list uchar int vertex_indices\nend_header\n0123456789";
  expect_reject("ply", huge, strlen(huge), 0, NULL);
  const char *huge_ascii = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                           "element face 1000000000000\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n";
  expect_reject("ply", huge_ascii, strlen(huge_ascii), 0, NULL);
  /* No faces: point cloud. */
  const char *cloud = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                      "end_header\n0 0 0\n";
  expect_reject("ply", cloud, strlen(cloud), 0, "point cloud");
  const char *zero = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                     "element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n";
  expect_reject("ply", zero, strlen(zero), 0, "point cloud");
  /* element tristrips (Stanford tools): a 2x3 grid of vertices, z = 0,
   *   3 4 5
   *   0 1 2
   * strip 0 3 1 4 2 5, then -1 restarts with 5 4 (too short: nothing), then
   * 0 1 1 (a padding triangle with a repeated vertex: skipped).
   * Triangles: (0,3,1) (3,1,4)->(1,3,4) (1,4,2) (4,2,5)->(2,4,5): all with the
   * first one's orientation, whose normal is -z ((3-0) x (1-0) = y x x = -z). */
  const char *strips =
      "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\n"
      "element tristrips 1\nproperty list int int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n2 0 0\n0 1 0\n1 1 0\n2 1 0\n12 0 3 1 4 2 5 -1 5 4 -1 0 1 1\n";
  s = load("ply", strips, strlen(strips), &st, &err);
  CHECK_OK(st, &err);
  if (s) {
    const iris_mesh *m = &s->meshes[0];
    CHECK_EQ_INT(m->triangle_count, 4);
    const uint32_t want[12] = {0, 3, 1, 1, 3, 4, 1, 4, 2, 2, 4, 5};
    if (m->triangle_count == 4) CHECK(memcmp(m->indices, want, sizeof want) == 0);
    double nsum[3];
    CHECK_NEAR(objply_mesh_area(m, nsum), 2.0, 1e-9); /* the whole 2x1 grid, no overlap */
    CHECK_NEAR(nsum[2], -2.0, 1e-9);                   /* one orientation throughout */
    iris_scene_destroy(s);
  }
  /* Strip index out of range (-2 is not a restart) and an only-strips point cloud. */
  const char *bad_strip =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element tristrips 1\nproperty list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -2\n";
  expect_reject("ply", bad_strip, strlen(bad_strip), 13, "out of range");
  const char *no_strips =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
      "element tristrips 0\nproperty list int int vertex_indices\nend_header\n0 0 0\n";
  expect_reject("ply", no_strips, strlen(no_strips), 0, "point cloud");
  /* ASCII truncated mid-row, with its line number (line 12 is the cut row). */
  const char *cut = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1";
  expect_reject("ply", cut, strlen(cut), 12, "truncated");
  expect_reject("ply", "", 0, 0, "empty");
  expect_reject("ply", "plx\n", 4, 1, "magic");
}

int main(void) {
  iris_log_set_level(IRIS_LOG_QUIET);
  obj_cases();
  ply_cases();
  return TEST_SUMMARY();
}
