/* --method auto (docs/guiding.md, "--method auto"):
 *  - it resolves to guided-nee on door and door-shielded and to mis on
 *    veach-mis, furnace-diffuse, a scene without lights and a view of nothing
 *    but mirrors, with the reason recorded in the result; stress-caustic, lit
 *    mostly directly, keeps its guide for the light its glass focuses, and so
 *    do the glass spheres on every seed (with light tracing off), their pilot
 *    going on where it holds too few caustic photons to decide; both render
 *    guided-nee without a race; with light tracing the glass spheres render
 *    mis, which traces light off their metal spheres;
 *  - the pilot traces fewer photon paths than the full pass and takes the
 *    decision the full pass takes (the same build with --pilot 0), and where
 *    guiding goes on the guide is the one built without a pilot (same photon
 *    count, same caches);
 *  - `auto` agrees with mis on door per image (3 sigma) and per 8x8 block
 *    (Bonferroni for 0.1% family-wise, never below 3 sigma), z on the
 *    variance of the mean (tests/common/film_stats.h);
 *  - the budget's cache resolution: 16 on sky-room (sky-lit), 8 on door.
 * The summary line, --json and the EXR metadata: guiding.auto_cli. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "render_run.h"
#include "film_stats.h"
#include "renderer/guiding/guiding.h"
#include "renderer/render.h"
#include "scenes/builtin.h"

/* The guiding provider, keeping the stats of the last guide it built. */
static iris_guiding_stats g_stats;
static size_t g_caches;
static iris_status keep_build(const iris_guide_setup *setup, iris_direction_sampler *out, void **state,
                              iris_error *err) {
  iris_status st = iris_guiding_provider.build(setup, out, state, err);
  if (st == IRIS_OK && *state) {
    g_stats = ((const iris_guiding *)*state)->stats;
    g_caches = ((const iris_guiding *)*state)->cache_count;
  }
  return st;
}
static void keep_destroy(void *state) { iris_guiding_provider.destroy(state); }
static bool keep_decision(const void *state, char *why, size_t size, bool *settled) {
  return iris_guiding_provider.decision(state, why, size, settled);
}
static const iris_guide_provider KEEP = {keep_build, keep_destroy, keep_decision, NULL, NULL};

static bool g_light_trace_off; /* renders with --light-trace off */

/* Renders `s` with `method` (spp samples, w x h); pilot: -1 auto, 0 none. */
static bool render(const iris_scene *s, iris_method method, int w, int h, int spp, uint64_t seed, int64_t pilot,
                   iris_render_result *r) {
  iris_render_params p = iris_test_params(w, h, spp, method, seed);
  p.light_trace = g_light_trace_off ? IRIS_LIGHT_TRACE_OFF : IRIS_LIGHT_TRACE_AUTO;
  iris_guiding_params gp = iris_guiding_params_default();
  gp.pilot_paths = pilot;
  p.threads = 2;
  p.guide = &KEEP;
  p.guide_options = &gp;
  memset(&g_stats, 0, sizeof g_stats);
  g_caches = 0;
  return iris_test_render(s, &p, r);
}

typedef struct expectation {
  const char *name;     /* built-in scene, or "no-lights" / "mirrors" (cornell-box changed) */
  iris_method resolved;
  const char *reason;   /* in the result's reason */
} expectation;

static iris_scene *make_scene(const char *name) {
  iris_scene *s = NULL;
  iris_error err;
  iris_error_clear(&err);
  const char *base = !strcmp(name, "no-lights") || !strcmp(name, "mirrors") ? "cornell-box"
                     : !strcmp(name, "spheres-glass")                       ? "env-spheres"
                                                                            : name;
  if (iris_builtin_create(base, &s, &err) != IRIS_OK) return NULL;
  if (!strcmp(name, "no-lights")) {
    for (size_t i = 0; i < s->material_count; i++)
      for (int k = 0; k < 3; k++) s->materials[i].emission[k] = 0.0f;
    s->light_count = 0; /* the box's lights are its emitting materials; keep none */
  }
  if (!strcmp(name, "spheres-glass")) /* env-spheres, the matte sphere clear glass (issue 31's spheres) */
    for (size_t i = 0; i < s->material_count; i++)
      if (!strcmp(s->materials[i].name, "matte")) {
        s->materials[i].type = IRIS_MATERIAL_GLASS;
        s->materials[i].roughness = 0.0f;
        s->materials[i].ior = 1.5f;
        for (int k = 0; k < 3; k++) s->materials[i].color[k] = 1.0f;
      }
  if (!strcmp(name, "mirrors")) /* every surface a perfect mirror, the light's too (it still emits) */
    for (size_t i = 0; i < s->material_count; i++) {
      iris_material *m = &s->materials[i];
      m->type = IRIS_MATERIAL_GLOSSY;
      m->roughness = 0.0f;
    }
  return s;
}

