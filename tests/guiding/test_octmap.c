/* Octahedral map: round trips, seams, exact solid-angle table, texel sampling
 * stays inside its texel. Expected values come from geometry, not from iris. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/rng.h"
#include "renderer/guiding/octmap.h"

static int failures = 0;
#define EXPECT(cond, ...)                        \
  do {                                           \
    if (!(cond)) {                               \
      ++failures;                                \
      fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__); \
      fprintf(stderr, __VA_ARGS__);              \
      fprintf(stderr, "\n");                     \
    }                                            \
  } while (0)

static iris_vec3 uniform_sphere(float u0, float u1) {
  float z = 1.0f - 2.0f * u0, r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 2.0f * IRIS_PI * u1;
  return iris_v3(r * cosf(phi), r * sinf(phi), z);
}

static void test_round_trip(int res, bool sphere) {
  iris_octmap m;
  EXPECT(iris_octmap_create(&m, res, sphere, NULL) == IRIS_OK, "create");
  float worst = 0.0f;
  for (int i = 0; i < 100000; ++i) {
    iris_sampler s = iris_sampler_start(7, (uint64_t)i, 0);
    iris_vec3 d = uniform_sphere(iris_sampler_next(&s), iris_sampler_next(&s));
    if (!sphere && d.z < 0.0f) d.z = -d.z;
    float u, v;
    EXPECT(iris_octmap_dir_to_uv(&m, d, &u, &v), "dir_to_uv refused");
    EXPECT(u >= 0.0f && u < m.width && v >= 0.0f && v < m.height, "uv out of range %g %g", u, v);
    iris_vec3 e = iris_octmap_uv_to_dir(&m, u, v);
    worst = fmaxf(worst, iris_length(iris_sub(d, e)));
    /* texel of a direction contains it: (u,v) -> texel index consistent */
    int32_t t = iris_octmap_dir_to_texel(&m, d);
    EXPECT(t == (int32_t)((int)v * m.width + (int)u), "texel index");
  }
  EXPECT(worst < 2e-6f, "round trip error %g (res %d sphere %d)", worst, res, sphere);
  /* texel -> dir -> texel for every texel centre */
  for (uint32_t t = 0; t < m.texel_count; ++t) {
    iris_vec3 d = iris_octmap_texel_to_dir(&m, t, 0.5f, 0.5f);
    EXPECT(fabsf(iris_length(d) - 1.0f) < 1e-6f, "not unit");
    EXPECT(iris_octmap_dir_to_texel(&m, d) == (int32_t)t, "centre of texel %u maps to %d", t,
           iris_octmap_dir_to_texel(&m, d));
  }
  if (!sphere) EXPECT(iris_octmap_dir_to_texel(&m, iris_v3(0.1f, 0.2f, -0.5f)) == -1, "below accepted");
  iris_octmap_destroy(&m);
}

/* Texel coordinates map continuously to directions: neighbouring texel-space
 * points map to nearby directions, also across the seams of the sphere layout
 * (u = res joins the halves along the equator; u = 0 and u = 2 res are the same
 * equator edge; v = 0 and v = res mirror u). */
static void test_seams(int res) {
  iris_octmap m;
  iris_octmap_create(&m, res, true, NULL);
  const float eps = 1e-4f;
  for (int k = 0; k <= 100; ++k) {
    float v = res * k / 100.0f;
    iris_vec3 a = iris_octmap_uv_to_dir(&m, res - eps, v), b = iris_octmap_uv_to_dir(&m, res + eps, v);
    EXPECT(iris_length(iris_sub(a, b)) < 1e-3f, "middle seam at v=%g", v);
    EXPECT(fabsf(a.z) < 1e-3f, "middle seam not on equator");
    a = iris_octmap_uv_to_dir(&m, eps, v);
    b = iris_octmap_uv_to_dir(&m, 2 * res - eps, v);
    EXPECT(iris_length(iris_sub(a, b)) < 1e-3f, "wrap seam at v=%g", v);
    float u = 2.0f * res * k / 100.0f;
    a = iris_octmap_uv_to_dir(&m, u, eps);
    b = iris_octmap_uv_to_dir(&m, 2.0f * res - u, eps);
    EXPECT(iris_length(iris_sub(a, b)) < 1e-3f, "bottom mirror seam at u=%g", u);
    a = iris_octmap_uv_to_dir(&m, u, res - eps);
    b = iris_octmap_uv_to_dir(&m, 2.0f * res - u, res - eps);
    EXPECT(iris_length(iris_sub(a, b)) < 1e-3f, "top mirror seam at u=%g", u);
  }
  /* Directions just above and below the equator land in texels that touch
   * across the middle seam (columns res-1 and res), the wrap seam (0, 2res-1)
   * or the mirrored top/bottom rows (column i meets column 2res-1-i). */
  for (int k = 0; k < 200; ++k) {
    float phi = 2.0f * IRIS_PI * (k + 0.5f) / 200.0f;
    iris_vec3 up = iris_v3(cosf(phi), sinf(phi), 1e-5f), dn = iris_v3(cosf(phi), sinf(phi), -1e-5f);
    int32_t tu = iris_octmap_dir_to_texel(&m, up), td = iris_octmap_dir_to_texel(&m, dn);
    int iu = tu % m.width, ju = tu / m.width, id = td % m.width, jd = td / m.width;
    bool touch = ju == jd && ((iu == res - 1 && id == res) || (iu == 0 && id == 2 * res - 1) ||
                              ((ju == 0 || ju == res - 1) && id == 2 * res - 1 - iu));
    EXPECT(touch, "equator at phi=%g: texels (%d,%d) and (%d,%d) do not touch", phi, iu, ju, id, jd);
  }
  iris_octmap_destroy(&m);
}

