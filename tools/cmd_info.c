/* `iris info FILE [--json]`: what a scene (or any importable file) contains:
 * counts, bounds, emitters, cameras and memory (docs/cli.md). */
#include <cjson/cJSON.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/log.h"
#include "renderer/camera.h"
#include "renderer/memory.h"
#include "importers/import.h"
#include "scene/scene.h"
#include "tools/cli.h"
#include "tools/options.h"

static const char *const CMD = "info";
static const char *const MATERIAL_TYPES[] = {"diffuse", "glossy", "glass", "gltf"};
static const char *const LIGHT_TYPES[] = {"point", "spot", "directional"};
static const char *const ATTRIBUTES[] = {"normals", "uvs", "colors", "uvs1", "tangents", "alphas"};
static const int ATTRIBUTE_BYTES[] = {12, 8, 12, 8, 16, 4};

static void print_help(void) {
  printf("Usage: iris info FILE [--json] [--variant NAME]\n"
         "\n"
         "Describes an iris scene (.json) or any file iris imports (.obj, .ply, .gltf,\n"
         ".glb): meshes, instances, triangles, materials by type, emissive materials,\n"
         "textures, lights by type, cameras, bounds, attributes, mesh memory and a glTF\n"
         "file's material variants (KHR_materials_variants).\n"
         "\n"
         "Options:\n"
         "      --json          print one JSON object instead of text\n"
         "      --variant NAME  describe the file with its material variant NAME applied\n"
         "  -q, --quiet         print no warnings while loading\n"
         "  -h, --help          show this help\n"
         "\n"
         "Exit status: 0 success, 2 bad usage or bad input, 1 other failure.\n");
}

/* Everything `info` reports, computed once for both output forms. */
typedef struct scene_stats {
  uint64_t vertices, triangles, world_triangles, emissive_world_triangles;
  uint64_t mesh_bytes, texture_bytes;
  size_t materials_by_type[4], lights_by_type[3], meshes_with[6];
  size_t embedded_textures;
  bool has_bounds;
  iris_vec3 lo, hi;
} scene_stats;

static bool is_emissive(const iris_material *m) {
  return m->emission[0] > 0.0f || m->emission[1] > 0.0f || m->emission[2] > 0.0f;
}

static scene_stats compute_stats(const iris_scene *s) {
  scene_stats st;
  memset(&st, 0, sizeof st);
  for (size_t i = 0; i < s->mesh_count; i++) {
    const iris_mesh *m = &s->meshes[i];
    st.vertices += m->vertex_count;
    st.triangles += m->triangle_count;
    const void *attrs[6] = {m->normals, m->uvs, m->colors, m->uvs1, m->tangents, m->alphas};
    uint64_t per_vertex = 12;
    for (int k = 0; k < 6; k++)
      if (attrs[k]) {
        st.meshes_with[k]++;
        per_vertex += (uint64_t)ATTRIBUTE_BYTES[k];
      }
    st.mesh_bytes += per_vertex * m->vertex_count + 12ull * m->triangle_count;
  }
  for (size_t i = 0; i < s->instance_count; i++) {
    const iris_mesh *m = &s->meshes[s->instances[i].mesh];
    if (m->material >= 0 && is_emissive(&s->materials[m->material]))
      st.emissive_world_triangles += m->triangle_count;
  }
  st.world_triangles = iris_scene_triangle_count(s);
  for (size_t i = 0; i < s->material_count; i++) st.materials_by_type[s->materials[i].type]++;
  for (size_t i = 0; i < s->light_count; i++) st.lights_by_type[s->lights[i].type]++;
  for (size_t i = 0; i < s->texture_count; i++)
    if (s->textures[i].data) {
      st.embedded_textures++;
      st.texture_bytes += s->textures[i].data_size;
    }
  st.has_bounds = iris_scene_bounds(s, &st.lo, &st.hi);
  return st;
}

static double deg(float rad) { return (double)rad * 180.0 / 3.14159265358979323846; }

static cJSON *vec(const float *v) {
  cJSON *a = cJSON_CreateArray();
  for (int i = 0; i < 3; i++) cJSON_AddItemToArray(a, cJSON_CreateNumber((double)v[i]));
  return a;
}

/* The render-memory estimate at the scene's default frame size: `total`
 * without a guide (mis, or auto where it declines), `guide` what the guided
 * methods add (auto where it guides). */
static void estimate_memory(const iris_scene *s, iris_memory_estimate *est, int *w, int *h) {
  iris_pinhole cam;
  iris_error err;
  *w = s->render.width, *h = s->render.height;
  if (iris_pinhole_setup(s, NULL, *w, *h, &cam, &err) == IRIS_OK) *w = cam.width, *h = cam.height;
  if (*w <= 0 || *h <= 0) *w = 640, *h = 480;
  iris_memory_estimate guided;
  iris_memory_estimate_scene(s, *w, *h, false, est);
  iris_memory_estimate_scene(s, *w, *h, true, &guided);
  est->guide = guided.guide; /* reported beside the total, which is without it */
  est->light_select = guided.light_select;
  est->connect = guided.connect;
}

