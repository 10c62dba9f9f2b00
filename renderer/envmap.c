/* Environment maps; see envmap.h. */
#include "renderer/envmap.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/image.h"
#include "core/log.h"

static float luminance3(const float *c) { return iris_luminance(iris_v3_load(c)); }

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
  free(env->row_cdf);
  free(env->cdf);
  free(env->guide);
  free(env->row_guide);
  free(env->rgb);
  memset(env, 0, sizeof *env);
}

/* cdf[0..n] of n weights, accumulated in double; uniform when all are 0; 1
 * exactly from the entry after the last positive weight on, so that rounding
 * never hands a sample to a zero-weight tail. Returns the weights' sum. */
static double build_cdf(const float *w, int n, float *cdf) {
  double sum = 0.0;
  for (int i = 0; i < n; i++) sum += w[i];
  double acc = 0.0;
  cdf[0] = 0.0f;
  for (int i = 0; i < n; i++) {
    acc += sum > 0.0 ? (double)w[i] / sum : 1.0 / n;
    cdf[i + 1] = (float)acc;
  }
  int last = n;
  while (last > 1 && sum > 0.0 && !(w[last - 1] > 0.0f)) --last;
  for (int i = last; i <= n; i++) cdf[i] = 1.0f;
  return sum;
}

/* Largest i in [lo, hi) with cdf[i] <= u, given cdf[lo] <= u (binary search). */
static int search_cdf(const float *cdf, int lo, int hi, float u) {
  while (hi - lo > 1) {
    int mid = lo + (hi - lo) / 2;
    if (cdf[mid] <= u) lo = mid;
    else hi = mid;
  }
  return lo;
}

/* Largest i in [0, n) with cdf[i] <= u (cdf[n] = 1 > u), searched between
 * the guide entries of u's bucket (guide[j]: largest i with cdf[i] <= j / m);
 * the walks mend the rounding of u * m. */
static int search_guided(const float *cdf, const uint32_t *guide, int m, int n, float u) {
  int j = (int)(u * (float)m);
  j = j < 0 ? 0 : j >= m ? m - 1 : j;
  int lo = (int)guide[j], hi = j + 1 < m ? (int)guide[j + 1] + 1 : n;
  while (lo > 0 && cdf[lo] > u) --lo;
  if (hi <= lo) hi = lo + 1;
  while (hi < n && cdf[hi] <= u) ++hi;
  return search_cdf(cdf, lo, hi, u);
}

/* Periodic index (Cycles' EXTENSION_REPEAT, which its Environment Texture uses on both axes). */
static int wrap(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}

/* Integrals over t in [0, 1] of the (periodic) linear tent of row r times
 * sin(pi t), per row: the bilinear map's luminance integrates over the sphere
 * to 2 pi^2 sum_r A_r mean_x(L(x, r)) (each column tent integrates to 1/W, and
 * dw = 2 pi^2 sin(pi t) ds dt). Exact: integral of (a + b t) sin(pi t). */
