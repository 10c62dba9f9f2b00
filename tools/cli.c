#include "tools/cli.h"

#include <errno.h>
#include <signal.h>
#include <getopt.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/cancel.h"
#include "core/fileio.h"
#include "importers/import.h"
#include "scenes/builtin.h"

static volatile sig_atomic_t g_stop = 0;
static struct sigaction g_old_int, g_old_term;
static bool g_catching = false;

static void on_signal(int sig) { g_stop = sig; }

void iris_cli_catch_signals(void) {
  if (g_catching) return;
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sa.sa_flags = SA_RESETHAND; /* a second signal stops at once */
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &g_old_int);
  sigaction(SIGTERM, &sa, &g_old_term);
  iris_cancel_watch(&g_stop);
  g_catching = true;
}

void iris_cli_release_signals(void) {
  if (!g_catching) return;
  sigaction(SIGINT, &g_old_int, NULL);
  sigaction(SIGTERM, &g_old_term, NULL);
  g_catching = false;
}

volatile sig_atomic_t *iris_cli_stop_flag(void) { return &g_stop; }

int iris_cli_interrupt_exit(void) { return g_stop == SIGTERM ? 143 : 130; }

int iris_cli_report(const iris_error *err) {
  char buf[1400];
  iris_error_format(err, buf, sizeof buf);
  if (err->status == IRIS_ERR_INTERRUPTED) {
    fprintf(stderr, "iris: %s; nothing was written\n", buf);
    return iris_cli_interrupt_exit();
  }
  fprintf(stderr, "iris: %s\n", buf);
  switch (err->status) {
    case IRIS_ERR_USAGE:
    case IRIS_ERR_PARSE:
    case IRIS_ERR_INVALID:
    case IRIS_ERR_UNSUPPORTED:
    case IRIS_ERR_NOMEM: /* a scene too big for the machine, or a declared size out of reason */
      return IRIS_EXIT_USAGE;
    case IRIS_ERR_IO:
      /* Unreadable input is bad input; unwritable output is a failure. Input
       * errors are reported with the input file name, which the caller knows;
       * default to bad input since reading is the common case. */
      return IRIS_EXIT_USAGE;
    default:
      return IRIS_EXIT_FAILURE;
  }
}

int iris_cli_usage_error(const char *cmd, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  fprintf(stderr, "iris: %s: ", cmd);
  vfprintf(stderr, fmt, ap);
  fprintf(stderr, "\nTry 'iris %s --help' for more information.\n", cmd);
  va_end(ap);
  return IRIS_EXIT_USAGE;
}

bool iris_cli_parse_int(const char *cmd, const char *opt, const char *text, long lo, long hi,
                        long *out) {
  char *end = NULL;
  errno = 0;
  long v = strtol(text, &end, 10);
  if (errno || !end || end == text || *end || v < lo || v > hi) {
    iris_cli_usage_error(cmd, "invalid value '%s' for %s (an integer in [%ld, %ld])", text, opt, lo, hi);
    return false;
  }
  *out = v;
  return true;
}

bool iris_cli_parse_u64(const char *cmd, const char *opt, const char *text, uint64_t *out) {
  char *end = NULL;
  errno = 0;
  if (text[0] == '-') {
    iris_cli_usage_error(cmd, "invalid value '%s' for %s (a non-negative integer)", text, opt);
    return false;
  }
  unsigned long long v = strtoull(text, &end, 10);
  if (errno || !end || end == text || *end) {
    iris_cli_usage_error(cmd, "invalid value '%s' for %s (a non-negative integer)", text, opt);
    return false;
  }
  *out = (uint64_t)v;
  return true;
}

bool iris_cli_parse_float(const char *cmd, const char *opt, const char *text, double lo,
                          double hi, double *out) {
  char *end = NULL;
  errno = 0;
  double v = strtod(text, &end);
  if (errno || !end || end == text || *end || !isfinite(v) || v < lo || v > hi) {
    iris_cli_usage_error(cmd, "invalid value '%s' for %s (a number in [%g, %g])", text, opt, lo, hi);
    return false;
  }
  *out = v;
  return true;
}

const char *iris_cli_split_option(const char *arg, char *name, size_t cap, const char **val) {
  *val = NULL;
  const char *eq = strchr(arg, '=');
  if (strncmp(arg, "--", 2) != 0 || !eq) return arg;
  size_t n = (size_t)(eq - arg);
  if (n >= cap) n = cap - 1;
  memcpy(name, arg, n);
  name[n] = 0;
  *val = eq + 1;
  return name;
}

bool iris_cli_take_value(const char *cmd, const char *opt, int argc, char **argv, int *i,
                         const char **val) {
  if (*val) return true;
  if (*i + 1 >= argc) {
    iris_cli_usage_error(cmd, "option %s needs a value", opt);
    return false;
  }
  *val = argv[++*i];
  return true;
}

int iris_cli_getopt_error(const char *cmd, int c, char **argv) {
  if (c == ':') return iris_cli_usage_error(cmd, "option '%s' needs a value", argv[optind - 1]);
  if (optopt) return iris_cli_usage_error(cmd, "unknown option '-%c'", optopt);
  return iris_cli_usage_error(cmd, "unknown option '%s'", argv[optind - 1]);
}

bool iris_cli_set_once(const char *cmd, const char *opt, const char **slot, const char *value) {
  if (*slot) {
    iris_cli_usage_error(cmd, "%s given twice ('%s' and '%s')", opt, *slot, value);
    return false;
  }
  *slot = value;
  return true;
}

bool iris_cli_output_folder_ok(const char *cmd, const char *output) {
  char dir[1024];
  iris_path_dir(output, dir, sizeof dir);
  struct stat st;
  if (stat(dir, &st) == 0 && S_ISDIR(st.st_mode)) return true;
  iris_cli_usage_error(cmd, "output folder '%s' does not exist", dir);
  return false;
}

bool iris_cli_same_file(const char *a, const char *b) {
  struct stat sa, sb;
  if (strcmp(a, b) == 0) return true;
  return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

int iris_cli_load_scene(const char *cmd, const char *input, const iris_import_options *opts,
                        const char *builtin_list, iris_scene **out) {
  iris_error err;
  iris_error_clear(&err);
  *out = NULL;
  iris_status st;
  iris_phase_begin("loading", "loading the scene");
  struct stat sb;
  const bool folder = stat(input, &sb) == 0 && S_ISDIR(sb.st_mode);
  if (folder && !iris_builtin_exists(input)) { /* a folder is never a scene; a built-in's name wins over one */
    return iris_cli_usage_error(cmd, "'%s' is a folder, not a scene file", input);
  } else if (!folder && iris_path_exists(input)) {
    st = iris_import_file(input, opts, out, &err);
  } else if (iris_builtin_exists(input) && opts && opts->variant) {
    st = iris_error_set(&err, IRIS_ERR_USAGE, input, 0, NULL,
                        "no material variant \"%s\": a built-in scene has no material variants (they come "
                        "from glTF files)", opts->variant);
  } else if (iris_builtin_exists(input)) {
    st = iris_builtin_create(input, out, &err);
  } else {
    char names[512] = "";
    for (const char *const *n = iris_builtin_names(); !builtin_list && *n && strlen(names) < 400; n++)
      snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", names[0] ? ", " : "", *n);
    return iris_cli_usage_error(cmd, "'%s' is neither a file nor a built-in scene (%s)", input,
                                builtin_list ? builtin_list : names);
  }
  return st == IRIS_OK ? IRIS_EXIT_OK : iris_cli_report(&err);
}
