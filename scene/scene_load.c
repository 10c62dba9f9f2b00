/* The scene JSON (docs/format.md), loading: parses leniently into the scene
 * model (types checked, unknown keys warned about), reads the mesh files
 * (mesh_file.c) and textures, then iris_scene_validate checks every
 * invariant. Writing: scene_write.c. */
/* realpath() is an X/Open extension in the glibc headers. */
#define _XOPEN_SOURCE 700

#include <cjson/cJSON.h>
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/fileio.h"
#include "core/log.h"
#include "scene/mesh_file.h"
#include "scene/scene.h"
#include "scene/scene_json.h"

#define MAX_JSON_BYTES ((size_t)256 << 20)

/* ====================================================================== */
/* Loading                                                                 */
/* ====================================================================== */

typedef struct jctx {
  const char *file; /* JSON path, for messages */
  iris_error *err;
  char element[96];
} jctx;

static iris_status jfail(jctx *c, iris_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static iris_status jfail(jctx *c, iris_status status, const char *fmt, ...) {
  char msg[400];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return iris_error_set(c->err, status, c->file, 0, c->element[0] ? c->element : NULL, "%s", msg);
}

static void set_element(jctx *c, const char *array, size_t i) {
  snprintf(c->element, sizeof c->element, "%s[%zu]", array, i);
}

static int cmp_key(const void *a, const void *b) {
  return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* The first key (in sorted order) that appears twice, or NULL. Sorting keeps
 * this O(k log k): a pairwise check was quadratic in the number of keys, which
 * a file controls. Small objects (all of a valid scene) are checked pairwise. */
static const char *duplicate_key(jctx *c, const cJSON *o, iris_status *st) {
  size_t k = 0;
  for (const cJSON *it = o->child; it; it = it->next) k++;
  if (k <= 32) {
    for (const cJSON *it = o->child; it; it = it->next)
      for (const cJSON *prev = o->child; prev != it; prev = prev->next)
        if (strcmp(prev->string, it->string) == 0) return it->string;
    return NULL;
  }
  const char **keys = malloc(k * sizeof *keys);
  if (!keys) {
    *st = jfail(c, IRIS_ERR_NOMEM, "out of memory");
    return NULL;
  }
  k = 0;
  for (const cJSON *it = o->child; it; it = it->next) keys[k++] = it->string;
  qsort(keys, k, sizeof *keys, cmp_key);
  const char *dup = NULL;
  for (size_t i = 1; i < k && !dup; i++)
    if (strcmp(keys[i - 1], keys[i]) == 0) dup = keys[i];
  free(keys);
  return dup;
}

/* Object check: must be an object; unknown keys warn; duplicate keys fail. */
static iris_status check_keys(jctx *c, const cJSON *o, const char *const *known, size_t n) {
  if (!cJSON_IsObject(o)) return jfail(c, IRIS_ERR_INVALID, "expected an object");
  iris_status st = IRIS_OK;
  const char *dup = duplicate_key(c, o, &st);
  if (st != IRIS_OK) return st;
  if (dup) return jfail(c, IRIS_ERR_INVALID, "duplicate key '%s'", dup);
  for (const cJSON *it = o->child; it; it = it->next) {
    bool found = false;
    for (size_t k = 0; k < n && !found; k++) found = strcmp(known[k], it->string) == 0;
    if (!found) {
      if (c->element[0])
        iris_warnf("%s: %s: unknown key '%s' (ignored)", c->file, c->element, it->string);
      else
        iris_warnf("%s: unknown key '%s' (ignored)", c->file, it->string);
    }
  }
  return IRIS_OK;
}

static const cJSON *item(const cJSON *o, const char *key) { return cJSON_GetObjectItemCaseSensitive(o, key); }

static iris_status require(jctx *c, const cJSON *o, const char *key) {
  return item(o, key) ? IRIS_OK : jfail(c, IRIS_ERR_INVALID, "missing required key '%s'", key);
}

/* Numbers keep the caller's default when the key is absent. */
static iris_status get_float(jctx *c, const cJSON *o, const char *key, float *out) {
  const cJSON *v = item(o, key);
  if (!v) return IRIS_OK;
  if (!cJSON_IsNumber(v)) return jfail(c, IRIS_ERR_INVALID, "'%s' must be a number", key);
  if (!isfinite(v->valuedouble) || fabs(v->valuedouble) > FLT_MAX)
    return jfail(c, IRIS_ERR_INVALID, "'%s' is not a finite 32-bit float", key);
  *out = (float)v->valuedouble;
  return IRIS_OK;
}

static iris_status get_double(jctx *c, const cJSON *o, const char *key, double *out) {
  const cJSON *v = item(o, key);
  if (!v) return IRIS_OK;
  if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble))
    return jfail(c, IRIS_ERR_INVALID, "'%s' must be a finite number", key);
  *out = v->valuedouble;
  return IRIS_OK;
}

