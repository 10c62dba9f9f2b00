/* libFuzzer harness for environment maps (renderer/envmap.h): the input is a
 * map file (OpenEXR or Radiance .hdr) written to a temporary file, which
 * iris_envmap_load must reject or accept without crashing, leaking, hanging or
 * allocating without bound; an accepted map must sample directions whose pdf
 * is finite and positive. Seeds: ../shared/assets/env/ (the CMake loop adds
 * assets/<format>/). */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "core/log.h"
#include "renderer/envmap.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  iris_log_set_level(IRIS_LOG_QUIET);
  char path[] = "/tmp/iris-fuzz-env-XXXXXX";
  int fd = mkstemp(path);
  if (fd < 0) return 0;
  size_t done = 0;
  while (done < size) {
    ssize_t n = write(fd, data + done, size - done);
    if (n <= 0) break;
    done += (size_t)n;
  }
  close(fd);
  iris_environment_map m = {path, 1.0f, 30.0f};
  iris_envmap env;
  iris_error err;
  iris_error_clear(&err);
  if (iris_envmap_load(&m, &env, &err) == IRIS_OK) {
    for (int i = 0; i < 16; i++) {
      iris_vec3 d;
      float pdf;
      if (iris_envmap_sample(&env, (float)i / 16.0f, (float)((i * 7) % 16) / 16.0f, &d, &pdf, NULL) &&
          !(pdf > 0.0f && pdf < INFINITY))
        __builtin_trap();
    }
    iris_envmap_destroy(&env);
  }
  unlink(path);
  return 0;
}
