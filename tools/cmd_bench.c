/* `iris bench INPUT... --methods LIST --times LIST --reference REF.exr|auto
 * --out DIR`: fills iris_bench_params from the flags and runs validate/bench.h.
 * docs/cli.md ("bench") and docs/benchmarks.md. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "core/log.h"
#include "renderer/integrator.h"
#include "tools/cli.h"
#include "tools/options.h"
#include "validate/bench.h"

static const char *CMD = "bench";

static void print_help(void) {
  printf(
      "Usage: iris bench INPUT... [--methods LIST] --times LIST --reference REF.exr|auto\n"
      "                  --out DIR [options]\n"
      "\n"
      "Speed against accuracy: renders every INPUT (iris scene, OBJ/PLY/glTF file or\n"
      "built-in scene: cornell-box, veach-mis, door, ...) with every method for every\n"
      "wall-clock time budget (setup included) and seed, and measures relMSE (eps 0.01,\n"
      "top 0.1%% of pixels dropped), MAPE and the mean-energy ratio against a reference.\n"
      "\n"
      "Runs:\n"
      "      --methods LIST   comma-separated: auto,bsdf,nee,mis,guided,guided-nee (default\n"
      "                       auto: guided-nee or mis per scene); a method may\n"
      "                       name its variant: mis@independent, mis@area,\n"
      "                       mis@independent+area, mis@power (sampler, emitter\n"
      "                       triangles, light sampler power|tree), mis@adaptive\n"
      "                       (adaptive sampling, samples where they lower relMSE\n"
      "                       most: what iris render --time does by default; a plain\n"
      "                       name gives every pixel the same samples), mis@freeze\n"
      "                       (Cycles' rule at its threshold 0.01)\n"
      "      --times LIST     comma-separated budgets in seconds, e.g. 1,2,4,8,16\n"
      "      --seeds N        seeds 0..N-1 per budget (default 1)\n"
      "      --threads N      worker threads (default: all cores)\n"
      "                       (--sampler, --light-sampling and --light-sampler\n"
      "                       below: what a plain name uses; the auto reference\n"
      "                       is always independent)\n"
      "      --width W, --height H   image size (default: the reference's, else the\n"
      "                       scene's; one of them: the other keeps the scene's aspect)\n"
      "      --max-depth B    bounces as Cycles counts them (default: the scene's, else 64)\n"
      "Reference:\n"
      "      --reference FILE|auto   an EXR per INPUT (repeat the flag, in input order),\n"
      "                       or auto: an iris mis render of --reference-spp samples,\n"
      "                       rendered once and cached\n"
      "      --reference-spp N   samples of the auto reference (default %d)\n"
      "      --cache DIR      cache of auto references (default ~/.cache/iris/bench)\n"
      "Cycles:\n"
      "      --cycles         also render with Blender Cycles at the spp of each budget's\n"
      "                       mis run (seed s); its render time excludes start-up\n"
      "      --cycles-adaptive   also render with Cycles as Blender users run it:\n"
      "                       adaptive sampling on, each budget its time limit\n"
      "      --cycles-threshold T   Cycles' noise threshold (default 0.01, Blender's)\n"
      "      --blender EXE    Blender executable (default $IRIS_BLENDER, else blender)\n"
      "Output:\n"
      "  -o, --out DIR        results.csv, results.json, table.md, table.html, images/,\n"
      "                       charts/ (PNG and SVG)\n"
      "      --target-relmse X   target of the time-to-target column (default: per\n"
      "                       scene, the geometric mean of mis's first and last relMSE)\n"
      "      --no-charts      do not run the chart script\n"
      "      --plot-script F  chart script (default $IRIS_BENCH_PLOT, else the source\n"
      "                       tree's bench/charts/plot_bench.py); run with $IRIS_PYTHON,\n"
      "                       else /usr/bin/python3 (matplotlib)\n"
      "      --quiet          no progress bar or messages\n"
      "\n"
      "Exit status: 0 done, 2 bad usage or input, 1 other failure, 130 interrupted\n"
      "(the rows done so far are written).\n",
      IRIS_BENCH_DEFAULT_REFERENCE_SPP);
}

static void draw_progress(void *ctx, const iris_bench_progress *p) {
  (void)ctx;
  int bar = (int)(p->run_fraction * 20.0 + 0.5);
  char b[21];
  for (int i = 0; i < 20; i++) b[i] = i < bar ? '#' : '.';
  b[20] = 0;
  char what[96];
  if (p->budget > 0)
    snprintf(what, sizeof what, "%s %s %gs seed %llu", p->scene, p->what, p->budget,
             (unsigned long long)p->seed);
  else
    snprintf(what, sizeof what, "%s %s", p->scene, p->what);
  int eta = (int)(p->eta + 0.5);
  fprintf(stderr, "\r\033[K[%s] run %d/%d  %-44.44s %5d spp  left ~%dm%02ds", b, p->run, p->runs,
          what, p->spp_done, eta / 60, eta % 60);
  fflush(stderr);
}

/* Splits a comma-separated list in place; returns the count or -1 when over max. */
static int split_list(char *text, char **items, int max) {
  int n = 0;
  for (char *tok = strtok(text, ","); tok; tok = strtok(NULL, ",")) {
    if (n == max) return -1;
    items[n++] = tok;
  }
  return n;
}

