// Mesh processing for the OBJ and PLY importers (C++17 shim behind meshproc.h).
// Plain-array code for the import path (fast, indifferent to non-manifold
// input) and an OpenMesh halfedge version of the normals used as a reference.
#include "importers/meshproc.h"

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <unordered_map>
#include <vector>

// ---- normals ---------------------------------------------------------------

static inline void sub3(const float *a, const float *b, double *r) {
  r[0] = (double)a[0] - b[0], r[1] = (double)a[1] - b[1], r[2] = (double)a[2] - b[2];
}
static inline double dot3(const double *a, const double *b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static inline void cross3(const double *a, const double *b, double *r) {
  r[0] = a[1] * b[2] - a[2] * b[1];
  r[1] = a[2] * b[0] - a[0] * b[2];
  r[2] = a[0] * b[1] - a[1] * b[0];
}

// Angle between edge vectors e and f (atan2 form: accurate for tiny and
// near-pi angles, unlike acos of a normalised dot product).
static inline double angle3(const double *e, const double *f) {
  double c[3];
  cross3(e, f, c);
  return std::atan2(std::sqrt(dot3(c, c)), dot3(e, f));
}

extern "C" void iris_normals_accumulate(const float *positions, const uint32_t *indices,
                                        size_t triangle_count, float *accum) {
  for (size_t t = 0; t < triangle_count; t++) {
    const uint32_t i0 = indices[3 * t], i1 = indices[3 * t + 1], i2 = indices[3 * t + 2];
    const float *p0 = positions + 3 * (size_t)i0, *p1 = positions + 3 * (size_t)i1,
                *p2 = positions + 3 * (size_t)i2;
    double e01[3], e02[3], e12[3], n[3];
    sub3(p1, p0, e01);
    sub3(p2, p0, e02);
    sub3(p2, p1, e12);
    cross3(e01, e02, n);
    double len = std::sqrt(dot3(n, n));
    if (!(len > 0) || !std::isfinite(len)) continue;
    n[0] /= len, n[1] /= len, n[2] /= len;
    double e10[3] = {-e01[0], -e01[1], -e01[2]}, e20[3] = {-e02[0], -e02[1], -e02[2]},
           e21[3] = {-e12[0], -e12[1], -e12[2]};
    const double w0 = angle3(e01, e02), w1 = angle3(e12, e10), w2 = angle3(e20, e21);
    const uint32_t idx[3] = {i0, i1, i2};
    const double w[3] = {w0, w1, w2};
    for (int k = 0; k < 3; k++) {
      float *a = accum + 3 * (size_t)idx[k];
      a[0] += (float)(w[k] * n[0]);
      a[1] += (float)(w[k] * n[1]);
      a[2] += (float)(w[k] * n[2]);
    }
  }
}

extern "C" void iris_normals_normalize(float *normals, size_t vertex_count) {
  for (size_t v = 0; v < vertex_count; v++) {
    float *n = normals + 3 * v;
    double len = std::sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
    if (len > 0 && std::isfinite(len)) {
      n[0] = (float)(n[0] / len), n[1] = (float)(n[1] / len), n[2] = (float)(n[2] / len);
    } else {
      n[0] = 0, n[1] = 0, n[2] = 1;
    }
  }
}

namespace {
struct OmTraits : public OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
  typedef OpenMesh::Vec3d Normal;
};
typedef OpenMesh::TriMesh_ArrayKernelT<OmTraits> OmMesh;
}  // namespace

extern "C" bool iris_normals_openmesh(const float *positions, size_t vertex_count,
                                      const uint32_t *indices, size_t triangle_count,
                                      float *normals) {
  try {
    OmMesh mesh;
    mesh.reserve(vertex_count, 3 * triangle_count, triangle_count);
    std::vector<OmMesh::VertexHandle> vh(vertex_count);
    for (size_t v = 0; v < vertex_count; v++)
      vh[v] = mesh.add_vertex(
          OmMesh::Point(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]));
    for (size_t t = 0; t < triangle_count; t++) {
      OmMesh::FaceHandle f =
          mesh.add_face(vh[indices[3 * t]], vh[indices[3 * t + 1]], vh[indices[3 * t + 2]]);
      if (!f.is_valid()) return false;
    }
    mesh.request_face_normals();
    mesh.update_face_normals();
    for (size_t v = 0; v < vertex_count; v++) {
      OmMesh::Normal sum(0, 0, 0);
      // Incoming halfedges: the sector at v between this halfedge and the next
      // one belongs to the halfedge's face.
      for (auto heh : mesh.vih_range(vh[v])) {
        if (mesh.is_boundary(heh)) continue;
        sum += mesh.normal(mesh.face_handle(heh)) * mesh.calc_sector_angle(heh);
      }
      normals[3 * v] = (float)sum[0];
      normals[3 * v + 1] = (float)sum[1];
      normals[3 * v + 2] = (float)sum[2];
    }
    iris_normals_normalize(normals, vertex_count);
    return true;
  } catch (...) {
    return false;
  }
}

// ---- clean-up ---------------------------------------------------------------

