/* bsdf.sampling: the chi-square harness checks itself, then every warp of
 * renderer/sampling.h is tested against its density with it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "chi2.h"
#include "renderer/sampling.h"

static int failures = 0, passes = 0;
#define N_TESTS 8 /* chi-square runs below, for the Sidak correction */

static void expect(bool ok, const char *what, const char *detail) {
  printf("%s %s: %s\n", ok ? "ok  " : "FAIL", what, detail);
  if (ok) passes++;
  else failures++;
}

static void run(const char *name, chi2_mode mode, chi2_sample_fn s, chi2_pdf_fn p, void *ctx) {
  chi2_domain d = {mode, 0, 0, 1234};
  chi2_result r = chi2_run(&d, s, p, ctx, 400000, 0.01, N_TESTS);
  expect(r.passed && fabs(r.pdf_integral - 1.0) < 2e-3, name, r.message);
}

static void store(iris_vec3 v, double dir[3]) {
  dir[0] = v.x;
  dir[1] = v.y;
  dir[2] = v.z;
}

static bool s_cos(void *c, const double u[3], double d[3]) {
  (void)c;
  store(iris_sample_cosine_hemisphere((float)u[0], (float)u[1]), d);
  return true;
}
static double p_cos(void *c, const double d[3]) {
  (void)c;
  return iris_sample_cosine_hemisphere_pdf((float)d[2]);
}
static bool s_hemi(void *c, const double u[3], double d[3]) {
  (void)c;
  store(iris_sample_uniform_hemisphere((float)u[0], (float)u[1]), d);
  return true;
}
static double p_hemi(void *c, const double d[3]) {
  (void)c;
  return iris_sample_uniform_hemisphere_pdf((float)d[2]);
}
static bool s_sphere(void *c, const double u[3], double d[3]) {
  (void)c;
  store(iris_sample_uniform_sphere((float)u[0], (float)u[1]), d);
  return true;
}
static double p_sphere(void *c, const double d[3]) {
  (void)c;
  (void)d;
  return iris_sample_uniform_sphere_pdf();
}
static bool s_cone(void *c, const double u[3], double d[3]) {
  store(iris_sample_uniform_cone((float)u[0], (float)u[1], *(const float *)c), d);
  return true;
}
static double p_cone(void *c, const double d[3]) {
  return iris_sample_uniform_cone_pdf((float)d[2], *(const float *)c);
}

/* Planar samplers are lifted to the hemisphere by the Lambert equal-area map
 * (unit disk -> hemisphere, d(omega) = 2 dA), so the same harness tests them. */
static void disk_to_dir(double x, double y, double d[3]) {
  double r2 = x * x + y * y;
  double s = sqrt(fmax(0.0, 2.0 - r2));
  d[0] = x * s;
  d[1] = y * s;
  d[2] = 1.0 - r2;
}
static void dir_to_disk(const double d[3], double *x, double *y) {
  double r2 = 1.0 - d[2];
  double s = sqrt(fmax(1e-300, 2.0 - r2));
  *x = d[0] / s;
  *y = d[1] / s;
}
static bool s_disk(void *c, const double u[3], double d[3]) {
  (void)c;
  float x, y;
  iris_sample_concentric_disk((float)u[0], (float)u[1], &x, &y);
  disk_to_dir(x, y, d);
  return true;
}
static double p_disk(void *c, const double d[3]) {
  (void)c;
  return d[2] >= 0.0 ? iris_sample_concentric_disk_pdf() * 0.5 : 0.0;
}

static const double tri[3][2] = {{-0.6, -0.5}, {0.7, -0.2}, {-0.1, 0.65}};
static double tri_area(void) {
  return 0.5 * fabs((tri[1][0] - tri[0][0]) * (tri[2][1] - tri[0][1]) -
                    (tri[2][0] - tri[0][0]) * (tri[1][1] - tri[0][1]));
}
static bool s_tri(void *c, const double u[3], double d[3]) {
  (void)c;
  float b0, b1;
  iris_sample_uniform_triangle((float)u[0], (float)u[1], &b0, &b1);
  double b2 = 1.0 - b0 - b1;
  disk_to_dir(b0 * tri[0][0] + b1 * tri[1][0] + b2 * tri[2][0],
              b0 * tri[0][1] + b1 * tri[1][1] + b2 * tri[2][1], d);
  return b0 >= 0.0f && b1 >= 0.0f && b2 >= -1e-6;
}
static double edge(const double a[2], const double b[2], double x, double y) {
  return (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]);
}
static double p_tri(void *c, const double d[3]) {
  (void)c;
  if (d[2] < 0.0) return 0.0;
  double x, y;
  dir_to_disk(d, &x, &y);
  bool in = edge(tri[0], tri[1], x, y) >= 0 && edge(tri[1], tri[2], x, y) >= 0 &&
            edge(tri[2], tri[0], x, y) >= 0;
  return in ? 0.5 / tri_area() : 0.0;
}

