/* What a glTF metallic-roughness material really is: some parameter sets are
 * exactly a simpler material (specularFactor 0 + metallic 0 + no transmission
 * is Lambert), others are a pure conductor or a pure dielectric. The importer
 * canonicalises with it; the Blender exporter and the validation stage use the
 * class to say whether Cycles can reproduce the material exactly (docs/export.md). */
#ifndef IRIS_SCENE_MATERIAL_CLASS_H
#define IRIS_SCENE_MATERIAL_CLASS_H

#include <stdbool.h>

#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* GGX lobes with roughness at or below this are mirrors in iris and in Cycles
 * (alpha^2 <= 1e-7; the same number as renderer/bsdf.h IRIS_BSDF_MIN_ROUGHNESS). */
#define IRIS_SMOOTH_ROUGHNESS 0.01778f

typedef enum iris_gltf_class {
  IRIS_GLTF_NOT_GLTF = 0, /* diffuse, glossy or glass: already the simplest form */
  IRIS_GLTF_LAMBERT,      /* metallic 0, transmission 0, specularFactor 0: f = baseColor / pi */
  IRIS_GLTF_CONDUCTOR,    /* metallic 1 (factor 1, no metallic texture): GGX x Schlick(baseColor) */
  IRIS_GLTF_DIELECTRIC,   /* metallic 0, transmission 1 (no transmission texture): Schlick-split
                             reflection + refraction */
  IRIS_GLTF_GENERAL       /* anything else: the full Appendix B mixture */
} iris_gltf_class;

iris_gltf_class iris_material_gltf_class(const iris_material *m);
const char *iris_gltf_class_name(iris_gltf_class c); /* "lambert", "conductor", ... */

/* True when every GGX lobe of the material is a mirror (roughness factor <=
 * IRIS_SMOOTH_ROUGHNESS and no roughness texture), so that the Fresnel terms
 * that glTF evaluates at V.H are evaluated at N.V = V.H exactly. */
bool iris_material_gltf_smooth(const iris_material *m);

/* Rewrites a glTF material that is exactly a simpler iris material into that
 * material (today: LAMBERT -> diffuse with the same colour, texture and
 * emission). Returns true when it changed `m`. Other materials are untouched. */
bool iris_material_canonicalize(iris_material *m);

#ifdef __cplusplus
}
#endif
#endif
