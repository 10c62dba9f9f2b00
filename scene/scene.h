/* The iris scene: what every importer produces, the renderer consumes and the
 * exporters translate. In memory it is plain arrays + indices; on disk it is a
 * JSON description plus one binary mesh file per mesh (docs/format.md).
 * Only what a scene has is stored: optional attributes are NULL when absent
 * and material fields that do not apply to a material's type are ignored. */
#ifndef IRIS_SCENE_SCENE_H
#define IRIS_SCENE_SCENE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "core/math.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IRIS_SCENE_FORMAT_VERSION 1

/* ---- textures ---------------------------------------------------------- */

typedef enum iris_wrap { IRIS_WRAP_REPEAT = 0, IRIS_WRAP_CLAMP, IRIS_WRAP_MIRROR } iris_wrap;

/* An encoded image (PNG or JPEG). Either `path` names the file (absolute, or
 * relative to the scene JSON's folder after loading it is made absolute), or the
 * encoded bytes are held in memory (glTF data URIs and GLB buffer views); when
 * written, in-memory images become files next to the scene JSON. */
typedef struct iris_texture {
  char *name;           /* may be NULL */
  char *path;           /* NULL when held in memory */
  uint8_t *data;        /* encoded bytes, owned; NULL when `path` is set */
  size_t data_size;
  char mime[16];        /* "image/png" or "image/jpeg" */
  iris_wrap wrap_s, wrap_t;
  bool nearest;         /* magnification filter NEAREST instead of bilinear */
  /* Where the image lies on the surface (glTF textureInfo.texCoord and
   * KHR_texture_transform): uv' = T(offset) R(rotation) S(scale) uv of set
   * `uv_set`, i.e. u' = ox + c sx u + s sy v, v' = oy - s sx u + c sy v with
   * c, s = cos, sin(rotation). Defaults: set 0, identity. */
  uint8_t uv_set;       /* 0: mesh uvs, 1: mesh uvs1 (the uvs when a mesh has no uvs1) */
  bool has_transform;   /* false: offset 0, rotation 0, scale 1 (not read) */
  float offset[2], rotation, scale[2];
} iris_texture;

/* ---- materials --------------------------------------------------------- */

typedef enum iris_material_type {
  IRIS_MATERIAL_DIFFUSE = 0, /* Lambert: color = albedo                      <-> Cycles Diffuse BSDF */
  IRIS_MATERIAL_GLOSSY,      /* GGX, alpha = roughness^2, tint, no Fresnel <-> Glossy BSDF (GGX) */
  IRIS_MATERIAL_GLASS,       /* dielectric, exact Fresnel, GGX if rough    <-> Glass BSDF (GGX) */
  IRIS_MATERIAL_GLTF         /* glTF 2.0 metallic-roughness (Appendix B)   <-> Principled BSDF */
} iris_material_type;

/* glTF alphaMode: how the coverage alpha = `alpha` x colour texture alpha x
 * vertex alpha is used (docs/materials.md, "Alpha"). */
typedef enum iris_alpha_mode {
  IRIS_ALPHA_OPAQUE = 0, /* alpha ignored */
  IRIS_ALPHA_MASK,       /* the surface exists where alpha >= alpha_cutoff */
  IRIS_ALPHA_BLEND       /* rays pass through with probability 1 - alpha */
} iris_alpha_mode;

typedef struct iris_material {
  char *name;
  iris_material_type type;
  float color[3];          /* albedo / tint / base colour (linear) */
  int32_t color_texture;   /* texture index or -1; multiplies color (sRGB-decoded) */
  float roughness;         /* glossy, glass, gltf: perceptual roughness in [0,1] */
  float ior;               /* glass, gltf */
  float metallic;          /* gltf */
  int32_t metallic_roughness_texture; /* gltf: B = metallic, G = roughness; -1 none */
  float specular;          /* gltf KHR_materials_specular specularFactor (1 default) */
  float specular_color[3]; /* gltf specularColorFactor (1,1,1 default) */
  float transmission;      /* gltf KHR_materials_transmission factor */
  /* gltf: transmission x texture R (linear), specular x texture A (linear),
   * specular_color x texture RGB (sRGB-decoded); -1 none */
  int32_t transmission_texture, specular_texture, specular_color_texture;
  float emission[3];       /* emitted radiance = colour x strength; all 0: not emissive */
  int32_t emission_texture;/* multiplies emission (sRGB-decoded); -1 none */
  bool emission_two_sided; /* true: emits from both faces (Cycles' behaviour) */
  bool unlit;              /* glTF KHR_materials_unlit: the emission is also multiplied by the
                              mesh's vertex colours (the importer stores an unlit surface as a
                              black diffuse emitting base colour x texture, docs/format.md) */
  bool double_sided;       /* glTF doubleSided (informational for back-face shading) */
  int32_t normal_texture;  /* tangent-space normal map (linear, glTF convention), -1 none;
                              used on meshes with tangents */
  float normal_scale;      /* glTF normalTexture.scale: scales the map's x and y (1 default) */
  iris_alpha_mode alpha_mode;
  float alpha;             /* glTF baseColorFactor.a, [0, 1] (1 default) */
  float alpha_cutoff;      /* MASK threshold, >= 0 (0.5 default) */
  /* gltf KHR_materials_clearcoat: factor x texture R, roughness x texture G,
   * the coat's own normal map (else the coat follows the unmapped normal) */
  float clearcoat, clearcoat_roughness;
  int32_t clearcoat_texture, clearcoat_roughness_texture, clearcoat_normal_texture;
  float clearcoat_normal_scale;
  /* gltf KHR_materials_sheen: colour x texture RGB (sRGB), roughness x texture A */
  float sheen_color[3];
  float sheen_roughness;
  int32_t sheen_color_texture, sheen_roughness_texture;
  /* gltf KHR_materials_volume: Beer-Lambert absorption inside the (closed,
   * transmissive) mesh, sigma = -ln(attenuation_color) / attenuation_distance;
   * distance 0 = no attenuation (the extension's infinity) */
  float attenuation_color[3];
  float attenuation_distance;
  /* gltf KHR_materials_anisotropy: strength in [0, 1] x texture B; the direction,
   * in the mesh's tangent frame (tangent, bitangent), is the texture's RG mapped
   * [0,1] -> [-1,1] (else (1, 0)) turned counter-clockwise by `anisotropy_rotation`
   * radians. Needs mesh tangents; without them the surface is isotropic. */
  float anisotropy, anisotropy_rotation;
  int32_t anisotropy_texture; /* linear, -1 none */
} iris_material;

