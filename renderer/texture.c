/* Texture decoding and filtered lookup; see texture.h. */
#include "renderer/texture.h"

#include <stdlib.h>
#include <string.h>

#include "core/cancel.h"

iris_status iris_textures_load(const iris_scene *scene, iris_textures *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  for (int i = 0; i < 256; i++) out->srgb_table[i] = iris_srgb_to_linear((float)i / 255.0f);
  if (scene->texture_count == 0) return IRIS_OK;
  out->images = calloc(scene->texture_count, sizeof *out->images);
  if (!out->images) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for textures");
  out->count = scene->texture_count;
  for (size_t i = 0; i < scene->texture_count; i++) {
    const iris_texture *t = &scene->textures[i];
    if (iris_cancel_requested()) { /* one texture decodes in well under a second */
      iris_textures_destroy(out);
      return iris_cancel_error(err);
    }
    iris_ldr_image img;
    memset(&img, 0, sizeof img);
    char what[64];
    snprintf(what, sizeof what, "textures[%zu]", i);
    iris_status st = t->path ? iris_ldr_load_file(t->path, &img, err)
                             : iris_ldr_load_memory(t->data, t->data_size, what, &img, err);
    if (st != IRIS_OK) {
      iris_textures_destroy(out);
      return st;
    }
    out->images[i].width = img.width;
    out->images[i].height = img.height;
    out->images[i].rgba = img.rgba;
    out->images[i].wrap_s = t->wrap_s;
    out->images[i].wrap_t = t->wrap_t;
    out->images[i].nearest = t->nearest;
    out->images[i].uv_set = t->uv_set;
    out->images[i].has_transform = t->has_transform;
    iris_texture_transform_matrix(t, out->images[i].xf);
  }
  return IRIS_OK;
}

void iris_texture_transform_matrix(const iris_texture *t, float xf[2][3]) {
  if (!t->has_transform) {
    const float id[2][3] = {{1, 0, 0}, {0, 1, 0}};
    memcpy(xf, id, sizeof id);
    return;
  }
  /* T(offset) R(rotation) S(scale) with R = [[c, s], [-s, c]]: the rotation the
   * KHR_texture_transform sample model (TextureTransformTest's markers) checks. */
  double c = cos((double)t->rotation), s = sin((double)t->rotation);
  xf[0][0] = (float)(c * t->scale[0]), xf[0][1] = (float)(s * t->scale[1]), xf[0][2] = t->offset[0];
  xf[1][0] = (float)(-s * t->scale[0]), xf[1][1] = (float)(c * t->scale[1]), xf[1][2] = t->offset[1];
}

void iris_texture_sample(const iris_textures *tex, int32_t index, const float uv[2], const float uv1[2],
                         bool srgb, float rgba[4]) {
  if (!tex || index < 0 || (size_t)index >= tex->count) {
    rgba[0] = rgba[1] = rgba[2] = rgba[3] = 1.0f;
    return;
  }
  const iris_texture_image *t = &tex->images[index];
  const float *p = t->uv_set ? uv1 : uv;
  float u = p[0], v = p[1];
  if (t->has_transform) {
    u = t->xf[0][0] * p[0] + t->xf[0][1] * p[1] + t->xf[0][2];
    v = t->xf[1][0] * p[0] + t->xf[1][1] * p[1] + t->xf[1][2];
  }
  iris_texture_lookup(tex, index, u, v, srgb, rgba);
}

void iris_textures_destroy(iris_textures *tex) {
  if (!tex) return;
  for (size_t i = 0; i < tex->count; i++) free(tex->images[i].rgba);
  free(tex->images);
  tex->images = NULL;
  tex->count = 0;
}

int iris_texture_wrap(int i, int n, iris_wrap mode) {
  if (n <= 1) return 0;
  switch (mode) {
    case IRIS_WRAP_CLAMP: return i < 0 ? 0 : (i >= n ? n - 1 : i);
    case IRIS_WRAP_MIRROR: {
      int period = 2 * n;
      int k = i % period;
      if (k < 0) k += period;
      return k < n ? k : period - 1 - k;
    }
    case IRIS_WRAP_REPEAT:
    default: {
      int k = i % n;
      return k < 0 ? k + n : k;
    }
  }
}

static float srgb_decode(const iris_textures *tex, uint8_t v) { return tex->srgb_table[v]; }

static void texel(const iris_textures *tex, const iris_texture_image *t, int x, int y, bool srgb,
                  float out[4]) {
  x = iris_texture_wrap(x, t->width, t->wrap_s);
  y = iris_texture_wrap(y, t->height, t->wrap_t);
  const uint8_t *p = t->rgba + 4 * ((size_t)y * (size_t)t->width + (size_t)x);
  for (int c = 0; c < 3; c++) out[c] = srgb ? srgb_decode(tex, p[c]) : (float)p[c] * (1.0f / 255.0f);
  out[3] = (float)p[3] * (1.0f / 255.0f);
}

void iris_texture_lookup(const iris_textures *tex, int32_t index, float u, float v, bool srgb,
                         float rgba[4]) {
  if (!tex || index < 0 || (size_t)index >= tex->count || !tex->images[index].rgba ||
      !isfinite(u) || !isfinite(v)) {
    rgba[0] = rgba[1] = rgba[2] = rgba[3] = 1.0f;
    return;
  }
  const iris_texture_image *t = &tex->images[index];
  /* Keep the coordinates in a range where float->int is exact; repeat and mirror are
   * periodic (period 2 for mirror), so subtracting an even integer does not change
   * the result; clamp is not periodic, and every coordinate outside [-1, 2] reads
   * the same edge texels as that bound. */
  u = t->wrap_s == IRIS_WRAP_CLAMP ? fminf(fmaxf(u, -1.0f), 2.0f) : u - 2.0f * floorf(u * 0.5f);
  v = t->wrap_t == IRIS_WRAP_CLAMP ? fminf(fmaxf(v, -1.0f), 2.0f) : v - 2.0f * floorf(v * 0.5f);
  float x = u * (float)t->width - 0.5f, y = v * (float)t->height - 0.5f;
  if (t->nearest) {
    texel(tex, t, (int)floorf(x + 0.5f), (int)floorf(y + 0.5f), srgb, rgba);
    return;
  }
  float fx = floorf(x), fy = floorf(y);
  int x0 = (int)fx, y0 = (int)fy;
  float ax = x - fx, ay = y - fy;
  float a[4], b[4], c[4], d[4];
  texel(tex, t, x0, y0, srgb, a);
  texel(tex, t, x0 + 1, y0, srgb, b);
  texel(tex, t, x0, y0 + 1, srgb, c);
  texel(tex, t, x0 + 1, y0 + 1, srgb, d);
  for (int k = 0; k < 4; k++)
    rgba[k] = (1 - ay) * ((1 - ax) * a[k] + ax * b[k]) + ay * ((1 - ax) * c[k] + ax * d[k]);
}
