/* The validation stage: render a scene with iris (one or more methods), get the
 * Cycles image of the same scene (stored reference, a given EXR, or Blender
 * run on the exported script), compare them with validate/metrics.h and write
 * DIR/report.html, DIR/summary.json and PNGs. Also regenerates the stored
 * references (validate/references/<scene>.exr + .json). docs/validation.md. */
#ifndef IRIS_VALIDATE_VALIDATE_H
#define IRIS_VALIDATE_VALIDATE_H

#include <signal.h>
#include <stdbool.h>
#include <stdint.h>

#include "core/error.h"
#include "core/image.h"
#include "renderer/integrator.h"
#include "scene/scene.h"
#include "validate/import_compare.h"
#include "validate/metrics.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IRIS_VALIDATE_DEFAULT_SPP 64
#define IRIS_VALIDATE_DEFAULT_TOLERANCE 0.01
#define IRIS_VALIDATE_DEFAULT_BLENDER_SPP 1024
/* --blender-import: default energy tolerance, the measured residual of Blender's
 * Principled BSDFs against iris's glTF BRDF on the sample models (docs/validation.md). */
#define IRIS_VALIDATE_IMPORT_TOLERANCE 0.05
/* Cycles runs split into independent batches to estimate the reference's
 * per-pixel variance (validate.c, render_cycles). */
#define IRIS_VALIDATE_BLENDER_BATCHES 8
#define IRIS_VALIDATE_REFRESH_BATCHES 16

/* Scenes with stored references, NULL-terminated: cornell-box, veach-mis, door. */
const char *const *iris_validate_reference_scenes(void);

/* Loads INPUT: an existing file (iris scene or importable) or a built-in scene
 * name; `variant` (NULL: none) is the glTF material variant to apply
 * (IRIS_ERR_USAGE for a built-in scene or a file without it). */
iris_status iris_validate_load_scene(const char *input, const char *camera_name, const char *variant,
                                     iris_scene **out, iris_error *err);

typedef enum iris_reference_source {
  IRIS_REFERENCE_FILE = 0, /* --reference REF.exr (or the stored one of a built-in scene) */
  IRIS_REFERENCE_BLENDER   /* Blender run on the exported script */
} iris_reference_source;

/* A world that replaces the scene's after loading it (the --env flags of
 * bench and validate): a map when `map` is set, else a constant colour when
 * `color` is set; all NULL: the scene's own. */
typedef struct iris_world_override {
  const char *map;
  float strength, rotation;
  const float *color;
} iris_world_override;
/* Applies the override; false when out of memory. */
bool iris_world_override_apply(const iris_world_override *w, iris_scene *scene);

typedef struct iris_validate_params {
  const char *input;
  iris_world_override world; /* zeroed: the scene's world */
  iris_method methods[IRIS_METHOD_COUNT];
  int method_count;         /* 0: mis */
  iris_sampler_kind sampler; /* iris's sampler (default sobol) */
  iris_light_sampler light_sampler; /* NEE's light choice (default IRIS_LIGHT_SAMPLER_DEFAULT) */
  int connect;                      /* iris_render_params.connect (--connect) */
  int light_trace; /* iris_render_params.light_trace (--light-trace) */
  int spp;                  /* iris samples per pixel (0: IRIS_VALIDATE_DEFAULT_SPP) */
  uint64_t seed;
  int threads;              /* <= 0: all cores (iris and Blender) */
  int width, height;        /* <= 0: the reference's size (file) or the scene's (Blender) */
  int max_depth;            /* < 0: the scene's, else 64 */
  const char *camera_name;
  const char *variant;      /* glTF material variant applied on import (NULL: the defaults); with
                               blender_import, Blender's importer is made to show it too */
  iris_reference_source source;
  const char *reference_path; /* IRIS_REFERENCE_FILE */
  int blender_spp;          /* IRIS_REFERENCE_BLENDER (0: default) */
  const char *blender;      /* executable (NULL: $IRIS_BLENDER, else "blender") */
  const char *blender_import; /* IRIS_REFERENCE_BLENDER: a .gltf/.glb that Blender imports with its
                               own importer instead of iris's export (NULL: the export) */
  double tolerance;         /* allowed |energy ratio - 1| per channel and overall */
  double alpha;             /* family-wise significance of the z-tests */
  bool pixel_test_gates;    /* the per-pixel z-test fails the run too (default: reported only;
                               the block z-test always gates) */
  const char *out_dir;
  bool quiet;
  volatile sig_atomic_t *cancel;
} iris_validate_params;

