/* Private interface between the glTF shim (gltf.cpp, which parses with
 * tinygltf) and the converter (gltf_convert.c, plain C). The shim copies
 * tinygltf's model into the plain "document" below without judging it; the
 * converter validates every reference and byte range and builds the scene.
 * Every pointer is borrowed from the tinygltf model, alive during conversion. */
#ifndef IRIS_IMPORTERS_GLTF_CONVERT_H
#define IRIS_IMPORTERS_GLTF_CONVERT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "importers/import.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct iris_gltf_buffer {
  const uint8_t *data;
  size_t size;
} iris_gltf_buffer;

typedef struct iris_gltf_view {
  int buffer;
  size_t offset, length, stride; /* stride 0 = tightly packed */
} iris_gltf_view;

typedef struct iris_gltf_accessor {
  int view; /* -1: all zeros (then usually sparse) */
  size_t offset;
  int component_type; /* 5120..5126 */
  int type;           /* tinygltf TINYGLTF_TYPE_* code (SCALAR 65, VEC2 2, ..., MAT4 36) */
  bool normalized;
  size_t count;
  bool sparse;
  long long sparse_count;
  int sparse_index_view, sparse_index_type;
  long long sparse_index_offset;
  int sparse_value_view;
  long long sparse_value_offset;
} iris_gltf_accessor;

typedef struct iris_gltf_attribute {
  const char *name;
  int accessor;
} iris_gltf_attribute;

/* One KHR_materials_variants mapping of a primitive. Numbers that are not
 * integers become INT_MIN (rejected by the validation); `bad` names a value
 * of the wrong JSON type. */
typedef struct iris_gltf_variant_mapping {
  int material;
  const int *variants;
  size_t variant_count;
  const char *bad;
} iris_gltf_variant_mapping;

typedef struct iris_gltf_primitive {
  int mode; /* -1 = absent (TRIANGLES) */
  int indices, material;
  const iris_gltf_attribute *attributes;
  size_t attribute_count;
  size_t target_count; /* morph targets (ignored) */
  /* KHR_materials_variants; `variants_bad` names what is wrong with the
   * extension object itself (not an object, "mappings" not an array). */
  const iris_gltf_variant_mapping *mappings;
  size_t mapping_count;
  const char *variants_bad;
} iris_gltf_primitive;

typedef struct iris_gltf_mesh {
  const char *name;
  const iris_gltf_primitive *primitives;
  size_t primitive_count;
} iris_gltf_mesh;

typedef struct iris_gltf_node {
  const char *name;
  int mesh, camera, skin, light; /* light: KHR_lights_punctual index or -1 */
  const int *children;
  size_t child_count;
  /* Lengths as found in the JSON (0 = absent); validated by the converter. */
  const double *matrix, *translation, *rotation, *scale;
  size_t matrix_len, translation_len, rotation_len, scale_len;
  bool has_weights;
  /* EXT_mesh_gpu_instancing: accessor indices of the per-instance TRANSLATION,
   * ROTATION and SCALE (-1 absent; INT_MIN present but not a number);
   * `gpu_instancing` when the node has the extension, `gpu_instancing_bad`
   * when it is not an object with an "attributes" object. */
  bool gpu_instancing, gpu_instancing_bad;
  int inst_translation, inst_rotation, inst_scale;
} iris_gltf_node;

typedef struct iris_gltf_texture_ref {
  int texture; /* -1 = none */
  int texcoord;
  double scale; /* normalTexture.scale (1 when absent; unused elsewhere) */
  /* KHR_texture_transform on this textureInfo */
  bool has_transform, bad_transform; /* bad: a value of the wrong JSON type or length */
  double offset[2], rotation, tscale[2];
  int transform_texcoord; /* its texCoord override, -1 when absent */
} iris_gltf_texture_ref;

