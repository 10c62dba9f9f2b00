/* Environment maps the tests write: a w x h RGB OpenEXR whose texels a
 * function gives, and the "sun map" the environment and sky-visibility tests
 * share (a smooth gradient, black polar rows and one small bright sun). */
#ifndef IRIS_TESTS_EXR_MAP_H
#define IRIS_TESTS_EXR_MAP_H

#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Fills texel (x, y) of a w x h map (rgb: its three channels). */
typedef void (*iris_test_texel_fn)(void *ctx, int x, int y, int w, int h, float rgb[3]);

/* Writes the map texel by texel, row by row (fill is called in that order);
 * every step CHECKed. Returns whether the file was written. */
bool iris_test_write_exr_map(const char *path, int w, int h, iris_test_texel_fn fill, void *ctx);

/* The sun map: RGB (v, 0.7 v, 0.3 v + 0.01) with
 * v = 0.05 + 0.5 x / w + y_gradient y / h, 0 on the top and bottom rows, and
 * `sun` on sun_width x 2 texels from (w / 3, h / 4). */
bool iris_test_write_sun_map(const char *path, int w, int h, float y_gradient, int sun_width, float sun);

#ifdef __cplusplus
}
#endif
#endif
