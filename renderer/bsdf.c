/* The four iris materials (see bsdf.h; every formula and its Cycles 3.4
 * counterpart is in docs/materials.md). Each type has eval / pdf / sample
 * side by side; the public functions dispatch on the type. */
#include "renderer/bsdf.h"

#include "renderer/microfacet.h"
#include "renderer/sampling.h"
#include "renderer/sheen_table.h"

/* Cycles 3.4 treats a microfacet closure as singular when alpha_x * alpha_y
 * <= 1e-7 (bsdf_microfacet.h); iris uses the same test so that the delta/rough
 * switch happens at the same roughness (about 0.0178). */
#define IRIS_BSDF_SINGULAR_ALPHA2 1e-7f
/* Cosines below this count as grazing: f, pdf and samples are zero there, so
 * that no 1/cos can overflow. */
#define IRIS_BSDF_MIN_COS 1e-6f

static const iris_vec3 zero3 = {0.0f, 0.0f, 0.0f};

/* For the rarely taken paths (layers, anisotropy): the common BSDF stays small. */
#if defined(__GNUC__)
#define IRIS_NOINLINE __attribute__((noinline))
#else
#define IRIS_NOINLINE
#endif

static float alpha_of(float roughness) {
  float r = iris_clampf(isfinite(roughness) ? roughness : 1.0f, 0.0f, 1.0f);
  return r * r;
}

static bool alpha_is_singular(float alpha) { return alpha * alpha <= IRIS_BSDF_SINGULAR_ALPHA2; }

/* NaN, Inf and negative values become 0 (per channel for colours). Written
 * as comparisons rather than fmaxf so it inlines without -ffinite-math-only. */
static float sanitize1(float v) { return (isfinite(v) && v > 0.0f) ? v : 0.0f; }

static iris_vec3 sanitize3(iris_vec3 v) { return iris_v3(sanitize1(v.x), sanitize1(v.y), sanitize1(v.z)); }

static iris_vec3 flip_z(iris_vec3 v) { return iris_v3(v.x, v.y, -v.z); }

/* ---- shared GGX lobes (wo.z > 0 in the frame they are given) ------------ */

/* Reflection half vector and the GGX reflection term without colour or
 * Fresnel: D G / (4 cos_o cos_i). `height_correlated` picks the Smith G. */
static float ggx_reflect_f(float alpha, iris_vec3 wo, iris_vec3 wi, bool height_correlated) {
  if (wo.z < IRIS_BSDF_MIN_COS || wi.z < IRIS_BSDF_MIN_COS) return 0.0f;
  iris_vec3 m = iris_normalize(iris_add(wo, wi));
  float d = iris_ggx_d(alpha, m);
  float g = height_correlated
                ? 1.0f / (1.0f + iris_ggx_lambda(alpha, wo) + iris_ggx_lambda(alpha, wi))
                : iris_ggx_g1(alpha, wo) * iris_ggx_g1(alpha, wi);
  return d * g / (4.0f * wo.z * wi.z);
}

/* Density of reflecting wo about a visible normal: D_wo(m) / (4 wo.m). */
static float ggx_reflect_pdf(float alpha, iris_vec3 wo, iris_vec3 wi) {
  if (wo.z < IRIS_BSDF_MIN_COS || wi.z < IRIS_BSDF_MIN_COS) return 0.0f;
  iris_vec3 m = iris_normalize(iris_add(wo, wi));
  return iris_ggx_g1(alpha, wo) * iris_ggx_d(alpha, m) / (4.0f * wo.z);
}

/* Generalised half vector of a refraction pair (Walter 2007 eq. 16), turned
 * to the +z side; false when the pair cannot come from one microfacet. */
static bool refract_half(iris_vec3 wo, iris_vec3 wi, float eta, iris_vec3 *m, float *denom) {
  if (wo.z < IRIS_BSDF_MIN_COS || wi.z > -IRIS_BSDF_MIN_COS) return false;
  iris_vec3 ht = iris_neg(iris_add(iris_scale(wi, eta), wo));
  float len2 = iris_dot(ht, ht);
  if (!(len2 > 1e-12f)) return false;
  iris_vec3 h = iris_scale(ht, 1.0f / sqrtf(len2));
  if (h.z < 0.0f) h = iris_neg(h);
  float wo_m = iris_dot(wo, h), wi_m = iris_dot(wi, h);
  if (wo_m <= 0.0f || wi_m >= 0.0f) return false;
  *m = h;
  *denom = eta * wi_m + wo_m;
  *denom *= *denom;
  return *denom > 0.0f;
}

/* Walter 2007 eq. 21 without Fresnel: D G |wo.m| |wi.m| eta^2 / (cos_o |cos_i| (eta wi.m + wo.m)^2).
 * No 1/eta^2 radiance scaling: Cycles 3.4 does not apply it either. */
static float ggx_refract_f(float alpha, float eta, iris_vec3 wo, iris_vec3 wi,
                           bool height_correlated) {
  iris_vec3 m;
  float denom;
  if (!refract_half(wo, wi, eta, &m, &denom)) return 0.0f;
  float d = iris_ggx_d(alpha, m);
  float g = height_correlated
                ? 1.0f / (1.0f + iris_ggx_lambda(alpha, wo) + iris_ggx_lambda(alpha, wi))
                : iris_ggx_g1(alpha, wo) * iris_ggx_g1(alpha, wi);
  return d * g * fabsf(iris_dot(wo, m) * iris_dot(wi, m)) * eta * eta /
         (wo.z * fabsf(wi.z) * denom);
}

/* Density of refracting wo through a visible normal: D_wo(m) eta^2 |wi.m| / (eta wi.m + wo.m)^2. */
static float ggx_refract_pdf(float alpha, float eta, iris_vec3 wo, iris_vec3 wi) {
  iris_vec3 m;
  float denom;
  if (!refract_half(wo, wi, eta, &m, &denom)) return 0.0f;
  return iris_ggx_vndf_pdf(alpha, wo, m) * eta * eta * fabsf(iris_dot(wi, m)) / denom;
}

