/* WebP -> PNG for glTF textures (EXT_texture_webp), libwebp + stb_image_write. */
#include "importers/webp.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image_write.h>
#include <webp/decode.h>

bool iris_webp_sniff(const uint8_t *data, size_t size) {
  return size >= 12 && memcmp(data, "RIFF", 4) == 0 && memcmp(data + 8, "WEBP", 4) == 0;
}

typedef struct png_sink {
  uint8_t *data;
  size_t size, cap;
  bool failed;
} png_sink;

static void sink_write(void *ctx, void *bytes, int n) {
  png_sink *s = ctx;
  if (s->failed || n <= 0) return;
  if (s->size + (size_t)n > s->cap) {
    size_t cap = s->cap ? s->cap : 4096;
    while (cap < s->size + (size_t)n) cap *= 2;
    uint8_t *grown = realloc(s->data, cap);
    if (!grown) {
      s->failed = true;
      return;
    }
    s->data = grown, s->cap = cap;
  }
  memcpy(s->data + s->size, bytes, (size_t)n);
  s->size += (size_t)n;
}

bool iris_webp_to_png(const uint8_t *data, size_t size, uint8_t **png, size_t *png_size, char *msg,
                      size_t msg_size) {
  *png = NULL;
  *png_size = 0;
  WebPBitstreamFeatures f;
  VP8StatusCode vs = WebPGetFeatures(data, size, &f);
  if (vs != VP8_STATUS_OK) {
    snprintf(msg, msg_size, "not a valid WebP image (libwebp status %d)", (int)vs);
    return false;
  }
  if (f.has_animation) {
    snprintf(msg, msg_size, "animated WebP is not supported");
    return false;
  }
  const uint64_t pixels = (uint64_t)f.width * (uint64_t)f.height;
  if (f.width <= 0 || f.height <= 0 || pixels > IRIS_WEBP_PIXELS_PER_BYTE * (uint64_t)size + IRIS_WEBP_FREE_PIXELS) {
    snprintf(msg, msg_size, "WebP declares %dx%d pixels, more than its %zu bytes can hold (truncated or corrupt)",
             f.width, f.height, size);
    return false;
  }
  const int comp = f.has_alpha ? 4 : 3;
  int w = 0, h = 0;
  uint8_t *pix = comp == 4 ? WebPDecodeRGBA(data, size, &w, &h) : WebPDecodeRGB(data, size, &w, &h);
  if (!pix) {
    snprintf(msg, msg_size, "WebP decoding failed (truncated or corrupt)");
    return false;
  }
  png_sink sink = {NULL, 0, 0, false};
  int ok = stbi_write_png_to_func(sink_write, &sink, w, h, comp, pix, w * comp);
  WebPFree(pix);
  if (!ok || sink.failed) {
    free(sink.data);
    snprintf(msg, msg_size, "out of memory re-encoding the WebP image as PNG");
    return false;
  }
  *png = sink.data;
  *png_size = sink.size;
  return true;
}
