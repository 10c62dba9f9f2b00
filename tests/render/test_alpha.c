/* Alpha coverage (glTF alphaMode MASK and BLEND, docs/rendering.md "Alpha"):
 *  - rays: a MASK quad whose vertex alpha runs 0 -> 1 across x, cutoff 0.25,
 *    lets exactly the cut-out quarter of a grid of parallel rays through, for
 *    closest-hit and shadow rays alike; a BLEND quad of alpha 0.3 lets 0.7 of
 *    them through (binomial 5 sigma), the same ray always getting the same
 *    answer;
 *  - light: that MASK quad in front of an emitter of radiance 1 filling the
 *    view passes exactly the cut-out fraction of its light, with bsdf, nee and
 *    mis (and the BLEND one 0.7), the images being equal for 1 and 2 threads;
 *  - opaque: the same quad with an opaque material blocks everything;
 *  - emitters: a white floor lit only by a two-sided emitting quad above it that is
 *    MASK with alpha 0 (all cut out) stays black with every method, and a BLEND one of
 *    alpha 0.3 lights it alike with bsdf (which sees the alpha through its rays) and
 *    with nee and mis (light sampling, whose shadow rays end before the emitter and
 *    must weigh its emission by the coverage itself). */
#include <stdlib.h>

#include "check.h"
#include "render_run.h"
#include "renderer/accel.h"
#include "renderer/render.h"

static void add_quad(iris_scene *s, float z, int32_t material, bool with_alpha) {
  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.name = iris_strdup("quad");
  m.vertex_count = 4;
  m.triangle_count = 2;
  m.owned = true;
  const float h = 2.0f; /* x, y in [-h, h] */
  const float p[12] = {-h, -h, z, h, -h, z, h, h, z, -h, h, z};
  m.positions = malloc(sizeof p);
  memcpy(m.positions, p, sizeof p);
  m.indices = malloc(6 * sizeof(uint32_t));
  const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
  memcpy(m.indices, idx, sizeof idx);
  if (with_alpha) { /* alpha = (x + h) / 2h */
    m.alphas = malloc(4 * sizeof(float));
    const float a[4] = {0, 1, 1, 0};
    memcpy(m.alphas, a, sizeof a);
  }
  m.material = material;
  iris_scene_add_mesh(s, &m);
  iris_instance inst = {(uint32_t)(s->mesh_count - 1), iris_mat4_identity()};
  iris_scene_add_instance(s, &inst);
}

/* mask quad at z = 0 (facing +z, black diffuse, the given alpha), emitter at z = -1 */
/* A camera at z = 4 seeing exactly x, y in [-1, 1] of the plane z = 0. */
static void add_front_camera(iris_scene *s) {
  iris_camera cam;
  memset(&cam, 0, sizeof cam);
  cam.name = iris_strdup("front");
  cam.to_world = iris_mat4_identity();
  cam.to_world.m[2][3] = 4.0f;
  cam.yfov = 2.0f * atanf(1.0f / 4.0f);
  cam.aspect = 1.0f;
  iris_scene_add_camera(s, &cam);
}

static iris_scene *alpha_scene(iris_alpha_mode mode, float alpha, bool gradient) {
  iris_scene *s = iris_scene_create();
  iris_material mask = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  mask.color[0] = mask.color[1] = mask.color[2] = 0.0f;
  mask.alpha_mode = mode;
  mask.alpha = alpha;
  mask.alpha_cutoff = 0.25f;
  iris_scene_add_material(s, &mask);
  iris_material light = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  light.color[0] = light.color[1] = light.color[2] = 0.0f;
  light.emission[0] = light.emission[1] = light.emission[2] = 1.0f;
  light.emission_two_sided = false;
  iris_scene_add_material(s, &light);
  add_quad(s, 0.0f, 0, gradient);
  add_quad(s, -1.0f, 1, false);
  add_front_camera(s);
  return s;
}

