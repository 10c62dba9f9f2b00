/* `iris export INPUT --to blender|pov -o OUT`: loads an iris scene, an
 * importable file or a built-in scene and writes it as a Blender 3.4 Python
 * script or a POV-Ray 3.7 scene (docs/export.md). */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "core/log.h"
#include "exporters/blender.h"
#include "exporters/pov.h"
#include "importers/import.h"
#include "tools/cli.h"
#include "tools/options.h"

static const char *const CMD = "export";

typedef struct export_cli {
  const char *to, *output;
  int radiosity; /* index into POV_RADIOSITY */
  bool embed, coverage, quiet;
} export_cli;

static const char *const POV_RADIOSITY[] = {"off", "low", "medium", "high", NULL};

static const iris_option EXPORT_ROWS[] = {
    {"to", 0, IRIS_OPT_STRING, "FORMAT", 0, 0, offsetof(export_cli, to), "blender or pov (required)", NULL},
    {"output", 'o', IRIS_OPT_STRING, "FILE", 0, 0, offsetof(export_cli, output),
     "the script (.py) or scene (.pov) to write (required)", NULL},
    {"embed", 0, IRIS_OPT_FLAG, NULL, 0, 0, offsetof(export_cli, embed), "blender: put the mesh data inside the script", NULL},
    {"pov-coverage", 0, IRIS_OPT_FLAG, NULL, 0, 0, offsetof(export_cli, coverage),
     "pov: every object a pure white emitter on black, no lights", NULL},
    {"pov-radiosity", 0, IRIS_OPT_CHOICE, "Q", 0, 0, offsetof(export_cli, radiosity),
     "pov: indirect light by POV-Ray radiosity, Q = off, low,\n"
     "medium (default) or high", POV_RADIOSITY},
    {"quiet", 'q', IRIS_OPT_FLAG, NULL, 0, 0, offsetof(export_cli, quiet), "no warnings or summary", NULL},
};
static const iris_option_group EXPORT_OPTIONS = {"Options", EXPORT_ROWS, sizeof EXPORT_ROWS / sizeof EXPORT_ROWS[0]};

static void print_help(const iris_option_binding *b, size_t n) {
  printf("Usage: iris export INPUT --to blender|pov -o OUT [options]\n"
         "\n"
         "Writes INPUT (an iris scene .json, an OBJ/PLY/glTF file, or a built-in scene:\n"
         "cornell-box, veach-mis, ...) for another renderer:\n"
         "  blender  a Python script that builds the scene in Blender 3.4 and renders it\n"
         "           with Cycles using iris's fair-comparison settings:\n"
         "             blender -b --factory-startup --python-exit-code 1 -P OUT.py -- \\\n"
         "                     --output IMG.exr [--spp N] [--threads T] [--seed S]\n"
         "                     [--width W --height H] [--max-bounces B]\n"
         "           mesh data goes to OUT's <stem>.meshes.bin next to it (or --embed).\n"
         "  pov      a POV-Ray 3.7 scene (materials and lights approximated):\n"
         "             povray +IOUT.pov +OIMG.png +FN +W<w> +H<h> -D -V\n"
         "In-memory textures are written to <stem>.textures/ next to OUT.\n"
         "\n");
  printf("blender: --spp and --seed are the script's defaults; --max-depth is Cycles'\n"
         "bounce count (pov: max_trace_level B+1, at most 1024); --seed at most 2^31-1.\n\n");
  iris_options_help(b, n);
  printf("  -h, --help              show this help\n"
         "\n"
         "Exit status: 0 success, 2 bad usage or bad input (nothing written), 1 other\n"
         "failure. Outputs are written atomically.\n");
}