/* ---- meshes and instances --------------------------------------------- */

/* A triangle mesh with one material. Attribute arrays are NULL when the
 * source did not have them. Arrays are either owned (malloc'ed) or borrowed
 * from a memory map held by the scene; `owned` tells which. */
typedef struct iris_mesh {
  char *name;
  uint32_t vertex_count;
  uint32_t triangle_count;
  float *positions;   /* 3 * vertex_count */
  float *normals;     /* 3 * vertex_count or NULL */
  float *uvs;         /* 2 * vertex_count or NULL (glTF convention: v down, (0,0) top-left of the image) */
  float *colors;      /* 3 * vertex_count or NULL (linear RGB) */
  float *uvs1;        /* 2 * vertex_count or NULL: a second uv set (glTF TEXCOORD_1) */
  float *tangents;    /* 4 * vertex_count or NULL: xyz unit tangent along +u, w = +-1 the
                         bitangent sign, B = w (N x T) (glTF TANGENT or generated; only
                         with normals, for normal maps) */
  float *alphas;      /* vertex_count or NULL: vertex alpha in [0, 1] (glTF COLOR_0.a; only for
                         MASK/BLEND materials) */
  uint32_t *indices;  /* 3 * triangle_count, counter-clockwise = front */
  int32_t material;   /* index or -1 for the default material (diffuse 0.8) */
  bool owned;
} iris_mesh;

typedef struct iris_instance {
  uint32_t mesh;
  iris_mat4 transform; /* object to world */
} iris_instance;

/* ---- cameras, lights, environment ------------------------------------- */

typedef struct iris_camera {
  char *name;
  iris_mat4 to_world; /* camera looks along its local -Z, +Y up (glTF/Blender) */
  float yfov;         /* vertical field of view, radians */
  float aspect;       /* width / height; 0 when the source does not say */
} iris_camera;

typedef enum iris_light_type {
  IRIS_LIGHT_POINT = 0,
  IRIS_LIGHT_SPOT,
  IRIS_LIGHT_DIRECTIONAL
} iris_light_type;

/* KHR_lights_punctual light in world space. Units as glTF: point and spot
 * `intensity` in candela (W/sr in iris's radiometric reading), directional in
 * lux (W/m^2). docs/materials.md gives the conversion to Cycles. */
typedef struct iris_light {
  char *name;
  iris_light_type type;
  float color[3];
  float intensity;
  float position[3];  /* point, spot */
  float direction[3]; /* spot, directional: unit vector the light travels along */
  float range;        /* 0 = infinite */
  float inner_cone;   /* spot, radians */
  float outer_cone;   /* spot, radians */
} iris_light;

/* An equirectangular (latitude-longitude, 2:1) HDR image lighting the scene
 * from infinitely far away: OpenEXR or Radiance .hdr. Direction d looks up
 * texel (s, t) = (1/2 + atan2(d'z, d'x) / 2pi, acos(d'y) / pi), row 0 at the
 * top, with d' = R_y(rotation) d: the texel Blender's Environment Texture
 * (default mapping) shows for the same direction of a glTF file imported by
 * Blender (docs/format.md, "environment"). */
typedef struct iris_environment_map {
  char *path;     /* absolute after loading a scene JSON; NULL = no map */
  float strength; /* radiance = texel x strength */
  float rotation; /* degrees about the up axis (+Y) */
} iris_environment_map;

