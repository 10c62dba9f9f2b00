/* `iris render INPUT -o OUT.exr`: fills iris_render_params from the flags,
 * loads the input (an iris scene, an importable file or a built-in scene name),
 * renders and writes EXR/PNG. docs/cli.md ("render") lists every flag. */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "core/fileio.h"
#include "core/image.h"
#include "core/log.h"
#include "core/rng.h"
#include "scenes/builtin.h"
#include "renderer/guiding/guiding.h"
#include "renderer/render.h"
#include "tools/cli.h"

static const char *CMD = "render";

static void print_help(void) {
  printf(
      "Usage: iris render INPUT [-o OUT.exr] [--png OUT.png] [options]\n"
      "\n"
      "Renders INPUT (an iris scene .json, an OBJ/PLY/glTF file, or a built-in scene).\n"
      "Built-in scenes:");
  int column = 16;
  for (const char *const *n = iris_builtin_names(); *n; n++) {
    if (column + (int)strlen(*n) + 2 > 78) {
      printf("\n ");
      column = 1;
    }
    printf(" %s", *n);
    column += (int)strlen(*n) + 1;
  }
  printf(
      "\n\n"
      "Output:\n"
      "  -o, --output FILE   OpenEXR output (float RGB + metadata)\n"
      "      --variance      also write var.R/G/B: variance of each pixel's mean\n"
      "      --png FILE      8-bit sRGB PNG as well (or instead)\n"
      "      --exposure EV   scale the PNG by 2^EV (default 0)\n"
      "Sampling:\n"
      "      --spp N         samples per pixel (default: the scene's, else 64)\n"
      "      --time SECONDS  whole passes until SECONDS have passed (not with --spp)\n"
      "      --seed N        random seed (default: the scene's, else 0)\n"
      "      --method M      bsdf | nee | mis (default) | guided | guided-nee\n"
      "      --sampler S     sobol (default: Owen-scrambled Sobol) | independent\n"
      "      --light-sampling M  emitter triangles: solid-angle (default, where it helps) | area\n"
      "      --max-depth B   bounces as Cycles counts them, 0 = direct light (default 64)\n"
      "      --threads N     worker threads (default: all cores); same image for any N\n"
      "Partitioned renders (merge the parts with iris merge; docs/distributed.md):\n"
      "      --sample-offset K   render sample indices K .. K+spp-1 (default 0)\n"
      "      --pixel-bounds x0,y0,x1,y1   render only this window of the frame\n"
      "                      (half-open; the output image is the window)\n"
      "Guiding (--method guided | guided-nee; docs/guiding.md; unset = from the scene):\n"
      "      --photons N     photon paths        --caches N      caches\n"
      "      --cache-res R   map texels per side --cache-k K     photons per cache\n"
      "      --pdf-floor F   texel probability floor (default 0.0002)\n"
      "      --alpha-max A   cap on the cache-sampling probability (default 0.5 for\n"
      "                      guided-nee, 0.7 for guided)\n"
      "      --cos-min C     cache normal agreement needed (default 0.9)\n"
      "      --splat nearest|bilinear   photon splatting (default bilinear)\n"
      "      --photon-lights power|area   photons leave lights in proportion to\n"
      "                      power (default) or, as the thesis, emitters by area\n"
      "      --force-guiding build caches even where guiding would be skipped\n"
      "      --dump-caches DIR   write pdf and photon-count PNGs of the caches that\n"
      "                      serve a 4x3 grid of pixels (DIR/caches.txt lists them)\n"
      "      --aov caches    also write OUT-caches.png: the image with cache positions\n"
      "                      marked (green: from camera rays, red: from photons)\n"
      "Camera:\n"
      "      --camera NAME   scene camera to use (default: the first; none: auto-framed)\n"
      "      --width W, --height H   film size (default: the scene's, else from the\n"
      "                      camera's aspect ratio, 512 pixels high)\n"
      "Reporting:\n"
      "      --quiet         no progress bar or messages\n"
      "      --json          JSON summary on stdout\n"
      "\n"
      "Exit status: 0 done, 2 bad usage or input, 1 other failure, 130 (SIGINT) or\n"
      "143 (SIGTERM) when interrupted: the image of the passes done is still written.\n");
}

