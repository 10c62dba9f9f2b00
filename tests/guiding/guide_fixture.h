/* Builds a guide for a scene outside iris_render, as the guiding tests need
 * it: a 48x36 camera, the scene's accel, textures and lights (freed again:
 * the guide keeps none of them), the guide setup of a render of `spp`
 * samples with the sobol sampler. NULL (and a message) when anything fails. */
#ifndef IRIS_TESTS_GUIDING_GUIDE_FIXTURE_H
#define IRIS_TESTS_GUIDING_GUIDE_FIXTURE_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "chi2.h"
#include "renderer/accel.h"
#include "renderer/envmap.h"
#include "renderer/guiding/guiding.h"
#include "renderer/lights.h"
#include "renderer/render.h"
#include "renderer/texture.h"
#include "scenes/builtin.h"

/* A scene set up for rendering by hand (a 48x36 camera): what
 * test_guide_build uses and frees, kept for tests that trace paths with the
 * guide themselves. False (and a message) when anything fails. */
typedef struct test_guide_scene {
  iris_pinhole cam;
  iris_accel *acc;
  iris_textures tx;
  iris_lights lights;
  iris_integrator it;
} test_guide_scene;

static inline void test_guide_scene_close(test_guide_scene *t) {
  iris_lights_destroy(&t->lights);
  iris_textures_destroy(&t->tx);
  iris_accel_destroy(t->acc);
  t->acc = NULL;
}

static inline bool test_guide_scene_open(const iris_scene *s, iris_method method, test_guide_scene *t) {
  iris_error err;
  iris_error_clear(&err);
  memset(t, 0, sizeof *t);
  if (iris_pinhole_setup(s, NULL, 48, 36, &t->cam, &err) == IRIS_OK && iris_accel_build(s, &t->acc, &err) == IRIS_OK &&
      iris_textures_load(s, &t->tx, &err) == IRIS_OK && iris_lights_build(s, t->acc, &t->tx, &t->lights, &err) == IRIS_OK) {
    t->it = iris_integrator_default(s, t->acc, &t->lights, &t->tx);
    t->it.method = method;
    return true;
  }
  fprintf(stderr, "scene set-up failed: %s\n", err.message);
  test_guide_scene_close(t);
  return false;
}

/* The built-in scene `name` in *sc, opened as test_guide_scene_open does:
 * both checked (CHECK), and on failure nothing is left to free. */
static inline bool test_guide_builtin_open(const char *name, iris_method method, iris_scene **sc,
                                           test_guide_scene *t) {
  iris_error err;
  *sc = NULL;
  if (!CHECK(iris_builtin_create(name, sc, &err) == IRIS_OK)) return false;
  if (CHECK(test_guide_scene_open(*sc, method, t))) return true;
  iris_scene_destroy(*sc);
  *sc = NULL;
  return false;
}

/* The guide setup of a render of `spp` samples (sobol) for an open scene:
 * no time budget, not deciding for auto, no film, no phases. */
static inline iris_guide_setup test_guide_setup(const iris_scene *s, test_guide_scene *t, uint64_t seed, int threads,
                                                int spp) {
  iris_guide_setup gs = {s, t->acc, &t->lights, &t->tx, &t->cam, &t->it, seed, threads, NULL, spp, 0.0, IRIS_SAMPLER_SOBOL, false, NULL, NULL, 0.0, NULL, {0, 0, 0, 0}, false, false};
  return gs;
}

/* The guide of a render of `spp` samples (sobol) for an open scene. */
static inline iris_guiding *test_guide_build_in(const iris_scene *s, test_guide_scene *t, iris_guiding_params gp,
                                                uint64_t seed, int threads, int spp) {
  iris_error err;
  iris_error_clear(&err);
  iris_guiding *g = NULL;
  gp.use_nee = iris_method_uses_nee(t->it.method);
  iris_guide_setup gs = test_guide_setup(s, t, seed, threads, spp);
  if (iris_guiding_build(&gs, &gp, &g, &err) != IRIS_OK) fprintf(stderr, "build failed: %s\n", err.message);
  return g;
}

