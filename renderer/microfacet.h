/* GGX (Trowbridge-Reitz) microfacet pieces, isotropic and anisotropic, and dielectric Fresnel,
 * in the local shading frame (z = normal). The BSDFs in bsdf.c assemble
 * these; each formula is written out in docs/materials.md. */
#ifndef IRIS_RENDERER_MICROFACET_H
#define IRIS_RENDERER_MICROFACET_H

#include <stdbool.h>

#include "core/math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* GGX normal distribution D(m) for a microfacet normal m (0 when m.z <= 0). */
float iris_ggx_d(float alpha, iris_vec3 m);
/* Smith Lambda(w) for GGX (Heitz 2014, eq. 72). */
float iris_ggx_lambda(float alpha, iris_vec3 w);
/* Smith masking G1(w) = 1 / (1 + Lambda(w)). */
float iris_ggx_g1(float alpha, iris_vec3 w);
/* Samples a visible normal for wo (wo.z > 0): Heitz 2018, "Sampling the GGX
 * Distribution of Visible Normals". */
iris_vec3 iris_ggx_sample_vndf(float alpha, iris_vec3 wo, float u0, float u1);
/* Density of that normal: D_wo(m) = G1(wo) max(0, wo.m) D(m) / wo.z. */
float iris_ggx_vndf_pdf(float alpha, iris_vec3 wo, iris_vec3 m);

/* Anisotropic GGX with roughness ax along the local x axis and ay along y
 * (Heitz 2014, eqs. 85-86; KHR_materials_anisotropy's D with at = ax, ab = ay). */
float iris_ggx_d_aniso(float ax, float ay, iris_vec3 m);
/* Lambda(w) = (sqrt(1 + (ax^2 x^2 + ay^2 y^2) / z^2) - 1) / 2. */
float iris_ggx_lambda_aniso(float ax, float ay, iris_vec3 w);
float iris_ggx_g1_aniso(float ax, float ay, iris_vec3 w);
/* Heitz 2018 handles anisotropy by stretching with (ax, ay); the isotropic
 * sampler is this with ax = ay (same operations, same bits). */
iris_vec3 iris_ggx_sample_vndf_aniso(float ax, float ay, iris_vec3 wo, float u0, float u1);
float iris_ggx_vndf_pdf_aniso(float ax, float ay, iris_vec3 wo, iris_vec3 m);

/* Exact unpolarised Fresnel reflectance of a dielectric interface for light
 * arriving at cos_i (sign ignored) from the side whose relative index is 1,
 * eta = n_other / n_this. 1 under total internal reflection. */
float iris_fresnel_dielectric(float cos_i, float eta);
/* Schlick's approximation f0 + (1 - f0) (1 - cos)^5 with a scalar f0. */
float iris_fresnel_schlick(float f0, float cos_theta);

/* Mirror of w about m. */
static inline iris_vec3 iris_reflect(iris_vec3 w, iris_vec3 m) {
  return iris_sub(iris_scale(m, 2.0f * iris_dot(w, m)), w);
}
/* Refracts w (pointing away, on the side m points to) through the interface
 * with normal m and eta = n_transmitted / n_incident. Returns false under
 * total internal reflection. */
bool iris_refract(iris_vec3 w, iris_vec3 m, float eta, iris_vec3 *wt);

#ifdef __cplusplus
}
#endif
#endif
