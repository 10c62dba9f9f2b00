/* Table-driven options; see options.h. */
#define _DEFAULT_SOURCE /* realpath */
#include "tools/options.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "core/log.h"
#include "renderer/envmap.h"
#include "renderer/guiding/guiding.h"
#include "tools/cli.h"

_Static_assert(sizeof(iris_splat_mode) == sizeof(int) && sizeof(iris_emission_selection) == sizeof(int),
               "choice options store an int into enum fields");

#define OPT(name, sn, type, arg, lo, hi, st, field, help) \
  { name, sn, type, arg, lo, hi, offsetof(st, field), help, NULL }
#define CHOICE(name, arg, st, field, choices, help) \
  { name, 0, IRIS_OPT_CHOICE, arg, 0, 0, offsetof(st, field), help, choices }

/* ---- shared groups -------------------------------------------------------- */

static const iris_option ENV_ROWS[] = {
    OPT("env", 0, IRIS_OPT_STRING, "FILE", 0, 0, iris_env_options, map,
        "equirectangular environment map (.exr or .hdr) lighting the scene"),
    OPT("env-strength", 0, IRIS_OPT_FLOAT, "S", 0, 1e9, iris_env_options, strength,
        "multiplies the map's texels (default 1)"),
    OPT("env-rotation", 0, IRIS_OPT_FLOAT, "DEG", -36000, 36000, iris_env_options, rotation,
        "turns the map about the up axis, as Blender's Mapping Z rotation (default 0)"),
    OPT("env-color", 0, IRIS_OPT_RGB, "R,G,B", 0, 1e9, iris_env_options, color,
        "a constant sky of this linear radiance instead of a map"),
};
const iris_option_group IRIS_ENV_OPTIONS = {"Environment (replaces the scene's world; docs/format.md)",
                                            ENV_ROWS, sizeof ENV_ROWS / sizeof ENV_ROWS[0]};

iris_env_options iris_env_options_default(void) {
  iris_env_options e;
  memset(&e, 0, sizeof e);
  e.strength = 1.0f;
  return e;
}

/* In the order of iris_sampler_kind and iris_triangle_sampling. */
static const char *const SAMPLER_CHOICES[] = {"sobol", "independent", NULL};
static const char *const LIGHT_SAMPLING_CHOICES[] = {"solid-angle", "area", NULL};
static const char *const LIGHT_SAMPLER_CHOICES[] = {"power", "tree", "learned", NULL}; /* iris_light_sampler */
static const char *const CONNECT_CHOICES[] = {"auto", "off", "on", NULL}; /* iris_render_params.connect */
static const char *const LIGHT_TRACE_CHOICES[] = {"auto", "off", NULL};    /* iris_render_params.light_trace */
static const iris_option RENDER_ROWS[] = {
    OPT("spp", 0, IRIS_OPT_INT, "N", 1, 1 << 24, iris_render_options, spp,
        "samples per pixel (default: the scene's, else 64)"),
    OPT("time", 0, IRIS_OPT_DOUBLE, "SECONDS", 1e-3, 1e7, iris_render_options, time,
        "render until SECONDS have passed, the samples where they\nlower the image's relMSE most (--adaptive off: whole\npasses; not with --spp)"),
    OPT("seed", 0, IRIS_OPT_U64, "N", 0, 0, iris_render_options, seed,
        "random seed (default: the scene's, else 0)"),
    OPT("method", 0, IRIS_OPT_STRING, "M", 0, 0, iris_render_options, method,
        "auto | bsdf | nee | mis | guided | guided-nee (default:\nthe scene's, else auto: guided-nee or mis per scene)"),
    CHOICE("sampler", "S", iris_render_options, sampler, SAMPLER_CHOICES,
           "sobol (default: Owen-scrambled Sobol) | independent"),
    CHOICE("light-sampling", "M", iris_render_options, light_sampling, LIGHT_SAMPLING_CHOICES,
           "emitter triangles: solid-angle (default, where it helps) | area"),
    CHOICE("light-sampler", "S", iris_render_options, light_sampler, LIGHT_SAMPLER_CHOICES,
           "NEE's light choice: tree (default: the light tree) | power"),
    CHOICE("connect", "M", iris_render_options, connect, CONNECT_CHOICES,
           "guided methods: connections to light paths kept behind the\nopening the guide found, or of the sky through its windows:\nauto (default: where enough of the caches' light came\nthrough them) | off | on"),
    CHOICE("light-trace", "M", iris_render_options, light_trace, LIGHT_TRACE_CHOICES,
           "mis: light paths off glossy reflectors (roughness <= 0.3)\nand of the sun through clear glass into the camera, for\ncaustics the camera finds by chance: auto (default: where\nsuch surfaces are) | off"),
    OPT("max-depth", 0, IRIS_OPT_INT, "B", 0, 1000000, iris_render_options, max_depth,
        "bounces as Cycles counts them, 0 = direct light (default 64)"),
    OPT("threads", 0, IRIS_OPT_INT, "N", 1, 4096, iris_render_options, threads,
        "worker threads (default: all cores); same image for any N"),
    OPT("camera", 0, IRIS_OPT_STRING, "NAME", 0, 0, iris_render_options, camera,
        "scene camera to use (default: the first; none: auto-framed)"),
    OPT("width", 0, IRIS_OPT_INT, "W", 1, 65536, iris_render_options, width,
        "film width (default: the scene's, else from the camera's aspect ratio)"),
    OPT("height", 0, IRIS_OPT_INT, "H", 1, 65536, iris_render_options, height,
        "film height (default: the scene's, else 512)"),
};
const iris_option_group IRIS_RENDER_OPTIONS = {"Sampling and camera", RENDER_ROWS,
                                               sizeof RENDER_ROWS / sizeof RENDER_ROWS[0]};