static inline iris_guiding *test_guide_build(const iris_scene *s, iris_method method, iris_guiding_params gp,
                                             uint64_t seed, int threads, int spp) {
  test_guide_scene t;
  if (!test_guide_scene_open(s, method, &t)) return NULL;
  iris_guiding *g = test_guide_build_in(s, &t, gp, seed, threads, spp);
  test_guide_scene_close(&t);
  return g;
}

/* Loads the environment map at `path` (strength 1, rotated by `rotation`
 * degrees) into *env; false (and the message) when it cannot. */
static inline bool test_envmap_open(const char *path, float rotation, iris_envmap *env) {
  iris_environment_map m = {(char *)path, 1.0f, rotation};
  iris_error err;
  iris_error_clear(&err);
  if (iris_envmap_load(&m, env, &err) == IRIS_OK) return true;
  fprintf(stderr, "environment map %s: %s\n", path, err.message);
  return false;
}

/* The shading point where a ray straight down from 5 cm above x meets the
 * scene, seen from above; false when it misses or the hit is not at x's
 * height (within 1 mm). */
static inline bool test_shade_below(const test_guide_scene *t, iris_vec3 x, iris_shading_point *sp) {
  iris_ray ray = {iris_add(x, iris_v3(0.0f, 0.05f, 0.0f)), 0.0f, iris_v3(0.0f, -1.0f, 0.0f), 1.0f};
  iris_hit hit;
  if (!iris_accel_intersect(t->acc, &ray, &hit)) return false;
  iris_interaction si;
  iris_accel_interaction(t->acc, ray.d, &hit, &si);
  iris_integrator_shade(&t->it, &si, iris_v3(0.0f, 1.0f, 0.0f), 0, sp);
  return fabsf(si.p.y - x.y) < 1e-3f;
}

/* The whole guided direction sampler at one prepared shading point, for
 * chi2_run: it draws its own numbers (chi2_run's are not the sampler's
 * slots), an independent stream per call from `key`; the pdf is the
 * sampler's MIS density. */
typedef struct test_sampler_ctx {
  iris_direction_sampler s;
  const iris_shading_point *sp;
  uint64_t key, calls;
} test_sampler_ctx;

static inline bool test_full_sample(void *vc, const double u[3], double dir[3]) {
  (void)u;
  test_sampler_ctx *c = vc;
  iris_sampler rng = iris_sampler_start(c->key, c->calls++, 0);
  iris_direction_sample ds;
  memset(&ds, 0, sizeof ds);
  if (!c->s.sample(c->s.ctx, c->sp, &rng, &ds)) return false;
  dir[0] = ds.wi.x, dir[1] = ds.wi.y, dir[2] = ds.wi.z;
  return true;
}

static inline double test_full_pdf(void *vc, const double dir[3]) {
  test_sampler_ctx *c = vc;
  return c->s.pdf(c->s.ctx, c->sp, iris_v3((float)dir[0], (float)dir[1], (float)dir[2]));
}

/* The whole sampler at sp against its own pdf: chi-square over the sphere
 * (400 000 samples, level 0.01 over n_tests) and the pdf's integral 1
 * (5e-3), recorded at the caller's file and line as "guided sampler with
 * WHAT". */
static inline chi2_result test_full_chi2(iris_direction_sampler s, const iris_shading_point *sp, uint64_t key,
                                         int n_tests, const char *what, const char *file, int line) {
  test_sampler_ctx c = {s, sp, key, 0};
  chi2_domain dom = {CHI2_SPHERE, 64, 128, 23};
  chi2_result r = chi2_run(&dom, test_full_sample, test_full_pdf, &c, 400000, 0.01, n_tests);
  iris_check_record(r.passed, file, line, "guided sampler with %s: %s", what, r.message);
  iris_check_record(fabs(r.pdf_integral - 1.0) <= 5e-3, file, line, "guided sampler with %s: pdf integral %.6f", what,
                    r.pdf_integral);
  return r;
}

#endif
