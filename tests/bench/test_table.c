/* bench.table: the time-to-target interpolation and the seed aggregation of
 * validate/bench_table.h on synthetic curves whose answers are known in
 * closed form (relMSE = c / t is a straight line in log-log), and the net
 * table's premise: relMSE against a noisy reference minus the reference's own
 * relMSE estimates the relMSE against the truth. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "core/rng.h"
#include "validate/bench_table.h"
#include "validate/metrics.h"

/* A standard normal number from the counter `i` (Box-Muller on hashed uniforms). */
static double normal(uint64_t i) {
  double u1 = ((double)(iris_mix64(2 * i + 1) >> 11) + 0.5) * 0x1p-53;
  double u2 = (double)(iris_mix64(2 * i + 2) >> 11) * 0x1p-53;
  return sqrt(-2.0 * log(u1)) * cos(2.0 * IRIS_PI * u2);
}

/* Truth T, a reference T + N(0, sr^2) carrying var.R/G/B = sr^2 and a test
 * T + N(0, st^2), with sr and st proportional to T: returns, through the
 * out parameters, relMSE(test, ref), the reference's own relMSE and
 * relMSE(test, truth), each as `iris bench` measures it. */
static void premise(double ref_noise, double test_noise, double *gross, double *own, double *truth) {
  const int w = 200, hgt = 200;
  static const char *const rgb[3] = {"R", "G", "B"};
  static const char *const rgbv[6] = {"R", "G", "B", "var.R", "var.G", "var.B"};
  iris_image t, r, tr;
  iris_error err;
  CHECK(iris_image_create(&t, w, hgt, 3, rgb, &err) == IRIS_OK);
  CHECK(iris_image_create(&tr, w, hgt, 3, rgb, &err) == IRIS_OK);
  CHECK(iris_image_create(&r, w, hgt, 6, rgbv, &err) == IRIS_OK);
  uint64_t k = 0;
  for (size_t i = 0; i < (size_t)w * (size_t)hgt; i++)
    for (int c = 0; c < 3; c++) {
      double truth_v = 0.05 + 2.0 * (double)(iris_mix64(977 * i + (uint64_t)c) >> 11) * 0x1p-53;
      double sr = ref_noise * truth_v, st = test_noise * truth_v;
      tr.data[3 * i + (size_t)c] = (float)truth_v;
      r.data[6 * i + (size_t)c] = (float)(truth_v + sr * normal(k++));
      r.data[6 * i + 3 + (size_t)c] = (float)(sr * sr);
      t.data[3 * i + (size_t)c] = (float)(truth_v + st * normal(k++));
    }
  *gross = iris_metric_relmse(&t, 0, &r, 0, IRIS_METRIC_EPS, IRIS_METRIC_DROP);
  *own = iris_metric_own_relmse(&r);
  *truth = iris_metric_relmse(&t, 0, &tr, 0, IRIS_METRIC_EPS, IRIS_METRIC_DROP);
  iris_image_destroy(&t);
  iris_image_destroy(&r);
  iris_image_destroy(&tr);
}

static iris_bench_row row(const char *scene, const char *method, int seed, double budget,
                          double seconds, double relmse) {
  iris_bench_row r;
  memset(&r, 0, sizeof r);
  snprintf(r.scene, sizeof r.scene, "%s", scene);
  snprintf(r.method, sizeof r.method, "%s", method);
  r.seed = (uint64_t)seed;
  r.budget_s = budget;
  r.seconds = seconds;
  r.relmse = relmse;
  r.spp = (int)(seconds * 10);
  return r;
}

