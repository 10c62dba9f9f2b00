/* `iris import INPUT... -o SCENE.json`: imports OBJ/PLY/glTF files (and iris
 * scenes), merges them and writes one iris scene (docs/cli.md). */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/fileio.h"
#include "core/log.h"
#include "importers/import.h"
#include "scene/scene.h"
#include "tools/cli.h"
#include "tools/options.h"

static const char *const CMD = "import";

typedef struct import_cli {
  const char *output, *camera;
  bool weld, no_normals, quiet;
} import_cli;

static const iris_option IMPORT_ROWS[] = {
    {"output", 'o', IRIS_OPT_STRING, "FILE", 0, 0, offsetof(import_cli, output),
     "scene JSON to write (required; must end in .json)", NULL},
    {"camera", 0, IRIS_OPT_STRING, "NAME", 0, 0, offsetof(import_cli, camera),
     "make the camera called NAME the scene's camera (the\n"
     "first one, which render uses); error if there is none", NULL},
    {"weld", 0, IRIS_OPT_FLAG, NULL, 0, 0, offsetof(import_cli, weld),
     "weld coincident vertices of OBJ/PLY meshes", NULL},
    {"no-normals", 0, IRIS_OPT_FLAG, NULL, 0, 0, offsetof(import_cli, no_normals),
     "do not compute normals for meshes that have none", NULL},
    {"quiet", 'q', IRIS_OPT_FLAG, NULL, 0, 0, offsetof(import_cli, quiet), "print no warnings or summary", NULL},
};
static const iris_option_group IMPORT_OPTIONS = {"Options", IMPORT_ROWS,
                                                 sizeof IMPORT_ROWS / sizeof IMPORT_ROWS[0]};

static void print_help(const iris_option_binding *b, size_t n) {
  printf("Usage: iris import INPUT... -o SCENE.json [OPTIONS]\n"
         "\n"
         "Converts OBJ (+MTL), PLY, glTF 2.0 (.gltf/.glb) files and iris scenes (.json)\n"
         "into one iris scene: SCENE.json plus its meshes in SCENE.meshes/ (and\n"
         "embedded textures in SCENE.textures/). Several inputs are merged in order.\n"
         "\n");
  iris_options_help(b, n);
  printf("  -h, --help              show this help\n"
         "\n"
         "Exit status: 0 success, 2 bad usage or bad input (nothing written), 1 other\n"
         "failure. Outputs are written atomically.\n");
}

static bool supported_input(const char *path) {
  char ext[16];
  iris_path_ext(path, ext, sizeof ext);
  static const char *const exts[] = {"obj", "ply", "gltf", "glb", "json"};
  for (size_t i = 0; i < sizeof exts / sizeof *exts; i++)
    if (strcmp(ext, exts[i]) == 0) return true;
  return false;
}

/* Moves the camera called `name` to index 0; false when there is none. */
static bool select_camera(iris_scene *s, const char *name) {
  for (size_t i = 0; i < s->camera_count; i++) {
    if (!s->cameras[i].name || strcmp(s->cameras[i].name, name) != 0) continue;
    iris_camera chosen = s->cameras[i];
    memmove(&s->cameras[1], &s->cameras[0], i * sizeof *s->cameras);
    s->cameras[0] = chosen;
    return true;
  }
  return false;
}