/* ---- anisotropic GGX lobes (KHR_materials_anisotropy), in the frame whose
 * x axis is the anisotropy direction: ax = alpha_t, ay = alpha_b. Always the
 * height-correlated Smith G, as the glTF BSDF uses. */

/* alpha_b is floored here (as the glTF Sample Viewer does) so that a smooth
 * material made anisotropic keeps a (thin) lobe rather than D = 0. */
#define ANISO_MIN_ALPHA 1e-3f

static float ggx_aniso_reflect_f(float ax, float ay, iris_vec3 wo, iris_vec3 wi) {
  if (wo.z < IRIS_BSDF_MIN_COS || wi.z < IRIS_BSDF_MIN_COS) return 0.0f;
  iris_vec3 m = iris_normalize(iris_add(wo, wi));
  float g = 1.0f / (1.0f + iris_ggx_lambda_aniso(ax, ay, wo) + iris_ggx_lambda_aniso(ax, ay, wi));
  return iris_ggx_d_aniso(ax, ay, m) * g / (4.0f * wo.z * wi.z);
}

static float ggx_aniso_reflect_pdf(float ax, float ay, iris_vec3 wo, iris_vec3 wi) {
  if (wo.z < IRIS_BSDF_MIN_COS || wi.z < IRIS_BSDF_MIN_COS) return 0.0f;
  iris_vec3 m = iris_normalize(iris_add(wo, wi));
  return iris_ggx_g1_aniso(ax, ay, wo) * iris_ggx_d_aniso(ax, ay, m) / (4.0f * wo.z);
}

static float ggx_aniso_refract_f(float ax, float ay, float eta, iris_vec3 wo, iris_vec3 wi) {
  iris_vec3 m;
  float denom;
  if (!refract_half(wo, wi, eta, &m, &denom)) return 0.0f;
  float g = 1.0f / (1.0f + iris_ggx_lambda_aniso(ax, ay, wo) + iris_ggx_lambda_aniso(ax, ay, wi));
  return iris_ggx_d_aniso(ax, ay, m) * g * fabsf(iris_dot(wo, m) * iris_dot(wi, m)) * eta * eta /
         (wo.z * fabsf(wi.z) * denom);
}

static float ggx_aniso_refract_pdf(float ax, float ay, float eta, iris_vec3 wo, iris_vec3 wi) {
  iris_vec3 m;
  float denom;
  if (!refract_half(wo, wi, eta, &m, &denom)) return 0.0f;
  return iris_ggx_vndf_pdf_aniso(ax, ay, wo, m) * eta * eta * fabsf(iris_dot(wi, m)) / denom;
}

/* alpha_t, alpha_b of a gltf BSDF with anisotropy > 0 (docs/materials.md). */
static void gltf_aniso_alphas(const iris_bsdf *b, float *at, float *ab) {
  float a = alpha_of(b->roughness);
  float s = iris_clampf(sanitize1(b->anisotropy), 0.0f, 1.0f);
  *at = a + (1.0f - a) * s * s;
  *ab = fmaxf(a, ANISO_MIN_ALPHA);
}

/* ---- diffuse: Lambert ---------------------------------------------------- */

static iris_vec3 diffuse_eval(const iris_bsdf *b, iris_vec3 wo, iris_vec3 wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return zero3;
  return iris_scale(b->color, IRIS_INV_PI);
}

static float diffuse_pdf(iris_vec3 wo, iris_vec3 wi) {
  if (wo.z <= 0.0f) return 0.0f;
  return iris_sample_cosine_hemisphere_pdf(wi.z);
}

static bool diffuse_sample(const iris_bsdf *b, iris_vec3 wo, float u0, float u1,
                           struct iris_bsdf_sample *s) {
  if (wo.z <= 0.0f) return false;
  s->wi = iris_sample_cosine_hemisphere(u0, u1);
  s->f = diffuse_eval(b, wo, s->wi);
  s->pdf = diffuse_pdf(wo, s->wi);
  s->lobe = IRIS_LOBE_REFLECTION | IRIS_LOBE_DIFFUSE;
  return s->pdf > 0.0f;
}

/* ---- glossy: GGX reflection, tint, no Fresnel (Cycles Glossy BSDF) ------- */

static iris_vec3 glossy_eval(const iris_bsdf *b, iris_vec3 wo, iris_vec3 wi) {
  float alpha = alpha_of(b->roughness);
  if (alpha_is_singular(alpha)) return zero3;
  return iris_scale(b->color, ggx_reflect_f(alpha, wo, wi, false));
}

static float glossy_pdf(const iris_bsdf *b, iris_vec3 wo, iris_vec3 wi) {
  float alpha = alpha_of(b->roughness);
  if (alpha_is_singular(alpha)) return 0.0f;
  return ggx_reflect_pdf(alpha, wo, wi);
}

static bool glossy_sample(const iris_bsdf *b, iris_vec3 wo, float u0, float u1,
                          struct iris_bsdf_sample *s) {
  if (wo.z < IRIS_BSDF_MIN_COS) return false;
  float alpha = alpha_of(b->roughness);
  if (alpha_is_singular(alpha)) {
    s->wi = iris_v3(-wo.x, -wo.y, wo.z);
    s->f = iris_scale(b->color, 1.0f / wo.z);
    s->pdf = 1.0f;
    s->lobe = IRIS_LOBE_REFLECTION | IRIS_LOBE_DELTA;
    return true;
  }
  iris_vec3 m = iris_ggx_sample_vndf(alpha, wo, u0, u1);
  s->wi = iris_reflect(wo, m);
  s->lobe = IRIS_LOBE_REFLECTION | IRIS_LOBE_GLOSSY;
  s->f = glossy_eval(b, wo, s->wi);
  s->pdf = glossy_pdf(b, wo, s->wi);
  return s->pdf > 0.0f;
}

/* ---- glass: dielectric, Fresnel from the shading normal (Cycles Glass BSDF) */

