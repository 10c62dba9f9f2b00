/* guiding.glints: glints (renderer/guiding/glints.h; docs/guiding.md, "Glints").
 *  - built on env-spheres (the map's sun and a metal sphere of roughness
 *    0.05): glint photons land on the ground, and at ground points around
 *    that sphere the spot a vertex finds holds the sphere's true mirror
 *    reflection of the sun's direction (the point whose reflection of the
 *    direction to x is the sun's), found by iteration on the sphere; most
 *    such points find a spot, and the spots are small (a tenth of the
 *    sphere); nothing with params.glints off; the same glint photons and
 *    shares for 1 and 2 threads and after a guide file, which refuses a
 *    glint photon with a NaN or a zero energy (checksum resealed);
 *  - guided-nee asked for by name keeps its guide on env-spheres (lit mostly
 *    directly) for its glints, not on veach-mis, nor without glints;
 *  - the whole guided sampler (BSDF, caches, the spot's cone) at a ground
 *    point that has a spot, against its own pdf: chi-square over the sphere
 *    and the pdf's integral. Fails when glint photons are not kept or keep
 *    the wrong smooth point, and when the cone's density is left out of the
 *    mixture;
 *  - glass that bends a lamp's light is a glint surface too: a small lamp
 *    above one horizontal glass quad (one refracting surface, as a shade is
 *    often modelled): floor points under it find spots that hold the point
 *    where Snell's law joins them to the lamp (solved in their vertical
 *    plane); light straight on through glass slabs is not a glint
 *    (lamp-shade: no cache gets a glint share and no glint photon is traced).
 *    Fails when glass is not a smooth surface, and when a slab's straight
 *    light counts. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "core/fileio.h"
#include "chi2.h"
#include "guide_fixture.h"
#include "renderer/guiding/guide_file.h"
#include "renderer/guiding/vertex.h"
#include "scenes/builtin.h"

#define N_TESTS 1

/* env-spheres' metal sphere of roughness 0.05 (scenes/sky.c) */
static const iris_vec3 SPHERE_C = {-0.7f, 0.6f, 0.0f};
#define SPHERE_R 0.6f

/* The direction of the map's brightest texel: its sun. */
static iris_vec3 sun_direction(const iris_envmap *env) {
  size_t best = 0;
  float lum = -1.0f;
  for (size_t i = 0; i < (size_t)env->width * (size_t)env->height; ++i) {
    const float l = env->rgb[3 * i] + env->rgb[3 * i + 1] + env->rgb[3 * i + 2];
    if (l > lum) lum = l, best = i;
  }
  const float s = ((float)(best % (size_t)env->width) + 0.5f) / (float)env->width,
              t = ((float)(best / (size_t)env->width) + 0.5f) / (float)env->height;
  return iris_envmap_st_to_dir(env, s, t);
}

/* The point of the sphere whose mirror reflection of the direction to x is
 * `sun`: its normal bisects the sun and the direction to x (fixed point). */
static bool mirror_point(iris_vec3 x, iris_vec3 sun, iris_vec3 *p) {
  iris_vec3 n = sun;
  for (int i = 0; i < 400; ++i) {
    const iris_vec3 q = iris_add(SPHERE_C, iris_scale(n, SPHERE_R));
    const iris_vec3 r = iris_normalize(iris_sub(x, q));
    n = iris_normalize(iris_add(iris_scale(n, 0.5f), iris_scale(iris_normalize(iris_add(sun, r)), 0.5f)));
  }
  *p = iris_add(SPHERE_C, iris_scale(n, SPHERE_R));
  const iris_vec3 r = iris_normalize(iris_sub(x, *p));
  /* converged, seen from x, and lit by the sun */
  return iris_dot(iris_normalize(iris_add(sun, r)), n) > 0.99999f && iris_dot(r, n) > 0.05f && iris_dot(sun, n) > 0.05f;
}

static iris_guiding *build(const iris_scene *sc, test_guide_scene *t, bool glints, int threads) {
  iris_guiding_params gp = iris_guiding_params_default();
  gp.glints = glints;
  gp.force = true; /* lit mostly directly: the guide would be skipped */
  return test_guide_build_in(sc, t, gp, 7, threads, 16);
}

