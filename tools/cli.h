/* Shared plumbing for the `iris` subcommands: exit codes, error printing and
 * option-parsing helpers. Each subcommand lives in cmd_<name>.c, fills its
 * library's params struct from the flags and calls the library. */
#ifndef IRIS_TOOLS_CLI_H
#define IRIS_TOOLS_CLI_H

#include <stdbool.h>
#include <stdint.h>

#include "core/error.h"

/* Exit codes: 0 success, 2 bad usage or bad input, 1 any other failure. */
enum { IRIS_EXIT_OK = 0, IRIS_EXIT_FAILURE = 1, IRIS_EXIT_USAGE = 2 };

/* Prints "iris: FILE[:LINE]: [element: ]message" and returns the exit code
 * for the error's status. */
int iris_cli_report(const iris_error *err);
/* Prints "iris: <cmd>: <message>" and a hint to run --help; returns 2. */
int iris_cli_usage_error(const char *cmd, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* Strict number parsing of an option value; false (after printing a usage
 * error) when `text` is not a number in [lo, hi]. */
bool iris_cli_parse_int(const char *cmd, const char *opt, const char *text, long lo, long hi,
                        long *out);
bool iris_cli_parse_u64(const char *cmd, const char *opt, const char *text, uint64_t *out);
bool iris_cli_parse_float(const char *cmd, const char *opt, const char *text, double lo,
                          double hi, double *out);

/* Subcommand entry points: argv[0] is the subcommand name. */
typedef struct iris_command {
  const char *name;
  const char *summary;
  int (*run)(int argc, char **argv);
} iris_command;

int iris_cmd_import(int argc, char **argv);
int iris_cmd_info(int argc, char **argv);
int iris_cmd_render(int argc, char **argv);
int iris_cmd_export(int argc, char **argv);
int iris_cmd_merge(int argc, char **argv);
int iris_cmd_validate(int argc, char **argv);
int iris_cmd_bench(int argc, char **argv);
int iris_cmd_report(int argc, char **argv);

#endif
