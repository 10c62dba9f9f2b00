/* Normal maps that keep their energy (docs/rendering.md, "Normal maps"):
 * - furnace at the shading point: with a tilted (normal-mapped) shading
 *   normal, the folded BSDF reflects what the BSDF reflects about that normal
 *   over its whole hemisphere (white Lambert: 1), estimated through its
 *   sampling routine and through its value; without the fold (iris before
 *   the fold, and what the fold must fix) the directions below the geometric
 *   surface are lost, and the test prints how much;
 * - chi-square of the folded sampling against its pdf with tilted normals;
 * - renders: a white Lambert quad with a strong random normal map under a
 *   white sky reflects 1 with every method; a white rough-metal quad with the
 *   same map gives the same image mean with every method. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "chi2.h"
#include "core/image.h"
#include "film_stats.h"
#include "render_run.h"
#include "renderer/guiding/guiding.h"
#include "renderer/integrator.h"
#include "renderer/normal_map.h"
#include "renderer/render.h"

/* ---- the materials ---------------------------------------------------- */

enum { MAT_LAMBERT, MAT_METAL, MAT_FABRIC, MAT_COATED, MAT_COUNT };
static const char *const MAT_NAMES[MAT_COUNT] = {"white lambert", "white rough metal", "sheen fabric",
                                                 "coated plastic"};

static iris_material material(int which) {
  iris_material m;
  switch (which) {
  case MAT_LAMBERT:
    m = iris_material_default(IRIS_MATERIAL_DIFFUSE);
    m.color[0] = m.color[1] = m.color[2] = 1.0f;
    return m;
  case MAT_METAL:
    m = iris_material_default(IRIS_MATERIAL_GLTF);
    m.color[0] = m.color[1] = m.color[2] = 1.0f;
    m.metallic = 1.0f;
    m.roughness = 0.5f;
    return m;
  case MAT_FABRIC: /* ToyCar's fabric: dark base, red sheen */
    m = iris_material_default(IRIS_MATERIAL_GLTF);
    m.color[0] = m.color[1] = m.color[2] = 0.15f;
    m.metallic = 0.0f;
    m.roughness = 1.0f;
    m.sheen_color[0] = 1.0f;
    m.sheen_roughness = 0.5f;
    return m;
  default:
    m = iris_material_default(IRIS_MATERIAL_GLTF);
    m.color[0] = 0.8f, m.color[1] = 0.6f, m.color[2] = 0.4f;
    m.metallic = 0.0f;
    m.roughness = 0.3f;
    m.clearcoat = 1.0f;
    m.clearcoat_roughness = 0.1f;
    return m;
  }
}

/* ---- shading-point furnace ------------------------------------------------ */

typedef struct point {
  iris_scene *scene;
  iris_integrator it;
  iris_shading_point sp;
} point;

/* A shading point with geometric normal +z, the normal `n` bent as a normal
 * map's is (iris_normal_make_valid), seen from wo; fold as given. */
static void point_make(point *pt, int mat, iris_vec3 n, iris_vec3 wo, bool fold) {
  pt->scene = iris_scene_create();
  iris_material m = material(mat);
  iris_scene_add_material(pt->scene, &m);
  pt->it = iris_integrator_default(pt->scene, NULL, NULL, NULL);
  iris_interaction si;
  memset(&si, 0, sizeof si);
  si.ng = iris_v3(0, 0, 1);
  si.ns = iris_normal_make_valid(si.ng, wo, n);
  si.color = iris_v3(1, 1, 1);
  si.material = 0;
  si.front = true;
  iris_integrator_shade(&pt->it, &si, wo, 0, &pt->sp);
  pt->sp.fold = fold;
}

static void point_free(point *pt) { iris_scene_destroy(pt->scene); }

typedef struct estimate {
  double mean, se;
} estimate;

static estimate finish(double s, double s2, int n) {
  estimate e;
  e.mean = s / n;
  e.se = sqrt(fmax(s2 / n - e.mean * e.mean, 0.0) / n);
  return e;
}

/* Red channel of f |cos| / pdf over the BSDF's own samples about the shading
 * normal, no direction refused: what the BSDF reflects over its hemisphere. */
static estimate albedo_about_n(const point *pt, int n, uint64_t seed) {
  double s = 0, s2 = 0;
  for (int i = 0; i < n; i++) {
    struct iris_bsdf_sample bs;
    float u0 = (float)chi2_uniform(&seed), u1 = (float)chi2_uniform(&seed), u2 = (float)chi2_uniform(&seed);
    double v = 0.0;
    if (iris_bsdf_sample(&pt->sp.bsdf, pt->sp.wo_local, u0, u1, u2, &bs) && bs.pdf > 0.0f)
      v = bs.f.x * fabs(bs.wi.z) / bs.pdf;
    s += v, s2 += v * v;
  }
  return finish(s, s2, n);
}

