/* Every good OBJ/PLY file in shared/assets imports with the counts derived
 * independently of iris, and the McGuire Cornell box keeps its exact MTL
 * numbers. How each expected number was obtained is noted next to it:
 *   "assimp" = `assimp info FILE` (Debian assimp-utils 5.2) "Meshes/Faces/Vertices" lines;
 *   "header" = the PLY header's `element` counts (`grep -a ^element FILE`);
 *   "awk"    = the command given in the comment, run on the file. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "core/log.h"
#include "objply_util.h"

typedef struct expect {
  const char *file;
  long meshes, vertices, triangles, materials; /* -1: not checked */
  int normals;                                 /* 1: every mesh has normals, 0: none, -1: not checked */
  int colors;                                  /* 1: colours present */
} expect;

static const expect goods[] = {
    /* meshes, triangles: assimp (8, 36); vertices: distinct referenced v = 64
     * (awk: resolve relative f indices, count unique; 72 v lines, the two
     * bottom faces reuse 8 of them); materials: 8 distinct usemtl names with faces.
     * No 's' line and no vn: flat, so no normals. */
    {"obj/cornell-box-mcguire/CornellBox-Original.obj", 8, 64, 36, 8, 0, 0},
    /* assimp: 8 meshes, 36 faces, 4 materials (the blue front wall's face is commented out) */
    {"obj/cornell-box-cornell-data/cornell_box.obj", 8, -1, 36, 4, 0, 0},
    /* assimp: 64 vertices, 64 faces (a 66-corner polygon with 2 repeated corners -> 64 triangles) */
    {"obj/assimp/concave_polygon.obj", 1, 64, 64, 1, 1, 0},
    /* assimp: 24 vertices, 12 faces; file has vn */
    {"obj/assimp/cube_with_vertexcolors.obj", 1, 24, 12, 0, 1, 1},
    /* assimp: 5856 faces; awk '/^f/{for(i=2;i<=NF;i++)k[$i]=1} END{print length(k)}' = 3225 (v/vt pairs) */
    {"obj/spot/spot_quadrangulated.obj", 1, 3225, 5856, 0, 0, 0},
    /* header: vertex 35947, face 69451 (all triangles; assimp agrees on faces) */
    {"ply/stanford-bunny/bun_zipper.ply", 1, 35947, 69451, 0, 1, 0},
    /* header: 8 vertices, 6 quads; assimp: 12 faces */
    {"ply/assimp/cube.ply", 1, 8, 12, 0, 1, 0},
    /* header: 8 vertices, 12 faces */
    {"ply/assimp/cube_binary.ply", 1, 8, 12, 0, 1, 0},
    /* header: 3 vertices, 1 face; float colours */
    {"ply/assimp/float-color.ply", 1, 3, 1, 0, 1, 1},
    /* header: 50 vertices, 50 faces; awk '/end_header/{h=1;next} h&&NF==$1+1{t+=$1-2} END{print t}'
     * on the ASCII twin = 80 triangles (assimp refuses: faces before vertices) */
    {"ply/happly/platonic_shelf.ply", 1, 50, 80, 0, 1, 0},
    {"ply/happly/platonic_shelf_ascii.ply", 1, 50, 80, 0, 1, 0},
    {"ply/happly/platonic_shelf_big_endian.ply", 1, 50, 80, 0, 1, 0},
    /* header: 12 vertices, 20 faces, with normals */
    {"ply/tinyply/icosahedron.ply", 1, 12, 20, 0, 1, 0},
    /* header: 12103 vertices, 24104 faces (assimp agrees), uchar RGBA */
    {"ply/tinyply/sofa.ply", 1, 12103, 24104, 0, 1, 1},
};

static void check_counts(const char *assets) {
  for (size_t i = 0; i < sizeof goods / sizeof goods[0]; i++) {
    const expect *e = &goods[i];
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", assets, e->file);
    iris_scene *s = NULL;
    iris_error err;
    CHECK_OK(objply_import(path, &s, &err), &err);
    if (!s) continue;
    printf("%s: %zu meshes, %llu vertices, %llu triangles, %zu materials\n", e->file, s->mesh_count,
           (unsigned long long)objply_vertices(s), (unsigned long long)objply_triangles(s), s->material_count);
    if (e->meshes >= 0) CHECK_EQ_INT(s->mesh_count, e->meshes);
    if (e->vertices >= 0) CHECK_EQ_INT(objply_vertices(s), e->vertices);
    if (e->triangles >= 0) CHECK_EQ_INT(objply_triangles(s), e->triangles);
    if (e->materials >= 0) CHECK_EQ_INT(s->material_count, e->materials);
    CHECK_EQ_INT(s->instance_count, s->mesh_count);
    for (size_t m = 0; m < s->mesh_count; m++) {
      if (e->normals >= 0) CHECK_EQ_INT(s->meshes[m].normals != NULL, e->normals);
      CHECK_EQ_INT(s->meshes[m].colors != NULL, e->colors);
    }
    iris_scene_destroy(s);
  }
}

