/* The bench (validate/bench.h): scenes -> references -> timed renders ->
 * metrics -> results.csv/json, tables, previews, charts. */
#include "validate/bench.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "core/fileio.h"
#include "core/image.h"
#include "core/log.h"
#include "core/rng.h"
#include "exporters/blender.h"
#include "exporters/export.h"
#include "renderer/guiding/guiding.h"
#include "renderer/merge.h"
#include "renderer/render.h"
#include "validate/bench_table.h"
#include "validate/blender_run.h"
#include "validate/json_out.h"
#include "validate/metrics.h"
#include "validate/report.h"
#include "validate/validate.h"

extern char **environ;

/* The auto reference uses a seed none of the bench runs uses (they use 0 ..
 * seeds-1), so that no run shares samples with its reference. */
#define REFERENCE_SEED 1000003u
/* Bump when a change makes cached references invalid (key of the cache). */
/* 2: references use the independent sampler (their variance channels are then
 * the exact error of the mean, so "own relMSE" stays honest) and the new
 * dimension layout. */
#define REFERENCE_CACHE_VERSION 2u

const char *iris_bench_method_label(const iris_bench_params *p, int k, char *buf, size_t size) {
  const bool indep = p->samplers[k] == IRIS_SAMPLER_INDEPENDENT;
  const bool area = p->light_samplings[k] == IRIS_TRIANGLE_SAMPLING_AREA;
  const bool tree = p->light_samplers[k] != IRIS_LIGHT_SAMPLER_DEFAULT; /* the other light sampler */
  const bool train = iris_method_uses_guiding(p->methods[k]) && p->keep_training[k] != IRIS_KEEP_TRAINING_DEFAULT;
  /* "@" and the non-default variants joined by "+" */
  char suffix[64] = "";
  const char *parts[5] = {indep ? "independent" : NULL, area ? "area" : NULL,
                          tree ? iris_light_sampler_name(p->light_samplers[k]) : NULL,
                          train ? (p->keep_training[k] ? "keep" : "discard") : NULL,
                          p->adaptive[k] == IRIS_ADAPTIVE_RELMSE   ? "adaptive"
                          : p->adaptive[k] == IRIS_ADAPTIVE_FREEZE ? "freeze"
                                                                   : NULL};
  for (int i = 0; i < 5; i++)
    if (parts[i])
      snprintf(suffix + strlen(suffix), sizeof suffix - strlen(suffix), "%s%s", suffix[0] ? "+" : "@", parts[i]);
  snprintf(buf, size, "%s%s", iris_method_name(p->methods[k]), suffix);
  return buf;
}

bool iris_bench_method_keeps_training(const char *label) {
  const char *at = strchr(label, '@');
  if (at && strstr(at, "keep")) return true;
  if (at && strstr(at, "discard")) return false;
  return IRIS_KEEP_TRAINING_DEFAULT;
}

iris_adaptive_rule iris_bench_method_adaptive(const char *label) {
  const char *at = strchr(label, '@');
  if (!at) return IRIS_ADAPTIVE_OFF;
  char buf[64];
  snprintf(buf, sizeof buf, "%s", at + 1);
  iris_adaptive_rule r = IRIS_ADAPTIVE_OFF;
  for (char *save = NULL, *tok = strtok_r(buf, "+", &save); tok; tok = strtok_r(NULL, "+", &save)) {
    if (strcmp(tok, "adaptive") == 0) r = IRIS_ADAPTIVE_RELMSE;
    if (strcmp(tok, "freeze") == 0) r = IRIS_ADAPTIVE_FREEZE;
  }
  return r;
}

bool iris_bench_method_parse(const char *label, iris_method *m, iris_sampler_kind *sampler, iris_light_sampler *light_sampler,
                             iris_triangle_sampling *light) {
  char name[64];
  snprintf(name, sizeof name, "%s", label);
  char *at = strchr(name, '@');
  *sampler = IRIS_SAMPLER_SOBOL;
  *light = IRIS_TRIANGLE_SAMPLING_SOLID_ANGLE;
  *light_sampler = IRIS_LIGHT_SAMPLER_DEFAULT;
  if (at) {
    *at++ = '\0';
    for (char *tok = strtok(at, "+"); tok; tok = strtok(NULL, "+")) {
      if (strcmp(tok, "independent") == 0)
        *sampler = IRIS_SAMPLER_INDEPENDENT;
      else if (strcmp(tok, "sobol") == 0)
        *sampler = IRIS_SAMPLER_SOBOL;
      else if (strcmp(tok, "area") == 0)
        *light = IRIS_TRIANGLE_SAMPLING_AREA;
      else if (strcmp(tok, "solid-angle") == 0)
        *light = IRIS_TRIANGLE_SAMPLING_SOLID_ANGLE;
      else if (strcmp(tok, "keep") == 0 || strcmp(tok, "discard") == 0)
        ; /* iris_bench_method_keeps_training */
      else if (strcmp(tok, "adaptive") == 0 || strcmp(tok, "freeze") == 0)
        ; /* iris_bench_method_adaptive */
      else if (iris_light_sampler_parse(tok, light_sampler))
        ;
      else
        return false;
    }
  }
  return iris_method_parse(name, m);
}

