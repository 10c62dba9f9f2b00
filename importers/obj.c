/* Wavefront OBJ + MTL importer: a single-pass line parser into global
 * attribute arrays and per-(group, material) face lists, then one iris_mesh
 * per (group, material) with vertices deduplicated per (v, vt, vn). The MTL
 * mapping and every decision are in docs/import-obj-ply.md. */
#include <math.h>
#include <stdarg.h>
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
#include "importers/strmap.h"

#define OBJ_MAX_FILE_SIZE ((size_t)1 << 34) /* 16 GiB */
#define OBJ_NAME_MAX 256
#define OBJ_NO_INDEX (-1)
#define OBJ_FLAT (-2) /* vn of a corner of a face outside any smoothing group */

/* ---- small growable arrays --------------------------------------------- */

static bool grow(void **ptr, size_t *cap, size_t need, size_t elem) {
  if (need <= *cap) return true;
  size_t n = *cap ? *cap : 64;
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

typedef struct floats {
  float *v;
  size_t count, cap; /* in floats */
} floats;

static bool floats_push(floats *a, const float *x, size_t n) {
  if (!grow((void **)&a->v, &a->cap, a->count + n, sizeof(float))) return false;
  memcpy(a->v + a->count, x, n * sizeof(float));
  a->count += n;
  return true;
}

/* ---- MTL ---------------------------------------------------------------- */

typedef struct mtl_material {
  char name[OBJ_NAME_MAX];
  float kd[3], ks[3], ke[3], tf[3];
  float ns, ni, d, pr, pm;
  int illum;
  bool has_tf, has_ni, has_pr, has_pm;
  char *map_kd, *map_ke; /* resolved paths */
  bool map_kd_clamp, map_ke_clamp;
  int32_t scene_index;   /* -2: not yet added */
} mtl_material;

/* A face list for one (group name, material name). */
typedef struct obj_group {
  char name[OBJ_NAME_MAX];
  char material[OBJ_NAME_MAX];
  int32_t *corners; /* (v, vt, vn) triples, 0-based; vn may be a FLAT marker */
  size_t corner_count, corner_cap;
  uint32_t *face_sizes;
  size_t face_count, face_cap;
  bool any_vt, any_vn, needs_normals, any_flat;
} obj_group;

typedef struct obj_ctx {
  const char *path; /* for messages */
  const char *dir;  /* for mtllib; NULL disables external files */
  const iris_import_options *opts;
  iris_error *err;
  iris_scene *scene;

  floats pos, col, uv, nrm;
  bool has_colors;
  obj_group *groups;
  size_t group_count, group_cap;
  size_t cur_group; /* SIZE_MAX: none yet */
  char cur_name[OBJ_NAME_MAX];
  char cur_material[OBJ_NAME_MAX];
  bool smooth;

  /* max positive index seen for v, vt, vn and where */
  int64_t max_idx[3];
  long max_line[3];

  mtl_material *mtls;
  size_t mtl_count, mtl_cap;

  /* Look-ups by name (a scan per query was quadratic in the number of names):
   * "name\nmaterial" -> group, material name -> its last definition (built on
   * first use), "0path"/"1path" (repeat/clamp) -> texture, library paths read. */
  iris_strmap group_map, mtl_map, texture_map, mtllib_map;
  bool mtl_map_built;

  /* ignored things, reported once */
  char ignored[512];
  long dropped_faces, dropped_faces_line;
  long lines_points;
} obj_ctx;

static void note_ignored(char *list, size_t size, const char *key, size_t key_len) {
  char k[48];
  if (key_len >= sizeof k) key_len = sizeof k - 1;
  for (size_t i = 0; i < key_len; i++) /* printable for the message, no NUL */
    k[i] = (key[i] > ' ' && key[i] < 127 && key[i] != ',') ? key[i] : '?';
  k[key_len] = 0;
  const size_t kl = key_len;
  if (kl == 0) return;
  for (const char *p = list; (p = strstr(p, k)) != NULL; p++) /* already listed? */
    if ((p == list || p[-1] == ' ') && (p[kl] == ',' || p[kl] == 0)) return;
  size_t n = strlen(list);
  if (n + kl + 3 >= size) return;
  if (n) strcat(list, ", ");
  strcat(list, k);
}

/* Copies the rest of the line (trimmed) into out. */
static void copy_rest(const char *p, const char *end, char *out, size_t size) {
  p = iris_np_skip_space(p, end);
  while (end > p && iris_np_is_space(end[-1])) end--;
  size_t n = (size_t)(end - p);
  if (n >= size) n = size - 1;
  memcpy(out, p, n);
  out[n] = 0;
}

static const char *line_end(const char *p, const char *end) {
  const char *e = memchr(p, '\n', (size_t)(end - p));
  return e ? e : end;
}

/* Strips a trailing comment: a '#' at the start or after white space (so
 * MSVC's "1.#IND" stays a number, to be rejected as non-finite). */
static const char *strip_comment(const char *p, const char *e) {
  for (const char *h = p; (h = memchr(h, '#', (size_t)(e - h))) != NULL; h++)
    if (h == p || iris_np_is_space(h[-1])) return h;
  return e;
}

static bool parse_floats(const char **pp, const char *end, float *out, int max, int *count) {
  int n = 0;
  const char *p = *pp;
  for (;;) {
    p = iris_np_skip_space(p, end);
    if (p >= end || n == max) break;
    if (!iris_parse_float(&p, end, &out[n])) return false;
    n++;
  }
  *pp = p;
  *count = n;
  return true;
}

static bool all_finite(const float *v, int n) {
  for (int i = 0; i < n; i++)
    if (!isfinite(v[i])) return false;
  return true;
}

static const char *mime_of(const char *path) {
  char ext[16];
  iris_path_ext(path, ext, sizeof ext);
  if (!strcmp(ext, "png")) return "image/png";
  if (!strcmp(ext, "jpg") || !strcmp(ext, "jpeg")) return "image/jpeg";
  return NULL;
}

/* "map_Kd [-options args] file name": returns the resolved path or NULL. */
static char *parse_map(const char *p, const char *end, const char *mtl_dir, bool *clamp,
                       const char *mtl_path, long line) {
  static const struct {
    const char *opt;
    int args;
  } opts[] = {{"-blendu", 1}, {"-blendv", 1}, {"-bm", 1},   {"-boost", 1}, {"-cc", 1},
              {"-clamp", 1},  {"-imfchan", 1}, {"-mm", 2},  {"-o", 3},     {"-s", 3},
              {"-t", 3},      {"-texres", 1}, {"-type", 1}};
  *clamp = false;
  for (;;) {
    p = iris_np_skip_space(p, end);
    if (p >= end || *p != '-') break;
    const char *q = p;
    while (q < end && !iris_np_is_space(*q)) q++;
    size_t n = (size_t)(q - p);
    int args = -1;
    for (size_t i = 0; i < sizeof opts / sizeof opts[0]; i++)
      if (strlen(opts[i].opt) == n && !memcmp(opts[i].opt, p, n)) args = opts[i].args;
    if (args < 0) break; /* a file name starting with '-' */
    bool is_clamp = n == 6 && !memcmp(p, "-clamp", 6);
    p = q;
    for (int a = 0; a < args; a++) {
      p = iris_np_skip_space(p, end);
      const char *s = p;
      /* -o/-s/-t take 1 to 3 numbers */
      if (a > 0 && args == 3) {
        double d;
        const char *t = p;
        if (!iris_parse_double(&t, end, &d)) break;
      }
      while (p < end && !iris_np_is_space(*p)) p++;
      if (is_clamp) *clamp = (p - s == 2 && !memcmp(s, "on", 2));
    }
  }
  char name[1024];
  copy_rest(p, end, name, sizeof name);
  for (char *c = name; *c; c++)
    if (*c == '\\') *c = '/';
  if (!name[0]) {
    iris_warnf("%s:%ld: texture map without a file name ignored", mtl_path, line);
    return NULL;
  }
  char full[2048];
  iris_path_join(mtl_dir, name, full, sizeof full);
  return iris_strdup(full);
}

static iris_status parse_mtl(obj_ctx *c, const char *data, size_t size, const char *mtl_path) {
  const char *p = data, *end = data + size;
  char mtl_dir[1024];
  iris_path_dir(mtl_path, mtl_dir, sizeof mtl_dir);
  char ignored[512] = "";
  mtl_material *m = NULL;
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
#define KEY(s) (kn == sizeof(s) - 1 && !memcmp(k, s, kn))
    if (kn == 0) {
    } else if (KEY("newmtl")) {
      if (!grow((void **)&c->mtls, &c->mtl_cap, c->mtl_count + 1, sizeof *c->mtls))
        return iris_error_set(c->err, IRIS_ERR_NOMEM, mtl_path, line, NULL, "out of memory");
      m = &c->mtls[c->mtl_count++];
      memset(m, 0, sizeof *m);
      copy_rest(a, le, m->name, sizeof m->name);
      m->kd[0] = m->kd[1] = m->kd[2] = 0.8f;
      m->ns = 0, m->ni = 1.5f, m->d = 1, m->illum = -1;
      m->scene_index = -2;
    } else if (!m) {
      note_ignored(ignored, sizeof ignored, k, kn);
    } else if (KEY("Kd") || KEY("Ks") || KEY("Ke") || KEY("Tf")) {
      float v[3];
      int n;
      const char *q = a;
      if (!parse_floats(&q, le, v, 3, &n) || n == 0) {
        /* "Kd spectral file" / "Tf xyz ..." */
        q = iris_np_skip_space(a, le);
        if (iris_np_match(q, le, "spectral") || iris_np_match(q, le, "xyz")) {
          note_ignored(ignored, sizeof ignored, k, kn);
          p = e + (e < end);
          continue;
        }
        return iris_error_set(c->err, IRIS_ERR_PARSE, mtl_path, line, NULL,
                              "expected 1 or 3 numbers after '%.*s'", (int)kn, k);
      }
      if (n == 1) v[1] = v[2] = v[0];
      if (n == 2) return iris_error_set(c->err, IRIS_ERR_PARSE, mtl_path, line, NULL,
                                        "expected 1 or 3 numbers after '%.*s'", (int)kn, k);
      if (!all_finite(v, 3) || v[0] < 0 || v[1] < 0 || v[2] < 0)
        return iris_error_set(c->err, IRIS_ERR_INVALID, mtl_path, line, m->name,
                              "'%.*s' must be finite and non-negative", (int)kn, k);
      float *dst = KEY("Kd") ? m->kd : KEY("Ks") ? m->ks : KEY("Ke") ? m->ke : m->tf;
      memcpy(dst, v, sizeof v);
      if (KEY("Tf")) m->has_tf = true;
    } else if (KEY("Ns") || KEY("Ni") || KEY("d") || KEY("Tr") || KEY("Pr") || KEY("Pm") ||
               KEY("illum")) {
      float v = 0;
      int n;
      const char *q = a;
      /* "d -halo 0.5" */
      q = iris_np_skip_space(q, le);
      if (KEY("d") && iris_np_match(q, le, "-halo")) q += 5;
      if (!parse_floats(&q, le, &v, 1, &n) || n != 1 || !isfinite(v))
        return iris_error_set(c->err, IRIS_ERR_PARSE, mtl_path, line, NULL,
                              "expected a finite number after '%.*s'", (int)kn, k);
      if (KEY("Ns")) m->ns = v;
      else if (KEY("Ni")) m->ni = v, m->has_ni = true;
      else if (KEY("d")) m->d = v;
      else if (KEY("Tr")) m->d = 1.0f - v;
      else if (KEY("Pr")) m->pr = v, m->has_pr = true;
      else if (KEY("Pm")) m->pm = v, m->has_pm = true;
      else m->illum = (int)v;
    } else if (KEY("map_Kd") || KEY("map_Ke")) {
      bool clamp;
      char *path = parse_map(a, le, mtl_dir, &clamp, mtl_path, line);
      if (KEY("map_Kd")) free(m->map_kd), m->map_kd = path, m->map_kd_clamp = clamp;
      else free(m->map_ke), m->map_ke = path, m->map_ke_clamp = clamp;
    } else {
      /* Ka, map_Ka, map_Ks, map_Ns, map_d, bump, map_bump, norm, disp, decal,
       * refl, sharpness, Ps, Pc, Pcr, aniso, anisor, map_Pr, map_Pm, ... */
      note_ignored(ignored, sizeof ignored, k, kn);
    }
#undef KEY
    p = e + (e < end);
  }
  if (ignored[0]) iris_warnf("%s: MTL keys ignored: %s", mtl_path, ignored);
  return IRIS_OK;
}

