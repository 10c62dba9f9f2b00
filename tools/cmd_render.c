/* `iris render INPUT -o OUT.exr`: fills iris_render_params from the flags,
 * loads the input (an iris scene, an importable file or a built-in scene name),
 * renders and writes EXR/PNG. docs/cli.md ("render") lists every flag. */
#include <math.h>
#include <stddef.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "core/fileio.h"
#include "core/image.h"
#include "core/log.h"
#include "core/rng.h"
#include "importers/import.h"
#include "scenes/builtin.h"
#include "renderer/guiding/guiding.h"
#include "renderer/guiding/inspect.h"
#include "renderer/render.h"
#include "tools/cli.h"
#include "tools/options.h"

static const char *CMD = "render";

/* The flags only render takes; the shared groups are in tools/options.c. */
typedef struct render_cli {
  const char *output, *png, *pixel_bounds, *aov;
  bool variance, quiet, json;
  double exposure;
  uint64_t sample_offset;
  double noise_threshold, target_error;
  int min_spp;
  int adaptive; /* iris_adaptive_rule; -1: unset */
  bool time_total;
} render_cli;

static const iris_option OUTPUT_ROWS[] = {
    {"output", 'o', IRIS_OPT_STRING, "FILE", 0, 0, offsetof(render_cli, output),
     "OpenEXR output (float RGB + metadata)", NULL},
    {"variance", 0, IRIS_OPT_FLAG, NULL, 0, 0, offsetof(render_cli, variance),
     "also write var.R/G/B: variance of each pixel's mean", NULL},
    {"png", 0, IRIS_OPT_STRING, "FILE", 0, 0, offsetof(render_cli, png),
     "8-bit sRGB PNG as well (or instead)", NULL},
    {"exposure", 0, IRIS_OPT_DOUBLE, "EV", -64, 64, offsetof(render_cli, exposure),
     "scale the PNG by 2^EV (default 0)", NULL},
    {"aov", 0, IRIS_OPT_STRING, "caches", 0, 0, offsetof(render_cli, aov),
     "also write OUT-caches.png: the image with cache positions\n"
     "marked (green: from camera rays, red: from photons)", NULL},
    {"quiet", 'q', IRIS_OPT_FLAG, NULL, 0, 0, offsetof(render_cli, quiet), "no progress bar or messages", NULL},
    {"json", 0, IRIS_OPT_FLAG, NULL, 0, 0, offsetof(render_cli, json), "JSON summary on stdout", NULL},
};
static const iris_option PARTITION_ROWS[] = {
    {"sample-offset", 0, IRIS_OPT_U64, "K", 0, 0, offsetof(render_cli, sample_offset),
     "render sample indices K .. K+spp-1 (default 0)", NULL},
    {"pixel-bounds", 0, IRIS_OPT_STRING, "x0,y0,x1,y1", 0, 0, offsetof(render_cli, pixel_bounds),
     "render only this window of the frame\n(half-open; the output image is the window)", NULL},
};
static const iris_option BUDGET_ROWS[] = {
    {"time-total", 0, IRIS_OPT_FLAG, NULL, 0, 0, offsetof(render_cli, time_total),
     "--time also holds the setup (BVH, textures, lights, photons,\nthe guide's training, auto's race), "
     "as iris bench's budgets\ndo; by default it holds the image passes", NULL},
};
/* In the order of iris_adaptive_rule. */
static const char *const ADAPTIVE_CHOICES[] = {"off", "freeze", "relmse", NULL};
static const iris_option ADAPTIVE_ROWS[] = {
    {"noise-threshold", 0, IRIS_OPT_DOUBLE, "T", 1e-6, 1.0, offsetof(render_cli, noise_threshold),
     "adaptive sampling: stop a pixel once its noise is below T,\n"
     "Cycles' scale and meaning (Blender's default 0.01); --spp\n"
     "(default 4096) and --time are then caps", NULL},
    {"target-error", 0, IRIS_OPT_DOUBLE, "E", 1e-12, 1e6, offsetof(render_cli, target_error),
     "adaptive sampling until the image's estimated relMSE is at\n"
     "most E (--time caps it); the estimate reached is reported", NULL},
    {"min-spp", 0, IRIS_OPT_INT, "N", 1, 1 << 24, offsetof(render_cli, min_spp),
     "samples every pixel gets first (default as Cycles:\nmax(4, ceil(16 / T^0.3)), 64 at T = 0.01; 16 without T)", NULL},
    {"adaptive", 0, IRIS_OPT_CHOICE, "RULE", 0, 0, offsetof(render_cli, adaptive),
     "relmse (default with --noise-threshold/--target-error and\nunder --time: samples where they lower the "
     "image's relMSE\nmost) | freeze (Cycles' rule) | off (every pixel the\nsame spp)", ADAPTIVE_CHOICES},
};
static const iris_option_group ADAPTIVE_OPTIONS = {"Adaptive sampling (on under --time without --spp, else off\n"
                                                   "unless one of these is given; docs/rendering.md)",
                                                   ADAPTIVE_ROWS, sizeof ADAPTIVE_ROWS / sizeof ADAPTIVE_ROWS[0]};