static void test_decisions(void) {
  static const expectation E[] = {
      {"door", IRIS_METHOD_GUIDED_NEE, "the race: guided-nee"},
      {"door-shielded", IRIS_METHOD_GUIDED_NEE, "the race: guided-nee"},
      {"office", IRIS_METHOD_MIS, "the race: guided-nee 0."},
      {"cornell-box", IRIS_METHOD_MIS, "what the camera sees is lit mostly directly"},
      /* 51-53% indirect: the race decides (the rule's 50% sends only what is
       * lit mostly directly to mis; at 55% stress-thin-walls went to mis where
       * guided-nee is 1.14-1.24x better at equal time) */
      {"stress-glossy-room", IRIS_METHOD_MIS, "the race: guided-nee 0."},
      {"stress-thin-walls", IRIS_METHOD_GUIDED_NEE, "the race: guided-nee"},
      /* 28% indirect photons, but 29% of their energy focused through the
       * glass sphere: light only the guide finds, and which a race's few paths
       * per pixel rarely carry (at this test's 32 x 24 and 1 spp they held a
       * few of the caustic's fireflies on guided-nee's side and the race said
       * mis, where at 96 x 72 and 4 s guided-nee is 2.4x mis): guided-nee
       * without a race (docs/guiding.md, "--method auto") */
      {"stress-caustic", IRIS_METHOD_GUIDED_NEE, "light focused through glass carries"},
      {"veach-mis", IRIS_METHOD_MIS, "lit mostly directly"},
      {"furnace-diffuse", IRIS_METHOD_MIS, "lit mostly directly"},
      {"no-lights", IRIS_METHOD_MIS, "no lights"},
      {"mirrors", IRIS_METHOD_MIS, "perfect mirror or glass"},
  };
  for (size_t i = 0; i < sizeof E / sizeof E[0]; i++) {
    iris_scene *s = make_scene(E[i].name);
    if (!CHECK(s != NULL)) continue;
    iris_render_result r, full;
    if (CHECK(render(s, IRIS_METHOD_AUTO, 32, 24, 1, 1, -1, &r))) {
      iris_guiding_stats pilot = g_stats;
      size_t caches = g_caches;
      printf("%-16s %s | pilot %llu paths, share %.3f | full %llu paths, share %.3f\n", E[i].name, r.method_reason,
             (unsigned long long)pilot.pilot_paths, pilot.pilot_share, (unsigned long long)pilot.photon_paths,
             pilot.indirect_share);
      CHECK_EQ_STR(iris_method_name(r.method), iris_method_name(E[i].resolved));
      /* the caustic rule keeps the guide on stress-caustic alone of these */
      iris_check_record((pilot.caustic_share >= 0.1) == !strcmp(E[i].name, "stress-caustic"), __FILE__, __LINE__,
                        "%s: caustic share %.3f", E[i].name, pilot.caustic_share);
      CHECK_EQ_INT(r.method_requested, IRIS_METHOD_AUTO);
      iris_check_record(strncmp(r.method_reason, "auto: ", 6) == 0 && strstr(r.method_reason, E[i].reason),
                        __FILE__, __LINE__, "%s: reason '%s' should name '%s'", E[i].name, r.method_reason,
                        E[i].reason);
      /* the same build deciding on the full photon pass only: the same
       * choice, unless the 50% rule's share lies within the noise of its
       * ~4096 sampled photons of the threshold (the rule then sees other
       * photons than the pilot's and may go either way: stress-thin-walls) */
      const double seen = pilot.seen_indirect_energy;
      const bool borderline = seen >= 0.0 && fabs(seen - IRIS_GUIDING_AUTO_SEEN_INDIRECT_MIN) < 0.03;
      if (borderline) printf("%-16s the rule's share %.3f is within 0.03 of its threshold: pilot and full pass may differ\n",
                             E[i].name, seen);
      if (!borderline && CHECK(render(s, IRIS_METHOD_AUTO, 32, 24, 1, 1, 0, &full))) {
        CHECK_EQ_STR(iris_method_name(full.method), iris_method_name(r.method));
        CHECK_EQ_INT(g_stats.pilot_paths, 0);
        if (pilot.pilot_paths > 0) { /* a pilot ran: fewer paths than the full pass */
          CHECK(pilot.pilot_paths < g_stats.photon_paths);
          CHECK_EQ_INT(pilot.pilot_paths, iris_guiding_pilot_paths(g_stats.photon_paths));
          /* the pilot's share lies on the full pass's side of 30% */
          CHECK((pilot.pilot_share < 0.3) == (g_stats.indirect_share < 0.3));
        }
        if (r.method == IRIS_METHOD_GUIDED_NEE) { /* the pilot's photons are the full pass's first */
          CHECK_EQ_INT(pilot.photon_paths, g_stats.photon_paths);
          CHECK_EQ_INT(pilot.photons_stored, g_stats.photons_stored);
          CHECK_EQ_INT(pilot.photons_indirect, g_stats.photons_indirect);
          CHECK_EQ_INT(caches, g_caches);
          size_t n = (size_t)r.film.width * (size_t)r.film.height;
          bool same = true;
          for (size_t k = 0; k < n && same; k++) {
            iris_vec3 a, b, va, vb;
            iris_film_pixel(&r.film, (int)(k % (size_t)r.film.width), (int)(k / (size_t)r.film.width), &a, &va);
            iris_film_pixel(&full.film, (int)(k % (size_t)full.film.width), (int)(k / (size_t)full.film.width), &b,
                            &vb);
            same = a.x == b.x && a.y == b.y && a.z == b.z;
          }
          iris_check_record(same, __FILE__, __LINE__, "%s: the image with a pilot differs from the one without",
                            E[i].name);
        }
        if (r.method == IRIS_METHOD_MIS && pilot.pilot_paths > 0 && !r.raced) /* skipped before the full pass */
          CHECK_EQ_INT(pilot.photon_paths, 0);
        iris_render_result_destroy(&full);
      }
      iris_render_result_destroy(&r);
    }
    iris_scene_destroy(s);
  }
}

