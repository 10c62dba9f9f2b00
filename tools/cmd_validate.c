/* `iris validate INPUT --out DIR`: renders INPUT with iris and compares it with
 * Cycles (a stored or given reference EXR, or Blender run here), and
 * `iris validate --refresh` regenerates the stored references. The library
 * does the work (validate/validate.h); docs/cli.md ("validate") lists the flags. */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "core/log.h"
#include "validate/validate.h"
#include "tools/cli.h"
#include "tools/options.h"

static const char *const CMD = "validate";

static void print_help(void) {
  printf(
      "Usage: iris validate INPUT --out DIR [--reference REF.exr | --blender | --blender-import[=FILE]] [options]\n"
      "       iris validate --refresh [SCENE...] [--blender-spp N] [--threads T] [--seed S]\n"
      "\n"
      "Renders INPUT (an iris scene .json, an OBJ/PLY/glTF file, or a built-in scene:\n"
      "cornell-box, veach-mis, door, ...) with iris and compares it with Blender Cycles:\n"
      "per-channel mean energy, energy per 8x8 block, relMSE, MAPE, block and per-pixel\n"
      "z-tests using iris's variance, NaN/Inf counts. Writes DIR/report.html,\n"
      "DIR/summary.json, DIR/<method>.exr and PNGs.\n"
      "\n"
      "Reference (one of; default for cornell-box, veach-mis and door: the stored one):\n"
      "      --reference REF.exr   a Cycles (or other) EXR; iris renders at its size\n"
      "      --blender             export the scene, run Blender here (--blender-spp)\n"
      "      --blender-import[=FILE]  run Blender here on FILE (default: INPUT, a .gltf/.glb)\n"
      "                            imported by Blender's own glTF importer, under iris's\n"
      "                            camera and world; reports where the importers disagree\n"
      "      --blender-spp N       Cycles samples per pixel (default %d; --refresh: per scene)\n"
      "Rendering:\n"
      "      --method M            auto | bsdf | nee | mis | guided | guided-nee; repeat or\n"
      "                            give a comma list to validate several (default: the\n"
      "                            scene's, else auto: guided-nee or mis per scene)\n"
      "      --spp N               iris samples per pixel (default %d)\n"
      "      --seed N              seed of iris and Cycles (default 0)\n"
      "      --threads N           threads of iris and Cycles (default: all cores)\n"
      "      --width W --height H  image size (must match a given reference)\n"
      "      --max-depth B         bounces as Cycles counts them (default: scene's, else 64)\n"
      "      --camera NAME         scene camera to use\n"
      "      --variant NAME        a glTF INPUT's material variant (KHR_materials_variants;\n"
      "                            --blender-import makes Blender show it too)\n"
      "Environment (replaces the scene's world; docs/format.md):\n"
      "      --env FILE, --env-strength S, --env-rotation DEG, --env-color R,G,B\n"
      "                            as `iris render` (iris render --help)\n"
      "Checks:\n"
      "      --tolerance T         allowed relative mean-energy difference (default 0.01)\n"
      "      --alpha A             family-wise significance of the z-tests (default 0.01)\n"
      "      --strict-pixels       fail on the per-pixel z-test too (default: reported; the\n"
      "                            8x8 block z-test always decides)\n"
      "Refresh:\n"
      "      --refresh             regenerate validate/references/<scene>.exr + .json with\n"
      "                            Blender (all reference scenes, or the ones named)\n"
      "      --references DIR      where stored references live (default: the source tree's\n"
      "                            validate/references)\n"
      "Other:\n"
      "      --out DIR             output folder (created if missing)\n"
      "      --blender-exe FILE    Blender executable (default $IRIS_BLENDER, else blender)\n"
      "  -q, --quiet               no progress messages\n"
      "  -h, --help                show this help\n"
      "\n"
      "Exit status: 0 all methods pass, 1 a check failed (energy beyond the tolerance, a\n"
      "z-test, NaN/Inf in iris's image) or Blender failed, 2 bad usage or bad input:\n"
      "missing/unreadable/non-finite reference, different image sizes.\n",
      IRIS_VALIDATE_DEFAULT_BLENDER_SPP, IRIS_VALIDATE_DEFAULT_SPP);
}


static const char *default_references_dir(void) {
#ifdef IRIS_SOURCE_DIR
  return IRIS_SOURCE_DIR "/validate/references";
#else
  return "validate/references";
#endif
}

