/* Wavefront OBJ importer: a single-pass line parser into global attribute
 * arrays and per-(group, material) face lists, then one iris_mesh per
 * (group, material) with vertices deduplicated per (v, vt, vn). MTL libraries
 * and materials: obj_mtl.c. Every decision is in docs/import-obj-ply.md. */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/cancel.h"
#include "core/fileio.h"
#include "core/log.h"
#include "importers/mapped.h"
#include "importers/meshproc.h"
#include "importers/obj_private.h"

/* ---- OBJ parsing -------------------------------------------------------- */

static obj_group *current_group(obj_ctx *c) {
  if (c->cur_group != SIZE_MAX) return &c->groups[c->cur_group];
  char key[2 * OBJ_NAME_MAX + 2]; /* names never hold a newline */
  snprintf(key, sizeof key, "%s\n%s", c->cur_name, c->cur_material);
  const int32_t *found = iris_strmap_find(&c->group_map, key);
  if (found) {
    c->cur_group = (size_t)*found;
    return &c->groups[c->cur_group];
  }
  if (c->group_count >= INT32_MAX ||
      !grow((void **)&c->groups, &c->group_cap, c->group_count + 1, sizeof *c->groups))
    return NULL;
  iris_strmap_put(&c->group_map, key, (int32_t)c->group_count);
  obj_group *g = &c->groups[c->group_count];
  memset(g, 0, sizeof *g);
  memcpy(g->name, c->cur_name, sizeof g->name);
  memcpy(g->material, c->cur_material, sizeof g->material);
  c->cur_group = c->group_count++;
  return g;
}

static iris_status parse_face(obj_ctx *c, const char *p, const char *le, long line) {
  obj_group *g = current_group(c);
  if (!g) return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, line, NULL, "out of memory");
  const size_t first = g->corner_count;
  const int64_t counts[3] = {(int64_t)(c->pos.count / 3), (int64_t)(c->uv.count / 2),
                             (int64_t)(c->nrm.count / 3)};
  static const char *what[3] = {"vertex", "texture coordinate", "normal"};
  uint32_t n = 0;
  bool missing_vn = false;
  for (;;) {
    p = iris_np_skip_space(p, le);
    if (p >= le) break;
    int32_t idx[3] = {OBJ_NO_INDEX, OBJ_NO_INDEX, OBJ_NO_INDEX};
    for (int k = 0; k < 3; k++) {
      if (k > 0) {
        if (p < le && *p == '/') p++;
        else break;
        if (p < le && *p == '/') continue; /* v//vn */
        if (p >= le || iris_np_is_space(*p)) break;
      }
      int64_t v;
      if (!iris_parse_int(&p, le, &v) || (p < le && !iris_np_is_space(*p) && *p != '/'))
        return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL,
                              "malformed face corner (expected v, v/vt, v//vn or v/vt/vn)");
      if (v == 0)
        return iris_error_set(c->err, IRIS_ERR_INVALID, c->path, line, NULL,
                              "%s index 0 (OBJ indices start at 1)", what[k]);
      if (v < 0) {
        v += counts[k];
        if (v < 0)
          return iris_error_set(c->err, IRIS_ERR_INVALID, c->path, line, NULL,
                                "relative %s index refers before the first %s (%lld defined so far)",
                                what[k], what[k], (long long)counts[k]);
      } else {
        v -= 1;
        if (v >= INT32_MAX)
          return iris_error_set(c->err, IRIS_ERR_INVALID, c->path, line, NULL,
                                "%s index %lld too large", what[k], (long long)v + 1);
        if (v + 1 > c->max_idx[k]) c->max_idx[k] = v + 1, c->max_line[k] = line;
      }
      idx[k] = (int32_t)v;
    }
    if (p < le && !iris_np_is_space(*p))
      return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL,
                            "malformed face corner (expected v, v/vt, v//vn or v/vt/vn)");
    if (idx[1] != OBJ_NO_INDEX) g->any_vt = true;
    if (idx[2] != OBJ_NO_INDEX) g->any_vn = true;
    else missing_vn = true;
    if (!grow((void **)&g->corners, &g->corner_cap, 3 * (g->corner_count + 1), sizeof(int32_t)))
      return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, line, NULL, "out of memory");
    memcpy(g->corners + 3 * g->corner_count, idx, sizeof idx);
    g->corner_count++;
    n++;
  }
  if (n < 3) {
    g->corner_count = first; /* drop points and lines written as faces */
    if (!c->dropped_faces++) c->dropped_faces_line = line;
    return IRIS_OK;
  }
  if (missing_vn) {
    if (c->smooth) {
      g->needs_normals = true;
    } else {
      g->any_flat = true;
      for (size_t i = first; i < g->corner_count; i++)
        if (g->corners[3 * i + 2] == OBJ_NO_INDEX) g->corners[3 * i + 2] = OBJ_FLAT;
    }
  }
  if (!grow((void **)&g->face_sizes, &g->face_cap, g->face_count + 1, sizeof(uint32_t)))
    return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, line, NULL, "out of memory");
  g->face_sizes[g->face_count++] = n;
  return IRIS_OK;
}