static void check_round_trip(const iris_guiding *g, const iris_vec3 *xs, int nx) {
  char path[256];
  const char *tmp = getenv("TMPDIR");
  snprintf(path, sizeof path, "%s/iris_test_glints_%ld.guide", tmp ? tmp : "/tmp", (long)getpid());
  iris_error err;
  iris_error_clear(&err);
  iris_guiding *l = NULL;
  if (CHECK(iris_guiding_save(g, path, 1, 2, &err) == IRIS_OK) &&
      CHECK(iris_guiding_load(path, 1, 2, 1, &l, &err) == IRIS_OK)) {
    CHECK(l->glints.count == g->glints.count && l->glints.radius2 == g->glints.radius2 &&
          memcmp(l->glints.photons, g->glints.photons, sizeof *g->glints.photons * g->glints.count) == 0);
    int differ = l->cache_count != g->cache_count;
    for (size_t i = 0; !differ && i < g->cache_count; ++i) differ += l->caches[i].glint_share != g->caches[i].glint_share;
    for (int i = 0; i < nx; ++i) {
      iris_guide_lamp a = {{0, 0, 0}, 0}, b = {{0, 0, 0}, 0};
      const bool fa = iris_glints_spot(&g->glints, xs[i], iris_v3(0, 1, 0), &a),
                 fb = iris_glints_spot(&l->glints, xs[i], iris_v3(0, 1, 0), &b);
      differ += fa != fb || memcmp(&a, &b, sizeof a) != 0;
    }
    iris_check_record(!differ, __FILE__, __LINE__, "glint shares or spots differ after the guide file");
  }
  iris_guiding_destroy(l);
  l = NULL;
  /* Forged with a valid checksum: a NaN in the first glint photon (they come last), and an
   * energy of 0 in the last one: each refused in one line naming the file and the photon. */
  char *data = NULL;
  size_t n = 0;
  if (CHECK(iris_file_read(path, 0, &data, &n, &err) == IRIS_OK) && CHECK(n > 40u * g->glints.count + 48)) {
    const size_t first = n - 40u * g->glints.count, last_energy = n - 4;
    const struct {
      size_t at;
      uint32_t bits;
      const char *want;
    } forges[] = {{first, 0x7fc00000u, "glint photon 0: invalid values"},
                  {last_energy, 0u, "invalid values"}};
    for (size_t f = 0; f < sizeof forges / sizeof forges[0]; ++f) {
      unsigned char *c = malloc(n);
      if (!CHECK(c)) break;
      memcpy(c, data, n);
      for (int i = 0; i < 4; ++i) c[forges[f].at + (size_t)i] = (unsigned char)(forges[f].bits >> (8 * i));
      const uint64_t sum = iris_guide_file_checksum(c, n);
      for (int i = 0; i < 8; ++i) c[40 + i] = (unsigned char)(sum >> (8 * i));
      FILE *fp = fopen(path, "wb");
      bool written = fp && fwrite(c, 1, n, fp) == n;
      if (fp) written = fclose(fp) == 0 && written;
      free(c);
      iris_error_clear(&err);
      const bool refused = written && iris_guiding_load(path, 1, 2, 1, &l, &err) == IRIS_ERR_PARSE && !l &&
                           strcmp(err.file, path) == 0 && strstr(err.message, forges[f].want);
      iris_check_record(refused, __FILE__, __LINE__, "forged glint photon %zu not refused: %s", f, err.message);
      iris_guiding_destroy(l);
      l = NULL;
    }
  }
  free(data);
  remove(path);
}

