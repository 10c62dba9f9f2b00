/* glTF 2.0 import, C side: validates the document the tinygltf shim filled
 * (every index, byte range and number) and turns it into an iris_scene: the
 * container checks, buffers, views and accessors, primitives into meshes, and
 * the top level that runs every pass. Nodes, cameras and lights:
 * gltf_nodes.c; materials: gltf_material.c. Mapping: docs/import-gltf.md. */
#include "importers/gltf_private.h"

#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/cancel.h"
#include "core/fileio.h"
#include "core/log.h"
#include "importers/meshproc.h"
#include "importers/tangents.h"


/* Accessors without a bufferView are zero-filled from nothing but their
 * declared count; cap them so a tiny file cannot demand gigabytes. */
#define ZERO_ACCESSOR_MAX_COUNT ((size_t)1 << 24)
/* tinygltf recurses over extras/extensions: refuse deeper JSON. */
#define JSON_MAX_DEPTH 64

/* Extensions whose content iris maps (anything else used produces one warning). */
static const char *const supported_extensions[] = {
    "KHR_materials_emissive_strength", "KHR_materials_specular", "KHR_materials_transmission",
    "KHR_materials_ior", "KHR_lights_punctual", "KHR_mesh_quantization", "KHR_texture_transform",
    "KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_volume", "KHR_materials_anisotropy",
    "KHR_draco_mesh_compression", "EXT_meshopt_compression", "EXT_texture_webp", "KHR_materials_unlit",
    "EXT_mesh_gpu_instancing", "KHR_materials_variants"};

/* ---- small helpers ------------------------------------------------------ */

static size_t component_size(int ct) {
  switch (ct) {
    case CT_BYTE: case CT_UBYTE: return 1;
    case CT_SHORT: case CT_USHORT: return 2;
    case CT_UINT: case CT_FLOAT: return 4;
    default: return 0;
  }
}

static int type_components(int type) {
  switch (type) {
    case TYPE_SCALAR: return 1;
    case TYPE_VEC2: return 2;
    case TYPE_VEC3: return 3;
    case TYPE_VEC4: case TYPE_MAT2: return 4;
    case TYPE_MAT3: return 9;
    case TYPE_MAT4: return 16;
    default: return 0;
  }
}

static const char *type_name(int type) {
  switch (type) {
    case TYPE_SCALAR: return "SCALAR";
    case TYPE_VEC2: return "VEC2";
    case TYPE_VEC3: return "VEC3";
    case TYPE_VEC4: return "VEC4";
    case TYPE_MAT2: return "MAT2";
    case TYPE_MAT3: return "MAT3";
    case TYPE_MAT4: return "MAT4";
    default: return "unknown";
  }
}

/* Element size including the column padding matrices of small components get. */
static size_t element_size(int ct, int type) {
  size_t cs = component_size(ct);
  if (type == TYPE_MAT2 && cs == 1) return 8;
  if (type == TYPE_MAT3 && cs == 1) return 12;
  if (type == TYPE_MAT3 && cs == 2) return 24;
  return cs * (size_t)type_components(type);
}

static uint32_t load_u32(const uint8_t *p, int ct) {
  switch (ct) {
    case CT_UBYTE: return p[0];
    case CT_USHORT: return (uint32_t)p[0] | (uint32_t)p[1] << 8;
    default: return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
  }
}

/* One component as float; normalized integers per glTF 2.0 section 3.11. */
static float load_component(const uint8_t *p, int ct, bool normalized) {
  switch (ct) {
    case CT_FLOAT: {
      uint32_t u = load_u32(p, CT_UINT);
      float f;
      memcpy(&f, &u, sizeof f);
      return f;
    }
    case CT_UBYTE: return normalized ? (float)p[0] / 255.0f : (float)p[0];
    case CT_BYTE: {
      float v = (float)(int8_t)p[0];
      return normalized ? fmaxf(v / 127.0f, -1.0f) : v;
    }
    case CT_USHORT: {
      float v = (float)load_u32(p, CT_USHORT);
      return normalized ? v / 65535.0f : v;
    }
    case CT_SHORT: {
      float v = (float)(int16_t)load_u32(p, CT_USHORT);
      return normalized ? fmaxf(v / 32767.0f, -1.0f) : v;
    }
    case CT_UINT: return (float)load_u32(p, CT_UINT);
    default: return 0.0f;
  }
}


/* Converted mesh data may use 16 bytes per byte of buffer plus this much. */
#define MESH_BUDGET_SLACK ((size_t)256 << 20)

iris_status gltf_fail(gltf_ctx *c, iris_status st, const char *element, const char *fmt, ...) {
  char msg[512];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return iris_error_set(c->err, st, c->file, 0, element, "%s", msg);
}

/* ---- container pre-checks ----------------------------------------------- */

static iris_status check_json_depth(const uint8_t *p, size_t n, const char *file, iris_error *err) {
  int depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < n; i++) {
    uint8_t ch = p[i];
    if (in_string) {
      if (ch == '\\') i++;
      else if (ch == '"') in_string = false;
    } else if (ch == '"') {
      in_string = true;
    } else if (ch == '[' || ch == '{') {
      if (++depth > JSON_MAX_DEPTH)
        return iris_error_set(err, IRIS_ERR_PARSE, file, 0, NULL,
                              "JSON nested deeper than %d levels", JSON_MAX_DEPTH);
    } else if (ch == ']' || ch == '}') {
      depth--;
    }
  }
  return IRIS_OK;
}

