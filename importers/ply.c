/* PLY importer (ASCII, binary little- and big-endian): header into a list of
 * elements and typed properties, every declared size checked against the file
 * length before anything is allocated, then one pass over the data. One
 * iris_mesh per file; polygons are ear-clipped (meshproc). docs/import-obj-ply.md. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/cancel.h"
#include "core/fileio.h"
#include "core/log.h"
#include "importers/import.h"
#include "importers/mapped.h"
#include "importers/meshproc.h"
#include "importers/numparse.h"

#define PLY_MAX_PROPS 256
#define PLY_MAX_ELEMENTS 64
#define PLY_MAX_LIST 65536 /* corners per face */

typedef enum ply_type { T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64, T_BAD } ply_type;
static const size_t type_size[] = {1, 1, 2, 2, 4, 4, 4, 8};

typedef enum ply_role {
  R_NONE = 0, R_X, R_Y, R_Z, R_NX, R_NY, R_NZ, R_R, R_G, R_B, R_U, R_V, R_INDICES, R_STRIP
} ply_role;

typedef struct ply_prop {
  char name[64];
  ply_type type;       /* item type for lists */
  ply_type count_type; /* lists only */
  bool is_list;
  ply_role role;
} ply_prop;

typedef struct ply_element {
  char name[64];
  uint64_t count;
  ply_prop props[PLY_MAX_PROPS];
  size_t prop_count;
  size_t min_row; /* bytes (binary) or tokens (ASCII) of the smallest possible row */
} ply_element;

typedef enum ply_format { F_ASCII, F_LE, F_BE } ply_format;

typedef struct ply_ctx {
  const char *path;
  iris_error *err;
  ply_format format;
  ply_element elements[PLY_MAX_ELEMENTS];
  size_t element_count;
  long header_lines;
  const char *data, *end; /* body */
  const char *p;          /* cursor */
  long line;              /* ASCII line of the cursor */

  uint64_t vertex_count;
  float *pos, *nrm, *col, *uv;
  bool has_nrm, has_col, has_uv;
  uint32_t *corners; /* all face corners, flattened */
  size_t corner_count, corner_cap;
  uint32_t *sizes;   /* per face, only when some face is not a triangle */
  size_t face_count, size_cap;
  bool all_triangles;
  long dropped_faces;
  size_t strip_degenerate; /* strip triangles with a repeated vertex */
  char ignored[512];
} ply_ctx;

static ply_type parse_type(const char *s, size_t n) {
  static const struct {
    const char *name;
    ply_type t;
  } names[] = {{"char", T_I8},    {"int8", T_I8},     {"uchar", T_U8},   {"uint8", T_U8},
               {"short", T_I16},  {"int16", T_I16},   {"ushort", T_U16}, {"uint16", T_U16},
               {"int", T_I32},    {"int32", T_I32},   {"uint", T_U32},   {"uint32", T_U32},
               {"float", T_F32},  {"float32", T_F32}, {"double", T_F64}, {"float64", T_F64}};
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
    if (strlen(names[i].name) == n && !memcmp(names[i].name, s, n)) return names[i].t;
  return T_BAD;
}

static bool grow(void **ptr, size_t *cap, size_t need, size_t elem) {
  if (need <= *cap) return true;
  size_t n = *cap ? *cap : 256;
  while (n < need) {
    if (n > SIZE_MAX / 2 / elem) return false;
    n *= 2;
  }
  void *p = realloc(*ptr, n * elem);
  if (!p) return false;
  *ptr = p;
  *cap = n;
  return true;
}

static void note_ignored(ply_ctx *c, const char *elem, const char *prop) {
  char k[160];
  snprintf(k, sizeof k, prop ? "%s.%s" : "%s", elem, prop);
  size_t n = strlen(c->ignored), kl = strlen(k);
  if (strstr(c->ignored, k)) return;
  if (n + kl + 3 >= sizeof c->ignored) return;
  if (n) strcat(c->ignored, ", ");
  strcat(c->ignored, k);
}

