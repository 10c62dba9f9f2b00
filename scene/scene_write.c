/* The scene JSON (docs/format.md), writing: the scene model and its mesh
 * files (mesh_file.c) and embedded textures written next to it. Writing is
 * deterministic: the same scene gives the same bytes, so import -> write ->
 * load -> write reproduces every file. Loading: scene_load.c. */
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

/* ====================================================================== */
/* Numbers                                                                 */
/* ====================================================================== */

/* The shortest decimal (as a double) that reads back as exactly `f`. cJSON
 * prints doubles with up to 15 significant digits when that is exact, so the
 * JSON shows "0.8" for 0.8f instead of 0.800000011920929 and still parses
 * back to the same float. */
static double shortest_float(float f) {
  char buf[48];
  for (int p = 1; p <= 9; p++) {
    snprintf(buf, sizeof buf, "%.*g", p, (double)f);
    if (strtof(buf, NULL) == f) return strtod(buf, NULL);
  }
  return (double)f;
}

/* Shortest decimal number of degrees that deg_to_rad maps back to `rad`. */
static double shortest_degrees(float rad) {
  char buf[48];
  double deg = (double)rad * (180.0 / PI_D);
  for (int p = 1; p <= 17; p++) {
    snprintf(buf, sizeof buf, "%.*g", p, deg);
    double d = strtod(buf, NULL);
    if (deg_to_rad(d) == rad) return d;
  }
  return deg;
}

/* ====================================================================== */
/* Writing                                                                 */
/* ====================================================================== */

static cJSON *json_floats(const float *v, int n) {
  cJSON *a = cJSON_CreateArray();
  for (int i = 0; a && i < n; i++) cJSON_AddItemToArray(a, cJSON_CreateNumber(shortest_float(v[i])));
  return a;
}

static void add_float(cJSON *o, const char *key, float v) {
  cJSON_AddNumberToObject(o, key, shortest_float(v));
}
static void add_floats(cJSON *o, const char *key, const float *v, int n) {
  cJSON_AddItemToObject(o, key, json_floats(v, n));
}

/* Splits an absolute, normalised path into '/'-separated components. */
static int split_path(char *path, char **parts, int max) {
  int n = 0;
  char *save = NULL;
  for (char *tok = strtok_r(path, "/", &save); tok && n < max; tok = strtok_r(NULL, "/", &save))
    parts[n++] = tok;
  return n;
}

/* Relative path from absolute folder `from` to absolute file `to`. */
static void relative_path(const char *from, const char *to, char *out, size_t size) {
  char a[PATH_MAX], b[PATH_MAX];
  char *pa[256], *pb[256];
  snprintf(a, sizeof a, "%s", from);
  snprintf(b, sizeof b, "%s", to);
  int na = split_path(a, pa, 256), nb = split_path(b, pb, 256);
  int common = 0;
  while (common < na && common < nb - 1 && strcmp(pa[common], pb[common]) == 0) common++;
  size_t used = 0;
  out[0] = '\0';
  for (int i = common; i < na; i++) used += (size_t)snprintf(out + used, used < size ? size - used : 0, "../");
  for (int i = common; i < nb; i++)
    used += (size_t)snprintf(out + used, used < size ? size - used : 0, "%s%s", pb[i], i + 1 < nb ? "/" : "");
}

/* The camera as position/target/up when iris_mat4_look_at rebuilds exactly
 * the same matrix from them (true for most hand-placed cameras); otherwise
 * the raw matrix, so a written scene always loads back bit for bit. */
static iris_vec3 plus_zero(iris_vec3 v) { return iris_v3(v.x + 0.0f, v.y + 0.0f, v.z + 0.0f); }

/* Rounds each component to 6 significant digits and flushes values that are
 * tiny next to `scale` to 0, so that 5.80000019 becomes 5.8. */
