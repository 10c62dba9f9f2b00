/* Float images and their files. EXR goes through the OpenEXRCore C API with
 * our own stream callbacks (so writes land in an iris_atomic_file and reads
 * see a size for header validation); PNG output through libpng; 8-bit
 * texture decoding through Debian's libstb (stb_image). */
#include "core/image.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <png.h>
#include <setjmp.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <OpenEXR/openexr.h>
#include <stb_image.h>

#include "core/exr_imf.h"
#include "core/fileio.h"

/* Limits that keep a corrupt or hostile header from asking for unbounded memory. */
#define IMAGE_MAX_DIM 65536
#define IMAGE_MAX_BYTES ((uint64_t)8 << 30) /* 8 GiB of float output */
/* Largest expansion of pixel data relative to the file size that a real EXR
 * reaches (ZIP of a constant image is about 1000:1); above it the header lies. */
#define EXR_MAX_EXPANSION 4096
#define EXR_SMALL_IMAGE_BYTES ((uint64_t)64 << 20)
#define LDR_MAX_PIXELS ((uint64_t)1 << 28)
/* stb_image decodes a truncated JPEG to the end as if zeros followed, so its
 * work follows the declared size, not the data: a 3.7 KB file declaring
 * 16384 x 16384 took 5.6 s and 1.4 GB. A flat JPEG holds about 60 pixels per
 * byte (stb_image_write, any quality); allow 1024 per byte plus 1 Mpixel. PNG
 * needs no such cap: its inflate stops when the data does. */
#define JPEG_MAX_PIXELS_PER_BYTE 1024
#define JPEG_SMALL_IMAGE_PIXELS ((uint64_t)1 << 20)
#define LDR_MAX_FILE ((size_t)1 << 30)

/* ---------------------------------------------------------------- images */

iris_status iris_image_create(iris_image *img, int width, int height, int channel_count,
                              const char *const *names, iris_error *err) {
  memset(img, 0, sizeof *img);
  if (width <= 0 || height <= 0 || width > IMAGE_MAX_DIM || height > IMAGE_MAX_DIM)
    return iris_error_set(err, IRIS_ERR_INVALID, NULL, 0, NULL, "bad image size %dx%d", width, height);
  if (channel_count <= 0 || channel_count > IRIS_IMAGE_MAX_CHANNELS)
    return iris_error_set(err, IRIS_ERR_INVALID, NULL, 0, NULL,
                          "bad channel count %d (1..%d)", channel_count, IRIS_IMAGE_MAX_CHANNELS);
  uint64_t n = (uint64_t)width * (uint64_t)height * (uint64_t)channel_count;
  if (n * sizeof(float) > IMAGE_MAX_BYTES)
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "image %dx%dx%d is too large", width,
                          height, channel_count);
  for (int c = 0; c < channel_count; c++) {
    const char *name = names ? names[c] : NULL;
    if (!name || !name[0] || strlen(name) >= sizeof img->channel_names[c])
      return iris_error_set(err, IRIS_ERR_INVALID, NULL, 0, NULL,
                            "channel %d: name must have 1..%zu characters", c,
                            sizeof img->channel_names[c] - 1);
    for (int k = 0; k < c; k++)
      if (strcmp(names[k], name) == 0)
        return iris_error_set(err, IRIS_ERR_INVALID, NULL, 0, NULL, "duplicate channel name '%s'", name);
  }
  img->data = calloc((size_t)n, sizeof(float));
  if (!img->data) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for image");
  img->width = width;
  img->height = height;
  img->channel_count = channel_count;
  for (int c = 0; c < channel_count; c++) strcpy(img->channel_names[c], names[c]);
  return IRIS_OK;
}

void iris_image_destroy(iris_image *img) {
  if (!img) return;
  free(img->data);
  memset(img, 0, sizeof *img);
}

int iris_image_channel(const iris_image *img, const char *name) {
  for (int c = 0; c < img->channel_count; c++)
    if (strcmp(img->channel_names[c], name) == 0) return c;
  return -1;
}

/* ------------------------------------------------------ sRGB transfer */

float iris_srgb_to_linear(float v) {
  if (v <= 0.04045f) return v / 12.92f;
  return powf((v + 0.055f) / 1.055f, 2.4f);
}

float iris_linear_to_srgb(float v) {
  if (v <= 0.0031308f) return 12.92f * v;
  return 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
}

/* ------------------------------------------------ OpenEXR stream glue */

/* Our stream for OpenEXRCore: a file descriptor plus the library's last
 * error message (the library reports through a callback, not a return). */
typedef struct exr_stream {
  int fd;
  int64_t size;
  char message[256];
} exr_stream;

/* OpenEXRCore calls the error handler with the context's lock held, so the
 * handler cannot ask the context for its user data; the stream in use is
 * found through this per-thread pointer instead (set for the duration of one
 * read or write call). */
static _Thread_local exr_stream *exr_current_stream;

static void exr_on_error(exr_const_context_t ctxt, exr_result_t code, const char *msg) {
  (void)ctxt;
  exr_stream *s = exr_current_stream;
  if (s && !s->message[0])
    snprintf(s->message, sizeof s->message, "%s", msg ? msg : exr_get_default_error_message(code));
}

