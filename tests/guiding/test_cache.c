/* Cache tables: pdf integrates to 1 over solid angle, floor, splatting rules,
 * and sampling is unbiased for integrals with known values. The chi-square
 * comparison of sampling against the pdf is in test_cache_chi2.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/rng.h"
#include "renderer/guiding/cache.h"

static int failures = 0;
#define EXPECT(cond, ...)                                   \
  do {                                                      \
    if (!(cond)) {                                          \
      ++failures;                                           \
      fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__); \
      fprintf(stderr, __VA_ARGS__);                         \
      fprintf(stderr, "\n");                                \
    }                                                       \
  } while (0)

#define PI_D 3.14159265358979323846

static iris_vec3 uniform_sphere(float u0, float u1) {
  float z = 1.0f - 2.0f * u0, r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 2.0f * IRIS_PI * u1;
  return iris_v3(r * cosf(phi), r * sinf(phi), z);
}

/* Fill patterns: a lobe around a direction, a cosine-ish spread, a single hot
 * texel, photons only from below. */
static void fill(const iris_octmap *m, float *hist, int pattern, iris_splat_mode mode) {
  for (uint32_t t = 0; t < m->texel_count; ++t) hist[t] = 0.0f;
  iris_vec3 lobe = iris_normalize(iris_v3(0.6f, -0.3f, 0.5f));
  for (int i = 0; i < 4000; ++i) {
    iris_sampler s = iris_sampler_start(100 + pattern, (uint64_t)i, 0);
    iris_vec3 d = uniform_sphere(iris_sampler_next(&s), iris_sampler_next(&s));
    float e = 1.0f;
    if (pattern == 0) e = powf(fmaxf(0.0f, iris_dot(d, lobe)), 20.0f);
    if (pattern == 1) e = fabsf(d.z) + 0.1f;
    if (pattern == 2 && i > 0) break;
    if (pattern == 2) d = lobe;
    if (pattern == 3) d.z = -fabsf(d.z);
    iris_cache_splat(m, hist, d, e, mode);
  }
}

static void test_tables(int res, bool sphere, int pattern, iris_splat_mode mode, float floor) {
  iris_octmap m;
  iris_octmap_create(&m, res, sphere, NULL);
  float *hist = calloc(m.texel_count, sizeof(float)), *pdf = calloc(m.texel_count, sizeof(float));
  iris_cache_alias *alias = calloc(m.texel_count, sizeof(iris_cache_alias));
  fill(&m, hist, pattern, mode);
  bool ok = iris_cache_build_tables(&m, hist, floor, pdf, alias);
  if (pattern == 3 && !sphere) {
    EXPECT(!ok, "photons from below filled a hemisphere cache");
    goto done;
  }
  EXPECT(ok, "tables not built (res %d sphere %d pattern %d)", res, sphere, pattern);
  /* texel probabilities (pdf table = P * res^2 / 2) sum to 1 */
  double integral = 0.0, pmin = 1.0;
  for (uint32_t t = 0; t < m.texel_count; ++t) {
    double pt = pdf[t] * 2.0 / ((double)res * res);
    integral += pt;
    pmin = fmin(pmin, pt);
  }
  EXPECT(fabs(integral - 1.0) < 1e-5, "texel probabilities sum to %.8f", integral);
  /* the density integrates to 1 over solid angle: Monte Carlo with uniform
   * directions (independent of the map's parametrisation) */
  {
    const int nq = 400000;
    double acc = 0.0, acc2 = 0.0, area = sphere ? 4.0 * PI_D : 2.0 * PI_D;
    for (int i = 0; i < nq; ++i) {
      iris_sampler s = iris_sampler_start(11, (uint64_t)i, 7);
      double zq = 1.0 - (sphere ? 2.0 : 1.0) * iris_sampler_next(&s);
      double ph = 2.0 * PI_D * iris_sampler_next(&s), rq = sqrt(fmax(0.0, 1.0 - zq * zq));
      double f = area * iris_cache_pdf(&m, pdf, iris_v3((float)(rq * cos(ph)), (float)(rq * sin(ph)), (float)zq));
      acc += f;
      acc2 += f * f;
    }
    double mq = acc / nq, se = sqrt(fmax(0.0, acc2 / nq - mq * mq) / nq);
    EXPECT(fabs(mq - 1.0) < 5.0 * se + 1e-3, "pdf integrates to %g +- %g over solid angle", mq, se);
  }
  /* floor: every texel keeps at least floor / (1 + n floor) probability */
  EXPECT(pmin >= floor / (1.0 + m.texel_count * floor) * 0.999, "floor violated: %g", pmin);
  /* The alias table samples exactly the table's probabilities: P_i = (q_i +
   * sum of (1 - q_j) over columns j aliased to i) / n, recomputed here, and
   * the table is proportional to the floored histogram. */
  {
    double *pa = calloc(m.texel_count, sizeof(double)), hsum = 0.0, fsum = 0.0, worst = 0.0;
    bool valid = true;
    for (uint32_t t = 0; t < m.texel_count; ++t) {
      valid = valid && alias[t].q >= 0.0f && alias[t].q <= 1.0f && alias[t].alias < m.texel_count;
      if (!valid) break;
      pa[t] += alias[t].q;
      pa[alias[t].alias] += 1.0 - alias[t].q;
      hsum += hist[t] > 0.0f ? hist[t] : 0.0f;
    }
    EXPECT(valid, "alias table entries out of range");
    for (uint32_t t = 0; valid && t < m.texel_count; ++t) fsum += fmax((hist[t] > 0.0f ? hist[t] : 0.0f) / hsum, floor);
    for (uint32_t t = 0; valid && t < m.texel_count; ++t) {
      double p_alias = pa[t] / m.texel_count, p_table = pdf[t] * 2.0 / ((double)res * res);
      double p_hist = fmax((hist[t] > 0.0f ? hist[t] : 0.0f) / hsum, floor) / fsum;
      worst = fmax(worst, fabs(p_alias - p_table) / p_table);
      EXPECT(fabs(p_hist - p_table) <= 1e-5 * p_table + 1e-7, "texel %u: P %g, floored histogram %g", t, p_table, p_hist);
    }
    EXPECT(worst < 1e-5, "alias table and pdf table disagree by %g", worst);
    free(pa);
  }
  /* Unbiasedness with importance sampling: E[g/pdf] = integral of g.
   * g = max(z,0): integral pi; g = 1: 2 pi or 4 pi. */
  double acc_cos = 0.0, acc_one = 0.0, acc_cos2 = 0.0;
  const int n = 200000;
  int mismatch = 0;
  for (int i = 0; i < n; ++i) {
    iris_sampler s = iris_sampler_start(5, (uint64_t)i, (uint64_t)pattern);
    float u0 = iris_sampler_next(&s), u1 = iris_sampler_next(&s), u2 = iris_sampler_next(&s), p;
    iris_vec3 d = iris_cache_sample(&m, pdf, alias, u0, u1, u2, &p);
    float q = iris_cache_pdf(&m, pdf, d);
    if (fabsf(q - p) > 1e-6f * p && fminf(fabsf(d.z), 1.0f) > 1e-4f) ++mismatch;
    if (!(p > 0.0f)) continue;
    double c = fmax(0.0, d.z) / p;
    acc_cos += c;
    acc_cos2 += c * c;
    acc_one += 1.0 / p;
  }
  /* pdf lookups disagree only where a sample lands exactly on a texel edge */
  EXPECT(mismatch < n / 1000, "%d pdf/sample mismatches", mismatch);
  double mean = acc_cos / n, var = acc_cos2 / n - mean * mean, se = sqrt(var / n);
  EXPECT(fabs(mean - PI_D) < 4.0 * se + 1e-4, "E[cos/pdf] = %g +- %g, want pi", mean, se);
  (void)acc_one;
done:
  free(hist);
  free(pdf);
  free(alias);
  iris_octmap_destroy(&m);
}

