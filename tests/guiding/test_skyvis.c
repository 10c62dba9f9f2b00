/* guiding.skyvis: light sampling of an environment map from what the caches
 * see of it (renderer/guiding/skyvis.h, envmap.h's regions).
 *  - regions of a map whose size the grid does not divide (61 x 29 cells in
 *    7 x 3 regions): their probabilities sum to 1; sampling within a region
 *    passes chi-square against the map's pdf over the region's probability
 *    (0 outside), which integrates to 1;
 *  - the mixture (tied caches picked uniformly, repeated ones, a cache that saw
 *    nothing, beta < 1 and beta = 1) passes chi-square against
 *    iris_skyvis_scale x the map's pdf, which integrates to 1; so do the
 *    mixtures with windows (a cache's own, one seen edge-on whose draws are
 *    lost, and at a vertex without caches the windows as a whole), whose
 *    density adds the windows' part;
 *  - built from sky-room's real caches: roof caches see all the sky (and take
 *    the map), back-floor caches see only the window's side; the caches find
 *    the window (its centre and size within 1 cm) and at least 90% of those
 *    that see part of the sky draw from it; the tables and windows are
 *    bit-identical for 1 and 2 threads; on env-objects (open sky) fewer than
 *    10% of the caches see less than half of their sky, and the map's own
 *    sampling is kept. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "chi2.h"
#include "core/fileio.h"
#include "core/image.h"
#include "exr_map.h"
#include "guide_fixture.h"
#include "renderer/envmap.h"
#include "renderer/guiding/skyvis.h"
#include "scenes/builtin.h"
#include "scenes/sky.h"

typedef struct region_ctx {
  const iris_envmap *env;
  const iris_envmap_regions *r;
  int region;
} region_ctx;

static bool region_sample(void *vc, const double u[3], double dir[3]) {
  region_ctx *c = vc;
  iris_vec3 d;
  float pdf, s, t;
  if (!iris_envmap_sample_region(c->env, c->r, c->region, (float)u[0], (float)u[1], &d, &pdf, &s, &t)) return false;
  dir[0] = d.x, dir[1] = d.y, dir[2] = d.z;
  return true;
}
static double region_pdf(void *vc, const double dir[3]) {
  region_ctx *c = vc;
  iris_vec3 d = iris_v3((float)dir[0], (float)dir[1], (float)dir[2]);
  float s, t;
  iris_envmap_dir_to_st(c->env, d, &s, &t);
  if (iris_envmap_region_of(c->env, c->r, s, t) != c->region) return 0.0;
  return (double)iris_envmap_pdf(c->env, d) / (double)c->r->prob[c->region];
}

typedef struct mix_ctx {
  const iris_skyvis *sv;
  const iris_envmap *env;
  const uint32_t *ids;
  int m;
  iris_vec3 x; /* the vertex */
} mix_ctx;

/* The mixture's density at c->x for d: the map's times the scale plus the windows'. */
static double mix_density(const mix_ctx *c, iris_vec3 d) {
  float s, t, through;
  iris_envmap_dir_to_st(c->env, d, &s, &t);
  const float scale = iris_skyvis_scale(c->sv, c->env, c->ids, c->m, c->x, d, s, t, &through);
  return (double)iris_envmap_pdf(c->env, d) * (double)scale + (double)through;
}

static bool mix_sample(void *vc, const double u[3], double dir[3]) {
  mix_ctx *c = vc;
  iris_vec3 d;
  float pdf, s, t;
  if (!iris_skyvis_sample(c->sv, c->env, c->ids, c->m, c->x, (float)u[0], (float)u[1], &d, &pdf, &s, &t))
    return false;
  /* the density it reports is the one the pdf gives for its direction (up to
   * a cell edge's rounding) */
  const float again = (float)mix_density(c, d);
  if (!(fabsf(again - pdf) <= 1e-3f * pdf)) {
    static int shown;
    if (shown++ < 3) fprintf(stderr, "sampled pdf %g, pdf of the direction %g\n", (double)pdf, (double)again);
  }
  dir[0] = d.x, dir[1] = d.y, dir[2] = d.z;
  return true;
}
static double mix_pdf(void *vc, const double dir[3]) {
  return mix_density(vc, iris_v3((float)dir[0], (float)dir[1], (float)dir[2]));
}

#define N_TESTS 7