static int64_t exr_stream_read(exr_const_context_t ctxt, void *userdata, void *buffer, uint64_t sz,
                               uint64_t offset, exr_stream_error_func_ptr_t error_cb) {
  exr_stream *s = userdata;
  if (offset > (uint64_t)INT64_MAX || sz > (uint64_t)INT64_MAX) return -1;
  uint8_t *p = buffer;
  uint64_t done = 0;
  while (done < sz) {
    ssize_t n = pread(s->fd, p + done, (size_t)(sz - done), (off_t)(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      if (error_cb) error_cb(ctxt, EXR_ERR_READ_IO, "read failed: %s", strerror(errno));
      return -1;
    }
    if (n == 0) break; /* end of file: the library reports the short read */
    done += (uint64_t)n;
  }
  return (int64_t)done;
}

static int64_t exr_stream_size(exr_const_context_t ctxt, void *userdata) {
  (void)ctxt;
  return ((exr_stream *)userdata)->size;
}

static int64_t exr_stream_write(exr_const_context_t ctxt, void *userdata, const void *buffer,
                                uint64_t sz, uint64_t offset, exr_stream_error_func_ptr_t error_cb) {
  exr_stream *s = userdata;
  const uint8_t *p = buffer;
  uint64_t done = 0;
  while (done < sz) {
    ssize_t n = pwrite(s->fd, p + done, (size_t)(sz - done), (off_t)(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (error_cb) error_cb(ctxt, EXR_ERR_WRITE_IO, "write failed: %s", strerror(errno));
      return -1;
    }
    done += (uint64_t)n;
  }
  return (int64_t)done;
}

static iris_status exr_fail(iris_error *err, iris_status status, const char *path, const exr_stream *s,
                            exr_result_t rv, const char *what) {
  const char *detail = s && s->message[0] ? s->message : exr_get_default_error_message(rv);
  return iris_error_set(err, status, path, 0, NULL, "%s: %s", what, detail);
}

/* -------------------------------------------------------- EXR writing */

/* OpenEXR 3.1's ZIP writer stores a chunk whose compressed size comes out
 * exactly equal to its raw size as compressed, while every reader takes a
 * chunk of raw size to be uncompressed, so that chunk reads back as garbage
 * (upstream issue #2306; seen on a 128x96x6 float image). The file format
 * says a chunk that does not shrink is stored raw: do that for >= as well. */
typedef struct exr_compressor {
  exr_result_t (*compress)(exr_encode_pipeline_t *enc);
} exr_compressor;

static exr_result_t exr_compress_or_store_raw(exr_encode_pipeline_t *enc) {
  const exr_compressor *c = (const exr_compressor *)enc->encoding_user_data;
  exr_result_t rv = c->compress(enc);
  if (rv != EXR_ERR_SUCCESS) return rv;
  if (enc->compressed_buffer && enc->compressed_buffer != enc->packed_buffer &&
      enc->compressed_bytes >= enc->packed_bytes) {
    if (enc->compressed_alloc_size < enc->packed_bytes) return EXR_ERR_OUT_OF_MEMORY;
    memcpy(enc->compressed_buffer, enc->packed_buffer, enc->packed_bytes);
    enc->compressed_bytes = enc->packed_bytes;
  }
  return EXR_ERR_SUCCESS;
}

static iris_status exr_write_pixels(exr_context_t ctx, const iris_image *img, const char *path,
                                    const exr_stream *s, iris_error *err) {
  int32_t lines = 0;
  exr_result_t rv = exr_get_scanlines_per_chunk(ctx, 0, &lines);
  if (rv != EXR_ERR_SUCCESS || lines <= 0) return exr_fail(err, IRIS_ERR_INTERNAL, path, s, rv, "cannot write EXR");
  exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
  exr_compressor compressor = {NULL};
  bool started = false;
  iris_status st = IRIS_OK;
  const size_t pixel_stride = (size_t)img->channel_count * sizeof(float);
  for (int y = 0; y < img->height && st == IRIS_OK; y += lines) {
    exr_chunk_info_t cinfo;
    rv = exr_write_scanline_chunk_info(ctx, 0, y, &cinfo);
    if (rv == EXR_ERR_SUCCESS)
      rv = started ? exr_encoding_update(ctx, 0, &cinfo, &enc) : exr_encoding_initialize(ctx, 0, &cinfo, &enc);
    if (rv != EXR_ERR_SUCCESS) {
      st = exr_fail(err, IRIS_ERR_IO, path, s, rv, "cannot write EXR");
      break;
    }
    /* The header keeps channels sorted by name; map each back to ours. */
    for (int k = 0; k < enc.channel_count; k++) {
      exr_coding_channel_info_t *ch = &enc.channels[k];
      int c = iris_image_channel(img, ch->channel_name);
      IRIS_CHECK(c >= 0);
      ch->encode_from_ptr = (const uint8_t *)&img->data[(size_t)y * (size_t)img->width * (size_t)img->channel_count + (size_t)c];
      ch->user_pixel_stride = (int32_t)pixel_stride;
      ch->user_line_stride = (int32_t)(pixel_stride * (size_t)img->width);
      ch->user_bytes_per_element = 4;
      ch->user_data_type = EXR_PIXEL_FLOAT;
    }
    if (!started) {
      rv = exr_encoding_choose_default_routines(ctx, 0, &enc);
      started = true;
      if (rv == EXR_ERR_SUCCESS && enc.compress_fn) {
        compressor.compress = enc.compress_fn;
        enc.encoding_user_data = &compressor;
        enc.compress_fn = exr_compress_or_store_raw;
      }
    }
    if (rv == EXR_ERR_SUCCESS) rv = exr_encoding_run(ctx, 0, &enc);
    if (rv != EXR_ERR_SUCCESS) st = exr_fail(err, IRIS_ERR_IO, path, s, rv, "cannot write EXR");
  }
  if (started) exr_encoding_destroy(ctx, &enc);
  return st;
}

iris_status iris_exr_write(const char *path, const iris_image *img, const iris_image_meta *meta,
                           size_t meta_count, iris_error *err) {
  if (!img || !img->data || img->width <= 0 || img->height <= 0 || img->channel_count <= 0 ||
      img->channel_count > IRIS_IMAGE_MAX_CHANNELS)
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL, "cannot write EXR: empty or malformed image");
  iris_atomic_file af;
  iris_status st = iris_atomic_open(&af, path, err);
  if (st != IRIS_OK) return st;

  exr_stream s = {.fd = fileno(af.fp), .size = 0, .message = ""};
  exr_current_stream = &s;
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.error_handler_fn = exr_on_error;
  init.user_data = &s;
  init.write_fn = exr_stream_write;
  exr_context_t ctx = NULL;
  exr_result_t rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
  int part = 0;
  if (rv == EXR_ERR_SUCCESS) rv = exr_add_part(ctx, "rgba", EXR_STORAGE_SCANLINE, &part);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_initialize_required_attr_simple(ctx, part, img->width, img->height, EXR_COMPRESSION_ZIP);
  for (int c = 0; c < img->channel_count && rv == EXR_ERR_SUCCESS; c++) {
    for (int k = 0; k < c; k++)
      if (strcmp(img->channel_names[k], img->channel_names[c]) == 0) {
        exr_finish(&ctx);
        exr_current_stream = NULL;
        iris_atomic_abort(&af);
        return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL,
                              "cannot write EXR: duplicate channel '%s'", img->channel_names[c]);
      }
    rv = exr_add_channel(ctx, part, img->channel_names[c], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, 1, 1);
  }
  /* Names over 31 bytes need the (OpenEXR 1.7+) long-name header flag. */
  bool long_names = false;
  for (size_t i = 0; i < meta_count; i++) long_names |= strlen(meta[i].key) > 31;
  if (long_names && rv == EXR_ERR_SUCCESS) rv = exr_set_longname_support(ctx, 1);
  for (size_t i = 0; i < meta_count && rv == EXR_ERR_SUCCESS; i++)
    rv = exr_attr_set_string(ctx, part, meta[i].key, meta[i].value);
  if (rv != EXR_ERR_SUCCESS) {
    st = exr_fail(err, IRIS_ERR_INVALID, path, &s, rv, "cannot write EXR header");
  } else if ((rv = exr_write_header(ctx)) != EXR_ERR_SUCCESS) {
    st = exr_fail(err, IRIS_ERR_IO, path, &s, rv, "cannot write EXR");
  } else {
    st = exr_write_pixels(ctx, img, path, &s, err);
  }
  if (ctx) {
    rv = exr_finish(&ctx); /* writes the chunk offset table */
    if (rv != EXR_ERR_SUCCESS && st == IRIS_OK) st = exr_fail(err, IRIS_ERR_IO, path, &s, rv, "cannot write EXR");
  }
  exr_current_stream = NULL;
  if (st != IRIS_OK) {
    iris_atomic_abort(&af);
    return st;
  }
  return iris_atomic_commit(&af, err);
}