static iris_vec3 snap(iris_vec3 v, float scale) {
  float c[3];
  iris_v3_store(v, c);
  for (int i = 0; i < 3; i++) {
    char buf[32];
    snprintf(buf, sizeof buf, "%.6g", (double)c[i]);
    c[i] = fabsf(c[i]) < 1e-5f * scale ? 0.0f : strtof(buf, NULL);
  }
  return plus_zero(iris_v3_load(c));
}

/* The camera as position/target/up when iris_mat4_look_at rebuilds exactly
 * the same matrix from them; otherwise the raw matrix, so a written scene
 * always loads back bit for bit. Candidate targets are points on the view
 * ray that people pick (where it crosses a coordinate plane, the point
 * nearest the origin, one unit ahead), each also rounded to 6 digits. */
static void add_camera_placement(cJSON *o, const iris_mat4 *m) {
  iris_vec3 eye = plus_zero(iris_v3(m->m[0][3], m->m[1][3], m->m[2][3]));
  iris_vec3 back = iris_v3(m->m[0][2], m->m[1][2], m->m[2][2]);
  float scale = fmaxf(1.0f, iris_max3(iris_v3(fabsf(eye.x), fabsf(eye.y), fabsf(eye.z))));
  float ahead[5];
  int n = 0;
  float e[3], b[3];
  iris_v3_store(eye, e);
  iris_v3_store(back, b);
  for (int axis = 0; axis < 3; axis++)
    if (fabsf(b[axis]) > 1e-6f && e[axis] / b[axis] > 0.0f) ahead[n++] = e[axis] / b[axis];
  float bb = iris_dot(back, back);
  if (bb > 0.0f && iris_dot(eye, back) / bb > 0.0f) ahead[n++] = iris_dot(eye, back) / bb;
  ahead[n++] = 1.0f;
  iris_vec3 ups[3] = {iris_v3(0, 1, 0), iris_v3(0, 0, 1),
                      plus_zero(iris_v3(m->m[0][1], m->m[1][1], m->m[2][1]))};
  for (int k = 0; k < 2 * n; k++) {
    iris_vec3 target = plus_zero(iris_madd(eye, back, -ahead[k / 2]));
    if (k % 2 == 0) target = snap(target, scale);
    if (target.x == eye.x && target.y == eye.y && target.z == eye.z) continue;
    for (int u = 0; u < 3; u++) {
      iris_mat4 r = iris_mat4_look_at(eye, target, ups[u]);
      if (!floats_equal(&r.m[0][0], &m->m[0][0], 16)) continue;
      float t[3], up[3];
      iris_v3_store(target, t);
      iris_v3_store(ups[u], up);
      add_floats(o, "position", e, 3);
      add_floats(o, "target", t, 3);
      add_floats(o, "up", up, 3);
      return;
    }
  }
  add_floats(o, "to_world", &m->m[0][0], 16);
}