iris_bench_params iris_bench_params_default(void) {
  iris_bench_params p;
  memset(&p, 0, sizeof p);
  for (int k = 0; k < IRIS_BENCH_MAX_METHODS; k++) p.keep_training[k] = IRIS_KEEP_TRAINING_DEFAULT;
  p.seeds = 1;
  p.max_depth = -1;
  p.cycles_threshold = 0.01; /* Blender's default noise threshold */
  for (int k = 0; k < IRIS_BENCH_MAX_METHODS; k++) p.light_samplers[k] = IRIS_LIGHT_SAMPLER_DEFAULT;
  return p;
}

void iris_bench_default_cache_dir(char *buf, size_t size) {
  const char *xdg = getenv("XDG_CACHE_HOME");
  const char *home = getenv("HOME");
  if (xdg && xdg[0] == '/')
    snprintf(buf, size, "%s/iris/bench", xdg);
  else if (home && home[0] == '/')
    snprintf(buf, size, "%s/.cache/iris/bench", home);
  else
    snprintf(buf, size, "/tmp/iris-bench-cache");
}

void iris_bench_result_destroy(iris_bench_result *res) {
  free(res->rows);
  res->rows = NULL;
  res->row_count = res->row_capacity = 0;
}

static iris_status add_row(iris_bench_result *res, const iris_bench_row *row, iris_error *err) {
  if (res->row_count == res->row_capacity) {
    size_t cap = res->row_capacity ? 2 * res->row_capacity : 64;
    iris_bench_row *r = realloc(res->rows, cap * sizeof *r);
    if (!r) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory");
    res->rows = r;
    res->row_capacity = cap;
  }
  res->rows[res->row_count++] = *row;
  return IRIS_OK;
}

static void read_loadavg(double out[3]) {
  out[0] = out[1] = out[2] = -1.0;
  FILE *fp = fopen("/proc/loadavg", "r");
  if (!fp) return;
  if (fscanf(fp, "%lf %lf %lf", &out[0], &out[1], &out[2]) != 3) out[0] = out[1] = out[2] = -1.0;
  fclose(fp);
}

static double now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* True when `exe` names an executable file, directly or on $PATH. */
static bool executable_found(const char *exe) {
  if (strchr(exe, '/')) return access(exe, X_OK) == 0;
  const char *path = getenv("PATH");
  if (!path) return false;
  char dir[1024], full[1300];
  while (*path) {
    size_t n = strcspn(path, ":");
    snprintf(dir, sizeof dir, "%.*s", (int)(n < sizeof dir - 1 ? n : sizeof dir - 1), path);
    snprintf(full, sizeof full, "%s/%s", n ? dir : ".", exe);
    if (access(full, X_OK) == 0) return true;
    path += n;
    if (*path == ':') path++;
  }
  return false;
}

/* ---- images ------------------------------------------------------------ */

/* Index of channel `name`, or of a layer's "<layer>.<name>" (Blender writes
 * "ViewLayer.Combined.R"), never a variance channel. */
static int find_channel(const iris_image *img, const char *name) {
  int c = iris_image_channel(img, name);
  if (c >= 0) return c;
  size_t n = strlen(name);
  for (int i = 0; i < img->channel_count; i++) {
    const char *cn = img->channel_names[i];
    size_t m = strlen(cn);
    if (m > n + 1 && cn[m - n - 1] == '.' && strcmp(cn + m - n, name) == 0 &&
        strncmp(cn, "var.", 4) != 0)
      return i;
  }
  return -1;
}

/* Appends "; own relMSE X" to a reference description (X from own_relmse). */
static void describe_own_relmse(iris_bench_scene *sc, double own) {
  sc->reference_relmse = own;
  if (!(own >= 0.0)) return;
  size_t len = strlen(sc->reference_description);
  snprintf(sc->reference_description + len, sizeof sc->reference_description - len,
           "; its own relMSE ~%.2g", own);
}

/* Reads an EXR into a 3-channel R, G, B image; all values must be finite.
 * *own (if not NULL) gets own_relmse of the file (-1 without variance). */
static iris_status read_rgb(const char *path, iris_image *out, char *renderer, size_t rsize,
                            int *spp, double *own, iris_error *err) {
  iris_image raw;
  memset(&raw, 0, sizeof raw);
  iris_image_meta *meta = NULL;
  size_t meta_count = 0;
  if (!iris_path_exists(path))
    return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "reference image does not exist");
  iris_status st = iris_exr_read(path, &raw, &meta, &meta_count, err);
  if (st != IRIS_OK) return st;
  if (renderer) snprintf(renderer, rsize, "unknown renderer");
  if (spp) *spp = 0;
  for (size_t i = 0; i < meta_count; i++) {
    if (renderer && strcmp(meta[i].key, "iris:renderer") == 0)
      snprintf(renderer, rsize, "%.200s", meta[i].value);
    if (renderer && strcmp(meta[i].key, "iris:method") == 0)
      snprintf(renderer, rsize, "iris %.200s", meta[i].value);
    if (spp && strcmp(meta[i].key, "iris:spp") == 0) *spp = atoi(meta[i].value);
  }
  free(meta);
  if (own) *own = iris_metric_own_relmse(&raw);
  static const char *const names[3] = {"R", "G", "B"};
  int src[3];
  for (int c = 0; c < 3; c++) src[c] = find_channel(&raw, names[c]);
  if (src[0] < 0 || src[1] < 0 || src[2] < 0) {
    iris_image_destroy(&raw);
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL, "the image has no R, G and B channels");
  }
  st = iris_image_create(out, raw.width, raw.height, 3, names, err);
  if (st == IRIS_OK) {
    size_t n = (size_t)raw.width * (size_t)raw.height;
    for (size_t i = 0; i < n; i++)
      for (int c = 0; c < 3; c++)
        out->data[3 * i + (size_t)c] = raw.data[i * (size_t)raw.channel_count + (size_t)src[c]];
  }
  iris_image_destroy(&raw);
  if (st != IRIS_OK) return st;
  uint64_t nans = 0, infs = 0;
  iris_metric_count_nonfinite(out, 0, 3, &nans, &infs);
  if (nans || infs) {
    iris_image_destroy(out);
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL,
                          "the image holds %llu NaN and %llu Inf values; it cannot be a reference",
                          (unsigned long long)nans, (unsigned long long)infs);
  }
  return IRIS_OK;
}

