/* JSON output shared by `iris validate` and `iris bench`: numbers that may be
 * non-finite (JSON has no Inf/NaN: they become null) and writing a document
 * atomically with a trailing newline. */
#ifndef IRIS_VALIDATE_JSON_OUT_H
#define IRIS_VALIDATE_JSON_OUT_H

#include <cjson/cJSON.h>

#include "core/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Adds `v` under `key`, or null when v is NaN or infinite. */
void iris_json_add_number(cJSON *object, const char *key, double v);

/* Prints `doc` (which this call deletes, whatever happens) and writes it to
 * `path` atomically, ending in a newline. */
iris_status iris_json_write_file(cJSON *doc, const char *path, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