static const iris_option GLTF_INPUT_ROWS[] = {
    OPT("variant", 0, IRIS_OPT_STRING, "NAME", 0, 0, iris_gltf_input_options, variant,
        "apply the glTF file's material variant NAME (KHR_materials_variants;\n"
        "default: its default materials; `iris info FILE` lists the names)"),
};
const iris_option_group IRIS_GLTF_INPUT_OPTIONS = {"glTF input", GLTF_INPUT_ROWS,
                                                   sizeof GLTF_INPUT_ROWS / sizeof GLTF_INPUT_ROWS[0]};

static const char *const SPLAT_CHOICES[] = {"nearest", "bilinear", NULL};
static const char *const PHOTON_LIGHT_CHOICES[] = {"power", "area", NULL};
static const iris_option GUIDING_ROWS[] = {
    OPT("photons", 0, IRIS_OPT_I64, "N", 1, 1099511627776.0, iris_guiding_params, photons, "photon paths"),
    OPT("caches", 0, IRIS_OPT_I64, "N", 1, 1099511627776.0, iris_guiding_params, caches, "caches"),
    OPT("cache-res", 0, IRIS_OPT_INT, "R", 1, 256, iris_guiding_params, cache_res, "map texels per side"),
    OPT("refine", 0, IRIS_OPT_INT, "N", 0, 8, iris_guiding_params, refine,
        "texels per cache split 4 x 4 where the light is\n"
        "concentrated (default 0: off; at most 8)"),
    OPT("cache-k", 0, IRIS_OPT_INT, "K", 1, 1000000, iris_guiding_params, cache_k, "photons per cache"),
    OPT("pdf-floor", 0, IRIS_OPT_FLOAT, "F", 0, 1, iris_guiding_params, pdf_floor,
        "texel probability floor (default 0.0002)"),
    OPT("alpha-max", 0, IRIS_OPT_FLOAT, "A", 0, 1, iris_guiding_params, alpha_max,
        "cap on the cache-sampling probability (default 0.5 for\n"
        "guided-nee, 0.7 for guided; trained caches learn their\n"
        "own up to 0.95, or up to A when given)"),
    OPT("cos-min", 0, IRIS_OPT_FLOAT, "C", -1, 1, iris_guiding_params, cos_min,
        "cache normal agreement needed (default 0.9)"),
    OPT("sky-regions", 0, IRIS_OPT_INT, "N", 1, 4096, iris_guiding_params, sky_regions,
        "environment map regions across for light sampling from\n"
        "what each cache sees of the sky (default 16; N/2 down)"),
    OPT("sky-probes", 0, IRIS_OPT_INT, "N", 0, 1024, iris_guiding_params, sky_probes,
        "shadow rays per cache and map region (default 2; 0: map\n"
        "sampling alone, as mis)"),
    OPT("sky-beta", 0, IRIS_OPT_FLOAT, "B", 0, 1, iris_guiding_params, sky_beta,
        "probability of a cache's seen regions in light sampling\n"
        "of the map (default 0.75; the map's own the rest)"),
    CHOICE("splat", "nearest|bilinear", iris_guiding_params, splat, SPLAT_CHOICES,
           "photon splatting (default bilinear)"),
    CHOICE("photon-lights", "power|area", iris_guiding_params, photon_lights, PHOTON_LIGHT_CHOICES,
           "photons leave lights in proportion to power (default)\n"
           "or, as the thesis, emitters by area"),
    OPT("train-spp", 0, IRIS_OPT_INT, "N", 0, 1000000, iris_guiding_params, train_spp,
        "samples per pixel of training passes from camera paths\n"
        "(default 5% of --spp, or of what --time holds; 0: photons only)"),
    OPT("train-prior", 0, IRIS_OPT_FLOAT, "W", 0, 1e9, iris_guiding_params, train_prior,
        "photon-equivalent weight of a cache's photons against its\n"
        "n training samples, mixed n / (n + W) (default 200)"),
    OPT("discard-training", 0, IRIS_OPT_FLAG, NULL, 0, 0, iris_guiding_params, discard_training,
        "leave the training passes' paths out of the image (by\n"
        "default they are in it: unbiased samples of each pixel)"),
    OPT("train-all-light", 0, IRIS_OPT_FLAG, NULL, 0, 0, iris_guiding_params, train_all_light,
        "train towards all incident light, not only the part light\n"
        "sampling leaves to the sampled direction"),
    OPT("no-learn-alpha", 0, IRIS_OPT_FLAG, NULL, -1, 0, iris_guiding_params, learn_alpha,
        "keep alpha = min(roughness, --alpha-max) instead of learning\n"
        "each cache's selection probability in training"),
    OPT("no-lamp-glass", 0, IRIS_OPT_FLAG, NULL, -1, 0, iris_guiding_params, lamp_glass,
        "do not aim guided directions at lamps whose light reaches\n"
        "a surface straight through glass (lamps behind glass)"),
    OPT("no-glints", 0, IRIS_OPT_FLAG, NULL, -1, 0, iris_guiding_params, glints,
        "do not aim guided directions at the spots where a mirror,\n"
        "glass or near-mirror metal reflects a light (glints)"),
    OPT("no-portals", 0, IRIS_OPT_FLAG, NULL, -1, 0, iris_guiding_params, portals,
        "do not draw guided directions through the openings (doors)\n"
        "the caches' indirect light came through (portals)"),
    OPT("no-light-samples", 0, IRIS_OPT_FLAG, NULL, -1, 0, iris_guiding_params, light_samples,
        "with --light-sampler learned: learn the caches' light tables\n"
        "from the photons alone, not also from training's light samples"),
    OPT("light-min", 0, IRIS_OPT_FLOAT, "P", 0.001, 1, iris_guiding_params, light_min,
        "probability of light sampling where the caches' training\n"
        "found it brings no light (default 0.1; 1: always)"),
    OPT("force-guiding", 0, IRIS_OPT_FLAG, NULL, 0, 0, iris_guiding_params, force,
        "build caches even where guiding would be skipped"),
    OPT("guide-out", 0, IRIS_OPT_STRING, "FILE", 0, 0, iris_guiding_params, guide_out,
        "write the built guide to FILE (without -o/--png: build\n"
        "and write the guide only, render nothing)"),
    OPT("guide-in", 0, IRIS_OPT_STRING, "FILE", 0, 0, iris_guiding_params, guide_in,
        "read the guide from FILE (from --guide-out, same scene\n"
        "and settings) instead of building it"),
    OPT("dump-caches", 0, IRIS_OPT_STRING, "DIR", 0, 0, iris_guiding_params, dump_dir,
        "write pdf and photon-count PNGs of the caches that\n"
        "serve a 4x3 grid of pixels (DIR/caches.txt lists them)"),
};
const iris_option_group IRIS_GUIDING_OPTIONS = {
    "Guiding (--method auto | guided | guided-nee; docs/guiding.md; unset = from the scene)", GUIDING_ROWS,
    sizeof GUIDING_ROWS / sizeof GUIDING_ROWS[0]};