iris_status iris_gltf_check_container(const uint8_t *data, size_t size, const char *file,
                                      bool *is_glb, iris_error *err) {
  *is_glb = size >= 4 && memcmp(data, "glTF", 4) == 0;
  if (size > UINT32_MAX)
    return iris_error_set(err, IRIS_ERR_NOMEM, file, 0, NULL, "file larger than 4 GiB");
  if (size == 0) return iris_error_set(err, IRIS_ERR_PARSE, file, 0, NULL, "empty file");
  char ext[16] = "";
  if (file) iris_path_ext(file, ext, sizeof ext);
  if (!*is_glb && strcmp(ext, "glb") == 0)
    return iris_error_set(err, IRIS_ERR_PARSE, file, 0, "GLB header", "invalid magic (not 'glTF')");
  if (!*is_glb) return check_json_depth(data, size, file, err);

  /* GLB: 12-byte header, then chunks (glTF 2.0 section 4.4). */
  if (size < 12)
    return iris_error_set(err, IRIS_ERR_PARSE, file, 0, "GLB header", "truncated (%zu bytes)", size);
  uint32_t version = load_u32(data + 4, CT_UINT), length = load_u32(data + 8, CT_UINT);
  if (version != 2)
    return iris_error_set(err, IRIS_ERR_UNSUPPORTED, file, 0, "GLB header",
                          "container version %u (only 2 is supported)", version);
  if (length != size)
    return iris_error_set(err, IRIS_ERR_PARSE, file, 0, "GLB header",
                          "declared length %u but the file has %zu bytes", length, size);
  size_t pos = 12;
  int chunk = 0;
  const uint8_t *json = NULL;
  size_t json_size = 0;
  while (pos < size) {
    char el[32];
    snprintf(el, sizeof el, "GLB chunk %d", chunk);
    if (size - pos < 8)
      return iris_error_set(err, IRIS_ERR_PARSE, file, 0, el, "truncated chunk header");
    uint32_t clen = load_u32(data + pos, CT_UINT), ctype = load_u32(data + pos + 4, CT_UINT);
    if (clen > size - pos - 8)
      return iris_error_set(err, IRIS_ERR_PARSE, file, 0, el,
                            "chunk length %u exceeds the remaining %zu bytes", clen, size - pos - 8);
    if (clen % 4 != 0)
      return iris_error_set(err, IRIS_ERR_PARSE, file, 0, el,
                            "chunk length %u is not a multiple of 4", clen);
    if (chunk == 0) {
      if (ctype != 0x4E4F534Au)
        return iris_error_set(err, IRIS_ERR_PARSE, file, 0, el, "first chunk is not JSON");
      if (clen == 0) return iris_error_set(err, IRIS_ERR_PARSE, file, 0, el, "empty JSON chunk");
      json = data + pos + 8;
      json_size = clen;
    } else if (chunk == 1 && ctype != 0x004E4942u) {
      /* Unknown chunk types must be ignored; tinygltf only looks at chunk 1. */
      return iris_error_set(err, IRIS_ERR_UNSUPPORTED, file, 0, el,
                            "second chunk is not BIN (type 0x%08x)", ctype);
    }
    pos += 8 + (size_t)clen;
    chunk++;
  }
  if (!json) return iris_error_set(err, IRIS_ERR_PARSE, file, 0, "GLB", "no JSON chunk");
  return check_json_depth(json, json_size, file, err);
}

static bool is_supported_extension(const char *name) {
  for (size_t i = 0; i < sizeof supported_extensions / sizeof *supported_extensions; i++)
    if (strcmp(name, supported_extensions[i]) == 0) return true;
  return false;
}

iris_status iris_gltf_check_required(const char *const *names, size_t count, const char *file,
                                     iris_error *err) {
  for (size_t i = 0; i < count; i++)
    if (!is_supported_extension(names[i]))
      return iris_error_set(err, IRIS_ERR_UNSUPPORTED, file, 0, "extensionsRequired",
                            "extension %s is not supported by iris", names[i]);
  return IRIS_OK;
}

/* ---- buffers, views, accessors ------------------------------------------ */

static iris_status validate_views(gltf_ctx *c) {
  const iris_gltf_doc *d = c->doc;
  char el[64];
  for (size_t i = 0; i < d->view_count; i++) {
    const iris_gltf_view *v = &d->views[i];
    ELEMENT(el, "bufferView %zu", i);
    if (v->buffer < 0 || (size_t)v->buffer >= d->buffer_count)
      return gltf_fail(c, IRIS_ERR_INVALID, el, "buffer %d does not exist (%zu buffers)", v->buffer,
                  d->buffer_count);
    size_t bsize = d->buffers[v->buffer].size;
    if (v->length < 1) return gltf_fail(c, IRIS_ERR_INVALID, el, "byteLength must be at least 1");
    if (v->offset > bsize || v->length > bsize - v->offset)
      return gltf_fail(c, IRIS_ERR_INVALID, el,
                  "byteOffset %zu + byteLength %zu exceeds buffer %d's %zu bytes", v->offset,
                  v->length, v->buffer, bsize);
    if (v->stride != 0 && (v->stride < 4 || v->stride > 252 || v->stride % 4 != 0))
      return gltf_fail(c, IRIS_ERR_INVALID, el, "byteStride %zu is not a multiple of 4 in [4, 252]",
                  v->stride);
  }
  return IRIS_OK;
}

/* Checks that `count` elements of `elem` bytes at `offset` with `stride` fit in view `vi`. */
static bool range_fits(const iris_gltf_view *v, size_t offset, size_t elem, size_t stride,
                       size_t count) {
  if (count == 0) return true;
  if (offset > v->length || elem > v->length - offset) return false;
  size_t room = v->length - offset - elem;
  return stride == 0 ? true : (count - 1) <= room / stride;
}

