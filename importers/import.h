/* Importers: turn OBJ(+MTL), PLY and glTF 2.0 files into an iris_scene.
 * iris_import_file picks the importer from the file extension. Every importer
 * parses leniently, then validates strictly; errors name the file and the line
 * or element; present-but-ignored features produce one warning. */
#ifndef IRIS_IMPORTERS_IMPORT_H
#define IRIS_IMPORTERS_IMPORT_H

#include <stdbool.h>
#include <stdint.h>

#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Work counters of an import, for the tests and benchmarks that check that
 * the work grows no faster than the input (docs/fuzzing.md). Added to, not reset. */
typedef struct iris_import_stats {
  uint64_t polygons;                /* faces of 4 or more corners triangulated */
  uint64_t polygon_corners;         /* their corners, summed */
  uint64_t triangulation_steps;     /* triangulation work (importers/triangulate.h) */
  uint64_t triangulation_fallbacks; /* polygons whose work budget ran out (partly fanned) */
} iris_import_stats;

typedef struct iris_import_options {
  const char *camera_name;  /* glTF: pick this camera (default: the first one) */
  const char *variant;      /* glTF: apply this KHR_materials_variants variant (default: none, the
                               default materials); IRIS_ERR_USAGE for other inputs or an unknown name */
  bool weld;                /* weld coincident vertices (OpenMesh) */
  bool compute_normals;     /* OBJ, PLY: angle-weighted normals where absent (default true);
                               glTF is always shaded flat where NORMAL is absent (its spec) */
  bool keep_materials;      /* keep glTF materials that are exactly Lambert as gltf (default:
                               they become diffuse, scene/material_class.h) */
  iris_import_stats *stats; /* optional (default NULL): work counters are added here */
} iris_import_options;

iris_import_options iris_import_options_default(void);

/* Dispatches on the extension (.obj, .ply, .gltf, .glb, .json = iris scene). */
iris_status iris_import_file(const char *path, const iris_import_options *opts, iris_scene **out,
                             iris_error *err);

iris_status iris_import_obj(const char *path, const iris_import_options *opts, iris_scene **out,
                            iris_error *err);
iris_status iris_import_ply(const char *path, const iris_import_options *opts, iris_scene **out,
                            iris_error *err);
iris_status iris_import_gltf(const char *path, const iris_import_options *opts, iris_scene **out,
                             iris_error *err);

/* Parsing straight from memory (used by the fuzzers; `path` is for messages and
 * for resolving relative references, which fuzzers disable by passing NULL). */
iris_status iris_import_obj_memory(const char *data, size_t size, const char *path,
                                   const iris_import_options *opts, iris_scene **out, iris_error *err);
iris_status iris_import_ply_memory(const char *data, size_t size, const char *path,
                                   const iris_import_options *opts, iris_scene **out, iris_error *err);
iris_status iris_import_gltf_memory(const char *data, size_t size, const char *path,
                                    const iris_import_options *opts, iris_scene **out, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
