/* bsdf.anisotropy: the glTF BSDF with KHR_materials_anisotropy.
 * - chi-square of iris_bsdf_sample against iris_bsdf_pdf at several (strength,
 *   direction, roughness, wo), reflection, transmission and under a clearcoat;
 * - point values: f at sampled and at random directions against the
 *   extension's D_aniso and V_aniso written out here in double precision;
 * - white furnace: a white anisotropic metal's albedo (MC through the BSDF's own
 *   sampling) is <= 1 and equals a quadrature of the extension's formula;
 * - strength 0 is the isotropic BSDF bit for bit: a hash of eval, pdf and
 *   sample over random BSDFs and directions equals the one the BSDF gave before
 *   anisotropy existed (commit 3e6a0e2; `test_bsdf_anisotropy hash` prints it).
 * - shading (iris_integrator_shade): the direction handed to the BSDF is the
 *   texture's RG (linear, [0,1] -> [-1,1]) turned by the rotation in the mesh's
 *   (tangent, bitangent) plane, B multiplies the strength; no tangents: isotropic.
 * Usage: test_bsdf_anisotropy [all|hash|chi2|values|furnace|iso|shade] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "chi2.h"
#include "renderer/bsdf.h"
#include "renderer/integrator.h"
#include "renderer/microfacet.h"
#include "renderer/texture.h"

#define M_PI 3.14159265358979323846

static int failures = 0, passes = 0;

static void expect(bool ok, const char *what, const char *detail) {
  if (!ok || getenv("IRIS_TEST_VERBOSE")) printf("%s %s: %s\n", ok ? "ok  " : "FAIL", what, detail);
  if (ok) passes++;
  else failures++;
}

typedef struct ctx {
  iris_bsdf b;
  iris_vec3 wo;
  double phi; /* anisotropy direction angle in the local frame (spec formulas) */
} ctx;

static bool sample_dir(void *c, const double u[3], double d[3]) {
  const ctx *x = c;
  struct iris_bsdf_sample s;
  if (!iris_bsdf_sample(&x->b, x->wo, (float)u[0], (float)u[1], (float)u[2], &s)) return false;
  d[0] = s.wi.x, d[1] = s.wi.y, d[2] = s.wi.z;
  return true;
}

static double pdf_dir(void *c, const double d[3]) {
  const ctx *x = c;
  return iris_bsdf_pdf(&x->b, x->wo, iris_v3((float)d[0], (float)d[1], (float)d[2]));
}

static iris_vec3 dir_from_angle(double theta_deg, double phi) {
  double t = theta_deg * M_PI / 180.0;
  return iris_v3((float)(sin(t) * cos(phi)), (float)(sin(t) * sin(phi)), (float)cos(t));
}

static iris_bsdf make(iris_vec3 color, float roughness, float metallic, float strength, double phi) {
  iris_bsdf b;
  memset(&b, 0, sizeof b);
  b.type = IRIS_BSDF_GLTF;
  b.color = color;
  b.roughness = roughness;
  b.metallic = metallic;
  b.ior = 1.5f;
  b.specular = 1.0f;
  b.specular_color = iris_v3(1, 1, 1);
  b.coat_n = iris_v3(0, 0, 1);
  b.anisotropy = strength;
  b.aniso_dir[0] = (float)cos(phi), b.aniso_dir[1] = (float)sin(phi);
  return b;
}

/* ---- the extension's formulas (KHR_materials_anisotropy, "Implementation") --- */

static double spec_D(double at, double ab, double NdotH, double TdotH, double BdotH) {
  double a2 = at * ab;
  double f0 = ab * TdotH, f1 = at * BdotH, f2 = a2 * NdotH;
  double w2 = a2 / (f0 * f0 + f1 * f1 + f2 * f2);
  return a2 * w2 * w2 / M_PI;
}

static double spec_V(double NdotL, double NdotV, double BdotV, double TdotV, double TdotL, double BdotL, double at,
                     double ab) {
  double ggxv = NdotL * sqrt(at * TdotV * at * TdotV + ab * BdotV * ab * BdotV + NdotV * NdotV);
  double ggxl = NdotV * sqrt(at * TdotL * at * TdotL + ab * BdotL * ab * BdotL + NdotL * NdotL);
  return 0.5 / (ggxv + ggxl);
}

