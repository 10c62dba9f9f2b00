/* exr_close A.exr B.exr: exit 0 when the two images have the same size and
 * channels, their R/G/B agree to float rounding (at most 2 float steps of the
 * larger value) and their var.* channels (if any) to 1e-4 relative; prints the
 * worst differences. The Slurm test compares the merged image of a job array
 * with a single-process render with it. */
#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/image.h"

int main(int argc, char **argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: exr_close A.exr B.exr\n");
    return 2;
  }
  iris_image a, b;
  iris_error err;
  iris_error_clear(&err);
  for (int i = 0; i < 2; i++)
    if (iris_exr_read(argv[1 + i], i ? &b : &a, NULL, NULL, &err) != IRIS_OK) {
      fprintf(stderr, "exr_close: %s: %s\n", argv[1 + i], err.message);
      return 2;
    }
  if (a.width != b.width || a.height != b.height || a.channel_count != b.channel_count) {
    printf("exr_close: %dx%d with %d channels vs %dx%d with %d channels\n", a.width, a.height,
           a.channel_count, b.width, b.height, b.channel_count);
    return 1;
  }
  double worst_mean = 0.0, worst_var = 0.0;
  long differ = 0;
  size_t n = (size_t)a.width * (size_t)a.height;
  for (int c = 0; c < a.channel_count; c++) {
    int cb = iris_image_channel(&b, a.channel_names[c]);
    if (cb < 0) {
      printf("exr_close: channel %s missing in %s\n", a.channel_names[c], argv[2]);
      return 1;
    }
    bool var = strncmp(a.channel_names[c], "var.", 4) == 0;
    for (size_t i = 0; i < n; i++) {
      float x = a.data[i * (size_t)a.channel_count + (size_t)c];
      float y = b.data[i * (size_t)b.channel_count + (size_t)cb];
      double s = fmax(fabs(x), fabs(y));
      double e = s > 0 ? fabs((double)x - (double)y) / s : 0.0;
      if (var) {
        worst_var = fmax(worst_var, e);
      } else {
        differ += x != y;
        worst_mean = fmax(worst_mean, e / FLT_EPSILON);
      }
    }
  }
  bool ok = worst_mean <= 2.0 && worst_var <= 1e-4;
  printf("exr_close: %dx%d, %ld values differ, worst %.2f float steps (mean), %.2g relative "
         "(variance): %s\n", a.width, a.height, differ, worst_mean, worst_var,
         ok ? "close" : "DIFFERENT");
  iris_image_destroy(&a);
  iris_image_destroy(&b);
  return ok ? 0 : 1;
}