iris_validate_params iris_validate_params_default(void);

/* Everything known about the reference image. */
typedef struct iris_validate_reference {
  char path[1024];
  char description[256];    /* e.g. "Cycles 3.4.1, 2048 spp (stored reference)" */
  int spp;                  /* 0: unknown */
  int width, height;
  double mean[3];
  double mean_se[3];        /* standard error of mean[] (0 without variance channels) */
  uint64_t nan_count, inf_count;
  bool has_variance;        /* var.R/G/B channels */
  double seconds;           /* Blender render time when run here, else from provenance */
} iris_validate_reference;

typedef struct iris_validate_method {
  iris_method method;       /* as requested (flag, scene, else auto): names the files */
  iris_method resolved;     /* what the paths used (auto's choice) */
  char method_reason[240];  /* auto: "auto: mis (...)"; else "" */
  int spp;
  double seconds;
  double mean[3];
  double mean_se[3];        /* standard error of iris's mean per channel */
  double channel_ratio[3];  /* iris / reference per channel */
  double ratio_se[3];       /* standard error of channel_ratio from both images' noise */
  double energy_ratio;      /* summed channels */
  uint64_t nan_count, inf_count;
  uint64_t dropped_samples; /* non-finite samples the renderer dropped */
  double relmse, mape;
  iris_block_stats blocks;
  iris_pixel_ztest pixels;
  char ref_variance[256];   /* how the reference variance was obtained */
  bool energy_passed, z_passed, passed;
} iris_validate_method;

typedef struct iris_validate_result {
  char scene[256];
  int width, height;
  int max_depth;
  iris_validate_reference reference;
  iris_validate_method methods[IRIS_METHOD_COUNT];
  int method_count;
  bool export_exact;        /* IRIS_REFERENCE_BLENDER via the export: every material is one Cycles
                               reproduces exactly (diffuse, glossy, glass, smooth or Lambert gltf) */
  double export_residual;   /* largest expected |iris / Cycles - 1| of a material's furnace mean */
  char export_note[360];    /* otherwise which materials are approximate and the expected residual */
  bool blender_import;      /* the reference came from Blender's own glTF importer */
  char import_file[1024];
  iris_import_diff import_diff; /* where the two importers disagree (geometry fails the run) */
  bool passed;
} iris_validate_result;

/* Runs the whole validation and writes the outputs into params->out_dir.
 * Returns IRIS_OK when the comparison was made (passed or not: see
 * result->passed); an error (IRIS_ERR_INVALID/IO/USAGE...) when it could not be
 * made: missing or unreadable reference, non-finite reference values,
 * different sizes, Blender failing. */
iris_status iris_validate_run(const iris_validate_params *params, iris_validate_result *result,
                              iris_error *err);

/* --refresh: renders `scene` (one of iris_validate_reference_scenes) with
 * Blender at its reference size and writes <dir>/<scene>.exr (float RGB, ZIP,
 * with iris:* metadata) and <dir>/<scene>.json (provenance). spp 0: the
 * scene's default reference spp. */
typedef struct iris_refresh_params {
  const char *scene;
  const char *dir;
  int spp;
  uint64_t seed;
  int threads;
  const char *blender;
  bool quiet;
} iris_refresh_params;
iris_status iris_validate_refresh(const iris_refresh_params *params, iris_error *err);

/* Reference size and spp of a stored-reference scene (false for other names). */
bool iris_validate_reference_settings(const char *scene, int *width, int *height, int *spp);

#ifdef __cplusplus
}
#endif
#endif
