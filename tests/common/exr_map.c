#include "exr_map.h"

#include <stddef.h>

#include "check.h"
#include "core/image.h"

bool iris_test_write_exr_map(const char *path, int w, int h, iris_test_texel_fn fill, void *ctx) {
  static const char *const rgb[3] = {"R", "G", "B"};
  iris_image img;
  iris_error err;
  iris_error_clear(&err);
  iris_status st = iris_image_create(&img, w, h, 3, rgb, &err);
  CHECK_OK(st, &err);
  if (st != IRIS_OK) return false;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) fill(ctx, x, y, w, h, &img.data[3 * ((size_t)y * (size_t)w + (size_t)x)]);
  st = iris_exr_write(path, &img, NULL, 0, &err);
  CHECK_OK(st, &err);
  iris_image_destroy(&img);
  return st == IRIS_OK;
}

typedef struct sun_map {
  float y_gradient, sun;
  int sun_width;
} sun_map;

static void sun_texel(void *ctx, int x, int y, int w, int h, float p[3]) {
  const sun_map *m = ctx;
  float v = 0.05f + 0.5f * (float)x / (float)w + m->y_gradient * (float)y / (float)h;
  if (y == 0 || y == h - 1) v = 0.0f;                                                  /* black polar rows */
  if (x >= w / 3 && x < w / 3 + m->sun_width && y >= h / 4 && y < h / 4 + 2) v = m->sun; /* a sun */
  p[0] = v;
  p[1] = 0.7f * v;
  p[2] = 0.3f * v + 0.01f;
}

bool iris_test_write_sun_map(const char *path, int w, int h, float y_gradient, int sun_width, float sun) {
  sun_map m = {y_gradient, sun, sun_width};
  return iris_test_write_exr_map(path, w, h, sun_texel, &m);
}