/* A metal (metallic 1) of base colour `color` channel k: F_schlick(color, V.H) D V. */
static double spec_metal(const ctx *x, int k, const double l[3]) {
  const double v[3] = {x->wo.x, x->wo.y, x->wo.z};
  if (v[2] <= 0 || l[2] <= 0) return 0.0;
  double h[3] = {v[0] + l[0], v[1] + l[1], v[2] + l[2]};
  double hl = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
  for (int i = 0; i < 3; i++) h[i] /= hl;
  double t[3] = {cos(x->phi), sin(x->phi), 0}, b[3] = {-sin(x->phi), cos(x->phi), 0}; /* B = N x T */
#define DOT(a, c) ((a)[0] * (c)[0] + (a)[1] * (c)[1] + (a)[2] * (c)[2])
  double alpha = (double)x->b.roughness * x->b.roughness, s = x->b.anisotropy;
  double at = alpha + (1.0 - alpha) * s * s, ab = alpha; /* mix(alpha, 1, s^2), alpha */
  double d = spec_D(at, ab, h[2], DOT(t, h), DOT(b, h));
  double vis = spec_V(l[2], v[2], DOT(b, v), DOT(t, v), DOT(t, l), DOT(b, l), at, ab);
  double f0 = k == 0 ? x->b.color.x : k == 1 ? x->b.color.y : x->b.color.z;
  double vh = DOT(v, h);
#undef DOT
  return (f0 + (1.0 - f0) * pow(1.0 - vh, 5.0)) * d * vis;
}

static double spec_metal_cos(void *c, const double l[3]) { return spec_metal(c, 0, l) * fmax(0.0, l[2]); }

/* ---- chi-square ------------------------------------------------------------ */

typedef struct config {
  const char *label;
  float strength, dir_deg, roughness, theta_o, metallic, transmission, clearcoat;
  bool inside;
} config;

static const config configs[] = {
    {"metal s=1 r=0 (alpha_b floor)", 1.0f, 0.0f, 0.0f, 45.0f, 1.0f, 0.0f, 0.0f, false},
    {"metal s=0.5 dir=30 r=0.3", 0.5f, 30.0f, 0.3f, 60.0f, 1.0f, 0.0f, 0.0f, false},
    {"metal s=1 dir=120 r=0.5 normal incidence", 1.0f, 120.0f, 0.5f, 0.0f, 1.0f, 0.0f, 0.0f, false},
    {"metal s=0.8 dir=-70 r=0.2 grazing", 0.8f, -70.0f, 0.2f, 80.0f, 1.0f, 0.0f, 0.0f, false},
    {"plastic s=0.6 dir=45 r=0.4", 0.6f, 45.0f, 0.4f, 50.0f, 0.0f, 0.0f, 0.0f, false},
    {"transmissive s=0.7 dir=20 r=0.3 outside", 0.7f, 20.0f, 0.3f, 40.0f, 0.0f, 1.0f, 0.0f, false},
    {"transmissive s=0.7 dir=20 r=0.3 inside", 0.7f, 20.0f, 0.3f, 40.0f, 0.0f, 1.0f, 0.0f, true},
    {"clearcoat over metal s=0.9 dir=10 r=0.3", 0.9f, 10.0f, 0.3f, 60.0f, 1.0f, 0.0f, 1.0f, false},
};
#define N_CONFIGS (int)(sizeof configs / sizeof *configs)

static ctx config_ctx(const config *c) {
  double phi = c->dir_deg * M_PI / 180.0;
  ctx x;
  x.b = make(iris_v3(0.9f, 0.6f, 0.3f), c->roughness, c->metallic, c->strength, phi);
  x.b.transmission = c->transmission;
  x.b.clearcoat = c->clearcoat, x.b.clearcoat_roughness = 0.2f;
  x.wo = dir_from_angle(c->theta_o, 0.7);
  if (c->inside) x.wo.z = -x.wo.z;
  x.phi = phi;
  return x;
}

static void check_chi2(void) {
  for (int i = 0; i < N_CONFIGS; i++) {
    ctx x = config_ctx(&configs[i]);
    bool sphere = configs[i].transmission > 0.0f;
    chi2_domain dom = {sphere ? CHI2_SPHERE : CHI2_HEMISPHERE, 0, 0, 42 + (uint64_t)i};
    chi2_result r = chi2_run(&dom, sample_dir, pdf_dir, &x, 200000, 0.01, N_CONFIGS);
    char what[200];
    snprintf(what, sizeof what, "chi2 %s", configs[i].label);
    expect(r.passed, what, r.message);
    snprintf(what, sizeof what, "pdf mass %s", configs[i].label);
    char msg[64];
    snprintf(msg, sizeof msg, "%.5f", r.pdf_integral);
    expect(r.pdf_integral <= 1.002, what, msg);
  }
}