static void fill_metrics(const iris_image *img, const iris_image *ref, iris_bench_row *row) {
  double tm[3], rm[3];
  iris_metric_channel_means(img, 0, tm);
  iris_metric_channel_means(ref, 0, rm);
  row->energy_ratio = iris_metric_energy_ratio(tm, rm);
  row->relmse = iris_metric_relmse(img, 0, ref, 0, IRIS_METRIC_EPS, IRIS_METRIC_DROP);
  row->relmse_full = iris_metric_relmse(img, 0, ref, 0, IRIS_METRIC_EPS, 0.0);
  row->mape = iris_metric_mape(img, 0, ref, 0, IRIS_METRIC_EPS, IRIS_METRIC_DROP);
  uint64_t nans = 0, infs = 0;
  iris_metric_count_nonfinite(img, 0, 3, &nans, &infs);
  row->nonfinite = nans + infs;
}

/* DIR/images/<scene>-<what>-spp.png: an adaptive render's samples per pixel,
 * log2(count / mean count) in false colour over [-3, 3] (blue: fewer than the
 * mean, red: more). */
static iris_status write_count_map(const char *out_dir, const iris_bench_scene *sc, const char *what,
                                   const iris_film *film, iris_error *err) {
  char dir[1100], name[300], path[1500];
  iris_path_join(out_dir, "images", dir, sizeof dir);
  iris_status st = iris_mkdir_p(dir, err);
  if (st != IRIS_OK) return st;
  size_t n = (size_t)film->width * (size_t)film->height;
  float *v = malloc(n * sizeof *v);
  if (!v) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory");
  double mean = 0.0;
  for (size_t i = 0; i < n; i++) mean += film->count[i];
  mean = mean > 0.0 ? mean / (double)n : 1.0;
  for (size_t i = 0; i < n; i++) v[i] = film->count[i] > 0 ? (float)log2(film->count[i] / mean) : -3.0f;
  snprintf(name, sizeof name, "%s-%s-spp.png", sc->name, what);
  iris_path_join(dir, name, path, sizeof path);
  st = iris_report_write_false_colour(path, v, film->width, film->height, 3.0f, err);
  free(v);
  return st;
}

/* DIR/images/<scene>-<what>.png and, against a reference, <scene>-<what>-diff.png
 * (relative energy difference, blue-white-red over [-0.5, 0.5]). */
static iris_status write_preview(const char *out_dir, iris_bench_scene *sc, const char *what,
                                 const iris_image *img, const iris_image *ref, float exposure,
                                 iris_error *err) {
  char dir[1100], name[300], path[1500];
  iris_path_join(out_dir, "images", dir, sizeof dir);
  iris_status st = iris_mkdir_p(dir, err);
  if (st != IRIS_OK) return st;
  snprintf(name, sizeof name, "%s-%s.png", sc->name, what);
  iris_path_join(dir, name, path, sizeof path);
  st = iris_png_write(path, img, 0, exposure, err);
  if (st != IRIS_OK) return st;
  if (sc->image_count < (int)(sizeof sc->images / sizeof sc->images[0]))
    snprintf(sc->images[sc->image_count++], sizeof sc->images[0], "%s", what);
  if (!ref) return IRIS_OK;
  size_t n = (size_t)img->width * (size_t)img->height;
  float *diff = malloc(n * sizeof *diff);
  if (!diff) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory");
  iris_report_relative_difference(img, ref, diff);
  snprintf(name, sizeof name, "%s-%s-diff.png", sc->name, what);
  iris_path_join(dir, name, path, sizeof path);
  st = iris_report_write_false_colour(path, diff, img->width, img->height, 0.5f, err);
  free(diff);
  return st;
}

/* ---- progress ---------------------------------------------------------- */

typedef struct bench_ctx {
  const iris_bench_params *p;
  iris_bench_result *res;
  int run, runs;
  double planned_left;   /* seconds of budget in the runs not started yet */
  iris_bench_progress cur;
  double run_start;
  double run_estimate;   /* expected seconds of the current run */
} bench_ctx;

static void report_progress(bench_ctx *c, double fraction) {
  if (!c->p->progress) return;
  c->cur.run = c->run;
  c->cur.runs = c->runs;
  c->cur.run_fraction = fraction < 0 ? 0 : fraction > 1 ? 1 : fraction;
  double left_here = c->run_estimate - (now_seconds() - c->run_start);
  c->cur.eta = c->planned_left + (left_here > 0 ? left_here : 0);
  c->p->progress(c->p->progress_ctx, &c->cur);
}