static iris_status get_floats(jctx *c, const cJSON *o, const char *key, float *out, int n) {
  const cJSON *v = item(o, key);
  if (!v) return IRIS_OK;
  if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != n)
    return jfail(c, IRIS_ERR_INVALID, "'%s' must be an array of %d numbers", key, n);
  int i = 0;
  for (const cJSON *e = v->child; e; e = e->next, i++) {
    if (!cJSON_IsNumber(e)) return jfail(c, IRIS_ERR_INVALID, "'%s' must be an array of %d numbers", key, n);
    if (!isfinite(e->valuedouble) || fabs(e->valuedouble) > FLT_MAX)
      return jfail(c, IRIS_ERR_INVALID, "'%s'[%d] is not a finite 32-bit float", key, i);
    out[i] = (float)e->valuedouble;
  }
  return IRIS_OK;
}

static iris_status get_int(jctx *c, const cJSON *o, const char *key, double lo, double hi,
                           double *out) {
  const cJSON *v = item(o, key);
  if (!v) return IRIS_OK;
  if (!cJSON_IsNumber(v) || v->valuedouble != floor(v->valuedouble) || v->valuedouble < lo ||
      v->valuedouble > hi)
    return jfail(c, IRIS_ERR_INVALID, "'%s' must be an integer in [%.0f, %.0f]", key, lo, hi);
  *out = v->valuedouble;
  return IRIS_OK;
}

static iris_status get_i32(jctx *c, const cJSON *o, const char *key, double lo, double hi, int32_t *out) {
  double d = *out;
  iris_status st = get_int(c, o, key, lo, hi, &d);
  *out = (int32_t)d;
  return st;
}

static iris_status get_string(jctx *c, const cJSON *o, const char *key, const char **out) {
  const cJSON *v = item(o, key);
  if (!v) return IRIS_OK;
  if (!cJSON_IsString(v)) return jfail(c, IRIS_ERR_INVALID, "'%s' must be a string", key);
  *out = v->valuestring;
  return IRIS_OK;
}

static iris_status get_bool(jctx *c, const cJSON *o, const char *key, bool *out) {
  const cJSON *v = item(o, key);
  if (!v) return IRIS_OK;
  if (!cJSON_IsBool(v)) return jfail(c, IRIS_ERR_INVALID, "'%s' must be true or false", key);
  *out = cJSON_IsTrue(v);
  return IRIS_OK;
}

/* A string from a fixed list; *out keeps its default when absent. */
static iris_status get_enum(jctx *c, const cJSON *o, const char *key, const char *const *names,
                            int count, int *out) {
  const char *s = NULL;
  iris_status st = get_string(c, o, key, &s);
  if (st != IRIS_OK || !s) return st;
  for (int i = 0; i < count; i++)
    if (strcmp(names[i], s) == 0) {
      *out = i;
      return IRIS_OK;
    }
  char list[160] = "";
  for (int i = 0; i < count; i++)
    snprintf(list + strlen(list), sizeof list - strlen(list), "%s'%s'", i ? ", " : "", names[i]);
  return jfail(c, IRIS_ERR_INVALID, "'%s' is '%s', expected one of %s", key, s, list);
}

static iris_status get_name(jctx *c, const cJSON *o, char **out) {
  const char *s = NULL;
  iris_status st = get_string(c, o, "name", &s);
  if (st != IRIS_OK || !s) return st;
  *out = iris_strdup(s);
  return *out ? IRIS_OK : jfail(c, IRIS_ERR_NOMEM, "out of memory");
}

/* An optional top-level array: absent means empty. */
static iris_status get_array(jctx *c, const cJSON *root, const char *key, const cJSON **out) {
  *out = item(root, key);
  if (*out && !cJSON_IsArray(*out)) {
    c->element[0] = '\0';
    return jfail(c, IRIS_ERR_INVALID, "'%s' must be an array", key);
  }
  return IRIS_OK;
}

#define TRY(expr)                        \
  do {                                   \
    iris_status st_ = (expr);            \
    if (st_ != IRIS_OK) return st_;      \
  } while (0)

static iris_status load_camera(jctx *c, const cJSON *o, iris_camera *cam) {
  static const char *const keys[] = {"name", "to_world", "position", "target", "up", "yfov_deg", "aspect"};
  TRY(check_keys(c, o, keys, sizeof keys / sizeof *keys));
  TRY(get_name(c, o, &cam->name));
  TRY(require(c, o, "yfov_deg"));
  double deg = 0;
  TRY(get_double(c, o, "yfov_deg", &deg));
  if (!(deg > 0.0 && deg < 180.0)) return jfail(c, IRIS_ERR_INVALID, "yfov_deg %g outside (0, 180)", deg);
  cam->yfov = deg_to_rad(deg);
  TRY(get_float(c, o, "aspect", &cam->aspect));
  bool matrix = item(o, "to_world") != NULL;
  bool look = item(o, "position") || item(o, "target") || item(o, "up");
  if (matrix && look) return jfail(c, IRIS_ERR_INVALID, "give either 'to_world' or 'position'/'target'/'up', not both");
  if (matrix) return get_floats(c, o, "to_world", &cam->to_world.m[0][0], 16);
  TRY(require(c, o, "position"));
  TRY(require(c, o, "target"));
  float eye[3], target[3], up[3] = {0, 1, 0};
  TRY(get_floats(c, o, "position", eye, 3));
  TRY(get_floats(c, o, "target", target, 3));
  TRY(get_floats(c, o, "up", up, 3));
  if (floats_equal(eye, target, 3)) return jfail(c, IRIS_ERR_INVALID, "'target' equals 'position'");
  if (!(iris_length(iris_v3_load(up)) > 0.0f)) return jfail(c, IRIS_ERR_INVALID, "'up' is a zero vector");
  cam->to_world = iris_mat4_look_at(iris_v3_load(eye), iris_v3_load(target), iris_v3_load(up));
  return IRIS_OK;
}