/* Next whitespace-separated word of a header line. */
static bool next_word(const char **p, const char *e, const char **w, size_t *n) {
  const char *q = iris_np_skip_space(*p, e);
  if (q >= e) return false;
  const char *s = q;
  while (q < e && !iris_np_is_space(*q)) q++;
  *w = s;
  *n = (size_t)(q - s);
  *p = q;
  return true;
}

#define WORD_IS(w, n, lit) ((n) == sizeof(lit) - 1 && !memcmp((w), (lit), (n)))

static ply_role vertex_role(const char *n) {
  static const struct {
    const char *name;
    ply_role r;
  } roles[] = {{"x", R_X},         {"y", R_Y},         {"z", R_Z},
               {"nx", R_NX},       {"ny", R_NY},       {"nz", R_NZ},
               {"normal_x", R_NX}, {"normal_y", R_NY}, {"normal_z", R_NZ},
               {"red", R_R},       {"green", R_G},     {"blue", R_B},
               {"r", R_R},         {"g", R_G},         {"b", R_B},
               {"diffuse_red", R_R}, {"diffuse_green", R_G}, {"diffuse_blue", R_B},
               {"u", R_U},         {"v", R_V},         {"s", R_U},         {"t", R_V},
               {"texture_u", R_U}, {"texture_v", R_V}, {"texture_s", R_U}, {"texture_t", R_V}};
  for (size_t i = 0; i < sizeof roles / sizeof roles[0]; i++)
    if (!strcmp(roles[i].name, n)) return roles[i].r;
  return R_NONE;
}

static iris_status parse_header(ply_ctx *c, const char *data, size_t size) {
  const char *p = data, *end = data + size;
  long line = 0;
  bool have_format = false;
  ply_element *el = NULL;
  for (;;) {
    if (p >= end)
      return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL,
                            size == 0 ? "empty file" : "header has no 'end_header' line");
    const char *e = memchr(p, '\n', (size_t)(end - p));
    if (!e) e = end;
    line++;
    const char *q = p, *w;
    size_t n;
    if (line == 1) {
      if (!next_word(&q, e, &w, &n) || !WORD_IS(w, n, "ply"))
        return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, 1, NULL, "not a PLY file (no 'ply' magic)");
    } else if (!next_word(&q, e, &w, &n)) {
      /* blank line: tolerated */
    } else if (WORD_IS(w, n, "comment") || WORD_IS(w, n, "obj_info")) {
    } else if (WORD_IS(w, n, "format")) {
      if (!next_word(&q, e, &w, &n))
        return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL, "format line without a format");
      if (WORD_IS(w, n, "ascii")) c->format = F_ASCII;
      else if (WORD_IS(w, n, "binary_little_endian")) c->format = F_LE;
      else if (WORD_IS(w, n, "binary_big_endian")) c->format = F_BE;
      else return iris_error_set(c->err, IRIS_ERR_UNSUPPORTED, c->path, line, NULL,
                                 "unknown PLY format '%.*s'", (int)n, w);
      if (!next_word(&q, e, &w, &n) || !WORD_IS(w, n, "1.0"))
        return iris_error_set(c->err, IRIS_ERR_UNSUPPORTED, c->path, line, NULL, "only PLY version 1.0 is supported");
      have_format = true;
    } else if (WORD_IS(w, n, "element")) {
      if (c->element_count == PLY_MAX_ELEMENTS)
        return iris_error_set(c->err, IRIS_ERR_UNSUPPORTED, c->path, line, NULL, "too many elements");
      el = &c->elements[c->element_count++];
      memset(el, 0, sizeof *el);
      const char *cw;
      size_t cn;
      if (!next_word(&q, e, &w, &n) || !next_word(&q, e, &cw, &cn))
        return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL, "expected 'element NAME COUNT'");
      snprintf(el->name, sizeof el->name, "%.*s", (int)n, w);
      int64_t count;
      const char *t = cw;
      if (!iris_parse_int(&t, cw + cn, &count) || t != cw + cn || count < 0)
        return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL,
                              "element '%s' has an invalid count '%.*s'", el->name, (int)cn, cw);
      el->count = (uint64_t)count;
    } else if (WORD_IS(w, n, "property")) {
      if (!el) return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL, "property before any element");
      if (el->prop_count == PLY_MAX_PROPS)
        return iris_error_set(c->err, IRIS_ERR_UNSUPPORTED, c->path, line, NULL, "too many properties");
      ply_prop *pr = &el->props[el->prop_count];
      memset(pr, 0, sizeof *pr);
      if (!next_word(&q, e, &w, &n))
        return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL, "property without a type");
      if (WORD_IS(w, n, "list")) {
        pr->is_list = true;
        if (!next_word(&q, e, &w, &n) || (pr->count_type = parse_type(w, n)) == T_BAD)
          return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL, "bad list count type");
        if (pr->count_type == T_F32 || pr->count_type == T_F64)
          return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL, "list count type must be an integer");
        if (!next_word(&q, e, &w, &n))
          return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL, "bad list item type");
      }
      if ((pr->type = parse_type(w, n)) == T_BAD)
        return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL, "unknown property type '%.*s'", (int)n, w);
      if (!next_word(&q, e, &w, &n))
        return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL, "property without a name");
      snprintf(pr->name, sizeof pr->name, "%.*s", (int)n, w);
      el->prop_count++;
      el->min_row += pr->is_list ? (c->format == F_ASCII ? 1 : type_size[pr->count_type])
                                 : (c->format == F_ASCII ? 1 : type_size[pr->type]);
    } else if (WORD_IS(w, n, "end_header")) {
      if (!have_format) return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL, "no format line");
      c->header_lines = line;
      c->data = e < end ? e + 1 : end;
      c->end = end;
      /* ASCII min_row counted tokens before the format was known for earlier
       * properties; recompute now. */
      for (size_t i = 0; i < c->element_count; i++) {
        ply_element *x = &c->elements[i];
        x->min_row = 0;
        for (size_t j = 0; j < x->prop_count; j++)
          x->min_row += c->format == F_ASCII ? 2 /* a digit and a separator */
                        : type_size[x->props[j].is_list ? x->props[j].count_type : x->props[j].type];
      }
      return IRIS_OK;
    } else {
      return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, line, NULL,
                            "unknown header keyword '%.*s'", (int)n, w);
    }
    p = e + 1;
  }
}

