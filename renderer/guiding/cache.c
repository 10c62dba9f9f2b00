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
  for (uint32_t i = 0; i < n; ++i) {
    float p = cdf[i] - (i ? cdf[i - 1] : 0.0f);
    pdf[i] = (float)(p / map->solid_angle[i]);
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
  float c0 = lo ? cdf[lo - 1] : 0.0f, p = cdf[lo] - c0;
  float r = p > 0.0f ? iris_clampf((u0 - c0) / p, 0.0f, 0x1.fffffep-1f) : 0.5f;
  *pdf_out = pdf[lo];
  return iris_octmap_sample_in_texel(map, lo, r, u1, u2);
}

float iris_cache_pdf(const iris_octmap *map, const float *pdf, iris_vec3 w) {
  int32_t t = iris_octmap_dir_to_texel(map, w);
  return t < 0 ? 0.0f : pdf[t];
}