/* ---- parser ---------------------------------------------------------------- */

static bool row_taken(const iris_option_binding *b, size_t r) {
  return b->rows == 0 || ((b->rows >> r) & 1u);
}

uint64_t iris_options_rows(const iris_option_group *g, const char *names) {
  uint64_t mask = 0;
  for (size_t r = 0; r < g->count; r++) {
    size_t n = strlen(g->rows[r].name);
    for (const char *p = names; *p;) {
      const char *end = strchr(p, ',');
      size_t len = end ? (size_t)(end - p) : strlen(p);
      if (len == n && strncmp(p, g->rows[r].name, n) == 0) mask |= 1ull << r;
      p += len + (end ? 1 : 0);
    }
  }
  return mask;
}

/* "R,G,B": three finite numbers in [lo, hi]. */
static bool parse_rgb(const char *text, double lo, double hi, float out[3]) {
  const char *q = text;
  for (int i = 0; i < 3; i++) {
    char *end = NULL;
    errno = 0;
    double v = strtod(q, &end);
    if (errno || end == q || !isfinite(v) || v < lo || v > hi) return false;
    out[i] = (float)v;
    q = end;
    if (i < 2 && *q++ != ',') return false;
  }
  return *q == 0;
}

static bool set_value(const char *cmd, const iris_option *o, const char *val, void *target) {
  char flag[80];
  snprintf(flag, sizeof flag, "--%s", o->name);
  char *field = (char *)target + o->offset;
  long lv;
  double dv;
  switch (o->type) {
    case IRIS_OPT_FLAG: *(bool *)field = o->lo >= 0.0; return true; /* lo < 0: a --no-X flag */
    case IRIS_OPT_INT:
      if (!iris_cli_parse_int(cmd, flag, val, (long)o->lo, (long)o->hi, &lv)) return false;
      *(int *)field = (int)lv;
      return true;
    case IRIS_OPT_I64:
      if (!iris_cli_parse_int(cmd, flag, val, (long)o->lo, (long)o->hi, &lv)) return false;
      *(int64_t *)field = (int64_t)lv;
      return true;
    case IRIS_OPT_U64: return iris_cli_parse_u64(cmd, flag, val, (uint64_t *)field);
    case IRIS_OPT_FLOAT:
      if (!iris_cli_parse_float(cmd, flag, val, o->lo, o->hi, &dv)) return false;
      *(float *)field = (float)dv;
      return true;
    case IRIS_OPT_DOUBLE:
      if (!iris_cli_parse_float(cmd, flag, val, o->lo, o->hi, &dv)) return false;
      *(double *)field = dv;
      return true;
    case IRIS_OPT_STRING:
      if (!val[0]) {
        iris_cli_usage_error(cmd, "%s needs a non-empty value", flag);
        return false;
      }
      if (val[0] == '-' && val[1]) { /* "--env -o out.exr": the value was forgotten */
        iris_cli_usage_error(cmd, "option '%s' needs a value (got the option '%s')", flag, val);
        return false;
      }
      *(const char **)field = val;
      return true;
    case IRIS_OPT_RGB:
      if (!parse_rgb(val, o->lo, o->hi, (float *)field)) {
        iris_cli_usage_error(cmd, "invalid value '%s' for %s (three numbers R,G,B in [%g, %g])", val,
                             flag, o->lo, o->hi);
        return false;
      }
      return true;
    case IRIS_OPT_CHOICE:
    default:
      for (int i = 0; o->choices[i]; i++)
        if (strcmp(val, o->choices[i]) == 0) {
          *(int *)field = i;
          return true;
        }
      iris_cli_usage_error(cmd, "invalid value '%s' for %s (%s)", val, flag, o->arg);
      return false;
  }
}