static cJSON *write_material(const iris_material *m) {
  const iris_material d = iris_material_default(m->type);
  bool rough = m->type != IRIS_MATERIAL_DIFFUSE;
  bool ior = m->type == IRIS_MATERIAL_GLASS || m->type == IRIS_MATERIAL_GLTF;
  bool gltf = m->type == IRIS_MATERIAL_GLTF;
  cJSON *o = cJSON_CreateObject();
  if (m->name) cJSON_AddStringToObject(o, "name", m->name);
  cJSON_AddStringToObject(o, "type", MATERIAL_TYPES[m->type]);
  if (!floats_equal(m->color, d.color, 3)) add_floats(o, "color", m->color, 3);
  if (m->color_texture >= 0) cJSON_AddNumberToObject(o, "color_texture", m->color_texture);
  if (rough && m->roughness != d.roughness) add_float(o, "roughness", m->roughness);
  if (ior && m->ior != d.ior) add_float(o, "ior", m->ior);
  if (gltf) {
    if (m->metallic != d.metallic) add_float(o, "metallic", m->metallic);
    if (m->metallic_roughness_texture >= 0)
      cJSON_AddNumberToObject(o, "metallic_roughness_texture", m->metallic_roughness_texture);
    if (m->specular != d.specular) add_float(o, "specular", m->specular);
    if (!floats_equal(m->specular_color, d.specular_color, 3))
      add_floats(o, "specular_color", m->specular_color, 3);
    if (m->transmission != d.transmission) add_float(o, "transmission", m->transmission);
    if (m->transmission_texture >= 0) cJSON_AddNumberToObject(o, "transmission_texture", m->transmission_texture);
    if (m->specular_texture >= 0) cJSON_AddNumberToObject(o, "specular_texture", m->specular_texture);
    if (m->specular_color_texture >= 0)
      cJSON_AddNumberToObject(o, "specular_color_texture", m->specular_color_texture);
    if (m->clearcoat != d.clearcoat) add_float(o, "clearcoat", m->clearcoat);
    if (m->clearcoat_roughness != d.clearcoat_roughness) add_float(o, "clearcoat_roughness", m->clearcoat_roughness);
    if (m->clearcoat_texture >= 0) cJSON_AddNumberToObject(o, "clearcoat_texture", m->clearcoat_texture);
    if (m->clearcoat_roughness_texture >= 0)
      cJSON_AddNumberToObject(o, "clearcoat_roughness_texture", m->clearcoat_roughness_texture);
    if (m->clearcoat_normal_texture >= 0)
      cJSON_AddNumberToObject(o, "clearcoat_normal_texture", m->clearcoat_normal_texture);
    if (m->clearcoat_normal_scale != d.clearcoat_normal_scale)
      add_float(o, "clearcoat_normal_scale", m->clearcoat_normal_scale);
    if (!floats_equal(m->sheen_color, d.sheen_color, 3)) add_floats(o, "sheen_color", m->sheen_color, 3);
    if (m->sheen_roughness != d.sheen_roughness) add_float(o, "sheen_roughness", m->sheen_roughness);
    if (m->sheen_color_texture >= 0) cJSON_AddNumberToObject(o, "sheen_color_texture", m->sheen_color_texture);
    if (m->sheen_roughness_texture >= 0)
      cJSON_AddNumberToObject(o, "sheen_roughness_texture", m->sheen_roughness_texture);
    if (!floats_equal(m->attenuation_color, d.attenuation_color, 3))
      add_floats(o, "attenuation_color", m->attenuation_color, 3);
    if (m->attenuation_distance != d.attenuation_distance)
      add_float(o, "attenuation_distance", m->attenuation_distance);
    if (m->anisotropy != d.anisotropy) add_float(o, "anisotropy", m->anisotropy);
    if (m->anisotropy_rotation != d.anisotropy_rotation)
      add_float(o, "anisotropy_rotation", m->anisotropy_rotation);
    if (m->anisotropy_texture >= 0) cJSON_AddNumberToObject(o, "anisotropy_texture", m->anisotropy_texture);
  }
  if (!floats_equal(m->emission, d.emission, 3)) add_floats(o, "emission", m->emission, 3);
  if (m->emission_texture >= 0) cJSON_AddNumberToObject(o, "emission_texture", m->emission_texture);
  if (m->emission_two_sided != d.emission_two_sided)
    cJSON_AddBoolToObject(o, "emission_two_sided", m->emission_two_sided);
  if (m->unlit) cJSON_AddBoolToObject(o, "unlit", true);
  if (m->double_sided != d.double_sided) cJSON_AddBoolToObject(o, "double_sided", m->double_sided);
  if (m->normal_texture >= 0) cJSON_AddNumberToObject(o, "normal_texture", m->normal_texture);
  if (m->normal_scale != d.normal_scale) add_float(o, "normal_scale", m->normal_scale);
  if (m->alpha_mode != IRIS_ALPHA_OPAQUE) cJSON_AddStringToObject(o, "alpha_mode", ALPHA_MODES[m->alpha_mode]);
  if (m->alpha != d.alpha) add_float(o, "alpha", m->alpha);
  if (m->alpha_cutoff != d.alpha_cutoff) add_float(o, "alpha_cutoff", m->alpha_cutoff);
  return o;
}

