// KHR_draco_mesh_compression decoding: a thin C++17 shim over libdraco behind
// importers/draco.h. Judges nothing about the glTF document; the caller checks
// counts and types against its accessors. No exception crosses into C.
#include "importers/draco.h"

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <string>

struct iris_draco_mesh {
  std::unique_ptr<draco::Mesh> mesh;
};

namespace {

template <class T>
bool read_values(const draco::PointAttribute *a, size_t points, int components, void *out) {
  T *dst = static_cast<T *>(out);
  for (size_t i = 0; i < points; i++) {
    const draco::AttributeValueIndex v = a->mapped_index(draco::PointIndex((uint32_t)i));
    if (v.value() >= a->size()) return false;
    if (!a->ConvertValue<T>(v, (int8_t)components, dst + i * (size_t)components)) return false;
  }
  return true;
}

template <class T>
bool read_indices(const draco::Mesh &m, void *out) {
  T *dst = static_cast<T *>(out);
  const uint64_t max = (uint64_t)(T)~(T)0;
  for (uint32_t f = 0; f < m.num_faces(); f++) {
    const draco::Mesh::Face &face = m.face(draco::FaceIndex(f));
    for (int k = 0; k < 3; k++) {
      const uint64_t i = face[k].value();
      if (i > max || i >= m.num_points()) return false;
      dst[3 * (size_t)f + (size_t)k] = (T)i;
    }
  }
  return true;
}

}  // namespace

extern "C" iris_draco_mesh *iris_draco_decode(const uint8_t *data, size_t size, char *msg,
                                              size_t msg_size) {
  try {
    draco::DecoderBuffer buffer;
    buffer.Init(reinterpret_cast<const char *>(data), size);
    auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
    if (!type.ok()) {
      std::snprintf(msg, msg_size, "not Draco data (%s)", type.status().error_msg());
      return nullptr;
    }
    if (type.value() != draco::TRIANGULAR_MESH) {
      std::snprintf(msg, msg_size, "Draco data holds a point cloud, not a triangle mesh");
      return nullptr;
    }
    draco::Decoder decoder;
    auto result = decoder.DecodeMeshFromBuffer(&buffer);
    if (!result.ok()) {
      std::snprintf(msg, msg_size, "Draco decoding failed (%s)", result.status().error_msg());
      return nullptr;
    }
    auto *m = new iris_draco_mesh;
    m->mesh = std::move(result).value();
    if (!m->mesh) {
      delete m;
      std::snprintf(msg, msg_size, "Draco decoding failed");
      return nullptr;
    }
    return m;
  } catch (const std::bad_alloc &) {
    std::snprintf(msg, msg_size, "out of memory decoding Draco data");
  } catch (const std::exception &e) {
    std::snprintf(msg, msg_size, "Draco decoding failed (%s)", e.what());
  } catch (...) {
    std::snprintf(msg, msg_size, "Draco decoding failed");
  }
  return nullptr;
}

extern "C" void iris_draco_destroy(iris_draco_mesh *m) { delete m; }

extern "C" size_t iris_draco_point_count(const iris_draco_mesh *m) { return m->mesh->num_points(); }

extern "C" size_t iris_draco_face_count(const iris_draco_mesh *m) { return m->mesh->num_faces(); }

extern "C" int iris_draco_attribute_components(const iris_draco_mesh *m, int unique_id) {
  if (unique_id < 0) return 0;
  const draco::PointAttribute *a = m->mesh->GetAttributeByUniqueId((uint32_t)unique_id);
  return a ? a->num_components() : 0;
}

extern "C" bool iris_draco_attribute_read(const iris_draco_mesh *m, int unique_id, int component_type,
                                          int components, void *out) {
  if (unique_id < 0 || components < 1 || components > 16) return false;
  const draco::PointAttribute *a = m->mesh->GetAttributeByUniqueId((uint32_t)unique_id);
  if (!a) return false;
  const size_t n = m->mesh->num_points();
  switch (component_type) {
    case 5120: return read_values<int8_t>(a, n, components, out);
    case 5121: return read_values<uint8_t>(a, n, components, out);
    case 5122: return read_values<int16_t>(a, n, components, out);
    case 5123: return read_values<uint16_t>(a, n, components, out);
    case 5125: return read_values<uint32_t>(a, n, components, out);
    case 5126: return read_values<float>(a, n, components, out);
    default: return false;
  }
}

extern "C" bool iris_draco_indices_read(const iris_draco_mesh *m, int component_type, void *out) {
  switch (component_type) {
    case 5121: return read_indices<uint8_t>(*m->mesh, out);
    case 5123: return read_indices<uint16_t>(*m->mesh, out);
    case 5125: return read_indices<uint32_t>(*m->mesh, out);
    default: return false;
  }
}
