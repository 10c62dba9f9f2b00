/* stress_suite: the failure-stability suite (docs/stability.md). For every
 * stress scene: a reference (a long mis render, cached in --refs DIR, or the
 * exact black image of stress-closed-box), then every method at equal
 * wall-clock time (setup included), compared with the reference: relMSE,
 * largest pixel, NaN/Inf, mean-energy and 8x8-block z-tests. Writes a
 * Markdown table (--markdown) and CSV (--csv); exit 1 when any method
 * produced NaN/Inf, light in the closed box, or failed a z-test. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/stress/suite.h"
#include "core/fileio.h"
#include "core/log.h"
#include "renderer/render.h"
#include "scenes/stress/stress.h"

#define MAX_METHODS IRIS_METHOD_COUNT
#define MAX_SCENES 16

typedef struct options {
  const char *scenes[MAX_SCENES];
  int scene_count;
  iris_method methods[MAX_METHODS];
  int method_count;
  double seconds, ref_seconds;
  int ref_spp;
  int width, height, threads;
  uint64_t seed;
  const char *refs, *markdown, *csv, *images;
  bool refs_only;
  double alpha, bias_factor;
} options;

static void usage(FILE *f) {
  fprintf(f,
          "Usage: stress_suite [options]\n"
          "  --scenes LIST     comma-separated stress scenes (default: all)\n"
          "  --methods LIST    comma-separated methods (default: bsdf,nee,mis,guided,guided-nee)\n"
          "  --time S          equal wall-clock budget per method, setup included (default 4)\n"
          "  --ref-time S      reference: mis for S seconds (default 60)\n"
          "  --ref-spp N       reference: mis at N spp instead of a time\n"
          "  --refs DIR        load references DIR/<scene>.exr of the right size, else\n"
          "                    render and store them there\n"
          "  --refs-only       only make the references\n"
          "  --width W --height H   film size (default: the scene's)\n"
          "  --threads N --seed S\n"
          "  --alpha A         family-wise significance over all z-tests (default 0.01)\n"
          "  --bias-factor F   a method failing the z-tests at equal time is rendered\n"
          "                    again with F x its samples, at least 32 (default 8; 1: never)\n"
          "  --images DIR      write every render as DIR/<scene>.<method>.exr\n"
          "  --markdown FILE --csv FILE   results\n");
}

static int split(char *s, const char **out, int max) {
  int n = 0;
  for (char *tok = strtok(s, ","); tok && n < max; tok = strtok(NULL, ",")) out[n++] = tok;
  return n;
}

static bool parse(int argc, char **argv, options *o) {
  memset(o, 0, sizeof *o);
  o->seconds = 4.0;
  o->ref_seconds = 60.0;
  o->alpha = 0.01;
  o->bias_factor = 8.0;
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i];
    const char *v = i + 1 < argc ? argv[i + 1] : NULL;
#define NEEDV()                                               \
  do {                                                        \
    if (!v) {                                                 \
      fprintf(stderr, "stress_suite: %s needs a value\n", a); \
      return false;                                           \
    }                                                         \
    i++;                                                      \
  } while (0)
    if (strcmp(a, "--scenes") == 0) {
      NEEDV();
      o->scene_count = split(argv[i], o->scenes, MAX_SCENES);
    } else if (strcmp(a, "--methods") == 0) {
      NEEDV();
      const char *names[MAX_METHODS];
      int k = split(argv[i], names, MAX_METHODS);
      for (int j = 0; j < k; j++)
        if (!iris_method_parse(names[j], &o->methods[o->method_count++])) {
          fprintf(stderr, "stress_suite: unknown method '%s'\n", names[j]);
          return false;
        }
    } else if (strcmp(a, "--time") == 0) {
      NEEDV();
      o->seconds = atof(v);
    } else if (strcmp(a, "--ref-time") == 0) {
      NEEDV();
      o->ref_seconds = atof(v);
    } else if (strcmp(a, "--ref-spp") == 0) {
      NEEDV();
      o->ref_spp = atoi(v);
    } else if (strcmp(a, "--refs") == 0) {
      NEEDV();
      o->refs = v;
    } else if (strcmp(a, "--refs-only") == 0) {
      o->refs_only = true;
    } else if (strcmp(a, "--width") == 0) {
      NEEDV();
      o->width = atoi(v);
    } else if (strcmp(a, "--height") == 0) {
      NEEDV();
      o->height = atoi(v);
    } else if (strcmp(a, "--threads") == 0) {
      NEEDV();
      o->threads = atoi(v);
    } else if (strcmp(a, "--seed") == 0) {
      NEEDV();
      o->seed = strtoull(v, NULL, 10);
    } else if (strcmp(a, "--alpha") == 0) {
      NEEDV();
      o->alpha = atof(v);
    } else if (strcmp(a, "--bias-factor") == 0) {
      NEEDV();
      o->bias_factor = atof(v);
    } else if (strcmp(a, "--images") == 0) {
      NEEDV();
      o->images = v;
    } else if (strcmp(a, "--markdown") == 0) {
      NEEDV();
      o->markdown = v;
    } else if (strcmp(a, "--csv") == 0) {
      NEEDV();
      o->csv = v;
    } else if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
      usage(stdout);
      exit(0);
    } else {
      fprintf(stderr, "stress_suite: unknown option '%s'\n", a);
      usage(stderr);
      return false;
    }
#undef NEEDV
  }
  if (o->scene_count == 0) {
    size_t n;
    const iris_stress_info *all = iris_stress_scenes(&n);
    for (size_t k = 0; k < n && k < MAX_SCENES; k++) o->scenes[o->scene_count++] = all[k].name;
  }
  if (o->method_count == 0)
    for (int m = 0; m < IRIS_METHOD_COUNT; m++) o->methods[o->method_count++] = (iris_method)m;
  for (int k = 0; k < o->scene_count; k++)
    if (!iris_stress_find(o->scenes[k])) {
      fprintf(stderr, "stress_suite: '%s' is not a stress scene\n", o->scenes[k]);
      return false;
    }
  if (o->seconds <= 0 || o->alpha <= 0 || o->alpha >= 1) {
    fprintf(stderr, "stress_suite: --time and --alpha must be positive (alpha < 1)\n");
    return false;
  }
  return true;
}

static bool report(iris_status st, const iris_error *err) {
  if (st == IRIS_OK) return true;
  char buf[1400];
  iris_error_format(err, buf, sizeof buf);
  fprintf(stderr, "stress_suite: %s\n", buf);
  return false;
}

/* The reference of one scene: exact black, a cached EXR of the right size,
 * or a fresh long mis render (stored when --refs is given). */
