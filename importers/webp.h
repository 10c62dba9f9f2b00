/* EXT_texture_webp: a WebP image (RGB or RGBA, lossy or lossless) decoded
 * with libwebp's C API and re-encoded as PNG, so that scenes, the renderer and
 * both exporters keep reading PNG and JPEG only (docs/import-gltf.md). */
#ifndef IRIS_IMPORTERS_WEBP_H
#define IRIS_IMPORTERS_WEBP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Whether the bytes start like a WebP file (RIFF....WEBP). */
bool iris_webp_sniff(const uint8_t *data, size_t size);

/* Pixels a WebP of `size` bytes may declare: IRIS_WEBP_PIXELS_PER_BYTE per
 * byte plus IRIS_WEBP_FREE_PIXELS, checked from the header before decoding. */
#define IRIS_WEBP_PIXELS_PER_BYTE 1024
#define IRIS_WEBP_FREE_PIXELS ((uint64_t)1 << 24)

/* Decodes and re-encodes as PNG (RGBA when the WebP has alpha, else RGB).
 * Returns false with a one-line reason in msg; *png is malloc'ed. */
bool iris_webp_to_png(const uint8_t *data, size_t size, uint8_t **png, size_t *png_size, char *msg,
                      size_t msg_size);

#ifdef __cplusplus
}
#endif
#endif
