/* The in-memory scene: lifetime, appenders, merging, validation and the
 * derived quantities (bounds, triangle counts). The file format is written
 * by scene_write.c and loaded by scene_load.c; docs/format.md describes both. */
#include "scene/scene.h"

#include <malloc.h>

#include "core/log.h"
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"

/* ---- lifetime ---------------------------------------------------------- */

iris_scene *iris_scene_create(void) {
  iris_scene *scene = calloc(1, sizeof *scene);
  if (!scene) return NULL;
  memcpy(scene->units, "m", 2);
  scene->render.max_depth = -1;
  scene->variants.applied = -1;
  return scene;
}

static void free_mesh(iris_mesh *m) {
  free(m->name);
  if (m->owned) {
    free(m->positions);
    free(m->normals);
    free(m->uvs);
    free(m->colors);
    free(m->uvs1);
    free(m->tangents);
    free(m->alphas);
    free(m->indices);
  }
}

void iris_scene_destroy(iris_scene *scene) {
  if (!scene) return;
  for (size_t i = 0; i < scene->texture_count; i++) {
    free(scene->textures[i].name);
    free(scene->textures[i].path);
    free(scene->textures[i].data);
  }
  for (size_t i = 0; i < scene->material_count; i++) free(scene->materials[i].name);
  for (size_t i = 0; i < scene->mesh_count; i++) free_mesh(&scene->meshes[i]);
  for (size_t i = 0; i < scene->camera_count; i++) free(scene->cameras[i].name);
  for (size_t i = 0; i < scene->light_count; i++) free(scene->lights[i].name);
  free(scene->environment_map.path);
  for (size_t i = 0; i < scene->variants.count; i++) free(scene->variants.names[i]);
  free(scene->variants.names);
  iris_file_map *maps = scene->maps;
  for (size_t i = 0; i < scene->map_count; i++) iris_file_map_close(&maps[i]);
  free(scene->maps);
  free(scene->textures);
  free(scene->materials);
  free(scene->meshes);
  free(scene->instances);
  free(scene->cameras);
  free(scene->lights);
  free(scene->source_path);
  free(scene);
}

bool iris_scene_set_environment_map(iris_scene *scene, const char *path, float strength,
                                    float rotation) {
  char *copy = iris_strdup(path);
  if (!copy) return false;
  free(scene->environment_map.path);
  scene->environment_map.path = copy;
  scene->environment_map.strength = strength;
  scene->environment_map.rotation = rotation;
  scene->has_environment = true;
  scene->environment[0] = scene->environment[1] = scene->environment[2] = 0.0f;
  return true;
}

void iris_scene_set_environment_color(iris_scene *scene, const float rgb[3]) {
  free(scene->environment_map.path);
  scene->environment_map.path = NULL;
  scene->has_environment = true;
  memcpy(scene->environment, rgb, sizeof scene->environment);
}

bool iris_scene_has_emitter(const iris_scene *scene) {
  for (size_t i = 0; i < scene->light_count; i++) {
    const iris_light *l = &scene->lights[i];
    if (l->intensity > 0.0f && (l->color[0] > 0.0f || l->color[1] > 0.0f || l->color[2] > 0.0f))
      return true;
  }
  if (scene->has_environment) {
    if (scene->environment_map.path && scene->environment_map.strength > 0.0f) return true;
    if (!scene->environment_map.path &&
        (scene->environment[0] > 0.0f || scene->environment[1] > 0.0f || scene->environment[2] > 0.0f))
      return true;
  }
  /* an emissive material counts only when a mesh uses it */
  for (size_t i = 0; i < scene->mesh_count; i++) {
    int32_t m = scene->meshes[i].material;
    if (m < 0 || (size_t)m >= scene->material_count || scene->meshes[i].triangle_count == 0) continue;
    const float *e = scene->materials[m].emission;
    if (e[0] > 0.0f || e[1] > 0.0f || e[2] > 0.0f) {
      for (size_t k = 0; k < scene->instance_count; k++)
        if (scene->instances[k].mesh == i) return true;
    }
  }
  return false;
}

