// Private to the glTF importer's C++ shim (gltf.cpp): decodes compressed
// geometry in a parsed tinygltf model before it is copied into the plain
// document, so that the converter reads decoded data through ordinary
// accessors and buffer views. KHR_draco_mesh_compression through libdraco
// (importers/draco.h), EXT_meshopt_compression through libmeshoptimizer.
#ifndef IRIS_IMPORTERS_GLTF_COMPRESSED_H
#define IRIS_IMPORTERS_GLTF_COMPRESSED_H

#include <tiny_gltf.h>

extern "C" {
#include "core/error.h"
}

#include <string>
#include <vector>

// Before tinygltf parses: tinygltf 2.7 refuses an indices accessor without a
// bufferView (as Draco primitives' are) and loads every buffer (an
// EXT_meshopt_compression fallback buffer may have no data). When the JSON uses
// either extension, gives such accessors the Draco bufferView as a placeholder
// (listed in *placeholders, all of which must then be decoded) and empties
// fallback buffers. Returns true with the new JSON in *out when it changed.
bool iris_gltf_patch_compressed_json(const char *json, size_t size, std::string *out,
                                     std::vector<int> *placeholders);

// Decoded data may use at most this many bytes per byte of the file's buffers,
// plus IRIS_GLTF_DECODE_SLACK (checked before anything is allocated).
#define IRIS_GLTF_DECODE_RATIO 64
#define IRIS_GLTF_DECODE_SLACK ((size_t)256 << 20)

// Replaces every KHR_draco_mesh_compression primitive's accessors and every
// EXT_meshopt_compression buffer view by decoded data appended to the model's
// buffers. One-line errors name the mesh and primitive or the buffer view.
// `placeholders` from iris_gltf_patch_compressed_json.
iris_status iris_gltf_decode_compressed(tinygltf::Model &m, const std::vector<int> &placeholders,
                                        const char *file, iris_error *err);

#endif