static iris_status load_material(jctx *c, const cJSON *o, iris_material *m) {
  static const char *const keys[] = {"name", "type", "color", "color_texture", "roughness", "ior",
                                     "metallic", "metallic_roughness_texture", "specular",
                                     "specular_color", "transmission", "emission", "emission_texture",
                                     "emission_two_sided", "unlit", "double_sided", "normal_texture",
                                     "normal_scale", "alpha_mode", "alpha", "alpha_cutoff", "clearcoat",
                                     "clearcoat_roughness", "clearcoat_texture",
                                     "clearcoat_roughness_texture", "clearcoat_normal_texture",
                                     "clearcoat_normal_scale", "sheen_color", "sheen_roughness",
                                     "sheen_color_texture", "sheen_roughness_texture",
                                     "attenuation_color", "attenuation_distance", "transmission_texture",
                                     "specular_texture", "specular_color_texture", "anisotropy",
                                     "anisotropy_rotation", "anisotropy_texture"};
  TRY(check_keys(c, o, keys, sizeof keys / sizeof *keys));
  TRY(require(c, o, "type"));
  int type = 0;
  TRY(get_enum(c, o, "type", MATERIAL_TYPES, 4, &type));
  *m = iris_material_default((iris_material_type)type);
  TRY(get_name(c, o, &m->name));
  /* Fields that do not apply to the type are read (so their types are
   * checked) but reported as ignored, and the defaults kept. */
  static const struct {
    const char *key;
    unsigned types; /* bit per iris_material_type */
  } applies[] = {{"roughness", 0xE}, {"ior", 0xC}, {"metallic", 0x8}, {"metallic_roughness_texture", 0x8},
                 {"specular", 0x8}, {"specular_color", 0x8}, {"transmission", 0x8},
                 {"clearcoat", 0x8}, {"clearcoat_roughness", 0x8}, {"clearcoat_texture", 0x8},
                 {"clearcoat_roughness_texture", 0x8}, {"clearcoat_normal_texture", 0x8},
                 {"clearcoat_normal_scale", 0x8}, {"sheen_color", 0x8}, {"sheen_roughness", 0x8},
                 {"sheen_color_texture", 0x8}, {"sheen_roughness_texture", 0x8},
                 {"attenuation_color", 0x8}, {"attenuation_distance", 0x8}, {"transmission_texture", 0x8},
                 {"specular_texture", 0x8}, {"specular_color_texture", 0x8}, {"anisotropy", 0x8},
                 {"anisotropy_rotation", 0x8}, {"anisotropy_texture", 0x8}};
  for (size_t k = 0; k < sizeof applies / sizeof *applies; k++)
    if (item(o, applies[k].key) && !(applies[k].types & (1u << type)))
      iris_warnf("%s: %s: '%s' does not apply to a %s material (ignored)", c->file, c->element,
                 applies[k].key, MATERIAL_TYPES[type]);
  iris_material full = *m;
  TRY(get_floats(c, o, "color", full.color, 3));
  TRY(get_i32(c, o, "color_texture", -1, INT32_MAX, &full.color_texture));
  TRY(get_float(c, o, "roughness", &full.roughness));
  TRY(get_float(c, o, "ior", &full.ior));
  TRY(get_float(c, o, "metallic", &full.metallic));
  TRY(get_i32(c, o, "metallic_roughness_texture", -1, INT32_MAX, &full.metallic_roughness_texture));
  TRY(get_float(c, o, "specular", &full.specular));
  TRY(get_floats(c, o, "specular_color", full.specular_color, 3));
  TRY(get_float(c, o, "transmission", &full.transmission));
  TRY(get_floats(c, o, "emission", full.emission, 3));
  TRY(get_i32(c, o, "emission_texture", -1, INT32_MAX, &full.emission_texture));
  TRY(get_bool(c, o, "emission_two_sided", &full.emission_two_sided));
  TRY(get_bool(c, o, "unlit", &m->unlit));
  TRY(get_bool(c, o, "double_sided", &full.double_sided));
  TRY(get_i32(c, o, "normal_texture", -1, INT32_MAX, &m->normal_texture));
  TRY(get_float(c, o, "normal_scale", &m->normal_scale));
  int alpha_mode = IRIS_ALPHA_OPAQUE;
  TRY(get_enum(c, o, "alpha_mode", ALPHA_MODES, 3, &alpha_mode));
  m->alpha_mode = (iris_alpha_mode)alpha_mode;
  TRY(get_float(c, o, "alpha", &m->alpha));
  TRY(get_float(c, o, "alpha_cutoff", &m->alpha_cutoff));
  memcpy(m->color, full.color, sizeof m->color);
  m->color_texture = full.color_texture;
  if (type != IRIS_MATERIAL_DIFFUSE) m->roughness = full.roughness;
  if (type == IRIS_MATERIAL_GLASS || type == IRIS_MATERIAL_GLTF) m->ior = full.ior;
  if (type == IRIS_MATERIAL_GLTF) {
    m->metallic = full.metallic;
    m->metallic_roughness_texture = full.metallic_roughness_texture;
    m->specular = full.specular;
    memcpy(m->specular_color, full.specular_color, sizeof m->specular_color);
    m->transmission = full.transmission;
  }
  if (type == IRIS_MATERIAL_GLTF) {
    TRY(get_float(c, o, "clearcoat", &m->clearcoat));
    TRY(get_float(c, o, "clearcoat_roughness", &m->clearcoat_roughness));
    TRY(get_i32(c, o, "clearcoat_texture", -1, INT32_MAX, &m->clearcoat_texture));
    TRY(get_i32(c, o, "clearcoat_roughness_texture", -1, INT32_MAX, &m->clearcoat_roughness_texture));
    TRY(get_i32(c, o, "clearcoat_normal_texture", -1, INT32_MAX, &m->clearcoat_normal_texture));
    TRY(get_float(c, o, "clearcoat_normal_scale", &m->clearcoat_normal_scale));
    TRY(get_floats(c, o, "sheen_color", m->sheen_color, 3));
    TRY(get_float(c, o, "sheen_roughness", &m->sheen_roughness));
    TRY(get_i32(c, o, "sheen_color_texture", -1, INT32_MAX, &m->sheen_color_texture));
    TRY(get_i32(c, o, "sheen_roughness_texture", -1, INT32_MAX, &m->sheen_roughness_texture));
    TRY(get_floats(c, o, "attenuation_color", m->attenuation_color, 3));
    TRY(get_float(c, o, "attenuation_distance", &m->attenuation_distance));
    TRY(get_i32(c, o, "transmission_texture", -1, INT32_MAX, &m->transmission_texture));
    TRY(get_i32(c, o, "specular_texture", -1, INT32_MAX, &m->specular_texture));
    TRY(get_i32(c, o, "specular_color_texture", -1, INT32_MAX, &m->specular_color_texture));
    TRY(get_float(c, o, "anisotropy", &m->anisotropy));
    TRY(get_float(c, o, "anisotropy_rotation", &m->anisotropy_rotation));
    TRY(get_i32(c, o, "anisotropy_texture", -1, INT32_MAX, &m->anisotropy_texture));
  }
  memcpy(m->emission, full.emission, sizeof m->emission);
  m->emission_texture = full.emission_texture;
  m->emission_two_sided = full.emission_two_sided;
  m->double_sided = full.double_sided;
  return IRIS_OK;
}