static const iris_option_group OUTPUT_OPTIONS = {"Output and reporting", OUTPUT_ROWS,
                                                 sizeof OUTPUT_ROWS / sizeof OUTPUT_ROWS[0]};
static const iris_option_group BUDGET_OPTIONS = {"Time budget", BUDGET_ROWS, sizeof BUDGET_ROWS / sizeof BUDGET_ROWS[0]};
static const iris_option_group PARTITION_OPTIONS = {
    "Partitioned renders (merge the parts with iris merge; docs/distributed.md)", PARTITION_ROWS,
    sizeof PARTITION_ROWS / sizeof PARTITION_ROWS[0]};

static void print_help(const iris_option_binding *b, size_t n) {
  printf(
      "Usage: iris render INPUT [-o OUT.exr] [--png OUT.png] [options]\n"
      "\n"
      "Renders INPUT (an iris scene .json, an OBJ/PLY/glTF file, or a built-in scene).\n"
      "Built-in scenes:");
  int column = 16;
  for (const char *const *nm = iris_builtin_names(); *nm; nm++) {
    if (column + (int)strlen(*nm) + 2 > 78) {
      printf("\n ");
      column = 1;
    }
    printf(" %s", *nm);
    column += (int)strlen(*nm) + 1;
  }
  printf("\n\n");
  iris_options_help(b, n);
  printf(
      "  -h, --help            show this help\n"
      "\n"
      "Exit status: 0 done, 2 bad usage or input, 1 other failure, 130 (SIGINT) or\n"
      "143 (SIGTERM) when interrupted: the image of the passes done is still written.\n");
}


typedef struct progress_state {
  bool enabled;
  uint64_t pixels;
} progress_state;

static void draw_progress(void *ctx, int done, int total, double elapsed, double eta) {
  progress_state *ps = (progress_state *)ctx;
  if (!ps->enabled) return;
  double frac = total > 0 ? (double)done / total : 1.0;
  int bar = (int)(frac * 30.0 + 0.5);
  char b[31];
  for (int i = 0; i < 30; i++) b[i] = i < bar ? '#' : '.';
  b[30] = 0;
  double rate = elapsed > 0 ? (double)done * (double)ps->pixels / elapsed : 0.0;
  fprintf(stderr, "\r[%s] %3d%%  %d/%d spp  %.2f Msamples/s  ETA %.0fs ", b, (int)(frac * 100.0),
          done, total, rate * 1e-6, eta);
  fflush(stderr);
  iris_log_progress_drawn();
}

/* An adaptive round on the progress line: samples so far, the share of pixels
 * still sampling and the image's estimated relMSE. */
static void draw_adaptive(void *ctx, const iris_adaptive_progress *a) {
  progress_state *ps = (progress_state *)ctx;
  if (!ps->enabled) return;
  char eta[32] = "";
  if (a->eta >= 0.0) snprintf(eta, sizeof eta, "  ETA %.0fs", a->eta);
  fprintf(stderr, "\radaptive round %d: %.1f spp mean, %.1f%% of pixels sampling, est. relMSE %.3g, %.1fs%s ",
          a->round, a->spp_mean, 100.0 * a->active_share, a->error_estimate, a->elapsed, eta);
  fflush(stderr);
  iris_log_progress_drawn();
}

/* A set-up phase on the progress line: what runs, time so far, and when the
 * first image pass is expected (the guide's training knows after its first pass). */
