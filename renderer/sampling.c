/* Sample warps and their densities (see sampling.h; formulas in docs/materials.md). */
#include "renderer/sampling.h"

#include <stdlib.h>
#include <string.h>

/* iris_safe_sqrt with the same results (fmaxf(x, 0): x > 0 ? x : +0, NaN -> 0),
 * inlined: without -ffinite-math-only fmaxf is a call into libm. */
static inline float safe_sqrt(float x) { return sqrtf(x > 0.0f ? x : 0.0f); }

void iris_sample_concentric_disk(float u0, float u1, float *x, float *y) {
  /* Shirley & Chiu 1997: squares to rings, so strata stay compact. */
  float a = 2.0f * u0 - 1.0f;
  float b = 2.0f * u1 - 1.0f;
  if (a == 0.0f && b == 0.0f) {
    *x = 0.0f;
    *y = 0.0f;
    return;
  }
  float r, phi;
  if (fabsf(a) > fabsf(b)) {
    r = a;
    phi = (IRIS_PI / 4.0f) * (b / a);
  } else {
    r = b;
    phi = (IRIS_PI / 2.0f) - (IRIS_PI / 4.0f) * (a / b);
  }
  *x = r * cosf(phi);
  *y = r * sinf(phi);
}

iris_vec3 iris_sample_cosine_hemisphere(float u0, float u1) {
  float x, y;
  iris_sample_concentric_disk(u0, u1, &x, &y);
  /* z > 0 strictly so that callers never get a direction in the surface plane. */
  float z = safe_sqrt(1.0f - x * x - y * y);
  return iris_v3(x, y, z > 1e-7f ? z : 1e-7f); /* = fmaxf(z, 1e-7f), inlined */
}

iris_vec3 iris_sample_uniform_hemisphere(float u0, float u1) {
  float z = u0;
  float r = safe_sqrt(1.0f - z * z);
  float phi = 2.0f * IRIS_PI * u1;
  return iris_v3(r * cosf(phi), r * sinf(phi), z);
}

iris_vec3 iris_sample_uniform_sphere(float u0, float u1) {
  float z = 1.0f - 2.0f * u0;
  float r = safe_sqrt(1.0f - z * z);
  float phi = 2.0f * IRIS_PI * u1;
  return iris_v3(r * cosf(phi), r * sinf(phi), z);
}

iris_vec3 iris_sample_uniform_cone(float u0, float u1, float cos_max) {
  float z = 1.0f - u0 * (1.0f - cos_max);
  float r = safe_sqrt(1.0f - z * z);
  float phi = 2.0f * IRIS_PI * u1;
  return iris_v3(r * cosf(phi), r * sinf(phi), z);
}

float iris_sample_uniform_cone_pdf(float cos_theta, float cos_max) {
  if (cos_theta < cos_max || cos_max >= 1.0f) return 0.0f;
  return 1.0f / (2.0f * IRIS_PI * (1.0f - cos_max));
}

void iris_sample_uniform_triangle(float u0, float u1, float *b0, float *b1) {
  /* Heitz 2019, "A Low-Distortion Map Between Triangle and Square". */
  if (u0 < u1) {
    *b0 = u0 * 0.5f;
    *b1 = u1 - *b0;
  } else {
    *b1 = u1 * 0.5f;
    *b0 = u0 - *b1;
  }
}

