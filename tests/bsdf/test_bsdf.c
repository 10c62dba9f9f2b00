/* bsdf.materials: every BSDF at several roughnesses and incident angles
 * (grazing included, both faces for transmissive ones):
 * - chi-square of iris_bsdf_sample against iris_bsdf_pdf (tests/common/chi2),
 * - pdf mass <= 1 (= 1 for Lambert), f cos / pdf from sampling agrees with the
 *   quadrature of f |cos| (eval, sample and pdf are one BSDF),
 * - albedo <= 1 (white furnace), reciprocity of reflection lobes,
 * - point values against formulas written out here from Cycles 3.4 and glTF,
 * - smooth (delta) lobes: reflect/refract split equals the exact Fresnel,
 * - no NaN/Inf at grazing or degenerate directions. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "chi2.h"
#include "renderer/bsdf.h"
#include "renderer/microfacet.h"

#define M_PI 3.14159265358979323846

static int failures = 0, passes = 0;
static int n_chi2_tests = 1;

static void expect(bool ok, const char *what, const char *detail) {
  if (!ok || getenv("IRIS_TEST_VERBOSE")) printf("%s %s: %s\n", ok ? "ok  " : "FAIL", what, detail);
  if (ok) passes++;
  else failures++;
}

typedef struct ctx {
  iris_bsdf b;
  iris_vec3 wo;
} ctx;

static bool sample_dir(void *c, const double u[3], double d[3]) {
  const ctx *x = c;
  struct iris_bsdf_sample s;
  if (!iris_bsdf_sample(&x->b, x->wo, (float)u[0], (float)u[1], (float)u[2], &s)) return false;
  d[0] = s.wi.x;
  d[1] = s.wi.y;
  d[2] = s.wi.z;
  return true;
}

static double pdf_dir(void *c, const double d[3]) {
  const ctx *x = c;
  return iris_bsdf_pdf(&x->b, x->wo, iris_v3((float)d[0], (float)d[1], (float)d[2]));
}

/* Average over channels of f |cos wi|. */
static double fcos_dir(void *c, const double d[3]) {
  const ctx *x = c;
  iris_vec3 wi = iris_v3((float)d[0], (float)d[1], (float)d[2]);
  iris_vec3 f = iris_bsdf_eval(&x->b, x->wo, wi);
  return iris_avg3(f) * fabs(d[2]);
}

static iris_vec3 dir_from_angle(float theta_deg, float phi) {
  float t = theta_deg * IRIS_PI / 180.0f;
  return iris_v3(sinf(t) * cosf(phi), sinf(t) * sinf(phi), cosf(t));
}

static iris_bsdf make(iris_bsdf_type type, iris_vec3 color, float roughness) {
  iris_bsdf b;
  memset(&b, 0, sizeof(b));
  b.type = type;
  b.color = color;
  b.roughness = roughness;
  b.ior = 1.5f;
  b.specular = 1.0f;
  b.specular_color = iris_v3(1.0f, 1.0f, 1.0f);
  return b;
}

/* One configuration: chi-square, pdf mass, eval/sample consistency, albedo;
 * `quadrature` adds the (slower) quadrature of f |cos| against the MC albedo. */
