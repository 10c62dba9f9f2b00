/* The importer dispatcher: picks an importer from the file extension. The
 * importers themselves live in obj.c, ply.c and gltf.cpp. */
#include "importers/import.h"

#include <string.h>

#include "core/cancel.h"
#include "core/fileio.h"
#include "scene/material_class.h"

iris_import_options iris_import_options_default(void) {
  iris_import_options o;
  memset(&o, 0, sizeof o);
  o.camera_name = NULL;
  o.weld = false;
  o.compute_normals = true;
  return o;
}

typedef iris_status (*importer_fn)(const char *, const iris_import_options *, iris_scene **,
                                   iris_error *);

iris_status iris_import_file(const char *path, const iris_import_options *opts, iris_scene **out,
                             iris_error *err) {
  *out = NULL;
  iris_import_options defaults = iris_import_options_default();
  if (!opts) opts = &defaults;
  char ext[16];
  iris_path_ext(path, ext, sizeof ext);
  bool gltf = strcmp(ext, "gltf") == 0 || strcmp(ext, "glb") == 0;
  if (opts->variant && !gltf)
    return iris_error_set(err, IRIS_ERR_USAGE, path, 0, NULL,
                          "no material variant \"%s\": material variants (KHR_materials_variants) come from "
                          "glTF files only%s", opts->variant,
                          strcmp(ext, "json") == 0 ? "; an iris scene keeps the variant it was imported with" : "");
  if (strcmp(ext, "json") == 0) return iris_scene_load(path, out, err);
  importer_fn fn = NULL;
  if (strcmp(ext, "obj") == 0)
    fn = iris_import_obj;
  else if (strcmp(ext, "ply") == 0)
    fn = iris_import_ply;
  else if (gltf)
    fn = iris_import_gltf;
  else
    return iris_error_set(err, IRIS_ERR_UNSUPPORTED, path, 0, NULL,
                          "unknown file type '%s%s' (iris reads .obj, .ply, .gltf, .glb and iris "
                          "scene .json files)",
                          ext[0] ? "." : "", ext[0] ? ext : "no extension");
  iris_status st = fn(path, opts, out, err);
  if (st != IRIS_OK) return st;
  if (iris_cancel_requested()) { /* Ctrl-C after the last check inside the importer */
    iris_scene_destroy(*out);
    *out = NULL;
    return iris_error_set(err, IRIS_ERR_INTERRUPTED, path, 0, NULL, "interrupted while loading the scene");
  }
  /* Every importer validates its result; checking again here costs one pass
   * and guarantees the renderer's invariants whatever the importer. */
  if (!(*out)->source_path) (*out)->source_path = iris_strdup(path);
  /* A glTF material that is exactly a Lambert becomes `diffuse` (docs/import-gltf.md). */
  if (!opts->keep_materials)
    for (size_t i = 0; i < (*out)->material_count; i++) iris_material_canonicalize(&(*out)->materials[i]);
  st = iris_scene_validate(*out, path, err);
  if (st != IRIS_OK) {
    iris_scene_destroy(*out);
    *out = NULL;
  }
  return st;
}
