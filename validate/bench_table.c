/* Bench tables (validate/bench_table.h). */
#include "validate/bench_table.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"

int iris_bench_curve(const iris_bench_row *rows, size_t row_count, const char *scene,
                     const char *method, const double *budgets, int budget_count,
                     iris_bench_point *out) {
  int n = 0;
  for (int t = 0; t < budget_count; t++) {
    iris_bench_point pt;
    memset(&pt, 0, sizeof pt);
    pt.budget = budgets[t];
    pt.relmse_min = INFINITY;
    pt.relmse_max = -INFINITY;
    for (size_t i = 0; i < row_count; i++) {
      const iris_bench_row *r = &rows[i];
      if (r->budget_s != budgets[t] || strcmp(r->scene, scene) != 0 || strcmp(r->method, method) != 0)
        continue;
      pt.runs++;
      pt.seconds += r->seconds;
      pt.relmse += r->relmse;
      pt.spp += r->spp;
      if (r->relmse < pt.relmse_min) pt.relmse_min = r->relmse;
      if (r->relmse > pt.relmse_max) pt.relmse_max = r->relmse;
    }
    if (pt.runs == 0) continue;
    pt.seconds /= pt.runs;
    pt.relmse /= pt.runs;
    pt.spp /= pt.runs;
    out[n++] = pt;
  }
  return n;
}

double iris_bench_time_to_target(const iris_bench_point *pts, int count, double target,
                                 bool *extrapolated) {
  *extrapolated = false;
  if (count < 1 || !(target > 0.0)) return -1.0;
  int first = -1;
  for (int i = 0; i < count; i++)
    if (pts[i].relmse <= target) {
      first = i;
      break;
    }
  if (first > 0) {
    const iris_bench_point *a = &pts[first - 1], *b = &pts[first];
    if (a->seconds > 0 && b->seconds > 0 && a->relmse > 0 && b->relmse > 0 &&
        a->relmse != b->relmse) {
      double u = (log(target) - log(a->relmse)) / (log(b->relmse) - log(a->relmse));
      return exp(log(a->seconds) + u * (log(b->seconds) - log(a->seconds)));
    }
    return b->seconds;
  }
  /* Not bracketed: relMSE ~ 1/t from the nearest point. */
  const iris_bench_point *q = first == 0 ? &pts[0] : &pts[count - 1];
  *extrapolated = true;
  if (!(q->relmse > 0.0)) return q->seconds;
  return q->seconds * q->relmse / target;
}

double iris_bench_default_target(const iris_bench_point *pts, int count) {
  if (count < 1) return -1.0;
  double a = pts[0].relmse, b = pts[count - 1].relmse;
  if (!(a > 0.0) || !(b > 0.0)) return a > 0.0 ? a : b;
  return sqrt(a * b);
}

int iris_bench_net_curve(const iris_bench_point *pts, int count, double own, iris_bench_point *out) {
  int n = 0;
  for (int i = 0; i < count; i++) {
    iris_bench_point q = pts[i];
    q.relmse -= own;
    q.relmse_min -= own;
    q.relmse_max -= own;
    if (q.relmse > 0.0) out[n++] = q;
  }
  return n;
}

/* ---- writing --------------------------------------------------------------- */

typedef struct method_curve {
  char name[32];
  iris_bench_point pts[IRIS_BENCH_MAX_TIMES];
  int count;
  double ttt;        /* time to target */
  bool extrapolated;
} method_curve;

/* The row name of a method in the tables: its label, and for a method that
 * resolves per scene (auto) what it resolved to, e.g. "auto (guided-nee)";
 * "auto (mis, guided-nee)" if the runs did not all choose the same. */
