#include "tools/cli.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

int iris_cli_report(const iris_error *err) {
  char buf[1400];
  iris_error_format(err, buf, sizeof buf);
  fprintf(stderr, "iris: %s\n", buf);
  switch (err->status) {
    case IRIS_ERR_USAGE:
    case IRIS_ERR_PARSE:
    case IRIS_ERR_INVALID:
    case IRIS_ERR_UNSUPPORTED:
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
