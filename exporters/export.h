/* What the Blender and POV-Ray exporters share: the export parameters (which
 * camera, image size, sampling) and their resolution against a scene into one
 * concrete view, so that both exporters and iris's own render frame the scene
 * identically. docs/export.md describes every default. */
#ifndef IRIS_EXPORTERS_EXPORT_H
#define IRIS_EXPORTERS_EXPORT_H

#include <stdbool.h>
#include <stdint.h>

#include "scene/framing.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* POV-Ray radiosity (indirect light) quality; OFF renders direct light only. */
typedef enum iris_pov_radiosity {
  IRIS_POV_RADIOSITY_OFF = 0,
  IRIS_POV_RADIOSITY_LOW,
  IRIS_POV_RADIOSITY_MEDIUM, /* the default */
  IRIS_POV_RADIOSITY_HIGH
} iris_pov_radiosity;

typedef struct iris_export_params {
  const char *camera_name; /* NULL: the scene's first camera (or a framing camera if none) */
  int width, height;       /* <= 0: scene render settings, else IRIS_EXPORT_DEFAULT_HEIGHT high\n                              and as wide as the camera aspect (as `iris render`) */
  int spp;                 /* 0: scene render settings, then IRIS_EXPORT_DEFAULT_SPP */
  int max_depth;           /* -1: scene render settings, then IRIS_EXPORT_DEFAULT_DEPTH */
  uint64_t seed;
  bool has_seed;           /* false: scene render settings, then 0 */
  bool embed_meshes;       /* blender: mesh data inside the script instead of a sidecar file */
  bool coverage;           /* pov: every object pure white emitter, black background, no lights */
  iris_pov_radiosity pov_radiosity; /* pov: indirect light (default MEDIUM; OFF in coverage mode) */
  bool gltf_principled;    /* blender: gltf materials as a Principled BSDF (the old, approximate
                              mapping; kept for the measurement in docs/export.md) instead of
                              the Appendix B node tree */
} iris_export_params;

#define IRIS_EXPORT_DEFAULT_HEIGHT IRIS_FRAMING_DEFAULT_HEIGHT
#define IRIS_EXPORT_DEFAULT_SPP 64
#define IRIS_EXPORT_DEFAULT_DEPTH 64
/* Vertical field of view of the framing camera used when a scene has none. */
#define IRIS_EXPORT_FRAMING_YFOV IRIS_FRAMING_AUTO_YFOV /* 40 degrees */

iris_export_params iris_export_params_default(void);

/* The concrete view an export renders: an orthonormal camera-to-world matrix
 * (scale removed), the vertical field of view and the image size. */
typedef struct iris_export_view {
  iris_mat4 to_world; /* camera looks along local -Z, +Y up */
  float yfov;
  int width, height;
  int spp;
  int max_depth;
  uint64_t seed;
  int32_t camera; /* index into scene->cameras, -1 for the framing camera */
} iris_export_view;

/* Resolves params against the scene exactly as `iris render` does (camera
 * choice, resolution, automatic framing of camera-less scenes). Fails
 * (IRIS_ERR_USAGE) when camera_name names no camera and (IRIS_ERR_INVALID)
 * when the camera is degenerate. `file` names the scene in messages. */
iris_status iris_export_resolve_view(const iris_scene *scene, const iris_export_params *params,
                                     const char *file, iris_export_view *view, iris_error *err);

/* World-space area of triangle t of mesh m under transform x. */
float iris_export_triangle_area(const iris_mesh *m, uint32_t t, const iris_mat4 *x);

/* True when the material emits (any emission component > 0). */
bool iris_export_material_emits(const iris_scene *scene, int32_t material);

/* In-memory textures (glTF data URIs, GLB buffer views) become files
 * "<stem>.textures/<i>.png|jpg" next to the exported file `out_path`. */
iris_status iris_export_write_textures(const iris_scene *scene, const char *out_path, iris_error *err);
/* The file of texture i as an export refers to it: file textures by their
 * absolute path, in-memory ones by "<stem>.textures/<i>.<ext>", relative to
 * the exported file's folder or (absolute = true) made absolute. Returns false
 * (after a warning) when a file texture does not exist. */
bool iris_export_texture_file(const iris_scene *scene, size_t i, const char *out_path, bool absolute,
                              char *buf, size_t size);

#ifdef __cplusplus
}
#endif
#endif
