/* Error records shared by every iris module: a status code plus the file, line
 * and element where the problem was found, formatted as `FILE:LINE: element: message`.
 * Functions that can fail return iris_status and fill an iris_error. */
#ifndef IRIS_CORE_ERROR_H
#define IRIS_CORE_ERROR_H

#include <stdio.h>
#include <stdlib.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum iris_status {
  IRIS_OK = 0,
  IRIS_ERR_IO,          /* cannot open/read/write a file */
  IRIS_ERR_PARSE,       /* syntax error in an input file */
  IRIS_ERR_INVALID,     /* well-formed but invalid data (indices, NaN, references) */
  IRIS_ERR_UNSUPPORTED, /* a feature iris does not implement (e.g. Draco) */
  IRIS_ERR_NOMEM,       /* allocation failed or a declared size is unreasonable */
  IRIS_ERR_USAGE,       /* bad arguments or options */
  IRIS_ERR_INTERRUPTED, /* stopped by a signal; partial result is valid */
  IRIS_ERR_INTERNAL     /* a bug or an external library failure */
} iris_status;

typedef struct iris_error {
  iris_status status;
  char file[512];    /* "" when not tied to a file */
  long line;         /* 0 when not applicable */
  char element[160]; /* e.g. "meshes[3]", "accessor 5"; "" when not applicable */
  char message[512];
} iris_error;

/* Clears an error record (status IRIS_OK). Accepts NULL. */
void iris_error_clear(iris_error *err);

/* Fills `err` (if not NULL) and returns `status`, so callers can write
 * `return iris_error_set(err, IRIS_ERR_PARSE, path, line, NULL, "bad token '%s'", tok);`.
 * file/element may be NULL. The first error set wins: a record that already
 * holds an error is not overwritten. */
iris_status iris_error_set(iris_error *err, iris_status status, const char *file, long line,
                           const char *element, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 6, 7)))
#endif
    ;

/* Writes "FILE:LINE: element: message" (omitting empty parts) into buf. */
void iris_error_format(const iris_error *err, char *buf, size_t size);

/* Short name of a status ("io", "parse", ...). */
const char *iris_status_name(iris_status status);

/* Always-on check that prints both values and aborts: for invariants, not input. */
#define IRIS_CHECK(cond)                                                              \
  do {                                                                                \
    if (!(cond)) {                                                                    \
      fprintf(stderr, "iris: internal check failed at %s:%d: %s\n", __FILE__, __LINE__, \
              #cond);                                                                 \
      abort();                                                                        \
    }                                                                                 \
  } while (0)
#define IRIS_CHECK_OP(a, op, b, fmt)                                                      \
  do {                                                                                    \
    if (!((a)op(b))) {                                                                    \
      fprintf(stderr, "iris: internal check failed at %s:%d: %s %s %s (" fmt " vs " fmt ")\n", \
              __FILE__, __LINE__, #a, #op, #b, (a), (b));                                 \
      abort();                                                                            \
    }                                                                                     \
  } while (0)
#ifndef NDEBUG
#define IRIS_DCHECK(cond) IRIS_CHECK(cond)
#else
#define IRIS_DCHECK(cond) ((void)0)
#endif

#ifdef __cplusplus
}
#endif
#endif