static void test_regions_and_mixture(const char *path) {
  iris_envmap env;
  if (!CHECK(test_envmap_open(path, 23.0f, &env))) return;
  iris_error err;
  iris_error_clear(&err);
  iris_status st;
  iris_envmap_regions R;
  st = iris_envmap_regions_build(&env, 7, 3, &R, &err);
  CHECK_OK(st, &err);
  if (st != IRIS_OK) {
    iris_envmap_destroy(&env);
    return;
  }
  double sum = 0.0;
  int sun = -1;
  for (int b = 0; b < 21; b++) {
    sum += R.prob[b];
    if (sun < 0 || R.prob[b] > R.prob[sun]) sun = b;
  }
  CHECK_NEAR(sum, 1.0, 1e-5);
  /* the brightest region (the sun's) and a dim one of the lower row */
  int regions[2] = {sun, 2 * 7 + 5};
  chi2_domain dom = {CHI2_SPHERE, 32, 64, 91};
  for (int k = 0; k < 2; k++) {
    region_ctx rc = {&env, &R, regions[k]};
    chi2_result r = chi2_run(&dom, region_sample, region_pdf, &rc, 200000, 0.01, N_TESTS);
    iris_check_record(r.passed, __FILE__, __LINE__, "region %d: %s", regions[k], r.message);
    CHECK_NEAR(r.pdf_integral, 1.0, 3e-3);
    CHECK(r.lost == 0);
    printf("region %d (probability %.4f): p = %.3g, pdf integral %.5f\n", regions[k], (double)R.prob[regions[k]],
           r.p_value, r.pdf_integral);
  }
  iris_envmap_regions_destroy(&R);

  /* A sky guide made by hand: cache 0 sees some regions (others 0), cache 1
   * saw nothing, cache 2 sees only the dim region. */
  iris_skyvis sv;
  memset(&sv, 0, sizeof sv);
  st = iris_envmap_regions_build(&env, 7, 3, &sv.regions, &err);
  CHECK_OK(st, &err);
  if (st != IRIS_OK) {
    iris_envmap_destroy(&env);
    return;
  }
  sv.region_count = 21;
  sv.cache_count = 3;
  sv.built = true;
  sv.map_width = env.width, sv.map_height = env.height, sv.map_mean = env.mean_luminance;
  sv.cdf = calloc(3 * 21, sizeof(float));
  sv.sees = calloc(3, 1);
  float w0[21];
  for (int b = 0; b < 21; b++) w0[b] = (b % 3 == 0) ? 0.0f : (float)(1 + (b * 7) % 5);
  double acc = 0.0, tot = 0.0;
  for (int b = 0; b < 21; b++) tot += w0[b];
  for (int b = 0; b < 21; b++) {
    acc += w0[b];
    sv.cdf[b] = (float)(acc / tot);
    sv.cdf[2 * 21 + b] = b >= regions[1] ? 1.0f : 0.0f;
  }
  sv.cdf[20] = 1.0f;
  sv.sees[0] = IRIS_SKYVIS_PART, sv.sees[1] = IRIS_SKYVIS_NONE, sv.sees[2] = IRIS_SKYVIS_PART;
  CHECK(iris_skyvis_serves(&sv, &env));
  const uint32_t ids_a[4] = {0, 1, 2, 0}, ids_b[1] = {2};
  const float betas[2] = {0.75f, 1.0f};
  for (int k = 0; k < 2; k++) {
    sv.beta = betas[k];
    mix_ctx mc = {&sv, &env, k == 0 ? ids_a : ids_b, k == 0 ? 4 : 1, iris_v3(0, 0, 0)};
    chi2_result r = chi2_run(&dom, mix_sample, mix_pdf, &mc, 300000, 0.01, N_TESTS);
    iris_check_record(r.passed, __FILE__, __LINE__, "mixture beta %.2f: %s", (double)betas[k], r.message);
    CHECK_NEAR(r.pdf_integral, 1.0, 3e-3);
    printf("mixture beta %.2f over %d caches: p = %.3g, pdf integral %.5f, lost %zu\n", (double)betas[k], mc.m,
           r.p_value, r.pdf_integral, r.lost);
  }
  /* Windows: cache 0 draws from a window 2 m away (a 1 x 0.6 m rectangle,
   * seen obliquely), cache 2 from one the vertex sees edge-on from its plane
   * (no direction: its draws there are lost, its density 0), cache 1 from
   * none; each also from the other window by solid angle (skyvis.h), which
   * from the origin gives the edge-on window nothing; the vertex at the
   * origin and, for the second case, behind the first window (its back:
   * directions through it still count, as a ray crosses it either way),
   * where both windows have a solid angle and each cache draws from both. */
  sv.cache_window = malloc(3);
  sv.window_count = 2;
  sv.window[0] = (iris_portal){{0.3f, 0.4f, 2.0f}, {0.5f, 0.0f, 0.1f}, {0.0f, 0.3f, 0.0f}};
  sv.window[1] = (iris_portal){{0.0f, 0.0f, -1.0f}, {0.0f, 0.0f, 0.4f}, {0.0f, 0.4f, 0.0f}}; /* the plane x = 0 */
  sv.cache_window[0] = 0, sv.cache_window[1] = 0xff, sv.cache_window[2] = 1;
  const iris_vec3 xs[2] = {iris_v3(0, 0, 0), iris_v3(0.3f, 0.4f, 3.0f)};
  const chi2_domain wdom = {CHI2_SPHERE, 16, 32, 92}; /* coarser: the windows' edges make the quadrature slow */
  for (int k = 0; k < 2; k++) {
    sv.beta = 0.75f;
    mix_ctx mc = {&sv, &env, ids_a, 4, xs[k]};
    chi2_result r = chi2_run(&wdom, mix_sample, mix_pdf, &mc, 200000, 0.01, N_TESTS);
    iris_check_record(r.passed, __FILE__, __LINE__, "mixture with windows, vertex %d: %s", k, r.message);
    /* cache 2's own window draws nothing from the origin, in its plane:
     * that share is lost, and the density integrates to 1 less it */
    const double lost_share = k == 0 ? 0.25 * IRIS_SKYVIS_WINDOW_SHARE * IRIS_SKYVIS_OWN_WINDOW : 0.0;
    CHECK_NEAR(r.pdf_integral, 1.0 - lost_share, 3e-3);
    printf("mixture with windows (vertex %d) over %d caches: p = %.3g, pdf integral %.5f, lost %zu\n", k, mc.m, r.p_value,
           r.pdf_integral, r.lost);
  }
  /* A vertex no cache covers draws from the windows as a whole (each alike)
   * and the map: from the origin the second window is edge-on, its half of
   * the windows' share lost. */
  {
    mix_ctx mc = {&sv, &env, NULL, 0, xs[0]};
    CHECK(iris_skyvis_guides(&sv, NULL, 0));
    chi2_result r = chi2_run(&wdom, mix_sample, mix_pdf, &mc, 200000, 0.01, N_TESTS);
    iris_check_record(r.passed, __FILE__, __LINE__, "windows without caches: %s", r.message);
    CHECK_NEAR(r.pdf_integral, 1.0 - 0.5 * IRIS_SKYVIS_WINDOW_SHARE, 3e-3);
    printf("windows without caches: p = %.3g, pdf integral %.5f, lost %zu\n", r.p_value, r.pdf_integral, r.lost);
  }
  iris_skyvis_destroy(&sv);
  iris_envmap_destroy(&env);
}

