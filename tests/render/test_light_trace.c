/* Light tracing of glossy caustics (renderer/light_trace.h): mis with it and
 * mis without it estimate the same image, per image and per 8x8 block
 * (Bonferroni, family-wise level 0.1%, as render.env_unbiased), on
 * env-objects (the sun's highlight in the glossy sphere reflected onto the
 * ground: an environment light through the camera's escapes),
 * stress-glossy-room (lamps in glossy walls and balls: emitter triangles hit
 * by the camera's bounce at the reflector) and stress-firefly (a 3 mm lamp
 * in a ball of roughness 0.1); both halves of the camera's MIS weights and the light
 * paths' must count the three strategies, or the caustics are counted twice
 * or not at all. Also: the light paths' sums are the same for 1 and 2
 * threads, a window of the frame gets the whole render's sums in it, and
 * scenes with nothing to start from (the Cornell box), whose reflectors send
 * their light out of the frame (veach-mis: the pilot) or another method get
 * no light tracing. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "film_stats.h"
#include "render_run.h"
#include "core/fileio.h"
#include "core/image.h"
#include "renderer/render.h"
#include "scenes/builtin.h"
#include "scenes/sky.h"

static bool render(const iris_scene *s, bool light_trace, int w, int h, int spp, uint64_t seed, int threads,
                   iris_pixel_bounds bounds, iris_render_result *r) {
  iris_render_params p = iris_test_params(w, h, spp, IRIS_METHOD_MIS, seed);
  p.light_trace = light_trace ? IRIS_LIGHT_TRACE_AUTO : IRIS_LIGHT_TRACE_OFF;
  p.threads = threads;
  p.bounds = bounds;
  return iris_test_render(s, &p, r);
}

static const iris_pixel_bounds WHOLE = {0, 0, 0, 0};

static char g_big_sun[1200]; /* the map of write_big_sun, for "spheres-glass-big-sun" */

/* A built-in scene, or "spheres-glass": env-spheres with its matte sphere
 * clear glass (the sun focused through it onto the ground: the second kind). */
static iris_scene *make_scene(const char *name) {
  iris_scene *s = NULL;
  iris_error err;
  iris_error_clear(&err);
  const bool glass = !strncmp(name, "spheres-glass", 13);
  if (iris_builtin_create(glass ? "env-spheres" : name, &s, &err) != IRIS_OK) return NULL;
  if (!strcmp(name, "spheres-glass-big-sun") && !iris_scene_set_environment_map(s, g_big_sun, 1.0f, 0.0f)) {
    iris_scene_destroy(s);
    return NULL;
  }
  for (size_t i = 0; glass && i < s->material_count; i++)
    if (!strcmp(s->materials[i].name, "matte")) {
      s->materials[i].type = IRIS_MATERIAL_GLASS;
      s->materials[i].roughness = 0.0f;
      s->materials[i].ior = 1.5f;
      for (int k = 0; k < 3; k++) s->materials[i].color[k] = 1.0f;
    }
  return s;
}

/* A 256 x 128 map of a dim sky (0.2) and a sun of 8 degrees' radius (20),
 * 45 degrees up: large enough that the camera's bounces through the glass
 * find it often, so that the light paths' share of the sun through glass can
 * be told from the camera's (written as EXR at `path`). */
static bool write_big_sun(const char *path) {
  enum { MW = 256, MH = 128 };
  static const char *const names[3] = {"R", "G", "B"};
  iris_image img;
  iris_error err;
  iris_error_clear(&err);
  if (iris_image_create(&img, MW, MH, 3, names, &err) != IRIS_OK) return false;
  const double th0 = 0.25 * IRIS_PI;
  const double c0[3] = {sin(th0), cos(th0), 0.0};
  for (int y = 0; y < MH; y++)
    for (int x = 0; x < MW; x++) {
      const double th = (y + 0.5) / MH * IRIS_PI, ph = ((x + 0.5) / MW - 0.5) * 2.0 * IRIS_PI;
      const double d[3] = {sin(th) * cos(ph), cos(th), sin(th) * sin(ph)};
      const bool sun = d[0] * c0[0] + d[1] * c0[1] + d[2] * c0[2] > cos(8.0 * IRIS_PI / 180.0);
      for (int k = 0; k < 3; k++) img.data[3 * ((size_t)y * MW + (size_t)x) + (size_t)k] = sun ? 20.0f : 0.2f;
    }
  bool ok = iris_exr_write(path, &img, NULL, 0, &err) == IRIS_OK;
  iris_image_destroy(&img);
  return ok;
}