static double tent_sin_integral(double t0, double t1, double a, double b) {
  /* integral over [t0, t1] of (a + b t) sin(pi t) dt */
  const double pi = IRIS_PI;
  double F1 = -(a + b * t1) * cos(pi * t1) / pi + b * sin(pi * t1) / (pi * pi);
  double F0 = -(a + b * t0) * cos(pi * t0) / pi + b * sin(pi * t0) / (pi * pi);
  return F1 - F0;
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
  out->blocks = (W + IRIS_ENVMAP_BLOCK - 1) / IRIS_ENVMAP_BLOCK;
  out->stride = (W + 1 + 15) / 16 * 16; /* 64-byte rows */
  out->pdf_scale = (float)((double)W * (double)H / (2.0 * IRIS_PI * IRIS_PI));
  out->row_cdf = malloc(sizeof(float) * ((size_t)H + 1));
  out->cdf = aligned_alloc(64, sizeof(float) * (size_t)out->stride * (size_t)H);
  out->row_guide = malloc(sizeof(uint32_t) * (size_t)H);
  out->guide = malloc(sizeof(uint32_t) * (size_t)out->blocks * (size_t)H);
  float *w = malloc(sizeof(float) * (size_t)(W > H ? W : H));
  float *roww = calloc((size_t)H + 1, sizeof(float));
  float *lum = malloc(sizeof(float) * n);
  double *hrow = malloc(sizeof(double) * 3 * (size_t)W); /* one row blurred across, 3 rows kept */
  double *rowmean = malloc(sizeof(double) * 4 * (size_t)H); /* per row: mean L (lum, r, g, b) */
  if (!out->row_cdf || !out->cdf || !out->guide || !out->row_guide || !w || !roww || !lum || !hrow || !rowmean) {
    free(w), free(roww), free(lum), free(hrow), free(rowmean);
    iris_envmap_destroy(out);
    return iris_error_set(err, IRIS_ERR_NOMEM, map->path, 0, NULL, "out of memory for the environment map");
  }
  for (size_t i = 0; i < n; i++) lum[i] = luminance3(&out->rgb[3 * i]);
  for (int y = 0; y < H; y++) {
    double m[4] = {0, 0, 0, 0};
    for (int x = 0; x < W; x++) {
      const float *c = &out->rgb[3 * ((size_t)y * (size_t)W + (size_t)x)];
      m[0] += lum[(size_t)y * (size_t)W + (size_t)x];
      for (int k = 0; k < 3; k++) m[1 + k] += c[k];
    }
    for (int k = 0; k < 4; k++) rowmean[4 * y + k] = m[k] / W;
  }
  /* The radiance is the bilinear interpolation of the texels (iris_envmap_radiance).
   * A texel's cell [x, x+1) x [y, y+1) sees its own texel and its 8 neighbours
   * (periodic in both axes, as the lookup); the integral of the interpolant over
   * the cell is the texels blurred by (1/8, 3/4, 1/8) across and down. That is
   * the cell's sampling weight (times sin of the row centre): positive wherever
   * the interpolated radiance is, so map sampling reaches every direction that
   * carries light, and the pdf stays exact per cell. */
  for (int y = 0; y < H; y++) {
    float sin_c = sinf(IRIS_PI * ((float)y + 0.5f) / (float)H);
    for (int k = 0; k < 3; k++) {
      const float *row = &lum[(size_t)wrap(y - 1 + k, H) * (size_t)W];
      for (int x = 0; x < W; x++)
        hrow[(size_t)k * (size_t)W + (size_t)x] =
            0.125 * row[wrap(x - 1, W)] + 0.75 * row[x] + 0.125 * row[wrap(x + 1, W)];
    }
    for (int x = 0; x < W; x++) {
      double b = 0.125 * hrow[x] + 0.75 * hrow[(size_t)W + (size_t)x] + 0.125 * hrow[2 * (size_t)W + (size_t)x];
      w[x] = (float)b * sin_c;
    }
    float *cdf = &out->cdf[(size_t)y * (size_t)out->stride];
    roww[y] = (float)build_cdf(w, W, cdf);
    for (int x = W + 1; x < out->stride; x++) cdf[x] = 1.0f;
    uint32_t *guide = &out->guide[(size_t)y * (size_t)out->blocks];
    for (int j = 0, x = 0; j < out->blocks; j++) {
      float lo = (float)j / (float)out->blocks;
      while (x + 1 < W && cdf[x + 1] <= lo) x++;
      guide[j] = (uint32_t)x;
    }
  }
  build_cdf(roww, H, out->row_cdf); /* a black map: uniform, and the lights leave it out */
  for (int j = 0, y = 0; j < H; j++) {
    float lo = (float)j / (float)H;
    while (y + 1 < H && out->row_cdf[y + 1] <= lo) y++;
    out->row_guide[j] = (uint32_t)y;
  }
  /* Means: the exact integral of the bilinear interpolant over the sphere. Row r's
   * tent spans t in [(r - 1/2)/H, (r + 3/2)/H], periodic (the half rows at the
   * poles blend the top and bottom rows, as Cycles' repeat extension does). */
  double acc[4] = {0, 0, 0, 0};
  for (int r = 0; r < H && st == IRIS_OK; r++) {
    double c = (r + 0.5) / H, A = 0.0;
    for (int side = 0; side < 2; side++) {
      /* rising half [c - 1/H, c], falling half [c, c + 1/H]; tent = 1 - |t - c| H */
      double lo = side ? c : c - 1.0 / H, hi = side ? c + 1.0 / H : c;
      double a = side ? 1.0 + c * H : 1.0 - c * H, b = side ? -(double)H : (double)H;
      /* the part outside [0, 1] wraps to the other pole: shift by +-1 */
      double shifts[3] = {-1.0, 0.0, 1.0};
      for (int k = 0; k < 3; k++) {
        double sh = shifts[k];
        double l0 = fmax(lo + sh, 0.0), l1 = fmin(hi + sh, 1.0);
        if (l1 > l0) A += tent_sin_integral(l0, l1, a - b * sh, b);
      }
    }
    for (int k = 0; k < 4; k++) acc[k] += A * rowmean[4 * r + k];
  }
  free(w), free(roww), free(lum), free(hrow), free(rowmean);
  if (st != IRIS_OK) {
    iris_envmap_destroy(out);
    return st;
  }
  /* integral over the sphere = 2 pi^2 sum A_r mean_r; mean = that / 4 pi */
  out->mean_luminance = acc[0] * 2.0 * IRIS_PI * IRIS_PI / (4.0 * IRIS_PI);
  for (int k = 0; k < 3; k++) out->mean_rgb[k] = (float)(acc[1 + k] * 2.0 * IRIS_PI * IRIS_PI / (4.0 * IRIS_PI));
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

/* Blender 3.4's Environment Texture, interpolation Linear (Cycles'
 * kernel/device/cpu/image.h interp_linear with EXTENSION_REPEAT): texel
 * centres at half-integers, so x = s W - 1/2 and y = t H - 1/2 (t counted from
 * the top row; Cycles' v = 1 - t counts from the bottom, the same pairs and
 * weights), the integer part floored, both neighbours wrapped periodically
 * (across the seam in s, and across the poles in t: the top half row blends
 * the top and the bottom rows, as Cycles does). */
iris_vec3 iris_envmap_radiance(const iris_envmap *env, iris_vec3 d) {
  float s, t;
  iris_envmap_dir_to_st(env, d, &s, &t);
  return iris_envmap_radiance_st(env, s, t);
}

/* Bilinear lookup at map coordinates; see iris_envmap_radiance. */
iris_vec3 iris_envmap_radiance_st(const iris_envmap *env, float s, float t) {
  const int W = env->width, H = env->height;
  float fx = s * (float)W - 0.5f, fy = t * (float)H - 0.5f;
  if (!isfinite(fx) || !isfinite(fy)) return iris_v3(0, 0, 0);
  float flx = floorf(fx), fly = floorf(fy);
  float tx = fx - flx, ty = fy - fly;
  int x0 = wrap((int)flx, W), y0 = wrap((int)fly, H);
  int x1 = x0 + 1 == W ? 0 : x0 + 1, y1 = y0 + 1 == H ? 0 : y0 + 1;
  const float *c00 = &env->rgb[3 * ((size_t)y0 * (size_t)W + (size_t)x0)];
  const float *c10 = &env->rgb[3 * ((size_t)y0 * (size_t)W + (size_t)x1)];
  const float *c01 = &env->rgb[3 * ((size_t)y1 * (size_t)W + (size_t)x0)];
  const float *c11 = &env->rgb[3 * ((size_t)y1 * (size_t)W + (size_t)x1)];
  float w00 = (1.0f - ty) * (1.0f - tx), w10 = (1.0f - ty) * tx, w01 = ty * (1.0f - tx), w11 = ty * tx;
  return iris_v3(w00 * c00[0] + w10 * c10[0] + w01 * c01[0] + w11 * c11[0],
                 w00 * c00[1] + w10 * c10[1] + w01 * c01[1] + w11 * c11[1],
                 w00 * c00[2] + w10 * c10[2] + w01 * c01[2] + w11 * c11[2]);
}

/* The cell's probability: the row's times the cell's within it, both CDF
 * differences (the measure of the u that choose them). */
static float cell_probability(const iris_envmap *env, int x, int y) {
  const float *cdf = &env->cdf[(size_t)y * (size_t)env->stride];
  return (env->row_cdf[y + 1] - env->row_cdf[y]) * (cdf[x + 1] - cdf[x]);
}

bool iris_envmap_sample(const iris_envmap *env, float u0, float u1, iris_vec3 *d, float *pdf,
                        iris_vec3 *radiance) {
  float s, t;
  if (!iris_envmap_sample_st(env, u0, u1, d, pdf, &s, &t)) return false;
  if (radiance) *radiance = iris_envmap_radiance_st(env, s, t);
  return true;
}

bool iris_envmap_sample_st(const iris_envmap *env, float u0, float u1, iris_vec3 *d, float *pdf, float *s_out,
                           float *t_out) {
  const int W = env->width, H = env->height;
  if (!(u0 >= 0.0f && u0 < 1.0f && u1 >= 0.0f && u1 < 1.0f)) return false;
  /* row: largest y with row_cdf[y] <= u0 (row_cdf[H] = 1 > u0) */
  int y = search_guided(env->row_cdf, env->row_guide, H, H, u0);
  float r0 = env->row_cdf[y], r1 = env->row_cdf[y + 1];
  if (!(r1 > r0)) return false;
  float ur = iris_rescale_unit(u0, r0, r1);
  /* cell: the guide entry bounds the search (the walks mend u * blocks's rounding) */
  const float *cdf = &env->cdf[(size_t)y * (size_t)env->stride];
  int x = search_guided(cdf, &env->guide[(size_t)y * (size_t)env->blocks], env->blocks, W, u1);
  float c0 = cdf[x], c1 = cdf[x + 1];
  if (!(c1 > c0)) return false;
  float uc = iris_rescale_unit(u1, c0, c1);
  float t = ((float)y + ur) / (float)H, s = ((float)x + uc) / (float)W;
  float sin_t = sinf(t * IRIS_PI);
  if (!(sin_t > 0.0f)) return false;
  *d = iris_envmap_st_to_dir(env, s, t);
  *pdf = (r1 - r0) * (c1 - c0) * env->pdf_scale / sin_t;
  *s_out = s;
  *t_out = t;
  return isfinite(*pdf) && *pdf > 0.0f;
}

void iris_envmap_prefetch(const iris_envmap *env, float u0, float u1, int stage) {
  if (!(u0 >= 0.0f && u0 < 1.0f && u1 >= 0.0f && u1 < 1.0f)) return;
  int y = search_guided(env->row_cdf, env->row_guide, env->height, env->height, u0);
  int j = (int)(u1 * (float)env->blocks);
  j = j < 0 ? 0 : j >= env->blocks ? env->blocks - 1 : j;
  const uint32_t *g = &env->guide[(size_t)y * (size_t)env->blocks + (size_t)j];
  if (stage == 0) __builtin_prefetch(g);
  else __builtin_prefetch(&env->cdf[(size_t)y * (size_t)env->stride + *g]);
}

static float pdf_st(const iris_envmap *env, float s, float t) {
  float sin_t = sinf(t * IRIS_PI);
  if (!(sin_t > 0.0f)) return 0.0f;
  int x, y;
  texel_of(env, s, t, &x, &y);
  return cell_probability(env, x, y) * env->pdf_scale / sin_t;
}

float iris_envmap_pdf(const iris_envmap *env, iris_vec3 d) {
  float s, t;
  iris_envmap_dir_to_st(env, d, &s, &t);
  return pdf_st(env, s, t);
}

iris_vec3 iris_envmap_eval(const iris_envmap *env, iris_vec3 d, float *pdf, float st[2]) {
  float s, t;
  iris_envmap_dir_to_st(env, d, &s, &t);
  if (pdf) *pdf = pdf_st(env, s, t);
  if (st) st[0] = s, st[1] = t;
  return iris_envmap_radiance_st(env, s, t);
}

float iris_envmap_pdf_st(const iris_envmap *env, float s, float t) { return pdf_st(env, s, t); }

/* ---- regions (envmap.h) ------------------------------------------------------ */

void iris_envmap_regions_destroy(iris_envmap_regions *r) {
  free(r->col0);
  free(r->row0);
  free(r->col_of);
  free(r->row_of);
  free(r->prob);
  free(r->row_cdf);
  memset(r, 0, sizeof *r);
}

iris_status iris_envmap_regions_build(const iris_envmap *env, int bx, int by, iris_envmap_regions *out,
                                      iris_error *err) {
  memset(out, 0, sizeof *out);
  if (bx < 1 || by < 1 || bx > 4096 || by > 4096)
    return iris_error_set(err, IRIS_ERR_INVALID, NULL, 0, "environment", "%d x %d map regions (1 to 4096 each)", bx, by);
  const int W = env->width, H = env->height;
  out->bx = bx, out->by = by;
  out->col0 = malloc(sizeof(int) * ((size_t)bx + 1));
  out->row0 = malloc(sizeof(int) * ((size_t)by + 1));
  out->col_of = malloc(sizeof(uint16_t) * (size_t)W);
  out->row_of = malloc(sizeof(uint16_t) * (size_t)H);
  out->prob = calloc((size_t)bx * (size_t)by, sizeof(float));
  out->row_cdf = malloc(sizeof(float) * (size_t)bx * ((size_t)H + (size_t)by));
  float *w = malloc(sizeof(float) * (size_t)H);
  if (!out->col0 || !out->row0 || !out->col_of || !out->row_of || !out->prob || !out->row_cdf || !w) {
    free(w);
    iris_envmap_regions_destroy(out);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "environment", "out of memory for map regions");
  }
  for (int i = 0; i <= bx; i++) out->col0[i] = (int)((int64_t)i * W / bx);
  for (int j = 0; j <= by; j++) out->row0[j] = (int)((int64_t)j * H / by);
  for (int i = 0; i < bx; i++)
    for (int x = out->col0[i]; x < out->col0[i + 1]; x++) out->col_of[x] = (uint16_t)i;
  for (int j = 0; j < by; j++)
    for (int y = out->row0[j]; y < out->row0[j + 1]; y++) out->row_of[y] = (uint16_t)j;
  /* A row's share of region column i: the row's probability times the
   * probability of the region's cells within it, both the CDF differences
   * that sampling the whole map uses (so a region's sample has the map's
   * density over the region's probability, up to rounding). */
  for (int i = 0; i < bx; i++) {
    const int c0 = out->col0[i], c1 = out->col0[i + 1];
    for (int y = 0; y < H; y++) {
      const float *cdf = &env->cdf[(size_t)y * (size_t)env->stride];
      w[y] = (env->row_cdf[y + 1] - env->row_cdf[y]) * (cdf[c1] - cdf[c0]);
    }
    for (int j = 0; j < by; j++) {
      const int r0 = out->row0[j], n = out->row0[j + 1] - r0;
      double p = 0.0;
      for (int k = 0; k < n; k++) p += w[r0 + k];
      out->prob[(size_t)j * (size_t)bx + (size_t)i] = (float)p;
      float *rc = &out->row_cdf[(size_t)i * ((size_t)H + (size_t)by) + (size_t)r0 + (size_t)j];
      if (n > 0) build_cdf(&w[r0], n, rc);
      else rc[0] = 1.0f;
    }
  }
  free(w);
  return IRIS_OK;
}