void iris_scene_warn_if_lightless(const iris_scene *scene, const char *what) {
  if (iris_scene_has_emitter(scene)) return;
  iris_warnf("%s: the scene has no light (no emitter, no light, black environment): "
             "the image will be black; pass --env FILE or --env-color R,G,B",
             what ? what : "scene");
}

char *iris_strdup(const char *s) {
  if (!s) return NULL;
  size_t n = strlen(s) + 1;
  char *d = malloc(n);
  if (d) memcpy(d, s, n);
  return d;
}

/* Grows *array by one element of `size` bytes and copies `elem` into it.
 * Arrays have no capacity field: the block's own size (malloc_usable_size)
 * is the capacity, and a full block grows to twice the count. A realloc per
 * append remapped large blocks each time, which made 131,000 glTF instances
 * cost 7x what 33,000 did. */
static int32_t append(void **array, size_t *count, size_t size, const void *elem) {
  if (*count >= (size_t)INT32_MAX) return -1;
  if (!*array || (*count + 1) * size > malloc_usable_size(*array)) {
    const size_t n = *count < 8 ? 8 : 2 * *count;
    void *grown = realloc(*array, n * size);
    if (!grown) return -1;
    *array = grown;
  }
  memcpy((char *)*array + *count * size, elem, size);
  return (int32_t)(*count)++;
}

int32_t iris_scene_add_texture(iris_scene *scene, const iris_texture *tex) {
  return append((void **)&scene->textures, &scene->texture_count, sizeof *tex, tex);
}
int32_t iris_scene_add_material(iris_scene *scene, const iris_material *mat) {
  return append((void **)&scene->materials, &scene->material_count, sizeof *mat, mat);
}
int32_t iris_scene_add_mesh(iris_scene *scene, const iris_mesh *mesh) {
  return append((void **)&scene->meshes, &scene->mesh_count, sizeof *mesh, mesh);
}
int32_t iris_scene_add_instance(iris_scene *scene, const iris_instance *inst) {
  return append((void **)&scene->instances, &scene->instance_count, sizeof *inst, inst);
}
int32_t iris_scene_add_camera(iris_scene *scene, const iris_camera *cam) {
  return append((void **)&scene->cameras, &scene->camera_count, sizeof *cam, cam);
}
int32_t iris_scene_add_light(iris_scene *scene, const iris_light *light) {
  return append((void **)&scene->lights, &scene->light_count, sizeof *light, light);
}

iris_material iris_material_default(iris_material_type type) {
  iris_material m;
  memset(&m, 0, sizeof m);
  m.type = type;
  m.color[0] = m.color[1] = m.color[2] = 0.8f;
  m.color_texture = -1;
  m.roughness = 0.5f;
  m.ior = 1.5f;
  m.metallic = 0.0f;
  m.metallic_roughness_texture = -1;
  m.specular = 1.0f;
  m.specular_color[0] = m.specular_color[1] = m.specular_color[2] = 1.0f;
  m.transmission = 0.0f;
  m.transmission_texture = m.specular_texture = m.specular_color_texture = -1;
  m.emission_texture = -1;
  m.emission_two_sided = true;
  m.double_sided = false;
  m.normal_texture = -1;
  m.normal_scale = 1.0f;
  m.alpha_mode = IRIS_ALPHA_OPAQUE;
  m.alpha = 1.0f;
  m.alpha_cutoff = 0.5f;
  m.clearcoat_texture = m.clearcoat_roughness_texture = m.clearcoat_normal_texture = -1;
  m.clearcoat_normal_scale = 1.0f;
  m.sheen_color_texture = m.sheen_roughness_texture = -1;
  m.anisotropy = m.anisotropy_rotation = 0.0f;
  m.anisotropy_texture = -1;
  m.attenuation_color[0] = m.attenuation_color[1] = m.attenuation_color[2] = 1.0f;
  m.attenuation_distance = 0.0f;
  return m;
}

/* ---- merging ----------------------------------------------------------- */