/* Reads the texture's first bytes to learn its type (and that it exists). */
static iris_status load_texture_file(jctx *c, const char *dir, const char *file, iris_texture *t) {
  char joined[PATH_MAX];
  iris_path_join(dir, file, joined, sizeof joined);
  t->path = realpath(joined, NULL);
  if (!t->path) return jfail(c, IRIS_ERR_IO, "cannot find texture file '%s': %s", joined, strerror(errno));
  FILE *fp = fopen(t->path, "rb");
  unsigned char magic[8] = {0};
  size_t n = fp ? fread(magic, 1, sizeof magic, fp) : 0;
  if (fp) fclose(fp);
  if (!fp) return jfail(c, IRIS_ERR_IO, "cannot open texture file '%s': %s", joined, strerror(errno));
  if (n == 8 && memcmp(magic, "\x89PNG\r\n\x1a\n", 8) == 0)
    memcpy(t->mime, "image/png", 10);
  else if (n >= 3 && magic[0] == 0xFF && magic[1] == 0xD8 && magic[2] == 0xFF)
    memcpy(t->mime, "image/jpeg", 11);
  else
    return jfail(c, IRIS_ERR_UNSUPPORTED, "texture file '%s' is not a PNG or JPEG image", joined);
  return IRIS_OK;
}