/* ---- scalar reading ------------------------------------------------------ */

static inline double read_bin(const unsigned char *b, ply_type t, bool swap) {
  unsigned char s[8];
  size_t n = type_size[t];
  if (swap) {
    for (size_t i = 0; i < n; i++) s[i] = b[n - 1 - i];
    b = s;
  }
  switch (t) {
    case T_I8: return (double)(int8_t)b[0];
    case T_U8: return (double)b[0];
    case T_I16: { int16_t v; memcpy(&v, b, 2); return v; }
    case T_U16: { uint16_t v; memcpy(&v, b, 2); return v; }
    case T_I32: { int32_t v; memcpy(&v, b, 4); return v; }
    case T_U32: { uint32_t v; memcpy(&v, b, 4); return v; }
    case T_F32: { float v; memcpy(&v, b, 4); return v; }
    case T_F64: { double v; memcpy(&v, b, 8); return v; }
    default: return 0;
  }
}

static bool host_little_endian(void) {
  const uint16_t one = 1;
  unsigned char b;
  memcpy(&b, &one, 1);
  return b == 1;
}

/* Reads one scalar at the cursor; false at the end of the data or on a bad token. */
static bool read_value(ply_ctx *c, ply_type t, bool swap, double *v) {
  if (c->format != F_ASCII) {
    size_t n = type_size[t];
    if ((size_t)(c->end - c->p) < n) return false;
    *v = read_bin((const unsigned char *)c->p, t, swap);
    c->p += n;
    return true;
  }
  const char *p = c->p;
  while (p < c->end && (iris_np_is_space(*p) || *p == '\n')) {
    if (*p == '\n') c->line++;
    p++;
  }
  if (p >= c->end) return false;
  c->p = p;
  if (!iris_parse_double(&c->p, c->end, v)) return false;
  if (t != T_F32 && t != T_F64 && *v != floor(*v)) return false; /* integers must be integral */
  return true;
}

static float srgb_to_linear(float v) {
  return v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
}