static const char *display_name(const iris_bench_result *res, const char *scene, const char *label, char *buf,
                                size_t size) {
  snprintf(buf, size, "%.31s", label);
  size_t at = strlen(buf);
  int found = 0;
  for (size_t i = 0; i < res->row_count; i++) {
    const iris_bench_row *r = &res->rows[i];
    if (strcmp(r->scene, scene) != 0 || strcmp(r->method, label) != 0 || !r->resolved[0] ||
        strcmp(r->resolved, label) == 0 || strncmp(r->resolved, label, strlen(r->resolved)) == 0)
      continue;
    bool seen = false; /* already listed */
    for (size_t j = 0; j < i && !seen; j++) {
      const iris_bench_row *q = &res->rows[j];
      seen = strcmp(q->scene, scene) == 0 && strcmp(q->method, label) == 0 && strcmp(q->resolved, r->resolved) == 0;
    }
    if (seen) continue;
    at += (size_t)snprintf(buf + at, at < size ? size - at : 0, "%s%.31s", found++ ? ", " : " (", r->resolved);
    if (at >= size) break;
  }
  if (found && at + 1 < size) snprintf(buf + at, size - at, ")");
  return buf;
}

static int collect(const iris_bench_params *p, const iris_bench_result *res, const char *scene,
                   const double *budgets, method_curve *mc) {
  int n = 0;
  for (int k = 0; k <= p->method_count + 1; k++) {
    char label[64];
    const char *name = k < p->method_count    ? iris_bench_method_label(p, k, label, sizeof label)
                       : k == p->method_count ? "cycles"
                                              : "cycles-adaptive";
    snprintf(mc[n].name, sizeof mc[n].name, "%s", name);
    mc[n].count = iris_bench_curve(res->rows, res->row_count, scene, name, budgets, p->time_count,
                                   mc[n].pts);
    if (mc[n].count > 0) n++;
  }
  return n;
}

static const iris_bench_point *at_budget(const method_curve *m, double budget) {
  for (int i = 0; i < m->count; i++)
    if (m->pts[i].budget == budget) return &m->pts[i];
  return NULL;
}

static void fmt_seconds(char *buf, size_t size, double s) {
  if (s < 10.0)
    snprintf(buf, size, "%.2f s", s);
  else if (s < 1000.0)
    snprintf(buf, size, "%.1f s", s);
  else
    snprintf(buf, size, "%.0f s", s);
}

/* A speed-up factor with two significant digits also when it is tiny. */
static void fmt_factor(char *buf, size_t size, double f) {
  if (f >= 0.095)
    snprintf(buf, size, "%.2fx", f);
  else
    snprintf(buf, size, "%.2gx", f);
}

/* One cell of the equal-time table and the time-to-target cells, as text;
 * html selects the HTML flavour (title attributes with the spread). */
static void cell_relmse(char *buf, size_t size, const method_curve *m, const method_curve *base,
                        double budget, bool html) {
  const iris_bench_point *pt = at_budget(m, budget);
  if (!pt) {
    snprintf(buf, size, "-");
    return;
  }
  const iris_bench_point *bp = base ? at_budget(base, budget) : NULL;
  char speed[64] = "";
  if (bp && pt->relmse > 0 && m != base) {
    char x[32];
    fmt_factor(x, sizeof x, bp->relmse / pt->relmse);
    snprintf(speed, sizeof speed, " (%s)", x);
  }
  char at[64] = "";
  /* setup alone over the budget: the run took longer, say so */
  if (pt->seconds > 1.25 * budget + 0.05) {
    char s[32];
    fmt_seconds(s, sizeof s, pt->seconds);
    snprintf(at, sizeof at, " [took %s]", s);
  }
  if (strcmp(m->name, "cycles") == 0) {
    char s[32];
    fmt_seconds(s, sizeof s, pt->seconds);
    snprintf(at, sizeof at, " @ %s, %.0f spp", s, pt->spp);
    speed[0] = 0; /* not at equal time: no equal-time speed-up */
  } else if (strcmp(m->name, "cycles-adaptive") == 0) {
    char s[32];
    fmt_seconds(s, sizeof s, pt->seconds);
    snprintf(at, sizeof at, " @ %s", s); /* the budget is its time limit; it may stop earlier */
  }
  if (html)
    snprintf(buf, size, "<span title=\"min %.4g, max %.4g over %d seed(s); %.1f s, %.0f spp\">%.4g</span>%s%s",
             pt->relmse_min, pt->relmse_max, pt->runs, pt->seconds, pt->spp, pt->relmse, speed, at);
  else
    snprintf(buf, size, "%.4g%s%s", pt->relmse, speed, at);
}