static iris_status parse_obj(obj_ctx *c, const char *data, size_t size) {
  const char *p = data, *end = data + size;
  long line = 0;
  while (p < end) {
    const char *e = line_end(p, end);
    line++;
    if ((line & 0xffff) == 0 && iris_cancel_requested()) /* Ctrl-C: core/cancel.h */
      return iris_error_set(c->err, IRIS_ERR_INTERRUPTED, c->path, line, NULL, "interrupted while loading the scene");
    const char *le = strip_comment(p, e);
    const char *k = iris_np_skip_space(p, le);
    const char *ke = k;
    while (ke < le && !iris_np_is_space(*ke)) ke++;
    size_t kn = (size_t)(ke - k);
    const char *a = ke;
    iris_status st = IRIS_OK;
#define KEY(s) (kn == sizeof(s) - 1 && !memcmp(k, s, kn))
    if (kn == 0) {
    } else if (KEY("v")) {
      float v[7];
      int n;
      if (!parse_floats(&a, le, v, 7, &n) || n < 3 || n == 5)
        return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL,
                              "malformed vertex (expected 'v x y z [w]' or 'v x y z r g b')");
      if (!all_finite(v, n))
        return iris_error_set(c->err, IRIS_ERR_INVALID, c->path, line, NULL,
                              "vertex has a non-finite value (NaN or infinity)");
      if (!floats_push(&c->pos, v, 3))
        return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, line, NULL, "out of memory");
      if (n >= 6 && !c->has_colors) {
        /* First coloured vertex: earlier vertices get white. */
        c->has_colors = true;
        float white[3] = {1, 1, 1};
        for (size_t i = 0; i + 1 < c->pos.count / 3; i++)
          if (!floats_push(&c->col, white, 3))
            return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, line, NULL, "out of memory");
      }
      if (c->has_colors) {
        float white[3] = {1, 1, 1};
        if (!floats_push(&c->col, n >= 6 ? v + 3 : white, 3))
          return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, line, NULL, "out of memory");
      }
    } else if (KEY("vt")) {
      float v[3] = {0, 0, 0};
      int n;
      if (!parse_floats(&a, le, v, 3, &n) || n < 1)
        return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL,
                              "malformed texture coordinate (expected 'vt u [v [w]]')");
      if (!all_finite(v, n))
        return iris_error_set(c->err, IRIS_ERR_INVALID, c->path, line, NULL,
                              "texture coordinate has a non-finite value");
      v[1] = 1.0f - v[1]; /* OBJ: v up from the bottom; iris: v down from the top */
      if (!floats_push(&c->uv, v, 2))
        return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, line, NULL, "out of memory");
    } else if (KEY("vn")) {
      float v[3];
      int n;
      if (!parse_floats(&a, le, v, 3, &n) || n != 3)
        return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL,
                              "malformed normal (expected 'vn x y z')");
      if (!all_finite(v, 3))
        return iris_error_set(c->err, IRIS_ERR_INVALID, c->path, line, NULL,
                              "normal has a non-finite value");
      if (!floats_push(&c->nrm, v, 3))
        return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, line, NULL, "out of memory");
    } else if (KEY("f")) {
      st = parse_face(c, a, le, line);
    } else if (KEY("g") || KEY("o")) {
      char name[OBJ_NAME_MAX];
      copy_rest(a, le, name, sizeof name);
      if (strcmp(name, c->cur_name)) {
        memcpy(c->cur_name, name, sizeof name);
        c->cur_group = SIZE_MAX;
      }
    } else if (KEY("usemtl")) {
      char name[OBJ_NAME_MAX];
      copy_rest(a, le, name, sizeof name);
      if (strcmp(name, c->cur_material)) {
        memcpy(c->cur_material, name, sizeof name);
        c->cur_group = SIZE_MAX;
      }
    } else if (KEY("mtllib")) {
      obj_load_mtllib(c, a, le, line);
      if (c->err && c->err->status != IRIS_OK) return c->err->status;
    } else if (KEY("s")) {
      const char *q = iris_np_skip_space(a, le);
      c->smooth = !(iris_np_match(q, le, "off") || (q < le && *q == '0' && (q + 1 >= le || iris_np_is_space(q[1]))));
    } else if (KEY("l") || KEY("p")) {
      c->lines_points++;
    } else {
      note_ignored(c->ignored, sizeof c->ignored, k, kn);
    }
