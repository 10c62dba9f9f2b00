/* Light sampling (renderer/lights.h) against its pdf with the shared
 * chi-square harness: the directions iris_lights_sample returns at a point,
 * for a mix of emitters (two one-sided quads of different radiance, a
 * two-sided tilted quad, a one-sided sphere light, a point light and the
 * environment), must follow iris_lights_pdf_triangle + pdf_environment (the
 * point light is a delta: its samples count as the lost mass). Also: the mean
 * photon power of iris_lights_sample_emission equals the total emitted power
 * computed from the geometry (pi L A per face, 4 pi I, ...). */
#include <stdlib.h>

#include "check.h"
#include "chi2.h"
#include "renderer/lights.h"
#include "scenes/builtin.h"

typedef struct ctx {
  const iris_accel *accel;
  const iris_lights *lights;
  iris_vec3 ref;
} ctx;

static bool sample_fn(void *vc, const double u[3], double dir[3]) {
  ctx *c = (ctx *)vc;
  iris_light_sample s;
  if (!iris_lights_sample(c->lights, c->ref, iris_v3(0, 0, 0), (float)u[0], (float)u[1], (float)u[2], &s)) return false;
  if (s.delta) return false;
  dir[0] = s.wi.x, dir[1] = s.wi.y, dir[2] = s.wi.z;
  return true;
}

static double pdf_fn(void *vc, const double dir[3]) {
  ctx *c = (ctx *)vc;
  iris_vec3 d = iris_normalize(iris_v3((float)dir[0], (float)dir[1], (float)dir[2]));
  double pdf = iris_lights_pdf_environment(c->lights, c->ref, iris_v3(0, 0, 0), d);
  iris_ray r = {c->ref, 0.0f, d, INFINITY};
  iris_hit h;
  if (iris_accel_intersect(c->accel, &r, &h)) {
    iris_interaction si;
    iris_accel_interaction(c->accel, d, &h, &si);
    pdf += iris_lights_pdf_triangle(c->lights, c->ref, iris_v3(0, 0, 0), &si);
  }
  return pdf;
}

static int32_t emitter(iris_scene *s, float L, bool two_sided) {
  iris_material m = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  m.emission[0] = m.emission[1] = m.emission[2] = L;
  m.emission_two_sided = two_sided;
  return iris_scene_add_material(s, &m);
}

