/* exporters.blender: exports scenes whose pixels are known analytically, renders
 * the scripts in real Blender 3.4 (Cycles) and checks the EXR pixel by pixel.
 *  - scene "cells" (uniform environment E, camera straight down on z = 0):
 *    environment seen directly = E; emitters seen directly = their radiance
 *    (one-sided seen from the back = 0); Lambert planes = albedo x E (also with
 *    vertex colours, instancing and a texture whose quadrants check the v flip);
 *    smooth white glass = E (white furnace); GGX glossy in (0.9, 1] x tint x E.
 *  - scenes "light0..2" (no environment, one delta light each, so Cycles is
 *    noise-free): point, spot (glTF falloff) and sun on a Lambert plane against
 *    rho/pi I cos/d^2 and rho/pi E cos; light0 has its mesh data embedded and a
 *    shading normal tilted 16.7 degrees from the geometric one (custom normals).
 *  - scene "features" (glTF features, same environment and camera): the checker
 *    texture read through the second uv set with a KHR_texture_transform offset
 *    of (0.5, 0.5) (quadrants swapped diagonally; the first uv set points at one
 *    texel, so reading it would show a single colour); a Lambert quad of albedo
 *    0.5 with alphaMode MASK, cutoff 0.25 and a vertex-alpha ramp 0 -> 1 across
 *    x (its left quarter cut: 1/6 E + 5/6 x 0.5 E over the 12x12 interior that
 *    is averaged); one with BLEND, alpha 0.5
 *    (0.5 E + 0.5 x 0.5 E).
 * SKIPs (exit 77) when `blender` is not installed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/fileio.h"
#include "core/image.h"
#include "exporters/blender.h"
#include "fixture.h"

#define PI_D 3.14159265358979323846
#define W 64
#define H 64
#define HALF 1.0f
#define CAM_Z 10.0f

static const float ENV[3] = {0.5f, 1.0f, 2.0f};

static char g_blender[1024];
static char g_dir[1024];

/* Renders `script` with Blender into `exr`; returns false (after a failed check)
 * when Blender fails. Checks the timing line the script prints. */
static bool render(const char *script, const char *exr, int spp) {
  char cmd[4096], log[1200];
  snprintf(log, sizeof log, "%s.log", exr);
  snprintf(cmd, sizeof cmd,
           "'%s' -b --factory-startup --python-exit-code 1 -P '%s' -- --output '%s' --spp %d "
           "--threads 2 --seed 7",
           g_blender, script, exr, spp);
  int rc = fixture_run(cmd, log);
  char *out = fixture_read_text(log);
  bool ok = CHECK(rc == 0);
  if (!ok) fprintf(stderr, "blender failed (%d):\n%s\n", rc, out ? out : "(no log)");
  const char *line = out ? strstr(out, "IRIS_BLENDER build_seconds=") : NULL;
  double build = -1, secs = -1;
  int got_spp = 0;
  if (line) sscanf(line, "IRIS_BLENDER build_seconds=%lf render_seconds=%lf spp=%d", &build, &secs, &got_spp);
  CHECK(line != NULL);
  CHECK(secs > 0.0 && build >= 0.0);
  CHECK_EQ_INT(got_spp, spp);
  if (line) printf("%.*s\n", (int)strcspn(line, "\n"), line);
  free(out);
  return ok;
}

static bool load(const char *exr, iris_image *img) {
  iris_error err;
  iris_error_clear(&err);
  iris_status st = iris_exr_read(exr, img, NULL, NULL, &err);
  CHECK_OK(st, &err);
  if (st != IRIS_OK) return false;
  CHECK_EQ_INT(img->width, W);
  CHECK_EQ_INT(img->height, H);
  CHECK(iris_image_channel(img, "R") >= 0 && iris_image_channel(img, "B") >= 0);
  return img->width == W && img->height == H;
}

static float px(const iris_image *img, int x, int y, int c) {
  static const char *const names[3] = {"R", "G", "B"};
  int ch = iris_image_channel(img, names[c]);
  return img->data[((size_t)y * img->width + x) * img->channel_count + ch];
}