/* Appends n elements of `size` bytes from src to *dst (all or nothing). */
static bool extend(void **dst, size_t *dst_count, const void *src, size_t n, size_t size) {
  if (n == 0) return true;
  if (*dst_count > (size_t)INT32_MAX - n) return false;
  void *grown = realloc(*dst, (*dst_count + n) * size);
  if (!grown) return false;
  *dst = grown;
  memcpy((char *)grown + *dst_count * size, src, n * size);
  *dst_count += n;
  return true;
}

static int32_t shift_ref(int32_t ref, size_t offset) {
  return ref < 0 ? ref : (int32_t)((size_t)ref + offset);
}

iris_status iris_scene_merge(iris_scene *dst, iris_scene *src, iris_error *err) {
  if (!src) return IRIS_OK;
  if (strcmp(dst->units, src->units) != 0) {
    iris_status st = iris_error_set(err, IRIS_ERR_INVALID, src->source_path, 0, NULL,
                                    "cannot merge a scene in units '%s' into one in '%s'",
                                    src->units, dst->units);
    iris_scene_destroy(src);
    return st;
  }
  size_t tex0 = dst->texture_count, mat0 = dst->material_count, mesh0 = dst->mesh_count;
  for (size_t i = 0; i < src->material_count; i++) {
    iris_material *m = &src->materials[i];
    m->color_texture = shift_ref(m->color_texture, tex0);
    m->metallic_roughness_texture = shift_ref(m->metallic_roughness_texture, tex0);
    m->emission_texture = shift_ref(m->emission_texture, tex0);
    m->normal_texture = shift_ref(m->normal_texture, tex0);
    m->clearcoat_texture = shift_ref(m->clearcoat_texture, tex0);
    m->clearcoat_roughness_texture = shift_ref(m->clearcoat_roughness_texture, tex0);
    m->clearcoat_normal_texture = shift_ref(m->clearcoat_normal_texture, tex0);
    m->sheen_color_texture = shift_ref(m->sheen_color_texture, tex0);
    m->sheen_roughness_texture = shift_ref(m->sheen_roughness_texture, tex0);
    m->transmission_texture = shift_ref(m->transmission_texture, tex0);
    m->specular_texture = shift_ref(m->specular_texture, tex0);
    m->specular_color_texture = shift_ref(m->specular_color_texture, tex0);
    m->anisotropy_texture = shift_ref(m->anisotropy_texture, tex0);
  }
  for (size_t i = 0; i < src->mesh_count; i++)
    src->meshes[i].material = shift_ref(src->meshes[i].material, mat0);
  for (size_t i = 0; i < src->instance_count; i++) src->instances[i].mesh += (uint32_t)mesh0;

  /* Reserve everything first so that a failed allocation leaves dst intact
   * (its counts unchanged) and src still owning its contents. */
  size_t saved[7] = {dst->texture_count, dst->material_count, dst->mesh_count,
                     dst->instance_count, dst->camera_count, dst->light_count, dst->map_count};
  bool ok = extend((void **)&dst->textures, &dst->texture_count, src->textures,
                   src->texture_count, sizeof *src->textures) &&
            extend((void **)&dst->materials, &dst->material_count, src->materials,
                   src->material_count, sizeof *src->materials) &&
            extend((void **)&dst->meshes, &dst->mesh_count, src->meshes, src->mesh_count,
                   sizeof *src->meshes) &&
            extend((void **)&dst->instances, &dst->instance_count, src->instances,
                   src->instance_count, sizeof *src->instances) &&
            extend((void **)&dst->cameras, &dst->camera_count, src->cameras, src->camera_count,
                   sizeof *src->cameras) &&
            extend((void **)&dst->lights, &dst->light_count, src->lights, src->light_count,
                   sizeof *src->lights) &&
            extend(&dst->maps, &dst->map_count, src->maps, src->map_count, sizeof(iris_file_map));
  if (!ok) {
    dst->texture_count = saved[0];
    dst->material_count = saved[1];
    dst->mesh_count = saved[2];
    dst->instance_count = saved[3];
    dst->camera_count = saved[4];
    dst->light_count = saved[5];
    dst->map_count = saved[6];
    iris_scene_destroy(src);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory merging scenes");
  }
  if (!dst->has_environment && src->has_environment) {
    dst->has_environment = true;
    memcpy(dst->environment, src->environment, sizeof dst->environment);
    dst->environment_map = src->environment_map; /* taken over */
    src->environment_map.path = NULL;
  }
  /* The first input's material variants are the record (docs/format.md). */
  if (!dst->variants.count && src->variants.count) {
    dst->variants = src->variants; /* taken over */
    src->variants.names = NULL;
    src->variants.count = 0;
  }
  /* dst's render settings win; src fills only what dst leaves at its default. */
  iris_render_settings *r = &dst->render;
  const iris_render_settings *s = &src->render;
  if (!r->width && !r->height) {
    r->width = s->width;
    r->height = s->height;
  }
  if (!r->spp) r->spp = s->spp;
  if (r->max_depth < 0) r->max_depth = s->max_depth;
  if (!r->method[0]) memcpy(r->method, s->method, sizeof r->method);
  if (!r->has_seed && s->has_seed) {
    r->seed = s->seed;
    r->has_seed = true;
  }
  /* dst now owns every pointer; release only src's arrays. */
  src->texture_count = src->material_count = src->mesh_count = 0;
  src->camera_count = src->light_count = src->map_count = 0;
  iris_scene_destroy(src);
  return IRIS_OK;
}