static void print_json(const char *path, const iris_scene *s, const scene_stats *st) {
  cJSON *o = cJSON_CreateObject();
  cJSON_AddStringToObject(o, "file", path);
  cJSON_AddStringToObject(o, "units", s->units);
  cJSON *meshes = cJSON_AddObjectToObject(o, "meshes");
  cJSON_AddNumberToObject(meshes, "count", (double)s->mesh_count);
  cJSON_AddNumberToObject(meshes, "vertices", (double)st->vertices);
  cJSON_AddNumberToObject(meshes, "triangles", (double)st->triangles);
  cJSON_AddNumberToObject(meshes, "bytes", (double)st->mesh_bytes);
  cJSON *with = cJSON_AddObjectToObject(meshes, "with_attribute");
  for (int k = 0; k < 6; k++) cJSON_AddNumberToObject(with, ATTRIBUTES[k], (double)st->meshes_with[k]);
  cJSON *inst = cJSON_AddObjectToObject(o, "instances");
  cJSON_AddNumberToObject(inst, "count", (double)s->instance_count);
  cJSON_AddNumberToObject(inst, "world_triangles", (double)st->world_triangles);
  cJSON_AddNumberToObject(inst, "emissive_world_triangles", (double)st->emissive_world_triangles);
  cJSON *mats = cJSON_AddObjectToObject(o, "materials");
  cJSON_AddNumberToObject(mats, "count", (double)s->material_count);
  for (int k = 0; k < 4; k++) cJSON_AddNumberToObject(mats, MATERIAL_TYPES[k], (double)st->materials_by_type[k]);
  cJSON *emissive = cJSON_AddArrayToObject(mats, "emissive");
  for (size_t i = 0; i < s->material_count; i++) {
    const iris_material *m = &s->materials[i];
    if (!is_emissive(m)) continue;
    cJSON *e = cJSON_CreateObject();
    cJSON_AddNumberToObject(e, "index", (double)i);
    if (m->name) cJSON_AddStringToObject(e, "name", m->name);
    cJSON_AddItemToObject(e, "emission", vec(m->emission));
    cJSON_AddBoolToObject(e, "textured", m->emission_texture >= 0);
    cJSON_AddItemToArray(emissive, e);
  }
  cJSON *tex = cJSON_AddObjectToObject(o, "textures");
  cJSON_AddNumberToObject(tex, "count", (double)s->texture_count);
  cJSON_AddNumberToObject(tex, "embedded", (double)st->embedded_textures);
  cJSON_AddNumberToObject(tex, "embedded_bytes", (double)st->texture_bytes);
  cJSON *lights = cJSON_AddObjectToObject(o, "lights");
  cJSON_AddNumberToObject(lights, "count", (double)s->light_count);
  for (int k = 0; k < 3; k++) cJSON_AddNumberToObject(lights, LIGHT_TYPES[k], (double)st->lights_by_type[k]);
  cJSON *cams = cJSON_AddArrayToObject(o, "cameras");
  for (size_t i = 0; i < s->camera_count; i++) {
    const iris_camera *c = &s->cameras[i];
    cJSON *e = cJSON_CreateObject();
    if (c->name) cJSON_AddStringToObject(e, "name", c->name);
    cJSON_AddNumberToObject(e, "yfov_deg", deg(c->yfov));
    if (c->aspect > 0.0f) cJSON_AddNumberToObject(e, "aspect", (double)c->aspect);
    float pos[3] = {c->to_world.m[0][3], c->to_world.m[1][3], c->to_world.m[2][3]};
    cJSON_AddItemToObject(e, "position", vec(pos));
    cJSON_AddItemToArray(cams, e);
  }
  if (st->has_bounds) {
    cJSON *b = cJSON_AddObjectToObject(o, "bounds");
    float lo[3], hi[3];
    iris_v3_store(st->lo, lo);
    iris_v3_store(st->hi, hi);
    cJSON_AddItemToObject(b, "min", vec(lo));
    cJSON_AddItemToObject(b, "max", vec(hi));
  } else {
    cJSON_AddNullToObject(o, "bounds");
  }
  if (s->has_environment && !s->environment_map.path)
    cJSON_AddItemToObject(o, "environment", vec(s->environment));
  else
    cJSON_AddNullToObject(o, "environment");
  if (s->environment_map.path) {
    cJSON *m = cJSON_AddObjectToObject(o, "environment_map");
    cJSON_AddStringToObject(m, "path", s->environment_map.path);
    cJSON_AddNumberToObject(m, "strength", s->environment_map.strength);
    cJSON_AddNumberToObject(m, "rotation", s->environment_map.rotation);
  } else {
    cJSON_AddNullToObject(o, "environment_map");
  }
  cJSON_AddBoolToObject(o, "has_light", iris_scene_has_emitter(s));
  if (s->variants.count) { /* as the scene format's "material_variants" */
    cJSON *v = cJSON_AddObjectToObject(o, "material_variants");
    cJSON *names = cJSON_AddArrayToObject(v, "names");
    for (size_t i = 0; i < s->variants.count; i++)
      cJSON_AddItemToArray(names, cJSON_CreateString(s->variants.names[i]));
    if (s->variants.applied >= 0)
      cJSON_AddStringToObject(v, "applied", s->variants.names[s->variants.applied]);
    else
      cJSON_AddNullToObject(v, "applied");
  } else {
    cJSON_AddNullToObject(o, "material_variants");
  }
  {
    iris_memory_estimate est;
    int w, h;
    estimate_memory(s, &est, &w, &h);
    cJSON *mem = cJSON_AddObjectToObject(o, "memory");
    cJSON_AddNumberToObject(mem, "width", w);
    cJSON_AddNumberToObject(mem, "height", h);
    cJSON_AddNumberToObject(mem, "estimate_bytes", (double)est.total);
    cJSON_AddNumberToObject(mem, "bvh_bytes", (double)est.accel);
    cJSON_AddNumberToObject(mem, "scene_bytes", (double)est.scene);
    cJSON_AddNumberToObject(mem, "texture_bytes", (double)est.textures);
    cJSON_AddNumberToObject(mem, "light_bytes", (double)est.lights);
    cJSON_AddNumberToObject(mem, "guide_bytes", (double)est.guide); /* not in estimate_bytes */
    cJSON_AddNumberToObject(mem, "light_select_bytes", (double)est.light_select); /* part of guide_bytes */
    cJSON_AddNumberToObject(mem, "connect_bytes", (double)est.connect);           /* part of guide_bytes */
    cJSON_AddNumberToObject(mem, "film_bytes", (double)est.film);
    cJSON_AddNumberToObject(mem, "process_bytes", (double)est.base);
    cJSON_AddNumberToObject(mem, "unique_triangles", (double)est.unique_triangles);
    cJSON_AddNumberToObject(mem, "instanced_placements", (double)est.instanced_placements);
    cJSON_AddNumberToObject(mem, "flattened_triangles", (double)est.flattened_triangles);
    uint64_t avail;
    char why[32];
    if (iris_memory_available(&avail, why, sizeof why)) {
      cJSON_AddNumberToObject(mem, "available_bytes", (double)avail);
      cJSON_AddStringToObject(mem, "available_limit", why);
    } else {
      cJSON_AddNullToObject(mem, "available_bytes");
    }
  }
  char *text = cJSON_Print(o);
  if (text) printf("%s\n", text);
  free(text);
  cJSON_Delete(o);
}