static void test_rays(void) {
  iris_error err;
  /* grid of 400 x 400 rays through x, y in (-2, 2): alpha < 0.25 where x < -1 */
  for (int mode = 0; mode < 3; mode++) {
    iris_scene *s = alpha_scene(mode == 0 ? IRIS_ALPHA_OPAQUE : mode == 1 ? IRIS_ALPHA_MASK : IRIS_ALPHA_BLEND,
                                mode == 2 ? 0.3f : 1.0f, mode == 1);
    iris_accel *a = NULL;
    CHECK_OK(iris_accel_build(s, &a, &err), &err);
    if (!a) continue;
    const int n = 400;
    long passed_hit = 0, passed_shadow = 0, consistent = 0;
    for (int j = 0; j < n; j++)
      for (int i = 0; i < n; i++) {
        float x = -2.0f + 4.0f * ((float)i + 0.5f) / (float)n, y = -2.0f + 4.0f * ((float)j + 0.5f) / (float)n;
        iris_ray r = {iris_v3(x, y, 1.0f), 0.0f, iris_v3(0.001f * x, 0.0007f * y, -1.0f), INFINITY};
        iris_hit h;
        bool hit = iris_accel_intersect(a, &r, &h);
        /* passes the mask when the first hit is the emitter (z = -1) */
        bool through = hit && h.t > 1.5f;
        passed_hit += through;
        iris_ray sr = r;
        sr.tmax = 1.5f; /* up to between the planes */
        bool occluded = iris_accel_occluded(a, &sr);
        passed_shadow += !occluded;
        iris_hit h2;
        consistent += iris_accel_intersect(a, &r, &h2) == hit && (!hit || h2.t == h.t);
      }
    double total = (double)n * n, f_hit = passed_hit / total, f_shadow = passed_shadow / total;
    printf("  mode %d: %.5f of closest-hit rays, %.5f of shadow rays pass\n", mode, f_hit, f_shadow);
    CHECK(consistent == (long)total);
    if (mode == 0) {
      CHECK(passed_hit == 0 && passed_shadow == 0);
    } else if (mode == 1) { /* columns with x < -1: exactly 100 of 400 */
      CHECK(passed_hit == 100L * n && passed_shadow == 100L * n);
    } else {
      double sigma = sqrt(0.7 * 0.3 / total);
      CHECK(fabs(f_hit - 0.7) < 5 * sigma && fabs(f_shadow - 0.7) < 5 * sigma);
    }
    iris_accel_destroy(a);
    iris_scene_destroy(s);
  }
}

static bool render_mean(const iris_scene *s, iris_method m, int threads, double *mean, double *sigma,
                        iris_film *keep) {
  iris_render_params p = iris_test_params(32, 32, 64, m, 7);
  p.threads = threads;
  iris_render_result r;
  if (!iris_test_render(s, &p, &r)) return false;
  double mu[3], var[3];
  region(&r.film, 0, 0, 32, 32, mu, var);
  *mean = mu[1];
  *sigma = sqrt(var[1]);
  if (keep) {
    *keep = r.film;
    memset(&r.film, 0, sizeof r.film);
  }
  iris_render_result_destroy(&r);
  return true;
}