/* ---- validation -------------------------------------------------------- */

static bool finite_n(const float *v, size_t n) {
  for (size_t i = 0; i < n; i++)
    if (!isfinite(v[i])) return false;
  return true;
}

static bool nonneg_finite_n(const float *v, size_t n) {
  for (size_t i = 0; i < n; i++)
    if (!isfinite(v[i]) || v[i] < 0.0f) return false;
  return true;
}

/* First index i in [0, n) with !isfinite(v[i]), or n. */
static size_t first_nonfinite(const float *v, size_t n) {
  for (size_t i = 0; i < n; i++)
    if (!isfinite(v[i])) return i;
  return n;
}

static bool mat4_finite(const iris_mat4 *m) { return finite_n(&m->m[0][0], 16); }

#define FAIL(...) return iris_error_set(err, IRIS_ERR_INVALID, file, 0, element, __VA_ARGS__)

static iris_status check_texture_ref(int32_t ref, size_t count, const char *what,
                                     const char *file, const char *element, iris_error *err) {
  if (ref < -1 || (ref >= 0 && (size_t)ref >= count))
    FAIL("%s %d out of range (texture count %zu)", what, (int)ref, count);
  return IRIS_OK;
}

static iris_status validate_material(const iris_scene *s, const iris_material *m,
                                     const char *file, const char *element, iris_error *err) {
  if ((unsigned)m->type > IRIS_MATERIAL_GLTF) FAIL("unknown material type %d", (int)m->type);
  if (!nonneg_finite_n(m->color, 3)) FAIL("color must be finite and non-negative");
  if (!isfinite(m->roughness) || m->roughness < 0.0f || m->roughness > 1.0f)
    FAIL("roughness %g outside [0, 1]", (double)m->roughness);
  if (!isfinite(m->ior) || m->ior <= 0.0f) FAIL("ior %g must be finite and positive", (double)m->ior);
  if (!isfinite(m->metallic) || m->metallic < 0.0f || m->metallic > 1.0f)
    FAIL("metallic %g outside [0, 1]", (double)m->metallic);
  if (!isfinite(m->specular) || m->specular < 0.0f)
    FAIL("specular %g must be finite and non-negative", (double)m->specular);
  if (!nonneg_finite_n(m->specular_color, 3)) FAIL("specular_color must be finite and non-negative");
  if (!isfinite(m->transmission) || m->transmission < 0.0f || m->transmission > 1.0f)
    FAIL("transmission %g outside [0, 1]", (double)m->transmission);
  if (!nonneg_finite_n(m->emission, 3)) FAIL("emission must be finite and non-negative");
  iris_status st;
  if ((st = check_texture_ref(m->color_texture, s->texture_count, "color_texture", file, element, err)))
    return st;
  if ((st = check_texture_ref(m->metallic_roughness_texture, s->texture_count,
                              "metallic_roughness_texture", file, element, err)))
    return st;
  if (!isfinite(m->normal_scale)) FAIL("normal_scale %g is not finite", (double)m->normal_scale);
  if ((unsigned)m->alpha_mode > IRIS_ALPHA_BLEND) FAIL("unknown alpha mode %d", (int)m->alpha_mode);
  if (!isfinite(m->alpha) || m->alpha < 0.0f || m->alpha > 1.0f) FAIL("alpha %g outside [0, 1]", (double)m->alpha);
  if (!isfinite(m->alpha_cutoff) || m->alpha_cutoff < 0.0f)
    FAIL("alpha_cutoff %g must be finite and non-negative", (double)m->alpha_cutoff);
  if ((st = check_texture_ref(m->normal_texture, s->texture_count, "normal_texture", file, element, err)))
    return st;
  if (!isfinite(m->clearcoat) || m->clearcoat < 0.0f || m->clearcoat > 1.0f)
    FAIL("clearcoat %g outside [0, 1]", (double)m->clearcoat);
  if (!isfinite(m->clearcoat_roughness) || m->clearcoat_roughness < 0.0f || m->clearcoat_roughness > 1.0f)
    FAIL("clearcoat_roughness %g outside [0, 1]", (double)m->clearcoat_roughness);
  if (!isfinite(m->clearcoat_normal_scale)) FAIL("clearcoat_normal_scale is not finite");
  if (!nonneg_finite_n(m->sheen_color, 3) || m->sheen_color[0] > 1.0f || m->sheen_color[1] > 1.0f ||
      m->sheen_color[2] > 1.0f)
    FAIL("sheen_color must be in [0, 1]");
  if (!nonneg_finite_n(m->attenuation_color, 3) || m->attenuation_color[0] > 1.0f ||
      m->attenuation_color[1] > 1.0f || m->attenuation_color[2] > 1.0f)
    FAIL("attenuation_color must be in [0, 1]");
  if (!isfinite(m->attenuation_distance) || m->attenuation_distance < 0.0f)
    FAIL("attenuation_distance %g must be finite and >= 0 (0: none)", (double)m->attenuation_distance);
  if (!isfinite(m->sheen_roughness) || m->sheen_roughness < 0.0f || m->sheen_roughness > 1.0f)
    FAIL("sheen_roughness %g outside [0, 1]", (double)m->sheen_roughness);
  if (!isfinite(m->anisotropy) || m->anisotropy < 0.0f || m->anisotropy > 1.0f)
    FAIL("anisotropy %g outside [0, 1]", (double)m->anisotropy);
  if (!isfinite(m->anisotropy_rotation)) FAIL("anisotropy_rotation is not finite");
  {
    const int32_t refs[9] = {m->clearcoat_texture, m->clearcoat_roughness_texture, m->clearcoat_normal_texture,
                             m->sheen_color_texture, m->sheen_roughness_texture, m->transmission_texture,
                             m->specular_texture, m->specular_color_texture, m->anisotropy_texture};
    const char *names[9] = {"clearcoat_texture", "clearcoat_roughness_texture", "clearcoat_normal_texture",
                            "sheen_color_texture", "sheen_roughness_texture", "transmission_texture",
                            "specular_texture", "specular_color_texture", "anisotropy_texture"};
    for (int k = 0; k < 9; k++)
      if ((st = check_texture_ref(refs[k], s->texture_count, names[k], file, element, err))) return st;
  }
  return check_texture_ref(m->emission_texture, s->texture_count, "emission_texture", file,
                           element, err);
}

