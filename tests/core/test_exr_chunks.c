/* EXR chunks whose ZIP output is exactly as large as the raw data must still
 * read back bit for bit (OpenEXR 3.1 stores them compressed while readers take
 * them for raw; core/image.c stores them raw). A sweep over the number of
 * zero bytes in otherwise random data walks the compressed size across the
 * raw size one byte at a time, so some chunk lands on equality; the test also
 * checks, with zlib, that the sweep really crosses the raw size. */
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <zlib.h>

#include "check.h"
#include "core/image.h"
#include "core/rng.h"

int main(void) {
  char dir[512];
  if (iris_test_tmpdir(dir, sizeof dir, "exr_chunks") != 0) return 1;
  char path[700];
  snprintf(path, sizeof path, "%s/chunk.exr", dir);
  enum { W = 64, H = 16 }; /* one 16-line ZIP chunk of 4 KiB */
  const size_t raw = (size_t)W * H * sizeof(float);
  int below = 0, above = 0, mismatches = 0;
  for (size_t zeros = 0; zeros <= 512; zeros++) {
    iris_image img;
    const char *names[] = {"Y"};
    iris_error err = {0};
    if (iris_image_create(&img, W, H, 1, names, &err) != IRIS_OK) return 1;
    uint8_t *bytes = (uint8_t *)img.data;
    for (size_t i = 0; i < raw; i++)
      bytes[i] = i < zeros ? 0 : (uint8_t)(iris_mix64(i * 7919u + 13u) >> 56);
    /* Rough guide only: plain zlib of the bytes (OpenEXR reorders first). */
    uLongf out;
    static uint8_t zbuf[8192];
    out = sizeof zbuf;
    compress2(zbuf, &out, bytes, (uLong)raw, Z_DEFAULT_COMPRESSION);
    if (out < raw) below++; else above++;
    iris_status st = iris_exr_write(path, &img, NULL, 0, &err);
    CHECK(st == IRIS_OK);
    iris_image back;
    iris_error rerr = {0};
    if (st == IRIS_OK && iris_exr_read(path, &back, NULL, NULL, &rerr) == IRIS_OK) {
      if (back.width != W || back.height != H || memcmp(back.data, img.data, raw) != 0) {
        if (mismatches++ < 3) fprintf(stderr, "round trip differs with %zu zero bytes\n", zeros);
      }
      iris_image_destroy(&back);
    } else {
      mismatches++;
    }
    iris_image_destroy(&img);
  }
  CHECK_EQ_INT(mismatches, 0);
  CHECK(below > 0 && above > 0); /* the sweep crosses the raw size */
  iris_test_rmtree(dir);
  return iris_check_summary("core.exr_chunks");
}