static void load_mtllib(obj_ctx *c, const char *a, const char *le, long line) {
  if (!c->dir) return; /* parsing from memory without a folder */
  char names[1024];
  copy_rest(a, le, names, sizeof names);
  /* Usually one file; several are separated by spaces. Try the whole string
   * first (names with spaces), then each word. */
  char full[2048];
  iris_path_join(c->dir, names, full, sizeof full);
  const char *list[16];
  int count = 0;
  char *save = NULL;
  if (iris_path_exists(full)) {
    list[count++] = names;
  } else {
    for (char *t = strtok_r(names, " \t", &save); t && count < 16; t = strtok_r(NULL, " \t", &save))
      list[count++] = t;
  }
  for (int i = 0; i < count; i++) {
    char nm[1024];
    snprintf(nm, sizeof nm, "%s", list[i]);
    for (char *ch = nm; *ch; ch++)
      if (*ch == '\\') *ch = '/';
    iris_path_join(c->dir, nm, full, sizeof full);
    if (iris_strmap_find(&c->mtllib_map, full)) continue; /* read once, however often named */
    iris_strmap_put(&c->mtllib_map, full, 0);
    char *data = NULL;
    size_t size = 0;
    iris_error e;
    iris_error_clear(&e);
    if (iris_file_read(full, (size_t)1 << 28, &data, &size, &e) != IRIS_OK) {
      iris_warnf("%s:%ld: cannot read material library '%s'; its materials get the default", c->path,
                 line, nm);
      continue;
    }
    parse_mtl(c, data, size, full);
    free(data);
  }
}

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
      load_mtllib(c, a, le, line);
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