static float color_value(double v, ply_type t) {
  switch (t) {
    case T_U8: return srgb_to_linear((float)(v / 255.0));
    case T_I8: return srgb_to_linear((float)(v / 127.0));
    case T_U16: return srgb_to_linear((float)(v / 65535.0));
    case T_I16: return srgb_to_linear((float)(v / 32767.0));
    case T_U32: return srgb_to_linear((float)(v / 4294967295.0));
    case T_I32: return srgb_to_linear((float)(v / 2147483647.0));
    default: return (float)v; /* floating-point colours are taken as linear */
  }
}

static iris_status data_error(ply_ctx *c, const ply_element *el, uint64_t row, const char *what) {
  char elem[96];
  snprintf(elem, sizeof elem, "%s %llu", el->name, (unsigned long long)row);
  if (c->format == F_ASCII)
    return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, c->line, elem, "%s", what);
  return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, 0, elem, "%s", what);
}

/* Appends one face of n >= 3 corners. */
static bool add_face(ply_ctx *c, const uint32_t *list, size_t n) {
  if (n != 3 && c->all_triangles) {
    /* First polygon: from now on keep per-face sizes. */
    if (!grow((void **)&c->sizes, &c->size_cap, c->face_count + 1, sizeof(uint32_t))) return false;
    for (size_t f = 0; f < c->face_count; f++) c->sizes[f] = 3;
    c->all_triangles = false;
  }
  if (!grow((void **)&c->corners, &c->corner_cap, c->corner_count + n, sizeof(uint32_t)) ||
      (!c->all_triangles && !grow((void **)&c->sizes, &c->size_cap, c->face_count + 1, sizeof(uint32_t))))
    return false;
  memcpy(c->corners + c->corner_count, list, n * sizeof(uint32_t));
  c->corner_count += n;
  if (!c->all_triangles) c->sizes[c->face_count] = (uint32_t)n;
  c->face_count++;
  return true;
}

#define STRIP_RESTART UINT32_MAX

/* Appends the triangles of a triangle strip list (PLY `element tristrips`, as
 * written by the Stanford tools: STRIP_RESTART (-1 in the file) starts a new
 * strip). Triangle i of a strip is (v_i, v_i+1, v_i+2), every odd one reversed
 * so all keep the first triangle's orientation; triangles that repeat a vertex
 * (the padding some writers use instead of restarts) are skipped. */
static bool add_strip(ply_ctx *c, const uint32_t *list, size_t n) {
  size_t start = 0;
  for (size_t k = 0; k <= n; k++) {
    if (k < n && list[k] != STRIP_RESTART) continue;
    for (size_t i = start; i + 2 < k; i++) {
      uint32_t t[3] = {list[i], list[i + 1], list[i + 2]};
      if ((i - start) % 2) t[0] = list[i + 1], t[1] = list[i];
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
        c->strip_degenerate++;
        continue;
      }
      if (!add_face(c, t, 3)) return false;
    }
    start = k + 1;
  }
  return true;
}