static iris_status validate_mesh(const iris_scene *s, const iris_mesh *m, const char *file,
                                 const char *element, iris_error *err) {
  if (m->vertex_count == 0) FAIL("mesh has no vertices");
  if (m->triangle_count == 0) FAIL("mesh has no triangles");
  if (!m->positions || !m->indices) FAIL("mesh has no position or index array");
  if (m->material < -1 || (m->material >= 0 && (size_t)m->material >= s->material_count))
    FAIL("material %d out of range (material count %zu)", (int)m->material, s->material_count);
  size_t nv = m->vertex_count;
  size_t bad;
  if ((bad = first_nonfinite(m->positions, 3 * nv)) < 3 * nv)
    FAIL("position of vertex %zu is not finite", bad / 3);
  if (m->normals && (bad = first_nonfinite(m->normals, 3 * nv)) < 3 * nv)
    FAIL("normal of vertex %zu is not finite", bad / 3);
  if (m->uvs && (bad = first_nonfinite(m->uvs, 2 * nv)) < 2 * nv)
    FAIL("uv of vertex %zu is not finite", bad / 2);
  if (m->colors && (bad = first_nonfinite(m->colors, 3 * nv)) < 3 * nv)
    FAIL("color of vertex %zu is not finite", bad / 3);
  if (m->uvs1 && (bad = first_nonfinite(m->uvs1, 2 * nv)) < 2 * nv)
    FAIL("uv1 of vertex %zu is not finite", bad / 2);
  if (m->alphas)
    for (size_t v = 0; v < nv; v++)
      if (!(m->alphas[v] >= 0.0f && m->alphas[v] <= 1.0f)) FAIL("alpha of vertex %zu is not in [0, 1]", v);
  if (m->tangents) {
    if (!m->normals) FAIL("mesh has tangents but no normals");
    if ((bad = first_nonfinite(m->tangents, 4 * nv)) < 4 * nv)
      FAIL("tangent of vertex %zu is not finite", bad / 4);
    for (size_t v = 0; v < nv; v++)
      if (m->tangents[4 * v + 3] != 1.0f && m->tangents[4 * v + 3] != -1.0f)
        FAIL("tangent of vertex %zu: w %g is not +1 or -1", v, (double)m->tangents[4 * v + 3]);
  }
  size_t ni = 3 * (size_t)m->triangle_count;
  for (size_t i = 0; i < ni; i++)
    if (m->indices[i] >= m->vertex_count)
      FAIL("index %u out of range (vertex count %u) in triangle %zu", (unsigned)m->indices[i],
           (unsigned)m->vertex_count, i / 3);
  return IRIS_OK;
}

