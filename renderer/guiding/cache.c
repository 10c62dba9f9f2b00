/* Cache tables: splatting, pdf with floor, CDF, sampling and pdf lookup. */
#include "renderer/guiding/cache.h"

#include "renderer/guiding/refine.h"

#include <math.h>
#include <stdlib.h>

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
                             iris_cache_alias *alias) {
  const uint32_t n = map->texel_count;
  double sum = 0.0;
  for (uint32_t i = 0; i < n; ++i) sum += hist[i] > 0.0f ? hist[i] : 0.0f;
  if (!(sum > 0.0) || !isfinite(sum)) return false;
  /* Normalise, floor, renormalise (thesis 4.2.3.1). */
  double sum2 = 0.0;
  for (uint32_t i = 0; i < n; ++i) {
    double p = (hist[i] > 0.0f ? hist[i] : 0.0f) / sum;
    sum2 += p < floor ? floor : p;
  }
  /* Vose's alias method in double, in place: scaled[i] = n P[i]; texels below 1
   * ("small") are topped up by one above 1 ("large"). Worklists are index
   * chains through alias[].alias, so no scratch memory is needed. */
  double scaled_buf[512];
  double *scaled = n <= 512 ? scaled_buf : malloc(sizeof(double) * n);
  if (!scaled) return false;
  const uint32_t NONE = UINT32_MAX;
  uint32_t small = NONE, large = NONE;
  for (uint32_t i = 0; i < n; ++i) {
    double p = (hist[i] > 0.0f ? hist[i] : 0.0f) / sum;
    scaled[i] = (p < floor ? floor : p) / sum2 * (double)n;
  }
  for (uint32_t i = n; i-- > 0;) { /* push in reverse: lists pop in index order */
    if (scaled[i] < 1.0) {
      alias[i].alias = small;
      small = i;
    } else {
      alias[i].alias = large;
      large = i;
    }
  }
  while (small != NONE && large != NONE) {
    uint32_t s = small, l = large;
    small = alias[s].alias;
    alias[s].q = (float)scaled[s];
    alias[s].alias = l;
    scaled[l] -= 1.0 - scaled[s];
    if (scaled[l] < 1.0) { /* l becomes small */
      large = alias[l].alias;
      alias[l].alias = small;
      small = l;
    }
  }
  /* Leftovers are 1 up to rounding: keep themselves. */
  while (large != NONE) {
    uint32_t l = large;
    large = alias[l].alias;
    alias[l].q = 1.0f;
    alias[l].alias = l;
  }
  while (small != NONE) {
    uint32_t s = small;
    small = alias[s].alias;
    alias[s].q = 1.0f;
    alias[s].alias = s;
  }
  /* The probabilities the float table actually samples, P[i] = (q_i + sum over
   * columns aliased to i of (1 - q_j)) / n; pdf(w) = P[texel] * res^2 /
   * (2 |w|_1^3): uniform in the texel's (a, b) square of area 4 / res^2, times
   * d(a,b)/d(omega) = 2 / |w|_1^3. */
  for (uint32_t i = 0; i < n; ++i) scaled[i] = 0.0;
  for (uint32_t i = 0; i < n; ++i) {
    double q = alias[i].q;
    scaled[i] += q;
    scaled[alias[i].alias] += 1.0 - q;
  }
  const double scale = 0.5 * (double)map->res * (double)map->res / (double)n;
  for (uint32_t i = 0; i < n; ++i) pdf[i] = (float)(scaled[i] * scale);
  if (scaled != scaled_buf) free(scaled);
  return true;
}

iris_vec3 iris_cache_sample(const iris_octmap *map, const float *pdf, const iris_cache_alias *alias,
                            float u0, float u1, float u2, float *pdf_out) {
  return iris_cache_sample_refined(map, pdf, alias, NULL, NULL, u0, u1, u2, pdf_out);
}

iris_vec3 iris_cache_sample_refined(const iris_octmap *map, const float *pdf, const iris_cache_alias *alias,
                                    const uint8_t *slot, const float *sub, float u0, float u1, float u2,
                                    float *pdf_out) {
  /* Alias table: column floor(u0 n), kept when the fraction is below q. */
  const uint32_t n = map->texel_count;
  float x = u0 * (float)n;
  uint32_t col = (uint32_t)x;
  if (col >= n) col = n - 1;
  const iris_cache_alias e = alias[col];
  const uint32_t texel = x - (float)col < e.q ? col : e.alias;
  /* Uniform point of the texel in map coordinates (no trigonometry). The
   * octahedron point q (|q|_1 = 1) normalised is w = q / |q|_2, so
   * 1 / |w|_1^3 = |q|_2^3. */
  uint32_t i = texel % (uint32_t)map->width, j = texel / (uint32_t)map->width;
  float u, v, m = 1.0f;
  if (slot && slot[texel]) { /* a refined texel: its sub-cell, then a point in it (refine.h) */
    const float *mk = sub + (size_t)(slot[texel] - 1) * IRIS_REFINE_SUB;
    int k = iris_refine_pick(mk, &u1);
    m = mk[k];
    u = (float)i + ((float)(k & 3) + u1) * 0.25f;
    v = (float)j + ((float)(k >> 2) + u2) * 0.25f;
  } else {
    u = (float)i + u1;
    v = (float)j + u2;
  }
  float a, sign = 1.0f, r = (float)map->res;
  if (i < (uint32_t)map->res) {
    a = 2.0f * u / r - 1.0f;
  } else {
    a = 1.0f - 2.0f * (u - r) / r;
    sign = -1.0f;
  }
  float b = 2.0f * v / r - 1.0f;
  float px = 0.5f * (a + b), py = 0.5f * (b - a);
  float pz = sign * fmaxf(0.0f, 1.0f - fabsf(px) - fabsf(py));
  float l2 = sqrtf(px * px + py * py + pz * pz);
  float inv = 1.0f / l2;
  *pdf_out = pdf[texel] * m * l2 * l2 * l2;
  return iris_v3(px * inv, py * inv, pz * inv);
}

float iris_cache_density_factor(iris_vec3 w) {
  float l1 = fabsf(w.x) + fabsf(w.y) + fabsf(w.z);
  float l2 = sqrtf(w.x * w.x + w.y * w.y + w.z * w.z);
  float r = l2 / l1;
  return r * r * r;
}

float iris_cache_pdf(const iris_octmap *map, const float *pdf, iris_vec3 w) {
  return iris_cache_pdf_refined(map, pdf, NULL, NULL, w);
}

float iris_cache_pdf_refined(const iris_octmap *map, const float *pdf, const uint8_t *slot, const float *sub,
                             iris_vec3 w) {
  float l2 = sqrtf(w.x * w.x + w.y * w.y + w.z * w.z), factor;
  int k;
  if (!(l2 > 0.0f)) return 0.0f;
  int32_t t = iris_cache_cell(map->res, map->sphere, iris_scale(w, 1.0f / l2), &factor, &k);
  if (t < 0) return 0.0f;
  float m = slot && slot[t] ? sub[(size_t)(slot[t] - 1) * IRIS_REFINE_SUB + k] : 1.0f;
  return pdf[t] * factor * m;
}