int iris_options_parse(const char *cmd, int argc, char **argv, iris_option_binding *bindings,
                       size_t binding_count, const char **operands, int max_operands,
                       int *operand_count) {
  size_t total = 0;
  for (size_t b = 0; b < binding_count; b++) {
    bindings[b].seen = 0;
    total += bindings[b].group->count;
  }
  struct option *longopts = calloc(total + 2, sizeof *longopts);
  char shorts[3 * IRIS_OPTIONS_MAX_ROWS + 8] = ":h";
  if (!longopts) return iris_cli_usage_error(cmd, "out of memory");
  size_t k = 0, sl = 2;
  for (size_t b = 0; b < binding_count; b++)
    for (size_t r = 0; r < bindings[b].group->count; r++, k++) {
      const iris_option *o = &bindings[b].group->rows[r];
      if (!row_taken(&bindings[b], r)) { /* a name no command-line flag matches */
        longopts[k].name = "\x01";
        longopts[k].val = 256 + (int)k;
        continue;
      }
      longopts[k].name = o->name;
      longopts[k].has_arg = o->type == IRIS_OPT_FLAG ? no_argument : required_argument;
      longopts[k].val = 256 + (int)k;
      if (o->short_name && sl + 3 < sizeof shorts) { /* (rows not taken have none here) */
        shorts[sl++] = o->short_name;
        if (o->type != IRIS_OPT_FLAG) shorts[sl++] = ':';
        shorts[sl] = 0;
      }
    }
  longopts[k].name = "help";
  longopts[k].has_arg = no_argument;
  longopts[k].val = 'h';
  opterr = 0;
  optind = 1;
  int c, rc = 0;
  *operand_count = 0;
  while (rc == 0 && (c = getopt_long(argc, argv, shorts, longopts, NULL)) != -1) {
    if (c == 'h') {
      rc = -1;
      break;
    }
    size_t index = 0;
    bool found = false;
    if (c >= 256 && (size_t)(c - 256) < total) {
      index = (size_t)(c - 256);
      found = true;
    } else if (c != ':' && c != '?') { /* a short option: find its row */
      for (size_t i = 0; i < total && !found; i++) {
        size_t b = 0, r = i;
        while (r >= bindings[b].group->count) r -= bindings[b++].group->count;
        if (bindings[b].group->rows[r].short_name == c && row_taken(&bindings[b], r)) index = i, found = true;
      }
    }
    if (!found) {
      rc = iris_cli_getopt_error(cmd, c, argv);
      break;
    }
    size_t b = 0, r = index;
    while (r >= bindings[b].group->count) r -= bindings[b++].group->count;
    const iris_option *o = &bindings[b].group->rows[r];
    /* A repeated number or flag overrides (scripts append to a base command
     * line); a repeated name of a file or camera is a mistake. */
    if ((bindings[b].seen & (1ull << r)) && o->type == IRIS_OPT_STRING) {
      rc = iris_cli_usage_error(cmd, "--%s given twice", o->name);
      break;
    }
    bindings[b].seen |= 1ull << r;
    if (!set_value(cmd, o, optarg, bindings[b].target)) rc = IRIS_EXIT_USAGE;
  }
  free(longopts);
  if (rc != 0) return rc;
  for (int i = optind; i < argc; i++) {
    if (*operand_count == max_operands)
      return max_operands == 1 ? iris_cli_usage_error(cmd, "more than one input ('%s' and '%s')",
                                                      operands[0], argv[i])
                               : iris_cli_usage_error(cmd, "too many inputs (at most %d)", max_operands);
    operands[(*operand_count)++] = argv[i];
  }
  return 0;
}