static iris_status load_texture(jctx *c, const cJSON *o, const char *dir, iris_texture *t) {
  static const char *const keys[] = {"name", "file", "wrap_s", "wrap_t", "filter", "uv_set", "transform"};
  static const char *const filters[] = {"linear", "nearest"};
  TRY(check_keys(c, o, keys, sizeof keys / sizeof *keys));
  TRY(get_name(c, o, &t->name));
  int ws = IRIS_WRAP_REPEAT, wt = IRIS_WRAP_REPEAT, filter = 0;
  TRY(get_enum(c, o, "wrap_s", WRAP_MODES, 3, &ws));
  TRY(get_enum(c, o, "wrap_t", WRAP_MODES, 3, &wt));
  TRY(get_enum(c, o, "filter", filters, 2, &filter));
  t->wrap_s = (iris_wrap)ws;
  t->wrap_t = (iris_wrap)wt;
  t->nearest = filter == 1;
  int32_t uv_set = 0;
  TRY(get_i32(c, o, "uv_set", 0, 1, &uv_set));
  t->uv_set = (uint8_t)uv_set;
  const cJSON *x = item(o, "transform");
  if (x) {
    static const char *const xkeys[] = {"offset", "rotation", "scale"};
    TRY(check_keys(c, x, xkeys, sizeof xkeys / sizeof *xkeys));
    t->has_transform = true;
    t->scale[0] = t->scale[1] = 1.0f;
    TRY(get_floats(c, x, "offset", t->offset, 2));
    TRY(get_float(c, x, "rotation", &t->rotation));
    TRY(get_floats(c, x, "scale", t->scale, 2));
  }
  TRY(require(c, o, "file"));
  const char *file = NULL;
  TRY(get_string(c, o, "file", &file));
  if (!file[0]) return jfail(c, IRIS_ERR_INVALID, "'file' is empty");
  return load_texture_file(c, dir, file, t);
}

/* JSON side of a mesh; the file is read afterwards by load_mesh_file. */
typedef struct mesh_desc {
  const char *file;
  double vertices, triangles; /* -1 when absent */
  int attributes;             /* IRIS_MESH_HAS_* bits, -1 when absent */
} mesh_desc;

static iris_status load_mesh_desc(jctx *c, const cJSON *o, iris_mesh *m, mesh_desc *d) {
  static const char *const keys[] = {"name", "file", "material", "vertices", "triangles", "attributes"};
  TRY(check_keys(c, o, keys, sizeof keys / sizeof *keys));
  TRY(get_name(c, o, &m->name));
  m->material = -1;
  TRY(get_i32(c, o, "material", -1, INT32_MAX, &m->material));
  TRY(require(c, o, "file"));
  d->file = NULL;
  TRY(get_string(c, o, "file", &d->file));
  if (!d->file[0]) return jfail(c, IRIS_ERR_INVALID, "'file' is empty");
  d->vertices = d->triangles = -1;
  TRY(get_int(c, o, "vertices", 1, UINT32_MAX, &d->vertices));
  TRY(get_int(c, o, "triangles", 1, UINT32_MAX, &d->triangles));
  d->attributes = -1;
  const cJSON *a = item(o, "attributes");
  if (a) {
    if (!cJSON_IsArray(a)) return jfail(c, IRIS_ERR_INVALID, "'attributes' must be an array of strings");
    d->attributes = 0;
    for (const cJSON *e = a->child; e; e = e->next) {
      int k = 0;
      while (k < ATTRIBUTE_COUNT && !(cJSON_IsString(e) && strcmp(e->valuestring, ATTRIBUTE_NAMES[k]) == 0)) k++;
      if (k == ATTRIBUTE_COUNT)
        return jfail(c, IRIS_ERR_INVALID,
                     "'attributes' entries must be \"normals\", \"uvs\", \"colors\", \"uvs1\", "
                     "\"tangents\" or \"alphas\"");
      if (d->attributes & (1 << k)) return jfail(c, IRIS_ERR_INVALID, "'%s' listed twice in 'attributes'", ATTRIBUTE_NAMES[k]);
      d->attributes |= 1 << k;
    }
  }
  return IRIS_OK;
}

static iris_status load_mesh_file(jctx *c, const char *dir, const mesh_desc *d, iris_mesh *m,
                                  iris_file_map *map) {
  char path[PATH_MAX];
  iris_path_join(dir, d->file, path, sizeof path);
  TRY(iris_file_map_open(path, map, c->err));
  iris_mesh loaded;
  TRY(iris_mesh_read_map(map, path, &loaded, c->err));
  if (d->vertices >= 0 && (uint32_t)d->vertices != loaded.vertex_count)
    return jfail(c, IRIS_ERR_INVALID, "'vertices' is %.0f but %s has %u", d->vertices, d->file,
                 (unsigned)loaded.vertex_count);
  if (d->triangles >= 0 && (uint32_t)d->triangles != loaded.triangle_count)
    return jfail(c, IRIS_ERR_INVALID, "'triangles' is %.0f but %s has %u", d->triangles, d->file,
                 (unsigned)loaded.triangle_count);
  if (d->attributes >= 0 && (uint32_t)d->attributes != iris_mesh_file_flags(&loaded))
    return jfail(c, IRIS_ERR_INVALID, "'attributes' do not match the attributes stored in %s", d->file);
  loaded.name = m->name;
  loaded.material = m->material;
  *m = loaded;
  return IRIS_OK;
}

static iris_status load_instance(jctx *c, const cJSON *o, iris_instance *inst) {
  static const char *const keys[] = {"mesh", "transform"};
  TRY(check_keys(c, o, keys, sizeof keys / sizeof *keys));
  TRY(require(c, o, "mesh"));
  double mesh = 0;
  TRY(get_int(c, o, "mesh", 0, UINT32_MAX, &mesh));
  inst->mesh = (uint32_t)mesh;
  inst->transform = iris_mat4_identity();
  return get_floats(c, o, "transform", &inst->transform.m[0][0], 16);
}