static void test_env_spheres(void) {
  iris_scene *sc = NULL;
  iris_error err;
  iris_error_clear(&err);
  test_guide_scene t;
  if (!test_guide_builtin_open("env-spheres", IRIS_METHOD_GUIDED_NEE, &sc, &t)) return;
  const iris_vec3 sun = sun_direction(t.lights.envmap);
  iris_guiding *g = build(sc, &t, true, 2);
  if (!CHECK(g != NULL)) goto done;
  printf("env-spheres: %u glint photons of %llu paths, a vertex looks %.3f m far; sun (%.2f, %.2f, %.2f)\n",
         g->glints.count, (unsigned long long)g->glints.paths, sqrt((double)g->glints.radius2), (double)sun.x,
         (double)sun.y, (double)sun.z);
  CHECK(g->glints.count > 1000);
  /* Ground points around the sphere, where its mirror shows the sun. */
  iris_vec3 xs[64];
  int nx = 0, eligible = 0, found = 0, holds = 0, small = 0;
  double worst = 0.0;
  for (int ring = 0; ring < 4; ++ring)
    for (int k = 0; k < 16; ++k) {
      const float d = 0.9f + 0.3f * (float)ring, phi = 6.2831853f * ((float)k + 0.5f) / 16.0f;
      const iris_vec3 x = iris_v3(SPHERE_C.x + d * cosf(phi), 0.0f, SPHERE_C.z + d * sinf(phi));
      iris_vec3 p;
      if (!mirror_point(x, sun, &p)) continue;
      /* neither the other spheres nor the ground between x and the glint */
      iris_ray r = iris_spawn_ray_to(iris_add(x, iris_v3(0, 1e-3f, 0)), iris_v3(0, 1, 0), p, iris_normalize(iris_sub(p, SPHERE_C)));
      if (iris_accel_occluded(t.acc, &r)) continue;
      eligible++;
      if (nx < 64) xs[nx++] = x;
      iris_guide_lamp spot;
      if (!iris_glints_spot(&g->glints, x, iris_v3(0, 1, 0), &spot)) continue;
      found++;
      const double miss = iris_length(iris_sub(p, spot.center)) - spot.radius;
      holds += miss <= 0.0;
      small += spot.radius <= 0.1f * SPHERE_R * 2.0f;
      if (miss > worst) worst = miss;
    }
  printf("  %d ground points see the sun in the sphere: %d find a spot, %d of those hold the glint (worst miss %.4f m), "
         "%d spots under 0.12 m\n",
         eligible, found, holds, worst, small);
  CHECK(eligible >= 20);
  CHECK(found >= eligible * 7 / 10);
  CHECK(holds >= found * 9 / 10);
  CHECK(small >= found * 8 / 10);

  /* The whole sampler at the first ground point that has a spot. */
  bool tested = false;
  iris_direction_sampler s = iris_guiding_sampler(g);
  for (int i = 0; i < nx && !tested && CHECK(s.sample != NULL); ++i) {
    iris_shading_point sp;
    if (!test_shade_below(&t, xs[i], &sp)) continue; /* on the ground, y = 0 */
    s.prepare(s.ctx, &sp);
    const iris_guide_vertex_state *v = iris_guide_vertex_get(&sp.guide);
    if (!(v->glint > 0.0f && v->alpha > 0.0f)) continue;
    tested = true;
    chi2_result r = test_full_chi2(s, &sp, 0x61696e74ULL, N_TESTS, "a glint", __FILE__, __LINE__);
    printf("  sampler at (%.2f, 0, %.2f): alpha %.2f, glint share %.2f, spot radius %.3f m at %.2f m: p = %.3g, pdf "
           "integral %.5f\n",
           (double)xs[i].x, (double)xs[i].z, (double)v->alpha, (double)v->glint, (double)v->spot.radius,
           (double)iris_length(iris_sub(v->spot.center, v->p)), r.p_value, r.pdf_integral);
  }
  CHECK(tested);
  check_round_trip(g, xs, nx);

  /* The same for 1 thread; nothing without glints. */
  iris_guiding *g1 = build(sc, &t, true, 1), *off = build(sc, &t, false, 2);
  if (CHECK(g1 != NULL && off != NULL)) {
    int differ = g1->glints.count != g->glints.count || g1->cache_count != g->cache_count ||
                 memcmp(g1->glints.photons, g->glints.photons, sizeof *g->glints.photons * g->glints.count) != 0;
    for (size_t i = 0; !differ && i < g->cache_count; ++i) differ += g1->caches[i].glint_share != g->caches[i].glint_share;
    iris_check_record(!differ, __FILE__, __LINE__, "glints differ between 1 and 2 threads");
    int shared = 0;
    for (size_t i = 0; i < off->cache_count; ++i) shared += off->caches[i].glint_share > 0.0f;
    CHECK(off->glints.count == 0 && shared == 0);
  }
  iris_guiding_destroy(g1);
  iris_guiding_destroy(off);
  iris_guiding_destroy(g);
done:
  test_guide_scene_close(&t);
  iris_scene_destroy(sc);
}