typedef struct glass_setup {
  bool inside;  /* wo.z < 0: directions were mirrored to the +z side */
  float eta;    /* n on the far side / n on wo's side */
  float alpha;
  bool smooth;
  float fr;     /* reflection weight: exact Fresnel at the shading normal */
} glass_setup;

static glass_setup glass_begin(const iris_bsdf *b, iris_vec3 *wo) {
  glass_setup g;
  float ior = (isfinite(b->ior) && b->ior > 1e-5f) ? b->ior : 1e-5f;
  g.inside = wo->z < 0.0f;
  g.eta = g.inside ? 1.0f / ior : ior;
  if (g.inside) *wo = flip_z(*wo);
  g.alpha = alpha_of(b->roughness);
  /* An index-matched interface only passes light straight through. */
  g.smooth = alpha_is_singular(g.alpha) || fabsf(g.eta - 1.0f) < 1e-4f;
  g.fr = iris_fresnel_dielectric(wo->z, g.eta);
  return g;
}

static iris_vec3 glass_eval(const iris_bsdf *b, iris_vec3 wo, iris_vec3 wi) {
  glass_setup g = glass_begin(b, &wo);
  if (g.smooth) return zero3;
  if (g.inside) wi = flip_z(wi);
  if (wi.z > 0.0f) return iris_scale(b->color, g.fr * ggx_reflect_f(g.alpha, wo, wi, false));
  return iris_scale(b->color, (1.0f - g.fr) * ggx_refract_f(g.alpha, g.eta, wo, wi, false));
}

static float glass_pdf(const iris_bsdf *b, iris_vec3 wo, iris_vec3 wi) {
  glass_setup g = glass_begin(b, &wo);
  if (g.smooth) return 0.0f;
  if (g.inside) wi = flip_z(wi);
  if (wi.z > 0.0f) return g.fr * ggx_reflect_pdf(g.alpha, wo, wi);
  return (1.0f - g.fr) * ggx_refract_pdf(g.alpha, g.eta, wo, wi);
}

static bool glass_sample(const iris_bsdf *b, iris_vec3 wo_in, float u_lobe, float u0, float u1,
                         struct iris_bsdf_sample *s) {
  iris_vec3 wo = wo_in;
  glass_setup g = glass_begin(b, &wo);
  if (wo.z < IRIS_BSDF_MIN_COS) return false;
  bool reflect = u_lobe < g.fr;
  if (g.smooth) {
    /* Delta lobes: f carries 1/|cos wi|, pdf is the lobe probability, so
     * f |cos| / pdf = colour, as in Cycles' singular closures. */
    if (reflect) {
      s->wi = iris_v3(-wo.x, -wo.y, wo.z);
      s->pdf = g.fr;
      s->lobe = IRIS_LOBE_REFLECTION | IRIS_LOBE_DELTA;
    } else {
      if (!iris_refract(wo, iris_v3(0.0f, 0.0f, 1.0f), g.eta, &s->wi)) return false;
      s->pdf = 1.0f - g.fr;
      s->lobe = IRIS_LOBE_TRANSMISSION | IRIS_LOBE_DELTA;
    }
    if (fabsf(s->wi.z) < IRIS_BSDF_MIN_COS || !(s->pdf > 0.0f)) return false;
    s->f = iris_scale(b->color, s->pdf / fabsf(s->wi.z));
  } else {
    iris_vec3 m = iris_ggx_sample_vndf(g.alpha, wo, u0, u1);
    if (reflect) {
      s->wi = iris_reflect(wo, m);
      if (s->wi.z < IRIS_BSDF_MIN_COS) return false;
      s->lobe = IRIS_LOBE_REFLECTION | IRIS_LOBE_GLOSSY;
    } else {
      /* Microfacet total internal reflection ends the path, as in Cycles. */
      if (!iris_refract(wo, m, g.eta, &s->wi) || s->wi.z > -IRIS_BSDF_MIN_COS) return false;
      s->lobe = IRIS_LOBE_TRANSMISSION | IRIS_LOBE_GLOSSY;
    }
    if (g.inside) s->wi = flip_z(s->wi);
    s->f = sanitize3(glass_eval(b, wo_in, s->wi));
    s->pdf = sanitize1(glass_pdf(b, wo_in, s->wi));
    return s->pdf > 0.0f;
  }
  if (g.inside) s->wi = flip_z(s->wi);
  return true;
}

/* ---- gltf: glTF 2.0 Appendix B + KHR_materials_specular / _transmission -- */

typedef struct gltf_setup {
  bool inside;
  float eta;
  float alpha;
  bool smooth;
  iris_vec3 f0;       /* min(((ior-1)/(ior+1))^2 specularColor, 1) */
  float weight;       /* specularFactor */
  float metallic;
  float transmission;
  float p_spec, p_diffuse, p_trans; /* lobe selection probabilities at wo */
  /* KHR_materials_anisotropy: directions are turned into the frame whose x axis is
   * the anisotropy direction (ca, sa); false: isotropic (alpha), nothing turned. */
  bool aniso;
  float ax, ay, ca, sa;
} gltf_setup;

/* Into / out of the anisotropy frame: a turn about z (cosines, Fresnel and the
 * diffuse lobe do not change). */
static iris_vec3 aniso_in(const gltf_setup *g, iris_vec3 w) {
  return iris_v3(g->ca * w.x + g->sa * w.y, g->ca * w.y - g->sa * w.x, w.z);
}
static iris_vec3 aniso_out(const gltf_setup *g, iris_vec3 w) {
  return iris_v3(g->ca * w.x - g->sa * w.y, g->sa * w.x + g->ca * w.y, w.z);
}

/* Kept out of line: the isotropic BSDF only pays the test of b->anisotropy. */
static IRIS_NOINLINE void gltf_begin_aniso(const iris_bsdf *b, iris_vec3 *wo, gltf_setup *g) {
  float at, ab;
  gltf_aniso_alphas(b, &at, &ab);
  g->smooth = at * ab <= IRIS_BSDF_SINGULAR_ALPHA2;
  if (g->smooth) return;
  float c = b->aniso_dir[0], sn = b->aniso_dir[1], len = sqrtf(c * c + sn * sn);
  if (!(len > 1e-6f) || !isfinite(len)) c = 1.0f, sn = 0.0f, len = 1.0f;
  g->aniso = true;
  g->ax = at, g->ay = ab;
  g->ca = c / len, g->sa = sn / len;
  *wo = aniso_in(g, *wo);
}