int main(void) {
  iris_scene *s = iris_scene_create();
  int32_t a = emitter(s, 4.0f, false), b = emitter(s, 1.0f, false), c2 = emitter(s, 2.0f, true),
          sph = emitter(s, 3.0f, false);
  /* quads facing down at y = 2 (front = cross(a, b) = -y) */
  iris_builtin_add_quad(s, iris_v3(-0.5f, 2, 0), iris_v3(0.5f, 0, 0), iris_v3(0, 0, 0.5f), 2, a, "qa");
  iris_builtin_add_quad(s, iris_v3(0.6f, 2, 0), iris_v3(0.5f, 0, 0), iris_v3(0, 0, 1.0f), 1, b, "qb");
  iris_builtin_add_quad(s, iris_v3(-2, 0.3f, 0.5f), iris_v3(0.3f, 0.3f, 0), iris_v3(0, 0, 0.4f), 1, c2, "qc");
  iris_builtin_add_sphere(s, iris_v3(2, -0.5f, -1), 0.5f, 24, sph, "sphere");
  iris_light pl;
  memset(&pl, 0, sizeof pl);
  pl.type = IRIS_LIGHT_POINT;
  pl.color[0] = pl.color[1] = pl.color[2] = 1.0f;
  pl.intensity = 2.0f;
  pl.position[0] = 0, pl.position[1] = -3, pl.position[2] = 0;
  iris_scene_add_light(s, &pl);
  s->has_environment = true;
  s->environment[0] = s->environment[1] = s->environment[2] = 0.02f;

  iris_accel *accel = NULL;
  iris_textures tex;
  iris_lights lights;
  iris_error err;
  iris_error_clear(&err);
  CHECK(iris_accel_build(s, &accel, &err) == IRIS_OK);
  CHECK(iris_textures_load(s, &tex, &err) == IRIS_OK);
  CHECK(iris_lights_build(s, accel, &tex, &lights, &err) == IRIS_OK);

  /* refs 3 and 4 lie close to the planes of quad qa (below it) and of the
   * tilted two-sided qc (just beyond its edge, so that qc hides no other
   * emitter: pdf_fn counts the first emitter hit only): there those triangles
   * are sampled by solid angle (lights.h), the others by area. */
  static const iris_vec3 refs[5] = {{0.1f, 0.2f, 0.05f}, {1.5f, 1.0f, -0.5f}, {-1.0f, -1.0f, 1.0f},
                                    {-0.2f, 1.93f, 0.3f}, {-1.62f, 0.66f, 0.7f}};
  {
    /* the mix of strategies really happens at the new refs */
    int solid = 0, area = 0;
    for (int i = 3; i < 5; i++)
      for (size_t k = 0; k < lights.tri_count; k++)
        if (iris_lights_triangle_solid_angle(&lights.tris[k], refs[i]) > 0.0f) solid++; else area++;
    iris_check_record(solid > 0 && area > 0, __FILE__, __LINE__, "strategies at refs 3-4: %d solid, %d area", solid, area);
  }
  for (int i = 0; i < 5; i++) {
    ctx c = {accel, &lights, refs[i]};
    chi2_domain dom = {CHI2_SPHERE, 64, 128, 1234 + (uint64_t)i};
    chi2_result r = chi2_run(&dom, sample_fn, pdf_fn, &c, 500000, 0.01, 5);
    iris_check_record(r.passed, __FILE__, __LINE__, "light sampling at ref %d: %s", i, r.message);
    printf("ref %d: p = %.3g, pdf integral %.4f, lost %zu\n", i, r.p_value, r.pdf_integral, r.lost);
  }

  /* Photon power: the average over photons is the total emitted power. */
  double expect = 0.0;
  for (size_t i = 0; i < lights.count; i++) {
    const iris_light_entry *e = &lights.entries[i];
    if (e->kind == IRIS_LIGHT_KIND_TRIANGLE)
      expect += IRIS_PI * e->radiance.y * e->area * (e->two_sided ? 2.0 : 1.0);
    else if (e->kind == IRIS_LIGHT_KIND_POINT)
      expect += 4.0 * IRIS_PI * 2.0;
    else if (e->kind == IRIS_LIGHT_KIND_ENVIRONMENT)
      expect += 0.02 * 4.0 * IRIS_PI * IRIS_PI * lights.radius * lights.radius;
  }
  /* Both photon light choices (by power, by area) must give the same total. */
  for (int by = 0; by < 2; by++) {
    iris_distrib1d select;
    CHECK(iris_lights_emission_selection(&lights, (iris_emission_selection)by, &select, &err) == IRIS_OK);
    uint64_t st = 99;
    double sum = 0.0, sum2 = 0.0;
    const int n = 400000;
    int bad_dirs = 0;
    double tri_hits = 0.0, tri_area_hits = 0.0; /* by area: picks of the largest triangle */
    size_t big = 0;
    double tri_area = 0.0;
    for (size_t i = 0; i < lights.count; i++)
      if (lights.entries[i].kind == IRIS_LIGHT_KIND_TRIANGLE) {
        tri_area += lights.entries[i].area;
        if (lights.entries[i].area > lights.entries[big].area) big = i;
      }
    for (int i = 0; i < n; i++) {
      double u[5];
      for (int k = 0; k < 5; k++) u[k] = chi2_uniform(&st);
      iris_photon_emission e;
      double v = 0.0;
      if (iris_lights_sample_emission_with(&lights, &select, (float)u[0], (float)u[1], (float)u[2],
                                           (float)u[3], (float)u[4], &e)) {
        v = e.power.y;
        if (!(fabsf(iris_length(e.dir) - 1.0f) < 1e-4f)) bad_dirs++;
        if (lights.entries[e.light].kind == IRIS_LIGHT_KIND_TRIANGLE) {
          tri_hits += 1.0;
          tri_area_hits += e.light == big;
        }
      }
      sum += v;
      sum2 += v * v;
    }
    CHECK_EQ_INT(bad_dirs, 0);
    double mean = sum / n, sd = sqrt((sum2 / n - mean * mean) / n);
    iris_check_record(fabs(mean - expect) <= 4.0 * sd + 1e-4 * expect, __FILE__, __LINE__,
                      "photon power (%s): mean %.5f, expected %.5f (sigma %.3g)", by ? "area" : "power", mean,
                      expect, sd);
    printf("photon power (%s) %.5f vs %.5f (sigma %.3g)\n", by ? "area" : "power", mean, expect, sd);
    if (by == IRIS_EMIT_BY_AREA && tri_hits > 0.0) {
      /* Among the triangles, the largest is picked in proportion to its area. */
      double f = tri_area_hits / tri_hits, want = lights.entries[big].area / tri_area;
      double sf = sqrt(want * (1.0 - want) / tri_hits);
      iris_check_record(fabs(f - want) <= 4.0 * sf + 1e-6, __FILE__, __LINE__,
                        "by area: largest triangle picked %.5f of the time, its area share %.5f", f, want);
    }
    iris_distrib1d_destroy(&select);
  }

  iris_lights_destroy(&lights);
  iris_textures_destroy(&tex);
  iris_accel_destroy(accel);
  iris_scene_destroy(s);
  return iris_check_summary("render.lights_chi2");
}
