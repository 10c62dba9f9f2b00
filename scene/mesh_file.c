/* Binary mesh files (".irmesh", docs/format.md): a 64-byte little-endian
 * header, then float32 positions, optional normals, uvs and colours, and
 * uint32 indices. The payload is used in place from a memory map, so the
 * reader checks everything a renderer would otherwise trust blindly. */
#include <stdint.h>
#include <string.h>
#include <zlib.h>

#include "core/fileio.h"
#include "scene/scene.h"
#include "scene/mesh_file.h"

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "iris mesh files are little-endian and mapped in place; a big-endian host needs byte swapping here"
#endif

static void put_u32(uint8_t *p, uint32_t v) {
  p[0] = (uint8_t)v;
  p[1] = (uint8_t)(v >> 8);
  p[2] = (uint8_t)(v >> 16);
  p[3] = (uint8_t)(v >> 24);
}

static uint32_t get_u32(const uint8_t *p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

uint32_t iris_mesh_file_flags(const iris_mesh *mesh) {
  return (mesh->normals ? IRIS_MESH_HAS_NORMALS : 0u) | (mesh->uvs ? IRIS_MESH_HAS_UVS : 0u) |
         (mesh->colors ? IRIS_MESH_HAS_COLORS : 0u) | (mesh->uvs1 ? IRIS_MESH_HAS_UVS1 : 0u) |
         (mesh->tangents ? IRIS_MESH_HAS_TANGENTS : 0u) | (mesh->alphas ? IRIS_MESH_HAS_ALPHAS : 0u);
}

uint64_t iris_mesh_file_size(uint32_t flags, uint64_t vertex_count, uint64_t triangle_count) {
  uint64_t per_vertex = 12 + (flags & IRIS_MESH_HAS_NORMALS ? 12 : 0) +
                        (flags & IRIS_MESH_HAS_UVS ? 8 : 0) + (flags & IRIS_MESH_HAS_COLORS ? 12 : 0) +
                        (flags & IRIS_MESH_HAS_UVS1 ? 8 : 0) + (flags & IRIS_MESH_HAS_TANGENTS ? 16 : 0) +
                        (flags & IRIS_MESH_HAS_ALPHAS ? 4 : 0);
  return IRIS_MESH_HEADER_SIZE + per_vertex * vertex_count + 12 * triangle_count;
}

/* zlib's crc32 takes 32-bit lengths; feed it in chunks. */
static uint32_t crc_update(uint32_t crc, const void *data, size_t size) {
  const Bytef *p = data;
  while (size > 0) {
    uInt n = size > (1u << 30) ? (1u << 30) : (uInt)size;
    crc = (uint32_t)crc32(crc, p, n);
    p += n;
    size -= n;
  }
  return crc;
}

iris_status iris_mesh_write_file(const iris_mesh *mesh, const char *path, iris_error *err) {
  if (mesh->vertex_count == 0 || mesh->triangle_count == 0 || !mesh->positions || !mesh->indices)
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL, "cannot write an empty mesh");
  size_t nv = mesh->vertex_count, nt = mesh->triangle_count;
  struct {
    const void *data;
    size_t size;
  } parts[8] = {{mesh->positions, 12 * nv},
                {mesh->normals, mesh->normals ? 12 * nv : 0},
                {mesh->uvs, mesh->uvs ? 8 * nv : 0},
                {mesh->colors, mesh->colors ? 12 * nv : 0},
                {mesh->uvs1, mesh->uvs1 ? 8 * nv : 0},
                {mesh->tangents, mesh->tangents ? 16 * nv : 0},
                {mesh->alphas, mesh->alphas ? 4 * nv : 0},
                {mesh->indices, 12 * nt}};
  uint32_t crc = (uint32_t)crc32(0L, Z_NULL, 0);
  for (int i = 0; i < 8; i++)
    if (parts[i].size) crc = crc_update(crc, parts[i].data, parts[i].size);

  uint8_t header[IRIS_MESH_HEADER_SIZE];
  memset(header, 0, sizeof header);
  memcpy(header, IRIS_MESH_MAGIC, 8);
  put_u32(header + 8, IRIS_MESH_FILE_VERSION);
  put_u32(header + 12, iris_mesh_file_flags(mesh));
  put_u32(header + 16, mesh->vertex_count);
  put_u32(header + 20, mesh->triangle_count);
  put_u32(header + 24, crc);

  iris_atomic_file f;
  iris_status st = iris_atomic_open(&f, path, err);
  if (st != IRIS_OK) return st;
  bool ok = fwrite(header, 1, sizeof header, f.fp) == sizeof header;
  for (int i = 0; ok && i < 8; i++)
    if (parts[i].size) ok = fwrite(parts[i].data, 1, parts[i].size, f.fp) == parts[i].size;
  if (!ok) {
    iris_atomic_abort(&f);
    return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "write failed (disk full?)");
  }
  return iris_atomic_commit(&f, err);
}