static iris_vec3 schlick3(iris_vec3 f0, float c) {
  return iris_v3(iris_fresnel_schlick(f0.x, c), iris_fresnel_schlick(f0.y, c),
                 iris_fresnel_schlick(f0.z, c));
}

/* Returns false when wo cannot be shaded (below the surface of an opaque material). */
static bool gltf_begin(const iris_bsdf *b, iris_vec3 *wo, gltf_setup *g) {
  g->metallic = iris_clampf(b->metallic, 0.0f, 1.0f);
  g->transmission = iris_clampf(b->transmission, 0.0f, 1.0f) * (1.0f - g->metallic);
  g->inside = wo->z < 0.0f;
  if (g->inside) {
    if (!(g->transmission > 0.0f)) return false;
    *wo = flip_z(*wo);
  }
  if (wo->z < IRIS_BSDF_MIN_COS) return false;
  float ior = (isfinite(b->ior) && b->ior > 1e-5f) ? b->ior : 1.5f;
  g->eta = g->inside ? 1.0f / ior : ior;
  g->alpha = alpha_of(b->roughness);
  g->smooth = alpha_is_singular(g->alpha);
  g->aniso = false;
  if (b->anisotropy > 0.0f) gltf_begin_aniso(b, wo, g);
  float f0 = iris_sqr((ior - 1.0f) / (ior + 1.0f));
  iris_vec3 sc = sanitize3(b->specular_color);
  g->f0 = iris_v3(fminf(f0 * sc.x, 1.0f), fminf(f0 * sc.y, 1.0f), fminf(f0 * sc.z, 1.0f));
  g->weight = sanitize1(b->specular);
  /* Lobe choice from the lobe weights at the macro normal (an albedo estimate). */
  float c = wo->z;
  float fr_max = iris_max3(schlick3(g->f0, c));
  float dielectric_base = fmaxf(0.0f, 1.0f - g->weight * fr_max) * iris_avg3(sanitize3(b->color));
  float metal = iris_avg3(schlick3(sanitize3(b->color), c));
  float ps = (1.0f - g->metallic) * g->weight * fr_max + g->metallic * metal;
  float pd = (1.0f - g->metallic) * (1.0f - iris_clampf(b->transmission, 0.0f, 1.0f)) *
             dielectric_base;
  float pt = g->transmission * dielectric_base;
  float sum = ps + pd + pt;
  if (!(sum > 0.0f) || !isfinite(sum)) {
    g->p_spec = g->p_diffuse = g->p_trans = 0.0f;
  } else {
    g->p_spec = ps / sum;
    g->p_diffuse = pd / sum;
    g->p_trans = pt / sum;
  }
  return true;
}

/* Dielectric specular tint w * F_r(c) and metal tint F_m(c) combined by metallic. */
static iris_vec3 gltf_spec_tint(const iris_bsdf *b, const gltf_setup *g, float c) {
  iris_vec3 diel = iris_scale(schlick3(g->f0, c), g->weight * (1.0f - g->metallic));
  iris_vec3 metal = iris_scale(schlick3(sanitize3(b->color), c), g->metallic);
  return iris_add(diel, metal);
}

/* (1 - w max(F_r(c))): what the dielectric layer leaves for diffuse and
 * transmission. Appendix B evaluates it at V.H; iris evaluates it at N.V
 * (c = wo.z), because the V.H form reflects more than it receives at grazing
 * angles (white furnace 1.33 at 87 degrees, roughness 0.05; docs/materials.md). */
static float gltf_base_weight(const gltf_setup *g, float c) {
  return fmaxf(0.0f, 1.0f - g->weight * iris_max3(schlick3(g->f0, c)));
}

static iris_vec3 gltf_eval_local(const iris_bsdf *b, const gltf_setup *g, iris_vec3 wo,
                                 iris_vec3 wi) {
  iris_vec3 base = sanitize3(b->color);
  if (wi.z > 0.0f) {
    if (wi.z < IRIS_BSDF_MIN_COS) return zero3;
    iris_vec3 m = iris_normalize(iris_add(wo, wi));
    float c = iris_dot(wo, m);
    float opaque = (1.0f - g->metallic) * (1.0f - iris_clampf(b->transmission, 0.0f, 1.0f));
    iris_vec3 f = iris_scale(base, opaque * gltf_base_weight(g, wo.z) * IRIS_INV_PI);
    if (!g->smooth) {
      float spec = g->aniso ? ggx_aniso_reflect_f(g->ax, g->ay, wo, wi) : ggx_reflect_f(g->alpha, wo, wi, true);
      f = iris_add(f, iris_scale(gltf_spec_tint(b, g, c), spec));
    }
    return f;
  }
  if (g->smooth || !(g->transmission > 0.0f)) return zero3;
  float btdf = g->aniso ? ggx_aniso_refract_f(g->ax, g->ay, g->eta, wo, wi)
                        : ggx_refract_f(g->alpha, g->eta, wo, wi, true);
  return iris_scale(base, g->transmission * gltf_base_weight(g, wo.z) * btdf);
}

static float gltf_pdf_local(const gltf_setup *g, iris_vec3 wo, iris_vec3 wi) {
  if (wi.z > 0.0f) {
    float p = g->p_diffuse * iris_sample_cosine_hemisphere_pdf(wi.z);
    if (!g->smooth)
      p += g->p_spec * (g->aniso ? ggx_aniso_reflect_pdf(g->ax, g->ay, wo, wi) : ggx_reflect_pdf(g->alpha, wo, wi));
    return p;
  }
  if (g->smooth) return 0.0f;
  return g->p_trans * (g->aniso ? ggx_aniso_refract_pdf(g->ax, g->ay, g->eta, wo, wi)
                                : ggx_refract_pdf(g->alpha, g->eta, wo, wi));
}

