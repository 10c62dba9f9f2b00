/* iris bench's result files (validate/bench.h): results.csv and results.json,
 * written after every scene so that an interrupted run keeps what it did. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "core/fileio.h"
#include "validate/bench.h"
#include "validate/json_out.h"
#include "validate/metrics.h"

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

/* The reference's own relMSE of a scene (from its variance), < 0 if unknown. */
static double own_relmse(const iris_bench_result *res, const char *scene) {
  for (int i = 0; i < res->scene_count; i++)
    if (strcmp(res->scenes[i].name, scene) == 0) return res->scenes[i].reference_relmse;
  return -1.0;
}

/* A row's relMSE net of the reference's own (docs/benchmarks.md, "Net of the
 * reference's noise"): NaN where that is unknown. One seed's value may be
 * negative: it is a difference of two noisy numbers. */
static double relmse_net(const iris_bench_result *res, const iris_bench_row *r) {
  const double own = own_relmse(res, r->scene);
  return own >= 0.0 && isfinite(r->relmse) ? r->relmse - own : NAN;
}

iris_status iris_bench_write_csv(const char *path, const iris_bench_result *res, iris_error *err) {
  iris_atomic_file f;
  iris_status st = iris_atomic_open(&f, path, err);
  if (st != IRIS_OK) return st;
  fprintf(f.fp, "scene,method,seed,budget_s,seconds,spp,relmse,mape,energy_ratio,resolved,relmse_net,relmse_full\n");
  for (size_t i = 0; i < res->row_count; i++) {
    const iris_bench_row *r = &res->rows[i];
    fprintf(f.fp, "%s,%s,%llu,%g,%.4f,%d,%.6g,%.6g,%.6g,%s,", r->scene, r->method,
            (unsigned long long)r->seed, r->budget_s, r->seconds, r->spp, r->relmse, r->mape,
            r->energy_ratio, r->resolved[0] ? r->resolved : r->method);
    const double net = relmse_net(res, r);
    if (isfinite(net)) fprintf(f.fp, "%.6g", net); /* empty where the reference's own is unknown */
    fprintf(f.fp, ",%.6g\n", r->relmse_full);
  }
  if (ferror(f.fp)) {
    iris_atomic_abort(&f);
    return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "write failed");
  }
  return iris_atomic_commit(&f, err);
}

