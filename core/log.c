#include "core/log.h"

#include <stdarg.h>
#include <stdio.h>
#include <unistd.h>

static iris_log_level g_level = IRIS_LOG_INFO;
static bool g_line_open = false; /* a progress line without its newline is on screen */

void iris_log_progress_drawn(void) { g_line_open = true; }

/* A message starts on a line of its own, below the progress line. */
static void close_line(void) {
  if (g_line_open) fputc('\n', stderr);
  g_line_open = false;
}

void iris_log_set_level(iris_log_level level) { g_level = level; }
iris_log_level iris_log_get_level(void) { return g_level; }

void iris_log_progress_end(void) { close_line(); }

void iris_warnf(const char *fmt, ...) {
  if (g_level < IRIS_LOG_WARN) return;
  va_list ap;
  va_start(ap, fmt);
  close_line();
  fputs("iris: warning: ", stderr);
  vfprintf(stderr, fmt, ap);
  fputc('\n', stderr);
  va_end(ap);
}

void iris_infof(const char *fmt, ...) {
  if (g_level < IRIS_LOG_INFO) return;
  va_list ap;
  va_start(ap, fmt);
  close_line();
  fputs("iris: ", stderr);
  vfprintf(stderr, fmt, ap);
  fputc('\n', stderr);
  va_end(ap);
}

bool iris_log_progress_enabled(void) { return g_level >= IRIS_LOG_INFO && isatty(STDERR_FILENO); }