static void test_light(void) {
  /* visible window x, y in [-1, 1]: alpha = (x + 2) / 4 < 0.25 for x < -1: nothing is cut
   * there, so use a cutoff of 0.375 (x < -0.5): a quarter of the window passes */
  iris_scene *mask = alpha_scene(IRIS_ALPHA_MASK, 1.0f, true);
  mask->materials[0].alpha_cutoff = 0.375f;
  iris_scene *blend = alpha_scene(IRIS_ALPHA_BLEND, 0.3f, false);
  iris_scene *opaque = alpha_scene(IRIS_ALPHA_OPAQUE, 0.3f, false);
  const iris_method methods[3] = {IRIS_METHOD_BSDF, IRIS_METHOD_NEE, IRIS_METHOD_MIS};
  for (int k = 0; k < 3; k++) {
    double mean, sigma;
    if (render_mean(mask, methods[k], 0, &mean, &sigma, NULL)) {
      printf("  %-4s MASK: mean %.5f (sigma %.2g), expected 0.25\n", iris_method_name(methods[k]), mean, sigma);
      /* each pixel is fully open, fully closed or (the column at x = -0.5) split; pixel
       * jitter makes the split column's share exact only in expectation */
      CHECK(fabs(mean - 0.25) < 5 * sigma + 2e-3);
    }
    if (render_mean(blend, methods[k], 0, &mean, &sigma, NULL)) {
      printf("  %-4s BLEND: mean %.5f (sigma %.2g), expected 0.7\n", iris_method_name(methods[k]), mean, sigma);
      CHECK(fabs(mean - 0.7) < 5 * sigma + 1e-3);
    }
    if (render_mean(opaque, methods[k], 0, &mean, &sigma, NULL)) CHECK(mean == 0.0);
  }
  /* determinism of the stochastic pass-through: 1 and 2 threads, bit for bit */
  iris_film f1, f2;
  double m1, m2, s1, s2;
  memset(&f1, 0, sizeof f1);
  memset(&f2, 0, sizeof f2);
  if (render_mean(blend, IRIS_METHOD_MIS, 1, &m1, &s1, &f1) && render_mean(blend, IRIS_METHOD_MIS, 2, &m2, &s2, &f2)) {
    bool same = true;
    for (int y = 0; y < 32 && same; y++)
      for (int x = 0; x < 32 && same; x++) {
        iris_vec3 a, b, va, vb;
        iris_film_pixel(&f1, x, y, &a, &va);
        iris_film_pixel(&f2, x, y, &b, &vb);
        same = a.x == b.x && a.y == b.y && a.z == b.z;
      }
    CHECK(same);
  }
  iris_film_destroy(&f1);
  iris_film_destroy(&f2);
  iris_scene_destroy(mask);
  iris_scene_destroy(blend);
  iris_scene_destroy(opaque);
}

/* white floor at z = 0, a two-sided emitter of radiance 1 at z = 1 (mode, alpha), the
 * camera of alpha_scene seeing the floor through it */
static iris_scene *emitter_scene(iris_alpha_mode mode, float alpha) {
  iris_scene *s = iris_scene_create();
  iris_material floor = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  floor.color[0] = floor.color[1] = floor.color[2] = 0.8f;
  iris_scene_add_material(s, &floor);
  iris_material light = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  light.color[0] = light.color[1] = light.color[2] = 0.0f;
  light.emission[0] = light.emission[1] = light.emission[2] = 1.0f;
  light.emission_two_sided = true;
  light.alpha_mode = mode;
  light.alpha = alpha;
  light.alpha_cutoff = 0.5f;
  iris_scene_add_material(s, &light);
  add_quad(s, 0.0f, 0, false);
  add_quad(s, 1.0f, 1, false);
  add_front_camera(s);
  return s;
}

static void test_emitters(void) {
  iris_scene *cut = emitter_scene(IRIS_ALPHA_MASK, 0.0f);
  iris_scene *blend = emitter_scene(IRIS_ALPHA_BLEND, 0.3f);
  const iris_method methods[3] = {IRIS_METHOD_BSDF, IRIS_METHOD_NEE, IRIS_METHOD_MIS};
  double ref = 0, ref_sigma = 0;
  for (int k = 0; k < 3; k++) {
    double mean, sigma;
    if (render_mean(cut, methods[k], 0, &mean, &sigma, NULL)) {
      printf("  %-4s cut-out MASK emitter: mean %.5f, expected 0\n", iris_method_name(methods[k]), mean);
      CHECK(mean == 0.0);
    }
    if (render_mean(blend, methods[k], 0, &mean, &sigma, NULL)) {
      if (k == 0) {
        ref = mean;
        ref_sigma = sigma;
      }
      printf("  %-4s BLEND 0.3 emitter: mean %.5f (sigma %.2g), bsdf %.5f\n", iris_method_name(methods[k]), mean,
             sigma, ref);
      CHECK(ref > 0.05);
      CHECK(fabs(mean - ref) < 5 * sqrt(sigma * sigma + ref_sigma * ref_sigma) + 1e-3);
    }
  }
  iris_scene_destroy(cut);
  iris_scene_destroy(blend);
}

int main(void) {
  test_rays();
  test_light();
  test_emitters();
  return iris_check_summary("render.alpha");
}
