// Compressed glTF geometry, decoded in the tinygltf model before the plain
// document is made (see gltf_compressed.h): KHR_draco_mesh_compression
// primitives and EXT_meshopt_compression buffer views. Limits are checked
// against the accessors' and views' declared sizes before anything is
// allocated; what was decoded is then checked against what was declared.
#include "importers/gltf_compressed.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

extern "C" {
#include "importers/draco.h"
#include "importers/meshopt.h"
}

namespace {

size_t component_size(int ct) {
  switch (ct) {
    case 5120: case 5121: return 1;
    case 5122: case 5123: return 2;
    case 5125: case 5126: return 4;
    default: return 0;
  }
}

int type_components(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
  }
}

const char *type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    default: return "a matrix type";
  }
}

struct Decoder {
  tinygltf::Model &m;
  const char *file;
  iris_error *err;
  size_t budget_left = 0;
  std::vector<int> accessor_source;  // Draco bufferView an accessor was decoded from, -1 none

  Decoder(tinygltf::Model &model, const char *f, iris_error *e) : m(model), file(f), err(e) {}

  iris_status fail(iris_status st, const std::string &el, const std::string &msg) {
    return iris_error_set(err, st, file, 0, el.c_str(), "%s", msg.c_str());
  }

  // Charges `bytes` (computed in double so no product overflows) to the budget.
  bool charge(double bytes) {
    if (!(bytes <= (double)budget_left)) return false;
    budget_left -= (size_t)bytes;
    return true;
  }

  // A view's bytes, range-checked against its buffer (the converter checks the
  // others later; these are read before it runs).
  bool view_bytes(int view, const uint8_t **data, size_t *size) {
    if (view < 0 || (size_t)view >= m.bufferViews.size()) return false;
    const tinygltf::BufferView &v = m.bufferViews[(size_t)view];
    if (v.buffer < 0 || (size_t)v.buffer >= m.buffers.size()) return false;
    const std::vector<unsigned char> &b = m.buffers[(size_t)v.buffer].data;
    if (v.byteOffset > b.size() || v.byteLength > b.size() - v.byteOffset || v.byteLength == 0) return false;
    *data = b.data() + v.byteOffset;
    *size = v.byteLength;
    return true;
  }

  // Appends a buffer and one tightly packed view over [offset, offset+length).
  int add_view(int buffer, size_t offset, size_t length) {
    tinygltf::BufferView v;
    v.buffer = buffer;
    v.byteOffset = offset;
    v.byteLength = length;
    v.byteStride = 0;
    m.bufferViews.push_back(v);
    return (int)m.bufferViews.size() - 1;
  }

  iris_status draco_primitive(size_t mi, size_t pi);
  iris_status draco_all();
  iris_status meshopt_view(size_t vi);
  iris_status meshopt_all();
};

struct DracoTarget {
  std::string name;  // attribute semantic, or "indices"
  int accessor;
  int id;            // Draco unique id (-1 for indices)
  size_t offset;     // in the decoded buffer
  size_t bytes;
};