/* -------------------------------------------------------- EXR reading */

/* Decoding goes into a buffer with one spare float per pixel (stride C + 1).
 * OpenEXRCore 3.1 picks hand-written unpackers for 3- and 4-channel half data
 * written "simply interleaved", and its 4-channel one puts the channels in the
 * wrong slots (it assumes R,G,B,A order while the file order is A,B,G,R).
 * With the spare float no special case matches and the generic, per-channel
 * unpacker runs; the padding is squeezed out afterwards. */
typedef struct exr_target {
  float *data; /* width * height * (channel_count + 1) */
  int width, height, channel_count;
} exr_target;

/* Points the decoder's channels at the target for a block whose top-left
 * pixel is (x0, y0). Channels are decoded in header order, which is ours. */
static void exr_point_channels(exr_decode_pipeline_t *dec, const exr_target *t, int x0, int y0) {
  const size_t stride = (size_t)t->channel_count + 1;
  for (int k = 0; k < dec->channel_count; k++) {
    exr_coding_channel_info_t *ch = &dec->channels[k];
    ch->decode_to_ptr = (uint8_t *)&t->data[((size_t)y0 * (size_t)t->width + (size_t)x0) * stride + (size_t)k];
    ch->user_pixel_stride = (int32_t)(stride * sizeof(float));
    ch->user_line_stride = (int32_t)(stride * sizeof(float) * (size_t)t->width);
    ch->user_bytes_per_element = 4;
    ch->user_data_type = EXR_PIXEL_FLOAT;
  }
}

