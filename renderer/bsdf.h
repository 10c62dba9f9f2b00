/* Materials at a shading point: evaluation, sampling and pdf side by side for
 * each BSDF (docs/materials.md gives every formula and its Cycles 3.4 node).
 * All directions are in the local shading frame (z = shading normal) and point
 * away from the surface: wo towards the viewer, wi towards the light.
 * For BSDFs without a transmission lobe (iris_bsdf_lobes has no
 * IRIS_LOBE_TRANSMISSION) the caller orients the frame so that wo.z > 0
 * (two-sided shading as in Cycles); glass and transmissive gltf keep the
 * geometric side: wo.z < 0 means wo is inside and the IOR is inverted. */
#ifndef IRIS_RENDERER_BSDF_H
#define IRIS_RENDERER_BSDF_H

#include <stdbool.h>
#include <stdint.h>

#include "core/math.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum iris_bsdf_type {
  IRIS_BSDF_DIFFUSE = 0,
  IRIS_BSDF_GLOSSY,
  IRIS_BSDF_GLASS,
  IRIS_BSDF_GLTF
} iris_bsdf_type;

/* Roughness at or below this is treated as perfectly smooth (a delta lobe).
 * Cycles 3.4 makes a GGX closure singular when alpha^2 <= 1e-7, i.e.
 * roughness^4 <= 1e-7; bsdf.c applies exactly that test and this is its
 * roughness (1e-7^(1/4)). */
#define IRIS_BSDF_MIN_ROUGHNESS 0.0177827941f

typedef struct iris_bsdf {
  iris_bsdf_type type;
  iris_vec3 color;          /* albedo / tint / base colour, textures already applied */
  float roughness;          /* perceptual; GGX alpha = roughness^2 */
  float ior;
  float metallic;           /* gltf */
  float specular;           /* gltf KHR_materials_specular factor */
  iris_vec3 specular_color; /* gltf */
  float transmission;       /* gltf */
  /* gltf layers over the base (0 = absent; docs/materials.md, "Clearcoat and sheen"):
   * KHR_materials_clearcoat, a GGX dielectric coat (F0 0.04) with its own normal
   * (local to this BSDF's frame; (0, 0, 1) when the coat follows the shading
   * normal), and KHR_materials_sheen, a Charlie-distribution lobe with the
   * extension's albedo scaling of what lies below. Set by the caller. */
  float clearcoat, clearcoat_roughness;
  iris_vec3 coat_n;
  iris_vec3 sheen_color;
  float sheen_roughness;
  /* gltf KHR_materials_anisotropy (0 = isotropic, the default): strength in
   * [0, 1] and the anisotropy direction (cos, sin) in this BSDF's local frame.
   * The specular and transmission lobes get alpha_t = mix(alpha, 1, strength^2)
   * along that direction and alpha_b = alpha across it. Set by the caller. */
  float anisotropy;
  float aniso_dir[2];
} iris_bsdf;

/* Lobe flags of a sample (and of a BSDF as a whole). */
enum {
  IRIS_LOBE_REFLECTION = 1u << 0,
  IRIS_LOBE_TRANSMISSION = 1u << 1,
  IRIS_LOBE_DIFFUSE = 1u << 2,
  IRIS_LOBE_GLOSSY = 1u << 3,
  IRIS_LOBE_DELTA = 1u << 4
};

/* A struct tag only (no typedef): the name also belongs to the function below. */
struct iris_bsdf_sample {
  iris_vec3 wi;   /* sampled direction (local) */
  iris_vec3 f;    /* BSDF value; for delta lobes it includes 1/|cos wi| */
  float pdf;      /* solid-angle pdf; for delta lobes the discrete lobe probability */
  uint32_t lobe;  /* IRIS_LOBE_* of the sampled lobe */
};

/* Builds the BSDF of a material at a point (texture value `tex_color` already
 * sRGB-decoded and multiplied in by the caller; pass the material's colour when
 * untextured). */
iris_bsdf iris_bsdf_from_material(const iris_material *mat, iris_vec3 color, float roughness,
                                  float metallic);

/* f(wo, wi) without the cosine; 0 for delta lobes. */
iris_vec3 iris_bsdf_eval(const iris_bsdf *b, iris_vec3 wo, iris_vec3 wi);
/* Solid-angle density with which iris_bsdf_sample returns wi; 0 for delta lobes. */
float iris_bsdf_pdf(const iris_bsdf *b, iris_vec3 wo, iris_vec3 wi);
/* Samples wi with three uniform numbers (u_lobe picks the lobe). Returns false
 * when no direction could be produced (the path ends). */
bool iris_bsdf_sample(const iris_bsdf *b, iris_vec3 wo, float u_lobe, float u0, float u1,
                      struct iris_bsdf_sample *s);

/* Union of IRIS_LOBE_* flags the BSDF can produce. */
uint32_t iris_bsdf_lobes(const iris_bsdf *b);
/* True when every lobe is a delta (no point in light sampling or guiding). */
bool iris_bsdf_is_delta(const iris_bsdf *b);
/* Roughness as the guiding chapter uses it (thesis 5.2.1): INFINITY for a
 * purely diffuse BSDF, 0 for delta, else the perceptual roughness. */
float iris_bsdf_guiding_roughness(const iris_bsdf *b);

#ifdef __cplusplus
}
#endif
#endif
