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
 *    not flagged, or flagged with the wrong side's normal or index;
 *  - at a point of the room's glossy sphere (roughness 0.25) lit by the sun
 *    through the pane, the map carried through the plane keeps at least
 *    alpha_max of its share (the lobe's roughness caps only the caches'
 *    part: docs/guiding.md, "Glass seen from glossy vertices"; fails with
 *    the cap on it), and every density the sampler returns there is the
 *    pdf's. (Chi-square of that whole sampler over the sphere takes minutes
 *    with the real map's sun; run once, the docs give its result.) */
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
#include "renderer/guiding/vertex.h"
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

/* The glossy sphere of sky-room (scenes/sky.c): centre and radius. */
static const iris_vec3 GLOSSY_C = {-0.8f, 0.5f, -0.9f};
#define GLOSSY_R 0.5f

static void test_glossy_vertex(void) {
  iris_scene *sc = NULL;
  test_guide_scene t;
  if (!test_guide_builtin_open("sky-room-pane", IRIS_METHOD_GUIDED_NEE, &sc, &t)) return;
  iris_guiding_params gp = iris_guiding_params_default();
  gp.force = true;
  iris_guiding *g = test_guide_build_in(sc, &t, gp, 5, 2, 64); /* trained: the caches learn alpha */
  if (g) g->env = t.lights.envmap; /* lent for rendering, as the provider does */
  iris_direction_sampler s = iris_guiding_sampler(g);
  int points = 0, tested = 0;
  if (CHECK(g && !g->stats.skipped && s.prepare != NULL)) {
    /* points of the sphere's lit side (towards the window, +x, and the sun's
     * patch): a ray from outside at the centre */
    for (int i = 0; i < 24; ++i) {
      const float a = -0.9f + 0.08f * (float)i, b = 0.15f * (float)(i % 5) - 0.1f;
      const iris_vec3 dir = iris_normalize(iris_v3(cosf(a), b, sinf(a)));
      iris_ray ray = {iris_add(GLOSSY_C, iris_scale(dir, 1.5f)), 0.0f, iris_neg(dir), 2.0f};
      iris_hit hit;
      if (!iris_accel_intersect(t.acc, &ray, &hit)) continue;
      iris_interaction si;
      iris_accel_interaction(t.acc, ray.d, &hit, &si);
      if (fabsf(iris_length(iris_sub(si.p, GLOSSY_C)) - GLOSSY_R) > 0.02f) continue; /* something else in front */
      iris_shading_point sp;
      iris_integrator_shade(&t.it, &si, dir, 1, &sp);
      s.prepare(s.ctx, &sp);
      const iris_guide_vertex_state *v = iris_guide_vertex_get(&sp.guide);
      float share = 0.0f; /* the tied caches' mean pane share, as the vertex took it */
      for (int k = 0; k < v->m; ++k) share += g->caches[v->ids[k]].pane_share + g->caches[v->ids[k]].sky_through;
      share = v->m > 0 ? share / (float)v->m : 0.0f;
      if (!(share > 0.05f)) continue;
      points++;
      /* the carried map's probability: at least alpha_max of its share (0.25 at most with the roughness cap) */
      iris_check_record(v->alpha * v->sky >= g->params.alpha_max * share * 0.999f, __FILE__, __LINE__,
                        "sphere point %d: the map through the pane drawn with probability %.3f, share %.3f", i,
                        (double)(v->alpha * v->sky), (double)share);
      /* the sampler's density is the pdf's, for MIS (bit for bit: the same fractions) */
      int drawn = 0, differ = 0;
      for (int k = 0; k < 20000; ++k) {
        iris_sampler rng = iris_sampler_start(0x70616e65ULL, (uint64_t)k, 0);
        iris_direction_sample ds;
        memset(&ds, 0, sizeof ds);
        if (!s.sample(s.ctx, &sp, &rng, &ds)) continue;
        drawn++;
        const float q = s.pdf(s.ctx, &sp, ds.wi);
        differ += !(fabsf(q - ds.pdf) <= 1e-5f * ds.pdf);
      }
      CHECK(drawn > 10000);
      iris_check_record(differ == 0, __FILE__, __LINE__, "sphere point %d: %d of %d sampled densities differ from the pdf",
                        i, differ, drawn);
      if (tested) continue;
      tested = 1;
      printf("glossy sphere at (%.2f, %.2f, %.2f): alpha %.3f, map share %.3f of it (pane share %.3f)\n",
             (double)si.p.x, (double)si.p.y, (double)si.p.z, (double)v->alpha, (double)v->sky, (double)share);
    }
  }
  printf("glossy sphere: %d points with a pane share\n", points);
  CHECK(points >= 4);
  iris_guiding_destroy(g);
  test_guide_scene_close(&t);
  iris_scene_destroy(sc);
}

int main(void) {
  char dir[1024], path[1100];
  if (iris_test_tmpdir(dir, sizeof dir, "pane") != 0) return TEST_SKIP("no temporary folder");
  snprintf(path, sizeof path, "%s/map.exr", dir);
  iris_test_write_sun_map(path, 61, 29, 0.2f, 2, 300.0f);
  test_density(path);
  iris_test_rmtree(dir);
  test_built();
  test_glossy_vertex();
  return iris_check_summary("guiding.pane");
}