static void print_text(const char *path, const iris_scene *s, const scene_stats *st) {
  printf("file         %s\n", path);
  printf("units        %s\n", s->units);
  printf("meshes       %zu (%llu vertices, %llu triangles)\n", s->mesh_count,
         (unsigned long long)st->vertices, (unsigned long long)st->triangles);
  printf("attributes   normals %zu, uvs %zu, colors %zu", st->meshes_with[0], st->meshes_with[1],
         st->meshes_with[2]);
  if (st->meshes_with[3] || st->meshes_with[4] || st->meshes_with[5]) /* only scenes that have them */
    printf(", uvs1 %zu, tangents %zu, alphas %zu", st->meshes_with[3], st->meshes_with[4], st->meshes_with[5]);
  printf(" of %zu meshes\n", s->mesh_count);
  printf("instances    %zu (%llu triangles in the world, %llu emissive)\n", s->instance_count,
         (unsigned long long)st->world_triangles, (unsigned long long)st->emissive_world_triangles);
  printf("materials    %zu (diffuse %zu, glossy %zu, glass %zu, gltf %zu)\n", s->material_count,
         st->materials_by_type[0], st->materials_by_type[1], st->materials_by_type[2],
         st->materials_by_type[3]);
  for (size_t i = 0; i < s->material_count; i++) {
    const iris_material *m = &s->materials[i];
    if (!is_emissive(m)) continue;
    printf("  emissive   [%zu] %s: emission %g %g %g%s\n", i, m->name ? m->name : "(unnamed)",
           (double)m->emission[0], (double)m->emission[1], (double)m->emission[2],
           m->emission_texture >= 0 ? " x texture" : "");
  }
  if (s->variants.count) {
    printf("variants     %zu:", s->variants.count);
    for (size_t i = 0; i < s->variants.count; i++)
      printf("%s \"%s\"%s", i ? "," : "", s->variants.names[i], (int32_t)i == s->variants.applied ? " (applied)" : "");
    printf("%s\n", s->variants.applied < 0 ? "; none applied (the default materials)" : "");
  }
  printf("textures     %zu (%zu embedded, %llu bytes)\n", s->texture_count, st->embedded_textures,
         (unsigned long long)st->texture_bytes);
  printf("lights       %zu (point %zu, spot %zu, directional %zu)\n", s->light_count,
         st->lights_by_type[0], st->lights_by_type[1], st->lights_by_type[2]);
  printf("cameras      %zu\n", s->camera_count);
  for (size_t i = 0; i < s->camera_count; i++) {
    const iris_camera *c = &s->cameras[i];
    printf("  camera     [%zu] %s: yfov %.4g deg", i, c->name ? c->name : "(unnamed)", deg(c->yfov));
    if (c->aspect > 0.0f) printf(", aspect %.4g", (double)c->aspect);
    printf(", at %g %g %g\n", (double)c->to_world.m[0][3], (double)c->to_world.m[1][3],
           (double)c->to_world.m[2][3]);
  }
  if (st->has_bounds)
    printf("bounds       min %g %g %g, max %g %g %g (size %g x %g x %g)\n", (double)st->lo.x,
           (double)st->lo.y, (double)st->lo.z, (double)st->hi.x, (double)st->hi.y, (double)st->hi.z,
           (double)(st->hi.x - st->lo.x), (double)(st->hi.y - st->lo.y), (double)(st->hi.z - st->lo.z));
  else
    printf("bounds       none (no instances)\n");
  if (s->environment_map.path)
    printf("environment  map %s, strength %g, rotation %g deg\n", s->environment_map.path,
           (double)s->environment_map.strength, (double)s->environment_map.rotation);
  else if (s->has_environment)
    printf("environment  %g %g %g\n", (double)s->environment[0], (double)s->environment[1],
           (double)s->environment[2]);
  else
    printf("environment  none\n");
  printf("mesh memory  %llu bytes (%.2f MiB)\n", (unsigned long long)st->mesh_bytes,
         (double)st->mesh_bytes / (1024.0 * 1024.0));
  iris_memory_estimate est;
  int w, h;
  estimate_memory(s, &est, &w, &h);
  printf("instancing   %llu unique triangles built once for %llu placements, %llu triangles flattened\n",
         (unsigned long long)est.unique_triangles, (unsigned long long)est.instanced_placements,
         (unsigned long long)est.flattened_triangles);
  char line[400];
  uint64_t guide = est.guide;
  est.guide = 0;
  iris_memory_format(&est, line, sizeof line);
  printf("render mem   %dx%d: %s; guided methods add about %.3f GB (learned light tables %.3f GB, connections' light "
         "vertices up to %.3f GB of it)\n",
         w, h, line, (double)guide / 1e9, (double)est.light_select / 1e9, (double)est.connect / 1e9);
}