static iris_vec3 gltf_base_eval(const iris_bsdf *b, iris_vec3 wo, iris_vec3 wi) {
  gltf_setup g;
  if (!gltf_begin(b, &wo, &g)) return zero3;
  if (g.inside) wi = flip_z(wi);
  if (g.aniso) wi = aniso_in(&g, wi);
  return gltf_eval_local(b, &g, wo, wi);
}

static float gltf_base_pdf(const iris_bsdf *b, iris_vec3 wo, iris_vec3 wi) {
  gltf_setup g;
  if (!gltf_begin(b, &wo, &g)) return 0.0f;
  if (g.inside) wi = flip_z(wi);
  if (g.aniso) wi = aniso_in(&g, wi);
  return gltf_pdf_local(&g, wo, wi);
}

static bool gltf_base_sample(const iris_bsdf *b, iris_vec3 wo, float u_lobe, float u0, float u1,
                             struct iris_bsdf_sample *s) {
  gltf_setup g;
  if (!gltf_begin(b, &wo, &g)) return false;
  iris_vec3 n = iris_v3(0.0f, 0.0f, 1.0f);
  if (u_lobe < g.p_spec) {
    if (g.smooth) {
      s->wi = iris_v3(-wo.x, -wo.y, wo.z);
      s->pdf = g.p_spec;
      s->f = iris_scale(gltf_spec_tint(b, &g, wo.z), 1.0f / wo.z);
      s->lobe = IRIS_LOBE_REFLECTION | IRIS_LOBE_DELTA;
      if (g.inside) s->wi = flip_z(s->wi);
      return s->pdf > 0.0f;
    }
    s->wi = iris_reflect(wo, g.aniso ? iris_ggx_sample_vndf_aniso(g.ax, g.ay, wo, u0, u1)
                                     : iris_ggx_sample_vndf(g.alpha, wo, u0, u1));
    if (s->wi.z < IRIS_BSDF_MIN_COS) return false;
    s->lobe = IRIS_LOBE_REFLECTION | IRIS_LOBE_GLOSSY;
  } else if (u_lobe < g.p_spec + g.p_diffuse) {
    s->wi = iris_sample_cosine_hemisphere(u0, u1);
    s->lobe = IRIS_LOBE_REFLECTION | IRIS_LOBE_DIFFUSE;
  } else {
    if (!(g.p_trans > 0.0f)) return false;
    if (g.smooth) {
      if (!iris_refract(wo, n, g.eta, &s->wi) || s->wi.z > -IRIS_BSDF_MIN_COS) return false;
      s->pdf = g.p_trans;
      float w = g.transmission * gltf_base_weight(&g, wo.z) / fabsf(s->wi.z);
      s->f = iris_scale(sanitize3(b->color), w);
      s->lobe = IRIS_LOBE_TRANSMISSION | IRIS_LOBE_DELTA;
      if (g.inside) s->wi = flip_z(s->wi);
      return true;
    }
    iris_vec3 m = g.aniso ? iris_ggx_sample_vndf_aniso(g.ax, g.ay, wo, u0, u1) : iris_ggx_sample_vndf(g.alpha, wo, u0, u1);
    if (!iris_refract(wo, m, g.eta, &s->wi) || s->wi.z > -IRIS_BSDF_MIN_COS) return false;
    s->lobe = IRIS_LOBE_TRANSMISSION | IRIS_LOBE_GLOSSY;
  }
  s->f = sanitize3(gltf_eval_local(b, &g, wo, s->wi));
  s->pdf = sanitize1(gltf_pdf_local(&g, wo, s->wi));
  if (g.aniso) s->wi = aniso_out(&g, s->wi);
  if (g.inside) s->wi = flip_z(s->wi);
  return s->pdf > 0.0f;
}

/* ---- gltf layers: KHR_materials_sheen and KHR_materials_clearcoat -------- */

/* Sheen (KHR_materials_sheen): f = colour D V with the Charlie distribution
 * D = (2 + 1/a) sin^(1/a)(theta_h) / (2 pi), a = roughness^2, and the
 * Estevez-Kulla visibility V = 1 / ((1 + L(wo) + L(wi)) 4 cos_o cos_i). */
#define SHEEN_MIN_ALPHA 1e-3f

static float sheen_l(float x, float ag) {
  float t = iris_sqr(1.0f - ag);
  float a = 21.5473f + (25.3245f - 21.5473f) * t, bb = 3.82987f + (3.32435f - 3.82987f) * t;
  float c = 0.19823f + (0.16801f - 0.19823f) * t, d = -1.97760f + (-1.27393f + 1.97760f) * t;
  float e = -4.32054f + (-4.85967f + 4.32054f) * t;
  return a / (1.0f + bb * powf(x, c)) + d * x + e;
}

static float sheen_lambda(float cos_t, float ag) {
  cos_t = fabsf(cos_t);
  return cos_t < 0.5f ? expf(sheen_l(cos_t, ag)) : expf(2.0f * sheen_l(0.5f, ag) - sheen_l(1.0f - cos_t, ag));
}

static float sheen_alpha(float roughness) { return fmaxf(iris_sqr(iris_clampf(roughness, 0.0f, 1.0f)), SHEEN_MIN_ALPHA); }

/* The sheen lobe for colour 1, without the cosine. */
static float sheen_f(float ag, iris_vec3 wo, iris_vec3 wi) {
  if (wo.z < IRIS_BSDF_MIN_COS || wi.z < IRIS_BSDF_MIN_COS) return 0.0f;
  iris_vec3 h = iris_normalize(iris_add(wo, wi));
  float sin2 = fmaxf(0.0f, 1.0f - h.z * h.z);
  float d = (2.0f + 1.0f / ag) * powf(sin2, 0.5f / ag) * (0.5f * IRIS_INV_PI);
  float v = 1.0f / ((1.0f + sheen_lambda(wo.z, ag) + sheen_lambda(wi.z, ag)) * 4.0f * wo.z * wi.z);
  return d * v;
}