/* The same through the integrator's sampling (what every method uses), with
 * the integrator's rule for directions below the geometric surface. */
static estimate albedo_sampled(const point *pt, int n, uint64_t seed) {
  double s = 0, s2 = 0;
  for (int i = 0; i < n; i++) {
    iris_direction_sample ds;
    float u0 = (float)chi2_uniform(&seed), u1 = (float)chi2_uniform(&seed), u2 = (float)chi2_uniform(&seed);
    double v = 0.0;
    if (iris_integrator_sample_bsdf_u(&pt->sp, u0, u1, u2, &ds) && iris_dot(ds.wi, pt->sp.si.ng) > 0.0f)
      v = ds.f.x * fabs(iris_dot(ds.wi, pt->sp.si.ns)) / ds.pdf;
    s += v, s2 += v * v;
  }
  return finish(s, s2, n);
}

/* The same from the value and the density alone (what light sampling and the
 * MIS weights use): one-sample mixture of uniform directions over the upper
 * hemisphere of the geometric normal and the sampling routine, each weighted
 * by value x cosine / mixture density. */
static estimate albedo_evaluated(const point *pt, int n, uint64_t seed) {
  double s = 0, s2 = 0;
  const double p_uniform = 1.0 / (2.0 * IRIS_PI);
  for (int i = 0; i < n; i++) {
    float u0 = (float)chi2_uniform(&seed), u1 = (float)chi2_uniform(&seed), u2 = (float)chi2_uniform(&seed);
    iris_vec3 wi;
    if (i & 1) {
      float z = u0, phi = (float)(2.0 * IRIS_PI) * u1, r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
      wi = iris_v3(r * cosf(phi), r * sinf(phi), z);
    } else {
      iris_direction_sample ds;
      if (!iris_integrator_sample_bsdf_u(&pt->sp, u0, u1, u2, &ds)) {
        s2 += 0.0;
        continue;
      }
      wi = ds.wi;
    }
    double v = 0.0;
    if (wi.z > 0.0f) {
      double mix = 0.5 * p_uniform + 0.5 * iris_integrator_bsdf_pdf(&pt->sp, wi);
      v = iris_integrator_bsdf_eval(&pt->sp, wi).x * fabs(iris_dot(wi, pt->sp.si.ns)) / mix;
    }
    s += v, s2 += v * v;
  }
  return finish(s, s2, n);
}

static iris_vec3 dir(float theta_deg, float phi_deg) {
  float t = theta_deg * (float)IRIS_PI / 180.0f, p = phi_deg * (float)IRIS_PI / 180.0f;
  return iris_v3(sinf(t) * cosf(p), sinf(t) * sinf(p), cosf(t));
}

static void test_furnace(void) {
  const float tilts[] = {35.0f, 70.0f};
  const float views[][2] = {{30.0f, 0.0f}, {70.0f, 90.0f}, {60.0f, 180.0f}, {80.0f, 200.0f}};
  const int n = 80000;
  const double z = 4.5;
  printf("%-18s %5s %9s  %-8s %-8s %-8s %-8s\n", "material", "tilt", "view", "about n", "folded", "eval",
         "unfolded");
  for (int m = 0; m < MAT_COUNT; m++) {
    double worst_loss = 0.0;
    for (int t = 0; t < 2; t++)
      for (int v = 0; v < 4; v++) {
        iris_vec3 nn = dir(tilts[t], 0.0f), wo = dir(views[v][0], views[v][1]);
        point a, b;
        point_make(&a, m, nn, wo, true);
        point_make(&b, m, nn, wo, false);
        uint64_t seed = 1000u * (uint64_t)(m * 8 + t * 4 + v) + 7u;
        estimate ref = albedo_about_n(&a, n, seed), fold = albedo_sampled(&a, n, seed + 1),
                 eval = albedo_evaluated(&a, n, seed + 2), unfold = albedo_sampled(&b, n, seed + 1);
        printf("%-18s %4.0f° %4.0f°/%3.0f° %.5f  %.5f  %.5f  %.5f\n", MAT_NAMES[m], tilts[t], views[v][0],
               views[v][1], ref.mean, fold.mean, eval.mean, unfold.mean);
        double tol_f = z * hypot(ref.se, fold.se) + 1e-3, tol_e = z * hypot(ref.se, eval.se) + 1e-3;
        CHECK_NEAR(fold.mean, ref.mean, tol_f);
        CHECK_NEAR(eval.mean, ref.mean, tol_e);
        if (m == MAT_LAMBERT) CHECK_NEAR(ref.mean, 1.0, z * ref.se + 1e-3);
        worst_loss = fmax(worst_loss, 1.0 - unfold.mean / ref.mean);
        point_free(&a);
        point_free(&b);
      }
    printf("%s: largest loss without the fold %.1f%%\n", MAT_NAMES[m], 100.0 * worst_loss);
    CHECK(worst_loss > 0.05); /* the loss the fold removes is there to remove */
  }
}