static bool make_reference(const options *o, const iris_stress_info *info, const iris_scene *scene,
                           iris_image *ref, bool *exact, int *ref_spp, double *ref_seconds) {
  iris_error err;
  iris_error_clear(&err);
  iris_stress_params p = iris_stress_params_default();
  p.width = o->width;
  p.height = o->height;
  p.threads = o->threads;
  p.seed = o->seed + 1000003; /* independent of the tested renders */
  *exact = info->black;
  *ref_spp = 0;
  *ref_seconds = 0;
  if (info->black) {
    /* size only: a 1 spp bsdf render gives the film size */
    iris_stress_render_out r;
    p.spp = 1;
    if (!report(iris_stress_render(scene, IRIS_METHOD_BSDF, &p, &r, &err), &err)) return false;
    static const char *const names[6] = {"R", "G", "B", "var.R", "var.G", "var.B"};
    bool ok = report(iris_image_create(ref, r.image.width, r.image.height, 6, names, &err), &err);
    iris_stress_render_out_destroy(&r);
    return ok;
  }
  char path[1024] = "";
  if (o->refs) {
    snprintf(path, sizeof path, "%s/%s.exr", o->refs, info->name);
    if (iris_stress_image_read(path, ref, ref_spp, ref_seconds, &err) == IRIS_OK) {
      bool size_ok = true;
      if (o->width > 0 && ref->width != o->width) size_ok = false;
      if (o->height > 0 && ref->height != o->height) size_ok = false;
      if (o->width <= 0 && o->height <= 0 && ref->width != scene->render.width) size_ok = false;
      if (size_ok) {
        fprintf(stderr, "%s: reference %s (%d spp)\n", info->name, path, *ref_spp);
        return true;
      }
      iris_image_destroy(ref);
    }
    iris_error_clear(&err);
  }
  iris_stress_render_out r;
  if (o->ref_spp > 0)
    p.spp = o->ref_spp;
  else
    p.seconds = o->ref_seconds;
  fprintf(stderr, "%s: rendering the mis reference (%s %g)...\n", info->name,
          o->ref_spp > 0 ? "spp" : "seconds", o->ref_spp > 0 ? (double)o->ref_spp : o->ref_seconds);
  if (!report(iris_stress_render(scene, IRIS_METHOD_MIS, &p, &r, &err), &err)) return false;
  *ref = r.image;
  *ref_spp = r.spp;
  *ref_seconds = r.seconds;
  if (path[0] && !report(iris_stress_image_write(path, ref, info->name, "mis", r.spp, r.seconds, &err), &err)) {
    iris_image_destroy(ref);
    return false;
  }
  return true;
}

