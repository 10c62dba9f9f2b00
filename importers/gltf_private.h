/* Private to the glTF importer: the conversion context shared by the
 * accessor/primitive converter (gltf_convert.c), the node placement
 * (gltf_nodes.c), the material converter (gltf_material.c) and the variants
 * (gltf_variants.c), the glTF numeric codes, and the functions each offers
 * the others. Not a public interface. */
#ifndef IRIS_IMPORTERS_GLTF_PRIVATE_H
#define IRIS_IMPORTERS_GLTF_PRIVATE_H

#include <stdio.h>

#include "importers/gltf_convert.h"

/* glTF constants (the numeric codes of the spec; tinygltf uses the same). */
enum {
  CT_BYTE = 5120, CT_UBYTE = 5121, CT_SHORT = 5122, CT_USHORT = 5123, CT_UINT = 5125, CT_FLOAT = 5126,
  TYPE_VEC2 = 2, TYPE_VEC3 = 3, TYPE_VEC4 = 4, TYPE_MAT2 = 34, TYPE_MAT3 = 35, TYPE_MAT4 = 36,
  TYPE_SCALAR = 65,
  MODE_TRIANGLES = 4, MODE_STRIP = 5, MODE_FAN = 6,
  WRAP_REPEAT = 10497, WRAP_CLAMP = 33071, WRAP_MIRROR = 33648,
  FILTER_NEAREST = 9728, FILTER_LINEAR = 9729
};

typedef struct dmat4 {
  double m[4][4]; /* row-major, column vectors (as iris_mat4) */
} dmat4;

/* ---- conversion context ------------------------------------------------- */

/* The texture references of a material, in this order. */
enum {
  GLTF_SLOT_COLOR, GLTF_SLOT_METALLIC_ROUGHNESS, GLTF_SLOT_EMISSION, GLTF_SLOT_NORMAL,
  GLTF_SLOT_CLEARCOAT, GLTF_SLOT_CLEARCOAT_ROUGHNESS, GLTF_SLOT_CLEARCOAT_NORMAL, GLTF_SLOT_SHEEN_COLOR,
  GLTF_SLOT_SHEEN_ROUGHNESS, GLTF_SLOT_TRANSMISSION, GLTF_SLOT_SPECULAR, GLTF_SLOT_SPECULAR_COLOR,
  GLTF_SLOT_ANISOTROPY, GLTF_SLOT_COUNT
};

/* How a material slot places a texture: the glTF texture, the uv set and
 * KHR_texture_transform (as iris_texture's mapping fields). */
typedef struct gltf_slot {
  int texture; /* glTF texture index, -1 none */
  uint8_t uv_set;
  bool has_transform;
  float offset[2], rotation, scale[2];
} gltf_slot;

/* One scene texture: (image, sampler, mapping) -> scene index. */
typedef struct gltf_tex_key {
  int source, sampler;
  gltf_slot map; /* texture field unused */
  int32_t id;
} gltf_tex_key;

typedef struct converted_prim {
  iris_mesh mesh;     /* arrays owned here until handed to the scene */
  bool valid;         /* false: skipped (points/lines, no POSITION) */
  int gltf_material;  /* -1: glTF default material */
  int32_t scene_mesh; /* index in the scene once instanced, else -1 */
} converted_prim;

