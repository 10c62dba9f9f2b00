/* libFuzzer harness for texture decoding (PNG and JPEG through stb_image,
 * iris_ldr_load_memory): what the renderer does with every texture a scene,
 * OBJ/MTL or glTF file names or embeds. The decoder must reject or accept
 * without crashing, leaking, or doing work or allocating memory out of
 * proportion to the input (a JPEG declaring a huge size is refused).
 * Seeds: tests/fuzz/corpus/texture/. */
#include <stddef.h>
#include <stdint.h>

#include "core/image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  iris_ldr_image img;
  iris_error err;
  iris_error_clear(&err);
  if (iris_ldr_load_memory(data, size, "fuzz", &img, &err) == IRIS_OK) {
    if (img.width <= 0 || img.height <= 0 || !img.rgba) __builtin_trap();
    iris_ldr_destroy(&img);
  }
  return 0;
}
