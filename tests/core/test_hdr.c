/* core.hdr: Radiance RGBE maps. A map of our own (run-length encoded, with
 * runs, literal dumps and one-texel features) reads back within RGBE's
 * precision; every cut of it short of its last byte (each scanline boundary
 * and every byte inside runs and dumps), the shared fuzz finding
 * env-truncated.hdr and cuts of the shared 1k sky map are refused with an
 * error naming the file; lying files (a zero run count, a run past the line's
 * end, a scanline declaring another width, more rows declared than stored)
 * are refused too. A hang in the decoder (stb_image loops for ever on a zero
 * count) ends the test through SIGALRM with the case that hung. */
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <stb_image_write.h>

#include "check.h"
#include "core/fileio.h"
#include "core/image.h"

static char dir[512];
static char current_case[640];

static void on_alarm(int sig) {
  (void)sig;
  static const char msg[] = "core.hdr: a read did not finish within 10 s (hang): ";
  if (write(2, msg, sizeof msg - 1) < 0 || write(2, current_case, strlen(current_case)) < 0 ||
      write(2, "\n", 1) < 0) {
  }
  _exit(1);
}

static int write_bytes(const char *path, const unsigned char *d, size_t n) {
  FILE *f = fopen(path, "wb");
  if (!f) return 0;
  int ok = fwrite(d, 1, n, f) == n;
  return fclose(f) == 0 && ok;
}

static unsigned char *read_all(const char *path, size_t *n) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  long len = ftell(f);
  fseek(f, 0, SEEK_SET);
  unsigned char *d = len > 0 ? malloc((size_t)len) : NULL;
  if (d && fread(d, 1, (size_t)len, f) != (size_t)len) {
    free(d);
    d = NULL;
  }
  fclose(f);
  *n = d ? (size_t)len : 0;
  return d;
}

/* Reads `n` bytes of `d` written to a file: must be refused, naming the file. */
static void expect_refused(const unsigned char *d, size_t n, const char *what) {
  char path[600];
  snprintf(path, sizeof path, "%s/cut.hdr", dir);
  snprintf(current_case, sizeof current_case, "%s (%zu bytes)", what, n);
  if (!CHECK(write_bytes(path, d, n))) return;
  iris_image img;
  iris_error err;
  iris_error_clear(&err);
  alarm(10);
  iris_status st = iris_hdr_read(path, &img, &err);
  alarm(0);
  if (!iris_check_record(st != IRIS_OK, __FILE__, __LINE__, "%s: accepted", current_case)) {
    iris_image_destroy(&img);
    return;
  }
  iris_check_record(strcmp(err.file, path) == 0 && err.message[0] && !strchr(err.message, '\n'),
                    __FILE__, __LINE__, "%s: error names '%s', message '%s'", current_case, err.file,
                    err.message);
}

/* A 40 x 12 map: constant spans (runs), noise (literal dumps), one-texel
 * peaks, a row of alternating texels and exponents from 2^-20 to 2^20. */
#define MW 40
#define MH 12
static void make_map(float *px) {
  uint32_t s = 12345;
  for (int y = 0; y < MH; y++)
    for (int x = 0; x < MW; x++) {
      float *p = px + 3 * (y * MW + x);
      s = s * 1664525u + 1013904223u;
      float noise = (float)(s >> 8) / 16777216.0f;
      if (y % 3 == 0) { /* runs */
        p[0] = x < 20 ? 0.5f : 2.0f;
        p[1] = 0.25f;
        p[2] = x < 30 ? 1.0f : 0.0f;
      } else if (y % 3 == 1) { /* dumps */
        p[0] = noise;
        p[1] = noise * 4.0f;
        p[2] = 1.0f - noise;
      } else { /* alternating, with a one-texel peak */
        float e = (float)((x % 41) - 20);
        p[0] = ldexpf(1.0f, (int)e);
        p[1] = (x & 1) ? 1.0f : 0.0f;
        p[2] = x == 7 ? 5000.0f : 0.125f;
      }
    }
}