static void check_config(const char *name, iris_bsdf b, iris_vec3 wo, bool full_sphere,
                         bool quadrature) {
  ctx c = {b, wo};
  char what[200], msg[512];
  clock_t t0 = clock();
  chi2_domain dom = {full_sphere ? CHI2_SPHERE : CHI2_HEMISPHERE, 0, 0, 42};
  const size_t n = 100000;
  chi2_result r = chi2_run(&dom, sample_dir, pdf_dir, &c, n, 0.01, n_chi2_tests);
  clock_t t1 = clock();
  snprintf(what, sizeof(what), "%s wo.z=%.3f chi2", name, wo.z);
  expect(r.passed, what, r.message);
  snprintf(what, sizeof(what), "%s wo.z=%.3f pdf mass", name, wo.z);
  snprintf(msg, sizeof(msg), "%.5f", r.pdf_integral);
  expect(r.pdf_integral <= 1.002, what, msg);

  /* MC estimate of the albedo from sampling vs quadrature of f |cos|. */
  uint64_t st = 7;
  double sum = 0.0, sum2 = 0.0;
  bool finite = true, pointwise_ok = true;
  const size_t m = 50000;
  for (size_t i = 0; i < m; ++i) {
    struct iris_bsdf_sample s;
    double w = 0.0;
    if (iris_bsdf_sample(&b, wo, (float)chi2_uniform(&st), (float)chi2_uniform(&st),
                         (float)chi2_uniform(&st), &s)) {
      w = iris_avg3(s.f) * fabs(s.wi.z) / s.pdf;
      if (!isfinite(w)) finite = false;
      /* The sample's f and pdf are what eval and pdf say for that direction. */
      iris_vec3 fe = iris_bsdf_eval(&b, wo, s.wi);
      float pe = iris_bsdf_pdf(&b, wo, s.wi);
      if (fabsf(fe.x - s.f.x) > 1e-4f * fmaxf(fe.x, 1.0f) || fabsf(pe - s.pdf) > 1e-4f * fmaxf(pe, 1.0f))
        pointwise_ok = false;
    }
    sum += w;
    sum2 += w * w;
  }
  double mean = sum / m, var = fmax(0.0, sum2 / m - mean * mean), se = sqrt(var / m);
  double quad = quadrature ? chi2_integrate(&dom, fcos_dir, &c, sample_dir, &c, 20000) : mean;
  snprintf(what, sizeof(what), "%s wo.z=%.3f sample f/pdf = eval/pdf", name, wo.z);
  expect(pointwise_ok, what, "");
  /* Wherever f > 0 the pdf must be > 0, or sampling misses energy. */
  bool support_ok = true;
  for (int i = 0; i < 20000; ++i) {
    double u0 = chi2_uniform(&st), u1 = chi2_uniform(&st);
    double z = full_sphere ? 1.0 - 2.0 * u0 : u0, rr = sqrt(fmax(0.0, 1.0 - z * z));
    iris_vec3 wi = iris_v3((float)(rr * cos(6.283185307 * u1)), (float)(rr * sin(6.283185307 * u1)), (float)z);
    if (iris_max3(iris_bsdf_eval(&b, wo, wi)) > 0.0f && !(iris_bsdf_pdf(&b, wo, wi) > 0.0f)) support_ok = false;
  }
  snprintf(what, sizeof(what), "%s wo.z=%.3f pdf > 0 where f > 0", name, wo.z);
  expect(support_ok, what, "");
  snprintf(msg, sizeof(msg), "MC %.5f +- %.5f, quadrature %s %.5f", mean, se,
           quadrature ? "" : "(not run)", quad);
  snprintf(what, sizeof(what), "%s wo.z=%.3f albedo <= 1", name, wo.z);
  expect(finite && quad <= 1.0 + 2e-3 && mean <= 1.0 + 5.0 * se + 1e-4, what, msg);
  if (quadrature) {
    snprintf(what, sizeof(what), "%s wo.z=%.3f E[f cos/pdf] = int f cos", name, wo.z);
    expect(fabs(mean - quad) < 5.0 * se + 2e-3 * fmax(quad, 0.05), what, msg);
  }
  if (getenv("IRIS_TEST_TIMING"))
    printf("time %s wo.z=%.3f: chi2 %.2fs, consistency %.2fs\n", name, wo.z,
           (double)(t1 - t0) / CLOCKS_PER_SEC, (double)(clock() - t1) / CLOCKS_PER_SEC);
}

static void check_reciprocity(const char *name, iris_bsdf b) {
  uint64_t st = 11;
  double worst = 0.0;
  for (int i = 0; i < 2000; ++i) {
    iris_vec3 a = dir_from_angle((float)(89.0 * chi2_uniform(&st)), (float)(6.2831853 * chi2_uniform(&st)));
    iris_vec3 c = dir_from_angle((float)(89.0 * chi2_uniform(&st)), (float)(6.2831853 * chi2_uniform(&st)));
    iris_vec3 f1 = iris_bsdf_eval(&b, a, c), f2 = iris_bsdf_eval(&b, c, a);
    double d = fabs(f1.x - f2.x) / fmax(1e-3, fmax(f1.x, f2.x));
    if (d > worst) worst = d;
  }
  char what[160], msg[128];
  snprintf(what, sizeof(what), "%s reciprocity", name);
  snprintf(msg, sizeof(msg), "worst relative difference %.2e", worst);
  expect(worst < 1e-4, what, msg);
}

/* ---- formulas written out independently (Cycles 3.4 bsdf_microfacet.h) ---- */