/* One scene's table: relMSE per budget (speed-up against `base` at equal
 * time) and the time to `target` with its speed-up. */
static void write_scene_table(FILE *m, FILE *h, const iris_bench_params *p, const iris_bench_result *res,
                              const char *scene, const double *budgets, method_curve *mc, int n,
                              const method_curve *base, double target, const char *caption) {
  for (int k = 0; k < n; k++) mc[k].ttt = iris_bench_time_to_target(mc[k].pts, mc[k].count, target, &mc[k].extrapolated);
  fprintf(m, "### %s\n\n| method |", caption);
  fprintf(h, "<table><caption>%s</caption>\n<tr><th>method</th>", caption);
  for (int t = 0; t < p->time_count; t++) {
    fprintf(m, " %g s |", budgets[t]);
    fprintf(h, "<th>%g s</th>", budgets[t]);
  }
  fprintf(m, " time to relMSE %.3g | speed-up |\n|---|", target);
  fprintf(h, "<th>time to relMSE %.3g</th><th>speed-up</th></tr>\n", target);
  for (int t = 0; t < p->time_count + 2; t++) fprintf(m, "---:|");
  fprintf(m, "\n");
  for (int k = 0; k < n; k++) {
    char shown[96];
    display_name(res, scene, mc[k].name, shown, sizeof shown);
    fprintf(m, "| %s |", shown);
    fprintf(h, "<tr><td>%s</td>", shown);
    for (int t = 0; t < p->time_count; t++) {
      char c[400];
      cell_relmse(c, sizeof c, &mc[k], base, budgets[t], false);
      fprintf(m, " %s |", c);
      cell_relmse(c, sizeof c, &mc[k], base, budgets[t], true);
      fprintf(h, "<td>%s</td>", c);
    }
    char ts[48] = "-", sp[48] = "-";
    if (mc[k].ttt > 0) {
      char s2[32];
      fmt_seconds(s2, sizeof s2, mc[k].ttt);
      snprintf(ts, sizeof ts, "%s%s", mc[k].extrapolated ? "~" : "", s2);
      if (base && base->ttt > 0) {
        char x[32];
        fmt_factor(x, sizeof x, base->ttt / mc[k].ttt);
        snprintf(sp, sizeof sp, "%s%s", (mc[k].extrapolated || base->extrapolated) ? "~" : "", x);
      }
    }
    fprintf(m, " %s | %s |\n", ts, sp);
    fprintf(h, "<td>%s</td><td>%s</td></tr>\n", ts, sp);
  }
  fprintf(m, "\n");
  fprintf(h, "</table>\n");
}