static void test_distrib1d(void) {
  float w[7] = {0.0f, 3.0f, 1.0f, 0.0f, 0.5f, NAN, 2.0f};
  iris_distrib1d d;
  iris_error err;
  iris_error_clear(&err);
  bool ok = iris_distrib1d_create(&d, w, 7, &err) == IRIS_OK;
  expect(ok, "distrib1d create", "7 weights");
  if (!ok) return;
  double pmf_sum = 0.0;
  for (size_t i = 0; i < 7; ++i) pmf_sum += iris_distrib1d_pmf(&d, i);
  char msg[256];
  snprintf(msg, sizeof(msg), "pmf sum %.7f, pmf[1] %.6f (expected %.6f)", pmf_sum,
           iris_distrib1d_pmf(&d, 1), 3.0 / 6.5);
  expect(fabs(pmf_sum - 1.0) < 1e-6 && fabs(iris_distrib1d_pmf(&d, 1) - 3.0 / 6.5) < 1e-6,
         "distrib1d pmf", msg);
  /* Frequencies against the pmf (chi-square by hand: 7 cells, few dof). */
  size_t counts[7] = {0};
  uint64_t st = 99;
  const size_t n = 200000;
  bool remap_ok = true, reported_ok = true;
  for (size_t i = 0; i < n; ++i) {
    float pmf, ur;
    size_t k = iris_distrib1d_sample(&d, (float)chi2_uniform(&st), &pmf, &ur);
    counts[k]++;
    if (!(ur >= 0.0f && ur < 1.0f)) remap_ok = false;
    if (pmf != iris_distrib1d_pmf(&d, k)) reported_ok = false;
  }
  double chsq = 0.0;
  int dof = -1;
  bool zero_ok = counts[0] == 0 && counts[3] == 0 && counts[5] == 0;
  for (size_t i = 0; i < 7; ++i) {
    double e = iris_distrib1d_pmf(&d, i) * n;
    if (e > 0.0) {
      chsq += (counts[i] - e) * (counts[i] - e) / e;
      dof++;
    }
  }
  double p = chi2_gamma_q(0.5 * dof, 0.5 * chsq);
  snprintf(msg, sizeof(msg), "chi2 %.2f dof %d p %.3g, zero-weight entries never chosen: %s", chsq,
           dof, p, zero_ok ? "yes" : "NO");
  expect(p > 0.01 / N_TESTS && zero_ok && remap_ok && reported_ok, "distrib1d sampling", msg);
  iris_distrib1d_destroy(&d);

  float zeros[3] = {0.0f, 0.0f, 0.0f};
  ok = iris_distrib1d_create(&d, zeros, 3, &err) == IRIS_OK;
  expect(ok && fabsf(iris_distrib1d_pmf(&d, 2) - 1.0f / 3.0f) < 1e-6f, "distrib1d all-zero",
         "falls back to uniform");
  if (ok) iris_distrib1d_destroy(&d);
  iris_error_clear(&err);
  expect(iris_distrib1d_create(&d, zeros, 0, &err) == IRIS_ERR_INVALID, "distrib1d empty",
         "rejected");
}

int main(void) {
  char msg[1024];
  /* Known values of Q(a, x): Q(1, x) = exp(-x); chi-square 3.84 with 1 dof has p = 0.05. */
  double q1 = chi2_gamma_q(1.0, 2.0), q2 = chi2_gamma_q(0.5, 0.5 * 3.841459);
  double q3 = chi2_gamma_q(50.0, 0.5 * 124.342); /* 0.95 quantile of chi2 with 100 dof */
  snprintf(msg, sizeof(msg), "Q(1,2)=%.9f (e^-2=%.9f), p(3.8415;1)=%.6f, p(124.342;100)=%.6f", q1,
           exp(-2.0), q2, q3);
  expect(fabs(q1 - exp(-2.0)) < 1e-9 && fabs(q2 - 0.05) < 1e-5 && fabs(q3 - 0.05) < 1e-4,
         "incomplete gamma", msg);

  bool self = chi2_self_test(msg, sizeof(msg));
  expect(self, "harness self-test", msg);

  run("cosine hemisphere", CHI2_HEMISPHERE, s_cos, p_cos, NULL);
  run("uniform hemisphere", CHI2_HEMISPHERE, s_hemi, p_hemi, NULL);
  run("uniform sphere", CHI2_SPHERE, s_sphere, p_sphere, NULL);
  float narrow = 0.95f, wide = -0.3f;
  run("uniform cone 0.95", CHI2_SPHERE, s_cone, p_cone, &narrow);
  run("uniform cone -0.3", CHI2_SPHERE, s_cone, p_cone, &wide);
  run("concentric disk", CHI2_HEMISPHERE, s_disk, p_disk, NULL);
  run("uniform triangle", CHI2_HEMISPHERE, s_tri, p_tri, NULL);
  test_distrib1d();

  printf("%d passed, %d failed\n", passes, failures);
  return failures == 0 ? 0 : 1;
}