int iris_cmd_bench(int argc, char **argv) {
  iris_bench_params p = iris_bench_params_default();
  const char *inputs[IRIS_BENCH_MAX_SCENES + 1];
  const char *refs[IRIS_BENCH_MAX_SCENES + 1];
  int input_count = 0, ref_count = 0;
  bool ref_auto = false, quiet = false, no_charts = false;
  const char *plot_script = NULL;
  char methods_buf[256] = "", times_buf[512] = "";
  iris_env_options eo = iris_env_options_default();
  iris_option_binding envb = {&IRIS_ENV_OPTIONS, &eo, 0, 0};
  /* the shared rows bench takes (tools/options.h); its own flags are below */
  iris_render_options ro;
  memset(&ro, 0, sizeof ro);
  ro.light_sampler = IRIS_LIGHT_SAMPLER_DEFAULT;
  iris_option_binding rb = {&IRIS_RENDER_OPTIONS, &ro, 0,
                            iris_options_rows(&IRIS_RENDER_OPTIONS,
                                             "threads,width,height,max-depth,sampler,light-sampling,light-sampler")};
  iris_gltf_input_options go = {NULL};
  iris_option_binding gb = {&IRIS_GLTF_INPUT_OPTIONS, &go, 0, 0};
  for (int i = 1; i < argc; i++) {
    char name[64];
    const char *val;
    const char *a = iris_cli_split_option(argv[i], name, sizeof name, &val);
#define NEED_VALUE()                                                                           \
  do {                                                                                         \
    if (!iris_cli_take_value(CMD, a, argc, argv, &i, &val)) return IRIS_EXIT_USAGE;            \
  } while (0)
#define NO_VALUE()                                                                        \
  do {                                                                                    \
    if (val) return iris_cli_usage_error(CMD, "option %s takes no value", a);              \
  } while (0)
    long lv;
    double dv;
    int erc = 0;
    if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
      print_help();
      printf("\n");
      iris_option_binding shared[3] = {rb, envb, gb};
      iris_options_help(shared, 3);
      return IRIS_EXIT_OK;
    } else if (iris_options_take(CMD, &envb, a, val, argc, argv, &i, &erc) ||
               iris_options_take(CMD, &gb, a, val, argc, argv, &i, &erc)) {
      if (erc) return erc;
    } else if (strcmp(a, "--methods") == 0) {
      NEED_VALUE();
      snprintf(methods_buf, sizeof methods_buf, "%s", val);
    } else if (strcmp(a, "--times") == 0) {
      NEED_VALUE();
      snprintf(times_buf, sizeof times_buf, "%s", val);
    } else if (strcmp(a, "--seeds") == 0) {
      NEED_VALUE();
      if (!iris_cli_parse_int(CMD, a, val, 1, IRIS_BENCH_MAX_SEEDS, &lv)) return IRIS_EXIT_USAGE;
      p.seeds = (int)lv;
    } else if (iris_options_take(CMD, &rb, a, val, argc, argv, &i, &erc)) {
      if (erc) return erc;
    } else if (strcmp(a, "--reference") == 0) {
      NEED_VALUE();
      if (strcmp(val, "auto") == 0)
        ref_auto = true;
      else if (ref_count == IRIS_BENCH_MAX_SCENES)
        return iris_cli_usage_error(CMD, "too many --reference files");
      else
        refs[ref_count++] = val;
    } else if (strcmp(a, "--reference-spp") == 0) {
      NEED_VALUE();
      if (!iris_cli_parse_int(CMD, a, val, 1, 1 << 24, &lv)) return IRIS_EXIT_USAGE;
      p.reference_spp = (int)lv;
    } else if (strcmp(a, "--cache") == 0) {
      NEED_VALUE();
      p.cache_dir = val;
    } else if (strcmp(a, "--cycles") == 0) {
      NO_VALUE();
      p.cycles = true;
    } else if (strcmp(a, "--cycles-adaptive") == 0) {
      NO_VALUE();
      p.cycles_adaptive = true;
    } else if (strcmp(a, "--cycles-threshold") == 0) {
      NEED_VALUE();
      if (!iris_cli_parse_float(CMD, a, val, 1e-6, 0.999, &dv)) return IRIS_EXIT_USAGE;
      p.cycles_threshold = dv;
    } else if (strcmp(a, "--blender") == 0) {
      NEED_VALUE();
      p.blender = val;
    } else if (strcmp(a, "-o") == 0 || strcmp(a, "--out") == 0) {
      NEED_VALUE();
      p.out_dir = val;
    } else if (strcmp(a, "--target-relmse") == 0) {
      NEED_VALUE();
      if (!iris_cli_parse_float(CMD, a, val, 1e-12, 1e12, &dv)) return IRIS_EXIT_USAGE;
      p.target_relmse = dv;
    } else if (strcmp(a, "--no-charts") == 0) {
      NO_VALUE();
      no_charts = true;
    } else if (strcmp(a, "--plot-script") == 0) {
      NEED_VALUE();
      plot_script = val;
    } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
      NO_VALUE();
      quiet = true;
    } else if (a[0] == '-' && a[1] != 0) {
      return iris_cli_usage_error(CMD, "unknown option '%s'", argv[i]);
    } else {
      if (input_count == IRIS_BENCH_MAX_SCENES)
        return iris_cli_usage_error(CMD, "at most %d inputs", IRIS_BENCH_MAX_SCENES);
      inputs[input_count++] = a;
    }