size_t iris_options_getopt_rows(const iris_option_binding *b, int base, struct option *out) {
  size_t n = 0;
  for (size_t r = 0; r < b->group->count; r++) {
    if (!row_taken(b, r)) continue;
    out[n].name = b->group->rows[r].name;
    out[n].has_arg = b->group->rows[r].type == IRIS_OPT_FLAG ? no_argument : required_argument;
    out[n].flag = NULL;
    out[n].val = base + (int)r;
    n++;
  }
  return n;
}

static bool take_row(const char *cmd, iris_option_binding *b, size_t r, const char *arg, int *rc) {
  const iris_option *o = &b->group->rows[r];
  *rc = 0;
  if ((b->seen & (1ull << r)) && o->type == IRIS_OPT_STRING) {
    *rc = iris_cli_usage_error(cmd, "--%s given twice", o->name);
    return true;
  }
  b->seen |= 1ull << r;
  if (!set_value(cmd, o, arg, b->target)) *rc = IRIS_EXIT_USAGE;
  return true;
}

bool iris_options_getopt_take(const char *cmd, iris_option_binding *b, int base, int c,
                              const char *arg, int *rc) {
  if (c < base || (size_t)(c - base) >= b->group->count || !row_taken(b, (size_t)(c - base))) return false;
  return take_row(cmd, b, (size_t)(c - base), arg, rc);
}