int iris_cmd_export(int argc, char **argv) {
  iris_export_params params = iris_export_params_default();
  export_cli ec;
  memset(&ec, 0, sizeof ec);
  iris_env_options eo = iris_env_options_default();
  iris_render_options ro;
  memset(&ro, 0, sizeof ro);
  iris_gltf_input_options go = {NULL};
  /* the shared sampling/camera rows export means something by: the script's defaults */
  iris_option_binding bind[] = {
      {&EXPORT_OPTIONS, &ec, 0, 0},
      {&IRIS_RENDER_OPTIONS, &ro, 0, iris_options_rows(&IRIS_RENDER_OPTIONS, "spp,seed,max-depth,camera,width,height")},
      {&IRIS_ENV_OPTIONS, &eo, 0, 0}, {&IRIS_GLTF_INPUT_OPTIONS, &go, 0, 0}};
  const size_t nbind = sizeof bind / sizeof bind[0];
  const char *input = NULL;
  int ninputs = 0;
  int prc = iris_options_parse(CMD, argc, argv, bind, nbind, &input, 1, &ninputs);
  if (prc < 0) {
    print_help(bind, nbind);
    return IRIS_EXIT_OK;
  }
  if (prc != 0) return prc;
  const iris_option_binding *rb = &bind[1];
  /* Cycles' seed is a non-negative 32-bit int; Cycles' bounce counts stop at 1024 */
  if (iris_options_seen(rb, "seed") && ro.seed > 2147483647u)
    return iris_cli_usage_error(CMD, "invalid value '%llu' for --seed (a number in [0, 2147483647])",
                                (unsigned long long)ro.seed);
  if (iris_options_seen(rb, "max-depth") && ro.max_depth > 1024)
    return iris_cli_usage_error(CMD, "invalid value '%d' for --max-depth (a number in [0, 1024])", ro.max_depth);
  const char *to = ec.to, *output = ec.output;
  bool quiet = ec.quiet;
  params.camera_name = ro.camera;
  if (iris_options_seen(rb, "width")) params.width = ro.width;
  if (iris_options_seen(rb, "height")) params.height = ro.height;
  if (iris_options_seen(rb, "spp")) params.spp = ro.spp;
  if (iris_options_seen(rb, "seed")) {
    params.seed = ro.seed;
    params.has_seed = true;
  }
  if (iris_options_seen(rb, "max-depth")) params.max_depth = ro.max_depth;
  params.embed_meshes = ec.embed;
  params.coverage = ec.coverage;
  const bool radiosity = iris_options_seen(&bind[0], "pov-radiosity");
  if (radiosity) params.pov_radiosity = (iris_pov_radiosity)ec.radiosity;
  if (quiet) iris_log_set_level(IRIS_LOG_QUIET);

  /* Everything that can be checked is checked before any work starts. */
  if (ninputs == 0) return iris_cli_usage_error(CMD, "no input");
  if (!to) return iris_cli_usage_error(CMD, "missing --to blender|pov");
  bool blender = strcmp(to, "blender") == 0;
  if (!blender && strcmp(to, "pov") != 0)
    return iris_cli_usage_error(CMD, "unknown format '%s' for --to (blender or pov)", to);
  if (!output) return iris_cli_usage_error(CMD, "missing --output FILE");
  char ext[16];
  iris_path_ext(output, ext, sizeof ext);
  if (blender && strcmp(ext, "py") != 0)
    return iris_cli_usage_error(CMD, "Blender output '%s' must end in .py", output);
  if (!blender && strcmp(ext, "pov") != 0)
    return iris_cli_usage_error(CMD, "POV-Ray output '%s' must end in .pov", output);
  if (blender && params.coverage) return iris_cli_usage_error(CMD, "--pov-coverage needs --to pov");
  if (!blender && params.embed_meshes) return iris_cli_usage_error(CMD, "--embed needs --to blender");
  if (blender && radiosity) return iris_cli_usage_error(CMD, "--pov-radiosity needs --to pov");
  if (params.coverage && radiosity && params.pov_radiosity != IRIS_POV_RADIOSITY_OFF)
    return iris_cli_usage_error(CMD, "--pov-coverage and --pov-radiosity conflict (coverage has no light)");
  if (!blender && (params.spp > 0 || params.has_seed))
    return iris_cli_usage_error(CMD, "--spp and --seed apply to --to blender only");
  if (!iris_cli_output_folder_ok(CMD, output)) return IRIS_EXIT_USAGE;
  if (iris_path_exists(input) && iris_cli_same_file(input, output))
    return iris_cli_usage_error(CMD, "output '%s' is also the input", output);

  int rc = iris_env_options_check(CMD, &bind[2], true);
  if (rc != IRIS_EXIT_OK) return rc;
  iris_scene *scene = NULL;
  iris_import_options io = iris_import_options_default();
  io.camera_name = params.camera_name;
  io.variant = go.variant;
  rc = iris_cli_load_scene(CMD, input, &io, NULL, &scene);
  if (rc != IRIS_EXIT_OK) return rc;
  if ((rc = iris_env_options_apply(CMD, &bind[2], scene)) != IRIS_EXIT_OK) {
    iris_scene_destroy(scene);
    return rc;
  }
  iris_error err;
  iris_error_clear(&err);
  iris_status status = blender ? iris_export_blender(scene, output, &params, &err) : iris_export_pov(scene, output, &params, &err);
  if (status != IRIS_OK) {
    iris_scene_destroy(scene);
    /* Write failures are failures (1); everything else is bad input (2). */
    int code = iris_cli_report(&err);
    return status == IRIS_ERR_IO ? IRIS_EXIT_FAILURE : code;
  }
  if (!quiet) {
    iris_export_view view;
    iris_export_resolve_view(scene, &params, input, &view, &err);
    char sidecar[1300] = "";
    if (blender && !params.embed_meshes) {
      iris_blender_sidecar_path(output, sidecar, sizeof sidecar);
    }
    fprintf(stderr, "iris: wrote %s%s%s: %zu meshes, %llu triangles, %zu lights, %dx%d%s\n", output,
            sidecar[0] ? " and " : "", sidecar, scene->mesh_count,
            (unsigned long long)iris_scene_triangle_count(scene), scene->light_count, view.width, view.height,
            params.coverage ? ", coverage mode" : "");
  }
  iris_scene_destroy(scene);
  return IRIS_EXIT_OK;
}