/* Decodes one chunk whose pixels start at (x0, y0) of the image. */
static exr_result_t exr_decode_chunk(exr_context_t ctx, const exr_chunk_info_t *cinfo,
                                     exr_decode_pipeline_t *dec, bool *started, const exr_target *img,
                                     int x0, int y0) {
  if (cinfo->width <= 0 || cinfo->height <= 0 || x0 < 0 || y0 < 0 || cinfo->width > img->width - x0 ||
      cinfo->height > img->height - y0)
    return EXR_ERR_CORRUPT_CHUNK;
  exr_result_t rv = *started ? exr_decoding_update(ctx, 0, cinfo, dec) : exr_decoding_initialize(ctx, 0, cinfo, dec);
  if (rv != EXR_ERR_SUCCESS) return rv;
  if (dec->channel_count != img->channel_count) return EXR_ERR_CORRUPT_CHUNK;
  for (int k = 0; k < dec->channel_count; k++)
    if (dec->channels[k].width != cinfo->width || dec->channels[k].height != cinfo->height)
      return EXR_ERR_CORRUPT_CHUNK;
  exr_point_channels(dec, img, x0, y0);
  if (!*started) {
    rv = exr_decoding_choose_default_routines(ctx, 0, dec);
    *started = true;
    if (rv != EXR_ERR_SUCCESS) return rv;
  }
  return exr_decoding_run(ctx, 0, dec);
}

static iris_status exr_read_pixels(exr_context_t ctx, exr_storage_t storage, const char *path,
                                   const exr_stream *s, const exr_target *img, iris_error *err) {
  exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
  bool started = false;
  exr_result_t rv = EXR_ERR_SUCCESS;
  exr_attr_box2i_t dw;
  rv = exr_get_data_window(ctx, 0, &dw);
  if (storage == EXR_STORAGE_SCANLINE) {
    int32_t lines = 0;
    if (rv == EXR_ERR_SUCCESS) rv = exr_get_scanlines_per_chunk(ctx, 0, &lines);
    if (rv == EXR_ERR_SUCCESS && lines <= 0) rv = EXR_ERR_CORRUPT_CHUNK;
    for (int row = 0; row < img->height && rv == EXR_ERR_SUCCESS; row += lines) {
      exr_chunk_info_t cinfo;
      rv = exr_read_scanline_chunk_info(ctx, 0, dw.min.y + row, &cinfo);
      if (rv != EXR_ERR_SUCCESS) break;
      /* A chunk holding rows above the data window would write out of bounds. */
      if (cinfo.start_y != dw.min.y + row) {
        rv = EXR_ERR_CORRUPT_CHUNK;
        break;
      }
      rv = exr_decode_chunk(ctx, &cinfo, &dec, &started, img, 0, row);
    }
  } else {
    uint32_t tw = 0, th = 0;
    exr_tile_level_mode_t level_mode;
    exr_tile_round_mode_t round_mode;
    if (rv == EXR_ERR_SUCCESS) rv = exr_get_tile_descriptor(ctx, 0, &tw, &th, &level_mode, &round_mode);
    if (rv == EXR_ERR_SUCCESS && (tw == 0 || th == 0)) rv = EXR_ERR_INVALID_ATTR;
    /* Level 0 (full resolution) only; mip/rip levels are ignored. */
    for (int ty = 0; rv == EXR_ERR_SUCCESS && (uint64_t)ty * th < (uint64_t)img->height; ty++)
      for (int tx = 0; rv == EXR_ERR_SUCCESS && (uint64_t)tx * tw < (uint64_t)img->width; tx++) {
        exr_chunk_info_t cinfo;
        rv = exr_read_tile_chunk_info(ctx, 0, tx, ty, 0, 0, &cinfo);
        if (rv == EXR_ERR_SUCCESS)
          rv = exr_decode_chunk(ctx, &cinfo, &dec, &started, img, (int)((uint64_t)tx * tw), (int)((uint64_t)ty * th));
      }
  }
  if (started || dec.channels) exr_decoding_destroy(ctx, &dec);
  if (rv != EXR_ERR_SUCCESS) return exr_fail(err, IRIS_ERR_PARSE, path, s, rv, "corrupt EXR pixel data");
  return IRIS_OK;
}

/* Copies the string attributes of part 0 into a malloc'ed meta array. */
static iris_status exr_read_meta(exr_context_t ctx, const char *path, iris_image_meta **meta,
                                 size_t *meta_count, iris_error *err) {
  int32_t count = 0;
  if (exr_get_attribute_count(ctx, 0, &count) != EXR_ERR_SUCCESS || count <= 0) return IRIS_OK;
  iris_image_meta *out = calloc((size_t)count, sizeof *out);
  if (!out) return iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "out of memory for EXR metadata");
  size_t n = 0;
  for (int32_t i = 0; i < count; i++) {
    const exr_attribute_t *a = NULL;
    if (exr_get_attribute_by_index(ctx, 0, EXR_ATTR_LIST_FILE_ORDER, i, &a) != EXR_ERR_SUCCESS || !a) continue;
    if (a->type != EXR_ATTR_STRING || !a->string || !a->name) continue;
    if (strlen(a->name) >= sizeof out[n].key) continue; /* cannot be represented: skip */
    strcpy(out[n].key, a->name);
    size_t len = a->string->length > 0 ? (size_t)a->string->length : 0;
    if (len >= sizeof out[n].value) len = sizeof out[n].value - 1; /* long values are truncated */
    if (len && a->string->str) memcpy(out[n].value, a->string->str, len);
    out[n].value[len] = '\0';
    n++;
  }
  if (n == 0) {
    free(out);
    return IRIS_OK;
  }
  *meta = out;
  *meta_count = n;
  return IRIS_OK;
}

