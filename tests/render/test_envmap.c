/* render.envmap: environment maps (renderer/envmap.h) and their use as a light.
 *  - direction -> (s, t) -> direction round trip, with rotation;
 *  - the documented texel of six axis directions (docs/format.md);
 *  - chi-square of iris_envmap_sample against iris_envmap_pdf on a map with a
 *    sharp bright block, a smooth gradient and black rows; the pdf integrates to 1;
 *  - chi-square of light sampling (iris_lights_sample) of a scene lit by the map
 *    against iris_lights_pdf_environment; photon emission's mean power equals
 *    the map's power through the scene's disk (pi r^2 x 4 pi x mean radiance);
 *  - white furnace: a diffuse sphere of albedo rho inside a uniform map of
 *    radiance 1 is rho everywhere (convex: no interreflection), for every
 *    method; a constant sky (environment.radiance) gives the same image
 *    within statistical error;
 *  - same seed, 1 or 2 threads: bit-identical images under a map, every method;
 *  - maps of sizes the tables do not divide (1 x 1 to 50 x 25): sampling never
 *    fails, its pdf is the lookup's, the pdf integrates to 1. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "render_run.h"
#include "chi2.h"
#include "core/fileio.h"
#include "core/image.h"
#include "exr_map.h"
#include "renderer/envmap.h"
#include "renderer/guiding/guiding.h"
#include "renderer/lights.h"
#include "renderer/render.h"
#include "scenes/builtin.h"

static char g_dir[1024];

/* The patterned map: a gradient along x with a 3 x 2 sun of 200. */
static void write_map(const char *path, int w, int h) { iris_test_write_sun_map(path, w, h, 0.0f, 3, 200.0f); }

static void white_texel(void *ctx, int x, int y, int w, int h, float rgb[3]) {
  (void)ctx, (void)x, (void)y, (void)w, (void)h;
  rgb[0] = rgb[1] = rgb[2] = 1.0f;
}

static bool env_sample(void *ctx, const double u[3], double dir[3]) {
  iris_vec3 d;
  float pdf;
  if (!iris_envmap_sample((const iris_envmap *)ctx, (float)u[0], (float)u[1], &d, &pdf, NULL)) return false;
  dir[0] = d.x, dir[1] = d.y, dir[2] = d.z;
  return true;
}
static double env_pdf(void *ctx, const double dir[3]) {
  return iris_envmap_pdf((const iris_envmap *)ctx, iris_v3((float)dir[0], (float)dir[1], (float)dir[2]));
}

typedef struct lctx {
  const iris_lights *lights;
  iris_vec3 ref;
} lctx;
static bool light_sample(void *vc, const double u[3], double dir[3]) {
  lctx *c = (lctx *)vc;
  iris_light_sample s;
  if (!iris_lights_sample(c->lights, c->ref, iris_v3(0, 0, 0), (float)u[0], (float)u[1], (float)u[2], &s)) return false;
  dir[0] = s.wi.x, dir[1] = s.wi.y, dir[2] = s.wi.z;
  return true;
}
static double light_pdf(void *vc, const double dir[3]) {
  lctx *c = (lctx *)vc;
  return iris_lights_pdf_environment(c->lights, c->ref, iris_v3(0, 0, 0),
                                     iris_v3((float)dir[0], (float)dir[1], (float)dir[2]));
}

