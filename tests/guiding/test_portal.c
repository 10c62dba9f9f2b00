/* Portals (renderer/guiding/portal.h, docs/guiding.md "Portals"):
 *  - a rectangle's sampler against its density: chi-square over the sphere,
 *    the density integrates to 1, every drawn direction has density > 0;
 *  - joining: rectangles in one plane that overlap join into the box of both,
 *    not across planes, sides or gaps;
 *  - on the door scene the caches whose indirect light came through the door
 *    find it: every portal lies in the door's plane within the door (plus 1
 *    cm), seen from room A, most of room A's caches have one, and their
 *    rectangles, joined and tightened to the opening's edges, cover 98% of
 *    the door (each cache alone sees a part; the 24 x 24 grid alone left 2-3
 *    cm strips out); none with portals off; the same for 1 and 2 threads;
 *  - the whole guided sampler at a room-A floor point with a portal passes
 *    chi-square over the sphere against its own pdf (which integrates to 1):
 *    the sampler and the MIS density agree with the portal in the mixture;
 *  - training keeps the door at nearly every room-A cache (candidates seen at
 *    grazing angles included), the same for 1 and 2 threads, and drops
 *    portals on corridor-rooms where their samples do not pay;
 *  - the portals survive the guide file bit for bit. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "chi2.h"
#include "guide_fixture.h"
#include "renderer/guiding/guide_file.h"
#include "renderer/guiding/portal.h"
#include "renderer/guiding/vertex.h"
#include "scenes/builtin.h"

#define N_TESTS 2

typedef struct rect_ctx {
  iris_portal p;
  iris_vec3 x;
} rect_ctx;

static bool rect_sample(void *vc, const double u[3], double dir[3]) {
  const rect_ctx *c = vc;
  iris_vec3 d = iris_portal_sample(&c->p, c->x, (float)u[0], (float)u[1]);
  dir[0] = d.x, dir[1] = d.y, dir[2] = d.z;
  return true;
}
static double rect_pdf(void *vc, const double dir[3]) {
  const rect_ctx *c = vc;
  return iris_portal_pdf(&c->p, c->x, iris_v3((float)dir[0], (float)dir[1], (float)dir[2]));
}

static void test_rectangle(void) {
  /* a door-like rectangle seen obliquely from 2.3 m */
  rect_ctx c = {{{0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 0.3f}, {0.0f, 1.0f, 0.0f}}, {-2.0f, 0.4f, 1.1f}};
  chi2_domain dom = {CHI2_SPHERE, 64, 128, 23};
  chi2_result r = chi2_run(&dom, rect_sample, rect_pdf, &c, 400000, 0.01, N_TESTS);
  iris_check_record(r.passed, __FILE__, __LINE__, "portal rectangle: %s", r.message);
  CHECK_NEAR(r.pdf_integral, 1.0, 5e-3);
  printf("rectangle: p = %.3g, pdf integral %.5f\n", r.p_value, r.pdf_integral);
  /* every drawn direction (corners included) has density, and the faces test */
  int zero = 0;
  for (int i = 0; i <= 64; ++i)
    for (int j = 0; j <= 64; ++j) {
      float u1 = fminf((float)i / 64.0f, IRIS_ONE_MINUS_EPSILON), u2 = fminf((float)j / 64.0f, IRIS_ONE_MINUS_EPSILON);
      zero += !(iris_portal_pdf(&c.p, c.x, iris_portal_sample(&c.p, c.x, u1, u2)) > 0.0f);
    }
  iris_check_record(zero == 0, __FILE__, __LINE__, "%d drawn directions with density 0", zero);
  CHECK(iris_portal_faces(&c.p, iris_v3(-1, 1, 0), c.x, iris_v3(1, 0, 0)));
  CHECK(!iris_portal_faces(&c.p, iris_v3(1, 1, 0), c.x, iris_v3(1, 0, 0)));  /* the other side's */
  CHECK(!iris_portal_faces(&c.p, iris_v3(-1, 1, 0), c.x, iris_v3(-1, 0, 0))); /* behind the surface */
  CHECK(!iris_portal_faces(&c.p, iris_v3(-1, 1, 0), iris_v3(-0.0005f, 0.5f, 1.0f), iris_v3(0, 1, 0))); /* in its plane */
}

