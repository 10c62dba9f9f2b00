/* `iris merge PART.exr... -o OUT.exr`: combines the EXRs of a partitioned
 * render (sample ranges and/or windows) into the image one process would have
 * rendered. The library is renderer/merge.h; docs/distributed.md explains it. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "core/fileio.h"
#include "core/log.h"
#include "renderer/merge.h"
#include "tools/cli.h"

static const char *const CMD = "merge";

static void print_help(void) {
  printf("Usage: iris merge PART.exr... -o OUT.exr [--json] [--quiet]\n"
         "\n"
         "Merges the EXRs of one partitioned render (iris render --sample-offset K\n"
         "and/or --pixel-bounds x0,y0,x1,y1) into the full image: per pixel the\n"
         "sample-weighted mean and, when every part has var.R/G/B, the exact variance\n"
         "of the merged mean. Parts must come from the same scene (scene hash), seed,\n"
         "method and configuration; their windows must tile the frame and, in every\n"
         "window, their sample ranges must follow each other without gap or overlap.\n"
         "\n"
         "Options:\n"
         "  -o, --output FILE  merged OpenEXR (written atomically; nothing on error)\n"
         "      --json         JSON summary on stdout\n"
         "  -q, --quiet        no messages\n"
         "  -h, --help         show this help\n"
         "\n"
         "Exit status: 0 merged, 2 bad usage or parts that do not belong together,\n"
         "1 other failure.\n");
}

int iris_cmd_merge(int argc, char **argv) {
  const char *out = NULL;
  bool json = false, quiet = false;
  const char **parts = calloc((size_t)argc + 1, sizeof *parts);
  if (!parts) return IRIS_EXIT_FAILURE;
  size_t count = 0;
  int rc = IRIS_EXIT_OK;
  for (int i = 1; i < argc && rc == IRIS_EXIT_OK; i++) {
    const char *a = argv[i];
    if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
      print_help();
      free(parts);
      return IRIS_EXIT_OK;
    } else if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
      if (i + 1 >= argc)
        rc = iris_cli_usage_error(CMD, "option %s needs a value", a);
      else
        out = argv[++i];
    } else if (strncmp(a, "--output=", 9) == 0) {
      out = a + 9;
    } else if (strcmp(a, "--json") == 0) {
      json = true;
    } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
      quiet = true;
    } else if (a[0] == '-' && a[1] != 0) {
      rc = iris_cli_usage_error(CMD, "unknown option '%s'", a);
    } else {
      parts[count++] = a;
    }
  }
  char ext[16] = "";
  if (rc == IRIS_EXIT_OK) {
    if (out) iris_path_ext(out, ext, sizeof ext);
    if (count == 0)
      rc = iris_cli_usage_error(CMD, "no parts given");
    else if (!out)
      rc = iris_cli_usage_error(CMD, "no output: give -o OUT.exr");
    else if (strcmp(ext, "exr") != 0)
      rc = iris_cli_usage_error(CMD, "output '%s' must end in .exr", out);
  }
  if (rc == IRIS_EXIT_OK) {
    char dir[1024];
    iris_path_dir(out, dir, sizeof dir);
    if (!iris_path_exists(dir)) rc = iris_cli_usage_error(CMD, "the folder of '%s' does not exist", out);
    for (size_t i = 0; i < count && rc == IRIS_EXIT_OK; i++)
      for (size_t j = i + 1; j < count && rc == IRIS_EXIT_OK; j++)
        if (strcmp(parts[i], parts[j]) == 0)
          rc = iris_cli_usage_error(CMD, "part '%s' is given twice", parts[i]);
  }
  if (rc != IRIS_EXIT_OK) {
    free(parts);
    return rc;
  }
  if (quiet) iris_log_set_level(IRIS_LOG_QUIET);

  iris_error err;
  iris_error_clear(&err);
  iris_merge_summary sum;
  iris_status st = iris_merge_files(parts, count, out, &sum, &err);
  free(parts);
  if (st != IRIS_OK) return iris_cli_report(&err);
  if (json) {
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "output", out);
    cJSON_AddNumberToObject(o, "width", sum.width);
    cJSON_AddNumberToObject(o, "height", sum.height);
    cJSON_AddNumberToObject(o, "parts", (double)sum.parts);
    cJSON_AddNumberToObject(o, "windows", (double)sum.windows);
    cJSON_AddNumberToObject(o, "sample_offset", (double)sum.sample_offset);
    cJSON_AddNumberToObject(o, "spp", (double)sum.spp);
    cJSON_AddBoolToObject(o, "variance", sum.variance);
    char *text = cJSON_Print(o);
    if (text) printf("%s\n", text);
    free(text);
    cJSON_Delete(o);
  } else if (!quiet) {
    iris_infof("merge: %zu parts (%zu windows) -> %s, %dx%d, samples %lld..%lld%s", sum.parts,
               sum.windows, out, sum.width, sum.height, (long long)sum.sample_offset,
               (long long)(sum.sample_offset + sum.spp - 1), sum.variance ? ", with variance" : "");
  }
  return IRIS_EXIT_OK;
}
