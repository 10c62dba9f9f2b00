/* libFuzzer harness for the PLY importer: the input is a .ply file held in
 * memory. The path is NULL, so no material library or texture is opened; the
 * importer must reject or accept without crashing, leaking, hanging or
 * allocating without bound. Seeds: tests/fuzz/corpus/ply/. */
#include <stddef.h>
#include <stdint.h>

#include "core/log.h"
#include "importers/import.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  iris_log_set_level(IRIS_LOG_QUIET);
  iris_import_options opts = iris_import_options_default();
  opts.weld = size > 0 && (data[size - 1] & 1); /* exercise welding on half the inputs */
  iris_scene *scene = NULL;
  iris_error err;
  iris_error_clear(&err);
  if (iris_import_ply_memory((const char *)data, size, NULL, &opts, &scene, &err) == IRIS_OK) {
    if (iris_scene_validate(scene, "fuzz", &err) != IRIS_OK) __builtin_trap();
    iris_scene_destroy(scene);
  }
  return 0;
}
