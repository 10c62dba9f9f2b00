/* meshproc: angle-weighted normals (exact on a cube corner, equal to the
 * OpenMesh halfedge computation on the bunny), ear clipping of random
 * star polygons (area kept, no flipped triangle), welding. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/log.h"
#include "importers/meshproc.h"
#include "objply_util.h"

/* Cube from quads: at a corner each face contributes the angle pi/2 whatever
 * the diagonal, so the angle-weighted normal is exactly along (p - centre).
 * (Area- or count-weighting would tilt it toward the face split twice.) */
static void check_cube(const char *assets) {
  char path[1024];
  snprintf(path, sizeof path, "%s/ply/assimp/cube.ply", assets);
  iris_scene *s = NULL;
  iris_error err;
  CHECK_OK(objply_import(path, &s, &err), &err);
  if (!s) return;
  const iris_mesh *m = &s->meshes[0];
  double c[3] = {0, 0, 0};
  for (uint32_t v = 0; v < m->vertex_count; v++)
    for (int k = 0; k < 3; k++) c[k] += m->positions[3 * v + k] / m->vertex_count;
  CHECK(m->normals != NULL);
  for (uint32_t v = 0; v < m->vertex_count && m->normals; v++) {
    double d[3], len = 0, dot = 0;
    for (int k = 0; k < 3; k++) d[k] = m->positions[3 * v + k] - c[k], len += d[k] * d[k];
    len = sqrt(len);
    for (int k = 0; k < 3; k++) dot += m->normals[3 * v + k] * d[k] / len;
    CHECK_NEAR(dot, 1.0, 1e-6);
  }
  iris_scene_destroy(s);
}

static void check_openmesh(const char *assets) {
  char path[1024];
  snprintf(path, sizeof path, "%s/ply/stanford-bunny/bun_zipper.ply", assets);
  iris_scene *s = NULL;
  iris_error err;
  CHECK_OK(objply_import(path, &s, &err), &err);
  if (!s) return;
  const iris_mesh *m = &s->meshes[0];
  float *ref = malloc(3 * (size_t)m->vertex_count * sizeof(float));
  bool ok = iris_normals_openmesh(m->positions, m->vertex_count, m->indices, m->triangle_count, ref);
  CHECK(ok);
  if (ok && m->normals) {
    /* Unreferenced vertices: OpenMesh gives (0,0,1) through our normalise, as we do. */
    double worst = 0;
    for (uint32_t v = 0; v < m->vertex_count; v++) {
      double dot = 0;
      for (int k = 0; k < 3; k++) dot += (double)ref[3 * v + k] * m->normals[3 * v + k];
      worst = fmax(worst, acos(fmin(1.0, dot)));
    }
    printf("bunny: largest angle between iris and OpenMesh normals %.3g rad\n", worst);
    CHECK(worst < 1e-3);
  }
  free(ref);
  iris_scene_destroy(s);
}

static uint64_t rng = 88172645463325252ull;
static double uniform(void) {
  rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
  return (double)(rng >> 11) / 9007199254740992.0;
}

static void check_ear_clipping(void) {
  iris_polygon_triangulator *t = iris_polygon_triangulator_create();
  enum { N = 64 };
  float pos[3 * N];
  uint32_t corners[N], tris[3 * (N - 2)];
  for (int trial = 0; trial < 200; trial++) {
    const int n = 4 + (int)(uniform() * (N - 4));
    /* Star-shaped polygon (concave when radii vary) in a tilted plane. */
    const double tilt = uniform() * 1.5, flip = uniform() < 0.5 ? -1 : 1;
    double area2 = 0;
    double px[N], py[N];
    for (int i = 0; i < n; i++) {
      const double a = flip * 2 * 3.14159265358979 * (i + 0.3 * uniform()) / n, r = 0.2 + uniform();
      px[i] = r * cos(a), py[i] = r * sin(a);
      pos[3 * i] = (float)px[i];
      pos[3 * i + 1] = (float)(py[i] * cos(tilt));
      pos[3 * i + 2] = (float)(py[i] * sin(tilt));
      corners[i] = (uint32_t)i;
    }
    for (int i = 0; i < n; i++) area2 += px[i] * py[(i + 1) % n] - px[(i + 1) % n] * py[i];
    const uint32_t nt = iris_polygon_triangulate(t, pos, corners, (uint32_t)n, tris);
    CHECK_EQ_INT(nt, n - 2);
    double sum = 0;
    int flipped = 0;
    for (uint32_t k = 0; k < nt; k++) {
      const uint32_t a = tris[3 * k], b = tris[3 * k + 1], c = tris[3 * k + 2];
      const double cr = (px[b] - px[a]) * (py[c] - py[a]) - (py[b] - py[a]) * (px[c] - px[a]);
      if (cr * area2 < 0) flipped++;
      sum += fabs(cr);
    }
    CHECK_EQ_INT(flipped, 0);
    CHECK_NEAR(sum, fabs(area2), 1e-4 * fabs(area2));
  }
  iris_polygon_triangulator_destroy(t);
}

static void check_weld(void) {
  /* Two triangles of a square with the diagonal's vertices duplicated. */
  iris_mesh m;
  memset(&m, 0, sizeof m);
  const float p[18] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0};
  const uint32_t idx[6] = {0, 1, 2, 3, 4, 5};
  m.positions = malloc(sizeof p), m.indices = malloc(sizeof idx);
  memcpy(m.positions, p, sizeof p), memcpy(m.indices, idx, sizeof idx);
  m.vertex_count = 6, m.triangle_count = 2, m.owned = true;
  CHECK_EQ_INT(iris_mesh_weld(&m), 2);
  CHECK_EQ_INT(m.vertex_count, 4);
  CHECK_EQ_INT(m.indices[3], 0);
  CHECK_EQ_INT(m.indices[4], 2);
  free(m.positions), free(m.indices);
}

int main(int argc, char **argv) {
  if (argc < 2) return TEST_SKIP("usage: test_meshproc ASSETS_DIR");
  iris_log_set_level(IRIS_LOG_QUIET);
  check_cube(argv[1]);
  check_openmesh(argv[1]);
  check_ear_clipping();
  check_weld();
  return TEST_SUMMARY();
}