iris_status iris_exr_read(const char *path, iris_image *img, iris_image_meta **meta,
                          size_t *meta_count, iris_error *err) {
  memset(img, 0, sizeof *img);
  if (meta) *meta = NULL;
  if (meta_count) *meta_count = 0;

  exr_stream s = {.fd = -1, .size = 0, .message = ""};
  s.fd = open(path, O_RDONLY);
  if (s.fd < 0) return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "cannot open: %s", strerror(errno));
  struct stat sb;
  if (fstat(s.fd, &sb) != 0 || !S_ISREG(sb.st_mode)) {
    close(s.fd);
    return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "not a regular file");
  }
  s.size = (int64_t)sb.st_size;
  exr_current_stream = &s;

  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.error_handler_fn = exr_on_error;
  init.user_data = &s;
  init.read_fn = exr_stream_read;
  init.size_fn = exr_stream_size;
  init.max_image_width = IMAGE_MAX_DIM;
  init.max_image_height = IMAGE_MAX_DIM;
  init.max_tile_width = IMAGE_MAX_DIM;
  init.max_tile_height = IMAGE_MAX_DIM;
  exr_context_t ctx = NULL;
  iris_status st = IRIS_OK;
  exr_result_t rv = exr_start_read(&ctx, path, &init);
  exr_storage_t storage = EXR_STORAGE_SCANLINE;
  exr_attr_box2i_t dw;
  const exr_attr_chlist_t *chl = NULL;
  int parts = 0;
  if (rv == EXR_ERR_SUCCESS) rv = exr_get_count(ctx, &parts);
  if (rv == EXR_ERR_SUCCESS && parts < 1) rv = EXR_ERR_FILE_BAD_HEADER;
  if (rv == EXR_ERR_SUCCESS) rv = exr_get_storage(ctx, 0, &storage);
  if (rv == EXR_ERR_SUCCESS) rv = exr_get_data_window(ctx, 0, &dw);
  if (rv == EXR_ERR_SUCCESS) rv = exr_get_channels(ctx, 0, &chl);
  if (rv == EXR_ERR_SUCCESS && !chl) rv = EXR_ERR_MISSING_REQ_ATTR;
  if (rv != EXR_ERR_SUCCESS) {
    st = exr_fail(err, IRIS_ERR_PARSE, path, &s, rv, "not a readable EXR");
    goto done;
  }
  if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED) {
    st = iris_error_set(err, IRIS_ERR_UNSUPPORTED, path, 0, NULL, "deep EXR images are not supported");
    goto done;
  }
  int64_t w64 = (int64_t)dw.max.x - dw.min.x + 1, h64 = (int64_t)dw.max.y - dw.min.y + 1;
  if (w64 <= 0 || h64 <= 0 || w64 > IMAGE_MAX_DIM || h64 > IMAGE_MAX_DIM) {
    st = iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL, "EXR data window %lldx%lld is out of range",
                        (long long)w64, (long long)h64);
    goto done;
  }
  if (chl->num_channels <= 0 || chl->num_channels > IRIS_IMAGE_MAX_CHANNELS) {
    st = iris_error_set(err, IRIS_ERR_UNSUPPORTED, path, 0, NULL, "EXR has %d channels (iris reads 1..%d)",
                        chl->num_channels, IRIS_IMAGE_MAX_CHANNELS);
    goto done;
  }
  const char *names[IRIS_IMAGE_MAX_CHANNELS];
  for (int c = 0; c < chl->num_channels; c++) {
    const exr_attr_chlist_entry_t *e = &chl->entries[c];
    if (e->x_sampling != 1 || e->y_sampling != 1) {
      st = iris_error_set(err, IRIS_ERR_UNSUPPORTED, path, 0, NULL, "EXR channel '%s' is subsampled",
                          e->name.str ? e->name.str : "?");
      goto done;
    }
    if (e->pixel_type != EXR_PIXEL_UINT && e->pixel_type != EXR_PIXEL_HALF && e->pixel_type != EXR_PIXEL_FLOAT) {
      st = iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "EXR channel has bad pixel type %d", (int)e->pixel_type);
      goto done;
    }
    names[c] = e->name.str;
    if (!names[c] || strlen(names[c]) >= sizeof img->channel_names[0]) {
      st = iris_error_set(err, IRIS_ERR_UNSUPPORTED, path, 0, NULL, "EXR channel name '%.40s...' is too long",
                          names[c] ? names[c] : "");
      goto done;
    }
  }
  uint64_t bytes = (uint64_t)w64 * (uint64_t)h64 * (uint64_t)chl->num_channels * sizeof(float);
  if (bytes > EXR_SMALL_IMAGE_BYTES && bytes / EXR_MAX_EXPANSION > (uint64_t)s.size) {
    st = iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL,
                        "EXR header declares %lldx%lld pixels, far more than a %lld-byte file can hold",
                        (long long)w64, (long long)h64, (long long)s.size);
    goto done;
  }
  st = iris_image_create(img, (int)w64, (int)h64, chl->num_channels, names, err);
  if (st != IRIS_OK) {
    if (err) snprintf(err->file, sizeof err->file, "%s", path);
    goto done;
  }
  exr_compression_t comp = EXR_COMPRESSION_NONE;
  exr_get_compression(ctx, 0, &comp);
  if (comp == EXR_COMPRESSION_DWAA || comp == EXR_COMPRESSION_DWAB) {
    /* OpenEXRCore 3.1 has no DWA decoder; the C++ library has. */
    char msg[256] = "";
    if (iris_exr_imf_read_pixels(path, img->width, img->height, img->channel_count, names, img->data, msg,
                                 sizeof msg) != 0)
      st = iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "corrupt EXR pixel data: %s", msg);
  } else {
    const size_t pixels = (size_t)img->width * (size_t)img->height, nc = (size_t)img->channel_count;
    exr_target t = {calloc(pixels * (nc + 1), sizeof(float)), img->width, img->height, img->channel_count};
    if (!t.data) {
      st = iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "out of memory for EXR pixels");
    } else {
      st = exr_read_pixels(ctx, storage, path, &s, &t, err);
      for (size_t p = 0; p < pixels && st == IRIS_OK; p++)
        memcpy(&img->data[p * nc], &t.data[p * (nc + 1)], nc * sizeof(float));
      free(t.data);
    }
  }
  if (st == IRIS_OK && meta && meta_count) st = exr_read_meta(ctx, path, meta, meta_count, err);
  if (st != IRIS_OK) iris_image_destroy(img);