int main(int argc, char **argv) {
  const char *shared = argc > 1 ? argv[1] : NULL; /* shared/ */
  signal(SIGALRM, on_alarm);
  if (iris_test_tmpdir(dir, sizeof dir, "hdr") != 0) return TEST_SKIP("no temporary directory");
  char path[600];
  snprintf(path, sizeof path, "%s/map.hdr", dir);
  static float px[MW * MH * 3];
  make_map(px);
  CHECK(stbi_write_hdr(path, MW, MH, 3, px));
  size_t n = 0;
  unsigned char *d = read_all(path, &n);
  if (!CHECK(d != NULL)) return TEST_SUMMARY();

  /* the whole map reads back within RGBE's 8-bit mantissa */
  iris_image img;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_hdr_read(path, &img, &err), &err);
  if (err.status == IRIS_OK) {
    CHECK_EQ_INT(img.width, MW);
    CHECK_EQ_INT(img.height, MH);
    int bad = 0;
    for (int i = 0; i < MW * MH; i++) {
      float m = fmaxf(px[3 * i], fmaxf(px[3 * i + 1], px[3 * i + 2]));
      for (int c = 0; c < 3; c++)
        if (fabsf(img.data[3 * i + c] - px[3 * i + c]) > m * (1.0f / 128.0f)) bad++;
    }
    CHECK_EQ_INT(bad, 0);
    iris_image_destroy(&img);
  }

  /* the pixel data starts after the resolution line; it is run-length
   * encoded (stb_image_write does for widths 8..32767) */
  const char *res = strstr((const char *)d, "+X 40\n");
  if (!CHECK(res != NULL)) return TEST_SUMMARY();
  const size_t data_at = (size_t)(res - (const char *)d) + 6;
  CHECK(d[data_at] == 2 && d[data_at + 1] == 2 && d[data_at + 2] == 0 && d[data_at + 3] == MW);

  /* every cut short of the last byte is refused */
  for (size_t cut = 0; cut < n; cut++) expect_refused(d, cut, "own map cut short");

  /* lies */
  unsigned char *m = malloc(n + 16);
  if (CHECK(m != NULL)) {
    memcpy(m, d, n);
    m[data_at + 4] = 0; /* a zero count: stb_image's endless loop */
    expect_refused(m, n, "zero run count");
    memcpy(m, d, n);
    m[data_at + 4] = 128 + MW + 1; /* a run past the line's end */
    expect_refused(m, n, "run past the end of the line");
    memcpy(m, d, n);
    m[data_at + 3] = MW - 1; /* scanline width */
    expect_refused(m, n, "scanline declares another width");
    /* more rows declared than stored: "-Y 12" -> "-Y 13" */
    memcpy(m, d, n);
    char *y = strstr((char *)m, "-Y 12");
    if (CHECK(y != NULL)) {
      y[4] = '3';
      expect_refused(m, n, "more rows declared than stored");
    }
    free(m);
  }
  free(d);

  if (shared) {
    char p2[600];
    snprintf(p2, sizeof p2, "%s/fuzz-findings/env-truncated.hdr", shared);
    size_t n2 = 0;
    unsigned char *d2 = read_all(p2, &n2);
    if (CHECK(d2 != NULL)) expect_refused(d2, n2, "fuzz-findings/env-truncated.hdr");
    free(d2);
    snprintf(p2, sizeof p2, "%s/assets/env/immenstadter_horn_1k.hdr", shared);
    d2 = read_all(p2, &n2);
    if (CHECK(d2 != NULL) && n2 > 4096) {
      /* cuts spread over the whole file, the last byte, and the cut sizes the
       * issue measured */
      const size_t fixed[] = {120, 300, 1024, 100000, 1000000, n2 - 1, n2 - 2, n2 - 4};
      for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++)
        if (fixed[i] < n2) expect_refused(d2, fixed[i], "shared map cut short");
      for (int k = 1; k < 40; k++) expect_refused(d2, n2 / 40 * (size_t)k + (size_t)k * 7, "shared map cut short");
      /* and the whole file still reads */
      iris_error_clear(&err);
      CHECK_OK(iris_hdr_read(p2, &img, &err), &err);
      if (err.status == IRIS_OK) iris_image_destroy(&img);
    }
    free(d2);
  }
  iris_test_rmtree(dir);
  return TEST_SUMMARY();
}
