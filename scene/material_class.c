/* glTF material classes and canonicalisation (scene/material_class.h). The
 * formulas they rely on are those of renderer/bsdf.c's gltf BSDF
 * (docs/materials.md): base weight (1-m)(1-T)(1 - w max Fr(N.V)), specular
 * w (1-m) Fr(V.H) + m F_m(V.H), transmission (1-m) T (1 - w max Fr(N.V)). */
#include "scene/material_class.h"

#include <stddef.h>

iris_gltf_class iris_material_gltf_class(const iris_material *m) {
  if (m->type != IRIS_MATERIAL_GLTF) return IRIS_GLTF_NOT_GLTF;
  /* clearcoat and sheen layers: no Cycles node reproduces them (Principled v1
   * approximates them), whatever the base is; anisotropy needs Principled too */
  if (m->clearcoat > 0.0f || m->sheen_color[0] > 0.0f || m->sheen_color[1] > 0.0f || m->sheen_color[2] > 0.0f ||
      m->anisotropy > 0.0f)
    return IRIS_GLTF_GENERAL;
  /* metallic = factor x texture B, so a factor of 0 is 0 whatever the texture;
   * a factor of 1 is 1 only without a texture. */
  bool metal0 = m->metallic == 0.0f;
  bool metal1 = m->metallic == 1.0f && m->metallic_roughness_texture < 0;
  if (metal1) return IRIS_GLTF_CONDUCTOR;
  /* Schlick's Fr(c) -> 1 at grazing even for f0 = 0, so only specularFactor 0
   * removes the specular lobe and leaves the base weight at exactly 1. The
   * transmission and specular textures multiply their factors, so a factor of
   * 0 is 0 whatever they hold; a transmission factor of 1 is 1 only without one. */
  if (metal0 && m->transmission == 0.0f && m->specular == 0.0f) return IRIS_GLTF_LAMBERT;
  if (metal0 && m->transmission == 1.0f && m->transmission_texture < 0) return IRIS_GLTF_DIELECTRIC;
  return IRIS_GLTF_GENERAL;
}

const char *iris_gltf_class_name(iris_gltf_class c) {
  switch (c) {
    case IRIS_GLTF_LAMBERT: return "lambert";
    case IRIS_GLTF_CONDUCTOR: return "conductor";
    case IRIS_GLTF_DIELECTRIC: return "dielectric";
    case IRIS_GLTF_GENERAL: return "general";
    default: return "not-gltf";
  }
}

bool iris_material_gltf_smooth(const iris_material *m) {
  return m->type == IRIS_MATERIAL_GLTF && m->roughness <= IRIS_SMOOTH_ROUGHNESS &&
         m->metallic_roughness_texture < 0;
}

bool iris_material_canonicalize(iris_material *m) {
  if (iris_material_gltf_class(m) != IRIS_GLTF_LAMBERT) return false;
  /* Only a material that is a Lambert and nothing else: layers (clearcoat,
   * sheen) exist for gltf materials only, and normal maps and alpha are kept
   * where every consumer (renderer, exporters) reads them on gltf materials. */
  if (m->clearcoat > 0.0f || m->sheen_color[0] > 0.0f || m->sheen_color[1] > 0.0f ||
      m->sheen_color[2] > 0.0f || m->normal_texture >= 0 || m->alpha_mode != IRIS_ALPHA_OPAQUE ||
      m->alpha < 1.0f)
    return false;
  /* A diffuse material keeps what applies to it; fields that do not apply are
   * reset to the diffuse defaults so that equal materials stay equal. */
  iris_material d = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  d.name = m->name;
  for (int k = 0; k < 3; k++) {
    d.color[k] = m->color[k];
    d.emission[k] = m->emission[k];
  }
  d.color_texture = m->color_texture;
  d.emission_texture = m->emission_texture;
  d.emission_two_sided = m->emission_two_sided;
  d.double_sided = m->double_sided;
  *m = d;
  return true;
}