/* The built-in scene `name` and its guide without training, built with 1
 * and with 2 threads; true when both have sky visibility (*s and g[] are
 * set either way: free them with close_scene). */
static bool open_scene(const char *name, iris_scene **s, iris_guiding *g[2]) {
  iris_error err;
  g[0] = g[1] = NULL;
  *s = NULL;
  if (!CHECK(iris_builtin_create(name, s, &err) == IRIS_OK)) return false;
  for (int t = 0; t < 2; t++) {
    iris_guiding_params gp = iris_guiding_params_default();
    gp.train_spp = 0;
    g[t] = test_guide_build(*s, IRIS_METHOD_GUIDED_NEE, gp, 3, t + 1, 16);
  }
  return CHECK(g[0] && g[1]) && CHECK(g[0]->sky.built && g[1]->sky.built);
}

static void close_scene(iris_scene *s, iris_guiding *g[2]) {
  iris_guiding_destroy(g[0]);
  iris_guiding_destroy(g[1]);
  iris_scene_destroy(s);
}

static void test_built_from_scene(void) {
  iris_scene *s;
  iris_error err;
  iris_guiding *g[2];
  if (open_scene("sky-room", &s, g)) {
    const iris_skyvis *a = &g[0]->sky, *b = &g[1]->sky;
    printf("sky-room: %zu caches, %llu probes, %.1f%% escaped, %.3f s\n", a->cache_count,
           (unsigned long long)a->probes, 100.0 * (double)a->escaped / (double)a->probes, a->seconds);
    CHECK(a->probes > 0 && a->escaped > 0 && a->escaped < a->probes);
    /* What the caches saw is the room's geometry: every cache on the roof
     * (y = 2.5, facing up) sees the sky above it (and takes the map); one
     * on the floor in the back half (x < -0.5, facing up) sees it only through
     * the window in the +x wall, so no region whose centre lies towards -x has
     * any probability. */
    iris_environment_map m = {(char *)iris_sky_map_path(), 1.0f, 0.0f};
    iris_envmap env;
    iris_status st = iris_envmap_load(&m, &env, &err);
    CHECK_OK(st, &err);
    if (st == IRIS_OK) {
      CHECK(iris_skyvis_serves(a, &env));
      size_t roof = 0, roof_seeing = 0, back = 0, back_seeing = 0, back_wrong = 0;
      for (size_t i = 0; i < a->cache_count; i++) {
        const iris_cache *c = &g[0]->caches[i];
        if (c->frame.n.y < 0.99f) continue;
        if (c->p.y > 2.49f) roof++, roof_seeing += a->sees[i] == IRIS_SKYVIS_OPEN; /* the ceiling's top */
        if (c->p.y < 0.01f && c->p.x < -0.5f && c->p.x > -1.99f && fabsf(c->p.z) < 1.99f) {
          back++;
          back_seeing += a->sees[i] == IRIS_SKYVIS_PART;
          CHECK(a->sees[i] != IRIS_SKYVIS_OPEN);
          const float *row = &a->cdf[i * (size_t)a->region_count];
          for (int r = 0; r < a->region_count; r++) {
            const iris_envmap_regions *R = &a->regions;
            int ci = r % R->bx, rj = r / R->bx;
            float sc = 0.5f * (float)(R->col0[ci] + R->col0[ci + 1]) / (float)env.width;
            float tc = 0.5f * (float)(R->row0[rj] + R->row0[rj + 1]) / (float)env.height;
            float pr = row[r] - (r > 0 ? row[r - 1] : 0.0f);
            if (a->sees[i] == IRIS_SKYVIS_PART && iris_envmap_st_to_dir(&env, sc, tc).x < -0.5f && pr > 0.0f) back_wrong++;
          }
        }
      }
      printf("roof caches %zu (%zu see all the sky), back floor caches %zu (%zu see part of it), %zu wrong regions\n", roof,
             roof_seeing, back, back_seeing, back_wrong);
      CHECK(roof > 0 && roof_seeing == roof);
      CHECK(back > 0 && back_seeing > 0 && back_wrong == 0);
      /* The connections' windows (the hook sky_windows): the one window,
       * turned to face out (+x), and the power entering through it against a
       * quadrature over the map's texels, sum L max(0, cos) dw times its area. */
      iris_direction_sampler ds = iris_guiding_sampler(g[0]);
      iris_vec3 wo[4], wu[4], wv[4];
      float flux[4], share[4];
      const int k = ds.sky_windows ? ds.sky_windows(ds.ctx, &env, 4, wo, wu, wv, flux, share) : 0;
      if (CHECK(k == 1)) {
        const iris_vec3 n = iris_normalize(iris_cross(wu[0], wv[0]));
        double ref = 0.0;
        for (int y = 0; y < env.height; y++)
          for (int x = 0; x < env.width; x++) {
            const float sx = ((float)x + 0.5f) / (float)env.width, ty = ((float)y + 0.5f) / (float)env.height;
            const float c = iris_dot(iris_envmap_st_to_dir(&env, sx, ty), n);
            if (c > 0.0f)
              ref += (double)iris_avg3(iris_envmap_radiance_st(&env, sx, ty)) * c * sin(IRIS_PI * ty) *
                     (2.0 * IRIS_PI / env.width) * (IRIS_PI / env.height);
          }
        ref *= 4.0 * iris_length(iris_cross(wu[0], wv[0]));
        printf("connections' window: normal (%.3f, %.3f, %.3f), %.0f%% of the caches, flux %.4f against %.4f by "
               "quadrature\n",
               (double)n.x, (double)n.y, (double)n.z, 100.0 * share[0], (double)flux[0], ref);
        CHECK(n.x > 0.99f && share[0] > 0.15f);
        CHECK(fabs(flux[0] / ref - 1.0) < 0.03);
      }
      iris_envmap_destroy(&env);
    }
    /* The window: the caches that see part of the sky find it and join their
     * parts into the whole opening (x = 2, y in [1, 2], z in [-0.6, 0.6]),
     * which nearly all of them then draw from. */
    if (CHECK(a->window_count == 1)) {
      const iris_portal *w = &a->window[0];
      const float hy = fabsf(w->u.y) + fabsf(w->v.y), hz = fabsf(w->u.z) + fabsf(w->v.z);
      printf("window: centre (%.4f, %.4f, %.4f), half-sizes %.4f (y) x %.4f (z); %zu of %zu caches that see part of "
             "the sky draw from it\n",
             (double)w->o.x, (double)w->o.y, (double)w->o.z, (double)hy, (double)hz, a->window_caches, a->part_caches);
      CHECK(fabsf(w->o.x - 2.0f) < 0.01f && fabsf(w->o.y - 1.5f) < 0.01f && fabsf(w->o.z) < 0.01f);
      CHECK(fabsf(hy - 0.5f) < 0.01f && fabsf(hz - 0.6f) < 0.01f);
      CHECK(a->window_caches * 10 >= a->part_caches * 9);
    }
    CHECK(a->window_count == b->window_count && a->window_caches == b->window_caches);
    CHECK(memcmp(a->window, b->window, sizeof(iris_portal) * (size_t)a->window_count) == 0);
    CHECK(a->cache_window && b->cache_window && memcmp(a->cache_window, b->cache_window, a->cache_count) == 0);
    CHECK(a->cache_count == b->cache_count && a->probes == b->probes && a->escaped == b->escaped);
    CHECK(memcmp(a->sees, b->sees, a->cache_count) == 0);
    CHECK(memcmp(a->cdf, b->cdf, sizeof(float) * a->cache_count * (size_t)a->region_count) == 0);
  }
  close_scene(s, g);
  /* Under the open sky nearly every cache sees most of it: the map's own
   * sampling is kept (probed, not built). */
  s = NULL;
  if (!CHECK(iris_builtin_create("env-objects", &s, &err) == IRIS_OK)) return;
  iris_guiding_params gp = iris_guiding_params_default();
  gp.train_spp = 0;
  gp.force = true;
  iris_guiding *o = test_guide_build(s, IRIS_METHOD_GUIDED_NEE, gp, 3, 2, 16);
  if (CHECK(o)) {
    printf("env-objects: %zu caches, %zu see part of the sky, built %d\n", o->sky.cache_count, o->sky.part_caches,
           o->sky.built);
    CHECK(o->sky.probed && !o->sky.built && !o->sky.cdf);
    CHECK(o->sky.part_caches * 10 < o->sky.cache_count);
    iris_direction_sampler ds = iris_guiding_sampler(o);
    CHECK(!ds.sample_environment && !ds.environment_scale);
  }
  iris_guiding_destroy(o);
  iris_scene_destroy(s);
}

