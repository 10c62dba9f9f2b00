/* Private to the OBJ importer: the parse state that obj.c (OBJ lines, meshes)
 * and obj_mtl.c (MTL libraries, materials and textures into the scene) share,
 * and the small line-scanning helpers both use. Not a public interface. */
#ifndef IRIS_IMPORTERS_OBJ_PRIVATE_H
#define IRIS_IMPORTERS_OBJ_PRIVATE_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "importers/import.h"
#include "importers/numparse.h"
#include "importers/strmap.h"

#define OBJ_MAX_FILE_SIZE ((size_t)1 << 34) /* 16 GiB */
#define OBJ_NAME_MAX 256
#define OBJ_NO_INDEX (-1)
#define OBJ_FLAT (-2) /* vn of a corner of a face outside any smoothing group */

/* ---- small growable arrays --------------------------------------------- */

static inline bool grow(void **ptr, size_t *cap, size_t need, size_t elem) {
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

static inline bool floats_push(floats *a, const float *x, size_t n) {
  if (!grow((void **)&a->v, &a->cap, a->count + n, sizeof(float))) return false;
  memcpy(a->v + a->count, x, n * sizeof(float));
  a->count += n;
  return true;
}

/* ---- the parse state ------------------------------------------------------ */

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

static inline void note_ignored(char *list, size_t size, const char *key, size_t key_len) {
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
static inline void copy_rest(const char *p, const char *end, char *out, size_t size) {
  p = iris_np_skip_space(p, end);
  while (end > p && iris_np_is_space(end[-1])) end--;
  size_t n = (size_t)(end - p);
  if (n >= size) n = size - 1;
  memcpy(out, p, n);
  out[n] = 0;
}

static inline const char *line_end(const char *p, const char *end) {
  const char *e = memchr(p, '\n', (size_t)(end - p));
  return e ? e : end;
}

/* Strips a trailing comment: a '#' at the start or after white space (so
 * MSVC's "1.#IND" stays a number, to be rejected as non-finite). */
static inline const char *strip_comment(const char *p, const char *e) {
  for (const char *h = p; (h = memchr(h, '#', (size_t)(e - h))) != NULL; h++)
    if (h == p || iris_np_is_space(h[-1])) return h;
  return e;
}

static inline bool parse_floats(const char **pp, const char *end, float *out, int max, int *count) {
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

static inline bool all_finite(const float *v, int n) {
  for (int i = 0; i < n; i++)
    if (!isfinite(v[i])) return false;
  return true;
}

/* ---- obj_mtl.c ------------------------------------------------------------ */

/* `mtllib` on line `line` (its arguments in [a, le)): reads each library named
 * (once per file, however often named) into c->mtls; a missing one is a warning. */
void obj_load_mtllib(obj_ctx *c, const char *a, const char *le, long line);
/* Scene material index for a usemtl name, added on first use with its
 * textures; -1 (the default) for none or unknown (warned about once). */
int32_t obj_resolve_material(obj_ctx *c, const char *name, bool *warned);

#endif