/* Its directional albedo (tools/gen_sheen_table.py), bilinear in (roughness, cos). */
static float sheen_albedo(float cos_t, float roughness) {
  const int n = IRIS_SHEEN_TABLE_N;
  float x = iris_clampf(cos_t, 0.0f, 1.0f) * (float)(n - 1), y = iris_clampf(roughness, 0.0f, 1.0f) * (float)(n - 1);
  int x0 = (int)x, y0 = (int)y;
  if (x0 > n - 2) x0 = n - 2;
  if (y0 > n - 2) y0 = n - 2;
  float fx = x - (float)x0, fy = y - (float)y0;
  const float(*t)[IRIS_SHEEN_TABLE_N] = iris_sheen_albedo;
  return (1 - fy) * ((1 - fx) * t[y0][x0] + fx * t[y0][x0 + 1]) + fy * ((1 - fx) * t[y0 + 1][x0] + fx * t[y0 + 1][x0 + 1]);
}

/* Sampled like a Lambert lobe (the Charlie lobe is broad). */
static float sheen_pdf(iris_vec3 wi) { return wi.z > 0.0f ? iris_sample_cosine_hemisphere_pdf(wi.z) : 0.0f; }

#define COAT_F0 0.04f /* ior 1.5, as the extension fixes it */

typedef struct layers {
  float cc, cc_alpha;
  bool cc_smooth;
  iris_frame cf;        /* frame of the coat normal, in the BSDF's local frame */
  float fc_o;           /* coat Fresnel at wo (about the coat normal) */
  float coat_below_o;   /* 1 - cc F_c(wo): what the coat lets through to the layers below */
  iris_vec3 sheen;      /* sheen colour */
  float sheen_max, sheen_r, sheen_ag, e_o, sheen_k; /* k = min(1, 1/E(wo)): no energy gain */
  float p_coat, p_sheen; /* lobe probabilities; the base gets the rest */
} layers;

static bool has_layers(const iris_bsdf *b) {
  return b->clearcoat > 0.0f || b->sheen_color.x > 0.0f || b->sheen_color.y > 0.0f || b->sheen_color.z > 0.0f;
}

static void layers_begin(const iris_bsdf *b, iris_vec3 wo, layers *l) {
  l->cc = iris_clampf(sanitize1(b->clearcoat), 0.0f, 1.0f);
  l->cc_alpha = alpha_of(b->clearcoat_roughness);
  l->cc_smooth = alpha_is_singular(l->cc_alpha);
  iris_vec3 cn = iris_isfinite3(b->coat_n) && iris_length(b->coat_n) > 0.5f ? iris_normalize(b->coat_n) : iris_v3(0, 0, 1);
  l->cf = iris_frame_from_normal(cn);
  float co = iris_dot(wo, cn);
  l->fc_o = co > 0.0f ? iris_fresnel_schlick(COAT_F0, co) : 0.0f;
  l->coat_below_o = 1.0f - l->cc * l->fc_o;
  l->sheen = sanitize3(b->sheen_color);
  l->sheen_max = iris_max3(l->sheen);
  l->sheen_r = iris_clampf(b->sheen_roughness, 0.0f, 1.0f);
  l->sheen_ag = sheen_alpha(l->sheen_r);
  l->e_o = l->sheen_max > 0.0f ? sheen_albedo(wo.z, l->sheen_r) : 0.0f;
  l->sheen_k = l->e_o > 1.0f ? 1.0f / l->e_o : 1.0f;
  l->p_coat = l->cc > 0.0f ? fminf(0.5f, l->cc * (0.1f + 2.0f * l->fc_o)) : 0.0f;
  l->p_sheen = l->sheen_max > 0.0f ? fminf(0.3f, 0.05f + l->sheen_max * fminf(l->e_o, 1.0f)) : 0.0f;
}

/* Albedo scaling of the base under the sheen (the extension's
 * min(1 - max(c) E(wo), 1 - max(c) E(wi)); wo only for transmitted wi). */
static float sheen_scale(const layers *l, iris_vec3 wi) {
  if (!(l->sheen_max > 0.0f)) return 1.0f;
  float s = 1.0f - l->sheen_max * l->e_o;
  if (wi.z > 0.0f) s = fminf(s, 1.0f - l->sheen_max * sheen_albedo(wi.z, l->sheen_r));
  return fmaxf(s, 0.0f);
}

/* The coat lobe (no delta part): cc F(wo.m) D G / (4 cos cos) about the coat normal. */
static float coat_f(const layers *l, iris_vec3 wo, iris_vec3 wi) {
  if (!(l->cc > 0.0f) || l->cc_smooth) return 0.0f;
  iris_vec3 o = iris_frame_to_local(&l->cf, wo), i = iris_frame_to_local(&l->cf, wi);
  if (o.z < IRIS_BSDF_MIN_COS || i.z < IRIS_BSDF_MIN_COS) return 0.0f;
  iris_vec3 m = iris_normalize(iris_add(o, i));
  return l->cc * iris_fresnel_schlick(COAT_F0, iris_dot(o, m)) * ggx_reflect_f(l->cc_alpha, o, i, true);
}

static float coat_pdf(const layers *l, iris_vec3 wo, iris_vec3 wi) {
  if (!(l->cc > 0.0f) || l->cc_smooth) return 0.0f;
  return ggx_reflect_pdf(l->cc_alpha, iris_frame_to_local(&l->cf, wo), iris_frame_to_local(&l->cf, wi));
}

static iris_vec3 layered_eval(const iris_bsdf *b, const layers *l, iris_vec3 wo, iris_vec3 wi) {
  iris_vec3 below = iris_scale(gltf_base_eval(b, wo, wi), sheen_scale(l, wi));
  if (l->sheen_max > 0.0f) below = iris_add(below, iris_scale(l->sheen, l->sheen_k * sheen_f(l->sheen_ag, wo, wi)));
  float c = coat_f(l, wo, wi);
  return iris_add(iris_scale(below, l->coat_below_o), iris_v3(c, c, c));
}

