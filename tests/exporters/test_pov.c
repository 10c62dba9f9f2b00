/* exporters.pov: renders exports with real POV-Ray 3.7 (headless).
 *  - coverage: a scene seen by a tilted camera with a non-square image and
 *    left/right-asymmetric geometry (instanced, rotated, at several depths) is
 *    exported in coverage mode; POV-Ray's object mask must match the mask of
 *    iris's own camera rays (renderer/camera.h) cast against the triangles here
 *    to within a few pixels. A mirrored or mis-scaled camera fails by hundreds.
 *  - shading: the camera looks straight down on z = 0; the background, an
 *    emitter seen directly, Lambert quads (plain, vertex-coloured, textured)
 *    under a parallel and a point light must match rho/pi (E cos + I cos/d^2)
 *    to 8-bit precision, proving the light-unit conversions and the UV flip.
 * SKIPs (exit 77) when `povray` is not installed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/fileio.h"
#include "core/image.h"
#include "exporters/pov.h"
#include "fixture.h"
#include "renderer/camera.h"

static char g_povray[1024];
static char g_dir[1024];

/* Renders pov into png at w x h; false (after a failed check) on failure. */
static bool render(const char *pov, const char *png, int w, int h) {
  char cmd[8192], log[1200];
  snprintf(log, sizeof log, "%s.log", png);
  /* HOME with a copy of the system povray.conf silences the "cannot open the
   * user configuration file" warning; -D: no display. */
  snprintf(cmd, sizeof cmd,
           "mkdir -p '%s/home/.povray/3.7' && (cp /etc/povray/3.7/povray.conf '%s/home/.povray/3.7/' "
           "2>/dev/null; true) && cd '%s' && HOME='%s/home' '%s' +I'%s' +O'%s' +FN +W%d +H%d -D -V",
           g_dir, g_dir, g_dir, g_dir, g_povray, pov, png, w, h);
  int rc = fixture_run(cmd, log);
  char *out = fixture_read_text(log);
  bool ok = CHECK(rc == 0);
  if (!ok) fprintf(stderr, "povray failed (%d):\n%s\n", rc, out ? out : "(no log)");
  CHECK(out && !strstr(out, "Parse Error") && !strstr(out, "Possible Parse Error"));
  free(out);
  return ok;
}

static bool load_png(const char *png, iris_ldr_image *img, int w, int h) {
  iris_error err;
  iris_error_clear(&err);
  iris_status st = iris_ldr_load_file(png, img, &err);
  CHECK_OK(st, &err);
  if (st != IRIS_OK) return false;
  CHECK_EQ_INT(img->width, w);
  CHECK_EQ_INT(img->height, h);
  return img->width == w && img->height == h;
}

/* ---- coverage -------------------------------------------------------------- */

#define CW 80
#define CH 60

typedef struct tri {
  iris_vec3 a, b, c;
} tri;

static bool hit(const tri *t, iris_ray r) {
  iris_vec3 e1 = iris_sub(t->b, t->a), e2 = iris_sub(t->c, t->a);
  iris_vec3 p = iris_cross(r.d, e2);
  float det = iris_dot(e1, p);
  if (fabsf(det) < 1e-12f) return false;
  float inv = 1.0f / det;
  iris_vec3 s = iris_sub(r.o, t->a);
  float u = iris_dot(s, p) * inv;
  if (u < 0.0f || u > 1.0f) return false;
  iris_vec3 q = iris_cross(s, e1);
  float v = iris_dot(r.d, q) * inv;
  if (v < 0.0f || u + v > 1.0f) return false;
  return iris_dot(e2, q) * inv > 1e-6f;
}