#undef NEED_VALUE
#undef NO_VALUE
  }
  /* Everything that can be checked is checked before any work starts. */
  if (input_count == 0) return iris_cli_usage_error(CMD, "no input scene given");
  p.variant = go.variant;
  if (iris_options_seen(&rb, "threads")) p.threads = ro.threads;
  /* what a method named without @variant uses */
  iris_sampler_kind sampler = (iris_sampler_kind)ro.sampler;
  iris_triangle_sampling light_sampling = (iris_triangle_sampling)ro.light_sampling;
  iris_light_sampler light_sampler = (iris_light_sampler)ro.light_sampler;
  p.connect = ro.connect;
  p.light_trace = ro.light_trace;
  if (iris_options_seen(&rb, "max-depth")) p.max_depth = ro.max_depth;
  if (iris_options_seen(&rb, "width")) p.width = ro.width;
  if (iris_options_seen(&rb, "height")) p.height = ro.height;
  if (p.width > 16384 || p.height > 16384)
    return iris_cli_usage_error(CMD, "invalid value '%d' for --%s (a number in [1, 16384])",
                                p.width > 16384 ? p.width : p.height, p.width > 16384 ? "width" : "height");
  int erc = iris_env_options_check(CMD, &envb, true);
  if (erc != IRIS_EXIT_OK) return erc;
  p.world.map = eo.map;
  p.world.strength = eo.strength;
  p.world.rotation = eo.rotation;
  p.world.color = iris_options_seen(&envb, "env-color") ? eo.color : NULL;
  if (!methods_buf[0]) snprintf(methods_buf, sizeof methods_buf, "auto"); /* docs/guiding.md, "--method auto" */
  if (!times_buf[0]) return iris_cli_usage_error(CMD, "no --times given (e.g. 1,2,4)");
  if (!p.out_dir) return iris_cli_usage_error(CMD, "no output folder: give --out DIR");
  if (!ref_auto && ref_count == 0)
    return iris_cli_usage_error(CMD, "no --reference given (an EXR per input, or auto)");
  if (ref_auto && ref_count > 0)
    return iris_cli_usage_error(CMD, "--reference auto and reference files exclude each other");
  if (ref_count > 0 && ref_count != input_count)
    return iris_cli_usage_error(CMD, "%d reference file(s) for %d input(s): give one per input",
                                ref_count, input_count);
  {
    char *items[IRIS_BENCH_MAX_METHODS + 1];
    int n = split_list(methods_buf, items, IRIS_BENCH_MAX_METHODS);
    if (n < 0) return iris_cli_usage_error(CMD, "at most %d --methods", IRIS_BENCH_MAX_METHODS);
    if (n == 0) return iris_cli_usage_error(CMD, "invalid --methods '%s'", methods_buf);
    for (int k = 0; k < n; k++) {
      iris_method m;
      iris_sampler_kind smp;
      iris_triangle_sampling ls;
      iris_light_sampler lsr;
      if (!iris_bench_method_parse(items[k], &m, &smp, &lsr, &ls))
        return iris_cli_usage_error(CMD, "unknown method '%s' (auto, bsdf, nee, mis, guided, guided-nee, "
                                         "optionally @ and + joined independent, area, power, tree, adaptive, freeze)", items[k]);
      /* --sampler and --light-sampling set what a plain name means */
      if (!strchr(items[k], '@')) {
        smp = sampler;
        ls = light_sampling;
        lsr = light_sampler;
      }
      p.methods[p.method_count] = m;
      p.samplers[p.method_count] = smp;
      p.light_samplings[p.method_count] = ls;
      p.keep_training[p.method_count] = iris_bench_method_keeps_training(items[k]);
      p.light_samplers[p.method_count] = lsr;
      p.adaptive[p.method_count] = iris_bench_method_adaptive(items[k]);
      char a[64], b[64];
      iris_bench_method_label(&p, p.method_count, a, sizeof a);
      for (int j = 0; j < p.method_count; j++)
        if (strcmp(iris_bench_method_label(&p, j, b, sizeof b), a) == 0)
          return iris_cli_usage_error(CMD, "method '%s' is given twice", a);
      p.method_count++;
    }
  }
  {
    char copy[512];
    snprintf(copy, sizeof copy, "%s", times_buf);
    char *items[IRIS_BENCH_MAX_TIMES + 1];
    int n = split_list(copy, items, IRIS_BENCH_MAX_TIMES);
    if (n < 0) return iris_cli_usage_error(CMD, "at most %d time budgets", IRIS_BENCH_MAX_TIMES);
    if (n == 0) return iris_cli_usage_error(CMD, "invalid --times '%s'", times_buf);
    for (int t = 0; t < n; t++) {
      double dv;
      if (!iris_cli_parse_float(CMD, "--times", items[t], 1e-3, 1e6, &dv)) return IRIS_EXIT_USAGE;
      for (int j = 0; j < p.time_count; j++)
        if (p.times[j] == dv) return iris_cli_usage_error(CMD, "time budget %s is given twice", items[t]);
      p.times[p.time_count++] = dv;
    }
  }
  inputs[input_count] = NULL;
  p.inputs = inputs;
  p.input_count = input_count;
  p.references = ref_count > 0 ? refs : NULL;
  if (!no_charts) {
    const char *env = getenv("IRIS_BENCH_PLOT");
    p.plot_script = plot_script ? plot_script
                    : env && env[0] ? env
#ifdef IRIS_SOURCE_DIR
                                    : IRIS_SOURCE_DIR "/bench/charts/plot_bench.py";
#else
                                    : NULL;
#endif
    if (p.plot_script && !iris_path_exists(p.plot_script))
      return iris_cli_usage_error(CMD, "chart script '%s' does not exist (--plot-script, or --no-charts)",
                                  p.plot_script);
    const char *py = getenv("IRIS_PYTHON");
    p.python = py && py[0] ? py : "/usr/bin/python3";
  }
  if (quiet) iris_log_set_level(IRIS_LOG_QUIET);
  p.quiet = quiet;
  bool bar = !quiet && iris_log_progress_enabled();
  if (bar) {
    p.progress = draw_progress;
    /* the progress line says what runs; per-run messages (e.g. the guide's
     * statistics) would break it */
    iris_log_set_level(IRIS_LOG_WARN);
  }
  iris_cli_catch_signals(); /* a second signal stops at once */
  p.cancel = iris_cli_stop_flag();
  iris_error err;
  iris_error_clear(&err);
  iris_bench_result res;
  iris_status st = iris_bench_run(&p, &res, &err);
  iris_cli_release_signals();
  if (bar) fprintf(stderr, "\n");
  if (st == IRIS_ERR_INTERRUPTED) {
    iris_warnf("bench: interrupted; %zu run(s) written to %s", res.row_count, p.out_dir);
    iris_bench_result_destroy(&res);
    return iris_cli_interrupt_exit();
  }
  if (st != IRIS_OK) {
    iris_bench_result_destroy(&res);
    return iris_cli_report(&err);
  }
  if (!quiet) {
    char table[1300];
    iris_path_join(p.out_dir, "table.md", table, sizeof table);
    iris_infof("bench: %zu runs; results in %s (results.csv, table.md%s)", res.row_count, p.out_dir,
               res.charts ? ", charts/" : "");
    char *text = NULL;
    size_t size = 0;
    if (iris_file_read(table, 1u << 20, &text, &size, NULL) == IRIS_OK) {
      fputs(text, stdout);
      free(text);
    }
  }
  iris_bench_result_destroy(&res);
  return IRIS_EXIT_OK;
}