static iris_status validate_accessors(gltf_ctx *c) {
  const iris_gltf_doc *d = c->doc;
  char el[64];
  for (size_t i = 0; i < d->accessor_count; i++) {
    const iris_gltf_accessor *a = &d->accessors[i];
    ELEMENT(el, "accessor %zu", i);
    if (component_size(a->component_type) == 0)
      return gltf_fail(c, IRIS_ERR_INVALID, el, "invalid componentType %d", a->component_type);
    if (type_components(a->type) == 0) return gltf_fail(c, IRIS_ERR_INVALID, el, "invalid type");
    if (a->count < 1) return gltf_fail(c, IRIS_ERR_INVALID, el, "count must be at least 1");
    if (a->normalized && (a->component_type == CT_FLOAT || a->component_type == CT_UINT))
      return gltf_fail(c, IRIS_ERR_INVALID, el, "normalized is only allowed for 8- and 16-bit integers");
    size_t elem = element_size(a->component_type, a->type);
    if (a->view >= 0) {
      if ((size_t)a->view >= d->view_count)
        return gltf_fail(c, IRIS_ERR_INVALID, el, "bufferView %d does not exist (%zu views)", a->view,
                    d->view_count);
      const iris_gltf_view *v = &d->views[a->view];
      if (v->stride != 0 && v->stride < elem)
        return gltf_fail(c, IRIS_ERR_INVALID, el, "byteStride %zu is smaller than the %zu-byte element",
                    v->stride, elem);
      size_t stride = v->stride ? v->stride : elem;
      if (!range_fits(v, a->offset, elem, stride, a->count))
        return gltf_fail(c, IRIS_ERR_INVALID, el,
                    "byteOffset %zu + %zu elements of %zu bytes (stride %zu) exceed bufferView "
                    "%d's %zu bytes",
                    a->offset, a->count, elem, stride, a->view, v->length);
    } else if (a->view != -1) {
      return gltf_fail(c, IRIS_ERR_INVALID, el, "bufferView %d does not exist", a->view);
    } else if (a->count > ZERO_ACCESSOR_MAX_COUNT) {
      return gltf_fail(c, IRIS_ERR_NOMEM, el, "count %zu without a bufferView exceeds the limit %zu",
                  a->count, ZERO_ACCESSOR_MAX_COUNT);
    }
    if (!a->sparse) continue;
    if (a->sparse_count < 1 || (unsigned long long)a->sparse_count > a->count)
      return gltf_fail(c, IRIS_ERR_INVALID, el, "sparse count %lld not in [1, %zu]", a->sparse_count,
                  a->count);
    size_t n = (size_t)a->sparse_count;
    size_t isize = component_size(a->sparse_index_type);
    if (a->sparse_index_type != CT_UBYTE && a->sparse_index_type != CT_USHORT &&
        a->sparse_index_type != CT_UINT)
      return gltf_fail(c, IRIS_ERR_INVALID, el, "sparse indices componentType %d is not unsigned",
                  a->sparse_index_type);
    int views[2] = {a->sparse_index_view, a->sparse_value_view};
    long long offsets[2] = {a->sparse_index_offset, a->sparse_value_offset};
    size_t sizes[2] = {isize, elem};
    for (int k = 0; k < 2; k++) {
      if (views[k] < 0 || (size_t)views[k] >= d->view_count)
        return gltf_fail(c, IRIS_ERR_INVALID, el, "sparse %s bufferView %d does not exist",
                    k ? "values" : "indices", views[k]);
      const iris_gltf_view *v = &d->views[views[k]];
      if (v->stride != 0)
        return gltf_fail(c, IRIS_ERR_INVALID, el, "sparse %s bufferView %d must not have byteStride",
                    k ? "values" : "indices", views[k]);
      if (offsets[k] < 0 || !range_fits(v, (size_t)offsets[k], sizes[k], sizes[k], n))
        return gltf_fail(c, IRIS_ERR_INVALID, el, "sparse %s exceed bufferView %d",
                    k ? "values" : "indices", views[k]);
    }
    /* Accessors that share one sparse index view would each re-read it
     * (accessors x indices): all of them together may read 4 indices per
     * buffer byte plus 2^20. */
    if (n > c->sparse_left)
      return gltf_fail(c, IRIS_ERR_NOMEM, el,
                  "sparse indices of all accessors exceed 4 per buffer byte (a sparse view shared by many accessors?)");
    c->sparse_left -= n;
    const iris_gltf_view *iv = &d->views[a->sparse_index_view];
    const uint8_t *ip = d->buffers[iv->buffer].data + iv->offset + (size_t)a->sparse_index_offset;
    for (size_t k = 0; k < n; k++) {
      uint32_t idx = load_u32(ip + k * isize, a->sparse_index_type);
      if (idx >= a->count)
        return gltf_fail(c, IRIS_ERR_INVALID, el, "sparse index %u >= count %zu", idx, a->count);
    }
  }
  return IRIS_OK;
}

/* Pointer to element `i` of accessor `a`'s dense data (NULL when zero-filled). */
static const uint8_t *element_ptr(const iris_gltf_doc *d, const iris_gltf_accessor *a, size_t i) {
  if (a->view < 0) return NULL;
  const iris_gltf_view *v = &d->views[a->view];
  size_t elem = element_size(a->component_type, a->type);
  size_t stride = v->stride ? v->stride : elem;
  return d->buffers[v->buffer].data + v->offset + a->offset + i * stride;
}

/* Reads a (validated) accessor into count * ncomp floats, applying sparse substitution. */
void gltf_read_floats(const iris_gltf_doc *d, const iris_gltf_accessor *a, int ncomp, float *out) {
  size_t cs = component_size(a->component_type);
  for (size_t i = 0; i < a->count; i++) {
    const uint8_t *p = element_ptr(d, a, i);
    for (int k = 0; k < ncomp; k++)
      out[i * (size_t)ncomp + (size_t)k] = p ? load_component(p + (size_t)k * cs, a->component_type, a->normalized) : 0.0f;
  }
  if (!a->sparse) return;
  const iris_gltf_view *iv = &d->views[a->sparse_index_view], *vv = &d->views[a->sparse_value_view];
  const uint8_t *ip = d->buffers[iv->buffer].data + iv->offset + (size_t)a->sparse_index_offset;
  const uint8_t *vp = d->buffers[vv->buffer].data + vv->offset + (size_t)a->sparse_value_offset;
  size_t isize = component_size(a->sparse_index_type), elem = element_size(a->component_type, a->type);
  for (size_t k = 0; k < (size_t)a->sparse_count; k++) {
    uint32_t idx = load_u32(ip + k * isize, a->sparse_index_type);
    for (int j = 0; j < ncomp; j++)
      out[(size_t)idx * (size_t)ncomp + (size_t)j] =
          load_component(vp + k * elem + (size_t)j * cs, a->component_type, a->normalized);
  }
}

