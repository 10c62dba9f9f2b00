/* Shared plumbing for the `iris` subcommands: exit codes, error printing and
 * option-parsing helpers. Each subcommand lives in cmd_<name>.c, fills its
 * library's params struct from the flags and calls the library. */
#ifndef IRIS_TOOLS_CLI_H
#define IRIS_TOOLS_CLI_H

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "scene/scene.h"

/* Exit codes: 0 success, 2 bad usage or bad input, 1 any other failure. */
enum { IRIS_EXIT_OK = 0, IRIS_EXIT_FAILURE = 1, IRIS_EXIT_USAGE = 2 };

/* Prints "iris: FILE[:LINE]: [element: ]message" and returns the exit code
 * for the error's status. IRIS_ERR_INTERRUPTED (a phase stopped before any
 * sample existed) adds "; nothing was written" and returns 130 or 143. */
int iris_cli_report(const iris_error *err);

/* SIGINT and SIGTERM: the first sets the stop flag (watched by
 * iris_cancel_requested, core/cancel.h) and restores the default action, so
 * a second signal ends the process at once. Install before any long work
 * (loading a scene included); release restores the previous handlers. */
void iris_cli_catch_signals(void);
void iris_cli_release_signals(void);
/* The flag the handler sets: 0, or the signal number. */
volatile sig_atomic_t *iris_cli_stop_flag(void);
/* 130 after SIGINT, 143 after SIGTERM. */
int iris_cli_interrupt_exit(void);
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

/* Hand-rolled long options: "--name=value" is split into `name` (a copy of at
 * most cap - 1 bytes) and *val, which is returned as the option; any other
 * argument is returned as it is, with *val = NULL. */
const char *iris_cli_split_option(const char *arg, char *name, size_t cap, const char **val);
/* The value of option `opt` at argv[*i]: *val when already split off, else
 * the next argument (advancing *i); false (after a usage error) when none. */
bool iris_cli_take_value(const char *cmd, const char *opt, int argc, char **argv, int *i,
                         const char **val);
/* getopt_long's ':' (missing value) and '?' (unknown option) results as
 * usage errors; returns 2. */
int iris_cli_getopt_error(const char *cmd, int c, char **argv);
/* Stores `value` in *slot; false (after "OPT given twice") when already set. */
bool iris_cli_set_once(const char *cmd, const char *opt, const char **slot, const char *value);
/* True when the folder that will hold `output` exists; else a usage error. */
bool iris_cli_output_folder_ok(const char *cmd, const char *output);
/* True when paths `a` and `b` name the same file (same string or inode). */
bool iris_cli_same_file(const char *a, const char *b);
/* Loads INPUT: an existing file is imported with `opts` (NULL: the
 * defaults), else it must be a built-in scene name (refused with a material
 * variant). Returns IRIS_EXIT_OK with *out set, or prints the error and
 * returns the exit code. An INPUT that is neither is a usage error naming
 * `builtin_list`, or all built-in scenes when NULL. */
struct iris_import_options;
int iris_cli_load_scene(const char *cmd, const char *input, const struct iris_import_options *opts,
                        const char *builtin_list, iris_scene **out);

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