static double cy_D(double alpha2, double cos_m) {
  double c2 = cos_m * cos_m, c4 = c2 * c2, t2 = (1.0 - c2) / c2;
  return alpha2 / (M_PI * c4 * (alpha2 + t2) * (alpha2 + t2));
}
static double cy_G1(double alpha2, double c) {
  return 2.0 / (1.0 + sqrt(1.0 + alpha2 * (1.0 - c * c) / (c * c)));
}
static double cy_fresnel(double cosi, double eta) {
  double c = fabs(cosi), g = eta * eta - 1.0 + c * c;
  if (g <= 0.0) return 1.0;
  g = sqrt(g);
  double A = (g - c) / (g + c), B = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
  return 0.5 * A * A * (1.0 + B * B);
}

static void check_point_values(void) {
  char msg[256];
  /* Lambert */
  iris_bsdf d = make(IRIS_BSDF_DIFFUSE, iris_v3(0.5f, 0.25f, 1.0f), 0.0f);
  iris_vec3 f = iris_bsdf_eval(&d, dir_from_angle(30, 0.3f), dir_from_angle(70, 2.0f));
  snprintf(msg, sizeof(msg), "f = %.6f %.6f %.6f", f.x, f.y, f.z);
  expect(fabs(f.x - 0.5 / M_PI) < 1e-6 && fabs(f.y - 0.25 / M_PI) < 1e-6 && fabs(f.z - 1.0 / M_PI) < 1e-6,
         "diffuse f = rho/pi", msg);
  expect(iris_bsdf_eval(&d, dir_from_angle(30, 0), iris_v3(0, 0.6f, -0.8f)).x == 0.0f,
         "diffuse below horizon is 0", "");

  /* Glossy = colour D G1 G1 / (4 cos cos), the separable form of Cycles 3.4. */
  double worst = 0.0;
  uint64_t st = 5;
  for (int i = 0; i < 500; ++i) {
    float r = 0.05f + 0.95f * (float)chi2_uniform(&st);
    iris_bsdf g = make(IRIS_BSDF_GLOSSY, iris_v3(0.9f, 0.6f, 0.3f), r);
    iris_vec3 wo = dir_from_angle((float)(88 * chi2_uniform(&st)), (float)(6.28 * chi2_uniform(&st)));
    iris_vec3 wi = dir_from_angle((float)(88 * chi2_uniform(&st)), (float)(6.28 * chi2_uniform(&st)));
    iris_vec3 h = iris_normalize(iris_add(wo, wi));
    double a2 = (double)r * r * r * r;
    double ref = 0.9 * cy_D(a2, h.z) * cy_G1(a2, wo.z) * cy_G1(a2, wi.z) / (4.0 * wo.z * wi.z);
    double got = iris_bsdf_eval(&g, wo, wi).x;
    double pref = cy_G1(a2, wo.z) * cy_D(a2, h.z) / (4.0 * wo.z);
    double pgot = iris_bsdf_pdf(&g, wo, wi);
    double e = fmax(fabs(got - ref) / fmax(ref, 1e-3), fabs(pgot - pref) / fmax(pref, 1e-3));
    if (e > worst) worst = e;
  }
  snprintf(msg, sizeof(msg), "worst relative error %.2e over 500 random (r, wo, wi)", worst);
  expect(worst < 2e-3, "glossy f and pdf = Cycles 3.4 GGX (separable G)", msg);

  /* Rough glass refraction = colour (1 - F(wo.n)) Walter eq. 21 (Cycles' out / cos). */
  worst = 0.0;
  for (int i = 0; i < 500; ++i) {
    float r = 0.1f + 0.9f * (float)chi2_uniform(&st);
    iris_bsdf g = make(IRIS_BSDF_GLASS, iris_v3(0.8f, 0.8f, 0.8f), r);
    bool inside = chi2_uniform(&st) < 0.5;
    double eta = inside ? 1.0 / 1.5 : 1.5;
    iris_vec3 wo = dir_from_angle((float)(85 * chi2_uniform(&st)), (float)(6.28 * chi2_uniform(&st)));
    iris_vec3 wi = dir_from_angle((float)(95 + 85 * chi2_uniform(&st)), (float)(6.28 * chi2_uniform(&st)));
    double a2 = (double)r * r * r * r;
    double hx = -(eta * wi.x + wo.x), hy = -(eta * wi.y + wo.y), hz = -(eta * wi.z + wo.z);
    double hl2 = hx * hx + hy * hy + hz * hz, hl = sqrt(hl2);
    hx /= hl, hy /= hl, hz /= hl;
    if (hz < 0) hx = -hx, hy = -hy, hz = -hz;
    double cho = hx * wo.x + hy * wo.y + hz * wo.z, chi = hx * wi.x + hy * wi.y + hz * wi.z;
    double ref = 0.0;
    if (cho > 0 && chi < 0) {
      double G = cy_G1(a2, wo.z) * cy_G1(a2, wi.z);
      ref = 0.8 * (1.0 - cy_fresnel(wo.z, eta)) * G * fabs(chi * cho) * cy_D(a2, hz) * eta * eta /
            (wo.z * hl2) / fabs(wi.z);
    }
    iris_vec3 wo_q = wo, wi_q = wi;
    if (inside) wo_q.z = -wo_q.z, wi_q.z = -wi_q.z;
    double got = iris_bsdf_eval(&g, wo_q, wi_q).x;
    double e = fabs(got - ref) / fmax(ref, 1e-3);
    if (e > worst) worst = e;
  }
  snprintf(msg, sizeof(msg), "worst relative error %.2e over 500 random pairs, both faces", worst);
  expect(worst < 2e-3, "glass refraction f = Cycles 3.4 GGX refraction x (1-F)", msg);

  /* Material -> BSDF: types, default IORs, clamping of texture-driven values. */
  iris_material mat;
  memset(&mat, 0, sizeof(mat));
  mat.type = IRIS_MATERIAL_GLASS;
  mat.specular = 1.0f;
  iris_bsdf fm = iris_bsdf_from_material(&mat, iris_v3(0.5f, NAN, -1.0f), 1.7f, 0.0f);
  mat.type = IRIS_MATERIAL_GLTF;
  mat.ior = 1.33f;
  mat.transmission = 0.25f;
  iris_bsdf fg = iris_bsdf_from_material(&mat, iris_v3(1, 1, 1), 0.4f, 2.0f);
  snprintf(msg, sizeof(msg), "glass ior %.3f colour %.2f %.2f %.2f roughness %.2f; gltf ior %.2f metallic %.2f",
           fm.ior, fm.color.x, fm.color.y, fm.color.z, fm.roughness, fg.ior, fg.metallic);
  expect(fm.type == IRIS_BSDF_GLASS && fm.ior == 1.45f && fm.color.x == 0.5f && fm.color.y == 0.0f &&
             fm.color.z == 0.0f && fm.roughness == 1.0f && fg.type == IRIS_BSDF_GLTF &&
             fg.ior == 1.33f && fg.metallic == 1.0f && fg.transmission == 0.25f,
         "bsdf from material", msg);
  expect(iris_bsdf_guiding_roughness(&fg) == 0.4f &&
             (iris_bsdf_lobes(&fm) & IRIS_LOBE_TRANSMISSION) && !iris_bsdf_is_delta(&fm),
         "lobes and guiding roughness", "");

  /* Fresnel */
  snprintf(msg, sizeof(msg), "F(1,1.5)=%.6f F(0.5,1.5)=%.6f F(0,1.5)=%.6f F(0.3,1/1.5)=%.6f",
           iris_fresnel_dielectric(1.0f, 1.5f), iris_fresnel_dielectric(0.5f, 1.5f),
           iris_fresnel_dielectric(0.0f, 1.5f), iris_fresnel_dielectric(0.3f, 1.0f / 1.5f));
  /* Reference for cos 0.5 from Snell + the s/p amplitude formulas. */
  double ci = 0.5, ct = sqrt(1.0 - (1.0 - ci * ci) / 2.25);
  double rs = (ci - 1.5 * ct) / (ci + 1.5 * ct), rp = (ct - 1.5 * ci) / (ct + 1.5 * ci);
  double f05 = 0.5 * (rs * rs + rp * rp);
  expect(fabsf(iris_fresnel_dielectric(1.0f, 1.5f) - 0.04f) < 1e-6f &&
             fabs(iris_fresnel_dielectric(0.5f, 1.5f) - f05) < 1e-6 &&
             iris_fresnel_dielectric(0.0f, 1.5f) == 1.0f &&
             iris_fresnel_dielectric(0.3f, 1.0f / 1.5f) == 1.0f,
         "exact dielectric Fresnel", msg);

  /* glTF: specular 0, metallic 0, no transmission is exactly Lambert. */
  iris_bsdf l = make(IRIS_BSDF_GLTF, iris_v3(0.7f, 0.5f, 0.2f), 0.4f);
  l.specular = 0.0f;
  f = iris_bsdf_eval(&l, dir_from_angle(20, 1), dir_from_angle(60, 4));
  snprintf(msg, sizeof(msg), "f = %.6f %.6f %.6f", f.x, f.y, f.z);
  expect(fabs(f.x - 0.7 / M_PI) < 1e-6 && fabs(f.z - 0.2 / M_PI) < 1e-6 &&
             iris_bsdf_guiding_roughness(&l) == INFINITY,
         "gltf specular 0 = Lambert", msg);

  /* glTF dielectric: (1 - F) base/pi + F D V with height-correlated V (Appendix B). */
  iris_bsdf p = make(IRIS_BSDF_GLTF, iris_v3(0.6f, 0.6f, 0.6f), 0.5f);
  iris_vec3 wo = dir_from_angle(40, 0.2f), wi = dir_from_angle(25, 3.0f);
  iris_vec3 h = iris_normalize(iris_add(wo, wi));
  double a = 0.25, a2 = a * a, vh = iris_dot(wo, h);
  double F = 0.04 + 0.96 * pow(1.0 - vh, 5.0);
  double Dg = a2 / (M_PI * pow(h.z * h.z * (a2 - 1.0) + 1.0, 2.0));
  double V = 0.5 / (wi.z * sqrt(wo.z * wo.z * (1.0 - a2) + a2) + wo.z * sqrt(wi.z * wi.z * (1.0 - a2) + a2));
  double Fv = 0.04 + 0.96 * pow(1.0 - wo.z, 5.0); /* base layer weight at N.V (see bsdf.c) */
  double ref = (1.0 - Fv) * 0.6 / M_PI + F * Dg * V;
  double got = iris_bsdf_eval(&p, wo, wi).x;
  snprintf(msg, sizeof(msg), "got %.6f expected %.6f", got, ref);
  expect(fabs(got - ref) < 1e-4 * ref, "gltf dielectric = Appendix B (base weight at N.V)", msg);

  /* glTF metal: F_schlick(baseColor) D V. */
  p.metallic = 1.0f;
  p.color = iris_v3(0.9f, 0.5f, 0.1f);
  double Fm = 0.5 + 0.5 * pow(1.0 - vh, 5.0);
  got = iris_bsdf_eval(&p, wo, wi).y;
  ref = Fm * Dg * V;
  snprintf(msg, sizeof(msg), "got %.6f expected %.6f", got, ref);
  expect(fabs(got - ref) < 1e-4 * ref, "gltf metal = Appendix B", msg);
}