static volatile sig_atomic_t g_stop = 0;
static void on_signal(int sig) { g_stop = sig; }

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
                (double)gp->photon_lights};
  for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
    uint64_t bits;
    memcpy(&bits, &v[i], sizeof bits);
    h = iris_mix64(h ^ (bits + 0x9e3779b97f4a7c15ULL));
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
  bool aov_caches = false;
  const char *input = NULL, *out_exr = NULL, *out_png = NULL, *camera = NULL;
  bool variance = false, quiet = false, json = false, have_spp = false, have_seed = false;
  double exposure = 0.0;
  for (int i = 1; i < argc; i++) {
    char name[64];
    const char *val;
    const char *a = iris_cli_split_option(argv[i], name, sizeof name, &val);
#define NEED_VALUE()                                                                           \
  do {                                                                                         \
    if (!iris_cli_take_value(CMD, a, argc, argv, &i, &val)) return IRIS_EXIT_USAGE;            \
  } while (0)
    long lv;
    double dv;
    if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
      print_help();
      return IRIS_EXIT_OK;
    } else if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
      NEED_VALUE();
      out_exr = val;
    } else if (strcmp(a, "--png") == 0) {
      NEED_VALUE();
      out_png = val;
    } else if (strcmp(a, "--exposure") == 0) {
      NEED_VALUE();
      if (!iris_cli_parse_float(CMD, a, val, -64, 64, &exposure)) return IRIS_EXIT_USAGE;
    } else if (strcmp(a, "--variance") == 0) {
      variance = true;
    } else if (strcmp(a, "--spp") == 0) {
      NEED_VALUE();
      if (!iris_cli_parse_int(CMD, a, val, 1, 1 << 24, &lv)) return IRIS_EXIT_USAGE;
      p.spp = (int)lv;
      have_spp = true;
    } else if (strcmp(a, "--time") == 0) {
      NEED_VALUE();
      if (!iris_cli_parse_float(CMD, a, val, 1e-3, 1e7, &dv)) return IRIS_EXIT_USAGE;
      p.time_budget = dv;
    } else if (strcmp(a, "--seed") == 0) {
      NEED_VALUE();
      if (!iris_cli_parse_u64(CMD, a, val, &p.seed)) return IRIS_EXIT_USAGE;
      have_seed = true;
    } else if (strcmp(a, "--method") == 0) {
      NEED_VALUE();
      if (!iris_method_parse(val, &p.method))
        return iris_cli_usage_error(CMD, "unknown method '%s' (bsdf, nee, mis, guided, guided-nee)", val);
    } else if (strcmp(a, "--light-sampling") == 0) {
      NEED_VALUE();
      if (!iris_triangle_sampling_parse(val, &p.light_sampling))
        return iris_cli_usage_error(CMD, "unknown light sampling '%s' (solid-angle, area)", val);
    } else if (strcmp(a, "--sampler") == 0) {
      NEED_VALUE();
      if (!iris_sampler_kind_parse(val, &p.sampler))
        return iris_cli_usage_error(CMD, "unknown sampler '%s' (sobol, independent)", val);
    } else if (strcmp(a, "--max-depth") == 0) {
      NEED_VALUE();
      if (!iris_cli_parse_int(CMD, a, val, 0, 1000000, &lv)) return IRIS_EXIT_USAGE;
      p.max_depth = (int)lv;
    } else if (strcmp(a, "--threads") == 0) {
      NEED_VALUE();
      if (!iris_cli_parse_int(CMD, a, val, 1, 4096, &lv)) return IRIS_EXIT_USAGE;
      p.threads = (int)lv;
    } else if (strcmp(a, "--width") == 0 || strcmp(a, "--height") == 0) {
      bool w = strcmp(a, "--width") == 0;
      NEED_VALUE();
      if (!iris_cli_parse_int(CMD, a, val, 1, 65536, &lv)) return IRIS_EXIT_USAGE;
      if (w)
        p.width = (int)lv;
      else
        p.height = (int)lv;
    } else if (strcmp(a, "--photons") == 0 || strcmp(a, "--caches") == 0) {
      bool photons = strcmp(a, "--photons") == 0;
      NEED_VALUE();
      if (!iris_cli_parse_int(CMD, a, val, 1, 1L << 40, &lv)) return IRIS_EXIT_USAGE;
      if (photons)
        gp.photons = lv;
      else
        gp.caches = lv;
    } else if (strcmp(a, "--cache-res") == 0 || strcmp(a, "--cache-k") == 0) {
      bool res = strcmp(a, "--cache-res") == 0;
      NEED_VALUE();
      if (!iris_cli_parse_int(CMD, a, val, 1, res ? 256 : 1000000, &lv)) return IRIS_EXIT_USAGE;
      if (res)
        gp.cache_res = (int)lv;
      else
        gp.cache_k = (int)lv;
    } else if (strcmp(a, "--pdf-floor") == 0 || strcmp(a, "--alpha-max") == 0 ||
               strcmp(a, "--cos-min") == 0) {
      NEED_VALUE();
      bool cosmin = strcmp(a, "--cos-min") == 0;
      if (!iris_cli_parse_float(CMD, a, val, cosmin ? -1.0 : 0.0, 1.0, &dv)) return IRIS_EXIT_USAGE;
      if (strcmp(a, "--pdf-floor") == 0)
        gp.pdf_floor = (float)dv;
      else if (cosmin)
        gp.cos_min = (float)dv;
      else
        gp.alpha_max = (float)dv;
    } else if (strcmp(a, "--splat") == 0) {
      NEED_VALUE();
      if (strcmp(val, "nearest") == 0)
        gp.splat = IRIS_SPLAT_NEAREST;
      else if (strcmp(val, "bilinear") == 0)
        gp.splat = IRIS_SPLAT_BILINEAR;
      else
        return iris_cli_usage_error(CMD, "unknown splat mode '%s' (nearest, bilinear)", val);
    } else if (strcmp(a, "--photon-lights") == 0) {
      NEED_VALUE();
      if (strcmp(val, "power") == 0)
        gp.photon_lights = IRIS_EMIT_BY_POWER;
      else if (strcmp(val, "area") == 0)
        gp.photon_lights = IRIS_EMIT_BY_AREA;
      else
        return iris_cli_usage_error(CMD, "unknown photon light choice '%s' (power, area)", val);
    } else if (strcmp(a, "--force-guiding") == 0) {
      gp.force = true;
    } else if (strcmp(a, "--dump-caches") == 0) {
      NEED_VALUE();
      gp.dump_dir = val;
    } else if (strcmp(a, "--aov") == 0) {
      NEED_VALUE();
      if (strcmp(val, "caches") != 0) return iris_cli_usage_error(CMD, "unknown AOV '%s' (caches)", val);
      aov_caches = true;
    } else if (strcmp(a, "--sample-offset") == 0) {
      NEED_VALUE();
      if (!iris_cli_parse_u64(CMD, a, val, &p.sample_offset)) return IRIS_EXIT_USAGE;
      if (p.sample_offset > (1ull << 40))
        return iris_cli_usage_error(CMD, "invalid value '%s' for %s (at most 2^40)", val, a);
    } else if (strcmp(a, "--pixel-bounds") == 0) {
      NEED_VALUE();
      if (!parse_bounds(val, &p.bounds))
        return iris_cli_usage_error(CMD, "invalid value '%s' for %s (x0,y0,x1,y1 with "
                                         "0 <= x0 < x1 and 0 <= y0 < y1)", val, a);
    } else if (strcmp(a, "--camera") == 0) {
      NEED_VALUE();
      camera = val;
    } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
      quiet = true;
    } else if (strcmp(a, "--json") == 0) {
      json = true;
    } else if (a[0] == '-' && a[1] != 0) {
      return iris_cli_usage_error(CMD, "unknown option '%s'", argv[i]);
    } else {
      if (input) return iris_cli_usage_error(CMD, "more than one input ('%s' and '%s')", input, a);
      input = a;
    }
    if (val && (strcmp(a, "--variance") == 0 || strcmp(a, "--quiet") == 0 ||
                strcmp(a, "--json") == 0 || strcmp(a, "--force-guiding") == 0))
      return iris_cli_usage_error(CMD, "option %s takes no value", a);