static iris_status read_element(ply_ctx *c, ply_element *el, bool is_vertex, bool is_face) {
  const bool swap = c->format != F_ASCII && ((c->format == F_LE) != host_little_endian());
  uint32_t *list = NULL;
  size_t list_cap = 0;
  iris_status st = IRIS_OK;
  if (is_face && !grow((void **)&c->corners, &c->corner_cap, 3 * (size_t)el->count, sizeof(uint32_t)))
    return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, el->name, "out of memory");
  for (uint64_t row = 0; row < el->count; row++) {
    if ((row & 0xffff) == 0xffff && iris_cancel_requested()) { /* Ctrl-C: core/cancel.h */
      st = iris_error_set(c->err, IRIS_ERR_INTERRUPTED, c->path, 0, NULL, "interrupted while loading the scene");
      goto done;
    }
    float vals[R_INDICES] = {0};
    bool indices_seen = false;
    for (size_t j = 0; j < el->prop_count; j++) {
      const ply_prop *pr = &el->props[j];
      double v;
      if (!pr->is_list) {
        if (!read_value(c, pr->type, swap, &v)) {
          st = data_error(c, el, row, c->p >= c->end ? "file ends inside the data (truncated)" : "malformed number");
          goto done;
        }
        if (pr->role != R_NONE && pr->role < R_INDICES) {
          float f = (pr->role >= R_R && pr->role <= R_B) ? color_value(v, pr->type) : (float)v;
          if (!isfinite(f)) {
            st = iris_error_set(c->err, IRIS_ERR_INVALID, c->path, c->format == F_ASCII ? c->line : 0,
                                NULL, "%s %llu: property '%s' is not finite (NaN or infinity)", el->name,
                                (unsigned long long)row, pr->name);
            goto done;
          }
          vals[pr->role] = f;
        }
        continue;
      }
      double cnt;
      if (!read_value(c, pr->count_type, swap, &cnt)) {
        st = data_error(c, el, row, c->p >= c->end ? "file ends inside the data (truncated)" : "malformed list count");
        goto done;
      }
      if (cnt < 0 || cnt > PLY_MAX_LIST) {
        st = data_error(c, el, row, "list length is negative or absurd");
        goto done;
      }
      const size_t n = (size_t)cnt;
      if (c->format != F_ASCII && n * type_size[pr->type] > (size_t)(c->end - c->p)) {
        st = data_error(c, el, row, "file ends inside a list (truncated)");
        goto done;
      }
      const bool want = pr->role == R_INDICES && !indices_seen;
      const bool strip = pr->role == R_STRIP && !indices_seen;
      if ((want || strip) && !grow((void **)&list, &list_cap, n, sizeof(uint32_t))) {
        st = iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, el->name, "out of memory");
        goto done;
      }
      for (size_t k = 0; k < n; k++) {
        if (!read_value(c, pr->type, swap, &v)) {
          st = data_error(c, el, row, c->p >= c->end ? "file ends inside a list (truncated)" : "malformed list item");
          goto done;
        }
        if (want) {
          if (!(v >= 0 && v < (double)c->vertex_count)) {
            char msg[160];
            snprintf(msg, sizeof msg, "vertex index %.0f out of range (%llu vertices)", v,
                     (unsigned long long)c->vertex_count);
            st = iris_error_set(c->err, IRIS_ERR_INVALID, c->path, c->format == F_ASCII ? c->line : 0, NULL,
                                "%s %llu: %s", el->name, (unsigned long long)row, msg);
            goto done;
          }
          list[k] = (uint32_t)v;
        } else if (strip) { /* -1 restarts the strip */
          /* -1, or its unsigned 32-bit pattern when the list type is uint */
          if (v == 4294967295.0 && pr->type == T_U32) v = -1;
          if (!(v == -1 || (v >= 0 && v < (double)c->vertex_count))) {
            char msg[160];
            snprintf(msg, sizeof msg, "strip index %.0f out of range (%llu vertices; -1 restarts)", v,
                     (unsigned long long)c->vertex_count);
            st = iris_error_set(c->err, IRIS_ERR_INVALID, c->path, c->format == F_ASCII ? c->line : 0, NULL,
                                "%s %llu: %s", el->name, (unsigned long long)row, msg);
            goto done;
          }
          list[k] = v < 0 ? STRIP_RESTART : (uint32_t)v;
        }
      }
      if (want) {
        indices_seen = true;
        if (n < 3) {
          c->dropped_faces++;
          continue;
        }
        if (!add_face(c, list, n)) {
          st = iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, el->name, "out of memory");
          goto done;
        }
      }
      if (strip) {
        indices_seen = true;
        if (!add_strip(c, list, n)) {
          st = iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, el->name, "out of memory");
          goto done;
        }
      }
    }
    if (is_vertex) {
      float *p = c->pos + 3 * row;
      p[0] = vals[R_X], p[1] = vals[R_Y], p[2] = vals[R_Z];
      if (c->has_nrm) c->nrm[3 * row] = vals[R_NX], c->nrm[3 * row + 1] = vals[R_NY], c->nrm[3 * row + 2] = vals[R_NZ];
      if (c->has_col) c->col[3 * row] = vals[R_R], c->col[3 * row + 1] = vals[R_G], c->col[3 * row + 2] = vals[R_B];
      if (c->has_uv) c->uv[2 * row] = vals[R_U], c->uv[2 * row + 1] = 1.0f - vals[R_V];
    }
  }