typedef struct iris_render_settings {
  int width, height;  /* 0 = derive */
  int spp;            /* 0 = default */
  int max_depth;      /* -1 = default (64) */
  char method[32];    /* "" = default */
  uint64_t seed;
  bool has_seed;
} iris_render_settings;

/* The KHR_materials_variants of the glTF file a scene was imported from: the
 * variant names the file offers, and which one's materials the scene holds
 * (docs/format.md, "material_variants"). count 0: none. */
typedef struct iris_material_variants {
  char **names;    /* count names (owned) */
  size_t count;
  int32_t applied; /* index into names, -1: the file's default materials */
} iris_material_variants;

typedef struct iris_scene {
  char units[16]; /* "m" unless the source says otherwise */

  iris_texture *textures;
  size_t texture_count;
  iris_material *materials;
  size_t material_count;
  iris_mesh *meshes;
  size_t mesh_count;
  iris_instance *instances;
  size_t instance_count;
  iris_camera *cameras;
  size_t camera_count;
  iris_light *lights;
  size_t light_count;

  bool has_environment;
  float environment[3]; /* constant radiance of the world (when there is no map) */
  iris_environment_map environment_map; /* path != NULL: the world is this map */

  iris_render_settings render;
  iris_material_variants variants;

  /* Source path (for messages) and memory maps that borrowed arrays point into. */
  char *source_path;
  void *maps;
  size_t map_count;
} iris_scene;

/* ---- lifetime and building -------------------------------------------- */

iris_scene *iris_scene_create(void);
void iris_scene_destroy(iris_scene *scene);

/* Appenders return the new element's index, or -1 when out of memory. The
 * scene takes ownership of every pointer stored in the appended element
 * (names, arrays); strings are copied by the _str helper. */
int32_t iris_scene_add_texture(iris_scene *scene, const iris_texture *tex);
int32_t iris_scene_add_material(iris_scene *scene, const iris_material *mat);
int32_t iris_scene_add_mesh(iris_scene *scene, const iris_mesh *mesh);
int32_t iris_scene_add_instance(iris_scene *scene, const iris_instance *inst);
int32_t iris_scene_add_camera(iris_scene *scene, const iris_camera *cam);
int32_t iris_scene_add_light(iris_scene *scene, const iris_light *light);
char *iris_strdup(const char *s);
/* The world becomes the map at `path` (copied; not opened here) times
 * `strength`, rotated by `rotation` degrees about +Y; false when out of memory. */
bool iris_scene_set_environment_map(iris_scene *scene, const char *path, float strength,
                                    float rotation);
/* The world becomes the constant radiance rgb (any map is dropped). */
void iris_scene_set_environment_color(iris_scene *scene, const float rgb[3]);
/* True when something in the scene emits: a punctual light of non-zero
 * intensity, a non-black environment, or an instanced mesh with an emissive
 * material. A scene without any renders black. */
bool iris_scene_has_emitter(const iris_scene *scene);
/* One warning line when !iris_scene_has_emitter: the image will be black, and
 * how to light it (--env FILE or --env-color R,G,B). `what` names the scene. */
void iris_scene_warn_if_lightless(const iris_scene *scene, const char *what);

/* A material with the defaults for its type (colour 0.8, roughness 0.5,
 * ior 1.5, specular 1, textures -1, not emissive, emission two-sided). */
iris_material iris_material_default(iris_material_type type);

/* Appends all of `src` to `dst` (indices remapped), taking src's contents;
 * src is destroyed. Used to combine several imported files. */
iris_status iris_scene_merge(iris_scene *dst, iris_scene *src, iris_error *err);

/* ---- validation and files --------------------------------------------- */

/* Checks every invariant: indices in range, finite numbers, references valid,
 * counts consistent. `file` names the source in messages. */
iris_status iris_scene_validate(const iris_scene *scene, const char *file, iris_error *err);

/* Loads a scene JSON and its mesh files (memory-mapped), validating everything. */
iris_status iris_scene_load(const char *json_path, iris_scene **out, iris_error *err);

/* Writes the JSON and one mesh file per mesh ("<stem>.meshes/<i>.irmesh" next
 * to the JSON) and in-memory textures, all atomically. Writing the same scene
 * twice gives identical bytes. */
iris_status iris_scene_write(const iris_scene *scene, const char *json_path, iris_error *err);

/* World-space bounds of all instances; returns false for an empty scene (or out of memory). */
bool iris_scene_bounds(const iris_scene *scene, iris_vec3 *lo, iris_vec3 *hi);
/* Total world-space triangle count (instances counted separately). */
uint64_t iris_scene_triangle_count(const iris_scene *scene);

/* Binary mesh files on their own (used by write/load, the fuzzer and tests). */
iris_status iris_mesh_write_file(const iris_mesh *mesh, const char *path, iris_error *err);
/* Validates header, sizes against the file length, checksum, finite values and
 * index range. On success the mesh's arrays point into *map (borrowed). */
typedef struct iris_file_map iris_file_map;
iris_status iris_mesh_read_map(const iris_file_map *map, const char *path, iris_mesh *mesh,
                               iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