static void on_render_progress(void *vctx, int spp_done, int spp_total, double elapsed, double eta) {
  bench_ctx *c = (bench_ctx *)vctx;
  c->cur.spp_done = spp_done;
  if (c->cur.budget <= 0.0) c->run_estimate = (now_seconds() - c->run_start) + eta;
  double frac = c->cur.budget > 0.0 ? (now_seconds() - c->run_start) / c->cur.budget
                                    : (spp_total > 0 ? (double)spp_done / spp_total : 0.0);
  (void)elapsed;
  report_progress(c, frac);
}

static void begin_run(bench_ctx *c, const char *scene, const char *what, double budget,
                      uint64_t seed, double estimate) {
  c->run++;
  c->cur.scene = scene;
  c->cur.what = what;
  c->cur.budget = budget;
  c->cur.seed = seed;
  c->cur.spp_done = 0;
  c->run_start = now_seconds();
  c->run_estimate = estimate;
  c->planned_left -= estimate;
  if (c->planned_left < 0) c->planned_left = 0;
  report_progress(c, 0.0);
}

/* ---- scenes and references --------------------------------------------- */

typedef struct bench_scene {
  iris_scene *scene;
  iris_image ref;
  bool have_ref;
  int max_depth;
} bench_scene;

/* Scene label: the built-in name or the file's stem, made unique with -2, -3... */
static void scene_label(const iris_bench_result *res, const char *input, char *out, size_t size) {
  char stem[128];
  if (iris_path_exists(input))
    iris_path_stem(input, stem, sizeof stem);
  else
    snprintf(stem, sizeof stem, "%s", input);
  for (char *q = stem; *q; q++)
    if (!((*q >= 'a' && *q <= 'z') || (*q >= 'A' && *q <= 'Z') || (*q >= '0' && *q <= '9') ||
          *q == '-' || *q == '_' || *q == '.'))
      *q = '_';
  snprintf(out, size, "%s", stem);
  for (int k = 2;; k++) {
    bool taken = false;
    for (int i = 0; i < res->scene_count; i++)
      if (strcmp(res->scenes[i].name, out) == 0) taken = true;
    if (!taken) return;
    snprintf(out, size, "%.100s-%d", stem, k);
  }
}

/* The bench size of a scene (see iris_bench_params.width/height). */
static iris_status resolve_size(const iris_bench_params *p, const iris_scene *scene,
                                const char *input, int ref_w, int ref_h, int *w, int *h,
                                iris_error *err) {
  if (p->width > 0 && p->height > 0) {
    *w = p->width;
    *h = p->height;
    return IRIS_OK;
  }
  if (ref_w > 0) {
    *w = ref_w;
    *h = ref_h;
    return IRIS_OK;
  }
  iris_export_params ep = iris_export_params_default();
  iris_export_view view;
  iris_status st = iris_export_resolve_view(scene, &ep, input, &view, err);
  if (st != IRIS_OK) return st;
  *w = view.width;
  *h = view.height;
  if (p->width > 0) {
    *h = (int)lround((double)p->width * view.height / view.width);
    *w = p->width;
  } else if (p->height > 0) {
    *w = (int)lround((double)p->height * view.width / view.height);
    *h = p->height;
  }
  if (*w < 1) *w = 1;
  if (*h < 1) *h = 1;
  return IRIS_OK;
}

static iris_render_params render_params(const iris_bench_params *p, const iris_bench_scene *sc,
                                        int max_depth, iris_method method, uint64_t seed,
                                        const iris_guiding_params *gp, bench_ctx *ctx) {
  iris_render_params rp = iris_render_params_default();
  rp.width = sc->width;
  rp.height = sc->height;
  rp.threads = p->threads;
  rp.method = method;
  rp.seed = seed;
  rp.max_depth = max_depth;
  rp.cancel = p->cancel;
  rp.progress = on_render_progress;
  rp.progress_ctx = ctx;
  if (iris_method_uses_guiding(method) || method == IRIS_METHOD_AUTO) {
    rp.guide = &iris_guiding_provider;
    rp.guide_options = gp;
  }
  return rp;
}

/* The auto reference: a long mis render, cached under a key of everything
 * that changes the image (scene hash, size, depth, spp, seed, cache version). */