static bool near3(iris_vec3 a, iris_vec3 b) { return iris_length(iris_sub(a, b)) < 1e-5f; }

static void test_join(void) {
  /* the door's plane x = 0, seen from x < 0 */
  const iris_vec3 side = iris_v3(-1.0f, 1.0f, 0.0f);
  const iris_portal low = {{0.0f, 0.5f, -0.1f}, {0.0f, 0.0f, 0.2f}, {0.0f, 0.5f, 0.0f}};  /* z [-0.3, 0.1], y [0, 1] */
  const iris_portal high = {{0.0f, 1.4f, 0.1f}, {0.0f, 0.6f, 0.0f}, {0.0f, 0.0f, -0.2f}}; /* z [-0.1, 0.3], y [0.8, 2] */
  iris_portal a = low;
  CHECK(iris_portal_join(&a, side, &high, iris_v3(-2.0f, 0.0f, 1.0f)));
  CHECK(near3(a.o, iris_v3(0.0f, 1.0f, 0.0f))); /* the box z [-0.3, 0.3], y [0, 2] */
  CHECK(fabsf(fabsf(iris_dot(a.u, iris_v3(0, 0, 1))) + fabsf(iris_dot(a.v, iris_v3(0, 0, 1))) - 0.3f) < 1e-5f);
  CHECK(fabsf(fabsf(iris_dot(a.u, iris_v3(0, 1, 0))) + fabsf(iris_dot(a.v, iris_v3(0, 1, 0))) - 1.0f) < 1e-5f);
  CHECK(fabsf(iris_dot(a.u, a.v)) < 1e-6f);
  /* not: seen from the other side, in a plane 10 cm behind, tilted 10 degrees, 1 m away */
  iris_portal b = low, other = high;
  CHECK(!iris_portal_join(&b, side, &high, iris_v3(1.0f, 1.0f, 0.0f)));
  other.o.x = 0.1f;
  CHECK(!iris_portal_join(&b, side, &other, side));
  other = high;
  other.u = iris_v3(0.6f * sinf(0.1745f), 0.6f * cosf(0.1745f), 0.0f);
  CHECK(!iris_portal_join(&b, side, &other, side));
  other = high;
  other.o.z += 1.0f;
  CHECK(!iris_portal_join(&b, side, &other, side));
  CHECK(memcmp(&b, &low, sizeof b) == 0); /* unchanged when refused */
}

static iris_guiding *build_trained(const iris_scene *sc, test_guide_scene *t, bool portals, int threads,
                                   int train_spp) {
  iris_guiding_params gp = iris_guiding_params_default();
  gp.portals = portals;
  gp.train_spp = train_spp;
  return test_guide_build_in(sc, t, gp, 7, threads, 16);
}

/* Without training (train_spp 0), as a short render builds it (16 spp: its 5% rounds to none). */
static iris_guiding *build(const iris_scene *sc, test_guide_scene *t, bool portals, int threads) {
  return build_trained(sc, t, portals, threads, 0);
}

/* Every portal in the door's plane (x = 0) within the door (z in [-0.3,
 * 0.3], y in [0, 2]) widened by 1 cm, found from room A; returns how many
 * room-A caches have one, *cover the mean share of the door's area their
 * rectangles cover. */