/* The caustic rule on a scene whose pilot finds few caustic photons: env-spheres
 * with a glass sphere, lit mostly directly (2-3% indirect photons), where the
 * photons the glass focuses carry 0.16-0.22 of the indirect energy on every
 * seed but a 16384-path pilot holds only 14-22 of them, around the rule's
 * minimum of 16. The pilot goes on while they are too few to decide, so every
 * seed keeps the guide (without that, seeds whose pilot held 14 or 15 went to
 * mis without a race). The light the guide was kept for is what a race's few
 * paths per pixel rarely carry (the race said mis on one seed of eight at
 * 108 x 72), so guided-nee renders without one. All that with light tracing
 * off; with it (the default) mis traces light paths off the metal spheres
 * and the caustic rule yields: mis on every seed, with light tracing. */
static void test_caustic_pilot(void) {
  iris_scene *s = make_scene("spheres-glass");
  if (!CHECK(s != NULL)) return;
  int traced = 0;
  for (int seed = 0; seed < 4; seed++) {
    iris_render_result r;
    if (!CHECK(render(s, IRIS_METHOD_AUTO, 32, 24, 1, (uint64_t)seed, -1, &r))) continue;
    printf("spheres-glass seed %d with light tracing: %s\n", seed, r.method_reason);
    traced += r.method == IRIS_METHOD_MIS && !r.raced && r.film.light_sum != NULL &&
              strstr(r.method_reason, "mis traces light paths off the glossy reflectors") != NULL;
    iris_render_result_destroy(&r);
  }
  iris_check_record(traced == 4, __FILE__, __LINE__, "mis with light tracing on %d of 4 seeds", traced);
  g_light_trace_off = true;
  int kept = 0, extended = 0, unraced = 0;
  const int seeds = 8;
  for (int seed = 0; seed < seeds; seed++) {
    iris_render_result r;
    if (!CHECK(render(s, IRIS_METHOD_AUTO, 32, 24, 1, (uint64_t)seed, -1, &r))) continue;
    const uint64_t first = iris_guiding_pilot_paths(g_stats.photon_paths > 0 ? g_stats.photon_paths : 1);
    printf("spheres-glass seed %d: pilot %llu paths, caustic share %.3f: %s\n", seed,
           (unsigned long long)g_stats.pilot_paths, g_stats.caustic_share, r.method_reason);
    kept += g_stats.caustic_share >= 0.1;
    extended += g_stats.photon_paths > 0 && g_stats.pilot_paths > first;
    /* what the guide was kept for, a race cannot measure: guided-nee without one */
    unraced += r.method == IRIS_METHOD_GUIDED_NEE && !r.raced;
    iris_render_result_destroy(&r);
  }
  iris_check_record(kept == seeds, __FILE__, __LINE__, "the caustic rule kept the guide on %d of %d seeds", kept,
                    seeds);
  iris_check_record(extended >= 1, __FILE__, __LINE__, "no seed's pilot went on (%d)", extended);
  iris_check_record(unraced == seeds, __FILE__, __LINE__, "guided-nee without a race on %d of %d seeds", unraced,
                    seeds);
  g_light_trace_off = false;
  iris_scene_destroy(s);
}