static iris_status auto_reference(const iris_bench_params *p, bench_ctx *ctx, bench_scene *bs,
                                  iris_bench_scene *sc, const char *cache_dir, iris_error *err) {
  int spp = p->reference_spp > 0 ? p->reference_spp : IRIS_BENCH_DEFAULT_REFERENCE_SPP;
  uint64_t key = iris_hash4(iris_merge_scene_hash(bs->scene), (uint64_t)sc->width,
                            (uint64_t)sc->height, (uint64_t)bs->max_depth);
  key = iris_hash4(key, (uint64_t)spp, REFERENCE_SEED, REFERENCE_CACHE_VERSION);
  for (const char *q = IRIS_VERSION_STRING; *q; q++) key = iris_mix64(key ^ (unsigned char)*q);
  char name[300];
  snprintf(name, sizeof name, "%s-%dx%d-%dspp-%016llx.exr", sc->name, sc->width, sc->height, spp,
           (unsigned long long)key);
  iris_path_join(cache_dir, name, sc->reference, sizeof sc->reference);
  sc->reference_spp = spp;
  if (iris_path_exists(sc->reference)) {
    char renderer[256];
    int got_spp = 0;
    iris_error e2;
    iris_error_clear(&e2);
    double own = -1.0;
    if (read_rgb(sc->reference, &bs->ref, renderer, sizeof renderer, &got_spp, &own, &e2) == IRIS_OK &&
        bs->ref.width == sc->width && bs->ref.height == sc->height) {
      bs->have_ref = true;
      snprintf(sc->reference_description, sizeof sc->reference_description,
               "iris mis, %d spp, seed %u (cached)", spp, REFERENCE_SEED);
      describe_own_relmse(sc, own);
      if (!p->quiet) iris_infof("bench: %s: cached reference %s", sc->name, sc->reference);
      return IRIS_OK;
    }
    if (bs->have_ref || bs->ref.data) iris_image_destroy(&bs->ref);
    iris_warnf("bench: %s: ignoring unusable cached reference %s", sc->name, sc->reference);
  }
  iris_status st = iris_mkdir_p(cache_dir, err);
  if (st != IRIS_OK) return st;
  if (!p->quiet)
    iris_infof("bench: %s: rendering the reference (mis, %d spp, %dx%d) into %s", sc->name, spp,
               sc->width, sc->height, cache_dir);
  iris_render_params rp = render_params(p, sc, bs->max_depth, IRIS_METHOD_MIS, REFERENCE_SEED, NULL, ctx);
  rp.spp = spp;
  rp.sampler = IRIS_SAMPLER_INDEPENDENT; /* honest own relMSE (docs/benchmarks.md) */
  begin_run(ctx, sc->name, "reference", 0.0, REFERENCE_SEED, 0.0);
  iris_render_result rr;
  st = iris_render(bs->scene, &rp, &rr, err);
  if (st != IRIS_OK) return st;
  if (rr.interrupted) {
    iris_render_result_destroy(&rr);
    return iris_error_set(err, IRIS_ERR_INTERRUPTED, NULL, 0, NULL, "interrupted");
  }
  st = iris_render_write_exr(&rr, sc->reference, sc->input, true, err);
  if (st == IRIS_OK) st = iris_film_to_image(&rr.film, false, &bs->ref, err);
  double own = -1.0; /* unknown if the variance image cannot be made: not an error */
  iris_image with_var;
  iris_error var_err;
  iris_error_clear(&var_err);
  if (st == IRIS_OK && iris_film_to_image(&rr.film, true, &with_var, &var_err) == IRIS_OK) {
    own = iris_metric_own_relmse(&with_var);
    iris_image_destroy(&with_var);
  }
  iris_render_result_destroy(&rr);
  if (st != IRIS_OK) return st;
  bs->have_ref = true;
  snprintf(sc->reference_description, sizeof sc->reference_description,
           "iris mis, %d spp, seed %u (rendered in %.0f s)", spp, REFERENCE_SEED,
           now_seconds() - ctx->run_start);
  describe_own_relmse(sc, own);
  return IRIS_OK;
}

/* ---- Cycles ------------------------------------------------------------ */

/* Cycles rows, per budget and seed s with Cycles' seed s (the table averages
 * Cycles over the same seeds as iris, so that one lucky or unlucky Cycles
 * image does not decide a comparison):
 * - "cycles": fixed spp, the spp the budget's mis run with seed s reached (the
 *   first method's when mis is not benched): the physical comparison;
 * - "cycles-adaptive": Cycles as Blender users run it, adaptive sampling on
 *   (noise threshold p->cycles_threshold, automatic minimum samples) with the
 *   budget as Cycles' time limit and no practical spp cap: it stops at the
 *   budget or earlier where every pixel has converged.
 * Times are Blender's render time as the exported script prints it, start-up
 * and scene build excluded. */
#define CYCLES_ADAPTIVE_SPP_CAP (1 << 20)