/* ---- materials into the scene ------------------------------------------ */

static int32_t add_texture(obj_ctx *c, const char *path, bool clamp) {
  char key[4096];
  snprintf(key, sizeof key, "%d%s", clamp ? 1 : 0, path);
  const int32_t *found = iris_strmap_find(&c->texture_map, key);
  if (found) return *found;
  const char *mime = mime_of(path);
  if (!mime) {
    iris_warnf("%s: texture '%s' ignored: only PNG and JPEG are supported", c->path, path);
    return -1;
  }
  if (!iris_path_exists(path)) {
    iris_warnf("%s: texture '%s' not found; ignored", c->path, path);
    return -1;
  }
  iris_texture t;
  memset(&t, 0, sizeof t);
  t.path = iris_strdup(path);
  snprintf(t.mime, sizeof t.mime, "%s", mime);
  t.wrap_s = t.wrap_t = clamp ? IRIS_WRAP_CLAMP : IRIS_WRAP_REPEAT;
  if (!t.path) return -1;
  const int32_t id = iris_scene_add_texture(c->scene, &t);
  if (id >= 0) iris_strmap_put(&c->texture_map, key, id);
  return id;
}

static float maxf3(const float *v) {
  float m = v[0] > v[1] ? v[0] : v[1];
  return m > v[2] ? m : v[2];
}

