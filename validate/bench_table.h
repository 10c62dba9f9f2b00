/* The tables of `iris bench`: per scene, relMSE at equal time (mean over the
 * seeds, with the speed-up against mis) and the time each method needs to reach
 * a target relMSE, interpolated in log-log. Written as DIR/table.md and
 * DIR/table.html. Formulas in docs/benchmarks.md ("Tables"). */
#ifndef IRIS_VALIDATE_BENCH_TABLE_H
#define IRIS_VALIDATE_BENCH_TABLE_H

#include <stdbool.h>
#include <stddef.h>

#include "core/error.h"
#include "validate/bench.h"

#ifdef __cplusplus
extern "C" {
#endif

/* One budget of one scene and method, over its seeds. */
typedef struct iris_bench_point {
  double budget;
  double seconds;                 /* mean measured seconds */
  double relmse;                  /* mean over the seeds */
  double relmse_min, relmse_max;
  double spp;                     /* mean spp */
  int runs;                       /* seeds averaged */
} iris_bench_point;

/* Points of `scene` x `method` for each of the budgets that has rows, in
 * budget order (at most budget_count). Returns the number of points. */
int iris_bench_curve(const iris_bench_row *rows, size_t row_count, const char *scene,
                     const char *method, const double *budgets, int budget_count,
                     iris_bench_point *out);

/* Seconds at which the curve reaches relMSE `target`: the first point at or
 * below the target and its predecessor, interpolated linearly in (log t,
 * log relMSE). When no pair brackets the target, the Monte Carlo law relMSE ~
 * 1/t is followed from the nearest point (t = t_i relmse_i / target) and
 * *extrapolated is set. -1 when there are no points. */
double iris_bench_time_to_target(const iris_bench_point *pts, int count, double target,
                                 bool *extrapolated);

/* Default target of a scene: the geometric mean of the first and last relMSE
 * of the reference method's curve, so that it is reached mid-range. */
double iris_bench_default_target(const iris_bench_point *pts, int count);

/* The curve net of the reference's own relMSE `own` (its variance channels'
 * expected error, iris_metric_own_relmse): every relMSE measured against a
 * noisy reference r estimates E[(t - r)^2] = E[(t - T)^2] + Var(r) for the
 * truth T and r independent of t, so relMSE - own estimates the error against
 * the truth (docs/benchmarks.md, "Net of the reference's noise"). Points
 * whose mean falls to <= 0 (an error within the reference's own) are dropped:
 * the reference cannot measure them. Returns the number of points written. */
int iris_bench_net_curve(const iris_bench_point *pts, int count, double own, iris_bench_point *out);

/* Sets each scene's target_relmse (params->target_relmse, else the default
 * from mis, else the first method) and writes DIR/table.md and DIR/table.html
 * and, where the reference's own relMSE is known, a second table net of it
 * (the tables sit between <!-- iris-bench-tables --> markers so that `iris
 * report` can embed them). */
iris_status iris_bench_write_tables(const char *dir, const iris_bench_params *params,
                                    iris_bench_result *res, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
