/* Shading normals from tangent-space normal maps (glTF normalTexture) and the
 * rule that keeps a bent shading normal usable: docs/rendering.md, "Normal
 * maps". The interaction carries the tangent frame (renderer/accel.h); the
 * integrator calls these once per shading point of a normal-mapped material. */
#ifndef IRIS_RENDERER_NORMAL_MAP_H
#define IRIS_RENDERER_NORMAL_MAP_H

#include "core/math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The normal a texel `rgb` (linear, in [0, 1]) of a tangent-space normal map
 * encodes, in world space: normalize(x T + y B + z N) with (x, y, z) = 2 rgb - 1
 * and x, y multiplied by `scale` (glTF normalTexture.scale). T, B, N need not
 * be orthonormal (glTF interpolates them per vertex). Returns N when the
 * result is degenerate. */
iris_vec3 iris_normal_map_apply(iris_vec3 t, iris_vec3 b, iris_vec3 n, const float rgb[3], float scale);

/* A shading normal n (unit) seen from wo (unit, on the side of the unit
 * geometric normal ng) whose mirror reflection of wo would fall below the
 * geometric surface is bent towards ng, within the plane of n and ng, just
 * enough that the reflection rises `min(0.9 dot(wo, ng), 0.01)` above it
 * (the rule Cycles applies to normal-mapped normals). Other n are returned as
 * they are; when no such normal exists, ng. */
iris_vec3 iris_normal_make_valid(iris_vec3 ng, iris_vec3 wo, iris_vec3 n);

#ifdef __cplusplus
}
#endif
#endif
