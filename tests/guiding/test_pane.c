/* guiding.pane: the sky through one refracting plane (renderer/guiding/pane.h;
 * docs/guiding.md, "Sky through a pane").
 *  - the map's sampling carried through the plane into the room against its
 *    density (the map's density at the refracted direction times the
 *    Jacobian eta^2 cos_room / cos_sky): chi-square over the sphere for a
 *    map with a sun, a tilted plane, entering glass (eta 1.5) and leaving it
 *    (eta 1/1.5, where some sky directions cannot reach the room: the
 *    sampler's lost mass must be missing from the density); the two
 *    directions' maps invert each other;
 *  - built on sky-room-pane (a window of one glass quad in the wall x = 2):
 *    most caches have a pane share, every plane is the window's (normal +x,
 *    eta 1.5: the light enters the quad's front), none in sky-room-glazed (its slab passes light
 *    straight: the share is sky_through's) or sky-room (no glass), and the
 *    same for 1 and 2 threads. Fails when photons through one refraction are
 *    not flagged, or flagged with the wrong side's normal or index. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "chi2.h"
#include "exr_map.h"
#include "guide_fixture.h"
#include "renderer/envmap.h"
#include "renderer/guiding/pane.h"
#include "scenes/builtin.h"

#define N_TESTS 2

typedef struct pane_ctx {
  const iris_envmap *env;
  iris_vec3 n;
  float eta;
} pane_ctx;

static bool pane_sample(void *vc, const double u[3], double dir[3]) {
  pane_ctx *c = vc;
  iris_vec3 ws, wr;
  float pdf;
  if (!iris_envmap_sample(c->env, (float)u[0], (float)u[1], &ws, &pdf, NULL)) return false;
  if (!iris_pane_to_room(c->n, c->eta, ws, &wr)) return false;
  dir[0] = wr.x, dir[1] = wr.y, dir[2] = wr.z;
  return true;
}
static double pane_pdf(void *vc, const double dir[3]) {
  pane_ctx *c = vc;
  iris_vec3 ws, wr = iris_v3((float)dir[0], (float)dir[1], (float)dir[2]);
  float jac;
  if (!iris_pane_to_sky(c->n, c->eta, wr, &ws, &jac)) return 0.0;
  return (double)iris_envmap_pdf(c->env, ws) * (double)jac;
}

static void test_density(const char *path) {
  iris_envmap env;
  if (!CHECK(test_envmap_open(path, 40.0f, &env))) return;
  const float etas[2] = {1.5f, 1.0f / 1.5f};
  chi2_domain dom = {CHI2_SPHERE, 32, 64, 29};
  for (int k = 0; k < 2; ++k) {
    pane_ctx c = {&env, iris_normalize(iris_v3(0.3f, 0.9f, -0.2f)), etas[k]};
    const size_t n = 200000;
    chi2_result r = chi2_run(&dom, pane_sample, pane_pdf, &c, n, 0.01, N_TESTS);
    iris_check_record(r.passed, __FILE__, __LINE__, "pane, eta %.3f: %s", (double)c.eta, r.message);
    /* the density integrates to the share of the map's samples that reach the room */
    const double reach = 1.0 - (double)r.lost / (double)n;
    iris_check_record(fabs(r.pdf_integral - reach) < 0.01, __FILE__, __LINE__,
                      "pane, eta %.3f: density integrates to %.4f, %.4f of the samples reach the room", (double)c.eta,
                      r.pdf_integral, reach);
    printf("pane, eta %.3f: p = %.3g, density integral %.4f, samples reaching the room %.4f\n", (double)c.eta,
           r.p_value, r.pdf_integral, reach);
    /* the maps invert each other */
    int bad = 0;
    uint64_t state = 5;
    for (int i = 0; i < 10000; ++i) {
      double u[3] = {chi2_uniform(&state), chi2_uniform(&state), chi2_uniform(&state)}, d[3];
      if (!pane_sample(&c, u, d)) continue;
      iris_vec3 wr = iris_v3((float)d[0], (float)d[1], (float)d[2]), ws, back;
      float jac;
      if (!iris_pane_to_sky(c.n, c.eta, wr, &ws, &jac) || !iris_pane_to_room(c.n, c.eta, ws, &back) ||
          iris_dot(back, wr) < 0.99999f)
        bad++;
    }
    CHECK(bad == 0);
  }
  iris_envmap_destroy(&env);
}

typedef struct panes {
  int caches, shared, window, other_plane, slabbed;
  float *values; /* per cache: share, normal, eta */
} panes;

static panes built(const char *scene, int threads) {
  panes p;
  memset(&p, 0, sizeof p);
  iris_scene *sc = NULL;
  iris_error err;
  if (!CHECK(iris_builtin_create(scene, &sc, &err) == IRIS_OK)) return p;
  iris_guiding_params gp = iris_guiding_params_default();
  gp.force = true;
  gp.train_spp = 0;
  iris_guiding *g = test_guide_build(sc, IRIS_METHOD_GUIDED_NEE, gp, 5, threads, 16);
  if (CHECK(g && !g->stats.skipped)) {
    p.caches = (int)g->cache_count;
    p.values = malloc(sizeof(float) * 5 * (g->cache_count ? g->cache_count : 1));
    for (size_t i = 0; i < g->cache_count; ++i) {
      const iris_cache *c = &g->caches[i];
      if (p.values) {
        p.values[5 * i] = c->pane_share;
        memcpy(&p.values[5 * i + 1], c->pane, sizeof c->pane);
      }
      p.slabbed += c->sky_through > 0.0f;
      if (!(c->pane_share > 0.0f)) continue;
      p.shared++;
      /* the quad's front faces the sky (+x): the light enters glass of index 1.5 */
      const bool window = c->pane[0] > 0.999f && fabsf(c->pane[3] - 1.5f) < 1e-4f;
      p.window += window;
      p.other_plane += !window;
    }
    printf("%s (%d threads): %d caches, %d with a pane share (%d the window's plane, %d another), %d with sky "
           "through a slab\n",
           scene, threads, p.caches, p.shared, p.window, p.other_plane, p.slabbed);
  }
  iris_guiding_destroy(g);
  iris_scene_destroy(sc);
  return p;
}

static void test_built(void) {
  panes a = built("sky-room-pane", 1), b = built("sky-room-pane", 2);
  iris_check_record(a.caches > 0 && a.shared > a.caches / 3, __FILE__, __LINE__,
                    "sky-room-pane: only %d of %d caches have a pane share", a.shared, a.caches);
  CHECK(a.other_plane == 0 && a.window == a.shared);
  CHECK(a.caches == b.caches && a.values && b.values &&
        memcmp(a.values, b.values, sizeof(float) * 5 * (size_t)a.caches) == 0);
  panes glazed = built("sky-room-glazed", 2), open = built("sky-room", 2);
  CHECK(glazed.caches > 0 && glazed.shared == 0 && glazed.slabbed > 0);
  CHECK(open.caches > 0 && open.shared == 0);
  free(a.values), free(b.values), free(glazed.values), free(open.values);
}

int main(void) {
  char dir[1024], path[1100];
  if (iris_test_tmpdir(dir, sizeof dir, "pane") != 0) return TEST_SKIP("no temporary folder");
  snprintf(path, sizeof path, "%s/map.exr", dir);
  iris_test_write_sun_map(path, 61, 29, 0.2f, 2, 300.0f);
  test_density(path);
  iris_test_rmtree(dir);
  test_built();
  return iris_check_summary("guiding.pane");
}