static float layered_pdf(const iris_bsdf *b, const layers *l, iris_vec3 wo, iris_vec3 wi) {
  float p_base = 1.0f - l->p_coat - l->p_sheen;
  return l->p_coat * coat_pdf(l, wo, wi) + l->p_sheen * sheen_pdf(wi) + p_base * gltf_base_pdf(b, wo, wi);
}

/* The layered paths are kept out of line (IRIS_NOINLINE) so that the plain glTF BSDF
 * inlines into the dispatch as it did before the layers existed (measured: docs/performance.md). */

static IRIS_NOINLINE iris_vec3 gltf_layered_eval(const iris_bsdf *b, iris_vec3 wo, iris_vec3 wi) {
  layers l;
  layers_begin(b, wo, &l);
  return layered_eval(b, &l, wo, wi);
}

static IRIS_NOINLINE float gltf_layered_pdf(const iris_bsdf *b, iris_vec3 wo, iris_vec3 wi) {
  layers l;
  layers_begin(b, wo, &l);
  return layered_pdf(b, &l, wo, wi);
}

static IRIS_NOINLINE bool gltf_layered_sample(const iris_bsdf *b, iris_vec3 wo, float u_lobe, float u0,
                                               float u1, struct iris_bsdf_sample *s) {
  layers l;
  layers_begin(b, wo, &l);
  if (u_lobe < l.p_coat) {
    iris_vec3 o = iris_frame_to_local(&l.cf, wo);
    if (o.z < IRIS_BSDF_MIN_COS) return false;
    if (l.cc_smooth) { /* mirror about the coat normal: a delta lobe */
      s->wi = iris_frame_to_world(&l.cf, iris_v3(-o.x, -o.y, o.z));
      if (fabsf(s->wi.z) < IRIS_BSDF_MIN_COS) return false;
      float f = l.cc * l.fc_o / fabsf(s->wi.z);
      s->f = iris_v3(f, f, f);
      s->pdf = l.p_coat;
      s->lobe = IRIS_LOBE_REFLECTION | IRIS_LOBE_DELTA;
      return true;
    }
    iris_vec3 i = iris_reflect(o, iris_ggx_sample_vndf(l.cc_alpha, o, u0, u1));
    if (i.z < IRIS_BSDF_MIN_COS) return false;
    s->wi = iris_frame_to_world(&l.cf, i);
    s->lobe = IRIS_LOBE_REFLECTION | IRIS_LOBE_GLOSSY;
  } else if (u_lobe < l.p_coat + l.p_sheen) {
    s->wi = iris_sample_cosine_hemisphere(u0, u1);
    s->lobe = IRIS_LOBE_REFLECTION | IRIS_LOBE_GLOSSY;
  } else {
    float p_base = 1.0f - l.p_coat - l.p_sheen;
    float u = iris_clampf((u_lobe - l.p_coat - l.p_sheen) / p_base, 0.0f, IRIS_ONE_MINUS_EPSILON);
    if (!gltf_base_sample(b, wo, u, u0, u1, s)) return false;
    if (s->lobe & IRIS_LOBE_DELTA) { /* the layers' share of a delta direction */
      s->f = iris_scale(s->f, l.coat_below_o * sheen_scale(&l, s->wi));
      s->pdf *= p_base;
      return s->pdf > 0.0f;
    }
  }
  s->f = sanitize3(layered_eval(b, &l, wo, s->wi));
  s->pdf = sanitize1(layered_pdf(b, &l, wo, s->wi));
  return s->pdf > 0.0f;
}

/* ---- public dispatch ----------------------------------------------------- */

static iris_vec3 color_from(const float *c) {
  return sanitize3(iris_v3(c[0], c[1], c[2]));
}

iris_bsdf iris_bsdf_from_material(const iris_material *mat, iris_vec3 color, float roughness,
                                  float metallic) {
  iris_bsdf b;
  switch (mat->type) {
    case IRIS_MATERIAL_GLOSSY: b.type = IRIS_BSDF_GLOSSY; break;
    case IRIS_MATERIAL_GLASS: b.type = IRIS_BSDF_GLASS; break;
    case IRIS_MATERIAL_GLTF: b.type = IRIS_BSDF_GLTF; break;
    case IRIS_MATERIAL_DIFFUSE:
    default: b.type = IRIS_BSDF_DIFFUSE; break;
  }
  b.color = sanitize3(color);
  b.roughness = iris_clampf(isfinite(roughness) ? roughness : 1.0f, 0.0f, 1.0f);
  /* Cycles clamps the Glass IOR to >= 1e-5; an unset (0) IOR gets the node
   * default (Glass 1.45) or the glTF default (1.5). */
  float default_ior = mat->type == IRIS_MATERIAL_GLASS ? 1.45f : 1.5f;
  b.ior = (isfinite(mat->ior) && mat->ior > 0.0f) ? iris_fmaxf(mat->ior, 1e-5f) : default_ior;
  b.metallic = iris_clampf(isfinite(metallic) ? metallic : 0.0f, 0.0f, 1.0f);
  b.specular = sanitize1(mat->specular);
  b.specular_color = color_from(mat->specular_color);
  b.transmission = iris_clampf(isfinite(mat->transmission) ? mat->transmission : 0.0f, 0.0f, 1.0f);
  b.clearcoat = b.clearcoat_roughness = b.sheen_roughness = 0.0f;
  b.coat_n = iris_v3(0.0f, 0.0f, 1.0f);
  b.sheen_color = zero3;
  b.anisotropy = 0.0f;
  b.aniso_dir[0] = 1.0f, b.aniso_dir[1] = 0.0f;
  return b;
}

iris_vec3 iris_bsdf_eval(const iris_bsdf *b, iris_vec3 wo, iris_vec3 wi) {
  iris_vec3 f;
  switch (b->type) {
    case IRIS_BSDF_DIFFUSE: f = diffuse_eval(b, wo, wi); break;
    case IRIS_BSDF_GLOSSY: f = glossy_eval(b, wo, wi); break;
    case IRIS_BSDF_GLASS: f = glass_eval(b, wo, wi); break;
    case IRIS_BSDF_GLTF: /* layers are outside only */
      f = has_layers(b) && wo.z > 0.0f ? gltf_layered_eval(b, wo, wi) : gltf_base_eval(b, wo, wi);
      break;
    default: f = zero3; break;
  }
  return sanitize3(f);
}