static void read_indices(const iris_gltf_doc *d, const iris_gltf_accessor *a, uint32_t *out) {
  for (size_t i = 0; i < a->count; i++) {
    const uint8_t *p = element_ptr(d, a, i);
    out[i] = p ? load_u32(p, a->component_type) : 0;
  }
  if (!a->sparse) return;
  const iris_gltf_view *iv = &d->views[a->sparse_index_view], *vv = &d->views[a->sparse_value_view];
  const uint8_t *ip = d->buffers[iv->buffer].data + iv->offset + (size_t)a->sparse_index_offset;
  const uint8_t *vp = d->buffers[vv->buffer].data + vv->offset + (size_t)a->sparse_value_offset;
  size_t isize = component_size(a->sparse_index_type), vsize = component_size(a->component_type);
  for (size_t k = 0; k < (size_t)a->sparse_count; k++)
    out[load_u32(ip + k * isize, a->sparse_index_type)] = load_u32(vp + k * vsize, a->component_type);
}

/* Reads elements used[0..count) of an accessor (all of them when used is NULL). */
static bool read_attribute(const iris_gltf_doc *d, const iris_gltf_accessor *a, int ncomp,
                           const uint32_t *used, size_t count, float *out) {
  if (!used) {
    gltf_read_floats(d, a, ncomp, out);
    return true;
  }
  if (a->sparse) { /* substitutions are listed by element: decode all, then gather */
    float *all = malloc(a->count * (size_t)ncomp * sizeof(float));
    if (!all) return false;
    gltf_read_floats(d, a, ncomp, all);
    for (size_t i = 0; i < count; i++)
      memcpy(out + i * (size_t)ncomp, all + (size_t)used[i] * (size_t)ncomp, (size_t)ncomp * sizeof(float));
    free(all);
    return true;
  }
  const size_t cs = component_size(a->component_type);
  for (size_t i = 0; i < count; i++) {
    const uint8_t *p = element_ptr(d, a, used[i]);
    for (int k = 0; k < ncomp; k++)
      out[i * (size_t)ncomp + (size_t)k] = p ? load_component(p + (size_t)k * cs, a->component_type, a->normalized) : 0.0f;
  }
  return true;
}

static int cmp_u32(const void *a, const void *b) {
  const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
  return x < y ? -1 : x > y;
}

/* The vertices a primitive's indices use, renumbered in place to 0..count-1
 * (in the accessors' order). *used (c->prim_used) is NULL when it uses all nv.
 * Primitives often share one vertex buffer and draw slices of it: copying all
 * nv vertices per primitive made the work (and memory) primitives x vertices.
 * The marks are stamped per call, so the cost is O(ni log ni), not O(nv). */
static bool primitive_vertices(gltf_ctx *c, uint32_t *idx, size_t ni, size_t nv, uint32_t **used, size_t *count) {
  *used = NULL, *count = nv;
  if (nv > c->vertex_cap) {
    uint32_t *mark = realloc(c->vertex_mark, nv * sizeof *mark);
    if (mark) c->vertex_mark = mark;
    uint32_t *remap = mark ? realloc(c->vertex_remap, nv * sizeof *remap) : NULL;
    if (remap) c->vertex_remap = remap;
    if (!mark || !remap) return false;
    memset(mark + c->vertex_cap, 0, (nv - c->vertex_cap) * sizeof *mark);
    c->vertex_cap = nv;
  }
  if (++c->vertex_stamp == 0) { /* wrapped: clear the marks once */
    memset(c->vertex_mark, 0, c->vertex_cap * sizeof *c->vertex_mark);
    c->vertex_stamp = 1;
  }
  if (ni > c->prim_used_cap) {
    uint32_t *p = realloc(c->prim_used, ni * sizeof *p);
    if (!p) return false;
    c->prim_used = p, c->prim_used_cap = ni;
  }
  uint32_t *list = c->prim_used;
  size_t k = 0;
  for (size_t i = 0; i < ni; i++)
    if (c->vertex_mark[idx[i]] != c->vertex_stamp) c->vertex_mark[idx[i]] = c->vertex_stamp, list[k++] = idx[i];
  if (k == nv) return true; /* all used: keep the file's numbering */
  qsort(list, k, sizeof *list, cmp_u32);
  for (size_t j = 0; j < k; j++) c->vertex_remap[list[j]] = (uint32_t)j;
  for (size_t i = 0; i < ni; i++) idx[i] = c->vertex_remap[idx[i]];
  *used = list, *count = k;
  return true;
}

/* ---- meshes -------------------------------------------------------------- */

static void note_ignored_attribute(gltf_ctx *c, const char *name) {
  /* Keep one entry per name; group numbered sets (TEXCOORD_1, JOINTS_0) as-is. */
  const char *p = c->ignored_attributes;
  size_t n = strlen(name);
  while ((p = strstr(p, name)) != NULL) {
    if ((p == c->ignored_attributes || p[-1] == ' ') && (p[n] == ',' || p[n] == '\0')) return;
    p += n;
  }
  size_t used = strlen(c->ignored_attributes);
  if (used + n + 3 >= sizeof c->ignored_attributes) return;
  snprintf(c->ignored_attributes + used, sizeof c->ignored_attributes - used, "%s%s",
           used ? ", " : "", name);
}

static void free_mesh_arrays(iris_mesh *m) {
  free(m->name);
  free(m->positions);
  free(m->normals);
  free(m->uvs);
  free(m->colors);
  free(m->uvs1);
  free(m->tangents);
  free(m->alphas);
  free(m->indices);
  memset(m, 0, sizeof *m);
}

/* Looks up an attribute accessor; checks its type and vertex count. */
static iris_status attribute_accessor(gltf_ctx *c, const iris_gltf_primitive *p, const char *name,
                                      const char *el, int want_type, int alt_type, size_t want_count,
                                      const iris_gltf_accessor **out) {
  *out = NULL;
  for (size_t i = 0; i < p->attribute_count; i++) {
    if (strcmp(p->attributes[i].name, name) != 0) continue;
    const iris_gltf_accessor *a = &c->doc->accessors[p->attributes[i].accessor];
    if (a->type != want_type && a->type != alt_type)
      return gltf_fail(c, IRIS_ERR_INVALID, el, "%s accessor %d has type %s", name,
                  p->attributes[i].accessor, type_name(a->type));
    if (want_count && a->count != want_count)
      return gltf_fail(c, IRIS_ERR_INVALID, el, "%s accessor %d has %zu elements but POSITION has %zu",
                  name, p->attributes[i].accessor, a->count, want_count);
    *out = a;
    return IRIS_OK;
  }
  return IRIS_OK;
}