static void test_mapping(const char *path) {
  iris_environment_map m = {(char *)path, 1.0f, 37.0f};
  iris_envmap env;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_envmap_load(&m, &env, &err), &err);
  uint64_t st = 5;
  double worst = 0.0;
  for (int i = 0; i < 10000; i++) {
    iris_vec3 d = iris_sample_uniform_sphere((float)chi2_uniform(&st), (float)chi2_uniform(&st));
    float s, t;
    iris_envmap_dir_to_st(&env, d, &s, &t);
    CHECK(s >= 0.0f && s < 1.0f && t >= 0.0f && t <= 1.0f);
    iris_vec3 back = iris_envmap_st_to_dir(&env, s, t);
    worst = fmax(worst, (double)iris_length(iris_sub(back, d)));
  }
  CHECK(worst < 1e-4);
  iris_envmap_destroy(&env);
  /* Without rotation: +X is the map's centre column, +Z three quarters across,
   * -Z a quarter, +Y the top row, -Y the bottom (Blender's glTF import puts
   * glTF (x, y, z) at (x, -z, y); measured in Blender 3.4.1: docs/format.md). */
  m.rotation = 0.0f;
  CHECK_OK(iris_envmap_load(&m, &env, &err), &err);
  float s, t;
  iris_envmap_dir_to_st(&env, iris_v3(1, 0, 0), &s, &t);
  CHECK_NEAR(s, 0.5, 1e-6);
  CHECK_NEAR(t, 0.5, 1e-6);
  iris_envmap_dir_to_st(&env, iris_v3(0, 0, 1), &s, &t);
  CHECK_NEAR(s, 0.75, 1e-6);
  iris_envmap_dir_to_st(&env, iris_v3(0, 0, -1), &s, &t);
  CHECK_NEAR(s, 0.25, 1e-6);
  iris_envmap_dir_to_st(&env, iris_v3(0, 1, 0), &s, &t);
  CHECK_NEAR(t, 0.0, 1e-6);
  iris_envmap_dir_to_st(&env, iris_v3(0, -1, 0), &s, &t);
  CHECK_NEAR(t, 1.0, 1e-6);
  /* a rotation of 90 degrees brings +Z's column to +X's: d' = R_y(90) d */
  iris_envmap_destroy(&env);
  m.rotation = 90.0f;
  CHECK_OK(iris_envmap_load(&m, &env, &err), &err);
  iris_envmap_dir_to_st(&env, iris_v3(0, 0, 1), &s, &t);
  CHECK_NEAR(s, 0.5, 1e-5);
  iris_envmap_destroy(&env);
}