#undef KEY
    if (st != IRIS_OK) return st;
    p = e + (e < end);
  }
  /* Strict validation of forward references. */
  const size_t counts[3] = {c->pos.count / 3, c->uv.count / 2, c->nrm.count / 3};
  static const char *what[3] = {"vertex", "texture coordinate", "normal"};
  for (int k = 0; k < 3; k++)
    if ((size_t)c->max_idx[k] > counts[k])
      return iris_error_set(c->err, IRIS_ERR_INVALID, c->path, c->max_line[k], NULL,
                            "%s index %lld out of range (%zu defined)", what[k],
                            (long long)c->max_idx[k], counts[k]);
  if (c->ignored[0]) iris_warnf("%s: OBJ keywords ignored: %s", c->path, c->ignored);
  if (c->dropped_faces)
    iris_warnf("%s:%ld: %ld face(s) with fewer than 3 corners dropped", c->path,
               c->dropped_faces_line, c->dropped_faces);
  if (c->lines_points) iris_warnf("%s: %ld line/point element(s) ignored (iris renders surfaces)",
                                  c->path, c->lines_points);
  return IRIS_OK;
}

/* ---- meshes ------------------------------------------------------------- */

/* Newell normal of a polygon given by position indices. */
static void polygon_normal(const float *pos, const int32_t *corners, uint32_t n, float *out) {
  double nx = 0, ny = 0, nz = 0;
  for (uint32_t i = 0; i < n; i++) {
    const float *a = pos + 3 * (size_t)corners[3 * i];
    const float *b = pos + 3 * (size_t)corners[3 * ((i + 1) % n)];
    nx += ((double)a[1] - b[1]) * ((double)a[2] + b[2]);
    ny += ((double)a[2] - b[2]) * ((double)a[0] + b[0]);
    nz += ((double)a[0] - b[0]) * ((double)a[1] + b[1]);
  }
  double len = sqrt(nx * nx + ny * ny + nz * nz);
  if (len > 0 && isfinite(len)) out[0] = (float)(nx / len), out[1] = (float)(ny / len), out[2] = (float)(nz / len);
  else out[0] = 0, out[1] = 0, out[2] = 1;
}

typedef struct build_scratch {
  iris_polygon_triangulator *tri;
  uint32_t *poly;   /* position indices of one polygon */
  size_t poly_cap;
  uint32_t *ptris;  /* local triangles of one polygon */
  size_t ptris_cap;
  uint32_t *tris;   /* triangles of a group as corner numbers */
  size_t tris_cap;
  int32_t *head;    /* per hash bucket: first local vertex, valid when stamp matches */
  uint32_t *stamp;
  size_t head_cap, stamp_cap;
  int32_t *chain;   /* per local vertex: next in the same bucket */
  size_t chain_cap;
  int64_t *vkey;    /* per local vertex: its normal key */
  size_t vkey_cap;
  float *smooth_normals; /* per position, angle-weighted; NULL when not needed */
  iris_strmap name_counts; /* group name -> number of non-empty groups of that name */
} build_scratch;