static iris_status validate_light(const iris_light *l, const char *file, const char *element,
                                  iris_error *err) {
  if ((unsigned)l->type > IRIS_LIGHT_DIRECTIONAL) FAIL("unknown light type %d", (int)l->type);
  if (!nonneg_finite_n(l->color, 3)) FAIL("color must be finite and non-negative");
  if (!isfinite(l->intensity) || l->intensity < 0.0f)
    FAIL("intensity %g must be finite and non-negative", (double)l->intensity);
  if (!finite_n(l->position, 3)) FAIL("position is not finite");
  if (!finite_n(l->direction, 3)) FAIL("direction is not finite");
  if (!isfinite(l->range) || l->range < 0.0f) FAIL("range %g must be finite and non-negative", (double)l->range);
  if (l->type != IRIS_LIGHT_POINT && !(iris_length(iris_v3_load(l->direction)) > 0.0f))
    FAIL("direction must be a non-zero vector");
  if (l->type == IRIS_LIGHT_SPOT) {
    if (!isfinite(l->inner_cone) || !isfinite(l->outer_cone) || l->inner_cone < 0.0f ||
        l->inner_cone > l->outer_cone || l->outer_cone <= 0.0f || l->outer_cone > 0.5f * IRIS_PI)
      FAIL("cone angles must satisfy 0 <= inner (%g) <= outer (%g) <= pi/2, outer > 0",
           (double)l->inner_cone, (double)l->outer_cone);
  }
  return IRIS_OK;
}