/* ---- point values against the extension ---------------------------------- */

static void check_values(void) {
  const struct {
    float s, dir_deg, r, theta_o;
  } v[] = {{1.0f, 0.0f, 0.3f, 30.0f}, {0.5f, 30.0f, 0.5f, 60.0f}, {0.8f, -70.0f, 0.2f, 75.0f},
           {0.3f, 100.0f, 0.7f, 10.0f}, {1.0f, 45.0f, 0.15f, 50.0f}};
  uint64_t st = 11;
  for (size_t i = 0; i < sizeof v / sizeof *v; i++) {
    double phi = v[i].dir_deg * M_PI / 180.0;
    ctx x = {make(iris_v3(0.9f, 0.6f, 0.3f), v[i].r, 1.0f, v[i].s, phi), dir_from_angle(v[i].theta_o, 2.1), phi};
    double worst = 0.0;
    int n = 0;
    for (int k = 0; k < 4000; k++) {
      iris_vec3 wi;
      if (k % 2 == 0) { /* sampled angles */
        struct iris_bsdf_sample s;
        if (!iris_bsdf_sample(&x.b, x.wo, (float)chi2_uniform(&st), (float)chi2_uniform(&st),
                              (float)chi2_uniform(&st), &s))
          continue;
        wi = s.wi;
      } else { /* anywhere on the hemisphere */
        double z = chi2_uniform(&st), p = 2 * M_PI * chi2_uniform(&st), rr = sqrt(1 - z * z);
        wi = iris_v3((float)(rr * cos(p)), (float)(rr * sin(p)), (float)z);
      }
      if (wi.z < 1e-3f) continue;
      const double l[3] = {wi.x, wi.y, wi.z};
      iris_vec3 f = iris_bsdf_eval(&x.b, x.wo, wi);
      const float fk[3] = {f.x, f.y, f.z};
      for (int c = 0; c < 3; c++) {
        double want = spec_metal(&x, c, l);
        double err = fabs(fk[c] - want) / fmax(want, 1e-3);
        if (err > worst) worst = err;
      }
      n++;
    }
    char what[160], msg[160];
    snprintf(what, sizeof what, "f = F D_aniso V_aniso (s=%.2f dir=%.0f r=%.2f wo %.0f deg)", v[i].s, v[i].dir_deg,
             v[i].r, v[i].theta_o);
    snprintf(msg, sizeof msg, "%d directions, worst relative error %.2e", n, worst);
    expect(n > 3000 && worst < 2e-4, what, msg);
  }
}

/* ---- white furnace ---------------------------------------------------------- */

static void check_furnace(void) {
  const struct {
    float s, dir_deg, r, theta_o;
  } v[] = {{1.0f, 0.0f, 0.3f, 0.0f}, {1.0f, 60.0f, 0.5f, 60.0f}, {0.7f, -30.0f, 0.2f, 80.0f},
           {1.0f, 90.0f, 1.0f, 45.0f}};
  for (size_t i = 0; i < sizeof v / sizeof *v; i++) {
    double phi = v[i].dir_deg * M_PI / 180.0;
    ctx x = {make(iris_v3(1, 1, 1), v[i].r, 1.0f, v[i].s, phi), dir_from_angle(v[i].theta_o, 0.4), phi};
    chi2_domain dom = {CHI2_HEMISPHERE, 0, 0, 5};
    double quad = chi2_integrate(&dom, spec_metal_cos, &x, sample_dir, &x, 20000);
    uint64_t st = 3;
    double sum = 0, sum2 = 0;
    const int m = 400000;
    for (int k = 0; k < m; k++) {
      struct iris_bsdf_sample s;
      double w = 0;
      if (iris_bsdf_sample(&x.b, x.wo, (float)chi2_uniform(&st), (float)chi2_uniform(&st), (float)chi2_uniform(&st),
                           &s))
        w = iris_avg3(s.f) * fabs(s.wi.z) / s.pdf;
      sum += w, sum2 += w * w;
    }
    double mean = sum / m, se = sqrt(fmax(0.0, sum2 / m - mean * mean) / m);
    char what[160], msg[200];
    snprintf(what, sizeof what, "white furnace s=%.2f dir=%.0f r=%.2f wo %.0f deg", v[i].s, v[i].dir_deg, v[i].r,
             v[i].theta_o);
    snprintf(msg, sizeof msg, "albedo MC %.5f +- %.5f, quadrature of the extension's f %.5f", mean, se, quad);
    expect(quad <= 1.0 + 1e-3 && mean <= 1.0 + 5 * se && fabs(mean - quad) < 5 * se + 2e-3, what, msg);
  }
}