/* Triangulates every face of g into s->tris (corner numbers). */
static bool triangulate_group(obj_ctx *c, const obj_group *g, build_scratch *s, size_t *tri_count) {
  size_t total = 0, corner = 0;
  for (size_t f = 0; f < g->face_count; f++) total += g->face_sizes[f] - 2;
  if (!grow((void **)&s->tris, &s->tris_cap, 3 * total, sizeof(uint32_t))) return false;
  size_t out = 0;
  for (size_t f = 0; f < g->face_count; f++) {
    const uint32_t n = g->face_sizes[f];
    if (n == 3) {
      s->tris[out++] = (uint32_t)corner, s->tris[out++] = (uint32_t)corner + 1,
      s->tris[out++] = (uint32_t)corner + 2;
    } else {
      if (!grow((void **)&s->poly, &s->poly_cap, n, sizeof(uint32_t)) ||
          !grow((void **)&s->ptris, &s->ptris_cap, 3 * (size_t)(n - 2), sizeof(uint32_t)))
        return false;
      for (uint32_t i = 0; i < n; i++) s->poly[i] = (uint32_t)g->corners[3 * (corner + i)];
      uint32_t t = iris_polygon_triangulate(s->tri, c->pos.v, s->poly, n, s->ptris);
      if (t == 0) return false;
      for (uint32_t i = 0; i < 3 * t; i++) s->tris[out++] = (uint32_t)corner + s->ptris[i];
    }
    corner += n;
  }
  *tri_count = out / 3;
  return true;
}