static cJSON *write_light(const iris_light *l) {
  cJSON *o = cJSON_CreateObject();
  if (l->name) cJSON_AddStringToObject(o, "name", l->name);
  cJSON_AddStringToObject(o, "type", LIGHT_TYPES[l->type]);
  static const float white[3] = {1, 1, 1};
  if (!floats_equal(l->color, white, 3)) add_floats(o, "color", l->color, 3);
  add_float(o, "intensity", l->intensity);
  if (l->type != IRIS_LIGHT_DIRECTIONAL) add_floats(o, "position", l->position, 3);
  if (l->type != IRIS_LIGHT_POINT) add_floats(o, "direction", l->direction, 3);
  if (l->range != 0.0f) add_float(o, "range", l->range);
  if (l->type == IRIS_LIGHT_SPOT) {
    cJSON_AddNumberToObject(o, "inner_cone_deg", shortest_degrees(l->inner_cone));
    cJSON_AddNumberToObject(o, "outer_cone_deg", shortest_degrees(l->outer_cone));
  }
  return o;
}

static bool is_identity(const iris_mat4 *m) {
  iris_mat4 id = iris_mat4_identity();
  return floats_equal(&m->m[0][0], &id.m[0][0], 16);
}

static cJSON *write_render(const iris_render_settings *r) {
  cJSON *o = cJSON_CreateObject();
  if (r->width) cJSON_AddNumberToObject(o, "width", r->width);
  if (r->height) cJSON_AddNumberToObject(o, "height", r->height);
  if (r->spp) cJSON_AddNumberToObject(o, "spp", r->spp);
  if (r->max_depth >= 0) cJSON_AddNumberToObject(o, "max_depth", r->max_depth);
  if (r->method[0]) cJSON_AddStringToObject(o, "method", r->method);
  if (r->has_seed) {
    /* JSON numbers are doubles: seeds beyond 2^53 are written as strings. */
    if (r->seed <= (UINT64_C(1) << 53)) {
      cJSON_AddNumberToObject(o, "seed", (double)r->seed);
    } else {
      char buf[32];
      snprintf(buf, sizeof buf, "%llu", (unsigned long long)r->seed);
      cJSON_AddStringToObject(o, "seed", buf);
    }
  }
  if (!o->child) {
    cJSON_Delete(o);
    return NULL;
  }
  return o;
}

/* Writes the in-memory texture `t` as "<stem>.textures/<i>.<ext>" and stores
 * that name in `file`; path-based textures get their path relative to dir. */
static iris_status write_texture_file(const iris_texture *t, size_t i, const char *dir,
                                      const char *dir_abs, const char *stem, const char *scene_name,
                                      char *file, size_t file_size, iris_error *err) {
  char path[PATH_MAX], sub[PATH_MAX];
  if (t->data) {
    const char *ext = strcmp(t->mime, "image/jpeg") == 0 ? "jpg" : "png";
    snprintf(file, file_size, "%s.textures/%zu.%s", stem, i, ext);
    snprintf(sub, sizeof sub, "%s.textures", stem);
    iris_path_join(dir, sub, path, sizeof path);
    iris_status st = iris_mkdir_p(path, err);
    if (st != IRIS_OK) return st;
    iris_path_join(dir, file, path, sizeof path);
    return iris_file_write_atomic(path, t->data, t->data_size, err);
  }
  char *abs = realpath(t->path, NULL);
  if (!abs) {
    char element[48];
    snprintf(element, sizeof element, "textures[%zu]", i);
    return iris_error_set(err, IRIS_ERR_IO, scene_name, 0, element, "cannot find texture file '%s': %s",
                          t->path, strerror(errno));
  }
  relative_path(dir_abs, abs, file, file_size);
  free(abs);
  return IRIS_OK;
}