iris_status iris_scene_validate(const iris_scene *s, const char *file, iris_error *err) {
  char element[64];
  iris_status st;
  if (!s->units[0] || !memchr(s->units, '\0', sizeof s->units)) {
    snprintf(element, sizeof element, "units");
    FAIL("units must be a non-empty string");
  }
  if (s->variants.count) {
    snprintf(element, sizeof element, "material_variants");
    for (size_t i = 0; i < s->variants.count; i++)
      if (!s->variants.names || !s->variants.names[i]) FAIL("variant %zu has no name", i);
    if (s->variants.applied < -1 || s->variants.applied >= (int32_t)s->variants.count)
      FAIL("applied variant %d out of range (%zu variants)", (int)s->variants.applied, s->variants.count);
  }
  for (size_t i = 0; i < s->texture_count; i++) {
    const iris_texture *t = &s->textures[i];
    snprintf(element, sizeof element, "textures[%zu]", i);
    if (!t->path && !t->data) FAIL("texture has neither a file nor data");
    if (t->path && t->data) FAIL("texture has both a file and data");
    if (t->data && t->data_size == 0) FAIL("texture data is empty");
    if ((unsigned)t->wrap_s > IRIS_WRAP_MIRROR || (unsigned)t->wrap_t > IRIS_WRAP_MIRROR)
      FAIL("unknown wrap mode");
    if (t->uv_set > 1) FAIL("uv_set %u is not 0 or 1", (unsigned)t->uv_set);
    if (t->has_transform && !(finite_n(t->offset, 2) && isfinite(t->rotation) && finite_n(t->scale, 2)))
      FAIL("transform is not finite");
    if (t->data && strcmp(t->mime, "image/png") != 0 && strcmp(t->mime, "image/jpeg") != 0)
      FAIL("unsupported image type '%.16s' (PNG and JPEG are supported)", t->mime);
  }
  for (size_t i = 0; i < s->material_count; i++) {
    snprintf(element, sizeof element, "materials[%zu]", i);
    if ((st = validate_material(s, &s->materials[i], file, element, err))) return st;
  }
  for (size_t i = 0; i < s->mesh_count; i++) {
    snprintf(element, sizeof element, "meshes[%zu]", i);
    if ((st = validate_mesh(s, &s->meshes[i], file, element, err))) return st;
  }
  for (size_t i = 0; i < s->instance_count; i++) {
    const iris_instance *inst = &s->instances[i];
    snprintf(element, sizeof element, "instances[%zu]", i);
    if (inst->mesh >= s->mesh_count)
      FAIL("mesh %u out of range (mesh count %zu)", (unsigned)inst->mesh, s->mesh_count);
    if (!mat4_finite(&inst->transform)) FAIL("transform is not finite");
  }
  for (size_t i = 0; i < s->camera_count; i++) {
    const iris_camera *c = &s->cameras[i];
    snprintf(element, sizeof element, "cameras[%zu]", i);
    if (!mat4_finite(&c->to_world)) FAIL("to_world is not finite");
    iris_mat4 inv;
    if (!iris_mat4_inverse(&c->to_world, &inv)) FAIL("to_world is singular");
    if (!isfinite(c->yfov) || c->yfov <= 0.0f || c->yfov >= IRIS_PI)
      FAIL("yfov %g rad outside (0, pi)", (double)c->yfov);
    if (!isfinite(c->aspect) || c->aspect < 0.0f) FAIL("aspect %g must be finite and >= 0", (double)c->aspect);
  }
  for (size_t i = 0; i < s->light_count; i++) {
    snprintf(element, sizeof element, "lights[%zu]", i);
    if ((st = validate_light(&s->lights[i], file, element, err))) return st;
  }
  if (s->has_environment && !nonneg_finite_n(s->environment, 3)) {
    snprintf(element, sizeof element, "environment");
    FAIL("environment must be finite and non-negative");
  }
  if (s->environment_map.path) {
    const iris_environment_map *em = &s->environment_map;
    snprintf(element, sizeof element, "environment.map");
    if (!s->has_environment) FAIL("a map needs has_environment");
    if (!em->path[0]) FAIL("path is empty");
    if (!isfinite(em->strength) || em->strength < 0.0f)
      FAIL("strength %g must be finite and non-negative", (double)em->strength);
    if (!isfinite(em->rotation) || fabsf(em->rotation) > 1e6f)
      FAIL("rotation %g must be a finite number of degrees", (double)em->rotation);
  }
  const iris_render_settings *r = &s->render;
  snprintf(element, sizeof element, "render");
  if (r->width < 0 || r->height < 0 || r->width > 65536 || r->height > 65536)
    FAIL("image size %dx%d outside [0, 65536]", r->width, r->height);
  if (r->spp < 0) FAIL("spp %d is negative", r->spp);
  if (r->max_depth < -1) FAIL("max_depth %d is below -1", r->max_depth);
  if (!memchr(r->method, '\0', sizeof r->method)) FAIL("method is not a terminated string");
  return IRIS_OK;
}
#undef FAIL