static int check_portals(const iris_guiding *g, double *cover) {
  int bad = 0, room_a = 0, found = 0;
  *cover = 0.0;
  for (size_t i = 0; i < g->cache_count; ++i) {
    const iris_cache *c = &g->caches[i];
    if (!(c->portal_weight > 0.0f)) continue;
    found++;
    const iris_portal *p = &c->portal;
    const float zext = fabsf(p->u.z) + fabsf(p->v.z), yext = fabsf(p->u.y) + fabsf(p->v.y);
    const bool ok = fabsf(p->o.x) < 0.01f && fabsf(p->u.x) < 1e-3f && fabsf(p->v.x) < 1e-3f &&
                    p->o.z - zext >= -0.31f && p->o.z + zext <= 0.31f && p->o.y - yext >= -0.01f &&
                    p->o.y + yext <= 2.01f && c->p.x < 0.0f;
    const double z0 = fmax(p->o.z - zext, -0.3), z1 = fmin(p->o.z + zext, 0.3);
    const double y0 = fmax(p->o.y - yext, 0.0), y1 = fmin(p->o.y + yext, 2.0);
    if (c->p.x < 0.0f) *cover += fmax(z1 - z0, 0.0) * fmax(y1 - y0, 0.0) / 1.2;
    if (!ok && bad++ < 5)
      printf("  portal of the cache at (%.2f, %.2f, %.2f): centre (%.2f, %.2f, %.2f), half-axes (%.2f, %.2f, %.2f), "
             "(%.2f, %.2f, %.2f)\n",
             (double)c->p.x, (double)c->p.y, (double)c->p.z, (double)p->o.x, (double)p->o.y, (double)p->o.z,
             (double)p->u.x, (double)p->u.y, (double)p->u.z, (double)p->v.x, (double)p->v.y, (double)p->v.z);
    room_a += c->p.x < 0.0f;
  }
  iris_check_record(bad == 0, __FILE__, __LINE__, "%d of %d portals not the door seen from room A", bad, found);
  if (room_a > 0) *cover /= room_a;
  return room_a;
}

static void test_door(void) {
  iris_scene *sc = NULL;
  iris_error err;
  test_guide_scene t;
  if (!test_guide_builtin_open("door", IRIS_METHOD_GUIDED_NEE, &sc, &t)) return;
  iris_guiding *g = build(sc, &t, true, 1);
  if (!CHECK(g != NULL)) {
    test_guide_scene_close(&t);
    iris_scene_destroy(sc);
    return;
  }
  size_t room_a_caches = 0;
  for (size_t i = 0; i < g->cache_count; ++i) room_a_caches += g->caches[i].p.x < -0.05f;
  double cover;
  const int room_a = check_portals(g, &cover);
  printf("door: %llu caches with a portal, %d of room A's %zu, covering %.0f%% of the door on average\n",
         (unsigned long long)g->stats.portal_caches, room_a, room_a_caches, 100.0 * cover);
  iris_check_record(room_a >= 30 && (double)room_a >= 0.6 * (double)room_a_caches, __FILE__, __LINE__,
                    "only %d of room A's %zu caches found the door", room_a, room_a_caches);
  iris_check_record(cover >= 0.98, __FILE__, __LINE__, "room A's portals cover %.0f%% of the door on average",
                    100.0 * cover);
  /* the same with 2 threads */
  {
    iris_guiding *g2 = build(sc, &t, true, 2);
    int differ = !g2 || g2->cache_count != g->cache_count;
    for (size_t i = 0; !differ && i < g->cache_count; ++i)
      differ += memcmp(&g->caches[i].portal, &g2->caches[i].portal, sizeof g->caches[i].portal) != 0 ||
                g->caches[i].portal_weight != g2->caches[i].portal_weight;
    iris_check_record(!differ, __FILE__, __LINE__, "portals differ between 1 and 2 threads");
    iris_guiding_destroy(g2);
  }
  /* Training keeps the candidates (the door seen at grazing angles from
   * beside it: a small share of the caches' coarse maps) where its samples
   * say the door lowers their second moment: nearly all of room A, where
   * without training only those with 5% of their light through it have it;
   * the same for 1 and 2 threads. */
  {
    iris_guiding *gt = build_trained(sc, &t, true, 1, 8), *gt2 = build_trained(sc, &t, true, 2, 8);
    if (CHECK(gt != NULL && gt2 != NULL)) {
      double cover_t;
      const int room_a_t = check_portals(gt, &cover_t);
      printf("door, trained (8 spp): %d of room A's caches keep the door\n", room_a_t);
      iris_check_record((double)room_a_t >= 0.9 * (double)room_a_caches && room_a_t > room_a, __FILE__, __LINE__,
                        "training kept the door at %d of room A's %zu caches (%d without training)", room_a_t,
                        room_a_caches, room_a);
      int differ = gt->cache_count != gt2->cache_count;
      for (size_t i = 0; !differ && i < gt->cache_count; ++i)
        differ += memcmp(&gt->caches[i].portal, &gt2->caches[i].portal, sizeof gt->caches[i].portal) != 0;
      iris_check_record(!differ, __FILE__, __LINE__, "trained portals differ between 1 and 2 threads");
    }
    iris_guiding_destroy(gt);
    iris_guiding_destroy(gt2);
  }
  /* none with portals off */
  {
    iris_guiding *g3 = build(sc, &t, false, 1);
    if (CHECK(g3 != NULL)) CHECK_EQ_INT((int)g3->stats.portal_caches, 0);
    iris_guiding_destroy(g3);
  }
  /* the whole sampler at a room-A floor point whose vertex takes a portal */
  iris_direction_sampler s = iris_guiding_sampler(g);
  bool tested = false;
  for (int i = 0; i < 40 && !tested && CHECK(s.sample != NULL); ++i) {
    iris_shading_point sp;
    if (!test_shade_below(&t, iris_v3(-3.6f + 0.08f * (float)i, 0.0f, -1.7f + 0.085f * (float)i), &sp)) continue;
    s.prepare(s.ctx, &sp);
    const iris_guide_vertex_state *v = iris_guide_vertex_get(&sp.guide);
    if (!(v->portal > 0.0f && v->alpha > 0.0f)) continue;
    tested = true;
    chi2_result r = test_full_chi2(s, &sp, 0x706f7274ULL, N_TESTS, "a portal", __FILE__, __LINE__);
    printf("  sampler at (%.2f, 0, %.2f): alpha %.2f, portal %.2f: p = %.3g, pdf integral %.5f\n",
           (double)sp.si.p.x, (double)sp.si.p.z, (double)v->alpha, (double)v->portal, r.p_value, r.pdf_integral);
  }
  iris_check_record(tested, __FILE__, __LINE__, "no room-A floor point with a portal");
  /* the guide file keeps them bit for bit */
  char path[256];
  const char *tmp = getenv("TMPDIR");
  snprintf(path, sizeof path, "%s/iris_test_portal_%ld.guide", tmp ? tmp : "/tmp", (long)getpid());
  iris_guiding *l = NULL;
  if (CHECK(iris_guiding_save(g, path, 1, 2, &err) == IRIS_OK) &&
      CHECK(iris_guiding_load(path, 1, 2, 1, &l, &err) == IRIS_OK)) {
    int differ = l->cache_count != g->cache_count;
    for (size_t i = 0; !differ && i < g->cache_count; ++i)
      differ += memcmp(&g->caches[i].portal, &l->caches[i].portal, sizeof g->caches[i].portal) != 0 ||
                g->caches[i].portal_weight != l->caches[i].portal_weight;
    iris_check_record(!differ, __FILE__, __LINE__, "portals differ after the guide file");
    CHECK(l->stats.portal_caches == g->stats.portal_caches);
  }
  iris_guiding_destroy(l);
  remove(path);
  iris_guiding_destroy(g);
  test_guide_scene_close(&t);
  iris_scene_destroy(sc);
}