/* ---- chi-square of the folded sampling ------------------------------------ */

static bool chi2_sample(void *ctx, const double u[3], double d[3]) {
  const point *pt = ctx;
  iris_direction_sample ds;
  if (!iris_integrator_sample_bsdf_u(&pt->sp, (float)u[0], (float)u[1], (float)u[2], &ds) || ds.delta) return false;
  d[0] = ds.wi.x, d[1] = ds.wi.y, d[2] = ds.wi.z;
  return true;
}

static double chi2_pdf(void *ctx, const double d[3]) {
  const point *pt = ctx;
  return iris_integrator_bsdf_pdf(&pt->sp, iris_v3((float)d[0], (float)d[1], (float)d[2]));
}

static void test_chi2(void) {
  const float cases[][3] = {{40.0f, 60.0f, 150.0f}, {70.0f, 75.0f, 30.0f}, {60.0f, 20.0f, 200.0f}};
  const int n_tests = MAT_COUNT * 3;
  for (int m = 0; m < MAT_COUNT; m++)
    for (int c = 0; c < 3; c++) {
      point pt;
      point_make(&pt, m, dir(cases[c][0], 0.0f), dir(cases[c][1], cases[c][2]), true);
      chi2_domain dom = {CHI2_SPHERE, 0, 0, 0x5eed + (uint64_t)(m * 3 + c)};
      chi2_result r = chi2_run(&dom, chi2_sample, chi2_pdf, &pt, 200000, 0.01, n_tests);
      point_free(&pt);
      if (!iris_check_record(r.passed, __FILE__, __LINE__, "chi2 %s tilt %.0f: %s", MAT_NAMES[m], cases[c][0],
                             r.message))
        continue;
      /* the pdf integrates to the share of samples produced (GGX sampling
       * loses the microfacet reflections that leave the shading hemisphere) */
      double kept = 1.0 - (double)r.lost / 200000.0;
      iris_check_record(fabs(r.pdf_integral - kept) < 0.01, __FILE__, __LINE__,
                        "pdf of %s at tilt %.0f integrates to %.4f, samples kept %.4f", MAT_NAMES[m], cases[c][0],
                        r.pdf_integral, kept);
    }
}

/* ---- renders -------------------------------------------------------------- */

/* A 32x32 tangent-space normal map of random normals tilted up to 70 degrees. */
static bool write_random_normal_map(const char *path) {
  iris_image img;
  iris_error err;
  const char *names[3] = {"R", "G", "B"};
  if (iris_image_create(&img, 32, 32, 3, names, &err) != IRIS_OK) return false;
  uint64_t st = 99;
  for (int i = 0; i < 32 * 32; i++) {
    float t = (float)(chi2_uniform(&st) * 70.0), p = (float)(chi2_uniform(&st) * 360.0);
    iris_vec3 d = dir(t, p);
    img.data[3 * i] = 0.5f * d.x + 0.5f, img.data[3 * i + 1] = 0.5f * d.y + 0.5f, img.data[3 * i + 2] = 0.5f * d.z + 0.5f;
  }
  bool ok = iris_png_write(path, &img, 0, 0.0f, &err) == IRIS_OK;
  iris_image_destroy(&img);
  return ok;
}

/* A 4x4 quad in the xz plane facing +y, with normals, uvs and tangents, under
 * a white sky, a camera straight above it that sees only the quad. */