/* guided-nee asked for by name keeps its guide on env-spheres (lit mostly
 * directly, but 0.18 of the indirect light off the metal) and not on
 * veach-mis (its plates send 0.01); without glints env-spheres skips too. */
static void test_kept(void) {
  const struct {
    const char *scene;
    bool glints, kept;
  } cases[] = {{"env-spheres", true, true}, {"env-spheres", false, false}, {"veach-mis", true, false}};
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
    iris_scene *sc = NULL;
    iris_error err;
    iris_error_clear(&err);
    if (!CHECK(iris_builtin_create(cases[k].scene, &sc, &err) == IRIS_OK)) continue;
    iris_guiding_params gp = iris_guiding_params_default();
    gp.glints = cases[k].glints;
    iris_guiding *g = test_guide_build(sc, IRIS_METHOD_GUIDED_NEE, gp, 1, 2, 16);
    if (CHECK(g != NULL)) printf("%s, glints %s: %s%s\n", cases[k].scene, cases[k].glints ? "on" : "off",
                                 g->stats.skipped ? "skipped: " : "kept", g->stats.skipped ? g->stats.reason : "");
    if (g)
      iris_check_record(g->stats.skipped != cases[k].kept, __FILE__, __LINE__, "%s, glints %s: guide %s (%s)",
                        cases[k].scene, cases[k].glints ? "on" : "off", g->stats.skipped ? "skipped" : "kept",
                        g->stats.reason);
    iris_guiding_destroy(g);
    iris_scene_destroy(sc);
  }
}

/* A 3 cm lamp 1 m above the floor, a 1 x 1 m single glass quad (ior 1.5,
 * front up) at 0.5 m between them, a 4 x 4 m floor. */
static iris_scene *pane_lamp_scene(void) {
  iris_scene *s = iris_scene_create();
  if (!s) return NULL;
  iris_material floor_m = iris_material_default(IRIS_MATERIAL_DIFFUSE), glass = iris_material_default(IRIS_MATERIAL_GLASS),
                bulb = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  floor_m.name = iris_strdup("floor");
  glass.name = iris_strdup("glass");
  glass.roughness = 0.0f;
  glass.ior = 1.5f;
  bulb.name = iris_strdup("bulb");
  bulb.color[0] = bulb.color[1] = bulb.color[2] = 0.0f;
  bulb.emission[0] = bulb.emission[1] = bulb.emission[2] = 500.0f;
  const int32_t f = iris_scene_add_material(s, &floor_m), g = iris_scene_add_material(s, &glass),
                b = iris_scene_add_material(s, &bulb);
  bool ok = f >= 0 && g >= 0 && b >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 0, 0), iris_v3(0, 0, 2), iris_v3(2, 0, 0), 4, f, "floor") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 0.5f, 0), iris_v3(0, 0, 0.5f), iris_v3(0.5f, 0, 0), 1, g, "pane") >= 0;
  ok = ok && iris_builtin_add_sphere(s, iris_v3(0, 1.0f, 0), 0.03f, 24, b, "bulb") >= 0;
  iris_camera cam;
  memset(&cam, 0, sizeof cam);
  cam.name = iris_strdup("camera");
  cam.to_world = iris_mat4_look_at(iris_v3(0.0f, 2.5f, 1.5f), iris_v3(0, 0, 0), iris_v3(0, 1, 0));
  cam.yfov = 60.0f * (IRIS_PI / 180.0f);
  cam.aspect = 4.0f / 3.0f;
  ok = ok && cam.name && iris_scene_add_camera(s, &cam) >= 0;
  if (!ok) {
    iris_scene_destroy(s);
    return NULL;
  }
  return s;
}