iris_status Decoder::draco_primitive(size_t mi, size_t pi) {
  tinygltf::Primitive &p = m.meshes[mi].primitives[pi];
  auto it = p.extensions.find("KHR_draco_mesh_compression");
  if (it == p.extensions.end()) return IRIS_OK;
  const std::string el = "mesh " + std::to_string(mi) + " primitive " + std::to_string(pi);
  const std::string ex = "KHR_draco_mesh_compression: ";
  const tinygltf::Value &e = it->second;
  if (!e.IsObject() || !e.Has("bufferView") || !e.Get("bufferView").IsInt() || !e.Has("attributes") ||
      !e.Get("attributes").IsObject())
    return fail(IRIS_ERR_INVALID, el, ex + "needs an integer bufferView and an attributes object");
  const int view = e.Get("bufferView").GetNumberAsInt();
  const uint8_t *data = nullptr;
  size_t size = 0;
  if (!view_bytes(view, &data, &size))
    return fail(IRIS_ERR_INVALID, el, ex + "bufferView " + std::to_string(view) +
                                          " does not exist or lies outside its buffer");
  if (p.mode != -1 && p.mode != TINYGLTF_MODE_TRIANGLES)
    return fail(IRIS_ERR_UNSUPPORTED, el, ex + "mode " + std::to_string(p.mode) +
                                              " (only TRIANGLES is supported with Draco)");

  // What will be decoded, with the declared sizes, before any allocation.
  std::vector<DracoTarget> targets;
  const tinygltf::Value &attrs = e.Get("attributes");
  for (const std::string &name : attrs.Keys()) {
    const tinygltf::Value &id = attrs.Get(name);
    if (!id.IsInt() || id.GetNumberAsInt() < 0)
      return fail(IRIS_ERR_INVALID, el, ex + "attribute " + name + ": the Draco id is not a non-negative integer");
    auto a = p.attributes.find(name);
    if (a == p.attributes.end())
      return fail(IRIS_ERR_INVALID, el, ex + "attribute " + name + " is not an attribute of the primitive");
    targets.push_back({name, a->second, id.GetNumberAsInt(), 0, 0});
  }
  if (p.indices >= 0) targets.push_back({"indices", p.indices, -1, 0, 0});
  bool all_done = true;
  double need = 0;
  for (DracoTarget &t : targets) {
    if (t.accessor < 0 || (size_t)t.accessor >= m.accessors.size())
      return fail(IRIS_ERR_INVALID, el, ex + t.name + ": accessor " + std::to_string(t.accessor) + " does not exist");
    const tinygltf::Accessor &a = m.accessors[(size_t)t.accessor];
    const size_t cs = component_size(a.componentType), nc = (size_t)type_components(a.type);
    if (!cs || !nc)
      return fail(IRIS_ERR_INVALID, el, ex + t.name + ": accessor " + std::to_string(t.accessor) +
                                            " has an unknown componentType or type");
    if (t.id < 0 && (a.type != TINYGLTF_TYPE_SCALAR || a.componentType == 5126 || a.componentType == 5120 ||
                     a.componentType == 5122))
      return fail(IRIS_ERR_INVALID, el, ex + "indices accessor " + std::to_string(t.accessor) +
                                            " is not an unsigned integer SCALAR");
    need += (double)a.count * (double)(cs * nc) + 4;
    const int src = accessor_source[(size_t)t.accessor];
    if (src == -1) all_done = false;
    else if (src != view)
      return fail(IRIS_ERR_INVALID, el, ex + t.name + ": accessor " + std::to_string(t.accessor) +
                                            " is also decoded from another Draco bufferView");
  }
  if (all_done && !targets.empty()) return IRIS_OK;  // the same data, already decoded for another primitive
  if (!charge(need))
    return fail(IRIS_ERR_NOMEM, el, ex + "the accessors declare " + std::to_string((long long)(need / 1048576.0)) +
                                        " MiB of decoded data, more than the file's size allows");
  int made = -1;
  if (p.indices < 0) {  // Draco meshes are indexed: give the primitive an accessor for them
    tinygltf::Accessor a;
    a.componentType = 5125;
    a.type = TINYGLTF_TYPE_SCALAR;
    a.count = 0;  // set from the decoded faces
    m.accessors.push_back(a);
    accessor_source.push_back(-1);
    p.indices = made = (int)m.accessors.size() - 1;
    targets.push_back({"indices", p.indices, -1, 0, 0});
  }

  char msg[256] = "";
  iris_draco_mesh *dm = iris_draco_decode(data, size, msg, sizeof msg);
  if (!dm) return fail(IRIS_ERR_PARSE, el, ex + "bufferView " + std::to_string(view) + ": " + msg);
  const size_t points = iris_draco_point_count(dm), faces = iris_draco_face_count(dm);
  size_t total = 0;
  iris_status st = IRIS_OK;
  for (DracoTarget &t : targets) {
    tinygltf::Accessor &a = m.accessors[(size_t)t.accessor];
    const int nc = type_components(a.type);
    const std::string acc = "accessor " + std::to_string(t.accessor);
    if (t.id < 0) {
      if (t.accessor == made) a.count = 3 * faces;
      if (a.count != 3 * faces) {
        st = fail(IRIS_ERR_INVALID, el, ex + "indices " + acc + " declares " + std::to_string(a.count) +
                                            " indices but the Draco data decodes to " + std::to_string(faces) +
                                            " triangles");
        break;
      }
    } else {
      const int dc = iris_draco_attribute_components(dm, t.id);
      if (dc == 0) {
        st = fail(IRIS_ERR_INVALID, el, ex + "attribute " + t.name + ": Draco id " + std::to_string(t.id) +
                                            " is not in the compressed data");
        break;
      }
      if (dc != nc) {
        st = fail(IRIS_ERR_INVALID, el, ex + "attribute " + t.name + ": " + acc + " declares " + type_name(a.type) +
                                            " but the Draco attribute has " + std::to_string(dc) + " components");
        break;
      }
      if (a.count != points) {
        st = fail(IRIS_ERR_INVALID, el, ex + "attribute " + t.name + ": " + acc + " declares " +
                                            std::to_string(a.count) + " elements but the Draco data decodes to " +
                                            std::to_string(points) + " points");
        break;
      }
    }
    t.offset = total;
    t.bytes = a.count * component_size(a.componentType) * (size_t)nc;
    total += (t.bytes + 3) & ~(size_t)3;
  }
  if (st == IRIS_OK) {
    tinygltf::Buffer b;
    b.data.resize(total ? total : 4);
    for (const DracoTarget &t : targets) {
      tinygltf::Accessor &a = m.accessors[(size_t)t.accessor];
      bool ok = t.id < 0 ? iris_draco_indices_read(dm, a.componentType, b.data.data() + t.offset)
                         : iris_draco_attribute_read(dm, t.id, a.componentType, type_components(a.type),
                                                     b.data.data() + t.offset);
      if (!ok) {
        st = fail(IRIS_ERR_INVALID, el, ex + t.name + ": the decoded values do not fit accessor " +
                                            std::to_string(t.accessor) + "'s component type");
        break;
      }
    }
    if (st == IRIS_OK) {
      m.buffers.push_back(std::move(b));
      const int buffer = (int)m.buffers.size() - 1;
      for (const DracoTarget &t : targets) {
        tinygltf::Accessor &a = m.accessors[(size_t)t.accessor];
        if (t.bytes == 0) continue;  // no triangles: the converter skips the primitive
        a.bufferView = add_view(buffer, t.offset, t.bytes);
        a.byteOffset = 0;
        accessor_source[(size_t)t.accessor] = view;
      }
    }
  }
  iris_draco_destroy(dm);
  return st;
}