iris_status iris_scene_write(const iris_scene *scene, const char *json_path, iris_error *err) {
  const char *scene_name = scene->source_path ? scene->source_path : "scene";
  iris_status st = iris_scene_validate(scene, scene_name, err);
  if (st != IRIS_OK) return st;

  char dir[PATH_MAX], stem[256], sub[PATH_MAX], path[PATH_MAX], file[PATH_MAX];
  iris_path_dir(json_path, dir, sizeof dir);
  iris_path_stem(json_path, stem, sizeof stem);
  if ((st = iris_mkdir_p(dir, err)) != IRIS_OK) return st;
  char *dir_abs = realpath(dir, NULL);
  if (!dir_abs) return iris_error_set(err, IRIS_ERR_IO, dir, 0, NULL, "cannot resolve folder: %s", strerror(errno));

  cJSON *root = cJSON_CreateObject();
  cJSON_AddStringToObject(root, "format", SCENE_FORMAT_NAME);
  cJSON_AddNumberToObject(root, "version", IRIS_SCENE_FORMAT_VERSION);
  cJSON_AddStringToObject(root, "units", scene->units);

  if (scene->camera_count) {
    cJSON *a = cJSON_AddArrayToObject(root, "cameras");
    for (size_t i = 0; i < scene->camera_count; i++) {
      const iris_camera *c = &scene->cameras[i];
      cJSON *o = cJSON_CreateObject();
      if (c->name) cJSON_AddStringToObject(o, "name", c->name);
      add_camera_placement(o, &c->to_world);
      cJSON_AddNumberToObject(o, "yfov_deg", shortest_degrees(c->yfov));
      if (c->aspect != 0.0f) add_float(o, "aspect", c->aspect);
      cJSON_AddItemToArray(a, o);
    }
  }
  if (scene->texture_count) {
    cJSON *a = cJSON_AddArrayToObject(root, "textures");
    for (size_t i = 0; i < scene->texture_count && st == IRIS_OK; i++) {
      const iris_texture *t = &scene->textures[i];
      file[0] = '\0';
      st = write_texture_file(t, i, dir, dir_abs, stem, scene_name, file, sizeof file, err);
      cJSON *o = cJSON_CreateObject();
      if (t->name) cJSON_AddStringToObject(o, "name", t->name);
      cJSON_AddStringToObject(o, "file", file);
      if (t->wrap_s != IRIS_WRAP_REPEAT) cJSON_AddStringToObject(o, "wrap_s", WRAP_MODES[t->wrap_s]);
      if (t->wrap_t != IRIS_WRAP_REPEAT) cJSON_AddStringToObject(o, "wrap_t", WRAP_MODES[t->wrap_t]);
      if (t->nearest) cJSON_AddStringToObject(o, "filter", "nearest");
      if (t->uv_set) cJSON_AddNumberToObject(o, "uv_set", t->uv_set);
      if (t->has_transform) {
        cJSON *x = cJSON_AddObjectToObject(o, "transform");
        add_floats(x, "offset", t->offset, 2);
        add_float(x, "rotation", t->rotation);
        add_floats(x, "scale", t->scale, 2);
      }
      cJSON_AddItemToArray(a, o);
    }
  }
  if (scene->material_count) {
    cJSON *a = cJSON_AddArrayToObject(root, "materials");
    for (size_t i = 0; i < scene->material_count; i++)
      cJSON_AddItemToArray(a, write_material(&scene->materials[i]));
  }
  if (scene->mesh_count && st == IRIS_OK) {
    snprintf(sub, sizeof sub, "%s.meshes", stem);
    iris_path_join(dir, sub, path, sizeof path);
    st = iris_mkdir_p(path, err);
  }
  cJSON *meshes = cJSON_AddArrayToObject(root, "meshes");
  for (size_t i = 0; i < scene->mesh_count && st == IRIS_OK; i++) {
    const iris_mesh *m = &scene->meshes[i];
    snprintf(file, sizeof file, "%s.meshes/%zu.irmesh", stem, i);
    iris_path_join(dir, file, path, sizeof path);
    st = iris_mesh_write_file(m, path, err);
    cJSON *o = cJSON_CreateObject();
    if (m->name) cJSON_AddStringToObject(o, "name", m->name);
    cJSON_AddStringToObject(o, "file", file);
    if (m->material >= 0) cJSON_AddNumberToObject(o, "material", m->material);
    cJSON_AddNumberToObject(o, "vertices", m->vertex_count);
    cJSON_AddNumberToObject(o, "triangles", m->triangle_count);
    cJSON *attrs = cJSON_AddArrayToObject(o, "attributes");
    const void *present[ATTRIBUTE_COUNT] = {m->normals, m->uvs, m->colors, m->uvs1, m->tangents, m->alphas};
    for (int k = 0; k < ATTRIBUTE_COUNT; k++)
      if (present[k]) cJSON_AddItemToArray(attrs, cJSON_CreateString(ATTRIBUTE_NAMES[k]));
    cJSON_AddItemToArray(meshes, o);
  }
  cJSON *instances = cJSON_AddArrayToObject(root, "instances");
  for (size_t i = 0; i < scene->instance_count; i++) {
    const iris_instance *inst = &scene->instances[i];
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "mesh", inst->mesh);
    if (!is_identity(&inst->transform)) add_floats(o, "transform", &inst->transform.m[0][0], 16);
    cJSON_AddItemToArray(instances, o);
  }
  if (scene->light_count) {
    cJSON *a = cJSON_AddArrayToObject(root, "lights");
    for (size_t i = 0; i < scene->light_count; i++) cJSON_AddItemToArray(a, write_light(&scene->lights[i]));
  }
  if (scene->has_environment && st == IRIS_OK) {
    cJSON *o = cJSON_AddObjectToObject(root, "environment");
    const iris_environment_map *em = &scene->environment_map;
    if (em->path) {
      char *abs = realpath(em->path, NULL);
      if (!abs) {
        st = iris_error_set(err, IRIS_ERR_IO, scene_name, 0, "environment.map",
                            "cannot find environment map '%s': %s", em->path, strerror(errno));
      } else {
        relative_path(dir_abs, abs, file, sizeof file);
        free(abs);
        cJSON *m = cJSON_AddObjectToObject(o, "map");
        cJSON_AddStringToObject(m, "path", file);
        cJSON_AddNumberToObject(m, "strength", em->strength);
        cJSON_AddNumberToObject(m, "rotation", em->rotation);
      }
    } else {
      add_floats(o, "radiance", scene->environment, 3);
    }
  }
  cJSON *render = write_render(&scene->render);
  if (render) cJSON_AddItemToObject(root, "render", render);
  if (scene->variants.count) {
    cJSON *o = cJSON_AddObjectToObject(root, "material_variants");
    cJSON *names = cJSON_AddArrayToObject(o, "names");
    for (size_t i = 0; i < scene->variants.count; i++)
      cJSON_AddItemToArray(names, cJSON_CreateString(scene->variants.names[i]));
    if (scene->variants.applied >= 0)
      cJSON_AddStringToObject(o, "applied", scene->variants.names[scene->variants.applied]);
  }
  free(dir_abs);

  if (st == IRIS_OK) {
    char *text = cJSON_Print(root);
    if (!text) {
      st = iris_error_set(err, IRIS_ERR_NOMEM, json_path, 0, NULL, "out of memory printing JSON");
    } else {
      size_t n = strlen(text);
      text[n] = '\n'; /* replace the NUL: files end with a newline */
      st = iris_file_write_atomic(json_path, text, n + 1, err);
      free(text);
    }
  }
  /* Mesh files of an earlier, larger scene written under the same name are
   * removed once the new JSON is in place (never before: a failed write keeps
   * the old scene whole). */
  for (size_t i = scene->mesh_count; st == IRIS_OK; i++) {
    snprintf(file, sizeof file, "%s.meshes/%zu.irmesh", stem, i);
    iris_path_join(dir, file, path, sizeof path);
    if (unlink(path) != 0) break;
  }
  cJSON_Delete(root);
  return st;
}