/* Where the ray from floor point x (y = 0) to the lamp at (0, 1, 0) meets the
 * pane (y = 0.5): in the vertical plane of x and the lamp, b the horizontal
 * distance from the lamp's axis, sin(atan(b / 0.5)) = 1.5 sin(atan((D - b) /
 * 0.5)) (air above, the pane's glass below), by bisection. */
static iris_vec3 pane_point(iris_vec3 x) {
  const double D = hypot((double)x.x, (double)x.z);
  double lo = 0.0, hi = D;
  for (int i = 0; i < 60; ++i) {
    const double b = 0.5 * (lo + hi);
    const double g = sin(atan(b / 0.5)) - 1.5 * sin(atan((D - b) / 0.5));
    if (g < 0.0) lo = b;
    else hi = b;
  }
  const double b = 0.5 * (lo + hi), s = D > 0.0 ? b / D : 0.0;
  return iris_v3((float)(s * x.x), 0.5f, (float)(s * x.z));
}

static void test_glass(void) {
  iris_scene *sc = pane_lamp_scene();
  test_guide_scene t;
  if (!CHECK(sc != NULL) || !CHECK(test_guide_scene_open(sc, IRIS_METHOD_GUIDED_NEE, &t))) {
    iris_scene_destroy(sc);
    return;
  }
  iris_guiding *g = build(sc, &t, true, 2);
  if (CHECK(g != NULL)) {
    int shared = 0;
    for (size_t i = 0; i < g->cache_count; ++i) shared += g->caches[i].glint_share > 0.0f;
    printf("lamp over a glass quad: %u glint photons, %d caches with a glint share, a vertex looks %.3f m far\n",
           g->glints.count, shared, sqrt((double)g->glints.radius2));
    CHECK(g->glints.count > 1000 && shared > 0);
    int points = 0, found = 0, holds = 0, small = 0;
    double worst = 0.0;
    for (int ring = 0; ring < 3; ++ring)
      for (int k = 0; k < 12; ++k) { /* under the pane, away from its edges */
        const float d = 0.05f + 0.1f * (float)ring, phi = 6.2831853f * ((float)k + 0.5f) / 12.0f;
        const iris_vec3 x = iris_v3(d * cosf(phi), 0.0f, d * sinf(phi)), y = pane_point(x);
        points++;
        iris_guide_lamp spot;
        if (!iris_glints_spot(&g->glints, x, iris_v3(0, 1, 0), &spot)) continue;
        found++;
        const double miss = iris_length(iris_sub(y, spot.center)) - spot.radius;
        holds += miss <= 0.0;
        small += spot.radius <= 0.1f;
        if (miss > worst) worst = miss;
      }
    printf("  %d floor points under the pane: %d find a spot, %d of those hold the refraction point (worst miss %.4f "
           "m), %d spots under 0.1 m\n",
           points, found, holds, worst, small);
    CHECK(found >= points * 7 / 10);
    CHECK(holds >= found * 9 / 10);
    CHECK(small >= found * 8 / 10);
  }
  iris_guiding_destroy(g);
  test_guide_scene_close(&t);
  iris_scene_destroy(sc);
  /* a bulb in a shade of glass slabs: its light comes straight on through them */
  if (!test_guide_builtin_open("lamp-shade", IRIS_METHOD_GUIDED_NEE, &sc, &t)) return;
  g = build(sc, &t, true, 2);
  if (CHECK(g != NULL)) {
    int shared = 0;
    for (size_t i = 0; i < g->cache_count; ++i) shared += g->caches[i].glint_share > 0.0f;
    printf("lamp-shade: %u glint photons, %d caches with a glint share\n", g->glints.count, shared);
    CHECK(g->glints.count == 0 && shared == 0);
  }
  iris_guiding_destroy(g);
  test_guide_scene_close(&t);
  iris_scene_destroy(sc);
}

int main(void) {
  test_kept();
  test_env_spheres();
  test_glass();
  return iris_check_summary("guiding.glints");
}
