/* Random numbers are a pure function of (seed, pixel, sample, dimension): the
 * Cornell box rendered with 1 and with 2 threads must match bit for bit, and a
 * different seed must give a different image. Also the NaN/Inf guard. */
#include <stdlib.h>

#include "check.h"
#include "render_run.h"
#include "renderer/render.h"
#include "scenes/builtin.h"

static bool render(const iris_scene *s, int threads, uint64_t seed, iris_method m,
                   iris_render_result *r) {
  /* 40 x 24: not a multiple of the 8-pixel tiles */
  iris_render_params p = iris_test_params(40, 24, 12, m, seed);
  p.threads = threads;
  return iris_test_render(s, &p, r);
}

static bool same_film(const iris_film *a, const iris_film *b) {
  size_t n = (size_t)a->width * (size_t)a->height;
  return a->width == b->width && a->height == b->height &&
         memcmp(a->sum, b->sum, 3 * n * sizeof(double)) == 0 &&
         memcmp(a->sum2, b->sum2, 3 * n * sizeof(double)) == 0 &&
         memcmp(a->count, b->count, n * sizeof(uint32_t)) == 0;
}

/* NaN guard: a direction sampler that poisons one path in ten with NaN/Inf
 * (plugged in through the guiding hook) must not put a single non-finite
 * value on the film, and every poisoned sample is counted. */
static bool poison_sample(void *ctx, const iris_shading_point *sp, iris_sampler *rng,
                          iris_direction_sample *out) {
  (void)ctx;
  float u = iris_sampler_next(rng);
  if (!iris_integrator_sample_bsdf(sp, rng, out)) return false;
  if (u < 0.05f) out->f.x = NAN;
  else if (u < 0.1f) out->pdf = 0.0f * out->pdf + 1e-45f, out->f.y = INFINITY;
  return true;
}
static float poison_pdf(void *ctx, const iris_shading_point *sp, iris_vec3 wi) {
  (void)ctx;
  return iris_integrator_bsdf_pdf(sp, wi);
}
static iris_status poison_build(const iris_guide_setup *setup, iris_direction_sampler *out,
                                void **state, iris_error *err) {
  (void)setup, (void)err;
  out->ctx = NULL;
  out->sample = poison_sample;
  out->pdf = poison_pdf;
  *state = NULL;
  return IRIS_OK;
}

static void test_nan_guard(const iris_scene *s) {
  static const iris_guide_provider poison = {poison_build, NULL, NULL, NULL, NULL};
  iris_render_params p = iris_render_params_default();
  p.width = 16;
  p.height = 16;
  p.spp = 8;
  p.method = IRIS_METHOD_GUIDED_NEE;
  p.guide = &poison;
  iris_render_result r;
  iris_error err;
  if (!CHECK(iris_render(s, &p, &r, &err) == IRIS_OK)) return;
  CHECK(r.stats.nan_count > 0);
  bool finite = true;
  for (int y = 0; y < 16; y++)
    for (int x = 0; x < 16; x++) {
      iris_vec3 m, v;
      iris_film_pixel(&r.film, x, y, &m, &v);
      finite = finite && iris_isfinite3(m) && iris_isfinite3(v);
    }
  CHECK(finite);
  printf("NaN guard: %llu poisoned samples dropped\n", (unsigned long long)r.stats.nan_count);
  iris_render_result_destroy(&r);
}

int main(void) {
  iris_scene *s = NULL;
  iris_error err;
  if (!CHECK(iris_builtin_create("cornell-box", &s, &err) == IRIS_OK)) return iris_check_summary("render.determinism");
  static const iris_method methods[3] = {IRIS_METHOD_BSDF, IRIS_METHOD_NEE, IRIS_METHOD_MIS};
  for (int i = 0; i < 3; i++) {
    iris_render_result r1, r2, r3;
    if (!CHECK(render(s, 1, 42, methods[i], &r1))) continue;
    if (CHECK(render(s, 2, 42, methods[i], &r2))) {
      iris_check_record(same_film(&r1.film, &r2.film), __FILE__, __LINE__,
                        "%s: 1 and 2 threads differ", iris_method_name(methods[i]));
      CHECK_EQ_INT(r1.stats.rays, r2.stats.rays);
      CHECK_EQ_INT(r1.stats.shadow_rays, r2.stats.shadow_rays);
      iris_render_result_destroy(&r2);
    }
    if (CHECK(render(s, 2, 43, methods[i], &r3))) {
      iris_check_record(!same_film(&r1.film, &r3.film), __FILE__, __LINE__,
                        "%s: seeds 42 and 43 give the same image", iris_method_name(methods[i]));
      iris_render_result_destroy(&r3);
    }
    iris_render_result_destroy(&r1);
  }
  test_nan_guard(s);
  iris_scene_destroy(s);
  return iris_check_summary("render.determinism");
}
