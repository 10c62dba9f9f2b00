/* The `iris` command: dispatches to one subcommand per file (cmd_<name>.c). */
#include <stdio.h>
#include <string.h>

#include "core/log.h"
#include "tools/cli.h"

static const iris_command COMMANDS[] = {
    {"import", "convert OBJ/PLY/glTF files into an iris scene", iris_cmd_import},
    {"info", "describe a scene or importable file", iris_cmd_info},
    {"render", "render a scene (or any importable file) to EXR/PNG", iris_cmd_render},
    {"export", "export a scene to Blender (Python) or POV-Ray (SDL)", iris_cmd_export},
    {"merge", "merge the EXRs of a partitioned render (sample ranges, windows)", iris_cmd_merge},
    {"validate", "compare iris with Blender Cycles (stored reference or Blender)", iris_cmd_validate},
    {"bench", "speed against accuracy: relMSE vs time per method, charts, tables", iris_cmd_bench},
    {"report", "self-contained HTML page from bench and validate outputs", iris_cmd_report},
};
static const size_t COMMAND_COUNT = sizeof COMMANDS / sizeof COMMANDS[0];

static void print_usage(FILE *fp) {
  fprintf(fp,
          "Usage: iris [--version] [--help] COMMAND [ARGS...]\n"
          "\n"
          "iris imports artists' scenes, renders them with irradiance-cache-guided\n"
          "path tracing, exports them to Blender and POV-Ray and validates them\n"
          "against Blender Cycles.\n\nCommands:\n");
  for (size_t i = 0; i < COMMAND_COUNT; i++)
    fprintf(fp, "  %-10s %s\n", COMMANDS[i].name, COMMANDS[i].summary);
  fprintf(fp, "\nRun 'iris COMMAND --help' for the options of a command.\n"
              "Exit status: 0 success, 2 bad usage or bad input, 1 other failure.\n");
}

int main(int argc, char **argv) {
  if (argc < 2) {
    print_usage(stderr);
    return IRIS_EXIT_USAGE;
  }
  const char *cmd = argv[1];
  if (strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0 || strcmp(cmd, "help") == 0) {
    print_usage(stdout);
    return IRIS_EXIT_OK;
  }
  if (strcmp(cmd, "--version") == 0) {
    printf("iris %s\n", IRIS_VERSION_STRING);
    return IRIS_EXIT_OK;
  }
  for (size_t i = 0; i < COMMAND_COUNT; i++)
    if (strcmp(cmd, COMMANDS[i].name) == 0) return COMMANDS[i].run(argc - 1, argv + 1);
  fprintf(stderr, "iris: unknown command '%s'\n", cmd);
  print_usage(stderr);
  return IRIS_EXIT_USAGE;
}
