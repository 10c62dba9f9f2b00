/* `iris validate --blender-import`: where iris's glTF import and Blender's own
 * glTF importer disagree. Blender's script writes what its importer created
 * (exporters/blender.h, --inventory); this compares that with iris's scene:
 * geometry (triangles, bounds in glTF axes), units, cameras, lights (the unit
 * conversion of KHR_lights_punctual) and materials (parameters, and which BSDF
 * each side renders). docs/validation.md lists every check. */
#ifndef IRIS_VALIDATE_IMPORT_COMPARE_H
#define IRIS_VALIDATE_IMPORT_COMPARE_H

#include <stdbool.h>

#include "core/error.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IRIS_IMPORT_NOTES_MAX 48

typedef struct iris_import_note {
  char topic[16];    /* "geometry", "units", "camera", "light", "material" */
  bool geometry;     /* a geometric disagreement: the images cannot be compared */
  char text[300];
} iris_import_note;

typedef struct iris_import_diff {
  int note_count;    /* notes stored (at most IRIS_IMPORT_NOTES_MAX) */
  int total;         /* notes found (may exceed note_count) */
  bool geometry_differs;
  uint64_t iris_triangles, blender_triangles;
  iris_import_note notes[IRIS_IMPORT_NOTES_MAX];
} iris_import_diff;

/* Reads `inventory_path` (JSON written by the Blender script) and compares it
 * with `scene`. Fails only when the file is unreadable or not that JSON. */
iris_status iris_import_compare(const iris_scene *scene, const char *inventory_path,
                                iris_import_diff *out, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