extern "C" uint32_t iris_mesh_remove_degenerate(const float *positions, uint32_t *indices,
                                                uint32_t *triangle_count) {
  uint32_t kept = 0, n = *triangle_count;
  for (uint32_t t = 0; t < n; t++) {
    const uint32_t i0 = indices[3 * t], i1 = indices[3 * t + 1], i2 = indices[3 * t + 2];
    if (i0 == i1 || i1 == i2 || i0 == i2) continue;
    double e1[3], e2[3], c[3];
    sub3(positions + 3 * (size_t)i1, positions + 3 * (size_t)i0, e1);
    sub3(positions + 3 * (size_t)i2, positions + 3 * (size_t)i0, e2);
    cross3(e1, e2, c);
    if (c[0] == 0 && c[1] == 0 && c[2] == 0) continue;
    indices[3 * kept] = i0, indices[3 * kept + 1] = i1, indices[3 * kept + 2] = i2;
    kept++;
  }
  *triangle_count = kept;
  return n - kept;
}

namespace {
struct VertexKey {
  float f[18]; /* position, normal, uv, colour, uv1, tangent, alpha */
  int count;
  bool operator==(const VertexKey &o) const {
    return count == o.count && std::memcmp(f, o.f, sizeof(float) * count) == 0;
  }
};
struct VertexKeyHash {
  size_t operator()(const VertexKey &k) const {
    uint64_t h = 1469598103934665603ull;  // FNV-1a over the bytes
    const unsigned char *b = reinterpret_cast<const unsigned char *>(k.f);
    for (size_t i = 0; i < sizeof(float) * (size_t)k.count; i++) h = (h ^ b[i]) * 1099511628211ull;
    return (size_t)h;
  }
};
}  // namespace

extern "C" int64_t iris_mesh_weld(iris_mesh *m) {
  try {
    const uint32_t nv = m->vertex_count;
    std::vector<uint8_t> used(nv, 0);
    for (size_t i = 0; i < 3 * (size_t)m->triangle_count; i++) used[m->indices[i]] = 1;
    std::unordered_map<VertexKey, uint32_t, VertexKeyHash> seen;
    seen.reserve(nv);
    std::vector<uint32_t> remap(nv, UINT32_MAX);
    uint32_t out = 0;
    for (uint32_t v = 0; v < nv; v++) {
      if (!used[v]) continue;
      VertexKey k;
      k.count = 0;
      for (int c = 0; c < 3; c++) k.f[k.count++] = m->positions[3 * (size_t)v + c];
      if (m->normals)
        for (int c = 0; c < 3; c++) k.f[k.count++] = m->normals[3 * (size_t)v + c];
      if (m->uvs)
        for (int c = 0; c < 2; c++) k.f[k.count++] = m->uvs[2 * (size_t)v + c];
      if (m->colors)
        for (int c = 0; c < 3; c++) k.f[k.count++] = m->colors[3 * (size_t)v + c];
      if (m->uvs1)
        for (int c = 0; c < 2; c++) k.f[k.count++] = m->uvs1[2 * (size_t)v + c];
      if (m->tangents)
        for (int c = 0; c < 4; c++) k.f[k.count++] = m->tangents[4 * (size_t)v + c];
      if (m->alphas) k.f[k.count++] = m->alphas[v];
      // -0.0 and 0.0 differ bitwise but are the same vertex.
      for (int c = 0; c < k.count; c++)
        if (k.f[c] == 0.0f) k.f[c] = 0.0f;
      auto ins = seen.emplace(k, out);
      if (!ins.second) {
        remap[v] = ins.first->second;
        continue;
      }
      remap[v] = out;
      std::memmove(m->positions + 3 * (size_t)out, m->positions + 3 * (size_t)v, 3 * sizeof(float));
      if (m->normals)
        std::memmove(m->normals + 3 * (size_t)out, m->normals + 3 * (size_t)v, 3 * sizeof(float));
      if (m->uvs) std::memmove(m->uvs + 2 * (size_t)out, m->uvs + 2 * (size_t)v, 2 * sizeof(float));
      if (m->colors)
        std::memmove(m->colors + 3 * (size_t)out, m->colors + 3 * (size_t)v, 3 * sizeof(float));
      if (m->uvs1) std::memmove(m->uvs1 + 2 * (size_t)out, m->uvs1 + 2 * (size_t)v, 2 * sizeof(float));
      if (m->tangents)
        std::memmove(m->tangents + 4 * (size_t)out, m->tangents + 4 * (size_t)v, 4 * sizeof(float));
      if (m->alphas) m->alphas[out] = m->alphas[v];
      out++;
    }
    for (size_t i = 0; i < 3 * (size_t)m->triangle_count; i++) m->indices[i] = remap[m->indices[i]];
    m->vertex_count = out;
    return (int64_t)nv - out;
  } catch (const std::bad_alloc &) {
    return -1;
  }
}

extern "C" bool iris_mesh_finish(iris_mesh *mesh, bool compute_normals, bool weld,
                                 uint32_t *degenerate_removed) {
  uint32_t removed = iris_mesh_remove_degenerate(mesh->positions, mesh->indices, &mesh->triangle_count);
  if (degenerate_removed) *degenerate_removed = removed;
  if (!mesh->normals && compute_normals && mesh->vertex_count > 0) {
    mesh->normals = static_cast<float *>(std::calloc(3 * (size_t)mesh->vertex_count, sizeof(float)));
    if (!mesh->normals) return false;
    iris_normals_accumulate(mesh->positions, mesh->indices, mesh->triangle_count, mesh->normals);
    iris_normals_normalize(mesh->normals, mesh->vertex_count);
  }
  if (weld && iris_mesh_weld(mesh) < 0) return false;
  return true;
}