static iris_status build_group(obj_ctx *c, size_t gi, build_scratch *s, const char *stem) {
  const obj_group *g = &c->groups[gi];
  if (g->face_count == 0) return IRIS_OK;
  size_t tri_count;
  if (!triangulate_group(c, g, s, &tri_count))
    return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
  if (tri_count > UINT32_MAX / 3 || g->corner_count > UINT32_MAX)
    return iris_error_set(c->err, IRIS_ERR_UNSUPPORTED, c->path, 0, g->name,
                          "mesh too large (more than 2^32 triangles)");
  /* Deduplicate corners into vertices keyed by (v, vt, vn), in a hash table on
   * the whole key (buckets stamped per group, so none is cleared). A chain per
   * position was quadratic when one position carried many texture coordinates. */
  size_t buckets = 64;
  while (buckets < g->corner_count) buckets *= 2;
  const size_t old_stamps = s->stamp_cap;
  if (!grow((void **)&s->chain, &s->chain_cap, g->corner_count, sizeof(int32_t)) ||
      !grow((void **)&s->vkey, &s->vkey_cap, g->corner_count, sizeof(int64_t)) ||
      !grow((void **)&s->head, &s->head_cap, buckets, sizeof(int32_t)) ||
      !grow((void **)&s->stamp, &s->stamp_cap, buckets, sizeof(uint32_t)))
    return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
  memset(s->stamp + old_stamps, 0, (s->stamp_cap - old_stamps) * sizeof(uint32_t));
  uint32_t *corner_vertex = malloc(g->corner_count * sizeof(uint32_t));
  uint32_t *first_corner = malloc(g->corner_count * sizeof(uint32_t)); /* per vertex */
  if (!corner_vertex || !first_corner) {
    free(corner_vertex), free(first_corner);
    return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
  }
  /* Once a mesh has normals every vertex needs one, whatever compute_normals
   * says; a mesh of flat faces only keeps none (the geometric normal). */
  const bool want_normals = g->any_vn || (g->needs_normals && c->opts->compute_normals);
  const uint32_t stamp = (uint32_t)gi + 1;
  uint32_t nv = 0;
  size_t i = 0;
  for (size_t f = 0; f < g->face_count; f++) {
    for (uint32_t j = 0; j < g->face_sizes[f]; j++, i++) {
      const int32_t *k = g->corners + 3 * i;
      /* Corners of flat faces get their own vertices (with the face normal)
       * when the mesh has normals; the key -3 - f keeps them apart. */
      const int64_t kn = k[2] == OBJ_FLAT ? (want_normals ? -3 - (int64_t)f : OBJ_NO_INDEX) : k[2];
      uint64_t h = ((uint64_t)(uint32_t)k[0] << 32 | (uint32_t)k[1]) ^ ((uint64_t)kn * 0x9E3779B97F4A7C15ull);
      h ^= h >> 31, h *= 0xBF58476D1CE4E5B9ull, h ^= h >> 29, h *= 0x94D049BB133111EBull, h ^= h >> 32;
      const size_t b = (size_t)(h & (buckets - 1));
      int32_t v = s->stamp[b] == stamp ? s->head[b] : -1;
      while (v >= 0) {
        const int32_t *o = g->corners + 3 * (size_t)first_corner[v];
        if (o[0] == k[0] && o[1] == k[1] && s->vkey[v] == kn) break;
        v = s->chain[v];
      }
      if (v < 0) {
        v = (int32_t)nv++;
        first_corner[v] = (uint32_t)i;
        s->vkey[v] = kn;
        s->chain[v] = s->stamp[b] == stamp ? s->head[b] : -1;
        s->head[b] = v;
        s->stamp[b] = stamp;
      }
      corner_vertex[i] = (uint32_t)v;
    }
  }
  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.owned = true;
  m.vertex_count = nv;
  m.triangle_count = (uint32_t)tri_count;
  m.positions = malloc(3 * (size_t)nv * sizeof(float));
  m.indices = malloc(3 * tri_count * sizeof(uint32_t) + 1);
  bool ok = m.positions && m.indices;
  if (ok && g->any_vt) ok = (m.uvs = malloc(2 * (size_t)nv * sizeof(float))) != NULL;
  if (ok && c->has_colors) ok = (m.colors = malloc(3 * (size_t)nv * sizeof(float))) != NULL;
  if (ok && want_normals) ok = (m.normals = malloc(3 * (size_t)nv * sizeof(float))) != NULL;
  if (!ok) {
    free(corner_vertex), free(first_corner);
    free(m.positions), free(m.indices), free(m.uvs), free(m.colors), free(m.normals);
    return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
  }
  /* Flat-face normals: computed per face, written to that face's vertices. */
  if (m.normals) {
    size_t corner = 0;
    for (size_t f = 0; f < g->face_count; f++) {
      const uint32_t n = g->face_sizes[f];
      /* A face may mix corners with and without vn ("f 1//1 2 3"): only the
       * corners without one are flat, and any of them may be. */
      bool flat = false;
      for (uint32_t i = 0; i < n; i++) flat |= g->corners[3 * (corner + i) + 2] == OBJ_FLAT;
      if (flat) {
        float fn[3];
        polygon_normal(c->pos.v, g->corners + 3 * corner, n, fn);
        for (uint32_t i = 0; i < n; i++)
          if (g->corners[3 * (corner + i) + 2] == OBJ_FLAT)
            memcpy(m.normals + 3 * (size_t)corner_vertex[corner + i], fn, sizeof fn);
      }
      corner += n;
    }
  }
  for (uint32_t v = 0; v < nv; v++) {
    const int32_t *k = g->corners + 3 * (size_t)first_corner[v];
    memcpy(m.positions + 3 * (size_t)v, c->pos.v + 3 * (size_t)k[0], 3 * sizeof(float));
    if (m.colors) memcpy(m.colors + 3 * (size_t)v, c->col.v + 3 * (size_t)k[0], 3 * sizeof(float));
    if (m.uvs) {
      if (k[1] >= 0) memcpy(m.uvs + 2 * (size_t)v, c->uv.v + 2 * (size_t)k[1], 2 * sizeof(float));
      else m.uvs[2 * (size_t)v] = 0, m.uvs[2 * (size_t)v + 1] = 1; /* (0,0) in OBJ's convention */
    }
    if (m.normals) {
      float *n = m.normals + 3 * (size_t)v;
      if (k[2] >= 0) memcpy(n, c->nrm.v + 3 * (size_t)k[2], 3 * sizeof(float));
      else if (k[2] == OBJ_NO_INDEX) {
        if (s->smooth_normals) memcpy(n, s->smooth_normals + 3 * (size_t)k[0], 3 * sizeof(float));
        else n[0] = 0, n[1] = 0, n[2] = 1;
      }
    }
  }
  for (size_t i = 0; i < 3 * tri_count; i++) m.indices[i] = corner_vertex[s->tris[i]];
  free(corner_vertex);
  free(first_corner);
  /* Name: the group/object name, else the material, else the file stem. */
  char name[2 * OBJ_NAME_MAX + 2];
  const int32_t *named = iris_strmap_find(&s->name_counts, g->name);
  const int same_name = named ? *named : 0;
  if (g->name[0] && same_name > 1 && g->material[0]) snprintf(name, sizeof name, "%s/%s", g->name, g->material);
  else snprintf(name, sizeof name, "%s", g->name[0] ? g->name : g->material[0] ? g->material : stem);
  m.name = iris_strdup(name);
  bool warned = false;
  m.material = obj_resolve_material(c, g->material, &warned);
  if (!m.name || !iris_mesh_finish(&m, false, c->opts->weld, NULL)) {
    free(m.name), free(m.positions), free(m.indices), free(m.uvs), free(m.colors), free(m.normals);
    return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
  }
  if (m.triangle_count == 0) {
    free(m.name), free(m.positions), free(m.indices), free(m.uvs), free(m.colors), free(m.normals);
    return IRIS_OK;
  }
  if (iris_scene_add_mesh(c->scene, &m) < 0) {
    free(m.name), free(m.positions), free(m.indices), free(m.uvs), free(m.colors), free(m.normals);
    return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
  }
  iris_instance inst;
  memset(&inst, 0, sizeof inst);
  inst.mesh = (uint32_t)(c->scene->mesh_count - 1);
  inst.transform = iris_mat4_identity();
  if (iris_scene_add_instance(c->scene, &inst) < 0)
    return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
  return IRIS_OK;
}