/* mis with light tracing against mis without, z-tested per image and block */
static void compare(const char *scene, int spp, double z_max) {
  enum { W = 48, H = 32 };
  iris_scene *s = make_scene(scene);
  if (!CHECK(s != NULL)) return;
  iris_render_result a, b;
  bool ok_a = CHECK(render(s, true, W, H, spp, 41, 2, WHOLE, &a));
  bool ok_b = CHECK(render(s, false, W, H, spp, 42, 2, WHOLE, &b));
  if (ok_a && ok_b) {
    CHECK(a.film.light_sum != NULL && a.film.light_paths > 0.0);
    CHECK(b.film.light_sum == NULL && b.film.light_paths == 0.0);
    char what[160];
    snprintf(what, sizeof what, "%s: mis with light tracing vs without", scene);
    double worst = iris_test_z_compare(&a.film, &b.film, W / 8, H / 8, z_max, z_max, what);
    double ma[3], va[3], mb[3], vb[3];
    region(&a.film, 0, 0, W, H, ma, va);
    region(&b.film, 0, 0, W, H, mb, vb);
    /* what the light paths carry, after their MIS weights: a share of the image */
    double lt = 0.0;
    for (size_t i = 0; i < (size_t)W * H; i++) lt += a.film.light_sum[3 * i + 1];
    lt /= a.film.light_paths * (double)(W * H);
    printf("%s: %.0f light paths, %.5f (light paths %.5f) vs %.5f, variance of the mean %.3g vs %.3g; worst |z| = %.2f\n",
           scene, a.film.light_paths, ma[1], lt, mb[1], va[1], vb[1], worst);
    CHECK(lt > 0.0);
    CHECK_EQ_INT(a.stats.nan_count, 0);
  }
  if (ok_a) iris_render_result_destroy(&a);
  if (ok_b) iris_render_result_destroy(&b);
  iris_scene_destroy(s);
}

static bool same_light(const iris_film *a, const iris_film *b) {
  const size_t n = 3 * (size_t)a->width * (size_t)a->height;
  return a->light_sum && b->light_sum && a->light_paths == b->light_paths &&
         memcmp(a->light_sum, b->light_sum, n * sizeof(double)) == 0 &&
         memcmp(a->light_sum2, b->light_sum2, n * sizeof(double)) == 0;
}

static void determinism(void) {
  iris_scene *s = NULL;
  iris_error err;
  iris_error_clear(&err);
  if (!CHECK(iris_builtin_create("env-objects", &s, &err) == IRIS_OK)) return;
  enum { W = 40, H = 24 };
  iris_render_result r1, r2, rw;
  const iris_pixel_bounds win = {10, 5, 33, 20};
  bool ok1 = CHECK(render(s, true, W, H, 8, 7, 1, WHOLE, &r1));
  bool ok2 = CHECK(render(s, true, W, H, 8, 7, 2, WHOLE, &r2));
  bool okw = CHECK(render(s, true, W, H, 8, 7, 2, win, &rw));
  if (ok1 && ok2) CHECK(same_light(&r1.film, &r2.film));
  if (ok2 && okw && CHECK(rw.film.light_sum != NULL) && CHECK(rw.film.light_paths == r2.film.light_paths)) {
    bool same = true;
    for (int y = win.y0; y < win.y1; y++)
      for (int x = win.x0; x < win.x1; x++) {
        const size_t i = (size_t)y * W + (size_t)x, j = (size_t)(y - win.y0) * (size_t)(win.x1 - win.x0) + (size_t)(x - win.x0);
        same = same && memcmp(&r2.film.light_sum[3 * i], &rw.film.light_sum[3 * j], 3 * sizeof(double)) == 0;
      }
    CHECK(same);
  }
  if (ok1) iris_render_result_destroy(&r1);
  if (ok2) iris_render_result_destroy(&r2);
  if (okw) iris_render_result_destroy(&rw);
  /* nee (no MIS to share the caustics with) traces no light paths */
  iris_render_params p = iris_test_params(W, H, 4, IRIS_METHOD_NEE, 7);
  iris_render_result rn;
  if (CHECK(iris_test_render(s, &p, &rn))) {
    CHECK(rn.film.light_sum == NULL);
    iris_render_result_destroy(&rn);
  }
  iris_scene_destroy(s);
  /* the plates reflect the lamps out of the frame: the pilot says no */
  if (CHECK(iris_builtin_create("veach-mis", &s, &err) == IRIS_OK)) {
    iris_render_result rv;
    if (CHECK(render(s, true, 48, 32, 2, 1, 2, WHOLE, &rv))) {
      CHECK(rv.film.light_sum == NULL);
      iris_render_result_destroy(&rv);
    }
    iris_scene_destroy(s);
  }
  /* nothing to start from */
  if (CHECK(iris_builtin_create("cornell-box", &s, &err) == IRIS_OK)) {
    iris_render_result rc;
    if (CHECK(render(s, true, 16, 16, 4, 1, 2, WHOLE, &rc))) {
      CHECK(rc.film.light_sum == NULL && rc.light_trace_rays == 0);
      iris_render_result_destroy(&rc);
    }
    iris_scene_destroy(s);
  }
}

int main(void) {
  if (!iris_path_exists(iris_sky_map_path())) return TEST_SKIP("the shared environment map is missing");
  /* 5 scenes, 3 channels x (image + 24 blocks) */
  const int n_tests = 5 * 3 * (1 + 6 * 4);
  const double z_max = z_for_alpha(1e-3 / n_tests);
  printf("%d tests, |z| < %.2f\n", n_tests, z_max);
  compare("env-objects", 1024, z_max);
  compare("stress-glossy-room", 512, z_max);
  compare("stress-firefly", 1024, z_max);
  compare("spheres-glass", 2048, z_max);
  char dir[1024];
  if (CHECK(iris_test_tmpdir(dir, sizeof dir, "light-trace") == 0)) {
    snprintf(g_big_sun, sizeof g_big_sun, "%s/big-sun.exr", dir);
    if (CHECK(write_big_sun(g_big_sun))) compare("spheres-glass-big-sun", 1024, z_max);
    iris_test_rmtree(dir);
  }
  determinism();
  return iris_check_summary("render.light_trace");
}