static void test_sampling(const char *path) {
  iris_environment_map m = {(char *)path, 2.0f, 37.0f};
  iris_envmap env;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_envmap_load(&m, &env, &err), &err);
  chi2_domain dom = {CHI2_SPHERE, 32, 64, 77}; /* the quadrature of a discontinuous pdf dominates the cost */
  chi2_result r = chi2_run(&dom, env_sample, env_pdf, &env, 400000, 0.01, 3);
  iris_check_record(r.passed, __FILE__, __LINE__, "envmap sampling: %s", r.message);
  printf("envmap: p = %.3g, pdf integral %.5f, lost %zu\n", r.p_value, r.pdf_integral, r.lost);
  CHECK_NEAR(r.pdf_integral, 1.0, 2e-3);
  CHECK(r.lost == 0);
  /* the radiance is the map times the strength, interpolated bilinearly between
   * texel centres: s = 0.9 on 32 columns is 28.3 texels from the first centre
   * (0.7 of column 28, 0.3 of column 29); the map is constant down a column
   * away from the black polar rows and the sun */
  iris_vec3 L = iris_envmap_radiance(&env, iris_envmap_st_to_dir(&env, 0.9f, 0.5f));
  float expect = 2.0f * (0.05f + 0.5f * (0.7f * 28.0f + 0.3f * 29.0f) / 32.0f);
  CHECK_NEAR(L.x, expect, 1e-4);
  /* What a sample hands back is what the lookups say for its direction (to
   * float rounding of the (s, t) round trip): the radiance at the sampled
   * (s, t), the pdf, and iris_envmap_eval's pair; the prefetch changes nothing. */
  uint64_t rs = 5;
  int mismatches = 0, samples = 0;
  for (int i = 0; i < 20000; i++) {
    float u0 = (float)chi2_uniform(&rs), u1 = (float)chi2_uniform(&rs);
    iris_vec3 d, Ls, Ld;
    float pdf, pdf_e, s_, t_;
    iris_envmap_prefetch(&env, u0, u1, 0);
    iris_envmap_prefetch(&env, u0, u1, 1);
    if (!iris_envmap_sample(&env, u0, u1, &d, &pdf, &Ls)) continue;
    iris_vec3 d2;
    float pdf2;
    CHECK(iris_envmap_sample_st(&env, u0, u1, &d2, &pdf2, &s_, &t_));
    CHECK(d2.x == d.x && d2.y == d.y && d2.z == d.z && pdf2 == pdf);
    Ld = iris_envmap_eval(&env, d, &pdf_e, NULL);
    samples++;
    bool same_l = fabsf(Ls.x - Ld.x) <= 1e-3f * fmaxf(Ld.x, 1e-3f) && fabsf(Ls.y - Ld.y) <= 1e-3f * fmaxf(Ld.y, 1e-3f);
    bool same_p = fabsf(pdf - pdf_e) <= 1e-4f * pdf || fabsf(pdf - iris_envmap_pdf(&env, d)) <= 1e-4f * pdf;
    mismatches += !(same_l && same_p && pdf_e == iris_envmap_pdf(&env, d));
  }
  /* a direction within rounding of a cell edge may look up the neighbour cell */
  printf("envmap sample vs lookups: %d of %d differ\n", mismatches, samples);
  CHECK(samples > 19000 && mismatches <= samples / 1000);

  /* As a light of a scene (a small quad that does not block the reference point). */
  iris_scene *s = iris_scene_create();
  iris_material mat = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  int32_t mi = iris_scene_add_material(s, &mat);
  iris_builtin_add_quad(s, iris_v3(-1, -1, -1), iris_v3(2, 0, 0), iris_v3(0, 0, 2), 1, mi, "floor");
  CHECK(iris_scene_set_environment_map(s, path, 2.0f, 37.0f));
  iris_accel *accel = NULL;
  iris_textures tex;
  iris_lights lights;
  CHECK_OK(iris_accel_build(s, &accel, &err), &err);
  CHECK_OK(iris_textures_load(s, &tex, &err), &err);
  CHECK_OK(iris_lights_build(s, accel, &tex, &lights, &err), &err);
  CHECK(lights.envmap != NULL);
  /* A lazily drawn map sample is the eager one once its radiance is looked up. */
  for (int i = 0; i < 64; i++) {
    iris_light_choice ch;
    iris_lights_choose(&lights, iris_v3(0.1f, 0.3f, 0.2f), iris_v3(0, 0, 0), 0.5f, &ch);
    iris_light_sample a, b;
    float u0 = (i + 0.5f) / 64.0f, u1 = (float)((i * 37) % 64 + 0.5f) / 64.0f;
    bool oa = iris_lights_sample_choice(&lights, iris_v3(0.1f, 0.3f, 0.2f), &ch, u0, u1, &a);
    bool ob = iris_lights_sample_choice_lazy(&lights, iris_v3(0.1f, 0.3f, 0.2f), &ch, u0, u1, &b);
    CHECK(oa == ob);
    if (!oa) continue;
    CHECK(b.L_pending);
    iris_lights_sample_radiance(&lights, &b);
    CHECK(!b.L_pending && a.L.x == b.L.x && a.L.y == b.L.y && a.L.z == b.L.z && a.pdf == b.pdf);
  }
  lctx c = {&lights, iris_v3(0.1f, 0.3f, 0.2f)};
  r = chi2_run(&dom, light_sample, light_pdf, &c, 400000, 0.01, 3);
  iris_check_record(r.passed, __FILE__, __LINE__, "environment light sampling: %s", r.message);
  printf("lights: p = %.3g, pdf integral %.5f\n", r.p_value, r.pdf_integral);
  CHECK_NEAR(r.pdf_integral, 1.0, 2e-3);
  /* Photon power: mean = pi r^2 * integral of L over the sphere = pi r^2 4 pi mean. */
  uint64_t st = 11;
  double sum[3] = {0, 0, 0};
  const int n = 400000;
  for (int i = 0; i < n; i++) {
    float u[5];
    for (int k = 0; k < 5; k++) u[k] = (float)chi2_uniform(&st);
    iris_photon_emission e;
    if (!iris_lights_sample_emission(&lights, u[0], u[1], u[2], u[3], u[4], &e)) continue;
    sum[0] += e.power.x, sum[1] += e.power.y, sum[2] += e.power.z;
  }
  double area = IRIS_PI * (double)lights.radius * (double)lights.radius;
  for (int k = 0; k < 3; k++) {
    double expect_p = area * 4.0 * IRIS_PI * env.mean_rgb[k];
    printf("photon power[%d] %.5g expected %.5g\n", k, sum[k] / n, expect_p);
    CHECK_NEAR(sum[k] / n, expect_p, 0.01 * expect_p);
  }
  iris_lights_destroy(&lights);
  iris_textures_destroy(&tex);
  iris_accel_destroy(accel);
  iris_scene_destroy(s);
  iris_envmap_destroy(&env);
}