/* A scene's own method wins over auto; without a guide provider auto is mis. */
static void test_defaults(void) {
  iris_scene *s = make_scene("door");
  if (!CHECK(s != NULL)) return;
  iris_render_params p = iris_render_params_default();
  iris_render_params_from_scene(&p, s);
  CHECK_EQ_STR(iris_method_name(p.method), "auto");
  snprintf(s->render.method, sizeof s->render.method, "nee");
  p = iris_render_params_default();
  iris_render_params_from_scene(&p, s);
  CHECK_EQ_STR(iris_method_name(p.method), "nee");
  s->render.method[0] = 0;
  p = iris_render_params_default();
  p.width = 16;
  p.height = 12;
  p.spp = 1;
  iris_render_result r;
  iris_error err;
  iris_error_clear(&err);
  if (CHECK(iris_render(s, &p, &r, &err) == IRIS_OK)) {
    CHECK_EQ_STR(iris_method_name(r.method), "mis");
    CHECK(strstr(r.method_reason, "not linked in") != NULL);
    iris_render_result_destroy(&r);
  }
  iris_scene_destroy(s);
}

/* auto (guided-nee on door) agrees with mis. */
static void test_unbiased(void) {
  iris_scene *s = make_scene("door");
  if (!CHECK(s != NULL)) return;
  const int w = 32, h = 24, spp = 128;
  const int bx = w / 8, by = h / 8, n_tests = 3 * bx * by;
  const double z_block = fmax(3.0, z_for_alpha(1e-3 / n_tests)), z_image = 3.0;
  iris_render_result a, m;
  bool ok_a = CHECK(render(s, IRIS_METHOD_AUTO, w, h, spp, 301, -1, &a));
  bool ok_m = CHECK(render(s, IRIS_METHOD_MIS, w, h, 2 * spp, 302, -1, &m));
  if (ok_a && ok_m) {
    CHECK_EQ_STR(iris_method_name(a.method), "guided-nee");
    double worst = iris_test_z_compare(&m.film, &a.film, bx, by, z_image, z_block, "door mis vs auto");
    printf("door: mis vs auto (%s): worst |z| = %.2f (image < %.1f, blocks < %.2f)\n", a.method_reason, worst,
           z_image, z_block);
    CHECK_EQ_INT(a.stats.nan_count, 0);
  }
  if (ok_a) iris_render_result_destroy(&a);
  if (ok_m) iris_render_result_destroy(&m);
  iris_scene_destroy(s);
}

/* The budget's map resolution: 16 where the sky holds most of the power
 * (sky-room: the window and the sun's patch are small), 8 for lamp-lit
 * scenes (door); an explicit --cache-res wins (docs/guiding.md). */
static void test_cache_res(void) {
  static const struct { const char *name; int res; } E[] = {{"door", 8}, {"sky-room", 16}};
  for (size_t i = 0; i < sizeof E / sizeof E[0]; i++) {
    iris_scene *s = make_scene(E[i].name);
    if (!CHECK(s != NULL)) continue;
    iris_render_result r;
    if (CHECK(render(s, IRIS_METHOD_GUIDED_NEE, 32, 24, 1, 1, 0, &r))) {
      printf("%s: cache res %d\n", E[i].name, g_stats.cache_res);
      CHECK_EQ_INT(g_stats.cache_res, E[i].res);
      iris_render_result_destroy(&r);
    }
    iris_scene_destroy(s);
  }
}

int main(void) {
  test_cache_res();
  test_defaults();
  test_decisions();
  test_caustic_pilot();
  test_unbiased();
  return iris_check_summary("guiding.auto");
}
