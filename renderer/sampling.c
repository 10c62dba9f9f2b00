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
    *u_remapped = d->cdf[lo + 1] > d->cdf[lo] ? iris_rescale_unit(u, d->cdf[lo], d->cdf[lo + 1]) : 0.0f;
  }
  return lo;
}

float iris_spherical_triangle_area(iris_vec3 a, iris_vec3 b, iris_vec3 c) {
  /* In double, and the triple product from the edges (a . (b x c) = a . ((b - a) x (c - a))):
   * for a small, distant triangle a, b and c are nearly parallel and the direct
   * triple product cancels catastrophically in float. */
  double ax = a.x, ay = a.y, az = a.z, bx = b.x, by = b.y, bz = b.z, cx = c.x, cy = c.y, cz = c.z;
  double la = sqrt(ax * ax + ay * ay + az * az), lb = sqrt(bx * bx + by * by + bz * bz),
         lc = sqrt(cx * cx + cy * cy + cz * cz);
  if (!(la > 0.0) || !(lb > 0.0) || !(lc > 0.0)) return 0.0f;
  double e1x = bx - ax, e1y = by - ay, e1z = bz - az, e2x = cx - ax, e2y = cy - ay, e2z = cz - az;
  double nx = e1y * e2z - e1z * e2y, ny = e1z * e2x - e1x * e2z, nz = e1x * e2y - e1y * e2x;
  /* tan(omega / 2) = |a . (b x c)| / (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|) */
  double num = fabs(ax * nx + ay * ny + az * nz);
  double den = la * lb * lc + (ax * bx + ay * by + az * bz) * lc + (ax * cx + ay * cy + az * cz) * lb +
               (bx * cx + by * cy + bz * cz) * la;
  double omega = 2.0 * atan2(num, den);
  if (omega < 0.0) omega += 2.0 * IRIS_PI;
  return (float)omega;
}

/* Arvo's construction loses accuracy in float for slivers and for triangles
 * seen at grazing angles (directions land outside the triangle), so it runs
 * in double. */
typedef struct dvec3 {
  double x, y, z;
} dvec3;
static dvec3 dv(iris_vec3 v) { return (dvec3){v.x, v.y, v.z}; }
static double ddot(dvec3 a, dvec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static dvec3 dcross(dvec3 a, dvec3 b) {
  return (dvec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static dvec3 dscale(dvec3 a, double s) { return (dvec3){a.x * s, a.y * s, a.z * s}; }
static dvec3 dadd(dvec3 a, dvec3 b) { return (dvec3){a.x + b.x, a.y + b.y, a.z + b.z}; }
static dvec3 dsub(dvec3 a, dvec3 b) { return (dvec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static double dlen(dvec3 a) { return sqrt(ddot(a, a)); }
static dvec3 dnorm(dvec3 a) { return dscale(a, 1.0 / dlen(a)); }

/* angle between unit vectors, accurate near 0 and pi (pbrt-v4's AngleBetween) */
static double angle_between(dvec3 v1, dvec3 v2) {
  if (ddot(v1, v2) < 0.0) return IRIS_PI - 2.0 * asin(fmin(1.0, 0.5 * dlen(dadd(v1, v2))));
  return 2.0 * asin(fmin(1.0, 0.5 * dlen(dsub(v2, v1))));
}

/* v - (v . w) w, normalised: the component of v orthogonal to unit w. */
static dvec3 orthogonal_unit(dvec3 v, dvec3 w) { return dnorm(dsub(v, dscale(w, ddot(v, w)))); }

bool iris_sample_spherical_triangle(iris_vec3 a_in, iris_vec3 b_in, iris_vec3 c_in, float u0,
                                    float u1, iris_vec3 *wi) {
  dvec3 a = dv(a_in), b = dv(b_in), c = dv(c_in);
  if (!(dlen(a) > 0.0) || !(dlen(b) > 0.0) || !(dlen(c) > 0.0)) return false;
  a = dnorm(a);
  b = dnorm(b);
  c = dnorm(c);
  dvec3 n_ab = dcross(a, b), n_bc = dcross(b, c), n_ca = dcross(c, a);
  double l_ab = dlen(n_ab), l_bc = dlen(n_bc), l_ca = dlen(n_ca);
  if (!(l_ab > 1e-14) || !(l_bc > 1e-14) || !(l_ca > 1e-14)) return false;
  n_ab = dscale(n_ab, 1.0 / l_ab);
  n_bc = dscale(n_bc, 1.0 / l_bc);
  n_ca = dscale(n_ca, 1.0 / l_ca);
  /* the spherical triangle's interior angles at a, b, c */
  double alpha = angle_between(n_ab, dscale(n_ca, -1.0));
  double beta = angle_between(n_bc, dscale(n_ab, -1.0));
  double gamma = angle_between(n_ca, dscale(n_bc, -1.0));
  /* A' + pi: the area of the sub-triangle (a, b, c') chosen by u0, plus pi */
  double a_pi = alpha + beta + gamma;
  if (!(a_pi - IRIS_PI > 0.0)) return false;
  double ap_pi = IRIS_PI + (double)u0 * (a_pi - IRIS_PI);
  double cos_alpha = cos(alpha), sin_alpha = sin(alpha);
  double sin_phi = sin(ap_pi) * cos_alpha - cos(ap_pi) * sin_alpha;
  double cos_phi = cos(ap_pi) * cos_alpha + sin(ap_pi) * sin_alpha;
  double k1 = cos_phi + cos_alpha;
  double k2 = sin_phi - sin_alpha * ddot(a, b); /* dot(a, b) = cos of the side c */
  double den = (k2 * sin_phi + k1 * cos_phi) * sin_alpha;
  double cos_bp = den != 0.0 ? (k2 + (k2 * cos_phi - k1 * sin_phi) * cos_alpha) / den : 1.0;
  cos_bp = fmin(1.0, fmax(-1.0, cos_bp));
  double sin_bp = sqrt(fmax(0.0, 1.0 - cos_bp * cos_bp));
  /* c' on the arc from a to c, then the point on the arc from b to c' */
  dvec3 cp = dadd(dscale(a, cos_bp), dscale(orthogonal_unit(c, a), sin_bp));
  double cos_theta = 1.0 - (double)u1 * (1.0 - ddot(cp, b));
  double sin_theta = sqrt(fmax(0.0, 1.0 - cos_theta * cos_theta));
  dvec3 w = b;
  if (sin_theta > 0.0) w = dadd(dscale(b, cos_theta), dscale(orthogonal_unit(cp, b), sin_theta));
  w = dnorm(w);
  iris_vec3 out = iris_v3((float)w.x, (float)w.y, (float)w.z);
  if (!iris_isfinite3(out)) return false;
  *wi = out;
  return true;
}