iris_status iris_mesh_read_map(const iris_file_map *map, const char *path, iris_mesh *mesh,
                               iris_error *err) {
#define BAD(status, element, ...) return iris_error_set(err, status, path, 0, element, __VA_ARGS__)
  memset(mesh, 0, sizeof *mesh);
  mesh->material = -1;
  const uint8_t *p = map->data;
  size_t size = map->size;
  if (size < IRIS_MESH_HEADER_SIZE)
    BAD(IRIS_ERR_PARSE, "header", "truncated header (%zu bytes, expected at least %d)", size,
        IRIS_MESH_HEADER_SIZE);
  if (memcmp(p, IRIS_MESH_MAGIC, 8) != 0) BAD(IRIS_ERR_PARSE, "header", "not an iris mesh file (bad magic)");
  if (((uintptr_t)p & 3u) != 0)
    BAD(IRIS_ERR_INTERNAL, NULL, "mesh buffer is not 4-byte aligned");
  uint32_t version = get_u32(p + 8), flags = get_u32(p + 12);
  uint32_t nv = get_u32(p + 16), nt = get_u32(p + 20), crc = get_u32(p + 24);
  if (version != IRIS_MESH_FILE_VERSION)
    BAD(IRIS_ERR_UNSUPPORTED, "header", "unsupported version %u (this iris reads version %d)",
        (unsigned)version, IRIS_MESH_FILE_VERSION);
  if (flags & ~(uint32_t)IRIS_MESH_ALL_FLAGS)
    BAD(IRIS_ERR_UNSUPPORTED, "header", "unknown attribute flags 0x%x", (unsigned)(flags & ~(uint32_t)IRIS_MESH_ALL_FLAGS));
  for (int i = 28; i < IRIS_MESH_HEADER_SIZE; i++)
    if (p[i] != 0) BAD(IRIS_ERR_PARSE, "header", "reserved header byte %d is not zero", i);
  if (nv == 0 || nt == 0) BAD(IRIS_ERR_INVALID, "header", "empty mesh (%u vertices, %u triangles)", (unsigned)nv, (unsigned)nt);
  /* Counts are checked before any size arithmetic (which is 64-bit anyway). */
  if (nv > IRIS_MESH_MAX_COUNT || nt > IRIS_MESH_MAX_COUNT)
    BAD(IRIS_ERR_NOMEM, "header", "absurd counts (%u vertices, %u triangles; limit %u)", (unsigned)nv,
        (unsigned)nt, (unsigned)IRIS_MESH_MAX_COUNT);
  uint64_t expected = iris_mesh_file_size(flags, nv, nt);
  if ((uint64_t)size != expected)
    BAD(IRIS_ERR_PARSE, NULL, "file is %zu bytes but the header (%u vertices, %u triangles) needs %llu",
        size, (unsigned)nv, (unsigned)nt, (unsigned long long)expected);
  uint32_t actual = crc_update((uint32_t)crc32(0L, Z_NULL, 0), p + IRIS_MESH_HEADER_SIZE,
                               size - IRIS_MESH_HEADER_SIZE);
  if (actual != crc)
    BAD(IRIS_ERR_PARSE, NULL, "checksum mismatch (header 0x%08x, data 0x%08x): the file is corrupt",
        (unsigned)crc, (unsigned)actual);

  const uint8_t *q = p + IRIS_MESH_HEADER_SIZE;
  const float *positions = (const float *)q;
  q += 12 * (size_t)nv;
  const float *normals = NULL, *uvs = NULL, *colors = NULL, *uvs1 = NULL, *tangents = NULL, *alphas = NULL;
  if (flags & IRIS_MESH_HAS_NORMALS) {
    normals = (const float *)q;
    q += 12 * (size_t)nv;
  }
  if (flags & IRIS_MESH_HAS_UVS) {
    uvs = (const float *)q;
    q += 8 * (size_t)nv;
  }
  if (flags & IRIS_MESH_HAS_COLORS) {
    colors = (const float *)q;
    q += 12 * (size_t)nv;
  }
  if (flags & IRIS_MESH_HAS_UVS1) {
    uvs1 = (const float *)q;
    q += 8 * (size_t)nv;
  }
  if (flags & IRIS_MESH_HAS_TANGENTS) {
    tangents = (const float *)q;
    q += 16 * (size_t)nv;
  }
  if (flags & IRIS_MESH_HAS_ALPHAS) {
    alphas = (const float *)q;
    q += 4 * (size_t)nv;
  }
  const uint32_t *indices = (const uint32_t *)q;

  char element[64];
  struct {
    const float *v;
    int width;
    const char *what;
  } arrays[7] = {{positions, 3, "position"}, {normals, 3, "normal"}, {uvs, 2, "uv"},
                  {colors, 3, "color"},       {uvs1, 2, "uv1"},       {tangents, 4, "tangent"},
                  {alphas, 1, "alpha"}};
  for (int a = 0; a < 7; a++) {
    if (!arrays[a].v) continue;
    size_t n = (size_t)arrays[a].width * nv;
    for (size_t i = 0; i < n; i++)
      if (!isfinite(arrays[a].v[i])) {
        snprintf(element, sizeof element, "vertex %zu", i / (size_t)arrays[a].width);
        BAD(IRIS_ERR_INVALID, element, "%s is not finite", arrays[a].what);
      }
  }
  for (size_t i = 0; i < 3 * (size_t)nt; i++)
    if (indices[i] >= nv) {
      snprintf(element, sizeof element, "triangle %zu", i / 3);
      BAD(IRIS_ERR_INVALID, element, "index %u out of range (vertex count %u)", (unsigned)indices[i],
          (unsigned)nv);
    }
#undef BAD
  /* The scene model has non-const pointers; borrowed arrays are never written. */
  mesh->vertex_count = nv;
  mesh->triangle_count = nt;
  mesh->positions = (float *)(uintptr_t)positions;
  mesh->normals = (float *)(uintptr_t)normals;
  mesh->uvs = (float *)(uintptr_t)uvs;
  mesh->colors = (float *)(uintptr_t)colors;
  mesh->uvs1 = (float *)(uintptr_t)uvs1;
  mesh->tangents = (float *)(uintptr_t)tangents;
  mesh->alphas = (float *)(uintptr_t)alphas;
  mesh->indices = (uint32_t *)(uintptr_t)indices;
  mesh->owned = false;
  return IRIS_OK;
}