static iris_scene *coverage_scene(void) {
  iris_scene *s = iris_scene_create();
  iris_camera cam;
  memset(&cam, 0, sizeof cam);
  cam.name = iris_strdup("tilted");
  cam.to_world = iris_mat4_look_at(iris_v3(1.2f, 1.2f, 2.6f), iris_v3(0.0f, 0.1f, 0.0f), iris_v3(0, 1, 0));
  cam.yfov = 50.0f * IRIS_PI / 180.0f;
  cam.aspect = (float)CW / CH;
  iris_scene_add_camera(s, &cam);

  iris_material glass = iris_material_default(IRIS_MATERIAL_GLASS);
  glass.name = iris_strdup("glass");
  int32_t mg = iris_scene_add_material(s, &glass);
  iris_material em = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  em.name = iris_strdup("emitter");
  em.emission[0] = em.emission[1] = em.emission[2] = 5.0f;
  int32_t me = iris_scene_add_material(s, &em);

  /* A floor, an upright quad on the left only, a small rotated quad instanced
   * twice, an emitter and a glass pane in front. */
  fixture_quad q = {0};
  q.hx = 1.2f, q.hy = 0.8f, q.material = -1;
  int32_t floor = fixture_add_quad(s, "floor", &q);
  iris_instance inst;
  inst.mesh = (uint32_t)floor;
  const float rx[4] = {-0.70710678f, 0, 0, 0.70710678f}; /* -90 degrees about x: z=0 plane -> y=0 plane */
  const float t0[3] = {0, -0.5f, 0}, one[3] = {1, 1, 1};
  inst.transform = iris_mat4_trs(t0, rx, one);
  iris_scene_add_instance(s, &inst);

  fixture_quad w = {0};
  w.cx = -0.9f, w.cy = 0.2f, w.cz = -0.6f, w.hx = 0.25f, w.hy = 0.7f, w.material = -1;
  fixture_add_instance(s, fixture_add_quad(s, "left-wall", &w), 0, 0, 0);

  fixture_quad small = {0};
  small.hx = 0.2f, small.hy = 0.1f, small.material = -1, small.normals = true;
  int32_t sm = fixture_add_quad(s, "small", &small);
  const float rz[4] = {0, 0, 0.38268343f, 0.92387953f}; /* 45 degrees about z */
  const float t1[3] = {0.5f, 0.6f, 0.3f}, t2[3] = {0.9f, -0.1f, 0.8f}, sc[3] = {1.5f, 1.0f, 1.0f};
  inst.mesh = (uint32_t)sm;
  inst.transform = iris_mat4_trs(t1, rz, sc);
  iris_scene_add_instance(s, &inst);
  inst.transform = iris_mat4_trs(t2, rz, one);
  iris_scene_add_instance(s, &inst);

  fixture_quad e = {0};
  e.cx = 0.2f, e.cy = 1.1f, e.cz = -0.3f, e.hx = 0.3f, e.hy = 0.15f, e.material = me;
  fixture_add_instance(s, fixture_add_quad(s, "emitter", &e), 0, 0, 0);
  fixture_quad g = {0};
  g.cx = -0.2f, g.cy = -0.1f, g.cz = 1.0f, g.hx = 0.15f, g.hy = 0.3f, g.material = mg, g.normals = true;
  fixture_add_instance(s, fixture_add_quad(s, "glass", &g), 0, 0, 0);
  return s;
}

