/* libFuzzer harness for the glTF importer: the input is a .gltf or .glb held
 * in memory. The path is NULL, so external buffers and images are never
 * opened; the importer must reject or accept without crashing, leaking or
 * allocating without bound. Seeds: tests/fuzz/corpus/gltf/. */
#include <stddef.h>
#include <stdint.h>

#include "core/log.h"
#include "importers/import.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  iris_log_set_level(IRIS_LOG_QUIET);
  iris_import_options opts = iris_import_options_default();
  iris_scene *scene = NULL;
  iris_error err;
  iris_error_clear(&err);
  if (iris_import_gltf_memory((const char *)data, size, NULL, &opts, &scene, &err) == IRIS_OK)
    iris_scene_destroy(scene);
  return 0;
}