int main(void) {
  /* aggregation: mean, min, max over seeds, per budget, other scenes/methods ignored */
  iris_bench_row rows[] = {
      row("a", "mis", 0, 1, 1.0, 0.4), row("a", "mis", 1, 1, 1.2, 0.2),
      row("a", "mis", 0, 2, 2.0, 0.1), row("a", "mis", 1, 2, 2.2, 0.3),
      row("a", "nee", 0, 1, 1.0, 9.0), row("b", "mis", 0, 1, 1.0, 7.0),
  };
  double budgets[3] = {1, 2, 4};
  iris_bench_point pts[3];
  int n = iris_bench_curve(rows, 6, "a", "mis", budgets, 3, pts);
  CHECK_EQ_INT(n, 2);
  CHECK_NEAR(pts[0].relmse, 0.3, 1e-12);
  CHECK_NEAR(pts[0].relmse_min, 0.2, 1e-12);
  CHECK_NEAR(pts[0].relmse_max, 0.4, 1e-12);
  CHECK_NEAR(pts[0].seconds, 1.1, 1e-12);
  CHECK_EQ_INT(pts[0].runs, 2);
  CHECK_NEAR(pts[1].relmse, 0.2, 1e-12);
  CHECK_NEAR(pts[1].budget, 2.0, 0);

  /* relMSE = c / t through (1, 0.5), (2, 0.25), (4, 0.125): t(target) = c / target exactly */
  iris_bench_point line[3];
  memset(line, 0, sizeof line);
  for (int i = 0; i < 3; i++) {
    line[i].seconds = pow(2.0, i);
    line[i].relmse = 0.5 / line[i].seconds;
  }
  bool ex = true;
  CHECK_NEAR(iris_bench_time_to_target(line, 3, 0.3, &ex), 0.5 / 0.3, 1e-9);
  CHECK(!ex);
  CHECK_NEAR(iris_bench_time_to_target(line, 3, 0.125, &ex), 4.0, 1e-9);
  CHECK(!ex);
  /* outside the range: the 1/t law from the nearest point, flagged */
  CHECK_NEAR(iris_bench_time_to_target(line, 3, 0.05, &ex), 10.0, 1e-9);
  CHECK(ex);
  CHECK_NEAR(iris_bench_time_to_target(line, 3, 1.0, &ex), 0.5, 1e-9);
  CHECK(ex);
  /* a steeper line relMSE = t^-2 through (1,1), (3, 1/9): log-log interpolation, not linear */
  iris_bench_point steep[2];
  memset(steep, 0, sizeof steep);
  steep[0].seconds = 1;
  steep[0].relmse = 1;
  steep[1].seconds = 3;
  steep[1].relmse = 1.0 / 9.0;
  CHECK_NEAR(iris_bench_time_to_target(steep, 2, 0.25, &ex), 2.0, 1e-9);
  CHECK(!ex);
  /* a noisy, non-monotone curve: the first crossing counts */
  iris_bench_point bumpy[3];
  memset(bumpy, 0, sizeof bumpy);
  double bs[3] = {1, 2, 4}, br[3] = {0.4, 0.1, 0.2};
  for (int i = 0; i < 3; i++) {
    bumpy[i].seconds = bs[i];
    bumpy[i].relmse = br[i];
  }
  CHECK_NEAR(iris_bench_time_to_target(bumpy, 3, 0.2, &ex), sqrt(2.0), 1e-9);
  CHECK(iris_bench_time_to_target(line, 0, 0.2, &ex) < 0);
  /* default target: geometric mean of the ends */
  CHECK_NEAR(iris_bench_default_target(line, 3), sqrt(0.5 * 0.125), 1e-12);

  /* net curve: every value minus the reference's own, points at or below it dropped */
  iris_bench_point net[3];
  CHECK_EQ_INT(iris_bench_net_curve(line, 3, 0.2, net), 2);
  CHECK_NEAR(net[0].relmse, 0.3, 1e-12);
  CHECK_NEAR(net[1].relmse, 0.05, 1e-12);
  CHECK_NEAR(net[1].seconds, 2.0, 0);
  CHECK_EQ_INT(iris_bench_net_curve(line, 3, 0.5, net), 0);
  CHECK_EQ_INT(iris_bench_net_curve(line, 3, 0.0, net), 3);
  /* on the net line (relMSE - 0.1) the target 0.15 is reached at t = 2 exactly */
  CHECK_NEAR(iris_bench_time_to_target(net, iris_bench_net_curve(line, 3, 0.1, net), 0.15, &ex), 2.0, 1e-9);
  CHECK(!ex);

  /* The premise, on 120 000 values: with a reference as noisy as the test
   * (relative noise 5% each) the measured relMSE is twice the true one, and
   * minus the reference's own it is the true one within 3% (its sampling
   * error here is ~0.6%); a reference 3x quieter still adds 11%. */
  double gross, own, truth;
  premise(0.05, 0.05, &gross, &own, &truth);
  CHECK(gross > 1.8 * truth);
  CHECK_NEAR((gross - own) / truth, 1.0, 0.03);
  premise(0.05 / 3.0, 0.05, &gross, &own, &truth);
  CHECK(gross > 1.08 * truth);
  CHECK_NEAR((gross - own) / truth, 1.0, 0.03);
  return TEST_SUMMARY();
}