iris_status iris_bench_write_json(const char *path, const iris_bench_params *p,
                                  const iris_bench_result *res, iris_error *err) {
  cJSON *o = cJSON_CreateObject();
  cJSON_AddStringToObject(o, "kind", "iris-bench");
  cJSON_AddStringToObject(o, "iris_version", IRIS_VERSION_STRING);
  time_t now = time(NULL);
  char date[64];
  strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", gmtime(&now));
  cJSON_AddStringToObject(o, "date", date);
  cJSON_AddBoolToObject(o, "interrupted", res->interrupted);
  cJSON *mach = cJSON_AddObjectToObject(o, "machine");
  cJSON_AddNumberToObject(mach, "cpus", res->cpus);
  cJSON *lb = cJSON_AddArrayToObject(mach, "load_average_before");
  cJSON *la = cJSON_AddArrayToObject(mach, "load_average_after");
  for (int i = 0; i < 3; i++) {
    cJSON_AddItemToArray(lb, cJSON_CreateNumber(res->load_before[i]));
    cJSON_AddItemToArray(la, cJSON_CreateNumber(res->load_after[i]));
  }
  cJSON *par = cJSON_AddObjectToObject(o, "params");
  cJSON *ms = cJSON_AddArrayToObject(par, "methods");
  for (int k = 0; k < p->method_count; k++)
  {
    char label[64];
    cJSON_AddItemToArray(ms, cJSON_CreateString(iris_bench_method_label(p, k, label, sizeof label)));
  }
  if (res->cycles_done) cJSON_AddItemToArray(ms, cJSON_CreateString("cycles"));
  if (res->cycles_adaptive_done) cJSON_AddItemToArray(ms, cJSON_CreateString("cycles-adaptive"));
  cJSON *ts = cJSON_AddArrayToObject(par, "times");
  double times[IRIS_BENCH_MAX_TIMES];
  memcpy(times, p->times, sizeof times);
  qsort(times, (size_t)p->time_count, sizeof times[0], cmp_double);
  for (int t = 0; t < p->time_count; t++) cJSON_AddItemToArray(ts, cJSON_CreateNumber(times[t]));
  cJSON_AddNumberToObject(par, "seeds", p->seeds);
  cJSON_AddNumberToObject(par, "threads", p->threads > 0 ? p->threads : res->cpus);
  cJSON_AddNumberToObject(par, "relmse_eps", IRIS_METRIC_EPS);
  cJSON_AddNumberToObject(par, "relmse_drop", IRIS_METRIC_DROP);
  cJSON_AddBoolToObject(par, "budget_includes_setup", true);
  if (res->cycles_done || res->cycles_adaptive_done)
    cJSON_AddStringToObject(par, "cycles_version", res->cycles_version);
  if (res->cycles_adaptive_done) cJSON_AddNumberToObject(par, "cycles_threshold", p->cycles_threshold);
  cJSON *scs = cJSON_AddArrayToObject(o, "scenes");
  for (int i = 0; i < res->scene_count; i++) {
    const iris_bench_scene *sc = &res->scenes[i];
    cJSON *j = cJSON_CreateObject();
    cJSON_AddStringToObject(j, "name", sc->name);
    cJSON_AddStringToObject(j, "input", sc->input);
    cJSON_AddNumberToObject(j, "width", sc->width);
    cJSON_AddNumberToObject(j, "height", sc->height);
    cJSON *r = cJSON_AddObjectToObject(j, "reference");
    cJSON_AddStringToObject(r, "path", sc->reference);
    cJSON_AddStringToObject(r, "description", sc->reference_description);
    cJSON_AddNumberToObject(r, "spp", sc->reference_spp);
    iris_json_add_number(r, "own_relmse", sc->reference_relmse >= 0.0 ? sc->reference_relmse : NAN);
    iris_json_add_number(j, "target_relmse", sc->target_relmse > 0 ? sc->target_relmse : NAN);
    cJSON *im = cJSON_AddArrayToObject(j, "images");
    for (int k = 0; k < sc->image_count; k++) {
      cJSON *e = cJSON_CreateObject();
      char name[300];
      cJSON_AddStringToObject(e, "what", sc->images[k]);
      snprintf(name, sizeof name, "images/%s-%s.png", sc->name, sc->images[k]);
      cJSON_AddStringToObject(e, "image", name);
      if (strcmp(sc->images[k], "reference") != 0) {
        snprintf(name, sizeof name, "images/%s-%s-diff.png", sc->name, sc->images[k]);
        cJSON_AddStringToObject(e, "diff", name);
        /* adaptive rows: their sample-count map (write_count_map) */
        snprintf(name, sizeof name, "images/%s-%s-spp.png", sc->name, sc->images[k]);
        char full[1500];
        iris_path_join(p->out_dir, name, full, sizeof full);
        if (iris_path_exists(full)) cJSON_AddStringToObject(e, "spp", name);
      }
      cJSON_AddItemToArray(im, e);
    }
    char chart[300];
    snprintf(chart, sizeof chart, "charts/%s.png", sc->name);
    cJSON_AddStringToObject(j, "chart_png", chart);
    snprintf(chart, sizeof chart, "charts/%s.svg", sc->name);
    cJSON_AddStringToObject(j, "chart_svg", chart);
    cJSON_AddItemToArray(scs, j);
  }
  cJSON *rows = cJSON_AddArrayToObject(o, "rows");
  for (size_t i = 0; i < res->row_count; i++) {
    const iris_bench_row *r = &res->rows[i];
    cJSON *j = cJSON_CreateObject();
    cJSON_AddStringToObject(j, "scene", r->scene);
    cJSON_AddStringToObject(j, "method", r->method);
    cJSON_AddStringToObject(j, "resolved", r->resolved[0] ? r->resolved : r->method);
    if (r->method_reason[0]) cJSON_AddStringToObject(j, "method_reason", r->method_reason);
    cJSON_AddNumberToObject(j, "seed", (double)r->seed);
    cJSON_AddNumberToObject(j, "budget_s", r->budget_s);
    iris_json_add_number(j, "seconds", r->seconds);
    iris_json_add_number(j, "setup_seconds", r->setup_seconds);
    cJSON_AddNumberToObject(j, "spp", r->spp);
    iris_json_add_number(j, "relmse", r->relmse);
    iris_json_add_number(j, "relmse_net", relmse_net(res, r));
    iris_json_add_number(j, "relmse_full", r->relmse_full);
    iris_json_add_number(j, "mape", r->mape);
    iris_json_add_number(j, "energy_ratio", r->energy_ratio);
    cJSON_AddNumberToObject(j, "nonfinite", (double)r->nonfinite);
    cJSON_AddItemToArray(rows, j);
  }
  cJSON *out = cJSON_AddObjectToObject(o, "outputs");
  cJSON_AddStringToObject(out, "csv", "results.csv");
  cJSON_AddStringToObject(out, "table_md", "table.md");
  cJSON_AddStringToObject(out, "table_html", "table.html");
  cJSON_AddBoolToObject(out, "charts", res->charts);
  if (res->charts) {
    cJSON_AddStringToObject(out, "chart_png", "charts/convergence.png");
    cJSON_AddStringToObject(out, "chart_svg", "charts/convergence.svg");
  }
  return iris_json_write_file(o, path, err);
}