iris_status Decoder::meshopt_view(size_t vi) {
  tinygltf::BufferView &v = m.bufferViews[vi];
  auto it = v.extensions.find("EXT_meshopt_compression");
  if (it == v.extensions.end()) return IRIS_OK;
  const std::string el = "bufferView " + std::to_string(vi);
  const std::string ex = "EXT_meshopt_compression: ";
  const tinygltf::Value &e = it->second;
  auto uint_member = [&](const char *key, bool required, size_t *out) {
    if (!e.Has(key)) return !required;
    const tinygltf::Value &x = e.Get(key);
    if (!x.IsNumber()) return false;
    const double d = x.GetNumberAsDouble();
    if (!(d >= 0 && d <= 9007199254740992.0) || d != (double)(uint64_t)d) return false;
    *out = (size_t)d;
    return true;
  };
  size_t buffer = 0, offset = 0, length = 0, stride = 0, count = 0;
  if (!e.IsObject() || !uint_member("buffer", true, &buffer) || !uint_member("byteOffset", false, &offset) ||
      !uint_member("byteLength", true, &length) || !uint_member("byteStride", true, &stride) ||
      !uint_member("count", true, &count) || !e.Has("mode") || !e.Get("mode").IsString() ||
      (e.Has("filter") && !e.Get("filter").IsString()))
    return fail(IRIS_ERR_INVALID, el, ex + "buffer, byteLength, byteStride, count (non-negative integers) "
                                           "and mode (a string) are required");
  iris_meshopt_mode mode;
  iris_meshopt_filter filter = IRIS_MESHOPT_NONE;
  if (!iris_meshopt_parse_mode(e.Get("mode").Get<std::string>().c_str(), &mode))
    return fail(IRIS_ERR_INVALID, el, ex + "unknown mode '" + e.Get("mode").Get<std::string>() + "'");
  if (e.Has("filter") && !iris_meshopt_parse_filter(e.Get("filter").Get<std::string>().c_str(), &filter))
    return fail(IRIS_ERR_INVALID, el, ex + "unknown filter '" + e.Get("filter").Get<std::string>() + "'");
  if (const char *why = iris_meshopt_check(count, stride, mode, filter)) return fail(IRIS_ERR_INVALID, el, ex + why);
  if (buffer >= m.buffers.size())
    return fail(IRIS_ERR_INVALID, el, ex + "buffer " + std::to_string(buffer) + " does not exist");
  const std::vector<unsigned char> &src = m.buffers[buffer].data;
  if (offset > src.size() || length > src.size() - offset || length == 0)
    return fail(IRIS_ERR_INVALID, el, ex + "byteOffset " + std::to_string(offset) + " + byteLength " +
                                          std::to_string(length) + " exceeds buffer " + std::to_string(buffer) +
                                          "'s " + std::to_string(src.size()) + " bytes");
  const double bytes = (double)count * (double)stride;
  if (bytes != (double)v.byteLength)
    return fail(IRIS_ERR_INVALID, el, ex + "count " + std::to_string(count) + " x byteStride " +
                                          std::to_string(stride) + " is not the bufferView's byteLength " +
                                          std::to_string(v.byteLength));
  if (!charge(bytes))
    return fail(IRIS_ERR_NOMEM, el, ex + "decoding " + std::to_string((long long)(bytes / 1048576.0)) +
                                        " MiB is more than the file's size allows");
  tinygltf::Buffer out;
  out.data.resize(count * stride);
  if (!iris_meshopt_decode(src.data() + offset, length, count, stride, mode, filter, out.data.data()))
    return fail(IRIS_ERR_PARSE, el, ex + "the compressed data is corrupt or truncated");
  m.buffers.push_back(std::move(out));
  v.buffer = (int)m.buffers.size() - 1;
  v.byteOffset = 0;
  return IRIS_OK;
}