typedef enum verdict {
  V_OK = 0,     /* unbiased at equal time */
  V_OK_LONG,    /* z-test fails at equal time, passes with bias_factor x the samples: under-sampled */
  V_UNRESOLVED, /* fails both, only by regions too dark: rare large samples not drawn yet */
  V_BIASED,     /* fails both with a region too bright, or the image mean off */
  V_NONFINITE,  /* NaN/Inf in the image or samples dropped as NaN/Inf */
  V_LEAK        /* light in the closed box */
} verdict;

static const char *const VERDICT_CSV[] = {"ok", "ok-long", "unresolved", "biased", "nonfinite", "light-leak"};

typedef struct row {
  const char *scene;
  iris_method method;
  iris_stress_render_out r, rl; /* equal time; long (bias check), when r failed the z-test */
  iris_stress_compare c, cl;
  bool have_long;
  bool slow;
  verdict v;
} row;

static bool nonfinite(const iris_stress_render_out *r, const iris_stress_compare *c) {
  return c->nan_values + c->inf_values + r->dropped > 0;
}

static const char *fmt_g(char *buf, size_t n, double v) {
  if (v == 0.0)
    snprintf(buf, n, "0");
  else if (fabs(v) >= 1e4 || fabs(v) < 1e-3)
    snprintf(buf, n, "%.2e", v);
  else
    snprintf(buf, n, "%.3g", v);
  return buf;
}

static void print_run(const char *scene, const char *what, iris_method m,
                      const iris_stress_render_out *r, const iris_stress_compare *c) {
  fprintf(stderr,
          "%-20s %-10s %-5s %6d spp %7.2f s  relMSE %-9.4g max %-9.4g NaN/Inf %llu+%llu "
          "dropped %llu  E %.4g/%.4g z %+.2f  regions max|z| %.2f/%.2f (%d low, %d high)  8x8 max|z| %.2f/%.2f\n",
          scene, iris_method_name(m), what, r->spp, r->seconds, c->relmse, c->max_value,
          (unsigned long long)c->nan_values, (unsigned long long)c->inf_values,
          (unsigned long long)r->dropped, c->energy_test, c->energy_ref, c->energy_z,
          c->regions.max_abs_z, c->regions.z_crit, c->regions_low, c->regions_high, c->blocks.max_abs_z,
          c->blocks.z_crit);
}