#undef NEED_VALUE
  }
  /* Everything that can be checked is checked before any work starts. */
  if (!input) return iris_cli_usage_error(CMD, "no input scene given");
  if (!out_exr && !out_png) return iris_cli_usage_error(CMD, "no output: give -o OUT.exr and/or --png OUT.png");
  if (have_spp && p.time_budget > 0.0)
    return iris_cli_usage_error(CMD, "--spp and --time exclude each other");
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
  if (gp.dump_dir && !iris_path_exists(gp.dump_dir))
    return iris_cli_usage_error(CMD, "the --dump-caches folder '%s' does not exist", gp.dump_dir);
  if (aov_caches) gp.marks = &marks;
  if (iris_method_uses_guiding(p.method)) {
    p.guide = &iris_guiding_provider;
    p.guide_options = &gp;
    p.config_hash = guiding_params_hash(&gp);
  }
  if (quiet) iris_log_set_level(IRIS_LOG_QUIET);

  iris_scene *scene = NULL;
  int rc = iris_cli_load_scene(CMD, input, camera, NULL, &scene);
  if (rc != IRIS_EXIT_OK) return rc;
  iris_error err;
  iris_error_clear(&err);
  iris_status st;
  if (!have_seed && scene->render.has_seed) p.seed = scene->render.seed;
  p.camera_name = camera;

  progress_state ps = {!quiet && !json && iris_log_progress_enabled(), 0};
  p.cancel = &g_stop;
  p.progress = draw_progress;
  p.progress_ctx = &ps;
  {
    /* the film size is only known inside iris_render; estimate pixels there */
    iris_pinhole cam;
    iris_error cerr;
    iris_error_clear(&cerr);
    if (iris_pinhole_setup(scene, camera, p.width, p.height, &cam, &cerr) == IRIS_OK)
      ps.pixels = p.bounds.x1 > 0 ? (uint64_t)(p.bounds.x1 - p.bounds.x0) * (uint64_t)(p.bounds.y1 - p.bounds.y0)
                                  : (uint64_t)cam.width * (uint64_t)cam.height;
  }
  struct sigaction sa, old_int, old_term;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sa.sa_flags = SA_RESETHAND; /* a second signal stops at once */
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &old_int);
  sigaction(SIGTERM, &sa, &old_term);

  iris_render_result res;
  st = iris_render(scene, &p, &res, &err);
  sigaction(SIGINT, &old_int, NULL);
  sigaction(SIGTERM, &old_term, NULL);
  if (ps.enabled) fprintf(stderr, "\n");
  if (st != IRIS_OK) {
    iris_guiding_marks_destroy(&marks);
    iris_scene_destroy(scene);
    return iris_cli_report(&err);
  }
  rc = IRIS_EXIT_OK;
  if (out_exr) st = iris_render_write_exr(&res, out_exr, input, variance, &err);
  if (st == IRIS_OK && out_png) st = iris_render_write_png(&res, out_png, (float)exposure, &err);
  if (st == IRIS_OK && aov_caches) st = write_cache_marks(&res, &marks, out_png ? out_png : out_exr, (float)exposure, &err);
  iris_guiding_marks_destroy(&marks);
  if (st != IRIS_OK) rc = iris_cli_report(&err);

  double samples = (double)res.spp * (double)res.film.width * (double)res.film.height;
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
    cJSON_AddStringToObject(o, "sampler", iris_sampler_kind_name(res.sampler));
    cJSON_AddStringToObject(o, "light_sampling", iris_triangle_sampling_name(res.light_sampling));
    cJSON_AddNumberToObject(o, "spp", res.spp);
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
    char *text = cJSON_Print(o);
    if (text) printf("%s\n", text);
    free(text);
    cJSON_Delete(o);
  } else if (!quiet) {
    iris_infof("render: %s, %dx%d, %d spp (%s), %.2f s, %.2f Msamples/s, %.1f Mrays/s%s",
               input, res.film.width, res.film.height, res.spp, iris_method_name(res.method),
               res.seconds, res.seconds > 0 ? samples / res.seconds * 1e-6 : 0.0,
               res.seconds > 0 ? rays / res.seconds * 1e-6 : 0.0,
               res.interrupted ? " (interrupted)" : "");
    if (res.stats.nan_count)
      iris_warnf("%llu NaN/Inf samples were dropped", (unsigned long long)res.stats.nan_count);
  }
  iris_render_result_destroy(&res);
  iris_scene_destroy(scene);
  if (rc == IRIS_EXIT_OK && res.interrupted) rc = g_stop == SIGTERM ? 143 : 130;
  return rc;
}