static void test_splat_rules(void) {
  iris_octmap hm, sm;
  iris_octmap_create(&hm, 8, false, NULL);
  iris_octmap_create(&sm, 8, true, NULL);
  float h[128] = {0}, s[128] = {0};
  EXPECT(!iris_cache_splat(&hm, h, iris_v3(0, 0, -1), 1.0f, IRIS_SPLAT_NEAREST), "below used");
  EXPECT(iris_cache_splat(&sm, s, iris_v3(0, 0, -1), 1.0f, IRIS_SPLAT_NEAREST), "below lost (sphere)");
  /* bilinear conserves energy, also at seams */
  for (int i = 0; i < 1000; ++i) {
    iris_sampler r = iris_sampler_start(9, (uint64_t)i, 0);
    iris_vec3 d = uniform_sphere(iris_sampler_next(&r), iris_sampler_next(&r));
    iris_cache_splat(&sm, s, d, 1.0f, IRIS_SPLAT_BILINEAR);
  }
  double sum = 0.0;
  for (int t = 0; t < 128; ++t) sum += s[t];
  EXPECT(fabs(sum - 1001.0) < 1e-2, "bilinear splat lost energy: %g", sum);
  /* a photon at a texel centre goes entirely to that texel */
  float c[128] = {0};
  iris_cache_splat(&sm, c, iris_octmap_texel_to_dir(&sm, 37, 0.5f, 0.5f), 1.0f, IRIS_SPLAT_BILINEAR);
  EXPECT(c[37] > 0.999f, "centre splat %g", c[37]);
  iris_octmap_destroy(&hm);
  iris_octmap_destroy(&sm);
}

int main(void) {
  int res[] = {4, 8, 16};
  for (int r = 0; r < 3; ++r)
    for (int s = 0; s < 2; ++s)
      for (int p = 0; p < 4; ++p)
        for (int mode = 0; mode < 2; ++mode) test_tables(res[r], s, p, (iris_splat_mode)mode, 2e-4f);
  test_tables(8, false, 1, IRIS_SPLAT_NEAREST, 0.0f);
  test_tables(8, true, 2, IRIS_SPLAT_NEAREST, 0.01f);
  test_splat_rules();
  if (failures) fprintf(stderr, "%d failures\n", failures);
  return failures ? 1 : 0;
}
