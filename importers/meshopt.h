/* EXT_meshopt_compression: decodes one compressed buffer view with
 * libmeshoptimizer's C API (modes ATTRIBUTES, TRIANGLES, INDICES; filters
 * NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL). Checks the parameters the
 * library would otherwise assert on; the caller bounds count * stride. */
#ifndef IRIS_IMPORTERS_MESHOPT_H
#define IRIS_IMPORTERS_MESHOPT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { IRIS_MESHOPT_ATTRIBUTES, IRIS_MESHOPT_TRIANGLES, IRIS_MESHOPT_INDICES } iris_meshopt_mode;
typedef enum {
  IRIS_MESHOPT_NONE, IRIS_MESHOPT_OCTAHEDRAL, IRIS_MESHOPT_QUATERNION, IRIS_MESHOPT_EXPONENTIAL
} iris_meshopt_filter;

/* Parses the extension's mode / filter strings; false when unknown. */
bool iris_meshopt_parse_mode(const char *s, iris_meshopt_mode *out);
bool iris_meshopt_parse_filter(const char *s, iris_meshopt_filter *out);

/* Checks count/stride/mode/filter against the extension's rules; returns NULL
 * when they are valid, else a short reason. */
const char *iris_meshopt_check(size_t count, size_t stride, iris_meshopt_mode mode, iris_meshopt_filter filter);

/* Decodes `size` bytes into dst (count * stride bytes) and applies the
 * filter. Returns false when the data is corrupt or truncated. Parameters
 * must have passed iris_meshopt_check. */
bool iris_meshopt_decode(const uint8_t *src, size_t size, size_t count, size_t stride, iris_meshopt_mode mode,
                         iris_meshopt_filter filter, void *dst);

#ifdef __cplusplus
}
#endif
#endif