/* McGuire's MTL numbers (shared/assets/README.md, "Cornell box numbers"). */
static void check_cornell(const char *assets) {
  char path[1024];
  snprintf(path, sizeof path, "%s/obj/cornell-box-mcguire/CornellBox-Original.obj", assets);
  iris_scene *s = NULL;
  iris_error err;
  CHECK_OK(objply_import(path, &s, &err), &err);
  if (!s) return;
  static const struct {
    const char *name;
    float kd[3];
  } kd[] = {{"leftWall", {0.63f, 0.065f, 0.05f}}, {"rightWall", {0.14f, 0.45f, 0.091f}},
            {"floor", {0.725f, 0.71f, 0.68f}},    {"ceiling", {0.725f, 0.71f, 0.68f}},
            {"backWall", {0.725f, 0.71f, 0.68f}}, {"shortBox", {0.725f, 0.71f, 0.68f}},
            {"tallBox", {0.725f, 0.71f, 0.68f}},  {"light", {0.78f, 0.78f, 0.78f}}};
  for (size_t i = 0; i < sizeof kd / sizeof kd[0]; i++) {
    /* Meshes are found by material: in this file `usemtl` precedes `g`, so
     * the box faces sit in groups named after the previous object. */
    const iris_mesh *m = NULL;
    for (size_t k = 0; k < s->mesh_count; k++)
      if (s->meshes[k].material >= 0 && !strcmp(s->materials[s->meshes[k].material].name, kd[i].name))
        m = &s->meshes[k];
    CHECK(m != NULL);
    if (!m) continue;
    CHECK(m->material >= 0);
    if (m->material < 0) continue;
    const iris_material *mat = &s->materials[m->material];
    CHECK_EQ_STR(mat->name, kd[i].name);
    CHECK_EQ_INT(mat->type, IRIS_MATERIAL_DIFFUSE);
    for (int k = 0; k < 3; k++) CHECK(mat->color[k] == kd[i].kd[k]); /* exact */
    CHECK_EQ_INT(mat->color_texture, -1);
    const bool light = !strcmp(kd[i].name, "light");
    const float ke[3] = {light ? 17.0f : 0.0f, light ? 12.0f : 0.0f, light ? 4.0f : 0.0f};
    for (int k = 0; k < 3; k++) CHECK(mat->emission[k] == ke[k]);
    if (light) CHECK(mat->emission_two_sided);
    if (light) {
      /* The light quad: area 0.47 x 0.38 = 0.1786, facing down (-y). */
      double n[3];
      CHECK_NEAR(objply_mesh_area(m, n), 0.47 * 0.38, 1e-6);
      CHECK(n[1] < 0 && fabs(n[0]) < 1e-9 && fabs(n[2]) < 1e-9);
      CHECK_EQ_INT(m->triangle_count, 2);
    }
  }
  /* Bounds from the README: x in [-1.02, 1.00], y in [0, 1.99], z in [-1.04, 0.99]. */
  float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
  for (size_t m = 0; m < s->mesh_count; m++)
    for (uint32_t v = 0; v < s->meshes[m].vertex_count; v++)
      for (int k = 0; k < 3; k++) {
        float x = s->meshes[m].positions[3 * v + k];
        lo[k] = x < lo[k] ? x : lo[k];
        hi[k] = x > hi[k] ? x : hi[k];
      }
  CHECK(lo[0] == -1.02f && hi[0] == 1.00f && lo[1] == 0.0f && hi[1] == 1.99f && lo[2] == -1.04f &&
        hi[2] == 0.99f);
  iris_scene_destroy(s);
}

/* The 66-corner keyhole polygon: the triangulation must cover exactly the
 * polygon (total area = shoelace area, computed here from the file itself)
 * with every triangle facing the polygon's way. */