static iris_status run_cycles(const iris_bench_params *p, bench_ctx *ctx, bench_scene *bs,
                              iris_bench_scene *sc, iris_bench_result *res, float exposure,
                              bool adaptive, iris_error *err) {
  const char *what = adaptive ? "cycles-adaptive" : "cycles";
  char dir[1300], script[1400], exr[1400], log[1400];
  snprintf(dir, sizeof dir, "%.1000s/cycles/%s", p->out_dir, sc->name);
  iris_status st = iris_mkdir_p(dir, err);
  if (st != IRIS_OK) return st;
  snprintf(script, sizeof script, "%s/scene.py", dir);
  iris_export_params ep = iris_export_params_default();
  ep.width = sc->width;
  ep.height = sc->height;
  ep.max_depth = bs->max_depth;
  ep.seed = 0;
  ep.has_seed = true;
  st = iris_export_blender(bs->scene, script, &ep, err);
  if (st != IRIS_OK) return st;
  /* Cycles takes the spp of the first mis variant's runs (else the first method's) */
  char base[64];
  int kb = 0;
  for (int k = p->method_count - 1; k >= 0; k--)
    if (p->methods[k] == IRIS_METHOD_MIS) kb = k;
  iris_bench_method_label(p, kb, base, sizeof base);
  int threads = p->threads > 0 ? p->threads : (int)sysconf(_SC_NPROCESSORS_ONLN);
  for (int run = 0; run < p->time_count * p->seeds; run++) {
    const int t = run / p->seeds, seed = run % p->seeds;
    int spp = adaptive ? CYCLES_ADAPTIVE_SPP_CAP : 0;
    for (size_t i = 0; i < res->row_count && !adaptive; i++) {
      const iris_bench_row *r = &res->rows[i];
      if (strcmp(r->scene, sc->name) == 0 && strcmp(r->method, base) == 0 && r->seed == (uint64_t)seed &&
          r->budget_s == p->times[t])
        spp = r->spp;
    }
    if (spp <= 0) continue;
    if (p->cancel && *p->cancel)
      return iris_error_set(err, IRIS_ERR_INTERRUPTED, NULL, 0, NULL, "interrupted");
    begin_run(ctx, sc->name, what, 0.0, (uint64_t)seed, p->times[t]);
    snprintf(exr, sizeof exr, "%s/%s-%gs-seed%d.exr", dir, what, p->times[t], seed);
    snprintf(log, sizeof log, "%s/%s-%gs-seed%d.log", dir, what, p->times[t], seed);
    char a_spp[32], a_threads[32], a_w[32], a_h[32], a_b[32], a_seed[32], a_thr[32], a_limit[32];
    snprintf(a_seed, sizeof a_seed, "%d", seed);
    snprintf(a_spp, sizeof a_spp, "%d", spp);
    snprintf(a_threads, sizeof a_threads, "%d", threads);
    snprintf(a_w, sizeof a_w, "%d", sc->width);
    snprintf(a_h, sizeof a_h, "%d", sc->height);
    snprintf(a_b, sizeof a_b, "%d", bs->max_depth);
    snprintf(a_thr, sizeof a_thr, "%.17g", adaptive ? p->cycles_threshold : 0.0);
    snprintf(a_limit, sizeof a_limit, "%.17g", adaptive ? p->times[t] : 0.0);
    const char *args[] = {"--output", exr, "--spp", a_spp, "--threads", a_threads, "--seed", a_seed,
                          "--width", a_w, "--height", a_h, "--max-bounces", a_b,
                          "--adaptive-threshold", a_thr, "--time-limit", a_limit, NULL};
    iris_blender_run_info info;
    st = iris_blender_run(p->blender, script, args, log, &info, err);
    if (st != IRIS_OK) return st;
    if (!res->cycles_version[0]) snprintf(res->cycles_version, sizeof res->cycles_version, "%s", info.version);
    iris_image img;
    st = read_rgb(exr, &img, NULL, 0, NULL, NULL, err);
    if (st != IRIS_OK) return st;
    if (img.width != sc->width || img.height != sc->height) {
      iris_image_destroy(&img);
      return iris_error_set(err, IRIS_ERR_INTERNAL, exr, 0, NULL, "Blender wrote %dx%d, not %dx%d",
                            img.width, img.height, sc->width, sc->height);
    }
    iris_bench_row row;
    memset(&row, 0, sizeof row);
    snprintf(row.scene, sizeof row.scene, "%s", sc->name);
    snprintf(row.method, sizeof row.method, "%s", what);
    row.budget_s = p->times[t];
    row.seed = (uint64_t)seed;
    row.seconds = info.render_seconds;
    row.setup_seconds = info.build_seconds;
    row.spp = adaptive ? 0 : spp; /* adaptive: per pixel, not known from the image */
    fill_metrics(&img, &bs->ref, &row);
    st = add_row(res, &row, err);
    if (st == IRIS_OK && t == p->time_count - 1 && seed == 0)
      st = write_preview(p->out_dir, sc, what, &img, &bs->ref, exposure, err);
    iris_image_destroy(&img);
    if (st != IRIS_OK) return st;
    if (adaptive)
      res->cycles_adaptive_done = true;
    else
      res->cycles_done = true;
  }
  return IRIS_OK;
}

/* ---- charts -------------------------------------------------------------- */

static bool run_plot(const iris_bench_params *p) {
  const char *python = p->python ? p->python : "/usr/bin/python3";
  char log[1300];
  iris_path_join(p->out_dir, "charts.log", log, sizeof log);
  const char *argv[] = {python, p->plot_script, p->out_dir, NULL};
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addclose(&fa, STDIN_FILENO);
  pid_t pid;
  int rc = posix_spawnp(&pid, python, &fa, NULL, (char *const *)argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) {
    iris_warnf("bench: cannot run %s for the charts: %s", python, strerror(rc));
    return false;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return false;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    iris_warnf("bench: the chart script failed; see %s", log);
    return false;
  }
  remove(log);
  return true;
}

/* ---- the run ------------------------------------------------------------- */

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

static iris_status check_params(const iris_bench_params *p, iris_error *err) {
  if (p->input_count < 1)
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "no input scene");
  if (p->input_count > IRIS_BENCH_MAX_SCENES)
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "at most %d scenes", IRIS_BENCH_MAX_SCENES);
  if (p->method_count < 1)
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "no method");
  if (p->time_count < 1 || p->time_count > IRIS_BENCH_MAX_TIMES)
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "1 to %d time budgets are needed",
                          IRIS_BENCH_MAX_TIMES);
  for (int t = 0; t < p->time_count; t++)
    if (!(p->times[t] > 0.0) || p->times[t] > 1e6)
      return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "time budget %g is not in (0, 1e6] s",
                            p->times[t]);
  if (p->seeds < 1 || p->seeds > IRIS_BENCH_MAX_SEEDS)
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "--seeds must be 1 to %d",
                          IRIS_BENCH_MAX_SEEDS);
  if (!p->out_dir) return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "no output folder");
  if (p->cycles_adaptive && !(p->cycles_threshold > 0.0 && p->cycles_threshold < 1.0))
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "the Cycles noise threshold %g is not in (0, 1)",
                          p->cycles_threshold);
  if ((p->cycles || p->cycles_adaptive) && !executable_found(iris_blender_executable(p->blender)))
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL,
                          "%s: Blender '%s' is not installed (Debian's blender package, or "
                          "set IRIS_BLENDER)", p->cycles ? "--cycles" : "--cycles-adaptive",
                          iris_blender_executable(p->blender));
  return IRIS_OK;
}