static void check_smooth(void) {
  char msg[256];
  /* Mirror: one direction, weight = colour. */
  iris_bsdf m = make(IRIS_BSDF_GLOSSY, iris_v3(0.8f, 0.7f, 0.6f), 0.0f);
  iris_vec3 wo = dir_from_angle(60, 1.0f);
  struct iris_bsdf_sample s;
  bool ok = iris_bsdf_sample(&m, wo, 0.3f, 0.2f, 0.9f, &s);
  float w = s.f.x * s.wi.z / s.pdf;
  snprintf(msg, sizeof(msg), "wi = %.4f %.4f %.4f weight %.6f", s.wi.x, s.wi.y, s.wi.z, w);
  expect(ok && (s.lobe & IRIS_LOBE_DELTA) && fabsf(s.wi.x + wo.x) < 1e-6f &&
             fabsf(s.wi.z - wo.z) < 1e-6f && fabsf(w - 0.8f) < 1e-5f && iris_bsdf_is_delta(&m) &&
             iris_bsdf_guiding_roughness(&m) == 0.0f && iris_bsdf_eval(&m, wo, s.wi).x == 0.0f,
         "mirror (roughness 0)", msg);
  /* The Cycles singular threshold: alpha^2 <= 1e-7. */
  iris_bsdf t = make(IRIS_BSDF_GLOSSY, iris_v3(1, 1, 1), 0.0177f);
  iris_bsdf u = make(IRIS_BSDF_GLOSSY, iris_v3(1, 1, 1), 0.0179f);
  expect(iris_bsdf_is_delta(&t) && !iris_bsdf_is_delta(&u) &&
             0.0177f <= IRIS_BSDF_MIN_ROUGHNESS && 0.0179f > IRIS_BSDF_MIN_ROUGHNESS,
         "delta threshold at roughness^4 = 1e-7 (Cycles)", "");

  /* Smooth glass, both faces, several angles: reflection frequency = F,
   * every sample carries weight = colour, refraction obeys Snell. */
  const float angles[4] = {0.0f, 30.0f, 60.0f, 85.0f};
  for (int face = 0; face < 2; ++face) {
    for (int k = 0; k < 4; ++k) {
      iris_bsdf g = make(IRIS_BSDF_GLASS, iris_v3(0.9f, 0.9f, 0.9f), 0.0f);
      iris_vec3 v = dir_from_angle(angles[k], 0.7f);
      double eta = face ? 1.0 / 1.5 : 1.5;
      if (face) v.z = -v.z;
      double F = cy_fresnel(v.z, eta);
      uint64_t st = 3 + k;
      int n = 100000, refl = 0;
      bool weights_ok = true, snell_ok = true;
      for (int i = 0; i < n; ++i) {
        if (!iris_bsdf_sample(&g, v, (float)chi2_uniform(&st), 0.5f, 0.5f, &s)) {
          weights_ok = false;
          continue;
        }
        if (fabsf(s.f.x * fabsf(s.wi.z) / s.pdf - 0.9f) > 1e-4f) weights_ok = false;
        if (s.lobe & IRIS_LOBE_REFLECTION) {
          refl++;
        } else {
          double sin_o = sqrt(fmax(0.0, 1.0 - v.z * v.z)), sin_i = sqrt(fmax(0.0, 1.0 - s.wi.z * s.wi.z));
          if (fabs(sin_o - eta * sin_i) > 1e-4 || (s.wi.z > 0) == (v.z > 0)) snell_ok = false;
        }
      }
      double se = sqrt(F * (1.0 - F) / n) + 1e-9;
      char what[128];
      snprintf(what, sizeof(what), "smooth glass %s %.0f deg", face ? "inside" : "outside", angles[k]);
      snprintf(msg, sizeof(msg), "reflected %.5f expected F %.5f, weights = colour: %s, Snell: %s",
               (double)refl / n, F, weights_ok ? "yes" : "NO", snell_ok ? "yes" : "NO");
      expect(fabs((double)refl / n - F) < 5.0 * se + 1e-6 && weights_ok && snell_ok, what, msg);
    }
  }
  /* Smooth glTF coat over diffuse: delta spec lobe plus diffuse. */
  iris_bsdf c = make(IRIS_BSDF_GLTF, iris_v3(0.5f, 0.5f, 0.5f), 0.0f);
  uint32_t lobes = iris_bsdf_lobes(&c);
  expect((lobes & IRIS_LOBE_DELTA) && (lobes & IRIS_LOBE_DIFFUSE) && !iris_bsdf_is_delta(&c),
         "smooth gltf lobes", "delta coat + diffuse");
  /* White smooth dielectric gltf: E[weight] = F_schlick + (1 - F) * 1 = 1 at any angle (furnace). */
  c.color = iris_v3(1, 1, 1);
  uint64_t st = 77;
  double sum = 0.0;
  int n = 200000;
  wo = dir_from_angle(70, 0.0f);
  for (int i = 0; i < n; ++i) {
    if (iris_bsdf_sample(&c, wo, (float)chi2_uniform(&st), (float)chi2_uniform(&st), (float)chi2_uniform(&st), &s))
      sum += s.f.x * fabsf(s.wi.z) / s.pdf;
  }
  snprintf(msg, sizeof(msg), "albedo %.5f", sum / n);
  expect(sum / n <= 1.0 + 1e-3 && sum / n > 0.9, "smooth gltf white furnace", msg);
}

