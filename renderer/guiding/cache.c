/* Cache tables: splatting, pdf with floor, CDF, sampling and pdf lookup. */
#include "renderer/guiding/cache.h"

#include <math.h>

/* Texel (i, j) possibly outside the grid -> the texel that is its neighbour
 * on the sphere (sphere maps wrap and mirror at the seams, hemisphere maps
 * clamp at the horizon). */
static uint32_t resolve_texel(const iris_octmap *map, int i, int j) {
  if (!map->sphere) {
    i = i < 0 ? 0 : (i >= map->width ? map->width - 1 : i);
    j = j < 0 ? 0 : (j >= map->height ? map->height - 1 : j);
    return (uint32_t)(j * map->width + i);
  }
  int w = map->width;
  if (j < 0) { /* the edge b = -1 of one half meets the other half mirrored */
    j = 0;
    i = w - 1 - i;
  } else if (j >= map->height) {
    j = map->height - 1;
    i = w - 1 - i;
  }
  i = ((i % w) + w) % w; /* u wraps continuously (docs/guiding.md) */
  return (uint32_t)(j * w + i);
}

bool iris_cache_splat(const iris_octmap *map, float *hist, iris_vec3 wi, float energy,
                      iris_splat_mode mode) {
  float u, v;
  if (!(energy > 0.0f) || !isfinite(energy)) return false;
  if (!map->sphere && !(wi.z > 0.0f)) return false;
  if (!iris_octmap_dir_to_uv(map, wi, &u, &v)) return false;
  if (mode == IRIS_SPLAT_NEAREST) {
    hist[resolve_texel(map, (int)u, (int)v)] += energy;
    return true;
  }
  float fx = u - 0.5f, fy = v - 0.5f;
  int i0 = (int)floorf(fx), j0 = (int)floorf(fy);
  float tx = fx - (float)i0, ty = fy - (float)j0;
  hist[resolve_texel(map, i0, j0)] += energy * (1.0f - tx) * (1.0f - ty);
  hist[resolve_texel(map, i0 + 1, j0)] += energy * tx * (1.0f - ty);
  hist[resolve_texel(map, i0, j0 + 1)] += energy * (1.0f - tx) * ty;
  hist[resolve_texel(map, i0 + 1, j0 + 1)] += energy * tx * ty;
  return true;
}

bool iris_cache_build_tables(const iris_octmap *map, const float *hist, float floor, float *pdf,
                             float *cdf) {
  uint32_t n = map->texel_count;
  double sum = 0.0;
  for (uint32_t i = 0; i < n; ++i) sum += hist[i] > 0.0f ? hist[i] : 0.0f;
  if (!(sum > 0.0) || !isfinite(sum)) return false;
  /* Normalise, floor, renormalise (thesis 4.2.3.1). */
  double sum2 = 0.0;
  for (uint32_t i = 0; i < n; ++i) {
    double p = (hist[i] > 0.0f ? hist[i] : 0.0f) / sum;
    sum2 += p < floor ? floor : p;
  }
  double acc = 0.0;
  for (uint32_t i = 0; i < n; ++i) {
    double p = (hist[i] > 0.0f ? hist[i] : 0.0f) / sum;
    acc += (p < floor ? floor : p) / sum2;
    cdf[i] = (float)acc;
  }
  cdf[n - 1] = 1.0f;
  /* pdf(w) = P[texel] * res^2 / (2 |w|_1^3): uniform in the texel's (a, b)
   * square of area 4 / res^2, times d(a,b)/d(omega) = 2 / |w|_1^3. */
  const float scale = 0.5f * (float)map->res * (float)map->res;
  for (uint32_t i = 0; i < n; ++i) {
    float p = cdf[i] - (i ? cdf[i - 1] : 0.0f);
    pdf[i] = p * scale;
  }
  return true;
}

iris_vec3 iris_cache_sample(const iris_octmap *map, const float *pdf, const float *cdf, float u0,
                            float u1, float u2, float *pdf_out) {
  /* First texel whose cdf exceeds u0. */
  uint32_t lo = 0, hi = map->texel_count - 1;
  while (lo < hi) {
    uint32_t mid = lo + (hi - lo) / 2;
    if (cdf[mid] > u0) hi = mid;
    else lo = mid + 1;
  }
  (void)u0;
  /* Uniform point of the texel in map coordinates (no trigonometry). The
   * octahedron point q (|q|_1 = 1) normalised is w = q / |q|_2, so
   * 1 / |w|_1^3 = |q|_2^3. */
  uint32_t i = lo % (uint32_t)map->width, j = lo / (uint32_t)map->width;
  float u = (float)i + u1, v = (float)j + u2;
  float a, sign = 1.0f, n = (float)map->res;
  if (i < (uint32_t)map->res) {
    a = 2.0f * u / n - 1.0f;
  } else {
    a = 1.0f - 2.0f * (u - n) / n;
    sign = -1.0f;
  }
  float b = 2.0f * v / n - 1.0f;
  float x = 0.5f * (a + b), y = 0.5f * (b - a);
  float z = sign * fmaxf(0.0f, 1.0f - fabsf(x) - fabsf(y));
  float l2 = sqrtf(x * x + y * y + z * z);
  float inv = 1.0f / l2;
  *pdf_out = pdf[lo] * l2 * l2 * l2;
  return iris_v3(x * inv, y * inv, z * inv);
}

float iris_cache_density_factor(iris_vec3 w) {
  float l1 = fabsf(w.x) + fabsf(w.y) + fabsf(w.z);
  float l2 = sqrtf(w.x * w.x + w.y * w.y + w.z * w.z);
  float r = l2 / l1;
  return r * r * r;
}

float iris_cache_pdf(const iris_octmap *map, const float *pdf, iris_vec3 w) {
  int32_t t = iris_octmap_dir_to_texel(map, w);
  return t < 0 ? 0.0f : pdf[t] * iris_cache_density_factor(w);
}