iris_status iris_bench_write_tables(const char *dir, const iris_bench_params *p,
                                    iris_bench_result *res, iris_error *err) {
  double budgets[IRIS_BENCH_MAX_TIMES];
  memcpy(budgets, p->times, sizeof budgets);
  /* the caller's order may be unsorted: sort a copy (small n) */
  for (int i = 1; i < p->time_count; i++)
    for (int j = i; j > 0 && budgets[j] < budgets[j - 1]; j--) {
      double t = budgets[j];
      budgets[j] = budgets[j - 1];
      budgets[j - 1] = t;
    }
  char md_path[1300], html_path[1300];
  iris_path_join(dir, "table.md", md_path, sizeof md_path);
  iris_path_join(dir, "table.html", html_path, sizeof html_path);
  iris_atomic_file md, html;
  iris_status st = iris_atomic_open(&md, md_path, err);
  if (st != IRIS_OK) return st;
  st = iris_atomic_open(&html, html_path, err);
  if (st != IRIS_OK) {
    iris_atomic_abort(&md);
    return st;
  }
  FILE *m = md.fp, *h = html.fp;
  fprintf(h, "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
             "<title>iris bench tables</title><style>"
             "body{font-family:sans-serif;margin:1.5em}table{border-collapse:collapse;margin:.5em 0 1.5em}"
             "td,th{border:1px solid #bbb;padding:.25em .6em;text-align:right}"
             "td:first-child,th:first-child{text-align:left}caption{text-align:left;font-weight:bold}"
             "</style></head><body>\n<!-- iris-bench-tables -->\n");
  fprintf(m, "relMSE (eps 0.01, top 0.1%% of pixels dropped) is the mean over the seeds; in brackets the\n"
             "speed-up against mis at equal time, relMSE(mis) / relMSE(method). Budgets are wall-clock\n"
             "seconds with setup included. Time to target is interpolated in log-log between the two\n"
             "budgets around the target (~: extrapolated with relMSE ~ 1/t). [took T]: the run needed T\n"
             "seconds, more than its budget (setup alone exceeded it; at least one pass always runs).\n"
             "Every relMSE also holds the reference's own error (\"its own relMSE\" in the captions, from\n"
             "its variance), which pulls the speed-ups towards 1 unless it is far below the values; where it\n"
             "is known, a second table gives every relMSE net of it, an estimate of the error against the truth.\n\n");
  fprintf(h, "<p>relMSE (&epsilon; = 0.01, top 0.1%% of pixels dropped), mean over the seeds (hover for the "
             "spread); in brackets the speed-up against mis at equal time, relMSE(mis) / relMSE(method). "
             "Budgets are wall-clock seconds with setup included. Time to target is interpolated in log-log "
             "between the budgets around the target (~: extrapolated with relMSE &prop; 1/t). [took T]: the run "
             "needed T seconds, more than its budget (setup alone exceeded it; at least one pass always runs). "
             "Every relMSE also holds the reference's own error (&ldquo;its own relMSE&rdquo; in the captions, "
             "from its variance), which pulls the speed-ups towards 1 unless it is far below the values; where it is "
             "known, a second table gives every relMSE net of it, an estimate of the error against the truth.</p>\n");
  for (int s = 0; s < res->scene_count; s++) {
    iris_bench_scene *sc = &res->scenes[s];
    method_curve mc[IRIS_BENCH_MAX_METHODS + 1];
    int n = collect(p, res, sc->name, budgets, mc);
    const method_curve *base = NULL;
    for (int k = 0; k < n; k++)
      if (strcmp(mc[k].name, "mis") == 0) base = &mc[k];
    if (!base && n > 0) base = &mc[0];
    double target = p->target_relmse > 0 ? p->target_relmse
                    : base ? iris_bench_default_target(base->pts, base->count)
                           : -1.0;
    sc->target_relmse = target;
    char caption[sizeof sc->reference_description + 200];
    snprintf(caption, sizeof caption, "%s (%dx%d; reference: %s)", sc->name, sc->width, sc->height,
             sc->reference_description);
    write_scene_table(m, h, p, res, sc->name, budgets, mc, n, base, target, caption);
    /* The same net of the reference's own error (iris_bench_net_curve): the
     * target moves with it, so that it is the same error against the truth. */
    const double own = sc->reference_relmse;
    if (!(own > 0.0) || !base) continue;
    method_curve net[IRIS_BENCH_MAX_METHODS + 1];
    const method_curve *net_base = NULL;
    for (int k = 0; k < n; k++) {
      net[k] = mc[k];
      net[k].count = iris_bench_net_curve(mc[k].pts, mc[k].count, own, net[k].pts);
      if (&mc[k] == base) net_base = &net[k];
    }
    double net_target = target - own;
    if (!(net_target > 0.0)) net_target = iris_bench_default_target(net_base->pts, net_base->count);
    snprintf(caption, sizeof caption,
             "%s net of the reference's own relMSE %.3g (each relMSE minus it; an error within it cannot be "
             "measured: -)",
             sc->name, own);
    write_scene_table(m, h, p, res, sc->name, budgets, net, n, net_base, net_target, caption);
  }
  fprintf(h, "<!-- /iris-bench-tables -->\n</body></html>\n");
  if (ferror(m) || ferror(h)) {
    iris_atomic_abort(&md);
    iris_atomic_abort(&html);
    return iris_error_set(err, IRIS_ERR_IO, dir, 0, NULL, "cannot write the tables");
  }
  st = iris_atomic_commit(&md, err);
  if (st != IRIS_OK) {
    iris_atomic_abort(&html);
    return st;
  }
  return iris_atomic_commit(&html, err);
}
