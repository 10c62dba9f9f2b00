/* bench.table: the time-to-target interpolation and the seed aggregation of
 * validate/bench_table.h on synthetic curves whose answers are known in
 * closed form (relMSE = c / t is a straight line in log-log). */
#include <math.h>
#include <string.h>

#include "check.h"
#include "validate/bench_table.h"

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
  return TEST_SUMMARY();
}