static iris_status check_finite_array(gltf_ctx *c, const float *v, size_t n, const char *el,
                                      const char *what) {
  for (size_t i = 0; i < n; i++)
    if (!isfinite(v[i]))
      return gltf_fail(c, IRIS_ERR_INVALID, el, "non-finite %s value %g at element %zu", what, (double)v[i],
                  i);
  return IRIS_OK;
}

static iris_status convert_primitive(gltf_ctx *c, size_t mi, size_t pi, converted_prim *out) {
  const iris_gltf_doc *d = c->doc;
  const iris_gltf_mesh *gm = &d->meshes[mi];
  const iris_gltf_primitive *p = &gm->primitives[pi];
  char el[96];
  ELEMENT(el, "mesh %zu primitive %zu", mi, pi);
  memset(out, 0, sizeof *out);
  out->scene_mesh = -1;

  for (size_t i = 0; i < p->attribute_count; i++) {
    int ai = p->attributes[i].accessor;
    if (ai < 0 || (size_t)ai >= d->accessor_count)
      return gltf_fail(c, IRIS_ERR_INVALID, el, "attribute %s: accessor %d does not exist",
                  p->attributes[i].name, ai);
    const char *n = p->attributes[i].name;
    if (strcmp(n, "POSITION") && strcmp(n, "NORMAL") && strcmp(n, "TEXCOORD_0") && strcmp(n, "COLOR_0") &&
        strcmp(n, "TEXCOORD_1") && strcmp(n, "TANGENT"))
      note_ignored_attribute(c, n);
  }
  if (p->indices != -1 && (p->indices < 0 || (size_t)p->indices >= d->accessor_count))
    return gltf_fail(c, IRIS_ERR_INVALID, el, "indices accessor %d does not exist (%zu accessors)",
                p->indices, d->accessor_count);
  if (p->material != -1 && (p->material < 0 || (size_t)p->material >= d->material_count))
    return gltf_fail(c, IRIS_ERR_INVALID, el, "material %d does not exist (%zu materials)", p->material,
                d->material_count);
  const int mat = out->gltf_material = gltf_variant_material(c, mi, pi); /* default or the variant's */
  int mode = p->mode < 0 ? MODE_TRIANGLES : p->mode;
  if (mode > MODE_FAN) return gltf_fail(c, IRIS_ERR_INVALID, el, "invalid mode %d", p->mode);
  if (p->target_count) c->warned_morph = true;
  if (mode < MODE_TRIANGLES) {
    c->skipped_points_lines++;
    return IRIS_OK;
  }
  const iris_gltf_accessor *pos, *nrm, *uv, *col, *uv1, *tan;
  iris_status st = attribute_accessor(c, p, "POSITION", el, TYPE_VEC3, TYPE_VEC3, 0, &pos);
  if (st) return st;
  if (!pos) {
    c->skipped_no_position++;
    return IRIS_OK;
  }
  if (pos->count > UINT32_MAX) return gltf_fail(c, IRIS_ERR_NOMEM, el, "more than 2^32 vertices");
  size_t nv = pos->count;
  if ((st = attribute_accessor(c, p, "NORMAL", el, TYPE_VEC3, TYPE_VEC3, nv, &nrm)) ||
      (st = attribute_accessor(c, p, "TEXCOORD_0", el, TYPE_VEC2, TYPE_VEC2, nv, &uv)) ||
      (st = attribute_accessor(c, p, "COLOR_0", el, TYPE_VEC3, TYPE_VEC4, nv, &col)) ||
      (st = attribute_accessor(c, p, "TEXCOORD_1", el, TYPE_VEC2, TYPE_VEC2, nv, &uv1)) ||
      (st = attribute_accessor(c, p, "TANGENT", el, TYPE_VEC4, TYPE_VEC4, nv, &tan)))
    return st;
  /* Tangent frames only for a normal map or anisotropy, and only with NORMAL: "When
   * normals are not specified, [...] the provided tangents (if present) MUST be ignored". */
  int normal_set = gltf_material_tangent_uv_set(c, mat);
  bool has_normal_map = gltf_material_normal_uv_set(c, mat) >= 0;
  if (normal_set >= 0 && !nrm) {
    if (has_normal_map) c->normal_map_no_normal++;
    normal_set = -1;
  } else if (normal_set >= 0 && !(normal_set ? uv1 : uv) && !tan) {
    if (has_normal_map) c->normal_map_no_uv++;
    normal_set = -1;
  }
  if (normal_set < 0) tan = NULL;
  /* The second uv set is kept only when the material reads it (and must then exist:
   * the glTF validator's "material needs TEXCOORD_1" error). */
  if (!gltf_material_uses_uv1(c, mat)) uv1 = NULL;
  else if (!uv1)
    return gltf_fail(c, IRIS_ERR_INVALID, el,
                     "material %d reads a texture through texCoord 1 but the primitive has no TEXCOORD_1", mat);
  const iris_gltf_accessor *ia = p->indices >= 0 ? &d->accessors[p->indices] : NULL;
  if (ia && (ia->type != TYPE_SCALAR || ia->normalized ||
             (ia->component_type != CT_UBYTE && ia->component_type != CT_USHORT &&
              ia->component_type != CT_UINT)))
    return gltf_fail(c, IRIS_ERR_INVALID, el, "indices accessor %d must be unsigned integer SCALAR",
                p->indices);
  size_t ni = ia ? ia->count : nv;
  if (mode == MODE_TRIANGLES && ni % 3 != 0)
    return gltf_fail(c, IRIS_ERR_INVALID, el, "TRIANGLES with %zu indices (not a multiple of 3)", ni);
  if ((ni ? ni : 1) > c->prim_indices_cap) {
    uint32_t *pi_ = realloc(c->prim_indices, (ni ? ni : 1) * sizeof *pi_);
    if (!pi_) return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
    c->prim_indices = pi_, c->prim_indices_cap = ni ? ni : 1;
  }
  uint32_t *idx = c->prim_indices;
  if (ia) {
    read_indices(d, ia, idx);
    for (size_t i = 0; i < ni; i++)
      if (idx[i] >= nv) {
        char iel[64];
        ELEMENT(iel, "accessor %d", p->indices);
        return gltf_fail(c, IRIS_ERR_INVALID, iel, "index %u at %zu >= vertex count %zu (%s)", idx[i], i, nv, el);
      }
  } else {
    for (size_t i = 0; i < ni; i++) idx[i] = (uint32_t)i;
  }
  /* Only the vertices this primitive uses are converted (renumbered in idx). */
  const size_t nv_file = nv;
  uint32_t *used = NULL;
  if (ia && !primitive_vertices(c, idx, ni, nv, &used, &nv))
    return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");

  /* Budget: converted data may exceed the file's buffers only by the expansion of
   * small types (u8 -> float, strip -> list), unless accessors are reused by many
   * primitives or are zero-filled; both could otherwise demand unbounded memory. */
  size_t nt_max = mode == MODE_TRIANGLES ? ni / 3 : (ni >= 3 ? ni - 2 : 0);
  /* (tangents: 16 bytes, and generation may double the vertices at mirror seams) */
  double need = (double)nv * (12.0 + (nrm ? 12 : 0) + (uv ? 8 : 0) + (col ? 32 : 0) + (uv1 ? 8 : 0) +
                              (normal_set >= 0 ? 16.0 + 12 + 12 + (uv ? 8 : 0) + (col ? 12 : 0) + (uv1 ? 8 : 0) : 0)) +
                (double)ni * 4.0 + (double)nt_max * 12.0;
  if (used) /* sparse accessors are decoded whole before the gather */
    need += (double)nv_file * ((pos->sparse ? 12 : 0) + (nrm && nrm->sparse ? 12 : 0) + (uv && uv->sparse ? 8 : 0) +
                               (uv1 && uv1->sparse ? 8 : 0) + (tan && tan->sparse ? 16 : 0) +
                               (col && col->sparse ? 16 : 0));
  if (need > (double)c->budget_left)
    return gltf_fail(c, IRIS_ERR_NOMEM, el,
                "mesh data would exceed %zu MiB (%g MiB for this primitive; accessors reused by "
                "many primitives or without a bufferView?)",
                c->budget_total >> 20, need / 1048576.0);
  c->budget_left -= (size_t)need;

  iris_mesh *m = &out->mesh;
  m->owned = true;
  m->material = -1;
  m->vertex_count = (uint32_t)nv;
  m->positions = malloc(nv * 3 * sizeof(float));
  if (!m->positions) return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
  if (!read_attribute(d, pos, 3, used, nv, m->positions)) return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
  char ael[128];
  ELEMENT(ael, "accessor %d", (int)(pos - d->accessors));
  if ((st = check_finite_array(c, m->positions, nv * 3, ael, "POSITION"))) return st;

  if (nrm) {
    m->normals = malloc(nv * 3 * sizeof(float));
    if (!m->normals) return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
    if (!read_attribute(d, nrm, 3, used, nv, m->normals)) return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
    if ((st = check_finite_array(c, m->normals, nv * 3, el, "NORMAL"))) return st;
    bool zero = false;
    for (size_t i = 0; i < nv; i++) {
      float *n = m->normals + 3 * i;
      float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      if (!(len > 0.0f) || !isfinite(1.0f / len)) {
        zero = true;
        break;
      }
      n[0] /= len, n[1] /= len, n[2] /= len;
    }
    if (zero) { /* unusable: drop them, the primitive is shaded flat */
      free(m->normals);
      m->normals = NULL;
      c->zero_normals++;
    }
  }
  if (uv) {
    m->uvs = malloc(nv * 2 * sizeof(float));
    if (!m->uvs) return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
    if (!read_attribute(d, uv, 2, used, nv, m->uvs)) return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
    if ((st = check_finite_array(c, m->uvs, nv * 2, el, "TEXCOORD_0"))) return st;
  }
  if (uv1) {
    m->uvs1 = malloc(nv * 2 * sizeof(float));
    if (!m->uvs1) return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
    if (!read_attribute(d, uv1, 2, used, nv, m->uvs1)) return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
    if ((st = check_finite_array(c, m->uvs1, nv * 2, el, "TEXCOORD_1"))) return st;
  }
  if (tan && m->normals) {
    m->tangents = malloc(nv * 4 * sizeof(float));
    if (!m->tangents) return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
    if (!read_attribute(d, tan, 4, used, nv, m->tangents)) return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
    if ((st = check_finite_array(c, m->tangents, nv * 4, el, "TANGENT"))) return st;
    for (size_t i = 0; i < nv; i++) {
      float *t = m->tangents + 4 * i;
      float len = sqrtf(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
      if (!(len > 0.0f) || !isfinite(1.0f / len)) { /* unusable: generate instead */
        free(m->tangents);
        m->tangents = NULL;
        break;
      }
      t[0] /= len, t[1] /= len, t[2] /= len;
      t[3] = t[3] < 0.0f ? -1.0f : 1.0f;
    }
  }
  if (col) {
    int nc = col->type == TYPE_VEC4 ? 4 : 3;
    float *tmp = malloc(nv * (size_t)nc * sizeof(float));
    m->colors = malloc(nv * 3 * sizeof(float));
    if (!tmp || !m->colors) {
      free(tmp);
      return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
    }
    if (!read_attribute(d, col, nc, used, nv, tmp)) {
      free(tmp);
      return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
    }
    if ((st = check_finite_array(c, tmp, nv * (size_t)nc, el, "COLOR_0"))) {
      free(tmp);
      return st;
    }
    for (size_t i = 0; i < nv; i++)
      for (int k = 0; k < 3; k++) m->colors[3 * i + (size_t)k] = tmp[(size_t)nc * i + (size_t)k];
    /* COLOR_0's alpha is kept only where it matters: a MASK/BLEND material and some alpha < 1 */
    bool alpha = false;
    if (nc == 4 && gltf_material_alpha_mode(c, mat) != IRIS_ALPHA_OPAQUE)
      for (size_t i = 0; i < nv && !alpha; i++) alpha = tmp[4 * i + 3] != 1.0f;
    if (alpha) {
      m->alphas = malloc(nv * sizeof(float));
      if (!m->alphas) {
        free(tmp);
        return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
      }
      for (size_t i = 0; i < nv; i++) {
        float a = tmp[4 * i + 3];
        m->alphas[i] = a < 0.0f ? 0.0f : a > 1.0f ? 1.0f : a; /* (normalised integers are in range) */
      }
    }
    free(tmp);
    if ((st = check_finite_array(c, m->colors, nv * 3, el, "COLOR_0"))) return st;
  }

  /* Triangle list per glTF 2.0 section 3.7.2.1 (strip and fan orders). */
  size_t nt = mode == MODE_TRIANGLES ? ni / 3 : (ni >= 3 ? ni - 2 : 0);
  if (nt > UINT32_MAX) return gltf_fail(c, IRIS_ERR_NOMEM, el, "more than 2^32 triangles");
  m->indices = malloc((nt ? nt : 1) * 3 * sizeof(uint32_t));
  if (!m->indices) return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
  size_t kept = 0;
  for (size_t t = 0; t < nt; t++) {
    uint32_t a, b, e;
    if (mode == MODE_TRIANGLES) {
      a = idx[3 * t], b = idx[3 * t + 1], e = idx[3 * t + 2];
    } else if (mode == MODE_STRIP) {
      a = idx[t], b = idx[t + 1 + t % 2], e = idx[t + 2 - t % 2];
    } else {
      a = idx[t + 1], b = idx[t + 2], e = idx[0];
    }
    if (a == b || b == e || a == e) {
      c->degenerate_dropped++;
      continue;
    }
    m->indices[3 * kept] = a, m->indices[3 * kept + 1] = b, m->indices[3 * kept + 2] = e;
    kept++;
  }
  m->triangle_count = (uint32_t)kept;
  /* Shared last step (meshproc.h): zero-area triangles out, optional welding.
   * Never computed normals: glTF 2.0 section 3.7.2.1 says "When normals are not
   * specified, client implementations MUST calculate flat normals", and a mesh
   * without normals is shaded with its geometric (flat) normal. */
  uint32_t removed = 0;
  if (kept > 0 && !iris_mesh_finish(m, false, c->opts->weld, &removed))
    return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
  c->degenerate_dropped += removed;
  if (normal_set >= 0 && m->normals && !m->tangents && m->triangle_count > 0 && (normal_set ? m->uvs1 : m->uvs)) {
    uint32_t split = 0;
    if (!iris_mesh_generate_tangents(m, normal_set, &split)) return gltf_fail(c, IRIS_ERR_NOMEM, el, "out of memory");
    c->tangents_generated++;
    c->tangents_split += split;
  }
  if (mat >= 0 && c->materials[mat].anisotropy > 0.0f && !m->tangents && m->triangle_count > 0)
    c->anisotropy_no_tangents++;
  if (m->triangle_count == 0) {
    c->skipped_empty++;
    free_mesh_arrays(m);
    return IRIS_OK;
  }
  char name[256];
  const char *base = gm->name && gm->name[0] ? gm->name : "mesh";
  if (gm->primitive_count > 1)
    snprintf(name, sizeof name, "%s#%zu", base, pi);
  else
    snprintf(name, sizeof name, "%s", base);
  m->name = iris_strdup(name);
  out->valid = true;
  return IRIS_OK;
}

static iris_status convert_meshes(gltf_ctx *c) {
  const iris_gltf_doc *d = c->doc;
  c->prims = calloc(d->mesh_count ? d->mesh_count : 1, sizeof *c->prims);
  if (!c->prims) return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
  for (size_t mi = 0; mi < d->mesh_count; mi++) {
    size_t np = d->meshes[mi].primitive_count;
    if (np == 0) {
      char el[32];
      ELEMENT(el, "mesh %zu", mi);
      return gltf_fail(c, IRIS_ERR_INVALID, el, "has no primitives");
    }
    c->prims[mi] = calloc(np, sizeof **c->prims);
    if (!c->prims[mi]) return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
    for (size_t pi = 0; pi < np; pi++) {
      if (iris_cancel_requested()) /* Ctrl-C: core/cancel.h */
        return gltf_fail(c, IRIS_ERR_INTERRUPTED, NULL, "interrupted while loading the scene");
      iris_status st = convert_primitive(c, mi, pi, &c->prims[mi][pi]);
      if (st) return st;
    }
  }
  return IRIS_OK;
}

/* ---- top level ----------------------------------------------------------- */

static iris_status check_asset(gltf_ctx *c) {
  const iris_gltf_doc *d = c->doc;
  const char *v = d->version ? d->version : "";
  if (strncmp(v, "2.", 2) != 0)
    return gltf_fail(c, IRIS_ERR_UNSUPPORTED, "asset", "version '%s' is not glTF 2.x", v);
  if (d->min_version && d->min_version[0] && strcmp(d->min_version, "2.0") != 0)
    return gltf_fail(c, IRIS_ERR_UNSUPPORTED, "asset", "minVersion '%s' is newer than 2.0", d->min_version);
  iris_status st = iris_gltf_check_required(d->extensions_required, d->extensions_required_count,
                                            c->file, c->err);
  if (st) return st;
  char list[400] = "";
  size_t used = 0;
  for (size_t i = 0; i < d->extensions_used_count; i++) {
    /* KHR_texture_basisu: its fallback source is used, with its own notice (gltf_material.c). */
    /* KHR_materials_dispersion: its own warning naming the materials (report_ignored). */
    if (is_supported_extension(d->extensions_used[i]) || strcmp(d->extensions_used[i], "KHR_texture_basisu") == 0 ||
        strcmp(d->extensions_used[i], "KHR_materials_dispersion") == 0)
      continue;
    int w = snprintf(list + used, sizeof list - used, "%s%s", used ? ", " : "", d->extensions_used[i]);
    if (w > 0) used += (size_t)w < sizeof list - used ? (size_t)w : sizeof list - used - 1;
  }
  if (used) iris_warnf("%s: ignoring unsupported extensions: %s", c->file, list);
  return IRIS_OK;
}

static void report_ignored(gltf_ctx *c) {
  const char *f = c->file;
  if (c->ignored_attributes[0]) iris_warnf("%s: ignoring vertex attributes: %s", f, c->ignored_attributes);
  if (c->skipped_points_lines)
    iris_warnf("%s: skipped %zu point/line primitive(s) (iris renders triangles)", f, c->skipped_points_lines);
  if (c->skipped_no_position)
    iris_warnf("%s: skipped %zu primitive(s) without POSITION", f, c->skipped_no_position);
  if (c->skipped_empty) iris_warnf("%s: skipped %zu primitive(s) with no triangles", f, c->skipped_empty);
  if (c->degenerate_dropped)
    iris_warnf("%s: dropped %zu degenerate triangle(s) (repeated vertex or zero area)", f,
               c->degenerate_dropped);
  if (c->zero_normals)
    iris_warnf("%s: %zu primitive(s) had zero-length normals; their normals were dropped (shaded flat)", f, c->zero_normals);
  if (c->warned_texcoord) iris_warnf("%s: textures using TEXCOORD_2 or higher are ignored", f);
  if (c->warned_occlusion) iris_warnf("%s: occlusion textures are ignored (a path tracer has its own)", f);
  if (c->normal_map_no_normal)
    iris_warnf("%s: %zu primitive(s) without NORMAL are shaded flat, without their normal map", f,
               c->normal_map_no_normal);
  if (c->normal_map_no_uv)
    iris_warnf("%s: %zu primitive(s) lack the uv set of their normal map, which is not applied", f,
               c->normal_map_no_uv);
  if (c->anisotropy_no_tangents)
    iris_warnf("%s: %zu anisotropic primitive(s) have no tangent frame (no NORMAL, or no uvs to make tangents "
               "from) and are shaded isotropic", f, c->anisotropy_no_tangents);
  if (c->dispersion_count)
    iris_warnf("%s: KHR_materials_dispersion in material(s) %s: dispersion is not rendered: the ior alone is used",
               f, c->dispersion_materials);
  if (c->warned_morph) iris_warnf("%s: morph targets ignored (base shape used)", f);
  if (c->warned_skin) iris_warnf("%s: skins ignored (bind pose used)", f);
  if (c->warned_ortho) iris_warnf("%s: orthographic cameras skipped", f);
  if (c->warned_matrix_trs) iris_warnf("%s: nodes with both matrix and TRS: matrix used", f);
  if (c->doc->animation_count) iris_warnf("%s: %zu animation(s) ignored", f, c->doc->animation_count);
  if (c->scene->instance_count == 0) iris_warnf("%s: the scene has no mesh instances", f);
}

static void ctx_free(gltf_ctx *c) {
  const iris_gltf_doc *d = c->doc;
  if (c->prims) {
    for (size_t mi = 0; mi < d->mesh_count; mi++) {
      if (!c->prims[mi]) continue;
      for (size_t pi = 0; pi < d->meshes[mi].primitive_count; pi++) free_mesh_arrays(&c->prims[mi][pi].mesh);
      free(c->prims[mi]);
    }
    free(c->prims);
  }
  free(c->materials);
  free(c->material_map);
  free(c->slots);
  free(c->tex_keys);
  free(c->parent);
  free(c->world);
  free(c->vertex_mark), free(c->vertex_remap), free(c->prim_indices), free(c->prim_used);
}

iris_status iris_gltf_convert(const iris_gltf_doc *doc, const iris_import_options *opts,
                              iris_scene **out, iris_error *err) {
  gltf_ctx c;
  memset(&c, 0, sizeof c);
  iris_import_options defaults = iris_import_options_default();
  c.doc = doc;
  c.opts = opts ? opts : &defaults;
  c.file = doc->file;
  c.err = err;
  c.default_material = -1;
  *out = NULL;
  iris_status st = check_asset(&c);
  if (st) return st;
  c.scene = iris_scene_create();
  c.material_map = malloc((doc->material_count ? doc->material_count : 1) * sizeof *c.material_map);
  if (!c.scene || !c.material_map) {
    st = gltf_fail(&c, IRIS_ERR_NOMEM, NULL, "out of memory");
    goto done;
  }
  for (size_t i = 0; i < doc->material_count; i++) c.material_map[i] = -1;
  c.budget_total = MESH_BUDGET_SLACK;
  for (size_t i = 0; i < doc->buffer_count; i++) {
    size_t add = doc->buffers[i].size > SIZE_MAX / 32 ? SIZE_MAX / 32 : doc->buffers[i].size * 16;
    c.budget_total = c.budget_total > SIZE_MAX / 2 - add ? SIZE_MAX / 2 : c.budget_total + add;
  }
  c.budget_left = c.budget_total;
  c.sparse_left = (size_t)1 << 20;
  for (size_t i = 0; i < doc->buffer_count; i++)
    c.sparse_left += doc->buffers[i].size > SIZE_MAX / 8 ? SIZE_MAX / 8 : 4 * doc->buffers[i].size;
  /* Validate everything first (even what the scene does not use), then build. */
  if ((st = validate_views(&c)) || (st = validate_accessors(&c)) || (st = gltf_validate_textures(&c)) ||
      (st = gltf_validate_materials(&c)) || (st = gltf_validate_variants(&c)) || (st = gltf_validate_cameras_lights(&c)) ||
      (st = gltf_validate_node_graph(&c)) || (st = convert_meshes(&c)) || (st = gltf_place_nodes(&c)) ||
      (st = gltf_store_variants(&c)))
    goto done;
  snprintf(c.scene->units, sizeof c.scene->units, "m"); /* glTF 2.0: metres */
  c.scene->source_path = iris_strdup(doc->file);
  report_ignored(&c);
  st = iris_scene_validate(c.scene, c.file, err);
done:
  ctx_free(&c);
  if (st != IRIS_OK) {
    iris_scene_destroy(c.scene);
    return st;
  }
  *out = c.scene;
  return IRIS_OK;
}