/* ---- derived quantities ------------------------------------------------ */

bool iris_scene_bounds(const iris_scene *s, iris_vec3 *lo, iris_vec3 *hi) {
  iris_vec3 a = iris_v3(INFINITY, INFINITY, INFINITY), b = iris_v3(-INFINITY, -INFINITY, -INFINITY);
  bool any = false;
  /* Object-space boxes per mesh (once each: per instance it was instances x
   * vertices), then the 8 transformed corners per instance: exact for
   * translations and axis permutations, conservative otherwise. */
  iris_vec3 *boxes = malloc((s->mesh_count ? s->mesh_count : 1) * 2 * sizeof *boxes);
  if (!boxes) return false;
  for (size_t i = 0; i < s->mesh_count; i++) {
    const iris_mesh *m = &s->meshes[i];
    iris_vec3 mlo = iris_v3(INFINITY, INFINITY, INFINITY), mhi = iris_neg(mlo);
    for (uint32_t v = 0; m->positions && v < m->vertex_count; v++) {
      iris_vec3 p = iris_v3_load(m->positions + 3 * (size_t)v);
      mlo = iris_v3(fminf(mlo.x, p.x), fminf(mlo.y, p.y), fminf(mlo.z, p.z));
      mhi = iris_v3(fmaxf(mhi.x, p.x), fmaxf(mhi.y, p.y), fmaxf(mhi.z, p.z));
    }
    boxes[2 * i] = mlo, boxes[2 * i + 1] = mhi;
  }
  for (size_t i = 0; i < s->instance_count; i++) {
    const iris_instance *inst = &s->instances[i];
    if (inst->mesh >= s->mesh_count) continue;
    const iris_mesh *m = &s->meshes[inst->mesh];
    if (!m->positions || m->vertex_count == 0) continue;
    const iris_vec3 mlo = boxes[2 * (size_t)inst->mesh], mhi = boxes[2 * (size_t)inst->mesh + 1];
    for (int c = 0; c < 8; c++) {
      iris_vec3 p = iris_v3(c & 1 ? mhi.x : mlo.x, c & 2 ? mhi.y : mlo.y, c & 4 ? mhi.z : mlo.z);
      p = iris_mat4_point(&inst->transform, p);
      a = iris_v3(fminf(a.x, p.x), fminf(a.y, p.y), fminf(a.z, p.z));
      b = iris_v3(fmaxf(b.x, p.x), fmaxf(b.y, p.y), fmaxf(b.z, p.z));
    }
    any = true;
  }
  free(boxes);
  if (!any) return false;
  if (lo) *lo = a;
  if (hi) *hi = b;
  return true;
}

uint64_t iris_scene_triangle_count(const iris_scene *s) {
  uint64_t n = 0;
  for (size_t i = 0; i < s->instance_count; i++)
    if (s->instances[i].mesh < s->mesh_count) n += s->meshes[s->instances[i].mesh].triangle_count;
  return n;
}