static iris_scene *make_scene(const char *map, int mat) {
  iris_scene *s = iris_scene_create();
  iris_texture tex;
  memset(&tex, 0, sizeof tex);
  tex.path = iris_strdup(map);
  strcpy(tex.mime, "image/png");
  tex.nearest = true;
  iris_scene_add_texture(s, &tex);
  iris_material m = material(mat);
  m.normal_texture = 0;
  iris_scene_add_material(s, &m);
  iris_mesh q;
  memset(&q, 0, sizeof q);
  q.name = iris_strdup("plane");
  q.owned = true;
  q.material = 0;
  q.vertex_count = 4;
  q.triangle_count = 2;
  const float p[12] = {-2, 0, 2, 2, 0, 2, 2, 0, -2, -2, 0, -2};
  const float nrm[12] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
  const float uv[8] = {0, 0, 4, 0, 4, 4, 0, 4};
  const float tg[16] = {1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1};
  const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
  q.positions = malloc(sizeof p), memcpy(q.positions, p, sizeof p);
  q.normals = malloc(sizeof nrm), memcpy(q.normals, nrm, sizeof nrm);
  q.uvs = malloc(sizeof uv), memcpy(q.uvs, uv, sizeof uv);
  q.tangents = malloc(sizeof tg), memcpy(q.tangents, tg, sizeof tg);
  q.indices = malloc(sizeof idx), memcpy(q.indices, idx, sizeof idx);
  iris_instance in = {(uint32_t)iris_scene_add_mesh(s, &q), iris_mat4_identity()};
  iris_scene_add_instance(s, &in);
  float white[3] = {1, 1, 1};
  iris_scene_set_environment_color(s, white);
  iris_camera cam;
  memset(&cam, 0, sizeof cam);
  cam.name = iris_strdup("above");
  iris_mat4 x = iris_mat4_identity(); /* looks down -y, image up = -z */
  x.m[1][1] = 0, x.m[1][2] = 1, x.m[2][1] = -1, x.m[2][2] = 0;
  x.m[1][3] = 2.5f;
  cam.to_world = x;
  cam.yfov = 60.0f * (float)IRIS_PI / 180.0f;
  cam.aspect = 1.0f;
  iris_scene_add_camera(s, &cam);
  return s;
}

static bool render(const iris_scene *s, iris_method method, iris_render_result *r) {
  iris_render_params p = iris_test_params(40, 40, 32, method, 3);
  iris_guiding_params gp = iris_guiding_params_default();
  gp.force = true;
  p.threads = 2;
  iris_test_attach_guide(&p, &gp);
  return iris_test_render(s, &p, r);
}

static void test_renders(const char *map) {
  const iris_method methods[] = {IRIS_METHOD_BSDF, IRIS_METHOD_NEE, IRIS_METHOD_MIS, IRIS_METHOD_GUIDED_NEE};
  const int nm = 4;
  const double z = fmax(3.0, z_for_alpha(1e-3 / (2.0 * nm)));
  const int mats[2] = {MAT_LAMBERT, MAT_METAL};
  for (int k = 0; k < 2; k++) {
    iris_scene *s = make_scene(map, mats[k]);
    double mean0 = 0.0, var0 = 0.0;
    for (int i = 0; i < nm; i++) {
      iris_render_result r;
      if (!CHECK(render(s, methods[i], &r))) continue;
      double mean[3], var[3];
      region(&r.film, 0, 0, r.film.width, r.film.height, mean, var);
      printf("%s, %s: image mean %.5f +- %.5f\n", MAT_NAMES[mats[k]], iris_method_name(methods[i]), mean[0],
             sqrt(var[0]));
      if (mats[k] == MAT_LAMBERT) /* the model's furnace: all of the sky comes back */
        iris_check_record(fabs(mean[0] - 1.0) <= z * sqrt(var[0]) + 2e-3, __FILE__, __LINE__,
                          "%s: white Lambert with a normal map reflects %.5f, not 1", iris_method_name(methods[i]),
                          mean[0]);
      if (i == 0) {
        mean0 = mean[0], var0 = var[0];
      } else {
        iris_check_record(fabs(mean[0] - mean0) <= z * sqrt(var[0] + var0) + 1e-3, __FILE__, __LINE__,
                          "%s: %s mean %.5f vs bsdf %.5f", MAT_NAMES[mats[k]], iris_method_name(methods[i]),
                          mean[0], mean0);
      }
      iris_render_result_destroy(&r);
    }
    iris_scene_destroy(s);
  }
}

int main(void) {
  test_furnace();
  test_chi2();
  char dir_path[512], map[600];
  if (iris_test_tmpdir(dir_path, sizeof dir_path, "normal-fold") == 0) {
    snprintf(map, sizeof map, "%s/normal.png", dir_path);
    if (CHECK(write_random_normal_map(map))) test_renders(map);
    iris_test_rmtree(dir_path);
  } else {
    CHECK(!"no temporary directory");
  }
  return TEST_SUMMARY();
}