iris_status iris_bench_run(const iris_bench_params *params, iris_bench_result *res,
                           iris_error *err) {
  memset(res, 0, sizeof *res);
  iris_bench_params p = *params;
  iris_status st = check_params(&p, err);
  if (st != IRIS_OK) return st;
  qsort(p.times, (size_t)p.time_count, sizeof p.times[0], cmp_double);
  for (int t = 1; t < p.time_count; t++)
    if (p.times[t] == p.times[t - 1])
      return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "time budget %g is given twice", p.times[t]);
  char cache_dir[1024];
  if (p.cache_dir)
    snprintf(cache_dir, sizeof cache_dir, "%s", p.cache_dir);
  else
    iris_bench_default_cache_dir(cache_dir, sizeof cache_dir);
  res->cpus = (int)sysconf(_SC_NPROCESSORS_ONLN);

  /* Everything that can be checked is checked before the first render:
   * scenes load, given references are readable, finite and of the right size. */
  bench_scene bs[IRIS_BENCH_MAX_SCENES];
  memset(bs, 0, sizeof bs);
  for (int i = 0; i < p.input_count && st == IRIS_OK; i++) {
    iris_bench_scene *sc = &res->scenes[i];
    snprintf(sc->input, sizeof sc->input, "%s", p.inputs[i]);
    sc->reference_relmse = -1.0;
    st = iris_validate_load_scene(p.inputs[i], NULL, p.variant, &bs[i].scene, err);
    if (st == IRIS_OK && !iris_world_override_apply(&p.world, bs[i].scene))
      st = iris_error_set(err, IRIS_ERR_NOMEM, p.inputs[i], 0, NULL, "out of memory");
    if (st != IRIS_OK) break;
    iris_scene_warn_if_lightless(bs[i].scene, p.inputs[i]);
    scene_label(res, p.inputs[i], sc->name, sizeof sc->name);
    res->scene_count = i + 1;
    bs[i].max_depth = p.max_depth >= 0 ? p.max_depth
                      : bs[i].scene->render.max_depth >= 0 ? bs[i].scene->render.max_depth
                                                            : IRIS_DEFAULT_MAX_DEPTH;
    int rw = 0, rh = 0;
    if (p.references) {
      char renderer[256];
      double own = -1.0;
      st = read_rgb(p.references[i], &bs[i].ref, renderer, sizeof renderer, &sc->reference_spp, &own, err);
      if (st != IRIS_OK) break;
      bs[i].have_ref = true;
      rw = bs[i].ref.width;
      rh = bs[i].ref.height;
      snprintf(sc->reference, sizeof sc->reference, "%s", p.references[i]);
      if (sc->reference_spp > 0)
        snprintf(sc->reference_description, sizeof sc->reference_description, "%.200s, %d spp (given)",
                 renderer, sc->reference_spp);
      else
        snprintf(sc->reference_description, sizeof sc->reference_description, "%.200s (given)", renderer);
      describe_own_relmse(sc, own);
    }
    st = resolve_size(&p, bs[i].scene, p.inputs[i], rw, rh, &sc->width, &sc->height, err);
    if (st == IRIS_OK && bs[i].have_ref && (rw != sc->width || rh != sc->height))
      st = iris_error_set(err, IRIS_ERR_INVALID, p.references[i], 0, NULL,
                          "image sizes differ: %dx%d requested against a %dx%d reference", sc->width,
                          sc->height, rw, rh);
  }
  if (st == IRIS_OK) st = iris_mkdir_p(p.out_dir, err);

  bench_ctx ctx;
  memset(&ctx, 0, sizeof ctx);
  ctx.p = &p;
  ctx.res = res;
  if (st == IRIS_OK) {
    double per_scene = 0.0;
    for (int t = 0; t < p.time_count; t++) per_scene += p.times[t];
    ctx.runs = p.input_count * p.method_count * p.time_count * p.seeds;
    ctx.planned_left = per_scene * p.method_count * p.seeds * p.input_count;
    for (int k = 0; k < (int)p.cycles + (int)p.cycles_adaptive; k++) { /* one Cycles run per budget and seed */
      ctx.runs += p.input_count * p.time_count * p.seeds;
      ctx.planned_left += per_scene * p.input_count * p.seeds;
    }
    if (!p.references) ctx.runs += p.input_count;
  }
  read_loadavg(res->load_before);
  char csv[1300], json[1300];
  iris_path_join(p.out_dir, "results.csv", csv, sizeof csv);
  iris_path_join(p.out_dir, "results.json", json, sizeof json);
  iris_guiding_params gp = iris_guiding_params_default();

  for (int i = 0; i < res->scene_count && st == IRIS_OK; i++) {
    iris_bench_scene *sc = &res->scenes[i];
    if (!bs[i].have_ref) {
      st = auto_reference(&p, &ctx, &bs[i], sc, cache_dir, err);
      if (st != IRIS_OK) break;
    }
    double ref_mean[3];
    iris_metric_channel_means(&bs[i].ref, 0, ref_mean);
    float exposure = iris_report_exposure(ref_mean);
    st = write_preview(p.out_dir, sc, "reference", &bs[i].ref, NULL, exposure, err);
    /* Budgets and seeds outside, methods inside: a drift of the machine's
     * load during the bench hits every method alike. */
    for (int t = 0; t < p.time_count && st == IRIS_OK; t++)
      for (int s = 0; s < p.seeds && st == IRIS_OK; s++)
        for (int k = 0; k < p.method_count && st == IRIS_OK; k++) {
          iris_method m = p.methods[k];
          char label[64];
          iris_bench_method_label(&p, k, label, sizeof label);
          begin_run(&ctx, sc->name, label, p.times[t], (uint64_t)s, p.times[t]);
          iris_render_params rp = render_params(&p, sc, bs[i].max_depth, m, (uint64_t)s, &gp, &ctx);
          rp.sampler = p.samplers[k];
          rp.light_sampling = p.light_samplings[k];
          rp.keep_training = p.keep_training[k];
          rp.light_sampler = p.light_samplers[k];
          rp.connect = p.connect;
          rp.light_trace = p.light_trace;
          if (p.adaptive[k] != IRIS_ADAPTIVE_OFF) {
            /* @freeze: Cycles' rule at Blender's threshold; @adaptive: the
             * relMSE allocation with the budget alone deciding. No spp cap. */
            rp.adaptive.rule = p.adaptive[k];
            rp.adaptive.noise_threshold = p.adaptive[k] == IRIS_ADAPTIVE_FREEZE ? IRIS_BENCH_ADAPTIVE_THRESHOLD : 0.0;
            rp.spp = IRIS_RENDER_BUDGET_ADAPTIVE_CAP;
          }
          if (rp.light_sampler == IRIS_LIGHT_SAMPLER_LEARNED && !rp.guide) { /* the caches' light tables */
            rp.guide = &iris_guiding_provider;
            rp.guide_options = &gp;
          }
          rp.time_budget = p.times[t];
          rp.budget_includes_setup = true;
          iris_render_result rr;
          double t0 = now_seconds();
          st = iris_render(bs[i].scene, &rp, &rr, err);
          double wall = now_seconds() - t0;
          if (st != IRIS_OK) break;
          if (rr.interrupted) {
            iris_render_result_destroy(&rr);
            st = iris_error_set(err, IRIS_ERR_INTERRUPTED, NULL, 0, NULL, "interrupted");
            break;
          }
          iris_bench_row row;
          memset(&row, 0, sizeof row);
          snprintf(row.scene, sizeof row.scene, "%s", sc->name);
          snprintf(row.method, sizeof row.method, "%s", label);
          snprintf(row.resolved, sizeof row.resolved, "%s", iris_method_name(rr.method));
          snprintf(row.method_reason, sizeof row.method_reason, "%s", rr.method_reason);
          row.seed = (uint64_t)s;
          row.budget_s = p.times[t];
          /* the whole call: setup, passes and the film's allocation */
          row.seconds = wall;
          row.setup_seconds = rr.setup_seconds;
          row.spp = rr.adaptive.rule != IRIS_ADAPTIVE_OFF ? (int)(rr.adaptive_outcome.spp_mean + 0.5) : rr.spp;
          iris_image img;
          st = iris_film_to_image(&rr.film, false, &img, err);
          const bool preview = s == 0 && t == p.time_count - 1;
          if (st == IRIS_OK && preview && rr.adaptive.rule != IRIS_ADAPTIVE_OFF)
            st = write_count_map(p.out_dir, sc, label, &rr.film, err);
          iris_render_result_destroy(&rr);
          if (st != IRIS_OK) break;
          fill_metrics(&img, &bs[i].ref, &row);
          st = add_row(res, &row, err);
          if (st == IRIS_OK && preview) st = write_preview(p.out_dir, sc, label, &img, &bs[i].ref, exposure, err);
          iris_image_destroy(&img);
        }
    if (st == IRIS_OK && p.cycles) st = run_cycles(&p, &ctx, &bs[i], sc, res, exposure, false, err);
    if (st == IRIS_OK && p.cycles_adaptive) st = run_cycles(&p, &ctx, &bs[i], sc, res, exposure, true, err);
    if (st == IRIS_OK || st == IRIS_ERR_INTERRUPTED) {
      /* results so far, also after an interruption */
      iris_error e2;
      iris_error_clear(&e2);
      read_loadavg(res->load_after);
      res->interrupted = st == IRIS_ERR_INTERRUPTED;
      if (iris_bench_write_csv(csv, res, &e2) != IRIS_OK || iris_bench_write_json(json, &p, res, &e2) != IRIS_OK)
        if (st == IRIS_OK) {
          *err = e2;
          st = e2.status;
        }
    }
  }
  read_loadavg(res->load_after);
  if (st == IRIS_OK) st = iris_bench_write_tables(p.out_dir, &p, res, err);
  if (st == IRIS_OK && p.plot_script) {
    st = iris_bench_write_json(json, &p, res, err); /* targets are known now */
    if (st == IRIS_OK) res->charts = run_plot(&p);
  }
  if (st == IRIS_OK) st = iris_bench_write_json(json, &p, res, err); /* with the chart list */
  for (int i = 0; i < IRIS_BENCH_MAX_SCENES; i++) {
    iris_scene_destroy(bs[i].scene);
    if (bs[i].ref.data) iris_image_destroy(&bs[i].ref);
  }
  return st;
}
