/* Float images and their files: OpenEXR (float32 channels + string metadata,
 * through the OpenEXRCore C API), PNG output (sRGB, with exposure) and 8-bit
 * texture decoding (PNG/JPEG) for the renderer. All writes are atomic. */
#ifndef IRIS_CORE_IMAGE_H
#define IRIS_CORE_IMAGE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IRIS_IMAGE_MAX_CHANNELS 16

/* Interleaved float image: pixel (x, y) channel c is
 * data[((size_t)y * width + x) * channel_count + c]; row 0 is the top row. */
typedef struct iris_image {
  int width, height;
  int channel_count;
  char channel_names[IRIS_IMAGE_MAX_CHANNELS][32]; /* e.g. "R","G","B","var.R" */
  float *data;
} iris_image;

/* One string attribute of an EXR header (iris stores all metadata as strings
 * under "iris:<key>"). */
typedef struct iris_image_meta {
  char key[64];
  char value[1024];
} iris_image_meta;

/* Allocates a zeroed image with the given channel names. */
iris_status iris_image_create(iris_image *img, int width, int height, int channel_count,
                              const char *const *names, iris_error *err);
void iris_image_destroy(iris_image *img);
/* Index of the channel called `name`, or -1. */
int iris_image_channel(const iris_image *img, const char *name);

/* Writes every channel as FLOAT (ZIP compression) plus the metadata. */
iris_status iris_exr_write(const char *path, const iris_image *img, const iris_image_meta *meta,
                           size_t meta_count, iris_error *err);
/* Reads any scanline or tiled EXR; every channel is converted to float. The
 * string attributes are returned in *meta (malloc'ed; may be NULL). */
iris_status iris_exr_read(const char *path, iris_image *img, iris_image_meta **meta,
                          size_t *meta_count, iris_error *err);

/* Radiance .hdr (RGBE, flat or run-length encoded) through stb_image: three
 * float channels R, G, B, linear, top row first. A file that is not an HDR
 * image (stb would gamma-decode a PNG into floats) is refused. */
iris_status iris_hdr_read(const char *path, iris_image *img, iris_error *err);

/* 8-bit sRGB PNG from three channels (r, g, b at offsets c0, c0+1, c0+2) scaled
 * by 2^exposure; values are clamped after the sRGB transfer function. */
iris_status iris_png_write(const char *path, const iris_image *img, int c0, float exposure,
                           iris_error *err);

/* Decoded 8-bit texture (PNG or JPEG), RGBA, top row first. */
typedef struct iris_ldr_image {
  int width, height;
  uint8_t *rgba;
} iris_ldr_image;
iris_status iris_ldr_load_file(const char *path, iris_ldr_image *out, iris_error *err);
iris_status iris_ldr_load_memory(const void *data, size_t size, const char *what,
                                 iris_ldr_image *out, iris_error *err);
void iris_ldr_destroy(iris_ldr_image *img);
/* Width and height from an image's header without decoding it (PNG, JPEG,
 * Radiance .hdr; from `data` when not NULL, else from the file at `path`):
 * false when the header cannot be read. Used for memory estimates only. */
bool iris_image_dims(const char *path, const void *data, size_t size, int *w, int *h);

/* sRGB <-> linear transfer functions (IEC 61966-2-1). */
float iris_srgb_to_linear(float v);
float iris_linear_to_srgb(float v);

#ifdef __cplusplus
}
#endif
#endif
