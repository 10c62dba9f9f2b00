/* `iris export INPUT --to blender|pov -o OUT`: loads an iris scene, an
 * importable file or a built-in scene and writes it as a Blender 3.4 Python
 * script or a POV-Ray 3.7 scene (docs/export.md). */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "core/log.h"
#include "exporters/blender.h"
#include "exporters/pov.h"
#include "tools/cli.h"

static const char *const CMD = "export";

static void print_help(void) {
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
         "\n"
         "Options:\n"
         "      --to FORMAT      blender or pov (required)\n"
         "  -o, --output FILE    the script (.py) or scene (.pov) to write (required)\n"
         "      --camera NAME    scene camera to use (default: the first; none: framed\n"
         "                       automatically, as `iris render` does)\n"
         "      --width W, --height H   image size (default: as `iris render`)\n"
         "      --spp N          blender: default samples per pixel of the script\n"
         "      --seed N         blender: default Cycles seed of the script\n"
         "      --max-depth B    bounces as Cycles counts them (default: the scene's, else 64);\n"
         "                       pov: max_trace_level B+1\n"
         "      --embed          blender: put the mesh data inside the script\n"
         "      --pov-coverage   pov: every object a pure white emitter on black, no lights\n"
         "      --pov-radiosity Q\n"
         "                       pov: indirect light by POV-Ray radiosity, Q = off, low,\n"
         "                       medium (default) or high\n"
         "  -q, --quiet          no warnings or summary\n"
         "  -h, --help           show this help\n"
         "\n"
         "Exit status: 0 success, 2 bad usage or bad input (nothing written), 1 other\n"
         "failure. Outputs are written atomically.\n");
}

int iris_cmd_export(int argc, char **argv) {
  enum { OPT_TO = 256, OPT_CAMERA, OPT_WIDTH, OPT_HEIGHT, OPT_SPP, OPT_SEED, OPT_DEPTH, OPT_EMBED, OPT_COVERAGE, OPT_RADIOSITY };
  static const struct option longopts[] = {{"to", required_argument, NULL, OPT_TO},
                                           {"output", required_argument, NULL, 'o'},
                                           {"camera", required_argument, NULL, OPT_CAMERA},
                                           {"width", required_argument, NULL, OPT_WIDTH},
                                           {"height", required_argument, NULL, OPT_HEIGHT},
                                           {"spp", required_argument, NULL, OPT_SPP},
                                           {"seed", required_argument, NULL, OPT_SEED},
                                           {"max-depth", required_argument, NULL, OPT_DEPTH},
                                           {"embed", no_argument, NULL, OPT_EMBED},
                                           {"pov-coverage", no_argument, NULL, OPT_COVERAGE},
                                           {"pov-radiosity", required_argument, NULL, OPT_RADIOSITY},
                                           {"quiet", no_argument, NULL, 'q'},
                                           {"help", no_argument, NULL, 'h'},
                                           {NULL, 0, NULL, 0}};
  iris_export_params params = iris_export_params_default();
  const char *to = NULL, *output = NULL, *radiosity = NULL;
  bool quiet = false;
  long v;
  opterr = 0;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, ":o:qh", longopts, NULL)) != -1) {
    switch (c) {
      case OPT_TO:
        if (!iris_cli_set_once(CMD, "--to", &to, optarg)) return IRIS_EXIT_USAGE;
        break;
      case 'o':
        if (!iris_cli_set_once(CMD, "--output", &output, optarg)) return IRIS_EXIT_USAGE;
        break;
      case OPT_CAMERA:
        if (!iris_cli_set_once(CMD, "--camera", &params.camera_name, optarg)) return IRIS_EXIT_USAGE;
        if (!optarg[0]) return iris_cli_usage_error(CMD, "--camera needs a non-empty name");
        break;
      case OPT_WIDTH:
        if (!iris_cli_parse_int(CMD, "--width", optarg, 1, 65536, &v)) return IRIS_EXIT_USAGE;
        params.width = (int)v;
        break;
      case OPT_HEIGHT:
        if (!iris_cli_parse_int(CMD, "--height", optarg, 1, 65536, &v)) return IRIS_EXIT_USAGE;
        params.height = (int)v;
        break;
      case OPT_SPP:
        if (!iris_cli_parse_int(CMD, "--spp", optarg, 1, 1 << 24, &v)) return IRIS_EXIT_USAGE;
        params.spp = (int)v;
        break;
      case OPT_SEED:
        /* Cycles' seed is a non-negative 32-bit int. */
        if (!iris_cli_parse_int(CMD, "--seed", optarg, 0, 2147483647L, &v)) return IRIS_EXIT_USAGE;
        params.seed = (uint64_t)v;
        params.has_seed = true;
        break;
      case OPT_DEPTH:
        if (!iris_cli_parse_int(CMD, "--max-depth", optarg, 0, 1024, &v)) return IRIS_EXIT_USAGE;
        params.max_depth = (int)v;
        break;
      case OPT_EMBED: params.embed_meshes = true; break;
      case OPT_COVERAGE: params.coverage = true; break;
      case OPT_RADIOSITY: {
        static const char *const LEVELS[] = {"off", "low", "medium", "high"};
        if (!iris_cli_set_once(CMD, "--pov-radiosity", &radiosity, optarg)) return IRIS_EXIT_USAGE;
        int k = 0;
        while (k < 4 && strcmp(optarg, LEVELS[k]) != 0) k++;
        if (k == 4)
          return iris_cli_usage_error(CMD, "unknown --pov-radiosity '%s' (off, low, medium or high)", optarg);
        params.pov_radiosity = (iris_pov_radiosity)k;
        break;
      }
      case 'q': quiet = true; break;
      case 'h': print_help(); return IRIS_EXIT_OK;
      default: return iris_cli_getopt_error(CMD, c, argv);
    }
  }
  if (quiet) iris_log_set_level(IRIS_LOG_QUIET);

  /* Everything that can be checked is checked before any work starts. */
  if (argc - optind == 0) return iris_cli_usage_error(CMD, "no input");
  if (argc - optind > 1) return iris_cli_usage_error(CMD, "one input only (got '%s' and '%s')", argv[optind], argv[optind + 1]);
  const char *input = argv[optind];
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
  if (blender && radiosity) return iris_cli_usage_error(CMD, "--pov-radiosity needs --to pov");
  if (params.coverage && radiosity && params.pov_radiosity != IRIS_POV_RADIOSITY_OFF)
    return iris_cli_usage_error(CMD, "--pov-coverage and --pov-radiosity conflict (coverage has no light)");
  if (!blender && params.embed_meshes) return iris_cli_usage_error(CMD, "--embed needs --to blender");
  if (!blender && (params.spp > 0 || params.has_seed))
    return iris_cli_usage_error(CMD, "--spp and --seed apply to --to blender only");
  if (!iris_cli_output_folder_ok(CMD, output)) return IRIS_EXIT_USAGE;
  if (iris_path_exists(input) && iris_cli_same_file(input, output))
    return iris_cli_usage_error(CMD, "output '%s' is also the input", output);

  iris_scene *scene = NULL;
  int rc = iris_cli_load_scene(CMD, input, params.camera_name, NULL, &scene);
  if (rc != IRIS_EXIT_OK) return rc;
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