static iris_status load_light(jctx *c, const cJSON *o, iris_light *l) {
  static const char *const keys[] = {"name", "type", "color", "intensity", "position", "direction",
                                     "range", "inner_cone_deg", "outer_cone_deg"};
  TRY(check_keys(c, o, keys, sizeof keys / sizeof *keys));
  TRY(get_name(c, o, &l->name));
  TRY(require(c, o, "type"));
  int type = 0;
  TRY(get_enum(c, o, "type", LIGHT_TYPES, 3, &type));
  l->type = (iris_light_type)type;
  l->color[0] = l->color[1] = l->color[2] = 1.0f;
  l->intensity = 1.0f;
  l->outer_cone = 0.25f * IRIS_PI;
  TRY(get_floats(c, o, "color", l->color, 3));
  TRY(get_float(c, o, "intensity", &l->intensity));
  if (l->type != IRIS_LIGHT_DIRECTIONAL) TRY(require(c, o, "position"));
  if (l->type != IRIS_LIGHT_POINT) TRY(require(c, o, "direction"));
  TRY(get_floats(c, o, "position", l->position, 3));
  TRY(get_floats(c, o, "direction", l->direction, 3));
  TRY(get_float(c, o, "range", &l->range));
  double inner = -1, outer = -1;
  TRY(get_double(c, o, "inner_cone_deg", &inner));
  TRY(get_double(c, o, "outer_cone_deg", &outer));
  if (inner != -1) l->inner_cone = deg_to_rad(inner);
  if (outer != -1) l->outer_cone = deg_to_rad(outer);
  return IRIS_OK;
}

static iris_status load_render(jctx *c, const cJSON *o, iris_render_settings *r) {
  static const char *const keys[] = {"width", "height", "spp", "max_depth", "method", "seed"};
  TRY(check_keys(c, o, keys, sizeof keys / sizeof *keys));
  double width = 0, height = 0, spp = 0, max_depth = -1;
  TRY(get_int(c, o, "width", 0, 65536, &width));
  TRY(get_int(c, o, "height", 0, 65536, &height));
  TRY(get_int(c, o, "spp", 0, INT_MAX, &spp));
  TRY(get_int(c, o, "max_depth", -1, INT_MAX, &max_depth));
  r->width = (int)width;
  r->height = (int)height;
  r->spp = (int)spp;
  r->max_depth = (int)max_depth;
  const char *method = NULL;
  TRY(get_string(c, o, "method", &method));
  if (method) {
    if (strlen(method) >= sizeof r->method)
      return jfail(c, IRIS_ERR_INVALID, "'method' is longer than %zu characters", sizeof r->method - 1);
    strcpy(r->method, method);
  }
  const cJSON *seed = item(o, "seed");
  if (seed) {
    r->has_seed = true;
    if (cJSON_IsString(seed)) {
      const char *s = seed->valuestring;
      char *end = NULL;
      errno = 0;
      unsigned long long u = strtoull(s, &end, 10);
      if (!s[0] || s[0] == '-' || s[0] == '+' || *end || errno)
        return jfail(c, IRIS_ERR_INVALID, "'seed' must be a non-negative 64-bit integer");
      r->seed = u;
    } else {
      double d = 0;
      TRY(get_int(c, o, "seed", 0, 9007199254740992.0, &d));
      r->seed = (uint64_t)d;
    }
  }
  return IRIS_OK;
}

/* 1-based line of byte `offset` in text. */
static long line_of(const char *text, size_t offset) {
  long line = 1;
  for (size_t i = 0; i < offset; i++)
    if (text[i] == '\n') line++;
  return line;
}

/* Reserves n zeroed elements for an array the loader fills in place. */
static void *alloc_array(jctx *c, size_t n, size_t size, iris_status *st) {
  if (n == 0) return NULL;
  void *p = calloc(n, size);
  if (!p) *st = jfail(c, IRIS_ERR_NOMEM, "out of memory");
  return p;
}

/* "material_variants": {"names": [...], "applied": NAME} (applied absent: the defaults). */
static iris_status load_variants(jctx *c, const cJSON *o, iris_material_variants *v) {
  static const char *const keys[] = {"names", "applied"};
  snprintf(c->element, sizeof c->element, "material_variants");
  TRY(check_keys(c, o, keys, 2));
  TRY(require(c, o, "names"));
  const cJSON *names = item(o, "names");
  if (!cJSON_IsArray(names) || cJSON_GetArraySize(names) < 1)
    return jfail(c, IRIS_ERR_INVALID, "'names' must be a non-empty array of strings");
  size_t n = (size_t)cJSON_GetArraySize(names);
  if (!(v->names = calloc(n, sizeof *v->names))) return jfail(c, IRIS_ERR_NOMEM, "out of memory");
  for (const cJSON *e = names->child; e; e = e->next) {
    if (!cJSON_IsString(e)) return jfail(c, IRIS_ERR_INVALID, "'names' must be a non-empty array of strings");
    if (!(v->names[v->count++] = iris_strdup(e->valuestring))) return jfail(c, IRIS_ERR_NOMEM, "out of memory");
  }
  const char *applied = NULL;
  TRY(get_string(c, o, "applied", &applied));
  v->applied = -1;
  for (size_t i = 0; applied && i < v->count && v->applied < 0; i++)
    if (strcmp(v->names[i], applied) == 0) v->applied = (int32_t)i;
  if (applied && v->applied < 0) return jfail(c, IRIS_ERR_INVALID, "'applied' variant '%s' is not in 'names'", applied);
  return IRIS_OK;
}