int iris_cmd_import(int argc, char **argv) {
  iris_import_options opts = iris_import_options_default();
  import_cli ic;
  memset(&ic, 0, sizeof ic);
  iris_env_options eo = iris_env_options_default();
  iris_gltf_input_options go = {NULL};
  iris_option_binding bind[] = {{&IMPORT_OPTIONS, &ic, 0, 0}, {&IRIS_GLTF_INPUT_OPTIONS, &go, 0, 0},
                                {&IRIS_ENV_OPTIONS, &eo, 0, 0}};
  const size_t nbind = sizeof bind / sizeof bind[0];
  const char *inputs[256];
  int ninputs = 0;
  int prc = iris_options_parse(CMD, argc, argv, bind, nbind, inputs, 256, &ninputs);
  if (prc < 0) {
    print_help(bind, nbind);
    return IRIS_EXIT_OK;
  }
  if (prc != 0) return prc;
  const char *output = ic.output;
  bool quiet = ic.quiet;
  opts.camera_name = ic.camera;
  opts.weld = ic.weld;
  opts.variant = go.variant; /* every glTF input; any other input refuses it */
  if (ic.no_normals) opts.compute_normals = false;
  if (quiet) iris_log_set_level(IRIS_LOG_QUIET);

  /* Everything that can be checked is checked before any work starts. */
  if (ninputs == 0) return iris_cli_usage_error(CMD, "no input file");
  if (!output) return iris_cli_usage_error(CMD, "missing --output SCENE.json");
  char ext[16];
  iris_path_ext(output, ext, sizeof ext);
  if (strcmp(ext, "json") != 0) return iris_cli_usage_error(CMD, "output '%s' must end in .json", output);
  if (!iris_cli_output_folder_ok(CMD, output)) return IRIS_EXIT_USAGE;
  struct stat st;
  for (int i = 0; i < ninputs; i++) {
    if (!supported_input(inputs[i]))
      return iris_cli_usage_error(CMD, "input '%s' is not an .obj, .ply, .gltf, .glb or .json file", inputs[i]);
    if (stat(inputs[i], &st) != 0 || !S_ISREG(st.st_mode)) {
      iris_error err;
      iris_error_clear(&err);
      iris_error_set(&err, IRIS_ERR_IO, inputs[i], 0, NULL, "cannot open: no such file");
      return iris_cli_report(&err);
    }
    if (iris_cli_same_file(inputs[i], output))
      return iris_cli_usage_error(CMD, "output '%s' is also an input", output);
  }
  int erc = iris_env_options_check(CMD, &bind[2], true);
  if (erc != IRIS_EXIT_OK) return erc;

  iris_error err;
  iris_error_clear(&err);
  iris_scene *scene = NULL;
  for (int i = 0; i < ninputs; i++) {
    iris_scene *one = NULL;
    iris_status status = iris_import_file(inputs[i], &opts, &one, &err);
    if (status == IRIS_OK && !scene) {
      scene = one;
    } else if (status == IRIS_OK) {
      status = iris_scene_merge(scene, one, &err);
    }
    if (status != IRIS_OK) {
      iris_scene_destroy(scene);
      return iris_cli_report(&err);
    }
  }
  if (opts.camera_name && !select_camera(scene, opts.camera_name)) {
    char names[400] = "";
    for (size_t i = 0; i < scene->camera_count && strlen(names) < 300; i++)
      snprintf(names + strlen(names), sizeof names - strlen(names), "%s'%s'", i ? ", " : "",
               scene->cameras[i].name ? scene->cameras[i].name : "(unnamed)");
    int rc = iris_cli_usage_error(CMD, "no camera named '%s' in the input (cameras: %s)", opts.camera_name,
                                  names[0] ? names : "none");
    iris_scene_destroy(scene);
    return rc;
  }
  int arc = iris_env_options_apply(CMD, &bind[2], scene);
  if (arc != IRIS_EXIT_OK) {
    iris_scene_destroy(scene);
    return arc;
  }
  /* Messages about the merged scene name the output it was going to be. */
  free(scene->source_path);
  scene->source_path = iris_strdup(ninputs == 1 ? inputs[0] : output);
  if (iris_scene_write(scene, output, &err) != IRIS_OK) {
    iris_scene_destroy(scene);
    char msg[1400];
    iris_error_format(&err, msg, sizeof msg);
    fprintf(stderr, "iris: %s\n", msg);
    /* Writing failures are not bad input, except a scene that fails validation. */
    return err.status == IRIS_ERR_INVALID ? IRIS_EXIT_USAGE : IRIS_EXIT_FAILURE;
  }
  iris_infof("wrote %s: %zu meshes, %zu instances, %llu triangles, %zu materials, %zu textures, "
             "%zu cameras, %zu lights",
             output, scene->mesh_count, scene->instance_count,
             (unsigned long long)iris_scene_triangle_count(scene), scene->material_count,
             scene->texture_count, scene->camera_count, scene->light_count);
  iris_scene_destroy(scene);
  return IRIS_EXIT_OK;
}