done:
  free(list);
  return st;
}

static bool has_role(const ply_element *el, ply_role r) {
  for (size_t j = 0; j < el->prop_count; j++)
    if (el->props[j].role == r) return true;
  return false;
}

static iris_status import_ply(ply_ctx *c, const char *data, size_t size, const iris_import_options *opts,
                              iris_scene *scene) {
  iris_status st = parse_header(c, data, size);
  if (st != IRIS_OK) return st;
  ply_element *vertex = NULL, *face = NULL, *strips = NULL;
  for (size_t i = 0; i < c->element_count; i++) {
    ply_element *el = &c->elements[i];
    if (!strcmp(el->name, "vertex") && !vertex) {
      vertex = el;
      for (size_t j = 0; j < el->prop_count; j++) {
        ply_prop *pr = &el->props[j];
        pr->role = pr->is_list ? R_NONE : vertex_role(pr->name);
        for (size_t k = 0; k < j; k++) /* duplicate roles: the first one wins */
          if (el->props[k].role == pr->role) pr->role = R_NONE;
        if (pr->role == R_NONE) note_ignored(c, el->name, pr->name);
      }
    } else if (!strcmp(el->name, "face") && !face) {
      face = el;
      for (size_t j = 0; j < el->prop_count; j++) {
        ply_prop *pr = &el->props[j];
        bool idx = pr->is_list && (!strcmp(pr->name, "vertex_indices") || !strcmp(pr->name, "vertex_index"));
        if (idx && (pr->type == T_F32 || pr->type == T_F64))
          return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, c->header_lines, "face",
                                "vertex indices must have an integer type");
        bool first = idx;
        for (size_t k = 0; k < j && first; k++) first = el->props[k].role != R_INDICES;
        pr->role = first ? R_INDICES : R_NONE;
        if (pr->role == R_NONE) note_ignored(c, el->name, pr->name);
      }
    } else if (!strcmp(el->name, "tristrips") && !strips) {
      strips = el;
      for (size_t j = 0; j < el->prop_count; j++) {
        ply_prop *pr = &el->props[j];
        bool idx = pr->is_list && (!strcmp(pr->name, "vertex_indices") || !strcmp(pr->name, "vertex_index"));
        if (idx && (pr->type == T_F32 || pr->type == T_F64))
          return iris_error_set(c->err, IRIS_ERR_PARSE, c->path, c->header_lines, "tristrips",
                                "vertex indices must have an integer type");
        bool first = idx;
        for (size_t k = 0; k < j && first; k++) first = el->props[k].role != R_STRIP;
        pr->role = first ? R_STRIP : R_NONE;
        if (pr->role == R_NONE) note_ignored(c, el->name, pr->name);
      }
    } else if (el->count > 0) {
      note_ignored(c, el->name, NULL);
    }
  }
  if (!vertex || !has_role(vertex, R_X) || !has_role(vertex, R_Y) || !has_role(vertex, R_Z))
    return iris_error_set(c->err, IRIS_ERR_INVALID, c->path, c->header_lines, NULL,
                          "no 'vertex' element with x, y and z properties");
  if (!face && !strips)
    return iris_error_set(c->err, IRIS_ERR_UNSUPPORTED, c->path, c->header_lines, NULL,
                          "no 'face' or 'tristrips' element: this is a point cloud, and iris renders "
                          "surfaces only");
  if (face && !has_role(face, R_INDICES))
    return iris_error_set(c->err, IRIS_ERR_INVALID, c->path, c->header_lines, NULL,
                          "the 'face' element has no 'vertex_indices' (or 'vertex_index') list");
  if (strips && !has_role(strips, R_STRIP))
    return iris_error_set(c->err, IRIS_ERR_INVALID, c->path, c->header_lines, NULL,
                          "the 'tristrips' element has no 'vertex_indices' list");
  if ((face ? face->count : 0) + (strips ? strips->count : 0) == 0)
    return iris_error_set(c->err, IRIS_ERR_UNSUPPORTED, c->path, c->header_lines, NULL,
                          "0 faces: this is a point cloud, and iris renders surfaces only");
  if (vertex->count > UINT32_MAX || (face && face->count > UINT32_MAX / 3))
    return iris_error_set(c->err, IRIS_ERR_UNSUPPORTED, c->path, c->header_lines, NULL,
                          "more than 2^32 vertices or triangles");
  /* Every declared row needs at least min_row bytes: refuse counts the file
   * cannot hold before allocating anything. */
  const uint64_t body = (uint64_t)(c->end - c->data);
  uint64_t need = 0;
  for (size_t i = 0; i < c->element_count; i++) {
    const ply_element *el = &c->elements[i];
    if (el->min_row && el->count > (body + 1) / el->min_row + 1)
      return iris_error_set(c->err, IRIS_ERR_INVALID, c->path, c->header_lines, el->name,
                            "declares %llu rows but the file holds at most %llu (truncated or corrupt)",
                            (unsigned long long)el->count, (unsigned long long)((body + 1) / el->min_row));
    need += el->count * el->min_row;
    if (c->format != F_ASCII && need > body)
      return iris_error_set(c->err, IRIS_ERR_INVALID, c->path, c->header_lines, el->name,
                            "the declared elements need at least %llu bytes but the data has %llu (truncated)",
                            (unsigned long long)need, (unsigned long long)body);
  }
  c->vertex_count = vertex->count;
  const size_t nv = (size_t)vertex->count;
  c->has_nrm = has_role(vertex, R_NX) && has_role(vertex, R_NY) && has_role(vertex, R_NZ);
  c->has_col = has_role(vertex, R_R) && has_role(vertex, R_G) && has_role(vertex, R_B);
  c->has_uv = has_role(vertex, R_U) && has_role(vertex, R_V);
  c->pos = malloc(3 * (nv ? nv : 1) * sizeof(float));
  if (c->has_nrm) c->nrm = malloc(3 * (nv ? nv : 1) * sizeof(float));
  if (c->has_col) c->col = malloc(3 * (nv ? nv : 1) * sizeof(float));
  if (c->has_uv) c->uv = malloc(2 * (nv ? nv : 1) * sizeof(float));
  if (!c->pos || (c->has_nrm && !c->nrm) || (c->has_col && !c->col) || (c->has_uv && !c->uv))
    return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
  c->p = c->data;
  c->line = c->header_lines + 1;
  c->all_triangles = true;
  for (size_t i = 0; i < c->element_count; i++) {
    ply_element *el = &c->elements[i];
    if (el->prop_count == 0) continue; /* rows without data */
    st = read_element(c, el, el == vertex, el == face);
    if (st != IRIS_OK) return st;
  }
  if (c->format == F_ASCII) {
    const char *q = c->p;
    while (q < c->end && (iris_np_is_space(*q) || *q == '\n')) q++;
    if (q < c->end) iris_warnf("%s:%ld: data after the last element ignored", c->path, c->line);
  } else if (c->p < c->end) {
    iris_warnf("%s: %zu bytes after the last element ignored", c->path, (size_t)(c->end - c->p));
  }
  if (c->ignored[0]) iris_warnf("%s: PLY properties/elements ignored: %s", c->path, c->ignored);
  if (c->dropped_faces) iris_warnf("%s: %ld face(s) with fewer than 3 corners dropped", c->path, c->dropped_faces);
  if (c->strip_degenerate)
    iris_warnf("%s: %zu tristrips triangle(s) with a repeated vertex skipped", c->path, c->strip_degenerate);
  if (c->face_count == 0)
    return iris_error_set(c->err, IRIS_ERR_INVALID, c->path, 0, NULL, "no face has 3 or more corners");
  if (c->face_count > UINT32_MAX / 3)
    return iris_error_set(c->err, IRIS_ERR_UNSUPPORTED, c->path, 0, NULL, "more than 2^32 triangles");

  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.owned = true;
  m.material = -1;
  m.vertex_count = (uint32_t)nv;
  if (c->all_triangles) {
    m.indices = c->corners;
    c->corners = NULL;
    m.triangle_count = (uint32_t)c->face_count;
  } else {
    size_t tris = c->corner_count - 2 * c->face_count;
    if (tris > UINT32_MAX / 3)
      return iris_error_set(c->err, IRIS_ERR_UNSUPPORTED, c->path, 0, NULL, "more than 2^32 triangles");
    m.indices = malloc(3 * tris * sizeof(uint32_t));
    uint32_t *local = malloc(3 * (PLY_MAX_LIST) * sizeof(uint32_t));
    iris_polygon_triangulator *tr = iris_polygon_triangulator_create();
    if (!m.indices || !local || !tr) {
      free(m.indices), free(local), iris_polygon_triangulator_destroy(tr);
      return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
    }
    size_t corner = 0, out = 0;
    for (size_t f = 0; f < c->face_count; f++) {
      const uint32_t n = c->sizes[f];
      const uint32_t *poly = c->corners + corner;
      uint32_t t = iris_polygon_triangulate(tr, c->pos, poly, n, local);
      if (t == 0) {
        free(m.indices), free(local), iris_polygon_triangulator_destroy(tr);
        return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
      }
      for (uint32_t i = 0; i < 3 * t; i++) m.indices[out++] = poly[local[i]];
      corner += n;
    }
    free(local);
    iris_polygon_triangulator_report(tr, c->path, opts->stats);
    iris_polygon_triangulator_destroy(tr);
    m.triangle_count = (uint32_t)(out / 3);
  }
  m.positions = c->pos, c->pos = NULL;
  m.normals = c->nrm, c->nrm = NULL;
  m.colors = c->col, c->col = NULL;
  m.uvs = c->uv, c->uv = NULL;
  char stem[256];
  if (c->path) iris_path_stem(c->path, stem, sizeof stem);
  m.name = iris_strdup(stem);
  if (!m.name || !iris_mesh_finish(&m, opts->compute_normals, opts->weld, NULL)) {
    free(m.name), free(m.positions), free(m.normals), free(m.colors), free(m.uvs), free(m.indices);
    return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
  }
  if (m.triangle_count == 0) {
    free(m.name), free(m.positions), free(m.normals), free(m.colors), free(m.uvs), free(m.indices);
    return iris_error_set(c->err, IRIS_ERR_INVALID, c->path, 0, NULL, "every face is degenerate (zero area)");
  }
  if (iris_scene_add_mesh(scene, &m) < 0) {
    free(m.name), free(m.positions), free(m.normals), free(m.colors), free(m.uvs), free(m.indices);
    return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
  }
  iris_instance inst;
  memset(&inst, 0, sizeof inst);
  inst.mesh = (uint32_t)(scene->mesh_count - 1);
  inst.transform = iris_mat4_identity();
  if (iris_scene_add_instance(scene, &inst) < 0)
    return iris_error_set(c->err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
  return IRIS_OK;
}