static void check_coverage(void) {
  iris_scene *s = coverage_scene();
  iris_error err;
  iris_error_clear(&err);

  /* The export frames exactly what iris's camera frames. */
  iris_pinhole cam;
  CHECK_OK(iris_pinhole_setup(s, NULL, CW, CH, &cam, &err), &err);
  iris_export_params p = iris_export_params_default();
  p.width = CW, p.height = CH, p.coverage = true;
  iris_export_view view;
  CHECK_OK(iris_export_resolve_view(s, &p, "test", &view, &err), &err);
  CHECK_EQ_INT(view.width, cam.width);
  CHECK_EQ_INT(view.height, cam.height);
  CHECK_NEAR(view.yfov, cam.yfov, 1e-6);
  CHECK_NEAR(view.to_world.m[0][3], cam.origin.x, 1e-5);
  CHECK_NEAR(-view.to_world.m[2][2], cam.forward.z, 1e-5);

  /* iris's own coverage: a ray through each pixel centre against every triangle. */
  size_t ntri = 0;
  for (size_t i = 0; i < s->instance_count; i++) ntri += s->meshes[s->instances[i].mesh].triangle_count;
  tri *tris = malloc(ntri * sizeof *tris);
  size_t k = 0;
  for (size_t i = 0; i < s->instance_count; i++) {
    const iris_instance *in = &s->instances[i];
    const iris_mesh *m = &s->meshes[in->mesh];
    for (uint32_t t = 0; t < m->triangle_count; t++) {
      iris_vec3 v[3];
      for (int j = 0; j < 3; j++)
        v[j] = iris_mat4_point(&in->transform, iris_v3_load(m->positions + 3 * (size_t)m->indices[3 * t + j]));
      tris[k].a = v[0], tris[k].b = v[1], tris[k].c = v[2];
      k++;
    }
  }
  static unsigned char mask[CH][CW];
  int covered = 0, left = 0;
  for (int y = 0; y < CH; y++)
    for (int x = 0; x < CW; x++) {
      iris_ray r = iris_pinhole_ray(&cam, (float)x + 0.5f, (float)y + 0.5f);
      mask[y][x] = 0;
      for (size_t t = 0; t < ntri && !mask[y][x]; t++) mask[y][x] = hit(&tris[t], r);
      covered += mask[y][x];
      left += mask[y][x] && x < CW / 2;
    }
  free(tris);
  /* The scene must be a meaningful test: partly covered and asymmetric. */
  CHECK(covered > CW * CH / 6 && covered < CW * CH * 5 / 6);
  CHECK(left != covered - left);

  char pov[1200], png[1200];
  snprintf(pov, sizeof pov, "%s/coverage.pov", g_dir);
  snprintf(png, sizeof png, "%s/coverage.png", g_dir);
  CHECK_OK(iris_export_pov(s, pov, &p, &err), &err);
  iris_ldr_image img = {0};
  if (render(pov, png, CW, CH) && load_png(png, &img, CW, CH)) {
    int mismatch = 0, mirrored = 0;
    for (int y = 0; y < CH; y++)
      for (int x = 0; x < CW; x++) {
        const uint8_t *c = img.rgba + 4 * ((size_t)y * CW + x);
        int pov_on = c[0] > 127;
        CHECK(c[0] == 0 || c[0] == 255); /* coverage mode is pure white on black */
        mismatch += pov_on != mask[y][x];
        mirrored += pov_on != mask[y][CW - 1 - x];
      }
    printf("coverage: %d of %d pixels covered by iris, %d differ from POV-Ray (%d if mirrored)\n",
           covered, CW * CH, mismatch, mirrored);
    CHECK(mismatch <= 4);
    CHECK(mirrored > 100);
  }
  iris_ldr_destroy(&img);

  /* The full export of the same scene (glass, emitter as area light) parses and renders. */
  p.coverage = false;
  snprintf(pov, sizeof pov, "%s/full.pov", g_dir);
  snprintf(png, sizeof png, "%s/full.png", g_dir);
  CHECK_OK(iris_export_pov(s, pov, &p, &err), &err);
  memset(&img, 0, sizeof img);
  if (render(pov, png, CW, CH)) load_png(png, &img, CW, CH);
  iris_ldr_destroy(&img);
  iris_scene_destroy(s);
}

/* ---- shading ---------------------------------------------------------------- */

#define SW 64
#define SH 64

static const float BG[3] = {0.1f, 0.2f, 0.3f};
static const float EMIT[3] = {0.25f, 0.5f, 0.75f};
static const float VC[3] = {0.9f, 0.5f, 0.2f};
static const float SUN_E = 0.45f * IRIS_PI; /* Lambert white under it: 0.45 */
static const float PT_I = 0.3f;
static const iris_vec3 PT_POS = {0.5f, -0.5f, 1.0f};

