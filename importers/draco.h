/* Draco mesh decoding (KHR_draco_mesh_compression) behind a C interface: a
 * thin C++17 shim over Debian's libdraco 1.5 (importers/draco.cpp). Decodes
 * one compressed buffer view into points, triangles and attributes addressed
 * by their Draco unique ids, converted to the glTF component type asked for. */
#ifndef IRIS_IMPORTERS_DRACO_H
#define IRIS_IMPORTERS_DRACO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct iris_draco_mesh iris_draco_mesh;

/* Decodes `size` bytes. Returns NULL on failure with a one-line reason in
 * msg (Draco's own message, or "out of memory"). */
iris_draco_mesh *iris_draco_decode(const uint8_t *data, size_t size, char *msg, size_t msg_size);
void iris_draco_destroy(iris_draco_mesh *m);

size_t iris_draco_point_count(const iris_draco_mesh *m);
size_t iris_draco_face_count(const iris_draco_mesh *m); /* triangles */

/* Components of the attribute with this unique id, 0 when there is none. */
int iris_draco_attribute_components(const iris_draco_mesh *m, int unique_id);

/* Writes point_count elements of `components` values of glTF component type
 * `component_type` (5120..5126) for the attribute, point by point. False when
 * a value cannot be converted. */
bool iris_draco_attribute_read(const iris_draco_mesh *m, int unique_id, int component_type,
                               int components, void *out);

/* Writes 3 * face_count indices as glTF component type 5121, 5123 or 5125.
 * False when an index does not fit the type. */
bool iris_draco_indices_read(const iris_draco_mesh *m, int component_type, void *out);

#ifdef __cplusplus
}
#endif
#endif