static iris_status parse_scene(jctx *c, const cJSON *root, const char *dir, iris_scene *s) {
  static const char *const keys[] = {"format",    "version", "units",  "cameras",     "textures",
                                     "materials", "meshes",  "instances", "lights", "environment",
                                     "render",    "material_variants"};
  c->element[0] = '\0';
  if (!cJSON_IsObject(root)) return jfail(c, IRIS_ERR_INVALID, "the top level must be a JSON object");
  TRY(check_keys(c, root, keys, sizeof keys / sizeof *keys));
  const char *format = NULL;
  TRY(require(c, root, "format"));
  TRY(get_string(c, root, "format", &format));
  if (strcmp(format, SCENE_FORMAT_NAME) != 0)
    return jfail(c, IRIS_ERR_PARSE, "'format' is '%s', expected '%s'", format, SCENE_FORMAT_NAME);
  TRY(require(c, root, "version"));
  double version = 0;
  TRY(get_int(c, root, "version", 1, INT_MAX, &version));
  if (version != IRIS_SCENE_FORMAT_VERSION)
    return jfail(c, IRIS_ERR_UNSUPPORTED, "version %.0f is not supported (this iris reads version %d)",
                 version, IRIS_SCENE_FORMAT_VERSION);
  const char *units = NULL;
  TRY(get_string(c, root, "units", &units));
  if (units) {
    if (!units[0] || strlen(units) >= sizeof s->units)
      return jfail(c, IRIS_ERR_INVALID, "'units' must be 1 to %zu characters", sizeof s->units - 1);
    strcpy(s->units, units);
  }

  const cJSON *cams, *texs, *mats, *meshes, *insts, *lights;
  TRY(get_array(c, root, "cameras", &cams));
  TRY(get_array(c, root, "textures", &texs));
  TRY(get_array(c, root, "materials", &mats));
  TRY(get_array(c, root, "meshes", &meshes));
  TRY(get_array(c, root, "instances", &insts));
  TRY(get_array(c, root, "lights", &lights));
  iris_status st = IRIS_OK;
  size_t n;

  /* Arrays are sized up front and counts raised element by element, so a
   * failure leaves a scene that iris_scene_destroy frees correctly. */
  n = (size_t)cJSON_GetArraySize(cams);
  if (!(s->cameras = alloc_array(c, n, sizeof *s->cameras, &st)) && n) return st;
  for (const cJSON *e = cams ? cams->child : NULL; e; e = e->next) {
    set_element(c, "cameras", s->camera_count);
    TRY(load_camera(c, e, &s->cameras[s->camera_count++]));
  }
  n = (size_t)cJSON_GetArraySize(texs);
  if (!(s->textures = alloc_array(c, n, sizeof *s->textures, &st)) && n) return st;
  for (const cJSON *e = texs ? texs->child : NULL; e; e = e->next) {
    set_element(c, "textures", s->texture_count);
    TRY(load_texture(c, e, dir, &s->textures[s->texture_count++]));
  }
  n = (size_t)cJSON_GetArraySize(mats);
  if (!(s->materials = alloc_array(c, n, sizeof *s->materials, &st)) && n) return st;
  for (const cJSON *e = mats ? mats->child : NULL; e; e = e->next) {
    set_element(c, "materials", s->material_count);
    TRY(load_material(c, e, &s->materials[s->material_count++]));
  }
  n = (size_t)cJSON_GetArraySize(insts);
  if (!(s->instances = alloc_array(c, n, sizeof *s->instances, &st)) && n) return st;
  for (const cJSON *e = insts ? insts->child : NULL; e; e = e->next) {
    set_element(c, "instances", s->instance_count);
    TRY(load_instance(c, e, &s->instances[s->instance_count++]));
  }
  n = (size_t)cJSON_GetArraySize(lights);
  if (!(s->lights = alloc_array(c, n, sizeof *s->lights, &st)) && n) return st;
  for (const cJSON *e = lights ? lights->child : NULL; e; e = e->next) {
    set_element(c, "lights", s->light_count);
    TRY(load_light(c, e, &s->lights[s->light_count++]));
  }
  const cJSON *env = item(root, "environment");
  if (env) {
    static const char *const env_keys[] = {"radiance", "map"};
    snprintf(c->element, sizeof c->element, "environment");
    TRY(check_keys(c, env, env_keys, 2));
    const cJSON *map = item(env, "map");
    if (map && item(env, "radiance"))
      return jfail(c, IRIS_ERR_INVALID, "give either 'radiance' or 'map', not both");
    if (!map) {
      TRY(require(c, env, "radiance"));
      TRY(get_floats(c, env, "radiance", s->environment, 3));
    } else {
      static const char *const map_keys[] = {"path", "strength", "rotation"};
      snprintf(c->element, sizeof c->element, "environment.map");
      TRY(check_keys(c, map, map_keys, 3));
      TRY(require(c, map, "path"));
      const char *file = NULL;
      float strength = 1.0f, rotation = 0.0f;
      TRY(get_string(c, map, "path", &file));
      TRY(get_float(c, map, "strength", &strength));
      TRY(get_float(c, map, "rotation", &rotation));
      if (!file[0]) return jfail(c, IRIS_ERR_INVALID, "'path' is empty");
      char joined[PATH_MAX];
      iris_path_join(dir, file, joined, sizeof joined);
      char *abs = realpath(joined, NULL);
      if (!abs) return jfail(c, IRIS_ERR_IO, "cannot find environment map '%s': %s", joined, strerror(errno));
      bool ok = iris_scene_set_environment_map(s, abs, strength, rotation);
      free(abs);
      if (!ok) return jfail(c, IRIS_ERR_NOMEM, "out of memory");
    }
    s->has_environment = true;
  }
  const cJSON *render = item(root, "render");
  if (render) {
    snprintf(c->element, sizeof c->element, "render");
    TRY(load_render(c, render, &s->render));
  }
  const cJSON *variants = item(root, "material_variants");
  if (variants) TRY(load_variants(c, variants, &s->variants));

  /* Meshes last: their JSON is checked completely before any file is mapped. */
  n = (size_t)cJSON_GetArraySize(meshes);
  mesh_desc *descs = alloc_array(c, n, sizeof *descs, &st);
  if (n && !descs) return st;
  if (n && !(s->meshes = alloc_array(c, n, sizeof *s->meshes, &st))) {
    free(descs);
    return st;
  }
  if (n && !(s->maps = alloc_array(c, n, sizeof(iris_file_map), &st))) {
    free(descs);
    return st;
  }
  size_t i = 0;
  for (const cJSON *e = meshes ? meshes->child : NULL; e && st == IRIS_OK; e = e->next, i++) {
    set_element(c, "meshes", i);
    s->meshes[i].owned = false;
    s->mesh_count = i + 1;
    st = load_mesh_desc(c, e, &s->meshes[i], &descs[i]);
  }
  for (i = 0; i < s->mesh_count && st == IRIS_OK; i++) {
    set_element(c, "meshes", i);
    iris_file_map *maps = s->maps;
    s->map_count = i + 1; /* before mapping, so that destroy unmaps it on failure */
    st = load_mesh_file(c, dir, &descs[i], &s->meshes[i], &maps[i]);
  }
  free(descs);
  return st;
}