static iris_scene *shading_scene(const char *dir) {
  iris_scene *s = iris_scene_create();
  s->has_environment = true;
  memcpy(s->environment, BG, sizeof BG);
  fixture_add_top_camera(s, 10.0f, 1.0f, 1.0f);

  iris_material white = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  white.color[0] = white.color[1] = white.color[2] = 1.0f;
  white.name = iris_strdup("white");
  int32_t mw = iris_scene_add_material(s, &white);
  iris_material em = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  memcpy(em.emission, EMIT, sizeof EMIT);
  em.name = iris_strdup("emitter");
  int32_t me = iris_scene_add_material(s, &em);

  /* A 2x2 PNG on disk: top-left red, top-right green, bottom-left blue, bottom-right white. */
  iris_image img;
  const char *names[3] = {"R", "G", "B"};
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_image_create(&img, 2, 2, 3, names, &err), &err);
  const float texel[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  memcpy(img.data, texel, sizeof texel);
  char path[1200];
  snprintf(path, sizeof path, "%s/checker.png", dir);
  CHECK_OK(iris_png_write(path, &img, 0, 0.0f, &err), &err);
  iris_image_destroy(&img);
  iris_texture t;
  memset(&t, 0, sizeof t);
  t.path = iris_strdup(path);
  snprintf(t.mime, sizeof t.mime, "image/png");
  t.nearest = true;
  int32_t tex = iris_scene_add_texture(s, &t);
  iris_material textured = white;
  textured.name = iris_strdup("textured");
  textured.color_texture = tex;
  int32_t mt = iris_scene_add_material(s, &textured);
  iris_material glossy = iris_material_default(IRIS_MATERIAL_GLOSSY);
  glossy.name = iris_strdup("glossy");
  int32_t mg = iris_scene_add_material(s, &glossy);
  iris_material gltf = iris_material_default(IRIS_MATERIAL_GLTF);
  gltf.name = iris_strdup("gltf");
  gltf.transmission = 0.5f;
  int32_t mf = iris_scene_add_material(s, &gltf);

  /* 4x4 cells of 16 pixels: row 0 = background, emitter, glossy, glTF;
   * row 1 = white, vertex colours; rows 2-3, cols 0-1 = texture; cols 2-3 = white. */
  fixture_quad q = {0};
  q.hx = q.hy = 0.25f, q.cy = 0.75f;
  q.cx = -0.25f, q.material = me;
  fixture_add_instance(s, fixture_add_quad(s, "emitter", &q), 0, 0, 0);
  q.cx = 0.25f, q.material = mg;
  fixture_add_instance(s, fixture_add_quad(s, "glossy", &q), 0, 0, 0);
  q.cx = 0.75f, q.material = mf, q.normals = true;
  fixture_add_instance(s, fixture_add_quad(s, "gltf", &q), 0, 0, 0);
  q.cx = -0.75f, q.cy = 0.25f, q.material = mw;
  fixture_add_instance(s, fixture_add_quad(s, "white", &q), 0, 0, 0);
  q.cx = -0.25f, q.color = VC;
  fixture_add_instance(s, fixture_add_quad(s, "vertex-colours", &q), 0, 0, 0);
  fixture_quad b = {0};
  b.hx = b.hy = 0.5f, b.uvs = true, b.cx = -0.5f, b.cy = -0.5f, b.material = mt;
  fixture_add_instance(s, fixture_add_quad(s, "textured", &b), 0, 0, 0);
  b.uvs = false, b.cx = 0.5f, b.material = mw;
  fixture_add_instance(s, fixture_add_quad(s, "white-big", &b), 0, 0, 0);

  iris_light l;
  memset(&l, 0, sizeof l);
  l.name = iris_strdup("sun");
  l.type = IRIS_LIGHT_DIRECTIONAL;
  l.color[0] = l.color[1] = l.color[2] = 1.0f;
  l.intensity = SUN_E;
  l.direction[2] = -1.0f;
  iris_scene_add_light(s, &l);
  memset(&l, 0, sizeof l);
  l.name = iris_strdup("point");
  l.type = IRIS_LIGHT_POINT;
  l.color[0] = l.color[1] = l.color[2] = 1.0f;
  l.intensity = PT_I;
  iris_v3_store(PT_POS, l.position);
  iris_scene_add_light(s, &l);
  return s;
}

