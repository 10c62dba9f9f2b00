// glTF 2.0 import, C++ side: parse with Debian's tinygltf 2.7 and copy its
// model into the plain iris_gltf_doc (gltf_convert.h) that gltf_convert.c
// validates and turns into an iris_scene. Nothing here judges the data; this
// file only talks to tinygltf (file access, image bytes kept encoded, errors
// condensed to one line) and never lets an exception cross into C.
#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <sys/stat.h>

#include <climits>
#include <cstdio>
#include <cmath>
#include <cstring>
#include <deque>
#include <new>
#include <string>
#include <vector>

extern "C" {
#include "core/fileio.h"
#include "core/log.h"
#include "importers/gltf_convert.h"
#include "importers/import.h"
}
#include "importers/gltf_compressed.h"

namespace {

// File access for tinygltf: external files only when the caller gave a path,
// no `~`/wordexp expansion of names taken from the file, and a size cap.
struct FsContext {
  bool allow_external;
};

bool fs_exists(const std::string &name, void *user) {
  const FsContext *ctx = static_cast<const FsContext *>(user);
  if (!ctx->allow_external) return false;
  struct stat st;
  return stat(name.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::string fs_expand(const std::string &name, void *) { return name; }

bool fs_read(std::vector<unsigned char> *out, std::string *err, const std::string &name,
             void *user) {
  const FsContext *ctx = static_cast<const FsContext *>(user);
  if (!ctx->allow_external) {
    if (err) *err += "external files are disabled: " + name + "\n";
    return false;
  }
  // tinygltf passes sizes as int: refuse what it cannot address.
  char *data = nullptr;
  size_t size = 0;
  iris_error e;
  iris_error_clear(&e);
  if (iris_file_read(name.c_str(), (size_t)INT_MAX, &data, &size, &e) != IRIS_OK) {
    if (err) *err += std::string("cannot read ") + name + ": " + e.message + "\n";
    return false;
  }
  try {
    out->assign(reinterpret_cast<unsigned char *>(data),
                reinterpret_cast<unsigned char *>(data) + size);
  } catch (...) {
    free(data);
    throw;
  }
  free(data);
  return true;
}

bool fs_write(std::string *err, const std::string &, const std::vector<unsigned char> &, void *) {
  if (err) *err += "writing is not supported\n";
  return false;
}

// Image callback: keep the encoded bytes instead of decoding pixels. Data-URI
// images are the only ones whose bytes exist nowhere else, so only those are
// stored; bufferView images are read by the converter from the buffer view,
// external ones are referenced by path.
struct ImageState {
  bool called = false;
  char mime[16] = {0};
};

void sniff_mime(const unsigned char *b, int n, char out[16]) {
  out[0] = '\0';
  if (n >= 8 && std::memcmp(b, "\x89PNG\r\n\x1a\n", 8) == 0)
    std::snprintf(out, 16, "image/png");
  else if (n >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF)
    std::snprintf(out, 16, "image/jpeg");
  else if (n >= 12 && std::memcmp(b, "RIFF", 4) == 0 && std::memcmp(b + 8, "WEBP", 4) == 0)
    std::snprintf(out, 16, "image/webp");
}

bool keep_encoded_image(tinygltf::Image *image, const int index, std::string *, std::string *,
                        int, int, const unsigned char *bytes, int size, void *user) {
  auto *states = static_cast<std::vector<ImageState> *>(user);
  if (index < 0) return true;
  if ((size_t)index >= states->size()) states->resize((size_t)index + 1);
  ImageState &st = (*states)[(size_t)index];
  st.called = true;
  if (image->bufferView >= 0) return true;  // converter reads the buffer view
  sniff_mime(bytes, size, st.mime);
  if (image->uri.empty() && size > 0) image->image.assign(bytes, bytes + size);  // data URI
  return true;
}

// tinygltf's messages are multi-line; iris errors are one line.
std::string one_line(const std::string &s) {
  std::string r;
  for (char c : s) {
    if (c == '\n' || c == '\r') {
      if (!r.empty() && r.back() != ' ' && r.compare(r.size() - 1, 1, ";") != 0) r += "; ";
    } else {
      r += c;
    }
  }
  while (!r.empty() && (r.back() == ' ' || r.back() == ';')) r.pop_back();
  return r;
}

// Reads a number member of a JSON object held as tinygltf::Value. Returns
// false when present with a non-numeric type.
bool get_number(const tinygltf::Value &obj, const char *key, double *out, bool *present) {
  if (!obj.IsObject() || !obj.Has(key)) return true;
  const tinygltf::Value &v = obj.Get(key);
  if (!v.IsNumber()) return false;
  *out = v.GetNumberAsDouble();
  if (present) *present = true;
  return true;
}

// Everything the plain document points into.
struct DocStorage {
  std::vector<iris_gltf_buffer> buffers;
  std::vector<iris_gltf_view> views;
  std::vector<iris_gltf_accessor> accessors;
  std::vector<std::vector<iris_gltf_attribute>> attributes;
  std::vector<std::vector<iris_gltf_primitive>> primitives;
  std::vector<iris_gltf_mesh> meshes;
  std::vector<iris_gltf_node> nodes;
  std::vector<iris_gltf_material> materials;
  std::vector<iris_gltf_texture> textures;
  std::vector<iris_gltf_image> images;
  std::vector<iris_gltf_sampler> samplers;
  std::vector<iris_gltf_camera> cameras;
  std::vector<iris_gltf_light> lights;
  std::vector<iris_gltf_scene> scenes;
  std::vector<const char *> used, required;
  // KHR_materials_variants (deques: elements never move, the document points into them)
  std::deque<std::vector<iris_gltf_variant_mapping>> mappings;
  std::deque<std::vector<int>> mapping_variants;
  std::deque<std::string> variant_name_storage;
  std::vector<bool> variant_named;
  std::vector<const char *> variant_names;
};

// KHR_materials_variants is read from the original JSON of the extensions
// (SetStoreOriginalJSONForExtrasAndExtensions), not from tinygltf's Value:
// that drops nulls, empty objects and empty arrays from arrays, which would
// renumber variants and mappings ("[{"name":"a"}, {}, ...]") instead of
// being refused. nlohmann::json is what tinygltf parses with.
const nlohmann::json *variants_ext(const std::string &extensions_json, nlohmann::json *storage) {
  if (extensions_json.empty()) return nullptr;
  *storage = nlohmann::json::parse(extensions_json, nullptr, false);
  if (!storage->is_object()) return nullptr;
  auto it = storage->find("KHR_materials_variants");
  return it == storage->end() ? nullptr : &*it;
}

// A JSON integer as int (values beyond int are clamped, to be reported out of
// range); false when not an integral number.
bool int_value(const nlohmann::json &v, int *out) {
  if (!v.is_number()) return false;
  double d = v.get<double>();
  if (!std::isfinite(d) || d != std::floor(d)) return false;
  *out = d > INT_MAX ? INT_MAX : d < -INT_MAX ? -INT_MAX : (int)d;
  return true;
}

// A primitive's KHR_materials_variants mappings, copied without judging the
// indices (the converter validates them, gltf_variants.c).
void fill_mappings(const tinygltf::Primitive &p, DocStorage &s, iris_gltf_primitive *o) {
  o->mappings = nullptr;
  o->mapping_count = 0;
  o->variants_bad = nullptr;
  nlohmann::json ext;
  const nlohmann::json *v = variants_ext(p.extensions_json_string, &ext);
  if (!v) return;
  if (!v->is_object() || !v->contains("mappings") || !(*v)["mappings"].is_array() || (*v)["mappings"].empty()) {
    o->variants_bad = "is not an object with a non-empty \"mappings\" array";
    return;
  }
  const nlohmann::json &a = (*v)["mappings"];
  s.mappings.emplace_back(a.size());
  std::vector<iris_gltf_variant_mapping> &ms = s.mappings.back();
  for (size_t k = 0; k < a.size(); k++) {
    const nlohmann::json &m = a[k];
    iris_gltf_variant_mapping &om = ms[k];
    om = {-1, nullptr, 0, nullptr};
    if (!m.is_object()) {
      om.bad = "is not an object";
      continue;
    }
    if (!m.contains("material") || !int_value(m["material"], &om.material))
      om.bad = "\"material\" is missing or not an integer";
    else if (m.contains("name") && !m["name"].is_string())
      om.bad = "\"name\" is not a string";
    else if (!m.contains("variants") || !m["variants"].is_array() || m["variants"].empty())
      om.bad = "\"variants\" is missing or not a non-empty array";
    if (om.bad) continue;
    const nlohmann::json &vs = m["variants"];
    s.mapping_variants.emplace_back(vs.size());
    std::vector<int> &ids = s.mapping_variants.back();
    for (size_t j = 0; j < vs.size() && !om.bad; j++)
      if (!int_value(vs[j], &ids[j])) om.bad = "\"variants\" holds a value that is not an integer";
    om.variants = ids.data();
    om.variant_count = ids.size();
  }
  o->mappings = ms.data();
  o->mapping_count = ms.size();
}

// The root KHR_materials_variants: the variant names (NULL: not a string).
void fill_variants(const tinygltf::Model &m, DocStorage &s, iris_gltf_doc *d) {
  d->variant_names = nullptr;
  d->variant_count = 0;
  d->variants_bad = nullptr;
  nlohmann::json ext;
  const nlohmann::json *v = variants_ext(m.extensions_json_string, &ext);
  if (!v) return;
  if (!v->is_object() || !v->contains("variants") || !(*v)["variants"].is_array() || (*v)["variants"].empty()) {
    d->variants_bad = "is not an object with a non-empty \"variants\" array";
    return;
  }
  for (const nlohmann::json &e : (*v)["variants"]) {
    bool named = e.is_object() && e.contains("name") && e["name"].is_string();
    s.variant_name_storage.push_back(named ? e["name"].get<std::string>() : std::string());
    s.variant_named.push_back(named);
  }
  for (size_t k = 0; k < s.variant_named.size(); k++)
    s.variant_names.push_back(s.variant_named[k] ? s.variant_name_storage[k].c_str() : nullptr);
  d->variant_names = s.variant_names.data();
  d->variant_count = s.variant_names.size();
}

// textureInfo (any of tinygltf's three kinds) with its KHR_texture_transform.
template <class Info>
iris_gltf_texture_ref texture_ref(const Info &t, double scale) {
  iris_gltf_texture_ref r;
  std::memset(&r, 0, sizeof r);
  r.texture = t.index;
  r.texcoord = t.texCoord;
  r.scale = scale;
  r.tscale[0] = r.tscale[1] = 1.0;
  r.transform_texcoord = -1;
  auto it = t.extensions.find("KHR_texture_transform");
  if (it == t.extensions.end()) return r;
  const tinygltf::Value &v = it->second;
  r.has_transform = true;
  if (!v.IsObject()) {
    r.bad_transform = true;
    return r;
  }
  auto vec2 = [&](const char *key, double *out) {
    if (!v.Has(key)) return;
    const tinygltf::Value &a = v.Get(key);
    if (!a.IsArray() || a.ArrayLen() != 2 || !a.Get(0).IsNumber() || !a.Get(1).IsNumber()) {
      r.bad_transform = true;
      return;
    }
    out[0] = a.Get(0).GetNumberAsDouble();
    out[1] = a.Get(1).GetNumberAsDouble();
  };
  vec2("offset", r.offset);
  vec2("scale", r.tscale);
  if (!get_number(v, "rotation", &r.rotation, nullptr)) r.bad_transform = true;
  double tc = -1;
  if (!get_number(v, "texCoord", &tc, nullptr) || (tc != -1 && (tc < 0 || tc != (double)(int)tc)))
    r.bad_transform = true;
  else
    r.transform_texcoord = (int)tc;
  return r;
}

// A textureInfo given as a JSON value inside an extension (index, texCoord,
// scale, KHR_texture_transform); false when present with wrong types.
bool texture_ref_value(const tinygltf::Value &ext, const char *key, iris_gltf_texture_ref *r) {
  tinygltf::TextureInfo none;
  *r = texture_ref(none, 1.0);
  if (!ext.IsObject() || !ext.Has(key)) return true;
  const tinygltf::Value &t = ext.Get(key);
  if (!t.IsObject() || !t.Has("index") || !t.Get("index").IsInt()) return false;
  r->texture = t.Get("index").GetNumberAsInt();
  if (t.Has("texCoord")) {
    if (!t.Get("texCoord").IsInt()) return false;
    r->texcoord = t.Get("texCoord").GetNumberAsInt();
  }
  if (!get_number(t, "scale", &r->scale, nullptr)) return false;
  if (t.Has("extensions") && t.Get("extensions").IsObject() && t.Get("extensions").Has("KHR_texture_transform")) {
    tinygltf::TextureInfo info;
    info.index = r->texture;
    info.texCoord = r->texcoord;
    info.extensions["KHR_texture_transform"] = t.Get("extensions").Get("KHR_texture_transform");
    double scale = r->scale;
    *r = texture_ref(info, scale);
  }
  return true;
}

void fill_material(const tinygltf::Material &m, iris_gltf_material *o) {
  std::memset(o, 0, sizeof *o);
  o->name = m.name.c_str();
  o->base_color = m.pbrMetallicRoughness.baseColorFactor.data();
  o->base_color_len = m.pbrMetallicRoughness.baseColorFactor.size();
  o->base_color_texture = texture_ref(m.pbrMetallicRoughness.baseColorTexture, 1.0);
  o->metallic = m.pbrMetallicRoughness.metallicFactor;
  o->roughness = m.pbrMetallicRoughness.roughnessFactor;
  o->metallic_roughness_texture = texture_ref(m.pbrMetallicRoughness.metallicRoughnessTexture, 1.0);
  o->emissive = m.emissiveFactor.data();
  o->emissive_len = m.emissiveFactor.size();
  o->emissive_texture = texture_ref(m.emissiveTexture, 1.0);
  o->double_sided = m.doubleSided;
  o->alpha_mode = m.alphaMode.c_str();
  o->alpha_cutoff = m.alphaCutoff;
  o->normal_texture = texture_ref(m.normalTexture, m.normalTexture.scale);
  o->has_occlusion_texture = m.occlusionTexture.index >= 0;
  o->emissive_strength = 1.0;
  o->specular = 1.0;
  o->specular_color[0] = o->specular_color[1] = o->specular_color[2] = 1.0;
  o->ior = 1.5;
  o->specular_texture = o->specular_color_texture = o->transmission_texture =
      texture_ref(tinygltf::TextureInfo(), 1.0);

  auto ext = [&](const char *name) -> const tinygltf::Value * {
    auto it = m.extensions.find(name);
    return it == m.extensions.end() ? nullptr : &it->second;
  };
  if (const tinygltf::Value *v = ext("KHR_materials_emissive_strength")) {
    if (!get_number(*v, "emissiveStrength", &o->emissive_strength, nullptr))
      o->bad_extension = "KHR_materials_emissive_strength";
    o->has_emissive_strength = true;
  }
  if (const tinygltf::Value *v = ext("KHR_materials_specular")) {
    o->has_specular = true;
    if (!get_number(*v, "specularFactor", &o->specular, nullptr))
      o->bad_extension = "KHR_materials_specular";
    if (v->IsObject() && v->Has("specularColorFactor")) {
      const tinygltf::Value &c = v->Get("specularColorFactor");
      if (!c.IsArray() || c.ArrayLen() != 3) {
        o->bad_extension = "KHR_materials_specular";
      } else {
        for (int i = 0; i < 3; i++) {
          if (!c.Get(i).IsNumber()) o->bad_extension = "KHR_materials_specular";
          else o->specular_color[i] = c.Get(i).GetNumberAsDouble();
        }
      }
    }
    if (!texture_ref_value(*v, "specularTexture", &o->specular_texture) ||
        !texture_ref_value(*v, "specularColorTexture", &o->specular_color_texture))
      o->bad_extension = "KHR_materials_specular";
  }
  if (const tinygltf::Value *v = ext("KHR_materials_transmission")) {
    o->has_transmission = true;
    if (!get_number(*v, "transmissionFactor", &o->transmission, nullptr))
      o->bad_extension = "KHR_materials_transmission";
    if (!texture_ref_value(*v, "transmissionTexture", &o->transmission_texture))
      o->bad_extension = "KHR_materials_transmission";
  }
  if (ext("KHR_materials_unlit")) o->unlit = true;
  if (const tinygltf::Value *v = ext("KHR_materials_ior")) {
    o->has_ior = true;
    if (!get_number(*v, "ior", &o->ior, nullptr)) o->bad_extension = "KHR_materials_ior";
  }
  {
    tinygltf::TextureInfo none;
    o->clearcoat_texture = o->clearcoat_roughness_texture = o->clearcoat_normal_texture =
        o->sheen_color_texture = o->sheen_roughness_texture = o->anisotropy_texture = texture_ref(none, 1.0);
  }
  if (const tinygltf::Value *v = ext("KHR_materials_clearcoat")) {
    o->has_clearcoat = true;
    if (!get_number(*v, "clearcoatFactor", &o->clearcoat, nullptr) ||
        !get_number(*v, "clearcoatRoughnessFactor", &o->clearcoat_roughness, nullptr) ||
        !texture_ref_value(*v, "clearcoatTexture", &o->clearcoat_texture) ||
        !texture_ref_value(*v, "clearcoatRoughnessTexture", &o->clearcoat_roughness_texture) ||
        !texture_ref_value(*v, "clearcoatNormalTexture", &o->clearcoat_normal_texture))
      o->bad_extension = "KHR_materials_clearcoat";
  }
  o->attenuation_color[0] = o->attenuation_color[1] = o->attenuation_color[2] = 1.0;
  if (const tinygltf::Value *v = ext("KHR_materials_volume")) {
    o->has_volume = true;
    if (!get_number(*v, "attenuationDistance", &o->attenuation_distance, &o->has_attenuation_distance))
      o->bad_extension = "KHR_materials_volume";
    if (v->IsObject() && v->Has("attenuationColor")) {
      const tinygltf::Value &c = v->Get("attenuationColor");
      if (!c.IsArray() || c.ArrayLen() != 3) {
        o->bad_extension = "KHR_materials_volume";
      } else {
        for (int i = 0; i < 3; i++) {
          if (!c.Get(i).IsNumber()) o->bad_extension = "KHR_materials_volume";
          else o->attenuation_color[i] = c.Get(i).GetNumberAsDouble();
        }
      }
    }
  }
  if (const tinygltf::Value *v = ext("KHR_materials_sheen")) {
    o->has_sheen = true;
    if (v->IsObject() && v->Has("sheenColorFactor")) {
      const tinygltf::Value &c = v->Get("sheenColorFactor");
      if (!c.IsArray() || c.ArrayLen() != 3) {
        o->bad_extension = "KHR_materials_sheen";
      } else {
        for (int i = 0; i < 3; i++) {
          if (!c.Get(i).IsNumber()) o->bad_extension = "KHR_materials_sheen";
          else o->sheen_color[i] = c.Get(i).GetNumberAsDouble();
        }
      }
    }
    if (!get_number(*v, "sheenRoughnessFactor", &o->sheen_roughness, nullptr) ||
        !texture_ref_value(*v, "sheenColorTexture", &o->sheen_color_texture) ||
        !texture_ref_value(*v, "sheenRoughnessTexture", &o->sheen_roughness_texture))
      o->bad_extension = "KHR_materials_sheen";
  }
  if (const tinygltf::Value *v = ext("KHR_materials_anisotropy")) {
    o->has_anisotropy = true;
    if (!get_number(*v, "anisotropyStrength", &o->anisotropy_strength, nullptr) ||
        !get_number(*v, "anisotropyRotation", &o->anisotropy_rotation, nullptr) ||
        !texture_ref_value(*v, "anisotropyTexture", &o->anisotropy_texture))
      o->bad_extension = "KHR_materials_anisotropy";
  }
  if (ext("KHR_materials_dispersion")) o->has_dispersion = true;
}

void fill_doc(const tinygltf::Model &m, const std::vector<ImageState> &image_states,
              DocStorage &s, iris_gltf_doc *d) {
  for (const auto &b : m.buffers) s.buffers.push_back({b.data.data(), b.data.size()});
  for (const auto &v : m.bufferViews) {
    iris_gltf_view o;
    o.buffer = v.buffer;
    o.offset = v.byteOffset;
    o.length = v.byteLength;
    o.stride = v.byteStride;
    s.views.push_back(o);
  }
  for (const auto &a : m.accessors) {
    iris_gltf_accessor o;
    std::memset(&o, 0, sizeof o);
    o.view = a.bufferView;
    o.offset = a.byteOffset;
    o.component_type = a.componentType;
    o.type = a.type;
    o.normalized = a.normalized;
    o.count = a.count;
    o.sparse = a.sparse.isSparse;
    if (o.sparse) {
      o.sparse_count = a.sparse.count;
      o.sparse_index_view = a.sparse.indices.bufferView;
      o.sparse_index_type = a.sparse.indices.componentType;
      o.sparse_index_offset = a.sparse.indices.byteOffset;
      o.sparse_value_view = a.sparse.values.bufferView;
      o.sparse_value_offset = a.sparse.values.byteOffset;
    }
    s.accessors.push_back(o);
  }
  s.attributes.resize(m.meshes.size());
  s.primitives.resize(m.meshes.size());
  for (size_t i = 0; i < m.meshes.size(); i++) {
    const auto &mesh = m.meshes[i];
    size_t total = 0;
    for (const auto &p : mesh.primitives) total += p.attributes.size();
    s.attributes[i].reserve(total);  // pointers into it stay valid
    for (const auto &p : mesh.primitives) {
      iris_gltf_primitive o;
      o.mode = p.mode;
      o.indices = p.indices;
      o.material = p.material;
      o.attribute_count = p.attributes.size();
      o.attributes = s.attributes[i].data() + s.attributes[i].size();
      for (const auto &kv : p.attributes) s.attributes[i].push_back({kv.first.c_str(), kv.second});
      o.target_count = p.targets.size();
      fill_mappings(p, s, &o);
      s.primitives[i].push_back(o);
    }
    s.meshes.push_back({mesh.name.c_str(), s.primitives[i].data(), s.primitives[i].size()});
  }
  for (const auto &n : m.nodes) {
    iris_gltf_node o;
    std::memset(&o, 0, sizeof o);
    o.name = n.name.c_str();
    o.mesh = n.mesh;
    o.camera = n.camera;
    o.skin = n.skin;
    o.light = -1;
    auto it = n.extensions.find("KHR_lights_punctual");
    if (it != n.extensions.end()) {
      const tinygltf::Value &v = it->second;
      // A present but malformed reference becomes INT_MIN: rejected as out of range.
      o.light = (v.IsObject() && v.Has("light") && v.Get("light").IsNumber())
                    ? v.Get("light").GetNumberAsInt()
                    : INT_MIN;
    }
    o.inst_translation = o.inst_rotation = o.inst_scale = -1;
    auto gi = n.extensions.find("EXT_mesh_gpu_instancing");
    if (gi != n.extensions.end()) {
      o.gpu_instancing = true;
      const tinygltf::Value &v = gi->second;
      if (!v.IsObject() || !v.Has("attributes") || !v.Get("attributes").IsObject()) {
        o.gpu_instancing_bad = true;
      } else {
        const tinygltf::Value &a = v.Get("attributes");
        // A present but malformed reference becomes INT_MIN: rejected as out of range.
        auto ref = [&a](const char *key) {
          if (!a.Has(key)) return -1;
          return a.Get(key).IsNumber() ? a.Get(key).GetNumberAsInt() : INT_MIN;
        };
        o.inst_translation = ref("TRANSLATION");
        o.inst_rotation = ref("ROTATION");
        o.inst_scale = ref("SCALE");
      }
    }
    o.children = n.children.data();
    o.child_count = n.children.size();
    o.matrix = n.matrix.data();
    o.matrix_len = n.matrix.size();
    o.translation = n.translation.data();
    o.translation_len = n.translation.size();
    o.rotation = n.rotation.data();
    o.rotation_len = n.rotation.size();
    o.scale = n.scale.data();
    o.scale_len = n.scale.size();
    o.has_weights = !n.weights.empty();
    s.nodes.push_back(o);
  }
  s.materials.resize(m.materials.size());
  for (size_t i = 0; i < m.materials.size(); i++) fill_material(m.materials[i], &s.materials[i]);
  for (const auto &t : m.textures) {
    iris_gltf_texture o = {t.source, t.sampler, -1, -1, nullptr};
    const char *names[2] = {"EXT_texture_webp", "KHR_texture_basisu"};
    int *dst[2] = {&o.webp_source, &o.basisu_source};
    for (int k = 0; k < 2; k++) {
      auto it = t.extensions.find(names[k]);
      if (it == t.extensions.end()) continue;
      const tinygltf::Value &v = it->second;
      if (v.IsObject() && v.Has("source") && v.Get("source").IsInt())
        *dst[k] = v.Get("source").GetNumberAsInt();
      else
        o.bad_extension = names[k];
    }
    s.textures.push_back(o);
  }
  for (size_t i = 0; i < m.images.size(); i++) {
    const auto &im = m.images[i];
    iris_gltf_image o;
    std::memset(&o, 0, sizeof o);
    o.name = im.name.c_str();
    o.uri = im.uri.empty() ? nullptr : im.uri.c_str();
    o.view = im.bufferView;
    o.mime = im.mimeType.c_str();
    if (!o.uri && o.view < 0 && !im.image.empty()) {
      o.data = im.image.data();
      o.size = im.image.size();
    }
    if (i < image_states.size()) {
      o.file_found = o.uri && image_states[i].called;
      std::memcpy(o.file_mime, image_states[i].mime, sizeof o.file_mime);
    }
    s.images.push_back(o);
  }
  for (const auto &sm : m.samplers) s.samplers.push_back({sm.magFilter, sm.minFilter, sm.wrapS, sm.wrapT});
  for (const auto &c : m.cameras) {
    iris_gltf_camera o;
    o.name = c.name.c_str();
    o.type = c.type.c_str();
    o.yfov = c.perspective.yfov;
    o.aspect = c.perspective.aspectRatio;
    s.cameras.push_back(o);
  }
  for (const auto &l : m.lights) {
    iris_gltf_light o;
    o.name = l.name.c_str();
    o.type = l.type.c_str();
    o.color = l.color.data();
    o.color_len = l.color.size();
    o.intensity = l.intensity;
    o.range = l.range;
    o.inner_cone = l.spot.innerConeAngle;
    o.outer_cone = l.spot.outerConeAngle;
    s.lights.push_back(o);
  }
  for (const auto &sc : m.scenes) s.scenes.push_back({sc.name.c_str(), sc.nodes.data(), sc.nodes.size()});
  for (const auto &e : m.extensionsUsed) s.used.push_back(e.c_str());
  for (const auto &e : m.extensionsRequired) s.required.push_back(e.c_str());

  d->version = m.asset.version.c_str();
  d->min_version = m.asset.minVersion.c_str();
  d->extensions_used = s.used.data();
  d->extensions_used_count = s.used.size();
  d->extensions_required = s.required.data();
  d->extensions_required_count = s.required.size();
  d->default_scene = m.defaultScene;
  d->animation_count = m.animations.size();
  d->buffers = s.buffers.data();
  d->buffer_count = s.buffers.size();
  d->views = s.views.data();
  d->view_count = s.views.size();
  d->accessors = s.accessors.data();
  d->accessor_count = s.accessors.size();
  d->meshes = s.meshes.data();
  d->mesh_count = s.meshes.size();
  d->nodes = s.nodes.data();
  d->node_count = s.nodes.size();
  d->materials = s.materials.data();
  d->material_count = s.materials.size();
  d->textures = s.textures.data();
  d->texture_count = s.textures.size();
  d->images = s.images.data();
  d->image_count = s.images.size();
  d->samplers = s.samplers.data();
  d->sampler_count = s.samplers.size();
  d->cameras = s.cameras.data();
  d->camera_count = s.cameras.size();
  d->lights = s.lights.data();
  d->light_count = s.lights.size();
  d->scenes = s.scenes.data();
  d->scene_count = s.scenes.size();
  fill_variants(m, s, d);
}

iris_status import_memory(const char *data, size_t size, const char *path,
                          const iris_import_options *opts, iris_scene **out, iris_error *err) {
  const char *file = path ? path : "<memory>";
  const uint8_t *bytes = reinterpret_cast<const uint8_t *>(data);
  bool is_glb = false;
  iris_status st = iris_gltf_check_container(bytes, size, file, &is_glb, err);
  if (st != IRIS_OK) return st;

  char base_dir[1024] = "";
  if (path) iris_path_dir(path, base_dir, sizeof base_dir);

  tinygltf::TinyGLTF loader;
  FsContext fs_ctx = {path != nullptr};
  tinygltf::FsCallbacks fs = {&fs_exists, &fs_expand, &fs_read, &fs_write, &fs_ctx};
  loader.SetFsCallbacks(fs);
  std::vector<ImageState> image_states;
  loader.SetImageLoader(&keep_encoded_image, &image_states);
  // KHR_materials_variants is read from the original JSON (fill_mappings); only
  // files that name it pay for keeping it.
  static const char kVariants[] = "KHR_materials_variants";
  loader.SetStoreOriginalJSONForExtrasAndExtensions(
      memmem(data, size, kVariants, sizeof kVariants - 1) != nullptr);

  // Draco and meshopt files need a patched JSON before tinygltf sees them
  // (gltf_compressed.h); a GLB gets its JSON chunk replaced.
  std::vector<int> placeholders;
  std::string patched;
  std::vector<uint8_t> glb;
  if (is_glb) {
    const size_t json_len = (size_t)bytes[12] | (size_t)bytes[13] << 8 | (size_t)bytes[14] << 16 |
                            (size_t)bytes[15] << 24;  // checked by iris_gltf_check_container
    if (iris_gltf_patch_compressed_json(data + 20, json_len, &patched, &placeholders)) {
      while (patched.size() % 4) patched += ' ';
      if (patched.size() > UINT32_MAX - size)
        return iris_error_set(err, IRIS_ERR_PARSE, file, 0, nullptr, "GLB too large");
      const size_t total = size - json_len + patched.size();
      glb.resize(total);
      std::memcpy(glb.data(), bytes, 12);
      const uint32_t t32 = (uint32_t)total, j32 = (uint32_t)patched.size();
      for (int k = 0; k < 4; k++) glb[8 + k] = (uint8_t)(t32 >> (8 * k)), glb[12 + k] = (uint8_t)(j32 >> (8 * k));
      std::memcpy(glb.data() + 16, bytes + 16, 4);
      std::memcpy(glb.data() + 20, patched.data(), patched.size());
      std::memcpy(glb.data() + 20 + patched.size(), bytes + 20 + json_len, size - 20 - json_len);
      bytes = glb.data();
      size = total;
    }
  } else if (iris_gltf_patch_compressed_json(data, size, &patched, &placeholders)) {
    data = patched.data();
    size = patched.size();
  }

  tinygltf::Model model;
  std::string terr, twarn;
  bool ok;
  if (is_glb)
    ok = loader.LoadBinaryFromMemory(&model, &terr, &twarn, bytes, (unsigned int)size, base_dir);
  else
    ok = loader.LoadASCIIFromString(&model, &terr, &twarn, data, (unsigned int)size, base_dir);
  if (!ok) {
    // Report an unsupported required extension rather than its symptoms.
    std::vector<const char *> req;
    for (const auto &e : model.extensionsRequired) req.push_back(e.c_str());
    st = iris_gltf_check_required(req.data(), req.size(), file, err);
    if (st != IRIS_OK) return st;
    std::string msg = one_line(terr);
    if (msg.empty()) msg = "tinygltf could not load the file";
    iris_status code = (msg.find("File not found") != std::string::npos ||
                        msg.find("cannot read") != std::string::npos ||
                        msg.find("external files are disabled") != std::string::npos)
                           ? IRIS_ERR_IO
                           : IRIS_ERR_PARSE;
    return iris_error_set(err, code, file, 0, nullptr, "%s", msg.c_str());
  }
  {
    std::vector<const char *> req;
    for (const auto &e : model.extensionsRequired) req.push_back(e.c_str());
    st = iris_gltf_check_required(req.data(), req.size(), file, err);
    if (st != IRIS_OK) return st;
  }
  if (!twarn.empty()) iris_infof("%s: tinygltf: %s", file, one_line(twarn).c_str());
  st = iris_gltf_decode_compressed(model, placeholders, file, err);
  if (st != IRIS_OK) return st;

  DocStorage storage;
  iris_gltf_doc doc;
  std::memset(&doc, 0, sizeof doc);
  doc.file = file;
  doc.base_dir = path ? base_dir : nullptr;
  fill_doc(model, image_states, storage, &doc);
  return iris_gltf_convert(&doc, opts, out, err);
}

}  // namespace

extern "C" iris_status iris_import_gltf_memory(const char *data, size_t size, const char *path,
                                               const iris_import_options *opts, iris_scene **out,
                                               iris_error *err) {
  if (out) *out = nullptr;
  const char *file = path ? path : "<memory>";
  if (!out || (!data && size > 0))
    return iris_error_set(err, IRIS_ERR_USAGE, file, 0, nullptr, "bad arguments");
  try {
    return import_memory(data ? data : "", size, path, opts, out, err);
  } catch (const std::bad_alloc &) {
    return iris_error_set(err, IRIS_ERR_NOMEM, file, 0, nullptr, "out of memory");
  } catch (const std::exception &e) {
    return iris_error_set(err, IRIS_ERR_PARSE, file, 0, nullptr, "%s", e.what());
  } catch (...) {
    return iris_error_set(err, IRIS_ERR_INTERNAL, file, 0, nullptr, "unexpected exception");
  }
}

extern "C" iris_status iris_import_gltf(const char *path, const iris_import_options *opts,
                                        iris_scene **out, iris_error *err) {
  if (out) *out = nullptr;
  if (!path) return iris_error_set(err, IRIS_ERR_USAGE, nullptr, 0, nullptr, "no file name");
  char *data = nullptr;
  size_t size = 0;
  // GLB lengths are 32-bit: anything larger cannot be a valid glTF file.
  iris_status st = iris_file_read(path, (size_t)UINT32_MAX, &data, &size, err);
  if (st != IRIS_OK) return st;
  st = iris_import_gltf_memory(data, size, path, opts, out, err);
  free(data);
  return st;
}
