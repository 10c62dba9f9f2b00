/* Private to scene/: what the scene JSON's writer (scene_write.c) and loader
 * (scene_load.c) share: the format's name, the names of its enums and
 * attribute bits, and the degree conversion both must agree on bit for bit.
 * Format: docs/format.md. */
#ifndef IRIS_SCENE_SCENE_JSON_H
#define IRIS_SCENE_SCENE_JSON_H

#include <stdbool.h>

#define SCENE_FORMAT_NAME "iris-scene"
#define PI_D 3.14159265358979323846

static const char *const MATERIAL_TYPES[] = {"diffuse", "glossy", "glass", "gltf"};
static const char *const LIGHT_TYPES[] = {"point", "spot", "directional"};
static const char *const WRAP_MODES[] = {"repeat", "clamp", "mirror"};
/* In IRIS_MESH_HAS_* bit order. */
static const char *const ATTRIBUTE_NAMES[] = {"normals", "uvs", "colors", "uvs1", "tangents", "alphas"};
#define ATTRIBUTE_COUNT 6
static const char *const ALPHA_MODES[] = {"opaque", "mask", "blend"};

/* Angles are stored in degrees; this is the one conversion back to radians. */
static inline float deg_to_rad(double deg) { return (float)(deg * (PI_D / 180.0)); }

static inline bool floats_equal(const float *a, const float *b, int n) {
  for (int i = 0; i < n; i++)
    if (a[i] != b[i]) return false;
  return true;
}

#endif
