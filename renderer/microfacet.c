/* GGX and Fresnel (see microfacet.h; formulas in docs/materials.md). */
#include "renderer/microfacet.h"

#include "renderer/sampling.h"

/* fmaxf(x, 0.0f) and iris_safe_sqrt with the same results (x > 0 ? x : +0,
 * NaN -> 0), inlined: without -ffinite-math-only fmaxf is a call into libm. */
static inline float max0(float x) { return x > 0.0f ? x : 0.0f; }
static inline float safe_sqrt(float x) { return sqrtf(max0(x)); }

float iris_ggx_d(float alpha, iris_vec3 m) {
  if (m.z <= 0.0f) return 0.0f;
  /* 1 + (a^2 - 1) cos^2 written as sin^2 + a^2 cos^2 with sin^2 from the
   * tangential components: no cancellation near the peak of a sharp lobe. */
  float s2 = m.x * m.x + m.y * m.y, c2 = m.z * m.z;
  float len2 = s2 + c2;
  float a2 = alpha * alpha;
  float t = (s2 + a2 * c2) / len2;
  if (!(t > 0.0f)) return 0.0f;
  return a2 / (IRIS_PI * t * t);
}

float iris_ggx_lambda(float alpha, iris_vec3 w) {
  float c2 = w.z * w.z;
  if (c2 <= 0.0f) return INFINITY;
  float s2 = max0(w.x * w.x + w.y * w.y);
  float a2t2 = alpha * alpha * s2 / c2;
  return 0.5f * (sqrtf(1.0f + a2t2) - 1.0f);
}

float iris_ggx_g1(float alpha, iris_vec3 w) {
  float c2 = w.z * w.z;
  if (c2 <= 0.0f) return 0.0f;
  float s2 = max0(w.x * w.x + w.y * w.y);
  /* 2 / (1 + sqrt(1 + a^2 tan^2)): the form Cycles 3.4 uses, finite at grazing. */
  return 2.0f / (1.0f + sqrtf(1.0f + alpha * alpha * s2 / c2));
}

/* Heitz 2018 with the stretch (ax, ay); inlined into both samplers below. */
static inline iris_vec3 sample_vndf(float ax, float ay, iris_vec3 wo, float u0, float u1) {
  /* Section 3.2: stretch to the hemisphere configuration. */
  iris_vec3 vh = iris_normalize(iris_v3(ax * wo.x, ay * wo.y, wo.z));
  /* Section 4.1: orthonormal basis. */
  float lensq = vh.x * vh.x + vh.y * vh.y;
  iris_vec3 t1 = lensq > 1e-7f ? iris_scale(iris_v3(-vh.y, vh.x, 0.0f), 1.0f / sqrtf(lensq))
                               : iris_v3(1.0f, 0.0f, 0.0f);
  iris_vec3 t2 = iris_cross(vh, t1);
  /* Section 4.2: parameterisation of the projected area. */
  float x, y;
  iris_sample_concentric_disk(u0, u1, &x, &y);
  float s = 0.5f * (1.0f + vh.z);
  y = (1.0f - s) * safe_sqrt(1.0f - x * x) + s * y;
  /* Section 4.3: reprojection onto the hemisphere. */
  iris_vec3 nh = iris_add(iris_add(iris_scale(t1, x), iris_scale(t2, y)),
                          iris_scale(vh, safe_sqrt(1.0f - x * x - y * y)));
  /* Section 3.4: back to the ellipsoid configuration. */
  iris_vec3 m = iris_normalize(iris_v3(ax * nh.x, ay * nh.y, fmaxf(1e-7f, nh.z)));
  return m;
}

iris_vec3 iris_ggx_sample_vndf(float alpha, iris_vec3 wo, float u0, float u1) {
  return sample_vndf(alpha, alpha, wo, u0, u1);
}

iris_vec3 iris_ggx_sample_vndf_aniso(float ax, float ay, iris_vec3 wo, float u0, float u1) {
  return sample_vndf(ax, ay, wo, u0, u1);
}

float iris_ggx_d_aniso(float ax, float ay, iris_vec3 m) {
  if (m.z <= 0.0f) return 0.0f;
  float len2 = m.x * m.x + m.y * m.y + m.z * m.z;
  float x = m.x / ax, y = m.y / ay;
  float t = (x * x + y * y + m.z * m.z) / len2;
  if (!(t > 0.0f)) return 0.0f;
  return 1.0f / (IRIS_PI * ax * ay * t * t);
}

float iris_ggx_lambda_aniso(float ax, float ay, iris_vec3 w) {
  float c2 = w.z * w.z;
  if (c2 <= 0.0f) return INFINITY;
  float a2t2 = max0(ax * ax * w.x * w.x + ay * ay * w.y * w.y) / c2;
  return 0.5f * (sqrtf(1.0f + a2t2) - 1.0f);
}

float iris_ggx_g1_aniso(float ax, float ay, iris_vec3 w) {
  float c2 = w.z * w.z;
  if (c2 <= 0.0f) return 0.0f;
  float a2t2 = max0(ax * ax * w.x * w.x + ay * ay * w.y * w.y) / c2;
  return 2.0f / (1.0f + sqrtf(1.0f + a2t2));
}

float iris_ggx_vndf_pdf_aniso(float ax, float ay, iris_vec3 wo, iris_vec3 m) {
  float wm = iris_dot(wo, m);
  if (wo.z <= 0.0f || wm <= 0.0f) return 0.0f;
  return iris_ggx_g1_aniso(ax, ay, wo) * wm * iris_ggx_d_aniso(ax, ay, m) / wo.z;
}

float iris_ggx_vndf_pdf(float alpha, iris_vec3 wo, iris_vec3 m) {
  float wm = iris_dot(wo, m);
  if (wo.z <= 0.0f || wm <= 0.0f) return 0.0f;
  return iris_ggx_g1(alpha, wo) * wm * iris_ggx_d(alpha, m) / wo.z;
}

float iris_fresnel_dielectric(float cos_i, float eta) {
  /* Same closed form as Cycles' fresnel_dielectric_cos (Walter 2007 eq. 22). */
  float c = fabsf(cos_i);
  float g = eta * eta - 1.0f + c * c;
  if (g <= 0.0f) return 1.0f;
  g = sqrtf(g);
  float a = (g - c) / (g + c);
  float b = (c * (g + c) - 1.0f) / (c * (g - c) + 1.0f);
  return iris_clampf(0.5f * a * a * (1.0f + b * b), 0.0f, 1.0f);
}

float iris_fresnel_schlick(float f0, float cos_theta) {
  float m = iris_clampf(1.0f - fabsf(cos_theta), 0.0f, 1.0f);
  float m2 = m * m;
  return f0 + (1.0f - f0) * m2 * m2 * m;
}

bool iris_refract(iris_vec3 w, iris_vec3 m, float eta, iris_vec3 *wt) {
  float cos_i = iris_dot(w, m);
  float inv = 1.0f / eta;
  float sin2_t = inv * inv * fmaxf(0.0f, 1.0f - cos_i * cos_i);
  if (sin2_t >= 1.0f) return false;
  float cos_t = sqrtf(1.0f - sin2_t);
  /* w on the side of m (cos_i > 0): transmitted ray leaves on the other side. */
  *wt = iris_add(iris_scale(w, -inv), iris_scale(m, inv * cos_i - cos_t));
  return true;
}