static iris_status build_scene(obj_ctx *c) {
  size_t nv = c->pos.count / 3;
  build_scratch s;
  memset(&s, 0, sizeof s);
  iris_status st = IRIS_OK;
  s.tri = iris_polygon_triangulator_create();
  if (!s.tri) {
    st = iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
    goto done;
  }
  /* Angle-weighted normals over the whole file, keyed by position index, so
   * that material boundaries on a smooth surface do not become shading seams. */
  bool any_smooth = false;
  for (size_t gi = 0; gi < c->group_count; gi++) {
    const obj_group *g = &c->groups[gi];
    any_smooth |= g->needs_normals && (c->opts->compute_normals || g->any_vn);
  }
  if (any_smooth) {
    s.smooth_normals = calloc(3 * nv, sizeof(float));
    uint32_t *vtris = NULL;
    size_t vcap = 0;
    if (!s.smooth_normals) {
      st = iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
      goto done;
    }
    for (size_t gi = 0; gi < c->group_count; gi++) {
      const obj_group *g = &c->groups[gi];
      if (!g->needs_normals || !(c->opts->compute_normals || g->any_vn)) continue;
      size_t tri_count;
      if (!triangulate_group(c, g, &s, &tri_count) ||
          !grow((void **)&vtris, &vcap, 3 * tri_count, sizeof(uint32_t))) {
        free(vtris);
        st = iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
        goto done;
      }
      /* Only triangles whose corners all lack vn shape the smooth normals. */
      size_t kept = 0;
      for (size_t t = 0; t < tri_count; t++) {
        bool smooth = true;
        for (int k = 0; k < 3; k++) smooth &= g->corners[3 * (size_t)s.tris[3 * t + k] + 2] == OBJ_NO_INDEX;
        if (!smooth) continue;
        for (int k = 0; k < 3; k++) vtris[3 * kept + k] = (uint32_t)g->corners[3 * (size_t)s.tris[3 * t + k]];
        kept++;
      }
      iris_normals_accumulate(c->pos.v, vtris, kept, s.smooth_normals);
    }
    free(vtris);
    iris_normals_normalize(s.smooth_normals, nv);
  }
  char stem[256];
  if (c->path) iris_path_stem(c->path, stem, sizeof stem);
  else snprintf(stem, sizeof stem, "mesh");
  for (size_t gi = 0; gi < c->group_count; gi++) {
    if (!c->groups[gi].face_count) continue;
    int32_t *n = iris_strmap_find(&s.name_counts, c->groups[gi].name);
    if (n) (*n)++;
    else iris_strmap_put(&s.name_counts, c->groups[gi].name, 1);
  }
  for (size_t gi = 0; gi < c->group_count && st == IRIS_OK; gi++) st = build_group(c, gi, &s, stem);
done:
  if (st == IRIS_OK) iris_polygon_triangulator_report(s.tri, c->path, c->opts->stats);
  iris_polygon_triangulator_destroy(s.tri);
  free(s.poly), free(s.ptris), free(s.tris), free(s.head), free(s.stamp), free(s.chain), free(s.vkey);
  free(s.smooth_normals);
  iris_strmap_free(&s.name_counts);
  return st;
}