float iris_bsdf_pdf(const iris_bsdf *b, iris_vec3 wo, iris_vec3 wi) {
  float p;
  switch (b->type) {
    case IRIS_BSDF_DIFFUSE: p = diffuse_pdf(wo, wi); break;
    case IRIS_BSDF_GLOSSY: p = glossy_pdf(b, wo, wi); break;
    case IRIS_BSDF_GLASS: p = glass_pdf(b, wo, wi); break;
    case IRIS_BSDF_GLTF:
      p = has_layers(b) && wo.z > 0.0f ? gltf_layered_pdf(b, wo, wi) : gltf_base_pdf(b, wo, wi);
      break;
    default: p = 0.0f; break;
  }
  return sanitize1(p);
}

bool iris_bsdf_sample(const iris_bsdf *b, iris_vec3 wo, float u_lobe, float u0, float u1,
                      struct iris_bsdf_sample *s) {
  bool ok;
  s->wi = zero3;
  s->f = zero3;
  s->pdf = 0.0f;
  s->lobe = 0;
  switch (b->type) {
    case IRIS_BSDF_DIFFUSE: ok = diffuse_sample(b, wo, u0, u1, s); break;
    case IRIS_BSDF_GLOSSY: ok = glossy_sample(b, wo, u0, u1, s); break;
    case IRIS_BSDF_GLASS: ok = glass_sample(b, wo, u_lobe, u0, u1, s); break;
    case IRIS_BSDF_GLTF:
      ok = has_layers(b) && wo.z > 0.0f ? gltf_layered_sample(b, wo, u_lobe, u0, u1, s)
                                        : gltf_base_sample(b, wo, u_lobe, u0, u1, s);
      break;
    default: ok = false; break;
  }
  s->f = sanitize3(s->f);
  s->pdf = sanitize1(s->pdf);
  if (!ok || !(s->pdf > 0.0f) || !iris_isfinite3(s->wi)) {
    s->f = zero3;
    s->pdf = 0.0f;
    return false;
  }
  return true;
}

uint32_t iris_bsdf_lobes(const iris_bsdf *b) {
  if (b->type == IRIS_BSDF_DIFFUSE) return IRIS_LOBE_REFLECTION | IRIS_LOBE_DIFFUSE;
  bool smooth = alpha_is_singular(alpha_of(b->roughness));
  if (b->type == IRIS_BSDF_GLTF && b->anisotropy > 0.0f) {
    float at, ab;
    gltf_aniso_alphas(b, &at, &ab);
    smooth = at * ab <= IRIS_BSDF_SINGULAR_ALPHA2;
  }
  uint32_t spec = smooth ? IRIS_LOBE_DELTA : IRIS_LOBE_GLOSSY;
  switch (b->type) {
    case IRIS_BSDF_DIFFUSE: return IRIS_LOBE_REFLECTION | IRIS_LOBE_DIFFUSE;
    case IRIS_BSDF_GLOSSY: return IRIS_LOBE_REFLECTION | spec;
    case IRIS_BSDF_GLASS:
      if (fabsf(b->ior - 1.0f) < 1e-4f) spec = IRIS_LOBE_DELTA;
      return IRIS_LOBE_REFLECTION | IRIS_LOBE_TRANSMISSION | spec;
    case IRIS_BSDF_GLTF: {
      float metallic = iris_clampf(b->metallic, 0.0f, 1.0f);
      float transmission = iris_clampf(b->transmission, 0.0f, 1.0f);
      uint32_t l = 0;
      if (metallic < 1.0f && transmission < 1.0f) l |= IRIS_LOBE_REFLECTION | IRIS_LOBE_DIFFUSE;
      if (metallic > 0.0f || b->specular > 0.0f) l |= IRIS_LOBE_REFLECTION | spec;
      if (metallic < 1.0f && transmission > 0.0f) l |= IRIS_LOBE_TRANSMISSION | spec;
      if (b->clearcoat > 0.0f)
        l |= IRIS_LOBE_REFLECTION | (alpha_is_singular(alpha_of(b->clearcoat_roughness)) ? IRIS_LOBE_DELTA : IRIS_LOBE_GLOSSY);
      if (iris_max3(b->sheen_color) > 0.0f) l |= IRIS_LOBE_REFLECTION | IRIS_LOBE_GLOSSY;
      return l;
    }
    default: return 0;
  }
}

bool iris_bsdf_is_delta(const iris_bsdf *b) {
  if (b->type == IRIS_BSDF_DIFFUSE) return false;
  uint32_t l = iris_bsdf_lobes(b);
  return (l & IRIS_LOBE_DELTA) && !(l & (IRIS_LOBE_DIFFUSE | IRIS_LOBE_GLOSSY));
}

float iris_bsdf_guiding_roughness(const iris_bsdf *b) {
  uint32_t l = iris_bsdf_lobes(b);
  if (iris_bsdf_is_delta(b)) return 0.0f;
  if (!(l & (IRIS_LOBE_GLOSSY | IRIS_LOBE_DELTA))) return INFINITY;
  if ((l & IRIS_LOBE_GLOSSY) && b->type == IRIS_BSDF_GLTF && b->anisotropy > 0.0f) {
    float at, ab; /* the isotropic roughness of the same sqrt(at ab) */
    gltf_aniso_alphas(b, &at, &ab);
    return iris_clampf(sqrtf(sqrtf(at * ab)), 0.0f, 1.0f);
  }
  if (l & IRIS_LOBE_GLOSSY) return iris_clampf(b->roughness, 0.0f, 1.0f);
  /* gltf with a smooth coat over a diffuse base: the diffuse share of the
   * material decides how much irradiance sampling may be used. */
  return (1.0f - iris_clampf(b->metallic, 0.0f, 1.0f)) *
         (1.0f - iris_clampf(b->transmission, 0.0f, 1.0f));
}
