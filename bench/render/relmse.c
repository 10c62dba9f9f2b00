/* relmse: the benchmarks' relMSE (validate/metrics.h: eps 0.01, largest 0.1%
 * of pixel errors dropped) of one EXR against a reference EXR, channels taken
 * by name (R, G, B). Usage: relmse IMAGE.exr REFERENCE.exr
 *                           relmse --own IMAGE.exr   (from its var.R/G/B)
 * Prints the relMSE; exit 2 on unreadable or mismatched images. Used by
 * bench/render/equal_spp.sh to compare iris and Cycles at equal spp. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/image.h"
#include "validate/metrics.h"

static int load_rgb(const char *path, iris_image *out) {
  iris_image img;
  iris_error err;
  iris_error_clear(&err);
  if (iris_exr_read(path, &img, NULL, NULL, &err) != IRIS_OK) {
    fprintf(stderr, "relmse: %s: %s\n", path, err.message);
    return 0;
  }
  static const char *const names[3] = {"R", "G", "B"};
  int ch[3];
  for (int c = 0; c < 3; c++)
    if ((ch[c] = iris_image_channel(&img, names[c])) < 0) {
      fprintf(stderr, "relmse: %s: no channel %s\n", path, names[c]);
      iris_image_destroy(&img);
      return 0;
    }
  if (iris_image_create(out, img.width, img.height, 3, names, &err) != IRIS_OK) {
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
    iris_error err;
    iris_error_clear(&err);
    if (iris_exr_read(argv[2], &img, NULL, NULL, &err) != IRIS_OK) {
      fprintf(stderr, "relmse: %s: %s\n", argv[2], err.message);
      return 2;
    }
    double own = iris_metric_own_relmse(&img);
    iris_image_destroy(&img);
    if (own < 0) {
      fprintf(stderr, "relmse: %s has no var.R/G/B channels\n", argv[2]);
      return 2;
    }
    printf("%.6g\n", own);
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