/* The MTL -> iris material mapping (docs/import-obj-ply.md, "MTL mapping"). */
static iris_material material_from_mtl(obj_ctx *c, const mtl_material *m) {
  const float ns = m->ns < 0 ? 0 : (m->ns > 1e6f ? 1e6f : m->ns);
  /* Blinn-Phong exponent -> Beckmann/GGX alpha (Walter et al. 2007), roughness = sqrt(alpha). */
  const float ns_roughness = sqrtf(sqrtf(2.0f / (ns + 2.0f)));
  const float ior = (m->has_ni && m->ni > 1.0f) ? m->ni : 1.5f;
  const bool glass = m->illum == 4 || m->illum == 6 || m->illum == 7 || m->illum == 9 || m->d < 1.0f;
  iris_material mat;
  if (glass) {
    mat = iris_material_default(IRIS_MATERIAL_GLASS);
    if (m->has_tf) memcpy(mat.color, m->tf, sizeof mat.color);
    else mat.color[0] = mat.color[1] = mat.color[2] = 1.0f;
    mat.roughness = 0.0f;
    mat.ior = ior;
  } else if (m->has_pr || m->has_pm) {
    mat = iris_material_default(IRIS_MATERIAL_GLTF);
    memcpy(mat.color, m->kd, sizeof mat.color);
    mat.roughness = m->has_pr ? fminf(fmaxf(m->pr, 0), 1) : ns_roughness;
    mat.metallic = m->has_pm ? fminf(fmaxf(m->pm, 0), 1) : 0;
    mat.ior = ior;
  } else if (maxf3(m->ks) > 0) {
    if (maxf3(m->kd) > 0) {
      /* Diffuse + specular: a dielectric glTF material whose normal-incidence
       * reflectance F0 = 0.04 * specular_color equals Ks. */
      mat = iris_material_default(IRIS_MATERIAL_GLTF);
      memcpy(mat.color, m->kd, sizeof mat.color);
      mat.roughness = ns_roughness;
      mat.metallic = 0;
      mat.ior = 1.5f;
      mat.specular = 1;
      for (int i = 0; i < 3; i++) mat.specular_color[i] = fminf(m->ks[i], 1.0f) / 0.04f;
    } else {
      mat = iris_material_default(IRIS_MATERIAL_GLOSSY);
      memcpy(mat.color, m->ks, sizeof mat.color);
      mat.roughness = ns_roughness;
    }
  } else {
    mat = iris_material_default(IRIS_MATERIAL_DIFFUSE);
    memcpy(mat.color, m->kd, sizeof mat.color);
  }
  mat.name = iris_strdup(m->name);
  if (maxf3(m->ke) > 0) {
    memcpy(mat.emission, m->ke, sizeof mat.emission);
    mat.emission_two_sided = true;
  }
  if (m->map_kd && !glass) mat.color_texture = add_texture(c, m->map_kd, m->map_kd_clamp);
  if (m->map_ke) {
    mat.emission_texture = add_texture(c, m->map_ke, m->map_ke_clamp);
    if (mat.emission_texture >= 0 && maxf3(m->ke) <= 0)
      mat.emission[0] = mat.emission[1] = mat.emission[2] = 1.0f, mat.emission_two_sided = true;
  }
  return mat;
}

/* Scene material index for a usemtl name; -1 (default) for none/unknown. */
static int32_t resolve_material(obj_ctx *c, const char *name, bool *warned) {
  if (!name[0]) return -1;
  if (!c->mtl_map_built) { /* the last definition wins */
    for (size_t i = 0; i < c->mtl_count && i < INT32_MAX; i++) iris_strmap_put(&c->mtl_map, c->mtls[i].name, (int32_t)i);
    c->mtl_map_built = true;
  }
  const int32_t *found = iris_strmap_find(&c->mtl_map, name);
  if (found) {
    mtl_material *m = &c->mtls[*found];
    if (m->scene_index == -2) {
      iris_material mat = material_from_mtl(c, m);
      m->scene_index = iris_scene_add_material(c->scene, &mat);
    }
    return m->scene_index;
  }
  if (!*warned) {
    iris_warnf("%s: material '%s' is not defined%s; the default material is used", c->path, name,
               c->dir ? "" : " (material libraries are not read from memory)");
    *warned = true;
  }
  return -1;
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
  m.material = resolve_material(c, g->material, &warned);
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