done:
  if (ctx) exr_finish(&ctx);
  exr_current_stream = NULL;
  close(s.fd);
  return st;
}

/* ---------------------------------------------------------------- PNG */

static void png_on_error(png_structp png, png_const_charp msg) {
  char *buf = png_get_error_ptr(png);
  if (buf) snprintf(buf, 256, "%s", msg);
  png_longjmp(png, 1);
}

static void png_on_warning(png_structp png, png_const_charp msg) {
  (void)png;
  (void)msg;
}

static uint8_t png_encode(float linear, float scale) {
  float v = linear * scale;
  if (!(v > 0.0f)) return 0; /* negative and NaN */
  v = iris_linear_to_srgb(v);
  if (!(v < 1.0f)) return 255; /* includes +inf */
  return (uint8_t)(v * 255.0f + 0.5f);
}

iris_status iris_png_write(const char *path, const iris_image *img, int c0, float exposure,
                           iris_error *err) {
  if (!img || !img->data || img->width <= 0 || img->height <= 0)
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL, "cannot write PNG: empty image");
  if (c0 < 0 || c0 + 3 > img->channel_count)
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL,
                          "cannot write PNG: channels %d..%d do not exist (image has %d)", c0, c0 + 2,
                          img->channel_count);
  if (!isfinite(exposure))
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL, "cannot write PNG: exposure is not finite");
  const float scale = exp2f(exposure);
  const size_t w = (size_t)img->width, h = (size_t)img->height, nc = (size_t)img->channel_count;
  uint8_t *pixels = malloc(w * h * 3);
  png_bytep *rows = malloc(h * sizeof *rows);
  if (!pixels || !rows) {
    free(pixels);
    free(rows);
    return iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "out of memory for PNG");
  }
  for (size_t y = 0; y < h; y++) {
    rows[y] = pixels + y * w * 3;
    for (size_t x = 0; x < w; x++)
      for (size_t k = 0; k < 3; k++)
        rows[y][x * 3 + k] = png_encode(img->data[(y * w + x) * nc + (size_t)c0 + k], scale);
  }

  iris_atomic_file af;
  iris_status st = iris_atomic_open(&af, path, err);
  if (st != IRIS_OK) {
    free(pixels);
    free(rows);
    return st;
  }
  char message[256] = "";
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, message, png_on_error, png_on_warning);
  png_infop info = png ? png_create_info_struct(png) : NULL;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    st = iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "cannot start PNG writer");
  } else if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    st = iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "cannot write PNG: %s", message);
  } else {
    png_init_io(png, af.fp);
    png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
  }
  free(pixels);
  free(rows);
  if (st != IRIS_OK) {
    iris_atomic_abort(&af);
    return st;
  }
  return iris_atomic_commit(&af, err);
}

/* -------------------------------------------------- 8-bit textures */