static void free_ctx(obj_ctx *c) {
  free(c->pos.v), free(c->col.v), free(c->uv.v), free(c->nrm.v);
  for (size_t i = 0; i < c->group_count; i++) free(c->groups[i].corners), free(c->groups[i].face_sizes);
  free(c->groups);
  for (size_t i = 0; i < c->mtl_count; i++) free(c->mtls[i].map_kd), free(c->mtls[i].map_ke);
  free(c->mtls);
  iris_strmap_free(&c->group_map), iris_strmap_free(&c->mtl_map);
  iris_strmap_free(&c->texture_map), iris_strmap_free(&c->mtllib_map);
}

iris_status iris_import_obj_memory(const char *data, size_t size, const char *path,
                                   const iris_import_options *opts, iris_scene **out,
                                   iris_error *err) {
  *out = NULL;
  iris_import_options defaults = iris_import_options_default();
  obj_ctx c;
  memset(&c, 0, sizeof c);
  char dir[1024];
  c.path = path ? path : "<memory>";
  if (path) {
    iris_path_dir(path, dir, sizeof dir);
    c.dir = dir;
  }
  c.opts = opts ? opts : &defaults;
  c.err = err;
  c.cur_group = SIZE_MAX;
  c.smooth = false; /* OBJ: smoothing groups are off until an 's N' line */
  c.scene = iris_scene_create();
  if (!c.scene) return iris_error_set(err, IRIS_ERR_NOMEM, c.path, 0, NULL, "out of memory");
  iris_status st = parse_obj(&c, data ? data : "", data ? size : 0);
  if (st == IRIS_OK) {
    size_t faces = 0;
    for (size_t i = 0; i < c.group_count; i++) faces += c.groups[i].face_count;
    if (faces == 0)
      st = iris_error_set(err, IRIS_ERR_INVALID, c.path, 0, NULL,
                          size == 0 ? "empty file" : "no faces (iris imports surfaces only)");
  }
  if (st == IRIS_OK) st = build_scene(&c);
  if (st == IRIS_OK && c.scene->mesh_count == 0)
    st = iris_error_set(err, IRIS_ERR_INVALID, c.path, 0, NULL, "every face is degenerate (zero area)");
  if (st == IRIS_OK && path && !(c.scene->source_path = iris_strdup(path)))
    st = iris_error_set(err, IRIS_ERR_NOMEM, c.path, 0, NULL, "out of memory");
  free_ctx(&c);
  if (st != IRIS_OK) {
    if (err && err->status == IRIS_OK) iris_error_set(err, st, c.path, 0, NULL, "import failed");
    iris_scene_destroy(c.scene);
    return st;
  }
  *out = c.scene;
  return IRIS_OK;
}

iris_status iris_import_obj(const char *path, const iris_import_options *opts, iris_scene **out,
                            iris_error *err) {
  return iris_import_mapped(path, iris_import_obj_memory, opts, out, err);
}
