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

namespace {

struct Vec2 {
  double x, y;
};

inline double cross2(Vec2 a, Vec2 b, Vec2 c) {  // (b - a) x (c - a)
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

inline bool same2(Vec2 a, Vec2 b) { return a.x == b.x && a.y == b.y; }

// Inclusive point-in-triangle for a counter-clockwise triangle.
inline bool inside2(Vec2 a, Vec2 b, Vec2 c, Vec2 p) {
  return cross2(a, b, p) >= 0 && cross2(b, c, p) >= 0 && cross2(c, a, p) >= 0;
}

}  // namespace

struct iris_polygon_triangulator {
  std::vector<Vec2> pts;
  std::vector<uint32_t> prev, next;
};

extern "C" iris_polygon_triangulator *iris_polygon_triangulator_create(void) {
  return new (std::nothrow) iris_polygon_triangulator();
}

extern "C" void iris_polygon_triangulator_destroy(iris_polygon_triangulator *t) { delete t; }

static uint32_t triangulate_fan(uint32_t n, uint32_t *tris) {
  for (uint32_t i = 1; i + 1 < n; i++) {
    *tris++ = 0;
    *tris++ = i;
    *tris++ = i + 1;
  }
  return n - 2;
}

extern "C" uint32_t iris_polygon_triangulate(iris_polygon_triangulator *t, const float *positions,
                                             const uint32_t *corners, uint32_t n,
                                             uint32_t *tris) {
  if (n < 3) return 0;
  if (n == 3) {
    tris[0] = 0, tris[1] = 1, tris[2] = 2;
    return 1;
  }
  if (n > IRIS_POLYGON_EAR_CLIP_MAX) return triangulate_fan(n, tris);
  // Newell normal: robust for non-planar and concave polygons.
  double nx = 0, ny = 0, nz = 0;
  for (uint32_t i = 0; i < n; i++) {
    const float *a = positions + 3 * (size_t)corners[i];
    const float *b = positions + 3 * (size_t)corners[(i + 1) % n];
    nx += ((double)a[1] - b[1]) * ((double)a[2] + b[2]);
    ny += ((double)a[2] - b[2]) * ((double)a[0] + b[0]);
    nz += ((double)a[0] - b[0]) * ((double)a[1] + b[1]);
  }
  double ax = std::fabs(nx), ay = std::fabs(ny), az = std::fabs(nz);
  if (!(ax + ay + az > 0) || !std::isfinite(ax + ay + az)) return triangulate_fan(n, tris);
  // Drop the dominant axis; order the two kept axes so the polygon is
  // counter-clockwise in 2D.
  int k = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
  double nk = k == 0 ? nx : (k == 1 ? ny : nz);
  int u = (k + 1) % 3, v = (k + 2) % 3;
  if (nk < 0) std::swap(u, v);
  try {
    t->pts.resize(n);
    t->prev.resize(n);
    t->next.resize(n);
  } catch (const std::bad_alloc &) {
    return 0;
  }
  Vec2 *p = t->pts.data();
  for (uint32_t i = 0; i < n; i++) {
    const float *a = positions + 3 * (size_t)corners[i];
    p[i] = Vec2{a[u], a[v]};
  }
  if (n == 4) {
    // Cycles/Blender split quads along 0-2; keep that unless it leaves the quad.
    if (cross2(p[0], p[1], p[2]) > 0 && cross2(p[0], p[2], p[3]) > 0) {
      const uint32_t q[6] = {0, 1, 2, 0, 2, 3};
      std::memcpy(tris, q, sizeof q);
      return 2;
    }
    if (cross2(p[1], p[2], p[3]) > 0 && cross2(p[1], p[3], p[0]) > 0) {
      const uint32_t q[6] = {1, 2, 3, 1, 3, 0};
      std::memcpy(tris, q, sizeof q);
      return 2;
    }
  }
  uint32_t *prev = t->prev.data(), *next = t->next.data();
  for (uint32_t i = 0; i < n; i++) {
    prev[i] = (i + n - 1) % n;
    next[i] = (i + 1) % n;
  }
  uint32_t remaining = n, cur = 0, out = 0;
  while (remaining > 3) {
    bool clipped = false;
    for (uint32_t tries = 0; tries < remaining; tries++, cur = next[cur]) {
      uint32_t a = prev[cur], c = next[cur];
      if (!(cross2(p[a], p[cur], p[c]) > 0)) continue;  // reflex or collinear
      bool ear = true;
      for (uint32_t q = next[c]; q != a; q = next[q]) {
        // Vertices coinciding with the ear's corners (keyhole bridges) do not block it.
        if (same2(p[q], p[a]) || same2(p[q], p[cur]) || same2(p[q], p[c])) continue;
        if (inside2(p[a], p[cur], p[c], p[q])) {
          ear = false;
          break;
        }
      }
      if (ear) {
        clipped = true;
        break;
      }
    }
    // Self-intersecting or degenerate input has no ear: clip anyway so the
    // result always has n - 2 triangles; zero-area ones are removed later.
    (void)clipped;
    uint32_t a = prev[cur], c = next[cur];
    tris[out++] = a, tris[out++] = cur, tris[out++] = c;
    next[a] = c;
    prev[c] = a;
    remaining--;
    cur = c;
  }
  tris[out++] = prev[cur], tris[out++] = cur, tris[out++] = next[cur];
  return n - 2;
}

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