/* Irradiance / pi at (x, y, 0): a Lambert surface of albedo rho shows rho times this. */
static double lit(double x, double y) {
  double dx = PT_POS.x - x, dy = PT_POS.y - y, dz = PT_POS.z, d2 = dx * dx + dy * dy + dz * dz;
  return (SUN_E + PT_I * dz / sqrt(d2) / d2) / 3.14159265358979323846;
}

/* POV-Ray writes sRGB-encoded 8-bit PNGs: compare in that encoding (1.5 codes). */
static void check_pixel(const iris_ldr_image *img, int x, int y, const double want[3], const char *what) {
  const uint8_t *c = img->rgba + 4 * ((size_t)y * img->width + x);
  for (int k = 0; k < 3; k++) {
    double code = 255.0 * iris_linear_to_srgb((float)fmin(want[k], 1.0));
    if (!iris_check_record(fabs(code - c[k]) <= 1.5, __FILE__, __LINE__, "%s pixel (%d,%d) channel %d: %d vs expected %.1f",
                           what, x, y, k, c[k], code))
      return;
  }
}

static void check_shading(void) {
  char pov[1200], png[1200];
  iris_scene *s = shading_scene(g_dir);
  iris_export_params p = iris_export_params_default();
  p.width = SW, p.height = SH;
  p.pov_radiosity = IRIS_POV_RADIOSITY_OFF; /* the analytic values are direct light only */
  iris_error err;
  iris_error_clear(&err);
  snprintf(pov, sizeof pov, "%s/shading.pov", g_dir);
  snprintf(png, sizeof png, "%s/shading.png", g_dir);
  CHECK_OK(iris_export_pov(s, pov, &p, &err), &err);
  iris_ldr_image img = {0};
  if (render(pov, png, SW, SH) && load_png(png, &img, SW, SH)) {
    const double texel[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
    for (int y = 0; y < SH; y++)
      for (int x = 0; x < SW; x++) {
        int col = x / 16, row = y / 16, ix = x % 16, iy = y % 16;
        if (ix < 1 || ix > 14 || iy < 1 || iy > 14) continue; /* cell borders */
        float wx, wy;
        fixture_film_to_plane((float)x + 0.5f, (float)y + 0.5f, SW, SH, 1.0f, 1.0f, &wx, &wy);
        double e = lit(wx, wy), want[3];
        if (row == 0 && col == 0) {
          for (int k = 0; k < 3; k++) want[k] = BG[k];
          check_pixel(&img, x, y, want, "background");
        } else if (row == 0 && col == 1) {
          for (int k = 0; k < 3; k++) want[k] = EMIT[k];
          check_pixel(&img, x, y, want, "emitter");
        } else if (row == 1 && col == 0) {
          for (int k = 0; k < 3; k++) want[k] = e;
          check_pixel(&img, x, y, want, "white");
        } else if (row == 1 && col == 1) {
          for (int k = 0; k < 3; k++) want[k] = VC[k] * e;
          check_pixel(&img, x, y, want, "vertex colours");
        } else if (row >= 2 && col <= 1) {
          for (int k = 0; k < 3; k++) want[k] = texel[(row - 2) * 2 + col][k] * e;
          check_pixel(&img, x, y, want, "texture");
        } else if (row >= 2) {
          for (int k = 0; k < 3; k++) want[k] = e;
          check_pixel(&img, x, y, want, "white (point light)");
        }
      }
  }
  iris_ldr_destroy(&img);
  iris_scene_destroy(s);
}

int main(void) {
  if (!fixture_find_tool("povray", g_povray, sizeof g_povray)) return TEST_SKIP("povray is not installed");
  if (iris_test_tmpdir(g_dir, sizeof g_dir, "export-pov") != 0) return TEST_SKIP("no temporary folder");
  check_coverage();
  check_shading();
  if (iris_check_failures == 0 && !getenv("IRIS_KEEP_TEST_FILES"))
    iris_test_rmtree(g_dir);
  else
    printf("files kept in %s\n", g_dir);
  return TEST_SUMMARY();
}