static bool add_methods(iris_validate_params *p, const char *list) {
  char buf[256];
  snprintf(buf, sizeof buf, "%s", list);
  for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
    iris_method m;
    if (!iris_method_parse(tok, &m)) {
      iris_cli_usage_error(CMD, "unknown method '%s' (auto, bsdf, nee, mis, guided, guided-nee)", tok);
      return false;
    }
    for (int i = 0; i < p->method_count; i++)
      if (p->methods[i] == m) {
        iris_cli_usage_error(CMD, "method '%s' given twice", tok);
        return false;
      }
    p->methods[p->method_count++] = m;
  }
  return true;
}

static bool is_reference_scene(const char *name) {
  for (const char *const *s = iris_validate_reference_scenes(); *s; s++)
    if (strcmp(*s, name) == 0) return true;
  return false;
}

int iris_cmd_validate(int argc, char **argv) {
  enum {
    OPT_METHOD = 256, OPT_SPP, OPT_REFERENCE, OPT_BLENDER, OPT_TOLERANCE, OPT_BLENDER_SPP,
    OPT_THREADS, OPT_SEED, OPT_WIDTH, OPT_HEIGHT, OPT_OUT, OPT_REFRESH, OPT_REFERENCES,
    OPT_DEPTH, OPT_CAMERA, OPT_ALPHA, OPT_BLENDER_EXE, OPT_STRICT, OPT_BLENDER_IMPORT, OPT_ENV = 512,
    OPT_RENDER = 640, OPT_GLTF = 768
  };
  static const struct option own_opts[] = {
      {"method", required_argument, NULL, OPT_METHOD},
      {"reference", required_argument, NULL, OPT_REFERENCE},
      {"blender", no_argument, NULL, OPT_BLENDER},
      {"blender-import", optional_argument, NULL, OPT_BLENDER_IMPORT},
      {"tolerance", required_argument, NULL, OPT_TOLERANCE},
      {"blender-spp", required_argument, NULL, OPT_BLENDER_SPP},
      {"out", required_argument, NULL, OPT_OUT},
      {"refresh", no_argument, NULL, OPT_REFRESH},
      {"references", required_argument, NULL, OPT_REFERENCES},
      {"alpha", required_argument, NULL, OPT_ALPHA},
      {"blender-exe", required_argument, NULL, OPT_BLENDER_EXE},
      {"strict-pixels", no_argument, NULL, OPT_STRICT},
      {"quiet", no_argument, NULL, 'q'},
      {"help", no_argument, NULL, 'h'}};
  /* the shared sampling/camera and environment rows (tools/options.h) after validate's own */
  iris_env_options eo = iris_env_options_default();
  iris_option_binding envb = {&IRIS_ENV_OPTIONS, &eo, 0, 0};
  iris_render_options ro;
  memset(&ro, 0, sizeof ro);
  ro.light_sampler = IRIS_LIGHT_SAMPLER_DEFAULT;
  iris_option_binding rb = {&IRIS_RENDER_OPTIONS, &ro, 0,
                            iris_options_rows(&IRIS_RENDER_OPTIONS,
                                             "spp,seed,threads,width,height,max-depth,camera,sampler,light-sampler")};
  iris_gltf_input_options go = {NULL};
  iris_option_binding gb = {&IRIS_GLTF_INPUT_OPTIONS, &go, 0, 0};
  struct option longopts[sizeof own_opts / sizeof own_opts[0] + 3 * IRIS_OPTIONS_MAX_ROWS + 1];
  memset(longopts, 0, sizeof longopts);
  memcpy(longopts, own_opts, sizeof own_opts);
  size_t nl = sizeof own_opts / sizeof own_opts[0];
  nl += iris_options_getopt_rows(&rb, OPT_RENDER, longopts + nl);
  nl += iris_options_getopt_rows(&envb, OPT_ENV, longopts + nl);
  iris_options_getopt_rows(&gb, OPT_GLTF, longopts + nl);
  int erc = 0;
  iris_validate_params p = iris_validate_params_default();
  bool blender = false, refresh = false, have_blender_spp = false, blender_import = false;
  bool have_tolerance = false;
  const char *references = NULL;
  long v;
  double d;
  opterr = 0;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, ":qh", longopts, NULL)) != -1) {
    switch (c) {
      case OPT_METHOD:
        if (!add_methods(&p, optarg)) return IRIS_EXIT_USAGE;
        break;
      case OPT_REFERENCE:
        if (!iris_cli_set_once(CMD, "--reference", &p.reference_path, optarg)) return IRIS_EXIT_USAGE;
        break;
      case OPT_BLENDER: blender = true; break;
      case OPT_BLENDER_IMPORT:
        blender_import = true;
        p.blender_import = optarg; /* NULL: the input itself */
        break;
      case OPT_TOLERANCE:
        if (!iris_cli_parse_float(CMD, "--tolerance", optarg, 0.0, 10.0, &d)) return IRIS_EXIT_USAGE;
        p.tolerance = d;
        have_tolerance = true;
        break;
      case OPT_ALPHA:
        if (!iris_cli_parse_float(CMD, "--alpha", optarg, 1e-12, 0.5, &d)) return IRIS_EXIT_USAGE;
        p.alpha = d;
        break;
      case OPT_BLENDER_SPP:
        if (!iris_cli_parse_int(CMD, "--blender-spp", optarg, 1, 1 << 20, &v)) return IRIS_EXIT_USAGE;
        p.blender_spp = (int)v;
        have_blender_spp = true;
        break;
      case OPT_OUT:
        if (!iris_cli_set_once(CMD, "--out", &p.out_dir, optarg)) return IRIS_EXIT_USAGE;
        break;
      case OPT_REFRESH: refresh = true; break;
      case OPT_REFERENCES: references = optarg; break;
      case OPT_BLENDER_EXE: p.blender = optarg; break;
      case OPT_STRICT: p.pixel_test_gates = true; break;
      case 'q': p.quiet = true; break;
      case 'h': print_help(); return IRIS_EXIT_OK;
      default:
        if (iris_options_getopt_take(CMD, &envb, OPT_ENV, c, optarg, &erc) ||
            iris_options_getopt_take(CMD, &rb, OPT_RENDER, c, optarg, &erc) ||
            iris_options_getopt_take(CMD, &gb, OPT_GLTF, c, optarg, &erc)) {
          if (erc) return erc;
          break;
        }
        return iris_cli_getopt_error(CMD, c, argv);
    }
  }
  if (p.quiet) iris_log_set_level(IRIS_LOG_QUIET);
  if (iris_options_seen(&rb, "spp")) p.spp = ro.spp;
  p.sampler = (iris_sampler_kind)ro.sampler; /* 0 (sobol) unless given */
  p.light_sampler = (iris_light_sampler)ro.light_sampler;
  p.connect = ro.connect;
  p.light_trace = ro.light_trace;
  if (iris_options_seen(&rb, "threads")) p.threads = ro.threads;
  if (iris_options_seen(&rb, "width")) p.width = ro.width;
  if (iris_options_seen(&rb, "height")) p.height = ro.height;
  if (iris_options_seen(&rb, "camera")) p.camera_name = ro.camera;
  p.variant = go.variant;
  /* Cycles' seed is a non-negative 32-bit int (both renderers get the same);
   * Cycles' bounce counts stop at 1024 */
  if (iris_options_seen(&rb, "seed")) {
    if (ro.seed > 2147483647u)
      return iris_cli_usage_error(CMD, "invalid value '%llu' for --seed (a number in [0, 2147483647])",
                                  (unsigned long long)ro.seed);
    p.seed = ro.seed;
  }
  if (iris_options_seen(&rb, "max-depth")) {
    if (ro.max_depth > 1024)
      return iris_cli_usage_error(CMD, "invalid value '%d' for --max-depth (a number in [0, 1024])", ro.max_depth);
    p.max_depth = ro.max_depth;
  }
  if ((erc = iris_env_options_check(CMD, &envb, true)) != IRIS_EXIT_OK) return erc;
  p.world.map = eo.map;
  p.world.strength = eo.strength;
  p.world.rotation = eo.rotation;
  p.world.color = iris_options_seen(&envb, "env-color") ? eo.color : NULL;
  if (!references) references = default_references_dir();

  iris_error err;
  iris_error_clear(&err);
  if (refresh) {
    /* Everything checked before the (long) Blender runs. */
    if (p.reference_path || blender || blender_import || p.out_dir || p.method_count || p.width > 0 || p.height > 0 ||
        p.variant)
      return iris_cli_usage_error(CMD, "--refresh takes only scene names, --blender-spp, --threads, "
                                       "--seed, --references and --blender-exe");
    for (int i = optind; i < argc; i++)
      if (!is_reference_scene(argv[i]))
        return iris_cli_usage_error(CMD, "'%s' has no stored reference (cornell-box, veach-mis, door)", argv[i]);
    const char *const *all = iris_validate_reference_scenes();
    int count = argc - optind;
    for (int i = 0; count == 0 ? all[i] != NULL : i < count; i++) {
      iris_refresh_params rp = {count ? argv[optind + i] : all[i], references,
                                have_blender_spp ? p.blender_spp : 0, p.seed, p.threads, p.blender,
                                p.quiet};
      if (iris_validate_refresh(&rp, &err) != IRIS_OK) return iris_cli_report(&err);
    }
    return IRIS_EXIT_OK;
  }

  if (argc - optind == 0) return iris_cli_usage_error(CMD, "no input");
  if (argc - optind > 1)
    return iris_cli_usage_error(CMD, "one input only (got '%s' and '%s')", argv[optind], argv[optind + 1]);
  p.input = argv[optind];
  if (!p.out_dir) return iris_cli_usage_error(CMD, "missing --out DIR");
  if (blender_import) {
    if (p.reference_path) return iris_cli_usage_error(CMD, "--reference and --blender-import exclude each other");
    if (!p.blender_import) p.blender_import = p.input;
    char ext[16];
    iris_path_ext(p.blender_import, ext, sizeof ext);
    if (strcmp(ext, "gltf") != 0 && strcmp(ext, "glb") != 0)
      return iris_cli_usage_error(CMD, "--blender-import needs a .gltf or .glb file (got '%s')", p.blender_import);
    if (!iris_path_exists(p.blender_import))
      return iris_cli_usage_error(CMD, "--blender-import: '%s' does not exist", p.blender_import);
    blender = true;
    if (!have_tolerance) p.tolerance = IRIS_VALIDATE_IMPORT_TOLERANCE;
  }
  if (blender && p.reference_path) return iris_cli_usage_error(CMD, "--reference and --blender exclude each other");
  if (have_blender_spp && !blender) return iris_cli_usage_error(CMD, "--blender-spp needs --blender (or --refresh)");
  if ((p.width > 0) != (p.height > 0)) return iris_cli_usage_error(CMD, "give both --width and --height");
  char stored[1200];
  if (blender) {
    p.source = IRIS_REFERENCE_BLENDER;
  } else {
    p.source = IRIS_REFERENCE_FILE;
    if (!p.reference_path) {
      if (!is_reference_scene(p.input) || iris_path_exists(p.input))
        return iris_cli_usage_error(CMD, "'%s' has no stored reference: give --reference REF.exr or --blender", p.input);
      snprintf(stored, sizeof stored, "%s/%s.exr", references, p.input);
      p.reference_path = stored;
    }
  }

  iris_cli_catch_signals(); /* a second signal stops at once */
  p.cancel = iris_cli_stop_flag();
  iris_validate_result res;
  iris_status st = iris_validate_run(&p, &res, &err);
  iris_cli_release_signals();
  if (st == IRIS_ERR_INTERRUPTED) return iris_cli_interrupt_exit();
  if (st != IRIS_OK) {
    /* A reference that cannot be read or used is bad input (2); Blender
     * failing is a failure of the run (1). */
    return iris_cli_report(&err);
  }
  if (!p.quiet) {
    for (int k = 0; k < res.method_count; k++) {
      const iris_validate_method *m = &res.methods[k];
      iris_infof("validate: %s %s: energy ratio %.5f (R %.5f G %.5f B %.5f, +-%.5f) %s, max block dev %+.2f%%, "
                 "block z %.2f/%.2f, pixel z %.2f/%.2f, |z|>3 %llu/%.0f allowed, z-test %s, relMSE %.4g -> %s",
                 res.scene, iris_method_name(m->method), m->energy_ratio, m->channel_ratio[0],
                 m->channel_ratio[1], m->channel_ratio[2], m->ratio_se[1], m->energy_passed ? "ok" : "OFF",
                 100.0 * m->blocks.signed_max_rel_dev, m->blocks.max_abs_z, m->blocks.z_crit,
                 m->pixels.max_abs_z, m->pixels.z_crit, (unsigned long long)m->pixels.over_count,
                 m->pixels.allowed_over, m->z_passed ? "ok" : "FAILED", m->relmse,
                 m->passed ? "pass" : "FAIL");
      double se = fmax(m->ratio_se[0], fmax(m->ratio_se[1], m->ratio_se[2]));
      if (se > p.tolerance / 3.0)
        iris_warnf("validate: %s: the energy ratio's standard error (%.2f%%) is not small against "
                   "the tolerance (%.2f%%): the energy check is dominated by noise; raise --spp",
                   iris_method_name(m->method), 100.0 * se, 100.0 * p.tolerance);
    }
    if (p.source == IRIS_REFERENCE_BLENDER && !res.blender_import)
      iris_infof("validate: materials: %s", res.export_note);
    if (res.blender_import) {
      const iris_import_diff *d = &res.import_diff;
      iris_infof("validate: iris's glTF import vs Blender's of %s: %d note(s)%s (%s/importers.txt)",
                 res.import_file, d->total, d->geometry_differs ? ", the GEOMETRY DIFFERS" : "", p.out_dir);
      for (int i = 0; i < d->note_count; i++) iris_infof("  %s: %s", d->notes[i].topic, d->notes[i].text);
    }
    iris_infof("validate: report in %s/report.html", p.out_dir);
  }
  return res.passed ? IRIS_EXIT_OK : IRIS_EXIT_FAILURE;
}
