#include "validate/json_out.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"

void iris_json_add_number(cJSON *object, const char *key, double v) {
  if (isfinite(v))
    cJSON_AddNumberToObject(object, key, v);
  else
    cJSON_AddNullToObject(object, key);
}

iris_status iris_json_write_file(cJSON *doc, const char *path, iris_error *err) {
  char *text = cJSON_Print(doc);
  cJSON_Delete(doc);
  if (!text) return iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "out of memory");
  size_t len = strlen(text);
  text[len] = '\n'; /* the file ends in a newline, not a NUL */
  iris_status st = iris_file_write_atomic(path, text, len + 1, err);
  free(text);
  return st;
}