/* ---- strength 0 = the isotropic BSDF, bit for bit ---------------------------- */

static uint64_t hash_bits(uint64_t h, const void *p, size_t n) {
  const unsigned char *b = p;
  for (size_t i = 0; i < n; i++) h = (h ^ b[i]) * 0x100000001b3ull;
  return h;
}

static uint64_t iso_hash(void) {
  uint64_t st = 2024, h = 0xcbf29ce484222325ull;
  for (int k = 0; k < 20000; k++) {
    iris_bsdf b = make(iris_v3((float)chi2_uniform(&st), (float)chi2_uniform(&st), (float)chi2_uniform(&st)), 0.0f,
                       0.0f, 0.0f, 0.0);
    b.aniso_dir[0] = 0.3f, b.aniso_dir[1] = -0.8f; /* ignored at strength 0 */
    int kind = k % 8;
    b.roughness = kind == 0 ? 0.0f : (float)chi2_uniform(&st);
    b.metallic = kind == 1 ? 1.0f : kind == 2 ? (float)chi2_uniform(&st) : 0.0f;
    if (kind == 3 || kind == 4) b.transmission = kind == 3 ? 1.0f : (float)chi2_uniform(&st);
    if (kind == 5) b.clearcoat = (float)chi2_uniform(&st), b.clearcoat_roughness = (float)chi2_uniform(&st);
    if (kind == 6) b.sheen_color = iris_v3(0.5f, 0.7f, 0.9f), b.sheen_roughness = (float)chi2_uniform(&st);
    b.specular = kind == 7 ? (float)chi2_uniform(&st) : 1.0f;
    double z = 2 * chi2_uniform(&st) - 1, p = 2 * M_PI * chi2_uniform(&st), r = sqrt(fmax(0, 1 - z * z));
    iris_vec3 wo = iris_v3((float)(r * cos(p)), (float)(r * sin(p)), (float)z);
    z = 2 * chi2_uniform(&st) - 1, p = 2 * M_PI * chi2_uniform(&st), r = sqrt(fmax(0, 1 - z * z));
    iris_vec3 wi = iris_v3((float)(r * cos(p)), (float)(r * sin(p)), (float)z);
    if (kind != 3 && kind != 4 && wo.z < 0) wo.z = -wo.z;
    iris_vec3 f = iris_bsdf_eval(&b, wo, wi);
    float pdf = iris_bsdf_pdf(&b, wo, wi);
    struct iris_bsdf_sample s;
    memset(&s, 0, sizeof s);
    bool ok = iris_bsdf_sample(&b, wo, (float)chi2_uniform(&st), (float)chi2_uniform(&st), (float)chi2_uniform(&st), &s);
    uint32_t lobes = iris_bsdf_lobes(&b);
    float gr = iris_bsdf_guiding_roughness(&b);
    h = hash_bits(h, &f, sizeof f);
    h = hash_bits(h, &pdf, sizeof pdf);
    h = hash_bits(h, &ok, sizeof ok);
    h = hash_bits(h, &s.wi, sizeof s.wi);
    h = hash_bits(h, &s.f, sizeof s.f);
    h = hash_bits(h, &s.pdf, sizeof s.pdf);
    h = hash_bits(h, &s.lobe, sizeof s.lobe);
    h = hash_bits(h, &lobes, sizeof lobes);
    h = hash_bits(h, &gr, sizeof gr);
  }
  return h;
}

/* The hash the BSDF of commit 3e6a0e2 (before anisotropy) gives in this build. */
#define ISO_HASH_BEFORE 0x96f84a0d9657382bull

static void check_iso(void) {
  uint64_t h = iso_hash();
  char msg[120];
  snprintf(msg, sizeof msg, "hash 0x%016llx, before anisotropy 0x%016llx", (unsigned long long)h,
           (unsigned long long)ISO_HASH_BEFORE);
  expect(h == ISO_HASH_BEFORE, "strength 0 is the isotropic BSDF bit for bit", msg);
}

/* ---- the direction at a shading point (renderer/integrator.c) -------------- */

/* Shades a point with normal +z, the given tangent frame and material; returns the
 * strength and the anisotropy direction in world space. */