iris_status Decoder::meshopt_all() {
  const size_t n = m.bufferViews.size();
  for (size_t i = 0; i < n; i++) {
    iris_status st = meshopt_view(i);
    if (st != IRIS_OK) return st;
  }
  return IRIS_OK;
}

iris_status Decoder::draco_all() {
  accessor_source.assign(m.accessors.size(), -1);
  for (size_t mi = 0; mi < m.meshes.size(); mi++)
    for (size_t pi = 0; pi < m.meshes[mi].primitives.size(); pi++) {
      iris_status st = draco_primitive(mi, pi);
      if (st != IRIS_OK) return st;
    }
  return IRIS_OK;
}

}  // namespace

bool iris_gltf_patch_compressed_json(const char *json, size_t size, std::string *out,
                                     std::vector<int> *placeholders) {
  placeholders->clear();
  const std::string_view text(json, size);  // searched in place: most files use neither
  if (text.find("KHR_draco_mesh_compression") == std::string_view::npos &&
      text.find("EXT_meshopt_compression") == std::string_view::npos)
    return false;
  nlohmann::json j = nlohmann::json::parse(json, json + size, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return false;  // tinygltf reports it
  bool changed = false;
  auto accessors = j.find("accessors");
  auto meshes = j.find("meshes");
  if (accessors != j.end() && accessors->is_array() && meshes != j.end() && meshes->is_array()) {
    for (auto &mesh : *meshes) {
      if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
      for (auto &p : mesh["primitives"]) {
        if (!p.is_object() || !p.contains("extensions") || !p["extensions"].is_object()) continue;
        const auto &ext = p["extensions"];
        auto d = ext.find("KHR_draco_mesh_compression");
        if (d == ext.end() || !d->is_object() || !d->contains("bufferView") ||
            !(*d)["bufferView"].is_number_unsigned())
          continue;
        auto ind = p.find("indices");
        if (ind == p.end() || !ind->is_number_unsigned()) continue;
        const uint64_t i = ind->get<uint64_t>();
        if (i >= accessors->size() || !(*accessors)[i].is_object() || (*accessors)[i].contains("bufferView"))
          continue;
        (*accessors)[i]["bufferView"] = (*d)["bufferView"];
        placeholders->push_back((int)i);
        changed = true;
      }
    }
  }
  // A fallback buffer (EXT_meshopt_compression.fallback) is dropped: iris
  // decodes every compressed view, and only those may use it, so the file
  // imports even when the fallback's .bin is absent (and nothing is read twice).
  auto buffers = j.find("buffers");
  if (buffers != j.end() && buffers->is_array()) {
    for (auto &b : *buffers) {
      if (!b.is_object() || !b.contains("extensions") || !b["extensions"].is_object()) continue;
      auto e = b["extensions"].find("EXT_meshopt_compression");
      if (e == b["extensions"].end() || !e->is_object() || !e->contains("fallback") ||
          !(*e)["fallback"].is_boolean() || !(*e)["fallback"].get<bool>())
        continue;
      b["uri"] = "data:application/octet-stream;base64,AAAAAA==";  // tinygltf refuses empty buffers
      b["byteLength"] = 4;
      changed = true;
    }
  }
  if (changed) *out = j.dump();
  return changed;
}

iris_status iris_gltf_decode_compressed(tinygltf::Model &m, const std::vector<int> &placeholders,
                                        const char *file, iris_error *err) {
  Decoder d(m, file, err);
  d.budget_left = IRIS_GLTF_DECODE_SLACK;
  for (const tinygltf::Buffer &b : m.buffers) {
    const size_t add = b.data.size() > SIZE_MAX / (4 * IRIS_GLTF_DECODE_RATIO)
                           ? SIZE_MAX / 4
                           : b.data.size() * IRIS_GLTF_DECODE_RATIO;
    d.budget_left = d.budget_left > SIZE_MAX / 2 - add ? SIZE_MAX / 2 : d.budget_left + add;
  }
  iris_status st = d.meshopt_all();
  if (st != IRIS_OK) return st;
  st = d.draco_all();
  if (st != IRIS_OK) return st;
  for (int a : placeholders)
    if ((size_t)a < d.accessor_source.size() && d.accessor_source[(size_t)a] == -1)
      return iris_error_set(err, IRIS_ERR_INVALID, file, 0, ("accessor " + std::to_string(a)).c_str(),
                            "has no bufferView and is not decoded by KHR_draco_mesh_compression");
  return IRIS_OK;
}
