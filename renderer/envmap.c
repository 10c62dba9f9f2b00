/* Environment maps; see envmap.h. */
#include "renderer/envmap.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/image.h"
#include "core/log.h"

static float luminance3(const float *c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

/* EXR by its magic number (0x762f3101), else Radiance HDR (stb checks its header). */
static bool is_exr(const char *path) {
  FILE *fp = fopen(path, "rb");
  if (!fp) return false;
  unsigned char m[4] = {0};
  size_t n = fread(m, 1, 4, fp);
  fclose(fp);
  return n == 4 && m[0] == 0x76 && m[1] == 0x2f && m[2] == 0x31 && m[3] == 0x01;
}

/* Decodes the file into packed RGB (3 floats per texel, row 0 top) and checks every texel. */
static iris_status read_rgb(const char *path, float **rgb, int *w, int *h, iris_error *err) {
  *rgb = NULL;
  struct stat sb;
  if (stat(path, &sb) != 0)
    return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "cannot open environment map: %s", strerror(errno));
  if (!S_ISREG(sb.st_mode))
    return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "cannot open environment map: not a regular file");
  FILE *probe = fopen(path, "rb");
  if (!probe) return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "cannot open environment map: %s", strerror(errno));
  int c0 = fgetc(probe);
  fclose(probe);
  if (c0 == EOF) return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "empty environment map file");
  iris_image img;
  iris_status st;
  int ch[3] = {0, 1, 2};
  if (is_exr(path)) {
    st = iris_exr_read(path, &img, NULL, NULL, err);
    if (st != IRIS_OK) return st;
    ch[0] = iris_image_channel(&img, "R");
    ch[1] = iris_image_channel(&img, "G");
    ch[2] = iris_image_channel(&img, "B");
    if (ch[0] < 0 || ch[1] < 0 || ch[2] < 0) {
      int y = iris_image_channel(&img, "Y");
      if (y < 0) {
        iris_image_destroy(&img);
        return iris_error_set(err, IRIS_ERR_UNSUPPORTED, path, 0, NULL,
                              "environment map has neither R, G, B nor Y channels");
      }
      ch[0] = ch[1] = ch[2] = y;
    }
  } else {
    st = iris_hdr_read(path, &img, err);
    if (st != IRIS_OK) {
      if (err && err->status == IRIS_ERR_UNSUPPORTED)
        snprintf(err->message, sizeof err->message, "not an OpenEXR or Radiance HDR image");
      return st;
    }
  }
  size_t n = (size_t)img.width * (size_t)img.height;
  float *out = malloc(sizeof(float) * 3 * (n ? n : 1));
  if (!out) {
    iris_image_destroy(&img);
    return iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "out of memory for the environment map");
  }
  for (size_t i = 0; i < n; i++) {
    const float *px = &img.data[i * (size_t)img.channel_count];
    for (int k = 0; k < 3; k++) {
      float v = px[ch[k]];
      if (!isfinite(v) || v < 0.0f) {
        int x = (int)(i % (size_t)img.width), y = (int)(i / (size_t)img.width);
        iris_image_destroy(&img);
        free(out);
        return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL,
                              "environment map texel (%d, %d) is %s (texels must be finite and >= 0)",
                              x, y, isnan(v) ? "NaN" : isinf(v) ? "infinite" : "negative");
      }
      out[3 * i + (size_t)k] = v;
    }
  }
  *w = img.width;
  *h = img.height;
  iris_image_destroy(&img);
  if (*w != 2 * *h)
    iris_warnf("%s: environment map is %dx%d, not 2:1 (it is stretched over the sphere)", path, *w, *h);
  *rgb = out;
  return IRIS_OK;
}

iris_status iris_envmap_check(const char *path, iris_error *err) {
  float *rgb = NULL;
  int w, h;
  iris_status st = read_rgb(path, &rgb, &w, &h, err);
  free(rgb);
  return st;
}

void iris_envmap_destroy(iris_envmap *env) {
  if (!env) return;
  if (env->cols)
    for (int r = 0; r < env->height; r++) iris_distrib1d_destroy(&env->cols[r]);
  free(env->cols);
  iris_distrib1d_destroy(&env->rows);
  free(env->rgb);
  memset(env, 0, sizeof *env);
}