/* Two windows (sky-room-corner: the +x wall's and the +z wall's): the
 * caches with a window also know which others they reach, the same for 1
 * and 2 threads; every one reaches its own, and the back wall's (x = -2,
 * facing +x), whose own is the +x window, reach the +z one too, which they
 * see at a grazing angle. */
static void test_window_reach(void) {
  iris_scene *s;
  iris_guiding *g[2];
  if (open_scene("sky-room-corner", &s, g) && CHECK(g[0]->sky.window_count == 2) &&
      CHECK(g[0]->sky.window_reach && g[1]->sky.window_reach)) {
    const iris_skyvis *a = &g[0]->sky;
    CHECK(memcmp(a->window_reach, g[1]->sky.window_reach, sizeof *a->window_reach * a->cache_count) == 0);
    size_t own = 0, with = 0, both = 0, back = 0, back_both = 0;
    const int xw = fabsf(a->window[0].o.x - 2.0f) < 0.01f ? 0 : 1; /* the +x wall's */
    for (size_t i = 0; i < a->cache_count; i++) {
      if (a->cache_window[i] == 0xff) {
        CHECK(a->window_reach[i] == 0);
        continue;
      }
      with++;
      own += (a->window_reach[i] >> a->cache_window[i]) & 1u;
      both += a->window_reach[i] == 3u;
      const iris_cache *c = &g[0]->caches[i];
      if (c->p.x < -1.99f && c->frame.n.x > 0.99f && a->cache_window[i] == xw)
        back++, back_both += a->window_reach[i] == 3u;
    }
    printf("sky-room-corner: %zu caches with a window, %zu reach both; on the back wall %zu of %zu\n", with, both,
           back_both, back);
    CHECK(own == with);
    CHECK(back > 0 && back_both * 10 >= back * 8);
  }
  close_scene(s, g);
}

int main(void) {
  char dir[1024], path[1100];
  if (iris_test_tmpdir(dir, sizeof dir, "skyvis") != 0) return TEST_SKIP("no temporary folder");
  snprintf(path, sizeof path, "%s/map.exr", dir);
  iris_test_write_sun_map(path, 61, 29, 0.2f, 2, 300.0f);
  test_regions_and_mixture(path);
  test_built_from_scene();
  test_window_reach();
  iris_test_rmtree(dir);
  return iris_check_summary("guiding.skyvis");
}