typedef struct gltf_ctx {
  const iris_gltf_doc *doc;
  const iris_import_options *opts;
  const char *file;
  iris_error *err;
  iris_scene *scene;

  converted_prim **prims; /* [mesh][primitive] */
  iris_material *materials; /* validated, textures still glTF indices */
  int32_t *material_map;    /* glTF material -> scene index, -1 not yet */
  int32_t default_material;
  int32_t variant; /* KHR_materials_variants variant applied (opts->variant), -1: the defaults */
  struct gltf_slot (*slots)[GLTF_SLOT_COUNT]; /* per glTF material: its texture references */
  struct gltf_tex_key *tex_keys;  /* scene textures made so far (id -2: dropped) */
  size_t tex_key_count, tex_key_cap;

  int *parent;
  dmat4 *world;

  /* Present-but-ignored features, reported once each at the end. */
  char ignored_attributes[256];
  size_t skipped_points_lines, skipped_no_position, skipped_empty, degenerate_dropped;
  bool warned_texcoord, warned_occlusion;
  size_t normal_map_no_normal, normal_map_no_uv; /* primitives whose normal map is not applied */
  size_t anisotropy_no_tangents; /* anisotropic primitives left without a tangent frame (isotropic) */
  char dispersion_materials[256]; /* KHR_materials_dispersion users, named in one warning */
  size_t dispersion_count;
  size_t tangents_generated, tangents_split;
  bool noticed_basisu;
  bool warned_morph, warned_skin, warned_ortho, warned_matrix_trs, warned_bad_image;
  size_t zero_normals;
  size_t budget_total, budget_left; /* bytes of converted mesh data allowed */
  size_t sparse_left;               /* sparse indices the validation may still read */
  uint32_t *vertex_mark, *vertex_remap; /* per accessor element, for primitive_vertices */
  size_t vertex_cap;
  uint32_t vertex_stamp;
  uint32_t *prim_indices, *prim_used; /* one primitive's indices and used vertices */
  size_t prim_indices_cap, prim_used_cap;
} gltf_ctx;

iris_status gltf_fail(gltf_ctx *c, iris_status st, const char *element, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* Fails unless lo <= v <= hi (finite): "<what> <v> is not in [lo, hi]". */
iris_status gltf_check_range(gltf_ctx *c, const char *el, const char *what, double v, double lo,
                             double hi);

#define ELEMENT(buf, ...) snprintf(buf, sizeof buf, __VA_ARGS__)

/* Reads a (validated) accessor into count * ncomp floats, applying sparse substitution. */
void gltf_read_floats(const iris_gltf_doc *d, const iris_gltf_accessor *a, int ncomp, float *out);

/* ---- gltf_nodes.c ---------------------------------------------------------- */

/* Cameras (perspective yfov/aspect, type) and KHR_lights_punctual lights checked. */
iris_status gltf_validate_cameras_lights(gltf_ctx *c);
/* c->parent filled: every node reference checked, one parent per node, no cycles. */
iris_status gltf_validate_node_graph(gltf_ctx *c);
/* Walks the default scene (else every root) in pre-order filling c->world, and
 * adds the mesh instances, lights and cameras (the chosen one first). */
iris_status gltf_place_nodes(gltf_ctx *c);

/* ---- gltf_material.c ------------------------------------------------------ */

/* Samplers, images and textures: every reference and enum checked. */
iris_status gltf_validate_textures(gltf_ctx *c);
/* Every material validated and converted (Appendix B + KHR_materials_*) into
 * c->materials, texture references still glTF indices. */
iris_status gltf_validate_materials(gltf_ctx *c);
/* Scene material for glTF material `gi` (-1: the glTF default material),
 * created on first use together with its textures. */
iris_status gltf_resolve_material(gltf_ctx *c, int gi, int32_t *out);
/* The uv set (validated) glTF material `gi`'s normal map reads, -1 without one. */
int gltf_material_normal_uv_set(const gltf_ctx *c, int gi);
/* The uv set whose tangent frame material `gi` needs: its normal map's, else for
 * KHR_materials_anisotropy the anisotropy texture's (0 untextured); -1: none. */
int gltf_material_tangent_uv_set(const gltf_ctx *c, int gi);
/* The alpha mode of (validated) glTF material `gi` (-1: the default material, opaque). */
iris_alpha_mode gltf_material_alpha_mode(const gltf_ctx *c, int gi);
/* Whether (validated) glTF material `gi` reads textures through TEXCOORD_1. */
bool gltf_material_uses_uv1(const gltf_ctx *c, int gi);

/* ---- gltf_variants.c (KHR_materials_variants) ---------------------------- */

/* The root variants and every primitive's mappings validated (indices in
 * range, JSON types, a variant at most once per primitive), and
 * opts->variant resolved into c->variant (IRIS_ERR_USAGE listing the names
 * when the file has no such variant). */
iris_status gltf_validate_variants(gltf_ctx *c);
/* The glTF material (-1: none) that primitive `pi` of mesh `mi` uses under c->variant. */
int gltf_variant_material(const gltf_ctx *c, size_t mi, size_t pi);
/* The file's variant names and the applied one recorded in the scene. */
iris_status gltf_store_variants(gltf_ctx *c);

#endif