iris_status iris_scene_load(const char *json_path, iris_scene **out, iris_error *err) {
  *out = NULL;
  char *text = NULL;
  size_t size = 0;
  iris_status st = iris_file_read(json_path, MAX_JSON_BYTES, &text, &size, err);
  if (st != IRIS_OK) return st;
  if (strlen(text) != size) {
    st = iris_error_set(err, IRIS_ERR_PARSE, json_path, line_of(text, strlen(text)), NULL,
                        "the file contains a NUL byte (not a JSON text file)");
    free(text);
    return st;
  }
  jctx c = {json_path, err, ""};
  const char *end = NULL;
  /* size + 1: cJSON wants to see the terminating NUL to reject trailing garbage. */
  cJSON *root = cJSON_ParseWithLengthOpts(text, size + 1, &end, true);
  if (!root) {
    size_t offset = end && end >= text && end <= text + size ? (size_t)(end - text) : 0;
    char near[24] = "";
    for (size_t k = 0; k + 1 < sizeof near && offset + k < size && text[offset + k] != '\n'; k++)
      near[k] = (char)(text[offset + k] >= 32 && text[offset + k] < 127 ? text[offset + k] : '?');
    st = iris_error_set(err, IRIS_ERR_PARSE, json_path, line_of(text, offset), NULL,
                        near[0] ? "JSON syntax error near '%s'" : "JSON syntax error%s",
                        near[0] ? near : " (unexpected end of file)");
    free(text);
    return st;
  }
  iris_scene *s = iris_scene_create();
  if (!s) {
    cJSON_Delete(root);
    free(text);
    return iris_error_set(err, IRIS_ERR_NOMEM, json_path, 0, NULL, "out of memory");
  }
  char dir[PATH_MAX];
  iris_path_dir(json_path, dir, sizeof dir);
  st = parse_scene(&c, root, dir, s);
  cJSON_Delete(root);
  free(text);
  if (st == IRIS_OK && !(s->source_path = iris_strdup(json_path)))
    st = iris_error_set(err, IRIS_ERR_NOMEM, json_path, 0, NULL, "out of memory");
  if (st == IRIS_OK) st = iris_scene_validate(s, json_path, err);
  if (st != IRIS_OK) {
    iris_scene_destroy(s);
    return st;
  }
  *out = s;
  return IRIS_OK;
}