iris_status iris_ldr_load_memory(const void *data, size_t size, const char *what,
                                 iris_ldr_image *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  if (!what) what = "image";
  if (!data || size == 0) return iris_error_set(err, IRIS_ERR_PARSE, what, 0, NULL, "empty image data");
  if (size > (size_t)INT32_MAX) return iris_error_set(err, IRIS_ERR_NOMEM, what, 0, NULL, "image data is too large");
  /* Only PNG and JPEG reach stb_image: its other decoders are not needed and
   * not safe (fuzz_texture crashed Debian's stb_image with a 12-byte PNM).
   * A JPEG may start with 0xFF fill bytes before its SOI marker. */
  {
    const unsigned char *q = data;
    size_t i = 0;
    while (i < size && q[i] == 0xFF) i++;
    const bool png = size >= 8 && !memcmp(q, "\x89PNG\r\n\x1a\n", 8), jpeg = i >= 1 && i < size && q[i] == 0xD8;
    if (!png && !jpeg)
      return iris_error_set(err, IRIS_ERR_PARSE, what, 0, NULL, "cannot decode image: not a PNG or JPEG");
  }
  /* stb_image grows its buffer to each PNG chunk's declared length before
   * reading it: a 143-byte file declaring a 1.5 GB IDAT made it allocate 2 GB
   * (found by fuzz_texture). Every chunk, its CRC included, must fit in the
   * bytes present — also the last one, whose header alone may end the data
   * (a 113-byte file ending in a 1.2 GB IDAT's length and type: fuzz_texture
   * again), and a piece of a header is refused too. */
  const unsigned char *pb = data;
  if (size >= 8 && !memcmp(pb, "\x89PNG\r\n\x1a\n", 8)) { /* PNG signature */
    size_t at = 8;
    while (at < size) {
      if (size - at < 12)
        return iris_error_set(err, IRIS_ERR_PARSE, what, 0, NULL,
                              "PNG chunk at offset %zu is cut short (truncated or corrupt)", at);
      const size_t len = (size_t)pb[at] << 24 | (size_t)pb[at + 1] << 16 | (size_t)pb[at + 2] << 8 | pb[at + 3];
      if (len > size - at - 12)
        return iris_error_set(err, IRIS_ERR_PARSE, what, 0, NULL,
                              "PNG chunk of %zu bytes at offset %zu exceeds the data (truncated or corrupt)", len, at);
      if (!memcmp(pb + at + 4, "IEND", 4)) break;
      at += len + 12;
    }
  }
  int w = 0, h = 0, n = 0;
  if (!stbi_info_from_memory(data, (int)size, &w, &h, &n))
    return iris_error_set(err, IRIS_ERR_PARSE, what, 0, NULL, "cannot decode image: %s", stbi_failure_reason());
  if (w <= 0 || h <= 0 || w > IMAGE_MAX_DIM || h > IMAGE_MAX_DIM || (uint64_t)w * (uint64_t)h > LDR_MAX_PIXELS)
    return iris_error_set(err, IRIS_ERR_INVALID, what, 0, NULL, "image size %dx%d is out of range", w, h);
  /* Any format but PNG (stb_image also finds a JPEG behind leading 0xFF fill
   * bytes, so there is no reliable JPEG signature to test for). */
  const bool is_png = size >= 8 && !memcmp(data, "\x89PNG\r\n\x1a\n", 8);
  if (!is_png && (uint64_t)w * (uint64_t)h > JPEG_MAX_PIXELS_PER_BYTE * (uint64_t)size + JPEG_SMALL_IMAGE_PIXELS)
    return iris_error_set(err, IRIS_ERR_INVALID, what, 0, NULL,
                          "image declares %dx%d pixels, more than its %zu bytes can hold (truncated or corrupt)",
                          w, h, size);
  uint8_t *rgba = stbi_load_from_memory(data, (int)size, &w, &h, &n, 4);
  if (!rgba)
    return iris_error_set(err, IRIS_ERR_PARSE, what, 0, NULL, "cannot decode image: %s", stbi_failure_reason());
  out->rgba = rgba; /* released with stbi_image_free in iris_ldr_destroy */
  out->width = w;
  out->height = h;
  return IRIS_OK;
}

iris_status iris_ldr_load_file(const char *path, iris_ldr_image *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  char *data = NULL;
  size_t size = 0;
  iris_status st = iris_file_read(path, LDR_MAX_FILE, &data, &size, err);
  if (st != IRIS_OK) return st;
  st = iris_ldr_load_memory(data, size, path, out, err);
  free(data);
  return st;
}

/* Walks a Radiance RGBE file's pixel data the way stb_image's decoder reads
 * it and checks that every read stays inside the data, before the decoder
 * runs. stb_image (Debian's 2022 snapshot) reads a zero byte past the end and
 * takes a zero run count as a dump of nothing, so a file cut inside its
 * run-length data (or one holding a zero count) makes it loop for ever
 * (shared/fuzz-findings/env-truncated.hdr). The walk is linear in the file
 * size: each step consumes at least one byte or ends. w and h come from
 * stbi_info; the header is skipped line by line as stb_image reads it (lines
 * end at '\n'; a line whose first byte is NUL ends the header as an empty one
 * does). */