iris_status iris_distrib1d_create(iris_distrib1d *d, const float *weights, size_t count,
                                  iris_error *err) {
  memset(d, 0, sizeof(*d));
  if (count == 0 || count > ((size_t)1 << 32)) {
    return iris_error_set(err, IRIS_ERR_INVALID, NULL, 0, NULL,
                          "discrete distribution needs 1 to 2^32 entries, got %zu", count);
  }
  d->cdf = malloc((count + 1) * sizeof(float));
  d->func = malloc(count * sizeof(float));
  if (!d->cdf || !d->func) {
    iris_distrib1d_destroy(d);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL,
                          "out of memory for a distribution of %zu entries", count);
  }
  d->count = count;
  double sum = 0.0;
  for (size_t i = 0; i < count; ++i) {
    float w = weights[i];
    d->func[i] = (isfinite(w) && w > 0.0f) ? w : 0.0f;
    sum += d->func[i];
  }
  d->total = sum;
  /* Accumulate in double so that long tables keep their small entries. */
  double acc = 0.0;
  d->cdf[0] = 0.0f;
  for (size_t i = 0; i < count; ++i) {
    acc += sum > 0.0 ? (double)d->func[i] / sum : 1.0 / (double)count;
    d->cdf[i + 1] = (float)acc;
  }
  /* cdf ends at exactly 1 right after the last live entry, so rounding can
   * never hand a sample to a zero-weight tail. */
  size_t last = count;
  while (last > 1 && sum > 0.0 && d->func[last - 1] == 0.0f) --last;
  for (size_t i = last; i <= count; ++i) d->cdf[i] = 1.0f;
  /* Guide table: guide[j] = largest i < count with cdf[i] <= j / m. Tables
   * of up to 8 entries are searched directly. */
  if (count > 8 && count <= ((size_t)1 << 31)) {
    size_t m = count;
    d->guide = malloc(m * sizeof(uint32_t));
    if (!d->guide) {
      iris_distrib1d_destroy(d);
      return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL,
                            "out of memory for a distribution of %zu entries", count);
    }
    d->guide_count = m;
    size_t i = 0;
    for (size_t j = 0; j < m; ++j) {
      float lo = (float)((double)j / (double)m);
      while (i + 1 < count && d->cdf[i + 1] <= lo) ++i;
      d->guide[j] = (uint32_t)i;
    }
  }
  return IRIS_OK;
}

void iris_distrib1d_destroy(iris_distrib1d *d) {
  if (!d) return;
  free(d->cdf);
  free(d->func);
  free(d->guide);
  memset(d, 0, sizeof(*d));
}

float iris_distrib1d_pmf(const iris_distrib1d *d, size_t index) {
  if (index >= d->count) return 0.0f;
  if (d->total <= 0.0) return 1.0f / (float)d->count;
  return (float)((double)d->func[index] / d->total);
}

size_t iris_distrib1d_sample(const iris_distrib1d *d, float u, float *pmf, float *u_remapped) {
  /* Largest i < count with cdf[i] <= u (cdf is non-decreasing, cdf[count] = 1 > u),
   * which skips zero-probability entries. */
  size_t lo;
  if (d->guide) {
    float fu = u * (float)d->guide_count;
    size_t j = fu > 0.0f ? (size_t)fu : 0;
    if (j >= d->guide_count) j = d->guide_count - 1;
    lo = d->guide[j];
    /* The answer lies in [guide[j], guide[j + 1]] (up to the rounding of u * m,
     * which the walks fix); a bucket can span many entries of tiny weight
     * (the dark texels of an environment map's row), so the rest is a
     * binary search rather than a walk. */
    while (lo > 0 && d->cdf[lo] > u) --lo;
    size_t hi = j + 1 < d->guide_count ? (size_t)d->guide[j + 1] + 1 : d->count;
    if (hi > d->count) hi = d->count;
    if (hi <= lo) hi = lo + 1;
    while (hi < d->count && d->cdf[hi] <= u) ++hi;
    while (hi - lo > 1) { /* invariant: cdf[lo] <= u < cdf[hi] (cdf[count] = 1 > u) */
      size_t mid = lo + (hi - lo) / 2;
      if (d->cdf[mid] <= u) lo = mid;
      else hi = mid;
    }
  } else {
    size_t hi = d->count; /* invariant: cdf[lo] <= u < cdf[hi] */
    lo = 0;
    while (hi - lo > 1) {
      size_t mid = lo + (hi - lo) / 2;
      if (d->cdf[mid] <= u) lo = mid;
      else hi = mid;
    }
  }
  if (pmf) *pmf = iris_distrib1d_pmf(d, lo);
  if (u_remapped) {
    float width = d->cdf[lo + 1] - d->cdf[lo];
    float r = width > 0.0f ? (u - d->cdf[lo]) / width : 0.0f;
    *u_remapped = iris_clampf(r, 0.0f, 0x1.fffffep-1f);
  }
  return lo;
}