typedef struct iris_gltf_material {
  const char *name;
  const double *base_color; /* base_color_len values (4 expected) */
  size_t base_color_len;
  iris_gltf_texture_ref base_color_texture;
  double metallic, roughness;
  iris_gltf_texture_ref metallic_roughness_texture;
  const double *emissive; /* emissive_len values (3 expected) */
  size_t emissive_len;
  iris_gltf_texture_ref emissive_texture;
  bool double_sided;
  const char *alpha_mode;
  double alpha_cutoff;
  iris_gltf_texture_ref normal_texture;
  bool has_occlusion_texture;
  /* Extensions; `bad_extension` names one whose values have the wrong JSON type. */
  const char *bad_extension;
  bool has_emissive_strength;
  double emissive_strength;
  bool has_specular;
  double specular, specular_color[3];
  iris_gltf_texture_ref specular_texture, specular_color_texture;
  bool has_transmission;
  double transmission;
  iris_gltf_texture_ref transmission_texture;
  bool has_ior;
  double ior;
  bool has_clearcoat;
  double clearcoat, clearcoat_roughness;
  iris_gltf_texture_ref clearcoat_texture, clearcoat_roughness_texture, clearcoat_normal_texture;
  bool has_sheen;
  double sheen_color[3], sheen_roughness;
  iris_gltf_texture_ref sheen_color_texture, sheen_roughness_texture;
  bool has_volume, has_attenuation_distance;
  double attenuation_distance, attenuation_color[3];
  bool unlit; /* KHR_materials_unlit */
  bool has_anisotropy; /* KHR_materials_anisotropy */
  double anisotropy_strength, anisotropy_rotation;
  iris_gltf_texture_ref anisotropy_texture;
  bool has_dispersion; /* KHR_materials_dispersion (not rendered: warned about) */
} iris_gltf_material;

typedef struct iris_gltf_texture {
  int source, sampler;
  int webp_source, basisu_source; /* EXT_texture_webp / KHR_texture_basisu source, -1 none */
  const char *bad_extension;      /* names one whose source is not an integer */
} iris_gltf_texture;

typedef struct iris_gltf_image {
  const char *name;
  const char *uri;  /* external file (URL-encoded), or NULL */
  int view;         /* bufferView holding the encoded bytes, or -1 */
  const char *mime; /* declared mimeType ("" when absent) */
  const uint8_t *data; /* decoded data-URI bytes, or NULL */
  size_t size;
  bool file_found;     /* external file was read successfully */
  char file_mime[16];  /* sniffed from the external file's first bytes */
} iris_gltf_image;

typedef struct iris_gltf_sampler {
  int mag_filter, min_filter, wrap_s, wrap_t;
} iris_gltf_sampler;

typedef struct iris_gltf_camera {
  const char *name;
  const char *type; /* "perspective" or "orthographic" */
  double yfov, aspect;
} iris_gltf_camera;

typedef struct iris_gltf_light {
  const char *name;
  const char *type; /* "point", "spot", "directional" */
  const double *color;
  size_t color_len;
  double intensity, range, inner_cone, outer_cone;
} iris_gltf_light;

typedef struct iris_gltf_scene {
  const char *name;
  const int *nodes;
  size_t node_count;
} iris_gltf_scene;

typedef struct iris_gltf_doc {
  const char *file;     /* for messages */
  const char *base_dir; /* folder of the file; NULL: external files disabled */
  const char *version, *min_version;
  const char *const *extensions_used;
  size_t extensions_used_count;
  const char *const *extensions_required;
  size_t extensions_required_count;
  int default_scene;
  size_t animation_count;

  const iris_gltf_buffer *buffers;
  size_t buffer_count;
  const iris_gltf_view *views;
  size_t view_count;
  const iris_gltf_accessor *accessors;
  size_t accessor_count;
  const iris_gltf_mesh *meshes;
  size_t mesh_count;
  const iris_gltf_node *nodes;
  size_t node_count;
  const iris_gltf_material *materials;
  size_t material_count;
  const iris_gltf_texture *textures;
  size_t texture_count;
  const iris_gltf_image *images;
  size_t image_count;
  const iris_gltf_sampler *samplers;
  size_t sampler_count;
  const iris_gltf_camera *cameras;
  size_t camera_count;
  const iris_gltf_light *lights;
  size_t light_count;
  const iris_gltf_scene *scenes;
  size_t scene_count;
  /* KHR_materials_variants at the root: the variant names (NULL where a
   * variant has no string "name"); `variants_bad` names what is wrong with
   * the extension object itself. */
  const char *const *variant_names;
  size_t variant_count;
  const char *variants_bad;
} iris_gltf_doc;

/* Structural checks before tinygltf sees the bytes: the GLB container
 * (magic, version 2, total length, chunk bounds and alignment) and the JSON
 * nesting depth (tinygltf recurses over extras). Sets *is_glb. */
iris_status iris_gltf_check_container(const uint8_t *data, size_t size, const char *file,
                                      bool *is_glb, iris_error *err);

/* Rejects extensionsRequired naming anything iris does not implement. Called
 * with the names found by a light JSON scan as well, so that an unsupported
 * required extension is reported even when tinygltf cannot load the file. */
iris_status iris_gltf_check_required(const char *const *names, size_t count, const char *file,
                                     iris_error *err);

/* Validates the document and builds the scene. */
iris_status iris_gltf_convert(const iris_gltf_doc *doc, const iris_import_options *opts,
                              iris_scene **out, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