/* Training also drops portals: on corridor-rooms (rooms with their own
 * lamps along a corridor) many caches that found a doorway get little from
 * its samples; with training fewer caches keep a portal than without, though
 * training also weighs every candidate that the rule without it refuses. */
static void test_trained_drop(void) {
  iris_scene *sc = NULL;
  test_guide_scene t;
  if (!test_guide_builtin_open("corridor-rooms", IRIS_METHOD_GUIDED_NEE, &sc, &t)) return;
  iris_guiding *g0 = build(sc, &t, true, 2), *g1 = build_trained(sc, &t, true, 2, 8);
  if (CHECK(g0 != NULL && g1 != NULL)) {
    printf("corridor-rooms: %llu caches with a portal without training, %llu with 8 spp of it\n",
           (unsigned long long)g0->stats.portal_caches, (unsigned long long)g1->stats.portal_caches);
    iris_check_record(g0->stats.portal_caches > 0 && g1->stats.portal_caches < g0->stats.portal_caches, __FILE__,
                      __LINE__, "training dropped no portal on corridor-rooms (%llu, then %llu)",
                      (unsigned long long)g0->stats.portal_caches, (unsigned long long)g1->stats.portal_caches);
  }
  iris_guiding_destroy(g0);
  iris_guiding_destroy(g1);
  test_guide_scene_close(&t);
  iris_scene_destroy(sc);
}

int main(void) {
  test_rectangle();
  test_join();
  test_door();
  test_trained_drop();
  return iris_check_summary("guiding.portal");
}