int iris_cmd_info(int argc, char **argv) {
  static const struct option longopts[] = {{"json", no_argument, NULL, 'j'},
                                           {"variant", required_argument, NULL, 'v'},
                                           {"quiet", no_argument, NULL, 'q'},
                                           {"help", no_argument, NULL, 'h'},
                                           {NULL, 0, NULL, 0}};
  bool json = false, quiet = false;
  const char *variant = NULL;
  opterr = 0;
  optind = 1;
  int c;
  while ((c = getopt_long(argc, argv, ":qh", longopts, NULL)) != -1) {
    switch (c) {
      case 'j': json = true; break;
      case 'q': quiet = true; break;
      case 'v':
        if (!iris_cli_set_once(CMD, "--variant", &variant, optarg)) return IRIS_EXIT_USAGE;
        break;
      case 'h': print_help(); return IRIS_EXIT_OK;
      default: return iris_cli_getopt_error(CMD, c, argv);
    }
  }
  if (optind >= argc) return iris_cli_usage_error(CMD, "no input file");
  if (argc - optind > 1) return iris_cli_usage_error(CMD, "unexpected argument '%s' (one file at a time)", argv[optind + 1]);
  if (quiet) iris_log_set_level(IRIS_LOG_QUIET);
  const char *path = argv[optind];
  iris_error err;
  iris_error_clear(&err);
  iris_scene *scene = NULL;
  iris_import_options opts = iris_import_options_default();
  opts.variant = variant;
  if (iris_import_file(path, &opts, &scene, &err) != IRIS_OK) return iris_cli_report(&err);
  scene_stats st = compute_stats(scene);
  iris_warn_if_lightless(scene, path);
  if (json)
    print_json(path, scene, &st);
  else
    print_text(path, scene, &st);
  iris_scene_destroy(scene);
  return IRIS_EXIT_OK;
}