bool iris_options_take(const char *cmd, iris_option_binding *b, const char *name, const char *val,
                       int argc, char **argv, int *i, int *rc) {
  if (strncmp(name, "--", 2) != 0) return false;
  for (size_t r = 0; r < b->group->count; r++) {
    const iris_option *o = &b->group->rows[r];
    if (!row_taken(b, r) || strcmp(name + 2, o->name) != 0) continue;
    if (o->type == IRIS_OPT_FLAG) {
      if (val) {
        *rc = iris_cli_usage_error(cmd, "option %s takes no value", name);
        return true;
      }
    } else if (!val && !iris_cli_take_value(cmd, name, argc, argv, i, &val)) {
      *rc = IRIS_EXIT_USAGE;
      return true;
    }
    return take_row(cmd, b, r, val, rc);
  }
  return false;
}

void iris_options_help(const iris_option_binding *bindings, size_t binding_count) {
  for (size_t b = 0; b < binding_count; b++) {
    const iris_option_group *g = bindings[b].group;
    if (g->title) printf("%s:\n", g->title);
    for (size_t r = 0; r < g->count; r++) {
      const iris_option *o = &g->rows[r];
      if (!row_taken(&bindings[b], r)) continue;
      char head[96];
      int n = o->short_name ? snprintf(head, sizeof head, "  -%c, --%s", o->short_name, o->name)
                            : snprintf(head, sizeof head, "      --%s", o->name);
      if (o->arg && o->type != IRIS_OPT_FLAG && n > 0 && (size_t)n < sizeof head)
        snprintf(head + n, sizeof head - (size_t)n, " %s", o->arg);
      printf("%-24s", head);
      if (strlen(head) >= 24) printf("\n%-24s", "");
      for (const char *p = o->help; *p; p++) {
        putchar(*p);
        if (*p == '\n') printf("%-24s", "");
      }
      putchar('\n');
    }
  }
}

bool iris_options_seen(const iris_option_binding *b, const char *name) {
  for (size_t r = 0; r < b->group->count; r++)
    if (strcmp(b->group->rows[r].name, name) == 0) return (b->seen >> r) & 1u;
  return false;
}

/* ---- environment ----------------------------------------------------------- */

int iris_env_options_check(const char *cmd, const iris_option_binding *b, bool check_map) {
  if (b->group != &IRIS_ENV_OPTIONS) __builtin_trap(); /* a binding of another group: a bug */
  const iris_env_options *e = (const iris_env_options *)b->target;
  bool color = iris_options_seen(b, "env-color");
  if (color && e->map) return iris_cli_usage_error(cmd, "--env and --env-color exclude each other");
  if (!e->map && (iris_options_seen(b, "env-strength") || iris_options_seen(b, "env-rotation")))
    return iris_cli_usage_error(cmd, "--env-strength and --env-rotation need --env FILE");
  if (e->map && check_map) {
    iris_error err;
    iris_error_clear(&err);
    if (iris_envmap_check(e->map, &err) != IRIS_OK) return iris_cli_report(&err);
  }
  return IRIS_EXIT_OK;
}

int iris_env_options_apply(const char *cmd, const iris_option_binding *b, iris_scene *scene) {
  if (b->group != &IRIS_ENV_OPTIONS) __builtin_trap(); /* a binding of another group: a bug */
  const iris_env_options *e = (const iris_env_options *)b->target;
  if (e->map) {
    /* absolute, so that a scene written elsewhere still finds it */
    char *abs = realpath(e->map, NULL);
    bool ok = iris_scene_set_environment_map(scene, abs ? abs : e->map, e->strength, e->rotation);
    free(abs);
    if (!ok) return iris_cli_usage_error(cmd, "out of memory");
  } else if (iris_options_seen(b, "env-color")) {
    iris_scene_set_environment_color(scene, e->color);
  }
  return IRIS_EXIT_OK;
}

void iris_warn_if_lightless(const iris_scene *scene, const char *what) {
  iris_scene_warn_if_lightless(scene, what);
}