/* Mean and standard error of the mean of the image's first channel. */
static void image_mean(const iris_render_result *res, double *mean, double *se) {
  iris_image img;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_film_to_image(&res->film, true, &img, &err), &err);
  int vr = iris_image_channel(&img, "var.R");
  double m = 0.0, v = 0.0;
  size_t n = (size_t)img.width * (size_t)img.height;
  for (size_t i = 0; i < n; i++) {
    m += img.data[i * (size_t)img.channel_count];
    v += vr >= 0 ? img.data[i * (size_t)img.channel_count + (size_t)vr] : 0.0;
  }
  *mean = m / (double)n;
  *se = sqrt(v) / (double)n;
  iris_image_destroy(&img);
}

static void test_furnace(const char *uniform) {
  const float rho = 0.5f;
  double means[2][IRIS_METHOD_COUNT], ses[2][IRIS_METHOD_COUNT];
  for (int world = 0; world < 2; world++) {
    iris_scene *s = NULL;
    iris_error err;
    iris_error_clear(&err);
    CHECK_OK(iris_builtin_create("furnace-diffuse", &s, &err), &err);
    for (int k = 0; k < 3; k++) s->materials[0].color[k] = rho;
    if (world == 1) {
      CHECK(iris_scene_set_environment_map(s, uniform, 1.0f, 20.0f));
    } else {
      const float one[3] = {1, 1, 1};
      iris_scene_set_environment_color(s, one);
    }
    for (int m = 0; m < IRIS_METHOD_COUNT; m++) {
      iris_render_params p = iris_test_params(16, 16, 32, (iris_method)m, 0);
      p.threads = 2;
      iris_guiding_params gp = iris_guiding_params_default();
      gp.photons = 20000;
      iris_test_attach_guide(&p, &gp);
      iris_render_result res;
      CHECK(iris_test_render(s, &p, &res));
      /* pixel by pixel: everything between rho (sphere) and 1 (sky; silhouette
       * pixels mix both), the centre rho and the corners 1 within 5 sigma */
      iris_image img;
      CHECK_OK(iris_film_to_image(&res.film, true, &img, &err), &err);
      int vr = iris_image_channel(&img, "var.R");
      int bad = 0;
      for (int y = 0; y < img.height; y++)
        for (int x = 0; x < img.width; x++) {
          size_t i = ((size_t)y * (size_t)img.width + (size_t)x) * (size_t)img.channel_count;
          float v = img.data[i], tol = 5.0f * sqrtf(img.data[i + (size_t)vr]) + 1e-4f;
          bool centre = abs(2 * x + 1 - img.width) <= 4 && abs(2 * y + 1 - img.height) <= 4;
          bool corner = (x == 0 || x == img.width - 1) && (y == 0 || y == img.height - 1);
          if (v < rho - tol || v > 1.0f + tol || (centre && fabsf(v - rho) > tol) ||
              (corner && fabsf(v - 1.0f) > tol))
            bad++;
        }
      iris_check_record(bad == 0, __FILE__, __LINE__, "%s %s: %d pixels off", world ? "map" : "colour",
                        iris_method_name(p.method), bad);
      iris_image_destroy(&img);
      image_mean(&res, &means[world][m], &ses[world][m]);
      iris_render_result_destroy(&res);
    }
    iris_scene_destroy(s);
  }
  for (int m = 0; m < IRIS_METHOD_COUNT; m++) {
    double d = means[1][m] - means[0][m], se = sqrt(ses[0][m] * ses[0][m] + ses[1][m] * ses[1][m]);
    printf("furnace %-10s colour %.5f +- %.5f  map %.5f +- %.5f\n", iris_method_name((iris_method)m),
           means[0][m], ses[0][m], means[1][m], ses[1][m]);
    iris_check_record(fabs(d) <= 4.0 * se + 1e-6, __FILE__, __LINE__,
                      "%s: constant colour %.5f and constant map %.5f differ by more than 4 sigma",
                      iris_method_name((iris_method)m), means[0][m], means[1][m]);
  }
}