static void draw_phase(void *ctx, const char *what, double elapsed, double eta_first_image) {
  progress_state *ps = (progress_state *)ctx;
  if (!ps->enabled) return;
  char eta[64] = "";
  if (eta_first_image > 0.0) snprintf(eta, sizeof eta, ", first image pass in ~%.0fs", eta_first_image);
  fprintf(stderr, "\r%-44s %6.1fs%-34s", what, elapsed, eta);
  fflush(stderr);
  iris_log_progress_drawn();
}

static bool ends_with(const char *s, const char *suffix) {
  size_t n = strlen(s), m = strlen(suffix);
  if (n < m) return false;
  char ext[16];
  iris_path_ext(s, ext, sizeof ext);
  return strcmp(ext, suffix + 1) == 0;
}

/* "x0,y0,x1,y1": four integers, a non-empty window; the frame check is
 * iris_render's, which knows the frame size. */
static bool parse_bounds(const char *text, iris_pixel_bounds *b) {
  long v[4];
  const char *q = text;
  for (int i = 0; i < 4; i++) {
    char *end = NULL;
    if (*q < '0' || *q > '9') return false;
    v[i] = strtol(q, &end, 10);
    if (end == q || v[i] > 65536) return false;
    q = end;
    if (i < 3 && *q++ != ',') return false;
  }
  if (*q || v[0] >= v[2] || v[1] >= v[3]) return false;
  b->x0 = (int)v[0];
  b->y0 = (int)v[1];
  b->x1 = (int)v[2];
  b->y1 = (int)v[3];
  return true;
}

/* Folds the guiding options into iris:config_hash, so parts rendered with
 * different caches refuse to merge. */
static uint64_t guiding_params_hash(const iris_guiding_params *gp) {
  uint64_t h = 0x6a1d1e5ULL;
  double v[] = {(double)gp->photons, (double)gp->caches, gp->cache_res, gp->cache_k,
                gp->pdf_floor, gp->alpha_max, gp->cos_min, (double)gp->splat, gp->force,
                (double)gp->photon_lights, gp->train_spp, gp->train_prior, gp->train_all_light,
                gp->learn_alpha, gp->adjoint_rr, gp->direct_photons, gp->sky_regions, gp->sky_probes,
                gp->sky_beta, gp->refine};
  for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
    uint64_t bits;
    memcpy(&bits, &v[i], sizeof bits);
    h = iris_mix64(h ^ (bits + 0x9e3779b97f4a7c15ULL));
  }
  /* lamps behind glass off: renders with it on keep the hash they had before it */
  if (!gp->lamp_glass) h = iris_mix64(h ^ 0x1a3b91a55ULL);
  if (!gp->glints) h = iris_mix64(h ^ 0x611e75ULL); /* glints off: likewise */
  /* light sampling made optional where it brought nothing: likewise */
  if (gp->light_min != IRIS_GUIDING_LIGHT_MIN) {
    uint64_t bits;
    double v = gp->light_min;
    memcpy(&bits, &v, sizeof bits);
    h = iris_mix64(h ^ (bits + 0x11687a1eULL));
  }
  return h;
}

static bool output_dir_ok(const char *path) {
  char dir[1024];
  iris_path_dir(path, dir, sizeof dir);
  return iris_path_exists(dir);
}

/* --aov caches: the image (as the PNG) with every visible cache marked,
 * written to OUT-caches.png next to the main output. */
static iris_status write_cache_marks(const iris_render_result *res, const iris_guiding_marks *marks,
                                     const char *out, float exposure, iris_error *err) {
  if (!marks->kind) {
    iris_warnf("--aov caches: guiding was skipped, no caches to mark");
    return IRIS_OK;
  }
  if (marks->width != res->film.width || marks->height != res->film.height) {
    iris_warnf("--aov caches: the film is a window of the frame; marks not written");
    return IRIS_OK;
  }
  char path[1200];
  size_t n = strlen(out);
  const char *dot = strrchr(out, '.');
  size_t base = dot ? (size_t)(dot - out) : n;
  snprintf(path, sizeof path, "%.*s-caches.png", (int)base, out);
  iris_image img;
  iris_status st = iris_film_to_image(&res->film, false, &img, err);
  if (st != IRIS_OK) return st;
  float unexpose = powf(2.0f, -exposure); /* marks stay pure green/red after the PNG's exposure */
  for (int y = 0; y < img.height; y++)
    for (int x = 0; x < img.width; x++) {
      uint8_t k = marks->kind[(size_t)y * (size_t)img.width + (size_t)x];
      if (!k) continue;
      float *px = &img.data[((size_t)y * (size_t)img.width + (size_t)x) * (size_t)img.channel_count];
      px[0] = k == 2 ? unexpose : 0.0f;
      px[1] = k == 1 ? unexpose : 0.0f;
      px[2] = 0.0f;
    }
  st = iris_png_write(path, &img, 0, exposure, err);
  iris_image_destroy(&img);
  if (st == IRIS_OK) iris_infof("cache marks: %s", path);
  return st;
}