iris_status iris_envmap_load(const iris_environment_map *map, iris_envmap *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  iris_status st = read_rgb(map->path, &out->rgb, &out->width, &out->height, err);
  if (st != IRIS_OK) return st;
  const int W = out->width, H = out->height;
  float rad = map->rotation * (IRIS_PI / 180.0f);
  out->cos_rot = cosf(rad);
  out->sin_rot = sinf(rad);
  size_t n = (size_t)W * (size_t)H;
  for (size_t i = 0; i < 3 * n; i++) out->rgb[i] *= map->strength;
  out->cols = calloc((size_t)H, sizeof *out->cols);
  float *w = malloc(sizeof(float) * (size_t)(W > H ? W : H));
  float *roww = malloc(sizeof(float) * (size_t)H);
  if (!out->cols || !w || !roww) {
    free(w), free(roww);
    iris_envmap_destroy(out);
    return iris_error_set(err, IRIS_ERR_NOMEM, map->path, 0, NULL, "out of memory for the environment map");
  }
  /* Texel (x, y) covers solid angle (2 pi / W) (cos theta0 - cos theta1): the
   * means are exact integrals of the piecewise-constant map. Sampling weights
   * use sin of the row centre (the density within a texel is uniform in (s, t)). */
  double lum = 0.0, rgbsum[3] = {0, 0, 0};
  for (int y = 0; y < H; y++) {
    double t0 = IRIS_PI * (double)y / H, t1 = IRIS_PI * (double)(y + 1) / H;
    double omega = (2.0 * IRIS_PI / W) * (cos(t0) - cos(t1));
    float sin_c = sinf(IRIS_PI * ((float)y + 0.5f) / (float)H);
    double sum = 0.0;
    for (int x = 0; x < W; x++) {
      const float *c = &out->rgb[3 * ((size_t)y * (size_t)W + (size_t)x)];
      float l = luminance3(c);
      lum += l * omega;
      for (int k = 0; k < 3; k++) rgbsum[k] += c[k] * omega;
      w[x] = l * sin_c;
      sum += w[x];
    }
    roww[y] = (float)sum;
    st = iris_distrib1d_create(&out->cols[y], w, (size_t)W, err);
    if (st != IRIS_OK) break;
  }
  if (st == IRIS_OK) st = iris_distrib1d_create(&out->rows, roww, (size_t)H, err);
  free(w), free(roww);
  if (st != IRIS_OK) {
    iris_envmap_destroy(out);
    return st;
  }
  out->mean_luminance = lum / (4.0 * IRIS_PI);
  for (int k = 0; k < 3; k++) out->mean_rgb[k] = (float)(rgbsum[k] / (4.0 * IRIS_PI));
  return IRIS_OK;
}

void iris_envmap_dir_to_st(const iris_envmap *env, iris_vec3 d, float *s, float *t) {
  /* d' = R_y(rotation) d */
  float x = d.x * env->cos_rot + d.z * env->sin_rot;
  float z = -d.x * env->sin_rot + d.z * env->cos_rot;
  float u = 0.5f + atan2f(z, x) * IRIS_INV_2PI;
  if (u >= 1.0f) u -= 1.0f;
  if (u < 0.0f) u += 1.0f;
  *s = u;
  *t = acosf(iris_clampf(d.y, -1.0f, 1.0f)) * IRIS_INV_PI;
}

iris_vec3 iris_envmap_st_to_dir(const iris_envmap *env, float s, float t) {
  float theta = t * IRIS_PI, phi = (s - 0.5f) * 2.0f * IRIS_PI;
  float st = sinf(theta);
  float x = st * cosf(phi), z = st * sinf(phi), y = cosf(theta);
  /* d = R_y(-rotation) d' */
  return iris_v3(x * env->cos_rot - z * env->sin_rot, y, x * env->sin_rot + z * env->cos_rot);
}

static void texel_of(const iris_envmap *env, float s, float t, int *x, int *y) {
  int xi = (int)(s * (float)env->width), yi = (int)(t * (float)env->height);
  *x = xi < 0 ? 0 : xi >= env->width ? env->width - 1 : xi;
  *y = yi < 0 ? 0 : yi >= env->height ? env->height - 1 : yi;
}

iris_vec3 iris_envmap_radiance(const iris_envmap *env, iris_vec3 d) {
  float s, t;
  int x, y;
  iris_envmap_dir_to_st(env, d, &s, &t);
  texel_of(env, s, t, &x, &y);
  const float *c = &env->rgb[3 * ((size_t)y * (size_t)env->width + (size_t)x)];
  return iris_v3(c[0], c[1], c[2]);
}

bool iris_envmap_sample(const iris_envmap *env, float u0, float u1, iris_vec3 *d, float *pdf) {
  float pr, pc, ur, uc;
  size_t y = iris_distrib1d_sample(&env->rows, u0, &pr, &ur);
  size_t x = iris_distrib1d_sample(&env->cols[y], u1, &pc, &uc);
  float t = ((float)y + ur) / (float)env->height, s = ((float)x + uc) / (float)env->width;
  float sin_t = sinf(t * IRIS_PI);
  if (!(pr > 0.0f) || !(pc > 0.0f) || !(sin_t > 0.0f)) return false;
  *d = iris_envmap_st_to_dir(env, s, t);
  *pdf = pr * pc * (float)env->width * (float)env->height / (2.0f * IRIS_PI * IRIS_PI * sin_t);
  return isfinite(*pdf) && *pdf > 0.0f;
}

float iris_envmap_pdf(const iris_envmap *env, iris_vec3 d) {
  float s, t;
  int x, y;
  iris_envmap_dir_to_st(env, d, &s, &t);
  float sin_t = sinf(t * IRIS_PI);
  if (!(sin_t > 0.0f)) return 0.0f;
  texel_of(env, s, t, &x, &y);
  float p = iris_distrib1d_pmf(&env->rows, (size_t)y) * iris_distrib1d_pmf(&env->cols[y], (size_t)x);
  return p * (float)env->width * (float)env->height / (2.0f * IRIS_PI * IRIS_PI * sin_t);
}