/* Same seed, 1 or 2 threads: bit-identical sums for every method under a map. */
static void test_determinism(const char *map) {
  iris_scene *s = NULL;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_builtin_create("furnace-glossy", &s, &err), &err);
  CHECK(iris_scene_set_environment_map(s, map, 1.5f, 10.0f));
  for (int m = 0; m < IRIS_METHOD_COUNT; m++) {
    iris_render_result r[2];
    iris_guiding_params gp = iris_guiding_params_default();
    gp.photons = 20000;
    gp.force = true;
    for (int t = 0; t < 2; t++) {
      iris_render_params p = iris_test_params(12, 12, 8, (iris_method)m, 42);
      p.threads = t + 1;
      iris_test_attach_guide(&p, &gp);
      CHECK(iris_test_render(s, &p, &r[t]));
    }
    size_t n = 3 * (size_t)r[0].film.width * (size_t)r[0].film.height;
    iris_check_record(memcmp(r[0].film.sum, r[1].film.sum, n * sizeof(double)) == 0 &&
                          memcmp(r[0].film.sum2, r[1].film.sum2, n * sizeof(double)) == 0,
                      __FILE__, __LINE__, "%s: 1 and 2 threads differ under a map",
                      iris_method_name((iris_method)m));
    iris_render_result_destroy(&r[0]);
    iris_render_result_destroy(&r[1]);
  }
  iris_scene_destroy(s);
}

/* Sizes the block and guide tables do not divide (1 x 1 up to 50 x 25, one
 * black everywhere): every stratified sample succeeds, its pdf is the
 * lookup's, and the pdf integrates to 1 over the sphere (Monte Carlo with
 * uniform directions). */
static void test_odd_sizes(void) {
  static const int S[][2] = {{1, 1}, {2, 1}, {3, 2}, {17, 9}, {33, 16}, {50, 25}};
  for (size_t k = 0; k < sizeof S / sizeof S[0]; k++) {
    char path[1200];
    snprintf(path, sizeof path, "%s/odd%zu.exr", g_dir, k);
    write_map(path, S[k][0], S[k][1]);
    iris_environment_map m = {path, 1.0f, 0.0f};
    iris_envmap env;
    iris_error err;
    iris_error_clear(&err);
    iris_status lst = iris_envmap_load(&m, &env, &err);
    CHECK_OK(lst, &err);
    if (lst != IRIS_OK) continue;
    int failed = 0, differ = 0;
    for (int i = 0; i < 64; i++)
      for (int j = 0; j < 64; j++) {
        iris_vec3 d, L;
        float pdf;
        if (!iris_envmap_sample(&env, (i + 0.5f) / 64.0f, (j + 0.5f) / 64.0f, &d, &pdf, &L)) {
          failed++;
          continue;
        }
        differ += !(fabsf(iris_envmap_pdf(&env, d) - pdf) <= 1e-3f * pdf);
      }
    uint64_t st = 99 + k;
    double sum = 0.0, sum2 = 0.0;
    const int n = 400000;
    for (int i = 0; i < n; i++) {
      double u0 = chi2_uniform(&st), u1 = chi2_uniform(&st);
      float z = (float)(1.0 - 2.0 * u0), r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = (float)(2.0 * IRIS_PI * u1);
      double v = 4.0 * IRIS_PI * iris_envmap_pdf(&env, iris_v3(r * cosf(phi), z, r * sinf(phi)));
      sum += v;
      sum2 += v * v;
    }
    double integral = sum / n, se = sqrt(fmax(0.0, sum2 / n - integral * integral) / n);
    printf("envmap %dx%d: %d failed, %d pdfs differ, pdf integral %.4f +- %.4f\n", S[k][0], S[k][1], failed,
           differ, integral, se);
    CHECK_EQ_INT(failed, 0);
    CHECK(differ <= 8); /* directions within rounding of a cell edge */
    CHECK_NEAR(integral, 1.0, 4.0 * se + 1e-3);
    iris_envmap_destroy(&env);
  }
}

int main(void) {
  if (iris_test_tmpdir(g_dir, sizeof g_dir, "envmap") != 0) return TEST_SKIP("no temporary folder");
  char patterned[1200], uniform[1200];
  snprintf(patterned, sizeof patterned, "%s/pattern.exr", g_dir);
  snprintf(uniform, sizeof uniform, "%s/uniform.exr", g_dir);
  write_map(patterned, 32, 16); /* small: the adaptive quadrature of its edges is the cost */
  iris_test_write_exr_map(uniform, 32, 16, white_texel, NULL);
  test_mapping(patterned);
  test_sampling(patterned);
  test_furnace(uniform);
  test_determinism(patterned);
  test_odd_sizes();
  iris_test_rmtree(g_dir);
  return TEST_SUMMARY();
}