int iris_envmap_region_of(const iris_envmap *env, const iris_envmap_regions *r, float s, float t) {
  int x, y;
  texel_of(env, s, t, &x, &y);
  return (int)r->row_of[y] * r->bx + (int)r->col_of[x];
}

bool iris_envmap_sample_region(const iris_envmap *env, const iris_envmap_regions *r, int region, float u0,
                               float u1, iris_vec3 *d, float *pdf_map, float *s_out, float *t_out) {
  if (region < 0 || region >= r->bx * r->by || !(r->prob[region] > 0.0f)) return false;
  if (!(u0 >= 0.0f && u0 < 1.0f && u1 >= 0.0f && u1 < 1.0f)) return false;
  const int i = region % r->bx, j = region / r->bx, H = env->height;
  const int r0 = r->row0[j], n = r->row0[j + 1] - r0, c0 = r->col0[i], c1 = r->col0[i + 1];
  const float *rc = &r->row_cdf[(size_t)i * ((size_t)H + (size_t)r->by) + (size_t)r0 + (size_t)j];
  int k = search_cdf(rc, 0, n, u0);
  float a = rc[k], b = rc[k + 1];
  if (!(b > a)) return false;
  const int y = r0 + k;
  float ur = iris_rescale_unit(u0, a, b);
  const float *cdf = &env->cdf[(size_t)y * (size_t)env->stride];
  float lo = cdf[c0], hi = cdf[c1];
  if (!(hi > lo)) return false;
  /* u1 scaled into the region's part of the row's CDF, searched within the
   * region's columns: cdf[c0] <= target, so this is the cell the whole row's
   * search finds, clamped to the region (target may round up to cdf[c1]) */
  float target = lo + u1 * (hi - lo);
  int x = search_cdf(cdf, c0, c1, target);
  float x0 = cdf[x], x1 = cdf[x + 1];
  if (!(x1 > x0)) return false;
  float uc = iris_rescale_unit(target, x0, x1);
  float t = ((float)y + ur) / (float)H, s = ((float)x + uc) / (float)env->width;
  float sin_t = sinf(t * IRIS_PI);
  if (!(sin_t > 0.0f)) return false;
  *d = iris_envmap_st_to_dir(env, s, t);
  *pdf_map = cell_probability(env, x, y) * env->pdf_scale / sin_t;
  *s_out = s;
  *t_out = t;
  return isfinite(*pdf_map) && *pdf_map > 0.0f;
}