static void check_nan_safety(void) {
  const iris_bsdf_type types[4] = {IRIS_BSDF_DIFFUSE, IRIS_BSDF_GLOSSY, IRIS_BSDF_GLASS, IRIS_BSDF_GLTF};
  const float rough[4] = {0.0f, 0.0178f, 0.05f, 1.0f};
  const iris_vec3 dirs[] = {
      {0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {0, 1, 0}, {1, 0, 1e-9f}, {1, 0, -1e-9f},
      {0.70710677f, 0, 0.70710677f}, {-0.70710677f, 0, 0.70710677f}, {-0.70710677f, 0, -0.70710677f},
      {0, 0, 0}, {0.6f, 0.8f, 1e-30f}, {0.999999f, 0, 0.0014f}, {-0.999999f, 0, -0.0014f}};
  size_t nd = sizeof(dirs) / sizeof(dirs[0]);
  int bad = 0, calls = 0;
  for (int t = 0; t < 4; ++t) {
    for (int r = 0; r < 4; ++r) {
      iris_bsdf b = make(types[t], iris_v3(1, 1, 1), rough[r]);
      b.transmission = t == 3 ? 0.5f : 0.0f;
      b.metallic = t == 3 ? 0.3f : 0.0f;
      for (size_t i = 0; i < nd; ++i) {
        for (size_t j = 0; j < nd; ++j) {
          iris_vec3 f = iris_bsdf_eval(&b, dirs[i], dirs[j]);
          float p = iris_bsdf_pdf(&b, dirs[i], dirs[j]);
          calls++;
          if (!iris_isfinite3(f) || !isfinite(p) || p < 0 || f.x < 0) bad++;
        }
        uint64_t st = 1;
        for (int k = 0; k < 200; ++k) {
          struct iris_bsdf_sample s;
          bool ok = iris_bsdf_sample(&b, dirs[i], (float)chi2_uniform(&st), (float)chi2_uniform(&st),
                                     (float)chi2_uniform(&st), &s);
          calls++;
          if (ok && (!iris_isfinite3(s.f) || !(s.pdf > 0) || !isfinite(s.pdf) || !iris_isfinite3(s.wi)))
            bad++;
          if (!ok && (s.pdf != 0.0f)) bad++;
        }
      }
    }
  }
  char msg[128];
  snprintf(msg, sizeof(msg), "%d of %d calls returned NaN/Inf/negative", bad, calls);
  expect(bad == 0, "no NaN at degenerate directions", msg);
}

int main(void) {
  setvbuf(stdout, NULL, _IOLBF, 0);
  const float rough[4] = {0.05f, 0.2f, 0.5f, 1.0f};
  const float angles[4] = {0.0f, 45.0f, 75.0f, 88.0f}; /* 88: grazing */
  /* Count the chi-square runs for the Sidak correction. */
  const int n_gltf = 5;
  const int n_layered = 6;
  n_chi2_tests = 4 + 4 * 4 + 4 * 4 * 2 + (n_gltf - 2) * 3 * 3 + 2 * 3 + 4 + n_layered * 3;

  char name[160];
  iris_vec3 white = iris_v3(1, 1, 1);
  for (int a = 0; a < 4; ++a) {
    iris_vec3 wo = dir_from_angle(angles[a], 0.4f);
    check_config("diffuse", make(IRIS_BSDF_DIFFUSE, white, 0.0f), wo, false, a % 2 == 1);
    for (int r = 0; r < 4; ++r) {
      snprintf(name, sizeof(name), "glossy r=%.2f", rough[r]);
      check_config(name, make(IRIS_BSDF_GLOSSY, white, rough[r]), wo, false, a % 2 == 1);
      for (int face = 0; face < 2; ++face) {
        iris_vec3 w = wo;
        if (face) w.z = -w.z;
        snprintf(name, sizeof(name), "glass r=%.2f %s", rough[r], face ? "inside" : "outside");
        check_config(name, make(IRIS_BSDF_GLASS, white, rough[r]), w, true, a % 2 == 1);
      }
    }
  }
  /* glTF: plastic, metal, mixed with coloured specular, transmissive, half transmissive. */
  const float grough[3] = {0.05f, 0.3f, 1.0f};
  const float gangles[3] = {0.0f, 60.0f, 87.0f};
  for (int k = 0; k < n_gltf; ++k) {
    iris_bsdf b = make(IRIS_BSDF_GLTF, iris_v3(0.8f, 0.6f, 0.4f), 0.5f);
    const char *label = "plastic";
    if (k == 1) b.metallic = 1.0f, label = "metal";
    if (k == 2) b.metallic = 0.5f, b.specular = 0.7f, b.specular_color = iris_v3(1.0f, 0.3f, 2.0f), label = "mixed";
    if (k == 3) b.transmission = 1.0f, b.color = white, label = "transmissive";
    if (k == 4) b.transmission = 0.5f, b.specular = 0.5f, label = "half-transmissive";
    for (int r = 0; r < 3; ++r) {
      /* The mixed cases only add colour handling: one roughness is enough. */
      if ((k == 2 || k == 4) && r != 1) continue;
      b.roughness = grough[r];
      for (int a = 0; a < 3; ++a) {
        snprintf(name, sizeof(name), "gltf %s r=%.2f", label, grough[r]);
        check_config(name, b, dir_from_angle(gangles[a], 1.3f), b.transmission > 0.0f, a == 1 || (a == 2 && r == 1));
      }
    }
  }
  /* Transmissive glTF seen from inside. */
  for (int a = 0; a < 4; ++a) {
    iris_bsdf b = make(IRIS_BSDF_GLTF, white, 0.3f);
    b.transmission = 1.0f;
    iris_vec3 wo = dir_from_angle(angles[a], 2.0f);
    wo.z = -wo.z;
    check_config("gltf transmissive inside r=0.30", b, wo, true, a == 3);
  }

  /* Layers over a white glTF plastic (white furnace: albedo <= 1): sheen of colour 1
   * (KHR_materials_sheen, rough and smooth), clearcoat 1 (smooth = a delta lobe, and
   * rough), both together, a coat with a tilted normal over a half-transmissive base. */
  for (int k = 0; k < n_layered; ++k) {
    iris_bsdf b = make(IRIS_BSDF_GLTF, white, 0.5f);
    const char *label = "";
    bool sphere = false;
    switch (k) {
      case 0: b.sheen_color = white, b.sheen_roughness = 1.0f, label = "sheen r=1"; break;
      case 1: b.sheen_color = white, b.sheen_roughness = 0.3f, label = "sheen r=0.3"; break;
      case 2: b.clearcoat = 1.0f, b.clearcoat_roughness = 0.05f, label = "clearcoat r=0.05"; break;
      case 3: b.clearcoat = 1.0f, b.clearcoat_roughness = 0.3f, label = "clearcoat r=0.3"; break;
      case 4:
        b.clearcoat = 0.7f, b.clearcoat_roughness = 0.2f, b.sheen_color = iris_v3(1.0f, 0.5f, 0.2f);
        b.sheen_roughness = 0.5f, label = "clearcoat + sheen";
        break;
      default:
        b.clearcoat = 1.0f, b.clearcoat_roughness = 0.1f, b.coat_n = iris_normalize(iris_v3(0.3f, 0.1f, 0.95f));
        b.transmission = 0.5f, label = "clearcoat tilted over transmission", sphere = true;
        break;
    }
    for (int a = 0; a < 3; ++a) {
      snprintf(name, sizeof(name), "gltf %s", label);
      check_config(name, b, dir_from_angle(gangles[a], 0.9f), sphere, a != 0);
    }
  }

  /* A smooth coat is a delta lobe: its samples carry exactly cc F(wo) of the energy,
   * and with the base below the albedo stays <= 1 (MC over all lobes). */
  for (int a = 0; a < 3; ++a) {
    iris_bsdf b = make(IRIS_BSDF_GLTF, white, 0.5f);
    b.clearcoat = 0.8f, b.clearcoat_roughness = 0.0f;
    iris_vec3 wo = dir_from_angle(gangles[a], 0.9f);
    uint64_t st = 99;
    double delta = 0, all = 0, all2 = 0;
    const int m = 200000;
    for (int i = 0; i < m; ++i) {
      struct iris_bsdf_sample s;
      if (!iris_bsdf_sample(&b, wo, (float)chi2_uniform(&st), (float)chi2_uniform(&st), (float)chi2_uniform(&st), &s))
        continue;
      double w = iris_avg3(s.f) * fabs(s.wi.z) / s.pdf;
      all += w, all2 += w * w;
      if (s.lobe & IRIS_LOBE_DELTA) delta += w;
    }
    double mean = all / m, se = sqrt(fmax(0.0, all2 / m - mean * mean) / m), want = 0.8 * iris_fresnel_schlick(0.04f, wo.z);
    char msg[200];
    snprintf(msg, sizeof msg, "delta share %.5f (cc F = %.5f), albedo %.5f +- %.5f", delta / m, want, mean, se);
    expect(fabs(delta / m - want) < 0.02 * want + 1e-4 && mean <= 1.0 + 5 * se + 1e-4, "gltf clearcoat smooth", msg);
  }

  check_reciprocity("diffuse", make(IRIS_BSDF_DIFFUSE, iris_v3(0.5f, 0.5f, 0.5f), 0.0f));
  for (int r = 0; r < 4; ++r) {
    snprintf(name, sizeof(name), "glossy r=%.2f", rough[r]);
    check_reciprocity(name, make(IRIS_BSDF_GLOSSY, white, rough[r]));
    /* Black base: only the (reciprocal) specular layers remain; the base
     * layer weight (1 - F(N.V)) is deliberately not reciprocal. */
    iris_bsdf g = make(IRIS_BSDF_GLTF, iris_v3(0.0f, 0.0f, 0.0f), rough[r]);
    g.metallic = 0.3f;
    snprintf(name, sizeof(name), "gltf r=%.2f", rough[r]);
    check_reciprocity(name, g);
  }
  check_point_values();
  check_smooth();
  check_nan_safety();

  printf("%d passed, %d failed\n", passes, failures);
  return failures == 0 ? 0 : 1;
}