static float shade_dir(const iris_material *m, const iris_textures *tex, bool has_tangent, iris_vec3 t, iris_vec3 b,
                       iris_vec3 *dir) {
  iris_scene *scene = iris_scene_create();
  iris_material copy = *m;
  copy.name = NULL;
  iris_scene_add_material(scene, &copy);
  iris_integrator it = iris_integrator_default(scene, NULL, NULL, tex);
  iris_interaction si;
  memset(&si, 0, sizeof si);
  si.ng = si.ns = iris_v3(0, 0, 1);
  si.uv[0] = si.uv[1] = si.uv1[0] = si.uv1[1] = 0.5f;
  si.color = iris_v3(1, 1, 1);
  si.material = 0;
  si.front = true;
  si.has_tangent = has_tangent;
  si.tangent = t, si.bitangent = b;
  iris_shading_point sp;
  iris_integrator_shade(&it, &si, iris_normalize(iris_v3(0.3f, 0.2f, 0.9f)), 0, &sp);
  *dir = iris_frame_to_world(&sp.frame, iris_v3(sp.bsdf.aniso_dir[0], sp.bsdf.aniso_dir[1], 0.0f));
  iris_scene_destroy(scene);
  return sp.bsdf.anisotropy;
}

static void check_shade(void) {
  /* one 1x1 texel: R 128 (x ~ 0), G 255 (y = 1), B 128 (strength x 0.502), read linearly */
  uint8_t texel[4] = {128, 255, 128, 255};
  iris_texture_image img;
  memset(&img, 0, sizeof img);
  img.width = img.height = 1;
  img.rgba = texel;
  img.nearest = true;
  iris_textures tex;
  memset(&tex, 0, sizeof tex);
  tex.images = &img;
  tex.count = 1;
  const double c30 = cos(M_PI / 6), s30 = sin(M_PI / 6), dx = 2.0 * 128 / 255 - 1;
  iris_material m = iris_material_default(IRIS_MATERIAL_GLTF);
  m.metallic = 1.0f, m.roughness = 0.3f, m.anisotropy = 0.8f, m.anisotropy_rotation = (float)(M_PI / 6);
  const iris_vec3 tx = iris_v3(1, 0, 0), by = iris_v3(0, 1, 0), bneg = iris_v3(0, -1, 0);
  struct {
    const char *what;
    int32_t texture;
    bool has_tangent;
    iris_vec3 b;
    double strength, wx, wy; /* expected strength and world direction (x, y) */
  } cases[] = {
      {"untextured: the tangent turned 30 deg towards the bitangent", -1, true, by, 0.8, c30, s30},
      {"bitangent sign -1: turned towards -y", -1, true, bneg, 0.8, c30, -s30},
      {"texture RG = (0, 1) turned 30 deg, strength x B", 0, true, by, 0.8 * 128.0 / 255.0, c30 * dx - s30,
       s30 * dx + c30},
      {"no tangents: isotropic", -1, false, by, 0.0, 0, 0},
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    m.anisotropy_texture = cases[i].texture;
    iris_vec3 d;
    float s = shade_dir(&m, &tex, cases[i].has_tangent, tx, cases[i].b, &d);
    double n = sqrt(cases[i].wx * cases[i].wx + cases[i].wy * cases[i].wy);
    /* the axis matters, not its sign (D is symmetric under a half turn) */
    double along = n > 0 ? fabs(d.x * cases[i].wx + d.y * cases[i].wy) / n : 1.0;
    char msg[200];
    snprintf(msg, sizeof msg, "strength %.5f (want %.5f), direction (%.4f, %.4f, %.4f), |cos| to want %.6f", s,
             cases[i].strength, d.x, d.y, d.z, along);
    expect(fabs(s - cases[i].strength) < 1e-5 && along > 1.0 - 1e-5, cases[i].what, msg);
  }
}

int main(int argc, char **argv) {
  setvbuf(stdout, NULL, _IOLBF, 0);
  const char *what = argc > 1 ? argv[1] : "all";
  bool all = strcmp(what, "all") == 0;
  if (strcmp(what, "hash") == 0) {
    printf("0x%016llx\n", (unsigned long long)iso_hash());
    return 0;
  }
  if (all || strcmp(what, "iso") == 0) check_iso();
  if (all || strcmp(what, "values") == 0) check_values();
  if (all || strcmp(what, "furnace") == 0) check_furnace();
  if (all || strcmp(what, "shade") == 0) check_shade();
  if (all || strcmp(what, "chi2") == 0) check_chi2();
  printf("%d passed, %d failed\n", passes, failures);
  return failures == 0 ? 0 : 1;
}