static void check_concave(const char *assets) {
  char path[1024];
  snprintf(path, sizeof path, "%s/obj/assimp/concave_polygon.obj", assets);
  FILE *f = fopen(path, "r");
  CHECK(f != NULL);
  if (!f) return;
  static float v[256][3];
  int nv = 0, poly[256], n = 0;
  char line[4096];
  while (fgets(line, sizeof line, f)) {
    if (line[0] == 'v' && line[1] == ' ' && nv < 256) sscanf(line + 2, "%f %f %f", &v[nv][0], &v[nv][1], &v[nv][2]), nv++;
    if (line[0] == 'f' && line[1] == ' ') {
      char *p = line + 2, *q;
      long idx;
      while ((idx = strtol(p, &q, 10)) != 0 && q != p && n < 256) {
        poly[n++] = (int)idx - 1;
        while (*q && *q != ' ' && *q != '\n') q++;
        p = q;
      }
    }
  }
  fclose(f);
  CHECK_EQ_INT(n, 66);
  double N[3] = {0, 0, 0};
  for (int i = 0; i < n; i++) {
    const float *a = v[poly[i]], *b = v[poly[(i + 1) % n]];
    N[0] += ((double)a[1] - b[1]) * ((double)a[2] + b[2]);
    N[1] += ((double)a[2] - b[2]) * ((double)a[0] + b[0]);
    N[2] += ((double)a[0] - b[0]) * ((double)a[1] + b[1]);
  }
  const double area = 0.5 * sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
  iris_scene *s = NULL;
  iris_error err;
  CHECK_OK(objply_import(path, &s, &err), &err);
  if (!s) return;
  const iris_mesh *m = &s->meshes[0];
  double nsum[3];
  const double tri_area = objply_mesh_area(m, nsum);
  CHECK_NEAR(tri_area, area, 1e-6 * area);
  int flipped = 0;
  for (uint32_t t = 0; t < m->triangle_count; t++) {
    const float *a = m->positions + 3 * m->indices[3 * t], *b = m->positions + 3 * m->indices[3 * t + 1],
                *c = m->positions + 3 * m->indices[3 * t + 2];
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double cn[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    if (cn[0] * N[0] + cn[1] * N[1] + cn[2] * N[2] < 0) flipped++;
  }
  CHECK_EQ_INT(flipped, 0);
  iris_scene_destroy(s);
}

/* Big-endian, little-endian and ASCII copies of the same model agree. */
static void check_ply_twins(const char *assets) {
  const char *names[3] = {"platonic_shelf.ply", "platonic_shelf_ascii.ply", "platonic_shelf_big_endian.ply"};
  iris_scene *s[3] = {NULL, NULL, NULL};
  for (int i = 0; i < 3; i++) {
    char path[1024];
    snprintf(path, sizeof path, "%s/ply/happly/%s", assets, names[i]);
    iris_error err;
    CHECK_OK(objply_import(path, &s[i], &err), &err);
  }
  if (s[0] && s[1] && s[2]) {
    for (int i = 1; i < 3; i++) {
      const iris_mesh *a = &s[0]->meshes[0], *b = &s[i]->meshes[0];
      CHECK_EQ_INT(a->vertex_count, b->vertex_count);
      CHECK_EQ_INT(a->triangle_count, b->triangle_count);
      if (a->vertex_count != b->vertex_count || a->triangle_count != b->triangle_count) continue;
      double dmax = 0;
      for (uint32_t k = 0; k < 3 * a->vertex_count; k++) dmax = fmax(dmax, fabs(a->positions[k] - b->positions[k]));
      CHECK(dmax < 1e-5);
      CHECK(memcmp(a->indices, b->indices, 3 * sizeof(uint32_t) * a->triangle_count) == 0);
    }
  }
  for (int i = 0; i < 3; i++) iris_scene_destroy(s[i]);
}

/* OBJ vertex colours are kept as written (first vertex of the file). */
static void check_obj_colors(const char *assets) {
  char path[1024];
  snprintf(path, sizeof path, "%s/obj/assimp/cube_with_vertexcolors.obj", assets);
  FILE *f = fopen(path, "r");
  float ref[6] = {0};
  char line[512];
  while (f && fgets(line, sizeof line, f))
    if (line[0] == 'v' && line[1] == ' ') {
      sscanf(line + 2, "%f %f %f %f %f %f", &ref[0], &ref[1], &ref[2], &ref[3], &ref[4], &ref[5]);
      break;
    }
  if (f) fclose(f);
  iris_scene *s = NULL;
  iris_error err;
  CHECK_OK(objply_import(path, &s, &err), &err);
  if (!s) return;
  const iris_mesh *m = &s->meshes[0];
  bool found = false;
  for (uint32_t v = 0; v < m->vertex_count && m->colors; v++)
    if (!memcmp(m->positions + 3 * v, ref, 3 * sizeof(float)))
      found = found || !memcmp(m->colors + 3 * v, ref + 3, 3 * sizeof(float));
  CHECK(found);
  iris_scene_destroy(s);
}

int main(int argc, char **argv) {
  if (argc < 2) return TEST_SKIP("usage: test_assets ASSETS_DIR");
  iris_log_set_level(IRIS_LOG_QUIET);
  check_counts(argv[1]);
  check_cornell(argv[1]);
  check_concave(argv[1]);
  check_ply_twins(argv[1]);
  check_obj_colors(argv[1]);
  return TEST_SUMMARY();
}