static void test_solid_angle(int res, bool sphere) {
  iris_octmap m;
  iris_octmap_create(&m, res, sphere, NULL);
  double sum = 0.0, mn = 1e9, mx = 0.0;
  for (uint32_t t = 0; t < m.texel_count; ++t) {
    EXPECT(m.solid_angle[t] > 0.0, "texel %u has no solid angle", t);
    sum += m.solid_angle[t];
    mn = fmin(mn, m.solid_angle[t]);
    mx = fmax(mx, m.solid_angle[t]);
  }
  double want = sphere ? 4.0 * 3.14159265358979323846 : 2.0 * 3.14159265358979323846;
  EXPECT(fabs(sum - want) < 1e-6, "solid angles sum to %.12f, want %.12f (res %d)", sum, want, res);
  /* d(area)/d(omega) = 2 / |d|_1^3 varies between 1 and 3^(3/2) = 5.196 (docs/guiding.md),
   * so texel solid angles can differ by at most that factor. */
  if (res >= 4) EXPECT(mx / mn < 5.2, "solid angle ratio %g", mx / mn);
  iris_octmap_destroy(&m);
}

/* Independent check of the table: Monte Carlo over uniform directions. */
static void test_solid_angle_mc(void) {
  iris_octmap m;
  iris_octmap_create(&m, 4, true, NULL);
  double counts[32] = {0};
  const int n = 2000000;
  for (int i = 0; i < n; ++i) {
    iris_sampler s = iris_sampler_start(11, (uint64_t)i, 0);
    counts[iris_octmap_dir_to_texel(&m, uniform_sphere(iris_sampler_next(&s), iris_sampler_next(&s)))] += 1;
  }
  for (int t = 0; t < 32; ++t) {
    double est = counts[t] / n * 4.0 * 3.14159265358979323846;
    double sigma = sqrt(counts[t]) / n * 4.0 * 3.14159265358979323846;
    EXPECT(fabs(est - m.solid_angle[t]) < 5.0 * sigma, "texel %d: MC %g exact %g", t, est, m.solid_angle[t]);
  }
  iris_octmap_destroy(&m);
}

/* A planar triangle's solid angle: the octant triangle (1,0,0),(0,1,0),(0,0,1) is pi/2. */
static void test_triangle(void) {
  double a[3] = {1, 0, 0}, b[3] = {0, 1, 0}, c[3] = {0, 0, 1};
  EXPECT(fabs(iris_octmap_triangle_solid_angle(a, b, c) - 3.14159265358979323846 / 2) < 1e-12, "octant");
  /* A small triangle at distance r facing the origin: omega ~ area / r^2. */
  double p[3] = {-1e-3, -1e-3, 10}, q[3] = {1e-3, -1e-3, 10}, r[3] = {0, 1e-3, 10};
  EXPECT(fabs(iris_octmap_triangle_solid_angle(p, q, r) - 2e-6 / 100.0) < 1e-14, "small triangle");
}

/* Samples inside a texel stay in that texel. */
static void test_sample_in_texel(int res, bool sphere) {
  iris_octmap m;
  iris_octmap_create(&m, res, sphere, NULL);
  int bad = 0;
  for (uint32_t t = 0; t < m.texel_count; ++t) {
    for (int k = 0; k < 64; ++k) {
      iris_sampler s = iris_sampler_start(3, t, (uint64_t)k);
      float u0 = iris_sampler_next(&s), u1 = iris_sampler_next(&s), u2 = iris_sampler_next(&s);
      iris_vec3 d = iris_octmap_sample_in_texel(&m, t, u0, u1, u2);
      if (fabsf(iris_length(d) - 1.0f) > 1e-5f) ++bad;
      /* allow landing on a neighbour only by float rounding at edges */
      int32_t got = iris_octmap_dir_to_texel(&m, d);
      if (got != (int32_t)t) {
        float u, v;
        iris_octmap_dir_to_uv(&m, d, &u, &v);
        int i = (int)(t % (uint32_t)m.width), j = (int)(t / (uint32_t)m.width);
        float du = fminf(fabsf(u - i), fabsf(u - i - 1)), dv = fminf(fabsf(v - j), fabsf(v - j - 1));
        if (fminf(du, dv) > 1e-3f) ++bad;
      }
    }
  }
  EXPECT(bad == 0, "%d samples outside their texel (res %d sphere %d)", bad, res, sphere);
  iris_octmap_destroy(&m);
}

int main(void) {
  int res[] = {1, 2, 3, 5, 8, 16, 31, 64};
  for (size_t i = 0; i < sizeof res / sizeof res[0]; ++i) {
    for (int s = 0; s < 2; ++s) {
      test_solid_angle(res[i], s);
      if (res[i] >= 2) test_round_trip(res[i], s);
      if (res[i] <= 16) test_sample_in_texel(res[i], s);
    }
  }
  test_seams(8);
  test_solid_angle_mc();
  test_triangle();
  iris_octmap m;
  EXPECT(iris_octmap_create(&m, 0, false, NULL) != IRIS_OK, "res 0 accepted");
  EXPECT(iris_octmap_create(&m, 100000, false, NULL) != IRIS_OK, "huge res accepted");
  if (failures) fprintf(stderr, "%d failures\n", failures);
  return failures ? 1 : 0;
}
