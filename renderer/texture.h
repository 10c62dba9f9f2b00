/* Texture lookup for the renderer: every scene texture decoded once (PNG/JPEG
 * through core/image.h), then bilinear (or nearest) lookups with the glTF
 * sampler's wrap modes. Colour textures are sRGB-decoded per texel before
 * filtering; data textures (metallic-roughness) are read linearly. */
#ifndef IRIS_RENDERER_TEXTURE_H
#define IRIS_RENDERER_TEXTURE_H

#include <stdbool.h>
#include <stdint.h>

#include "core/error.h"
#include "core/image.h"
#include "core/math.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct iris_texture_image {
  int width, height;
  uint8_t *rgba;      /* 8-bit texels as stored in the file, top row first */
  iris_wrap wrap_s, wrap_t;
  bool nearest;
  uint8_t uv_set;     /* which uv set of the surface (iris_texture.uv_set) */
  bool has_transform; /* uv' = xf * (u, v, 1) (iris_texture's KHR_texture_transform) */
  float xf[2][3];
} iris_texture_image;

typedef struct iris_textures {
  iris_texture_image *images; /* one per scene texture */
  size_t count;
  float srgb_table[256]; /* 8-bit sRGB -> linear */
} iris_textures;

/* Decodes every texture of the scene (a texture that cannot be decoded is an error). */
iris_status iris_textures_load(const iris_scene *scene, iris_textures *out, iris_error *err);
void iris_textures_destroy(iris_textures *tex);

/* RGBA at texture coordinates (u, v) (glTF convention: (0, 0) is the top-left
 * corner of the image). `srgb` decodes the RGB channels (alpha stays linear).
 * An index out of range gives (1, 1, 1, 1). */
void iris_texture_lookup(const iris_textures *tex, int32_t index, float u, float v, bool srgb,
                         float rgba[4]);

/* The texture as placed on a surface: picks the texture's uv set (uv1 is the
 * surface's second set, equal to uv when the mesh has none), applies its
 * transform, then looks up like iris_texture_lookup. */
void iris_texture_sample(const iris_textures *tex, int32_t index, const float uv[2], const float uv1[2],
                         bool srgb, float rgba[4]);
/* The KHR_texture_transform matrix of a texture: u' = xf[0] . (u, v, 1), v' = xf[1] . (u, v, 1). */
void iris_texture_transform_matrix(const iris_texture *t, float xf[2][3]);

/* Texel coordinate after applying a wrap mode to integer index i of n. */
int iris_texture_wrap(int i, int n, iris_wrap mode);

#ifdef __cplusplus
}
#endif
#endif