iris_status iris_import_ply_memory(const char *data, size_t size, const char *path,
                                   const iris_import_options *opts, iris_scene **out,
                                   iris_error *err) {
  *out = NULL;
  iris_import_options defaults = iris_import_options_default();
  ply_ctx *c = calloc(1, sizeof *c);
  if (!c) return iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "out of memory");
  c->path = path ? path : "<memory>";
  c->err = err;
  iris_scene *scene = iris_scene_create();
  iris_status st = scene ? import_ply(c, data ? data : "", data ? size : 0, opts ? opts : &defaults, scene)
                         : iris_error_set(err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
  if (st == IRIS_OK && path && !(scene->source_path = iris_strdup(path)))
    st = iris_error_set(err, IRIS_ERR_NOMEM, c->path, 0, NULL, "out of memory");
  free(c->pos), free(c->nrm), free(c->col), free(c->uv), free(c->corners), free(c->sizes);
  free(c);
  if (st != IRIS_OK) {
    iris_scene_destroy(scene);
    return st;
  }
  *out = scene;
  return IRIS_OK;
}

iris_status iris_import_ply(const char *path, const iris_import_options *opts, iris_scene **out,
                            iris_error *err) {
  return iris_import_mapped(path, iris_import_ply_memory, opts, out, err);
}