int main(int argc, char **argv) {
  options o;
  if (!parse(argc, argv, &o)) return 2;
  iris_log_set_level(IRIS_LOG_WARN);
  {
    iris_error err;
    iris_error_clear(&err);
    if ((o.refs && !report(iris_mkdir_p(o.refs, &err), &err)) ||
        (o.images && !report(iris_mkdir_p(o.images, &err), &err)))
      return 1;
  }
  const int tests = o.scene_count * o.method_count;
  const double alpha_each = o.alpha / (tests > 0 ? tests : 1);
  const double zcrit = iris_stress_energy_zcrit(alpha_each);
  row *rows = calloc((size_t)(tests > 0 ? tests : 1), sizeof *rows);
  if (!rows) return 1;
  int nrows = 0, failures = 0;
  double ref_floor[MAX_SCENES] = {0};
  int ref_spp[MAX_SCENES] = {0};
  double ref_secs[MAX_SCENES] = {0};
  for (int si = 0; si < o.scene_count; si++) {
    const iris_stress_info *info = iris_stress_find(o.scenes[si]);
    iris_scene *scene = NULL;
    iris_error err;
    iris_error_clear(&err);
    if (!report(iris_stress_create(info->name, &scene, &err), &err)) return 1;
    iris_image ref;
    bool exact;
    if (!make_reference(&o, info, scene, &ref, &exact, &ref_spp[si], &ref_secs[si])) return 1;
    if (o.refs_only) {
      iris_image_destroy(&ref);
      iris_scene_destroy(scene);
      continue;
    }
    double best = INFINITY;
    int first = nrows;
    for (int mi = 0; mi < o.method_count; mi++) {
      row *w = &rows[nrows++];
      w->scene = info->name;
      w->method = o.methods[mi];
      iris_stress_params p = iris_stress_params_default();
      p.width = o.width;
      p.height = o.height;
      p.threads = o.threads;
      p.seed = o.seed;
      p.seconds = o.seconds;
      if (!report(iris_stress_render(scene, w->method, &p, &w->r, &err), &err) ||
          !report(iris_stress_compare_images(&w->r.image, &ref, exact, alpha_each, 0, &w->c, &err), &err))
        return 1;
      ref_floor[si] = w->c.ref_relmse;
      print_run(info->name, "equal", w->method, &w->r, &w->c);
      if (w->c.relmse < best) best = w->c.relmse;
      bool ok = iris_stress_unbiased(&w->c, alpha_each);
      if (!ok && !info->black && o.bias_factor > 1.0) {
        /* bias check: F x the samples (at least 32), independent ones; by
         * samples, not time, so that a guide whose setup fills the budget
         * still gets enough samples for a variance estimate */
        p.seconds = 0.0;
        p.spp = (int)(o.bias_factor * w->r.spp);
        if (p.spp < 32) p.spp = 32;
        p.seed = o.seed + 7919;
        w->have_long = true;
        if (!report(iris_stress_render(scene, w->method, &p, &w->rl, &err), &err) ||
            !report(iris_stress_compare_images(&w->rl.image, &ref, exact, alpha_each, 0, &w->cl, &err), &err))
          return 1;
        print_run(info->name, "long", w->method, &w->rl, &w->cl);
      }
      if (nonfinite(&w->r, &w->c) || (w->have_long && nonfinite(&w->rl, &w->cl)))
        w->v = V_NONFINITE;
      else if (info->black && !w->c.black_exact)
        w->v = V_LEAK;
      else if (ok)
        w->v = V_OK;
      else if (w->have_long && iris_stress_unbiased(&w->cl, alpha_each))
        w->v = V_OK_LONG;
      else if (w->have_long && w->cl.regions_high == 0 && fabs(w->cl.energy_z) <= zcrit)
        w->v = V_UNRESOLVED;
      else
        w->v = V_BIASED;
      if (o.images) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s.%s.exr", o.images, info->name, iris_method_name(w->method));
        if (!report(iris_stress_image_write(path, &w->r.image, info->name, iris_method_name(w->method),
                                            w->r.spp, w->r.seconds, &err), &err))
          return 1;
      }
      iris_image_destroy(&w->r.image); /* keep only the numbers */
      iris_image_destroy(&w->rl.image);
    }
    for (int k = first; k < nrows; k++) {
      rows[k].slow = !info->black && rows[k].c.relmse > 2.0 * best;
      if (rows[k].v >= V_BIASED) failures++;
    }
    if (o.images) {
      char path[1024];
      snprintf(path, sizeof path, "%s/%s.reference.exr", o.images, info->name);
      if (!report(iris_stress_image_write(path, &ref, info->name, "reference", ref_spp[si],
                                          ref_secs[si], &err), &err))
        return 1;
    }
    iris_image_destroy(&ref);
    iris_scene_destroy(scene);
  }
  if (o.csv) {
    FILE *f = fopen(o.csv, "w");
    if (!f) {
      fprintf(stderr, "stress_suite: cannot write %s: %s\n", o.csv, strerror(errno));
      return 1;
    }
    fprintf(f, "scene,method,spp,seconds,setup_seconds,relmse,ref_relmse,max_value,nan,inf,dropped,"
               "energy_test,energy_ref,energy_ratio,energy_z,energy_zcrit,region_max_z,region_zcrit,"
               "block_max_z,block_zcrit,pixel_max_z,black_exact,long_spp,long_seconds,long_energy_z,"
               "long_region_max_z,slow,verdict\n");
    for (int k = 0; k < nrows; k++) {
      const row *w = &rows[k];
      fprintf(f, "%s,%s,%d,%.3f,%.3f,%.6g,%.6g,%.6g,%llu,%llu,%llu,%.6g,%.6g,%.6g,%.4f,%.4f,%.4f,%.4f,"
                 "%.4f,%.4f,%.4f,%d,%d,%.3f,%.4f,%.4f,%d,%s\n",
              w->scene, iris_method_name(w->method), w->r.spp, w->r.seconds, w->r.setup_seconds,
              w->c.relmse, w->c.ref_relmse, w->c.max_value, (unsigned long long)w->c.nan_values,
              (unsigned long long)w->c.inf_values, (unsigned long long)w->r.dropped,
              w->c.energy_test, w->c.energy_ref, w->c.energy_ratio, w->c.energy_z, zcrit,
              w->c.regions.max_abs_z, w->c.regions.z_crit, w->c.blocks.max_abs_z, w->c.blocks.z_crit,
              w->c.pixels.max_abs_z, w->c.black_exact, w->rl.spp, w->rl.seconds, w->cl.energy_z,
              w->cl.regions.max_abs_z, w->slow, VERDICT_CSV[w->v]);
    }
    fclose(f);
  }
  if (o.markdown) {
    FILE *f = fopen(o.markdown, "w");
    if (!f) {
      fprintf(stderr, "stress_suite: cannot write %s: %s\n", o.markdown, strerror(errno));
      return 1;
    }
    fprintf(f, "| scene | method | spp | setup s | relMSE | vs mis | max pixel | NaN/Inf (dropped) | "
               "energy ratio | energy z | region max \\|z\\| | 8x8 max \\|z\\| | verdict |\n");
    fprintf(f, "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
    for (int k = 0; k < nrows; k++) {
      const row *w = &rows[k];
      double mis = NAN;
      for (int j = 0; j < nrows; j++)
        if (rows[j].scene == w->scene && rows[j].method == IRIS_METHOD_MIS) mis = rows[j].c.relmse;
      char a[32], b[32], speed[32], verdict_text[160];
      if (isfinite(mis) && w->c.relmse > 0)
        snprintf(speed, sizeof speed, "%.2fx", mis / w->c.relmse);
      else
        snprintf(speed, sizeof speed, "-");
      switch (w->v) {
      case V_OK: snprintf(verdict_text, sizeof verdict_text, "%s", w->slow ? "unbiased; slow" : "unbiased"); break;
      case V_OK_LONG:
        snprintf(verdict_text, sizeof verdict_text,
                 "unbiased at %gx samples (%d spp: energy z %+.2f, region |z| %.2f); under-sampled at equal time",
                 o.bias_factor, w->rl.spp, w->cl.energy_z, w->cl.regions.max_abs_z);
        break;
      case V_UNRESOLVED:
        snprintf(verdict_text, sizeof verdict_text,
                 "**unresolved**: under-sampled (%gx: %d spp, energy z %+.2f, region |z| %.2f, %d region-channels too dark, none too bright)",
                 o.bias_factor, w->rl.spp, w->cl.energy_z, w->cl.regions.max_abs_z, w->cl.regions_low);
        break;
      case V_BIASED:
        snprintf(verdict_text, sizeof verdict_text, "**BIASED?** (%gx: %d spp, energy z %+.2f, region |z| %.2f, %d region-channels too dark, %d too bright)",
                 o.bias_factor, w->rl.spp, w->cl.energy_z, w->cl.regions.max_abs_z, w->cl.regions_low,
                 w->cl.regions_high);
        break;
      case V_NONFINITE: snprintf(verdict_text, sizeof verdict_text, "**NaN/Inf**"); break;
      case V_LEAK: snprintf(verdict_text, sizeof verdict_text, "**light leak**"); break;
      }
      fprintf(f, "| %s | %s | %d | %.2f | %s | %s | %s | %llu+%llu (%llu) | %.3f | %+.2f | %.2f | %.2f | %s |\n",
              w->scene, iris_method_name(w->method), w->r.spp, w->r.setup_seconds,
              fmt_g(a, sizeof a, w->c.relmse), speed, fmt_g(b, sizeof b, w->c.max_value),
              (unsigned long long)w->c.nan_values, (unsigned long long)w->c.inf_values,
              (unsigned long long)w->r.dropped, w->c.energy_ratio, w->c.energy_z,
              w->c.regions.max_abs_z, w->c.blocks.max_abs_z, verdict_text);
    }
    fprintf(f, "\nEqual time %g s per method, setup included; %d scene x method pairs; "
               "family-wise alpha %g, so |energy z| <= %.2f (per channel) and region |z| <= the "
               "Bonferroni bound over its region-channels (about %.1f at 12 regions).\n",
            o.seconds, tests, o.alpha, zcrit, iris_metric_normal_two_sided_z(alpha_each / 36.0));
    fprintf(f, "\nReferences (mis): ");
    for (int si = 0; si < o.scene_count; si++) {
      if (iris_stress_find(o.scenes[si])->black)
        fprintf(f, "%s%s exact black", si ? ", " : "", o.scenes[si]);
      else
        fprintf(f, "%s%s %d spp (own relMSE %.2g)", si ? ", " : "", o.scenes[si], ref_spp[si],
                ref_floor[si]);
    }
    fprintf(f, ".\n");
    fclose(f);
  }
  free(rows);
  fprintf(stderr, "stress_suite: %d of %d scene x method pairs failed (NaN/Inf, light leak or bias)\n",
          failures, nrows);
  return failures ? 1 : 0;
}
