/* relmse: the benchmarks' relMSE (validate/metrics.h: eps 0.01, largest 0.1%
 * of pixel errors dropped) of one EXR against a reference EXR, channels taken
 * by name (R, G, B). Usage: relmse IMAGE.exr REFERENCE.exr
 *                           relmse --own IMAGE.exr   (from its var.R/G/B)
 *                           relmse --expected IMAGE.exr REFERENCE.exr
 *   (the expected relMSE of IMAGE against the true image: the mean over
 *   pixels and channels of its var.R/G/B / (REF^2 + eps), nothing dropped;
 *   for scenes whose references are too noisy to measure against,
 *   docs/guiding.md "Sky behind glass")
 *                           relmse --raw IMAGE.exr OUT.f32
 *   (writes width, height as two int32 and then per pixel R, G, B, var.R,
 *   var.G, var.B as float32, the variances 0 when absent: for numpy)
 * Prints the relMSE; exit 2 on unreadable or mismatched images. Used by
 * bench/render/equal_spp.sh to compare iris and Cycles at equal spp. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/image.h"
#include "validate/metrics.h"

/* Reads an EXR, saying why not on stderr. */
static int read_exr(const char *path, iris_image *img) {
  iris_error err;
  iris_error_clear(&err);
  if (iris_exr_read(path, img, NULL, NULL, &err) == IRIS_OK) return 1;
  fprintf(stderr, "relmse: %s: %s\n", path, err.message);
  return 0;
}

static int load_rgb(const char *path, iris_image *out) {
  iris_image img;
  if (!read_exr(path, &img)) return 0;
  static const char *const names[3] = {"R", "G", "B"};
  int ch[3];
  for (int c = 0; c < 3; c++)
    if ((ch[c] = iris_image_channel(&img, names[c])) < 0) {
      fprintf(stderr, "relmse: %s: no channel %s\n", path, names[c]);
      iris_image_destroy(&img);
      return 0;
    }
  iris_error err;
  iris_error_clear(&err);
  if (iris_image_create(out, img.width, img.height, 3, names, &err) != IRIS_OK) {
    fprintf(stderr, "relmse: %s: %s\n", path, err.message);
    iris_image_destroy(&img);
    return 0;
  }
  for (size_t i = 0; i < (size_t)img.width * (size_t)img.height; i++)
    for (int c = 0; c < 3; c++)
      out->data[3 * i + (size_t)c] = img.data[i * (size_t)img.channel_count + (size_t)ch[c]];
  iris_image_destroy(&img);
  return 1;
}

int main(int argc, char **argv) {
  if (argc == 3 && strcmp(argv[1], "--own") == 0) {
    iris_image img;
    if (!read_exr(argv[2], &img)) return 2;
    double own = iris_metric_own_relmse(&img);
    iris_image_destroy(&img);
    if (own < 0) {
      fprintf(stderr, "relmse: %s has no var.R/G/B channels\n", argv[2]);
      return 2;
    }
    printf("%.6g\n", own);
    return 0;
  }
  if (argc == 4 && strcmp(argv[1], "--raw") == 0) {
    iris_image img;
    if (!read_exr(argv[2], &img)) return 2;
    static const char *const names[6] = {"R", "G", "B", "var.R", "var.G", "var.B"};
    int ch[6];
    for (int c = 0; c < 6; c++) ch[c] = iris_image_channel(&img, names[c]);
    FILE *f = fopen(argv[3], "wb");
    if (!f || ch[0] < 0 || ch[1] < 0 || ch[2] < 0) {
      fprintf(stderr, "relmse: cannot write %s or %s has no R, G, B\n", argv[3], argv[2]);
      if (f) fclose(f);
      iris_image_destroy(&img);
      return 2;
    }
    int32_t wh[2] = {img.width, img.height};
    fwrite(wh, sizeof wh, 1, f);
    for (size_t i = 0; i < (size_t)img.width * (size_t)img.height; i++)
      for (int c = 0; c < 6; c++) {
        float v = ch[c] < 0 ? 0.0f : img.data[i * (size_t)img.channel_count + (size_t)ch[c]];
        fwrite(&v, sizeof v, 1, f);
      }
    iris_image_destroy(&img);
    return fclose(f) == 0 ? 0 : 2;
  }
  if (argc == 4 && strcmp(argv[1], "--expected") == 0) {
    iris_image img, r;
    if (!read_exr(argv[2], &img)) return 2;
    if (!load_rgb(argv[3], &r)) {
      iris_image_destroy(&img);
      return 2;
    }
    static const char *const vnames[3] = {"var.R", "var.G", "var.B"};
    int v0[3];
    for (int c = 0; c < 3; c++) v0[c] = iris_image_channel(&img, vnames[c]);
    if (v0[0] < 0 || v0[1] < 0 || v0[2] < 0 || img.width != r.width || img.height != r.height) {
      fprintf(stderr, "relmse: %s has no var.R/G/B channels or another size than %s\n", argv[2], argv[3]);
      iris_image_destroy(&img);
      iris_image_destroy(&r);
      return 2;
    }
    size_t n = (size_t)img.width * (size_t)img.height;
    double sum = 0.0;
    for (size_t i = 0; i < n; i++)
      for (int c = 0; c < 3; c++) {
        double ref = r.data[3 * i + (size_t)c], v = img.data[i * (size_t)img.channel_count + (size_t)v0[c]];
        if (isfinite(v) && v > 0.0) sum += v / (ref * ref + IRIS_METRIC_EPS) / 3.0;
      }
    printf("%.6g\n", n ? sum / (double)n : -1.0);
    iris_image_destroy(&img);
    iris_image_destroy(&r);
    return 0;
  }
  if (argc != 3) {
    fprintf(stderr, "usage: relmse IMAGE.exr REFERENCE.exr\n");
    return 2;
  }
  iris_image a, r;
  if (!load_rgb(argv[1], &a)) return 2;
  if (!load_rgb(argv[2], &r)) return 2;
  if (a.width != r.width || a.height != r.height) {
    fprintf(stderr, "relmse: %s is %dx%d, %s is %dx%d\n", argv[1], a.width, a.height, argv[2], r.width, r.height);
    return 2;
  }
  printf("%.6g\n", iris_metric_relmse(&a, 0, &r, 0, IRIS_METRIC_EPS, IRIS_METRIC_DROP));
  iris_image_destroy(&a);
  iris_image_destroy(&r);
  return 0;
}