static iris_status hdr_check_stream(const unsigned char *d, size_t size, int w, int h, const char *path,
                                    iris_error *err) {
  size_t at = 0;
  int empty_seen = 0;
  for (int line = 0;; line++) { /* signature, header lines, blank line, resolution */
    const size_t start = at;
    while (at < size && d[at] != '\n') at++;
    if (at >= size)
      return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL,
                            "HDR header ends without pixel data (truncated at byte %zu)", size);
    const bool empty = at == start || d[start] == 0;
    at++; /* past '\n' */
    if (empty_seen) break; /* that was the resolution line */
    if (line > 0 && empty) empty_seen = 1;
  }
  const uint64_t need_flat = (uint64_t)w * (uint64_t)h * 4u;
  if (w < 8 || w >= 32768) {
    if (size - at < need_flat)
      return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL,
                            "HDR pixel data is cut short: %zu bytes of the %llu a %dx%d flat image needs "
                            "(truncated file)", size - at, (unsigned long long)need_flat, w, h);
    return IRIS_OK;
  }
  for (int y = 0; y < h; y++) {
    if (size - at < 4)
      return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL,
                            "HDR pixel data ends at scanline %d of %d (truncated file)", y, h);
    const unsigned c1 = d[at], c2 = d[at + 1], hi = d[at + 2], lo = d[at + 3];
    if (c1 != 2 || c2 != 2 || (hi & 0x80)) {
      /* not run-length encoded: stb_image then reads the whole image flat
       * from here, which only makes sense for the first scanline */
      if (y > 0)
        return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL,
                              "HDR scanline %d is not run-length encoded after %d that are "
                              "(mixed encodings are not supported; corrupt file?)", y, y);
      if (size - at < need_flat)
        return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL,
                              "HDR pixel data is cut short: %zu bytes of the %llu a %dx%d flat image needs "
                              "(truncated file)", size - at, (unsigned long long)need_flat, w, h);
      return IRIS_OK;
    }
    if ((int)(hi << 8 | lo) != w)
      return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL,
                            "HDR scanline %d declares width %u, the image is %d wide (corrupt file)", y,
                            hi << 8 | lo, w);
    at += 4;
    for (int k = 0; k < 4; k++) {
      int x = 0;
      while (x < w) {
        if (at >= size)
          return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL,
                                "HDR run-length data ends inside scanline %d of %d (truncated file)", y, h);
        unsigned count = d[at++];
        size_t bytes;
        if (count > 128) {
          count -= 128;
          bytes = 1;
        } else {
          bytes = count;
        }
        if (count == 0 || (int)count > w - x)
          return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL,
                                "HDR scanline %d, channel %d: run of %u at pixel %d overruns the %d-pixel "
                                "line (corrupt file)", y, k, count, x, w);
        if (size - at < bytes)
          return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL,
                                "HDR run-length data ends inside scanline %d of %d (truncated file)", y, h);
        at += bytes;
        x += (int)count;
      }
    }
  }
  return IRIS_OK;
}

iris_status iris_hdr_read(const char *path, iris_image *img, iris_error *err) {
  memset(img, 0, sizeof *img);
  char *data = NULL;
  size_t size = 0;
  iris_status st = iris_file_read(path, LDR_MAX_FILE, &data, &size, err);
  if (st != IRIS_OK) return st;
  if (size == 0) {
    free(data);
    return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "empty file");
  }
  if (size > (size_t)INT32_MAX || !stbi_is_hdr_from_memory((const stbi_uc *)data, (int)size)) {
    free(data);
    return iris_error_set(err, IRIS_ERR_UNSUPPORTED, path, 0, NULL,
                          "not a Radiance HDR image (no '#?RADIANCE' or '#?RGBE' header)");
  }
  int w = 0, h = 0, n = 0;
  if (!stbi_info_from_memory((const stbi_uc *)data, (int)size, &w, &h, &n) || w <= 0 || h <= 0 ||
      w > IMAGE_MAX_DIM || h > IMAGE_MAX_DIM || (uint64_t)w * (uint64_t)h > LDR_MAX_PIXELS) {
    free(data);
    return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "cannot decode HDR image: %s",
                          w > 0 && h > 0 ? "image size out of range" : stbi_failure_reason());
  }
  st = hdr_check_stream((const unsigned char *)data, size, w, h, path, err);
  if (st != IRIS_OK) {
    free(data);
    return st;
  }
  float *px = stbi_loadf_from_memory((const stbi_uc *)data, (int)size, &w, &h, &n, 3);
  free(data);
  if (!px) return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "cannot decode HDR image: %s", stbi_failure_reason());
  static const char *const rgb[3] = {"R", "G", "B"};
  st = iris_image_create(img, w, h, 3, rgb, err);
  if (st == IRIS_OK) memcpy(img->data, px, sizeof(float) * 3 * (size_t)w * (size_t)h);
  stbi_image_free(px);
  return st;
}

void iris_ldr_destroy(iris_ldr_image *img) {
  if (!img) return;
  stbi_image_free(img->rgba);
  memset(img, 0, sizeof *img);
}

bool iris_image_dims(const char *path, const void *data, size_t size, int *w, int *h) {
  int n = 0;
  *w = *h = 0;
  if (data) {
    if (size > (size_t)INT32_MAX) return false;
    return stbi_info_from_memory((const stbi_uc *)data, (int)size, w, h, &n) && *w > 0 && *h > 0;
  }
  if (!path) return false;
  FILE *fp = fopen(path, "rb");
  if (!fp) return false;
  bool ok = stbi_info_from_file(fp, w, h, &n) && *w > 0 && *h > 0;
  fclose(fp);
  return ok;
}