/* Mean of channel c over the 12x12 interior of a 16x16 cell (col, row). */
static double cell_mean(const iris_image *img, int col, int row, int c) {
  double sum = 0;
  for (int y = 16 * row + 2; y < 16 * row + 14; y++)
    for (int x = 16 * col + 2; x < 16 * col + 14; x++) sum += px(img, x, y, c);
  return sum / 144.0;
}

static float cell_x(int col) { return -0.75f + 0.5f * (float)col; }
static float cell_y(int row) { return 0.75f - 0.5f * (float)row; }

static int32_t add_material(iris_scene *s, iris_material m, const char *name) {
  m.name = iris_strdup(name);
  int32_t i = iris_scene_add_material(s, &m);
  if (i < 0) abort();
  return i;
}

/* A 2x2 texture: top-left red, top-right green, bottom-left blue, bottom-right white. */
static int32_t add_checker_texture(iris_scene *s) {
  const float texel[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  return fixture_add_png_texture(s, g_dir, "checker", texel, true);
}

static iris_scene *cells_scene(void) {
  iris_scene *s = iris_scene_create();
  s->has_environment = true;
  memcpy(s->environment, ENV, sizeof ENV);
  fixture_add_top_camera(s, CAM_Z, HALF, 1.0f);

  iris_material black = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  black.color[0] = black.color[1] = black.color[2] = 0.0f;
  iris_material e1 = black, e2 = black, e3 = black;
  e1.emission[0] = 3.0f, e1.emission[1] = 2.0f, e1.emission[2] = 1.0f;
  e1.emission_two_sided = false;
  e2 = e1; /* one-sided, seen from the back */
  e3.emission[0] = 1.0f, e3.emission[1] = 2.0f, e3.emission[2] = 3.0f;
  e3.emission_two_sided = true;
  iris_material dif = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  dif.color[0] = 0.8f, dif.color[1] = 0.5f, dif.color[2] = 0.2f;
  iris_material white = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  white.color[0] = white.color[1] = white.color[2] = 1.0f;
  iris_material glass = iris_material_default(IRIS_MATERIAL_GLASS);
  glass.color[0] = glass.color[1] = glass.color[2] = 1.0f;
  glass.roughness = 0.0f;
  glass.ior = 1.5f;
  iris_material glossy = iris_material_default(IRIS_MATERIAL_GLOSSY);
  glossy.color[0] = 0.9f, glossy.color[1] = 0.6f, glossy.color[2] = 0.3f;
  glossy.roughness = 0.3f;
  iris_material gltf = iris_material_default(IRIS_MATERIAL_GLTF);
  gltf.metallic = 0.5f;
  gltf.roughness = 0.4f;
  gltf.transmission = 0.2f;

  int32_t tex = add_checker_texture(s);
  iris_material textured = white;
  textured.color_texture = tex;
  gltf.color_texture = tex;

  fixture_quad q = {0};
  q.hx = q.hy = 0.25f;
  /* Row 0: (0,0) environment only; emitters. */
  q.cx = cell_x(1), q.cy = cell_y(0), q.material = add_material(s, e1, "emit-front");
  fixture_add_instance(s, fixture_add_quad(s, "emit-front", &q), 0, 0, 0);
  q.cx = cell_x(2), q.facing_down = true, q.material = add_material(s, e2, "emit-back-one-sided");
  fixture_add_instance(s, fixture_add_quad(s, "emit-back", &q), 0, 0, 0);
  q.cx = cell_x(3), q.material = add_material(s, e3, "emit-back-two-sided");
  fixture_add_instance(s, fixture_add_quad(s, "emit-back-2", &q), 0, 0, 0);
  q.facing_down = false;
  /* Row 1: Lambert, vertex colours (one mesh instanced twice), glass. */
  q.cx = cell_x(0), q.cy = cell_y(1), q.normals = true, q.material = add_material(s, dif, "lambert");
  fixture_add_instance(s, fixture_add_quad(s, "lambert", &q), 0, 0, 0);
  q.normals = false;
  const float vc[3] = {0.25f, 0.5f, 0.75f};
  int32_t white_index = add_material(s, white, "white");
  q.cx = 0.0f, q.cy = 0.0f, q.color = vc, q.material = white_index;
  int32_t vcq = fixture_add_quad(s, "vertex-colours", &q);
  fixture_add_instance(s, vcq, cell_x(1), cell_y(1), 0);
  fixture_add_instance(s, vcq, cell_x(3), cell_y(3), 0);
  q.color = NULL;
  q.cx = cell_x(2), q.cy = cell_y(1), q.material = add_material(s, glass, "glass");
  fixture_add_instance(s, fixture_add_quad(s, "glass", &q), 0, 0, 0);
  q.cx = cell_x(3), q.material = add_material(s, glossy, "glossy");
  fixture_add_instance(s, fixture_add_quad(s, "glossy", &q), 0, 0, 0);
  /* Rows 2-3, cols 0-1: the textured quad; (2,2): glTF; (3,3): vertex colours. */
  fixture_quad t = {0};
  t.cx = -0.5f, t.cy = -0.5f, t.hx = t.hy = 0.5f, t.uvs = true, t.normals = true;
  t.material = add_material(s, textured, "textured");
  fixture_add_instance(s, fixture_add_quad(s, "textured", &t), 0, 0, 0);
  q.cx = cell_x(2), q.cy = cell_y(2), q.uvs = true, q.material = add_material(s, gltf, "gltf");
  fixture_add_instance(s, fixture_add_quad(s, "gltf", &q), 0, 0, 0);
  /* (3,2): a white quad whose mesh also holds a degenerate triangle (Blender
   * must drop it with mesh.validate() rather than fail). */
  q.cx = cell_x(3), q.uvs = false, q.material = white_index;
  int32_t dq = fixture_add_quad(s, "with-degenerate", &q);
  iris_mesh *dm = &s->meshes[dq];
  uint32_t *grown = realloc(dm->indices, 9 * sizeof(uint32_t));
  if (!grown) abort();
  grown[6] = 0, grown[7] = 0, grown[8] = 1;
  dm->indices = grown;
  dm->triangle_count = 3;
  fixture_add_instance(s, dq, 0, 0, 0);
  return s;
}

static iris_scene *features_scene(void) {
  iris_scene *s = iris_scene_create();
  s->has_environment = true;
  memcpy(s->environment, ENV, sizeof ENV);
  fixture_add_top_camera(s, CAM_Z, HALF, 1.0f);
  iris_material white = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  white.color[0] = white.color[1] = white.color[2] = 1.0f;
  int32_t tex = add_checker_texture(s);
  s->textures[tex].uv_set = 1;
  s->textures[tex].has_transform = true;
  s->textures[tex].offset[0] = s->textures[tex].offset[1] = 0.5f;
  s->textures[tex].scale[0] = s->textures[tex].scale[1] = 1.0f;
  iris_material textured = white;
  textured.color_texture = tex;
  fixture_quad t = {0};
  t.cx = -0.5f, t.cy = -0.5f, t.hx = t.hy = 0.5f, t.uvs = true, t.normals = true;
  t.material = add_material(s, textured, "placed");
  int32_t tq = fixture_add_quad(s, "placed", &t);
  iris_mesh *m = &s->meshes[tq];
  m->uvs1 = m->uvs;
  m->uvs = malloc(8 * sizeof(float));
  for (int i = 0; i < 8; i++) m->uvs[i] = 0.25f; /* set 0: the red texel only */
  fixture_add_instance(s, tq, 0, 0, 0);
  iris_material half = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  half.color[0] = half.color[1] = half.color[2] = 0.5f;
  iris_material mask = half, blend = half;
  mask.alpha_mode = IRIS_ALPHA_MASK, mask.alpha_cutoff = 0.25f;
  blend.alpha_mode = IRIS_ALPHA_BLEND, blend.alpha = 0.5f;
  fixture_quad q = {0};
  q.hx = q.hy = 0.25f;
  q.cx = cell_x(0), q.cy = cell_y(0), q.material = add_material(s, mask, "mask");
  int32_t mq = fixture_add_quad(s, "mask", &q);
  s->meshes[mq].alphas = malloc(4 * sizeof(float));
  const float ramp[4] = {0, 1, 1, 0}; /* corners bottom-left, bottom-right, top-right, top-left */
  memcpy(s->meshes[mq].alphas, ramp, sizeof ramp);
  fixture_add_instance(s, mq, 0, 0, 0);
  q.cx = cell_x(1), q.material = add_material(s, blend, "blend");
  fixture_add_instance(s, fixture_add_quad(s, "blend", &q), 0, 0, 0);
  return s;
}

static void check_features(const iris_image *img) {
  const double rel = 0.03;
  const float texel[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  for (int c = 0; c < 3; c++) {
    for (int k = 0; k < 4; k++) { /* quadrant k shows texel 3 - k */
      double m = cell_mean(img, k % 2, 2 + k / 2, c), want = texel[3 - k][c] * ENV[c];
      CHECK_NEAR(m, want, rel * ENV[c]);
    }
    /* MASK: the cut part x < 1/4 of the quad is 2 of the 12 interior columns
     * cell_mean averages (pixels 2..13 of 16): 1/6 E + 5/6 x 0.5 E */
    CHECK_NEAR(cell_mean(img, 0, 0, c), (1.0 / 6.0 + 5.0 / 12.0) * ENV[c], rel * ENV[c]);
    CHECK_NEAR(cell_mean(img, 1, 0, c), 0.75 * ENV[c], 2 * rel * ENV[c]); /* BLEND (stochastic) */
  }
}

static void check_cells(const iris_image *img) {
  const double rel = 0.03; /* 16 spp x 144 pixels of a noisy environment estimate */
  for (int c = 0; c < 3; c++) {
    const float e1[3] = {3, 2, 1}, e3[3] = {1, 2, 3}, dif[3] = {0.8f, 0.5f, 0.2f};
    const float vc[3] = {0.25f, 0.5f, 0.75f}, gl[3] = {0.9f, 0.6f, 0.3f};
    CHECK_NEAR(cell_mean(img, 0, 0, c), ENV[c], 1e-4 * ENV[c]);    /* environment, exact */
    CHECK_NEAR(cell_mean(img, 1, 0, c), e1[c], 1e-4 * e1[c]);      /* emitter, exact */
    CHECK_NEAR(cell_mean(img, 2, 0, c), 0.0, 1e-6);                /* one-sided, back */
    CHECK_NEAR(cell_mean(img, 3, 0, c), e3[c], 1e-4 * e3[c]);      /* two-sided, back */
    CHECK_NEAR(cell_mean(img, 0, 1, c), dif[c] * ENV[c], rel * dif[c] * ENV[c]);
    CHECK_NEAR(cell_mean(img, 1, 1, c), vc[c] * ENV[c], rel * vc[c] * ENV[c]);
    CHECK_NEAR(cell_mean(img, 3, 3, c), vc[c] * ENV[c], rel * vc[c] * ENV[c]);
    CHECK_NEAR(cell_mean(img, 3, 2, c), ENV[c], rel * ENV[c]); /* white, degenerate triangle dropped */
    CHECK_NEAR(cell_mean(img, 2, 1, c), ENV[c], rel * ENV[c]);     /* smooth glass furnace */
    double g = cell_mean(img, 3, 1, c) / (gl[c] * ENV[c]);         /* GGX albedo, no Fresnel */
    CHECK(g > 0.9 && g < 1.0 + rel);
    double p = cell_mean(img, 2, 2, c);                            /* Principled: plausible */
    CHECK(p > 0.0 && p < 1.05 * ENV[c]);
    /* Texture quadrants: top-left red, top-right green, bottom-left blue, bottom-right white. */
    const float texel[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
    for (int k = 0; k < 4; k++) {
      double m = cell_mean(img, k % 2, 2 + k / 2, c), want = texel[k][c] * ENV[c];
      CHECK_NEAR(m, want, rel * ENV[c]);
    }
  }
  size_t bad = 0;
  for (size_t i = 0; i < (size_t)img->width * img->height * img->channel_count; i++)
    bad += !isfinite(img->data[i]);
  CHECK_EQ_INT(bad, 0);
}

/* ---- delta lights: exact expectation --------------------------------------- */

static const float RHO = 0.5f;
/* The point-light plane's shading normal, tilted away from the geometric +z so
 * that Blender's custom split normals are exercised. */
static const float TILT[3] = {0.28734789f, 0.0f, 0.95782629f}; /* normalize(0.3, 0, 1) */

static iris_scene *lights_scene(int which) {
  iris_scene *s = iris_scene_create();
  fixture_add_top_camera(s, CAM_Z, HALF, 1.0f);
  iris_material dif = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  dif.color[0] = dif.color[1] = dif.color[2] = RHO;
  fixture_quad q = {0};
  q.hx = q.hy = 1.5f, q.normals = true, q.material = add_material(s, dif, "plane");
  if (which == 0) q.normal = TILT;
  fixture_add_instance(s, fixture_add_quad(s, "plane", &q), 0, 0, 0);

  iris_light l;
  memset(&l, 0, sizeof l);
  l.name = which == 0 ? iris_strdup("point") : NULL;
  l.type = IRIS_LIGHT_POINT;
  l.color[0] = 1.0f, l.color[1] = 0.5f, l.color[2] = 0.25f;
  l.intensity = 2.0f;
  l.position[0] = 0.3f, l.position[1] = -0.2f, l.position[2] = 1.0f;
  if (which == 0) iris_scene_add_light(s, &l);
  memset(&l, 0, sizeof l);
  l.name = which == 1 ? iris_strdup("spot") : NULL;
  l.type = IRIS_LIGHT_SPOT;
  l.color[0] = 0.2f, l.color[1] = 0.6f, l.color[2] = 1.0f;
  l.intensity = 5.0f;
  l.position[0] = -0.4f, l.position[1] = 0.3f, l.position[2] = 1.5f;
  l.direction[2] = -1.0f;
  l.inner_cone = 15.0f * IRIS_PI / 180.0f;
  l.outer_cone = 35.0f * IRIS_PI / 180.0f;
  if (which == 1) iris_scene_add_light(s, &l);
  memset(&l, 0, sizeof l);
  l.name = which == 2 ? iris_strdup("sun") : NULL;
  l.type = IRIS_LIGHT_DIRECTIONAL;
  l.color[0] = l.color[1] = l.color[2] = 1.0f;
  l.intensity = 0.7f;
  iris_vec3 d = iris_normalize(iris_v3(0.3f, 0.2f, -1.0f));
  iris_v3_store(d, l.direction);
  if (which == 2) iris_scene_add_light(s, &l);
  return s;
}

/* Radiance leaving the plane at (x, y, 0) towards the camera, from the three
 * lights as defined by KHR_lights_punctual (spot: squared linear ramp in cos). */
static double analytic(double x, double y, int c, int which) {
  double sum = 0;
  if (which == 0) { /* point */
    double dx = 0.3 - x, dy = -0.2 - y, dz = 1.0, d2 = dx * dx + dy * dy + dz * dz;
    const double col[3] = {1, 0.5, 0.25};
    double cos_s = (TILT[0] * dx + TILT[1] * dy + TILT[2] * dz) / sqrt(d2); /* shading normal */
    sum += 2.0 * col[c] * fmax(cos_s, 0.0) / d2;
  }
  if (which == 1) { /* spot */
    double dx = -0.4 - x, dy = 0.3 - y, dz = 1.5, d2 = dx * dx + dy * dy + dz * dz;
    double cos_axis = dz / sqrt(d2); /* light travels along -z */
    double co = cos(35.0 * PI_D / 180.0), ci = cos(15.0 * PI_D / 180.0);
    double t = (cos_axis - co) / (ci - co);
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    const double col[3] = {0.2, 0.6, 1.0};
    sum += 5.0 * col[c] * t * t * cos_axis / d2;
  }
  if (which == 2) { /* sun: irradiance 0.7 on a surface facing it */
    double dz = 1.0 / sqrt(0.09 + 0.04 + 1.0);
    sum += 0.7 * dz;
  }
  return RHO / PI_D * sum;
}

static void check_lights(const iris_image *img, int which) {
  static double expect[H][W][3];
  double sum_r = 0, sum_a = 0;
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++)
      for (int c = 0; c < 3; c++) {
        /* Box-filtered pixel: average of 4x4 points over the pixel footprint. */
        double a = 0;
        for (int j = 0; j < 4; j++)
          for (int i = 0; i < 4; i++) {
            float wx, wy;
            fixture_film_to_plane((float)x + (i + 0.5f) / 4.0f, (float)y + (j + 0.5f) / 4.0f, W, H, HALF,
                                  1.0f, &wx, &wy);
            a += analytic(wx, wy, c, which) / 16.0;
          }
        expect[y][x][c] = a;
        sum_r += px(img, x, y, c);
        sum_a += a;
      }
  /* One delta light, so Cycles has no noise here beyond where in the pixel each
   * sample lands (the box filter) while the expectation averages 16 points:
   * 2% per pixel, plus 1% of the mean where the spot's t^2 ramp starts. */
  double mean = sum_a / (W * H * 3), worst = 0;
  int bad = 0;
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++)
      for (int c = 0; c < 3; c++) {
        double v = px(img, x, y, c), a = expect[y][x][c];
        double excess = fabs(v - a) / (0.02 * a + 0.01 * mean);
        if (excess > worst) worst = excess;
        bad += excess > 1.0;
      }
  printf("light %d: worst per-pixel error %.2f of tolerance, image mean %.6f vs analytic %.6f\n", which,
         worst, sum_r / (W * H * 3), mean);
  CHECK_EQ_INT(bad, 0);
  CHECK_NEAR(sum_r / sum_a, 1.0, 0.002);
}

int main(void) {
  if (!fixture_find_tool("blender", g_blender, sizeof g_blender)) return TEST_SKIP("blender is not installed");
  if (iris_test_tmpdir(g_dir, sizeof g_dir, "export-blender") != 0) return TEST_SKIP("no temporary folder");
  iris_error err;
  char script[1200], exr[1200], sidecar[1400];

  /* 1. cells: sidecar mesh file and an in-memory texture written next to the script. */
  iris_scene *s = cells_scene();
  iris_export_params p = iris_export_params_default();
  p.width = W, p.height = H, p.max_depth = 8;
  snprintf(script, sizeof script, "%s/cells.py", g_dir);
  iris_error_clear(&err);
  CHECK_OK(iris_export_blender(s, script, &p, &err), &err);
  iris_blender_sidecar_path(script, sidecar, sizeof sidecar);
  CHECK(iris_path_exists(sidecar));
  snprintf(exr, sizeof exr, "%s/cells.textures/0.png", g_dir);
  CHECK(iris_path_exists(exr));
  snprintf(exr, sizeof exr, "%s/cells.exr", g_dir);
  iris_image img = {0};
  if (render(script, exr, 16) && load(exr, &img)) check_cells(&img);
  iris_image_destroy(&img);
  iris_scene_destroy(s);

  /* 1b. glTF features: second uv set, texture transform, MASK and BLEND alpha. */
  s = features_scene();
  snprintf(script, sizeof script, "%s/features.py", g_dir);
  iris_error_clear(&err);
  CHECK_OK(iris_export_blender(s, script, &p, &err), &err);
  snprintf(exr, sizeof exr, "%s/features.exr", g_dir);
  memset(&img, 0, sizeof img);
  if (render(script, exr, 32) && load(exr, &img)) check_features(&img);
  iris_image_destroy(&img);
  iris_scene_destroy(s);

  /* 2. one scene per delta light (Cycles picks one light per sample, so a
   * single light keeps the render noise-free); the point-light scene has its
   * mesh data embedded in the script (no sidecar written). */
  for (int which = 0; which < 3; which++) {
    s = lights_scene(which);
    p.embed_meshes = which == 0;
    snprintf(script, sizeof script, "%s/light%d.py", g_dir, which);
    iris_error_clear(&err);
    CHECK_OK(iris_export_blender(s, script, &p, &err), &err);
    iris_blender_sidecar_path(script, sidecar, sizeof sidecar);
    CHECK(iris_path_exists(sidecar) == !p.embed_meshes);
    snprintf(exr, sizeof exr, "%s/light%d.exr", g_dir, which);
    memset(&img, 0, sizeof img);
    if (render(script, exr, 16) && load(exr, &img)) check_lights(&img, which);
    iris_image_destroy(&img);
    iris_scene_destroy(s);
  }

  if (iris_check_failures == 0)
    iris_test_rmtree(g_dir);
  else
    printf("files kept in %s\n", g_dir);
  return TEST_SUMMARY();
}