int iris_cmd_render(int argc, char **argv) {
  iris_render_params p = iris_render_params_default();
  iris_guiding_params gp = iris_guiding_params_default();
  iris_guiding_marks marks = {0, 0, NULL};
  render_cli rc_opts;
  memset(&rc_opts, 0, sizeof rc_opts);
  rc_opts.adaptive = -1;
  iris_render_options ro;
  memset(&ro, 0, sizeof ro);
  ro.light_sampler = IRIS_LIGHT_SAMPLER_DEFAULT;
  iris_env_options eo = iris_env_options_default();
  iris_gltf_input_options go = {NULL};
  iris_option_binding bind[] = {{&OUTPUT_OPTIONS, &rc_opts, 0, 0}, {&IRIS_RENDER_OPTIONS, &ro, 0, 0},
                                {&PARTITION_OPTIONS, &rc_opts, 0, 0}, {&IRIS_GUIDING_OPTIONS, &gp, 0, 0},
                                {&IRIS_ENV_OPTIONS, &eo, 0, 0}, {&IRIS_GLTF_INPUT_OPTIONS, &go, 0, 0},
                                {&ADAPTIVE_OPTIONS, &rc_opts, 0, 0}, {&BUDGET_OPTIONS, &rc_opts, 0, 0}};
  const size_t nbind = sizeof bind / sizeof bind[0];
  const char *input = NULL;
  int operands = 0;
  int prc = iris_options_parse(CMD, argc, argv, bind, nbind, &input, 1, &operands);
  if (prc < 0) {
    print_help(bind, nbind);
    return IRIS_EXIT_OK;
  }
  if (prc != 0) return prc;
  const iris_option_binding *rb = &bind[1];
  const char *out_exr = rc_opts.output, *out_png = rc_opts.png, *camera = ro.camera;
  bool variance = rc_opts.variance, quiet = rc_opts.quiet, json = rc_opts.json;
  bool have_spp = iris_options_seen(rb, "spp"), have_seed = iris_options_seen(rb, "seed");
  double exposure = rc_opts.exposure;
  if (have_spp) p.spp = ro.spp;
  if (iris_options_seen(rb, "time")) p.time_budget = ro.time;
  if (have_seed) p.seed = ro.seed;
  if (ro.method && !iris_method_parse(ro.method, &p.method))
    return iris_cli_usage_error(CMD, "unknown method '%s' (auto, bsdf, nee, mis, guided, guided-nee)", ro.method);
  p.sampler = (iris_sampler_kind)ro.sampler;               /* 0 (sobol) unless given */
  p.light_sampling = (iris_triangle_sampling)ro.light_sampling;
  p.light_sampler = (iris_light_sampler)ro.light_sampler;
  p.connect = ro.connect;
  p.light_trace = ro.light_trace;
  if (iris_options_seen(rb, "max-depth")) p.max_depth = ro.max_depth;
  if (iris_options_seen(rb, "threads")) p.threads = ro.threads;
  if (iris_options_seen(rb, "width")) p.width = ro.width;
  if (iris_options_seen(rb, "height")) p.height = ro.height;
  bool aov_caches = false;
  if (rc_opts.aov) {
    if (strcmp(rc_opts.aov, "caches") != 0) return iris_cli_usage_error(CMD, "unknown AOV '%s' (caches)", rc_opts.aov);
    aov_caches = true;
  }
  p.sample_offset = rc_opts.sample_offset;
  if (p.sample_offset > (1ull << 40))
    return iris_cli_usage_error(CMD, "invalid value '%llu' for --sample-offset (at most 2^40)",
                                (unsigned long long)p.sample_offset);
  if (rc_opts.pixel_bounds && !parse_bounds(rc_opts.pixel_bounds, &p.bounds))
    return iris_cli_usage_error(CMD, "invalid value '%s' for --pixel-bounds (x0,y0,x1,y1 with "
                                     "0 <= x0 < x1 and 0 <= y0 < y1)", rc_opts.pixel_bounds);
  {
    /* adaptive sampling: on with a threshold or a target error (relmse unless
     * --adaptive says otherwise), with --adaptive freeze|relmse alone (then at
     * Blender's threshold 0.01), and by default under --time without --spp
     * or --sample-offset (relmse, the budget deciding: docs/rendering.md) */
    iris_adaptive_params *ap = &p.adaptive;
    ap->noise_threshold = rc_opts.noise_threshold;
    ap->target_error = rc_opts.target_error;
    ap->min_spp = rc_opts.min_spp;
    bool asked = ap->noise_threshold > 0.0 || ap->target_error > 0.0;
    const bool by_budget = rc_opts.adaptive < 0 && !asked && p.time_budget > 0.0 && !have_spp &&
                           !iris_options_seen(&bind[2], "sample-offset");
    ap->rule = rc_opts.adaptive >= 0 ? (iris_adaptive_rule)rc_opts.adaptive
               : asked || by_budget  ? IRIS_ADAPTIVE_RELMSE
                                     : IRIS_ADAPTIVE_OFF;
    if (by_budget) p.spp = IRIS_RENDER_BUDGET_ADAPTIVE_CAP; /* the budget decides, as the passes do without it */
    if (ap->rule != IRIS_ADAPTIVE_OFF && !asked && !by_budget) ap->noise_threshold = 0.01;
    if (ap->rule == IRIS_ADAPTIVE_OFF && (asked || ap->min_spp > 0))
      return iris_cli_usage_error(CMD, "--noise-threshold, --target-error and --min-spp need adaptive sampling "
                                       "(not --adaptive off)");
    if (ap->rule == IRIS_ADAPTIVE_FREEZE && !(ap->noise_threshold > 0.0))
      return iris_cli_usage_error(CMD, "--adaptive freeze needs --noise-threshold (it stops pixels there)");
    if (ap->rule != IRIS_ADAPTIVE_OFF && have_spp && ap->min_spp > p.spp)
      return iris_cli_usage_error(CMD, "--min-spp %d is above the --spp cap %d", ap->min_spp, p.spp);
  }
  int erc = iris_env_options_check(CMD, &bind[4], false);
  if (erc != IRIS_EXIT_OK) return erc;
  /* Everything that can be checked is checked before any work starts. */
  if (!input) return iris_cli_usage_error(CMD, "no input scene given");
  /* --guide-out without an image output: build and write the guide only (the
   * Slurm driver's training job). */
  const bool guide_only = !out_exr && !out_png && gp.guide_out;
  if (!out_exr && !out_png && !guide_only)
    return iris_cli_usage_error(CMD, "no output: give -o OUT.exr and/or --png OUT.png");
  if (rc_opts.time_total && !(p.time_budget > 0.0))
    return iris_cli_usage_error(CMD, "--time-total needs --time");
  p.budget_includes_setup = rc_opts.time_total;
  if (have_spp && p.time_budget > 0.0 && p.adaptive.rule == IRIS_ADAPTIVE_OFF)
    return iris_cli_usage_error(CMD, "--spp and --time exclude each other (both caps only with adaptive sampling)");
  if (out_exr && !ends_with(out_exr, ".exr"))
    return iris_cli_usage_error(CMD, "output '%s' must end in .exr", out_exr);
  if (out_png && !ends_with(out_png, ".png"))
    return iris_cli_usage_error(CMD, "PNG output '%s' must end in .png", out_png);
  if (variance && !out_exr) return iris_cli_usage_error(CMD, "--variance needs -o OUT.exr");
  if ((out_exr && !output_dir_ok(out_exr)) || (out_png && !output_dir_ok(out_png)))
    return iris_cli_usage_error(CMD, "the folder of the output file does not exist");
  if ((aov_caches || gp.dump_dir) && !iris_method_uses_guiding(p.method))
    return iris_cli_usage_error(CMD, "%s needs --method guided or guided-nee",
                                aov_caches ? "--aov caches" : "--dump-caches");
  /* auto's guide is a file too (a declined one records why); an unset method
   * is checked once the scene says what it resolves to */
  if ((gp.guide_in || gp.guide_out) && !iris_method_uses_guiding(p.method) && p.method != IRIS_METHOD_AUTO &&
      p.method != IRIS_METHOD_COUNT)
    return iris_cli_usage_error(CMD, "%s needs --method auto, guided or guided-nee",
                                gp.guide_in ? "--guide-in" : "--guide-out");
  if (gp.guide_in && gp.guide_out)
    return iris_cli_usage_error(CMD, "--guide-in and --guide-out exclude each other (copy the file instead)");
  if (gp.guide_in && (aov_caches || gp.dump_dir))
    return iris_cli_usage_error(CMD, "%s needs the photons of a built guide; it does not work with --guide-in",
                                aov_caches ? "--aov caches" : "--dump-caches");
  if (gp.guide_out && !output_dir_ok(gp.guide_out))
    return iris_cli_usage_error(CMD, "the folder of the --guide-out file does not exist");
  if (gp.guide_in && !iris_path_exists(gp.guide_in)) {
    fprintf(stderr, "iris: %s: cannot open: no such guide file\n", gp.guide_in);
    return IRIS_EXIT_USAGE;
  }
  if (gp.dump_dir && !iris_path_exists(gp.dump_dir))
    return iris_cli_usage_error(CMD, "the --dump-caches folder '%s' does not exist", gp.dump_dir);
  if (aov_caches) gp.marks = &marks;
  if (gp.marks || gp.dump_dir) gp.inspect = iris_guiding_inspect;
  /* unset (the scene's method, else auto) and auto may need the guide too */
  /* ... and --light-sampler learned (the caches' light tables) for any method */
  if (iris_method_uses_guiding(p.method) || p.method == IRIS_METHOD_AUTO || p.method == IRIS_METHOD_COUNT ||
      p.light_sampler == IRIS_LIGHT_SAMPLER_LEARNED) {
    p.guide = &iris_guiding_provider;
    p.guide_options = &gp;
    p.config_hash = guiding_params_hash(&gp);
  }
  if (quiet) iris_log_set_level(IRIS_LOG_QUIET);

  /* From here on Ctrl-C stops the work in whatever phase it is (docs/cli.md). */
  iris_cli_catch_signals();
  iris_scene *scene = NULL;
  iris_import_options io = iris_import_options_default();
  io.camera_name = camera;
  io.variant = go.variant;
  int rc = iris_cli_load_scene(CMD, input, &io, NULL, &scene);
  if (rc != IRIS_EXIT_OK) {
    iris_cli_release_signals();
    return rc;
  }
  if ((rc = iris_env_options_apply(CMD, &bind[4], scene)) != IRIS_EXIT_OK) {
    iris_cli_release_signals();
    iris_scene_destroy(scene);
    return rc;
  }
  if (!quiet) iris_warn_if_lightless(scene, input);
  if ((gp.guide_in || gp.guide_out) && p.method == IRIS_METHOD_COUNT) {
    iris_render_params q = p;
    iris_render_params_from_scene(&q, scene);
    if (!iris_method_uses_guiding(q.method) && q.method != IRIS_METHOD_AUTO) {
      iris_cli_release_signals();
      iris_scene_destroy(scene);
      return iris_cli_usage_error(CMD, "%s needs --method auto, guided or guided-nee (the scene's is %s)",
                                  gp.guide_in ? "--guide-in" : "--guide-out", iris_method_name(q.method));
    }
  }
  iris_error err;
  iris_error_clear(&err);
  iris_status st;
  if (!have_seed && scene->render.has_seed) p.seed = scene->render.seed;
  p.camera_name = camera;

  progress_state ps = {!quiet && !json && iris_log_progress_enabled(), 0};
  /* Guide only: the guide is built (and written by the provider), no pass runs. */
  p.no_passes = guide_only;
  p.keep_training = !gp.discard_training;
  p.cancel = iris_cli_stop_flag();
  p.progress = draw_progress;
  p.adaptive_progress = draw_adaptive;
  p.progress_ctx = &ps;
  p.phase = ps.enabled ? draw_phase : NULL; /* else the guide logs its long training passes */
  p.phase_ctx = &ps;
  {
    /* the film size is only known inside iris_render; estimate pixels there */
    iris_pinhole cam;
    iris_error cerr;
    iris_error_clear(&cerr);
    if (iris_pinhole_setup(scene, camera, p.width, p.height, &cam, &cerr) == IRIS_OK)
      ps.pixels = p.bounds.x1 > 0 ? (uint64_t)(p.bounds.x1 - p.bounds.x0) * (uint64_t)(p.bounds.y1 - p.bounds.y0)
                                  : (uint64_t)cam.width * (uint64_t)cam.height;
  }
  iris_render_result res;
  st = iris_render(scene, &p, &res, &err);
  /* signals stay caught while the files are written: a first Ctrl-C there
   * changes nothing, a second ends at once (the writes go through a temporary
   * file, so no partial output is left under the output's name) */
  iris_log_progress_end();
  if (st != IRIS_OK) {
    iris_guiding_marks_destroy(&marks);
    iris_scene_destroy(scene);
    rc = iris_cli_report(&err);
    iris_cli_release_signals();
    return rc;
  }
  rc = IRIS_EXIT_OK;
  if (guide_only) {
    if (!quiet && !json) iris_infof("render: %s: guide written to %s (no image)", input, gp.guide_out);
  }
  if (out_exr) st = iris_render_write_exr(&res, out_exr, input, variance, &err);
  if (st == IRIS_OK && out_png) st = iris_render_write_png(&res, out_png, (float)exposure, &err);
  if (st == IRIS_OK && aov_caches) st = write_cache_marks(&res, &marks, out_png ? out_png : out_exr, (float)exposure, &err);
  iris_guiding_marks_destroy(&marks);
  if (st != IRIS_OK) rc = iris_cli_report(&err);

  double samples = res.adaptive.rule != IRIS_ADAPTIVE_OFF
                       ? (double)res.adaptive_outcome.paths
                       : (double)res.spp * (double)res.film.width * (double)res.film.height;
  double rays = (double)(res.stats.rays + res.stats.shadow_rays);
  if (json) {
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "input", input);
    if (out_exr) cJSON_AddStringToObject(o, "output", out_exr);
    if (out_png) cJSON_AddStringToObject(o, "png", out_png);
    cJSON_AddNumberToObject(o, "width", res.film.width);
    cJSON_AddNumberToObject(o, "height", res.film.height);
    cJSON_AddStringToObject(o, "camera", res.camera.name);
    cJSON_AddStringToObject(o, "method", iris_method_name(res.method));
    cJSON_AddStringToObject(o, "method_requested", iris_method_name(res.method_requested));
    if (res.method_reason[0]) cJSON_AddStringToObject(o, "method_reason", res.method_reason);
    cJSON_AddStringToObject(o, "sampler", iris_sampler_kind_name(res.sampler));
    cJSON_AddStringToObject(o, "light_sampling", iris_triangle_sampling_name(res.light_sampling));
    cJSON_AddStringToObject(o, "light_sampler", iris_light_sampler_name(res.light_sampler));
    cJSON_AddNumberToObject(o, "spp", res.spp);
    cJSON_AddNumberToObject(o, "train_spp", res.train_spp);
    cJSON_AddNumberToObject(o, "sample_offset", (double)res.sample_offset);
    cJSON *win = cJSON_AddArrayToObject(o, "pixel_bounds");
    int wb[4] = {res.bounds.x0, res.bounds.y0, res.bounds.x1, res.bounds.y1};
    for (int k = 0; k < 4; k++) cJSON_AddItemToArray(win, cJSON_CreateNumber(wb[k]));
    cJSON_AddNumberToObject(o, "seed", (double)res.seed);
    cJSON_AddNumberToObject(o, "threads", res.threads);
    cJSON_AddNumberToObject(o, "max_depth", p.max_depth < 0 ? (scene->render.max_depth >= 0 ? scene->render.max_depth : IRIS_DEFAULT_MAX_DEPTH) : p.max_depth);
    cJSON_AddNumberToObject(o, "seconds", res.seconds);
    cJSON_AddNumberToObject(o, "setup_seconds", res.setup_seconds);
    cJSON_AddNumberToObject(o, "samples", samples);
    cJSON_AddNumberToObject(o, "samples_per_second", res.seconds > 0 ? samples / res.seconds : 0);
    cJSON_AddNumberToObject(o, "rays", rays);
    cJSON_AddNumberToObject(o, "rays_per_second", res.seconds > 0 ? rays / res.seconds : 0);
    cJSON_AddNumberToObject(o, "closest_hit_rays", (double)res.stats.rays);
    cJSON_AddNumberToObject(o, "shadow_rays", (double)res.stats.shadow_rays);
    cJSON_AddNumberToObject(o, "nan_count", (double)res.stats.nan_count);
    cJSON_AddBoolToObject(o, "interrupted", res.interrupted);
    if (res.adaptive.rule != IRIS_ADAPTIVE_OFF) {
      const iris_adaptive_outcome *ao = &res.adaptive_outcome;
      cJSON *a = cJSON_AddObjectToObject(o, "adaptive");
      cJSON_AddStringToObject(a, "rule", iris_adaptive_rule_name(res.adaptive.rule));
      cJSON_AddNumberToObject(a, "noise_threshold", res.adaptive.noise_threshold);
      cJSON_AddNumberToObject(a, "target_error", res.adaptive.target_error);
      cJSON_AddNumberToObject(a, "error_estimate", ao->error_estimate);
      cJSON_AddNumberToObject(a, "spp_mean", ao->spp_mean);
      cJSON_AddNumberToObject(a, "spp_min", ao->spp_min);
      cJSON_AddNumberToObject(a, "spp_max", ao->spp_max);
      cJSON_AddNumberToObject(a, "scout_spp_mean", ao->scout_spp_mean);
      cJSON_AddNumberToObject(a, "rounds", ao->rounds);
      cJSON_AddStringToObject(a, "stop", iris_adaptive_stop_name(ao));
    }
    char *text = cJSON_Print(o);
    if (text) printf("%s\n", text);
    free(text);
    cJSON_Delete(o);
  } else if (!quiet) {
    char train[48] = "";
    if (res.train_spp > 0) snprintf(train, sizeof train, " + %d training spp", res.train_spp);
    char spp[48];
    if (res.adaptive.rule != IRIS_ADAPTIVE_OFF) {
      snprintf(spp, sizeof spp, "adaptive, %.1f spp mean", res.adaptive_outcome.spp_mean);
      if (res.train_spp > 0) snprintf(train, sizeof train, " (%d of them training)", res.train_spp);
    } else {
      snprintf(spp, sizeof spp, "%d spp", res.spp);
    }
    iris_infof("render: %s, %dx%d, %s%s (%s), %.2f s after %.2f s of setup, %.2f Msamples/s, %.1f Mrays/s%s",
               input, res.film.width, res.film.height, spp, train,
               res.method_reason[0] ? res.method_reason : iris_method_name(res.method),
               res.seconds, res.setup_seconds, res.seconds > 0 ? samples / res.seconds * 1e-6 : 0.0,
               res.seconds > 0 ? rays / res.seconds * 1e-6 : 0.0,
               res.interrupted ? " (interrupted)" : "");
    if (res.adaptive.rule != IRIS_ADAPTIVE_OFF) {
      const iris_adaptive_outcome *ao = &res.adaptive_outcome;
      char why[96];
      if (ao->reached_target)
        snprintf(why, sizeof why, "reached the target %.3g", res.adaptive.target_error);
      else if (ao->converged)
        snprintf(why, sizeof why, "every pixel below the noise threshold %g", res.adaptive.noise_threshold);
      else if (ao->interrupted)
        snprintf(why, sizeof why, "interrupted");
      else if (p.time_budget > 0 && !(res.adaptive.target_error > 0) && !(res.adaptive.noise_threshold > 0))
        snprintf(why, sizeof why, "the --time budget spent (--adaptive off: every pixel the same samples)");
      else
        snprintf(why, sizeof why, "stopped by the %s cap%s", p.time_budget > 0 ? "--time" : "--spp",
                 res.adaptive.target_error > 0 ? " before the target" : "");
      char scouts[48] = "";
      if (ao->scout_spp_mean > 0) snprintf(scouts, sizeof scouts, " + %.1f scout spp", ao->scout_spp_mean);
      iris_infof("adaptive (%s): %.1f spp mean (%d..%d)%s, estimated relMSE %.3g: %s",
                 iris_adaptive_rule_name(res.adaptive.rule), ao->spp_mean, ao->spp_min, ao->spp_max, scouts,
                 ao->error_estimate, why);
    }
    if (res.stats.nan_count)
      iris_warnf("%llu NaN/Inf samples were dropped", (unsigned long long)res.stats.nan_count);
  }
  iris_render_result_destroy(&res);
  iris_scene_destroy(scene);
  if (rc == IRIS_EXIT_OK && res.interrupted) rc = iris_cli_interrupt_exit();
  iris_cli_release_signals();
  return rc;
}
