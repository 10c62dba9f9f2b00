#include "core/error.h"

#include <stdarg.h>
#include <string.h>

void iris_error_clear(iris_error *err) {
  if (err) memset(err, 0, sizeof *err);
}

static void copy_str(char *dst, size_t size, const char *src) {
  if (!src) {
    dst[0] = '\0';
    return;
  }
  size_t n = strlen(src);
  if (n >= size) n = size - 1;
  memcpy(dst, src, n);
  dst[n] = '\0';
}

iris_status iris_error_set(iris_error *err, iris_status status, const char *file, long line,
                           const char *element, const char *fmt, ...) {
  if (!err || err->status != IRIS_OK) return status;
  err->status = status;
  copy_str(err->file, sizeof err->file, file);
  copy_str(err->element, sizeof err->element, element);
  err->line = line;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err->message, sizeof err->message, fmt, ap);
  va_end(ap);
  /* One line only: a message must never break the `iris: FILE: msg` shape. */
  for (char *c = err->message; *c; c++)
    if (*c == '\n' || *c == '\r') *c = ' ';
  return status;
}

void iris_error_format(const iris_error *err, char *buf, size_t size) {
  if (!buf || size == 0) return;
  buf[0] = '\0';
  if (!err) return;
  size_t used = 0;
#define APPEND(...)                                                    \
  do {                                                                 \
    int n_ = snprintf(buf + used, size - used, __VA_ARGS__);           \
    if (n_ > 0) used = (size_t)n_ >= size - used ? size - 1 : used + (size_t)n_; \
  } while (0)
  if (err->file[0]) {
    if (err->line > 0)
      APPEND("%s:%ld: ", err->file, err->line);
    else
      APPEND("%s: ", err->file);
  }
  if (err->element[0]) APPEND("%s: ", err->element);
  APPEND("%s", err->message[0] ? err->message : iris_status_name(err->status));
#undef APPEND
}

const char *iris_status_name(iris_status status) {
  switch (status) {
    case IRIS_OK: return "ok";
    case IRIS_ERR_IO: return "input/output error";
    case IRIS_ERR_PARSE: return "parse error";
    case IRIS_ERR_INVALID: return "invalid data";
    case IRIS_ERR_UNSUPPORTED: return "unsupported feature";
    case IRIS_ERR_NOMEM: return "out of memory";
    case IRIS_ERR_USAGE: return "bad usage";
    case IRIS_ERR_INTERRUPTED: return "interrupted";
    case IRIS_ERR_INTERNAL: return "internal error";
  }
  return "unknown error";
}
