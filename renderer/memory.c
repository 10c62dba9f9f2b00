/* Memory estimate and availability; see memory.h. */
#include "renderer/memory.h"
#include "renderer/light_trace.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include "core/image.h"
#include "renderer/guiding/guiding.h"
#include "renderer/guiding/photons.h"
#include "renderer/lights.h"
#include "renderer/vcache.h"

/* Measured costs (docs/performance.md, "Memory estimate"; Embree 3.13 with
 * ROBUST and HIGH quality, from its memory monitor and peak RSS). */
#define BVH_BYTES_PER_TRIANGLE 67.0     /* Embree's BVH, flattened or built once */
#define BUILD_BYTES_PER_TRIANGLE 24.0   /* Embree's transient build arrays at the peak */
#define COPY_BYTES_PER_VERTEX 12.0      /* iris's padded vertex copy */
#define BYTES_PER_PLACEMENT 240.0       /* Embree instance + iris placement table + box */
#define BYTES_PER_EMISSIVE_TRIANGLE 280.0 /* tables and tree; +100 for the descent's wide nodes (384 B, ~1 per 2 leaves) */
#define BASE_BYTES 14e6                 /* iris + libraries + Embree's threads */
#define PATH_BYTES 304.0                /* one photon path: ~4 stored photons (64 B) and their kd-tree */
#define CACHE_BYTES 1468.0              /* one 8x8 cache with its tables (and its portal, 40 B) */
#define GLINT_BYTES 3.8e6               /* glint photons and their tree (guiding/glints.h), with a smooth material */
#define LIGHT_SELECT_BYTES 129.0        /* one cache's learned light table (guiding/light_select.h) */
#define FILM_BYTES_PER_PIXEL 62.0       /* sums, counts and the EXR image */
#define ENV_BYTES_PER_TEXEL 24.0        /* RGB float + sampling tables */

static const iris_material *material_of(const iris_scene *s, int32_t m) {
  return m >= 0 && (size_t)m < s->material_count ? &s->materials[m] : NULL;
}

static bool emissive(const iris_material *m) {
  return m && (m->emission[0] > 0.0f || m->emission[1] > 0.0f || m->emission[2] > 0.0f);
}

static bool affine(const iris_mat4 *m) {
  return m->m[3][0] == 0.0f && m->m[3][1] == 0.0f && m->m[3][2] == 0.0f && m->m[3][3] == 1.0f;
}

static uint64_t file_size(const char *path) {
  struct stat st;
  return path && stat(path, &st) == 0 && st.st_size > 0 ? (uint64_t)st.st_size : 0;
}

/* A material that may reflect glints (renderer/guiding/glints.h): not diffuse,
 * and smooth enough, or textured so that it may be. */
static bool may_be_smooth(const iris_material *m) {
  return m->type != IRIS_MATERIAL_DIFFUSE && (m->roughness <= IRIS_GLINT_ROUGHNESS || m->metallic_roughness_texture >= 0);
}

void iris_memory_estimate_scene(const iris_scene *s, int width, int height, bool guided,
                                iris_memory_estimate *out) {
  memset(out, 0, sizeof *out);
  if (width <= 0 || height <= 0) width = 640, height = 480;
  uint32_t instance_min = 2;
  const char *env = getenv("IRIS_INSTANCE_MIN"); /* as iris_accel_build */
  if (env && atol(env) >= 1) instance_min = atol(env) > 1000000000 ? 1000000000u : (uint32_t)atol(env);
  uint32_t *placements = calloc(s->mesh_count ? s->mesh_count : 1, sizeof *placements);
  if (placements)
    for (size_t i = 0; i < s->instance_count; i++)
      if (s->instances[i].mesh < s->mesh_count && affine(&s->instances[i].transform))
        placements[s->instances[i].mesh]++;
  double accel = 0.0, flattened_peak = 0.0, emissive_tris = 0.0;
  uint64_t light_groups = 0; /* emitting placements, then every light group */
  for (size_t k = 0; k < s->mesh_count; k++) {
    const iris_mesh *m = &s->meshes[k];
    out->scene += 12ull * m->vertex_count + 12ull * m->triangle_count;
    if (m->normals) out->scene += 12ull * m->vertex_count;
    if (m->uvs) out->scene += 8ull * m->vertex_count;
    if (m->uvs1) out->scene += 8ull * m->vertex_count;
    if (m->colors) out->scene += 12ull * m->vertex_count;
    if (m->tangents) out->scene += 16ull * m->vertex_count;
    if (m->alphas) out->scene += 4ull * m->vertex_count;
    if (placements && placements[k] >= instance_min && m->triangle_count > 0) {
      out->unique_triangles += m->triangle_count;
      accel += BVH_BYTES_PER_TRIANGLE * m->triangle_count + COPY_BYTES_PER_VERTEX * m->vertex_count;
      double build = BUILD_BYTES_PER_TRIANGLE * m->triangle_count;
      if (build > flattened_peak) flattened_peak = build; /* built one at a time */
    }
  }
  double flattened = 0.0;
  for (size_t i = 0; i < s->instance_count; i++) {
    const iris_instance *in = &s->instances[i];
    if (in->mesh >= s->mesh_count) continue;
    const iris_mesh *m = &s->meshes[in->mesh];
    out->scene += sizeof *in;
    out->world_triangles += m->triangle_count;
    accel += BYTES_PER_PLACEMENT;
    if (emissive(material_of(s, m->material))) {
      emissive_tris += m->triangle_count;
      light_groups++;
    }
    if (placements && placements[in->mesh] >= instance_min && affine(&in->transform)) {
      out->instanced_placements++;
      continue;
    }
    out->flattened_triangles += m->triangle_count;
    accel += COPY_BYTES_PER_VERTEX * m->vertex_count;
    flattened += m->triangle_count;
  }
  free(placements);
  /* the top-level build holds every flattened triangle's build arrays at once */
  accel += BVH_BYTES_PER_TRIANGLE * flattened;
  double peak = BUILD_BYTES_PER_TRIANGLE * flattened;
  accel += peak > flattened_peak ? peak : flattened_peak;
  out->accel = (uint64_t)accel;
  for (size_t t = 0; t < s->texture_count; t++) {
    const iris_texture *tx = &s->textures[t];
    int w = 0, h = 0;
    if (iris_image_dims(tx->path, tx->data, tx->data_size, &w, &h))
      out->textures += 4ull * (uint64_t)w * (uint64_t)h;
    else
      out->textures += 8 * (tx->data ? tx->data_size : file_size(tx->path)); /* undecodable: a guess */
  }
  if (s->has_environment && s->environment_map.path) {
    int w = 0, h = 0;
    if (iris_image_dims(s->environment_map.path, NULL, 0, &w, &h))
      out->textures += (uint64_t)(ENV_BYTES_PER_TEXEL * (double)w * (double)h);
    else /* OpenEXR: half or float RGB(A), so texels >= size / 16 */
      out->textures += (uint64_t)(ENV_BYTES_PER_TEXEL / 6.0 * (double)file_size(s->environment_map.path));
  }
  out->lights = (uint64_t)(BYTES_PER_EMISSIVE_TRIANGLE * emissive_tris) + 16ull * s->instance_count;
  /* as the lights build their groups: emitting punctual lights and the sky one
   * each (a map counted whatever its mean: known only once loaded) */
  const bool sky = iris_lights_constant_environment_emits(s) || (s->has_environment && s->environment_map.path);
  size_t punctual = 0;
  for (size_t i = 0; i < s->light_count; i++) punctual += iris_lights_punctual_emits(&s->lights[i]);
  light_groups = iris_lights_group_count(light_groups, punctual + sky);
  if (guided) { /* the default budget of renderer/guiding/rules.c (iris_guiding_choose_budget) */
    double pixels = (double)width * height, caches = pixels / 32.0;
    caches = caches < 1024 ? 1024 : (caches > 65536 ? 65536 : caches);
    /* the sky's share of the power at its largest: up to twice the paths */
    double paths = iris_guiding_photon_paths(caches, 200, light_groups, sky ? 1.0 : 0.0);
    /* learned light selection: with more than one light to choose from */
    if (emissive_tris + (double)punctual > 1) out->light_select = (uint64_t)(caches * LIGHT_SELECT_BYTES);
    out->guide = (uint64_t)(caches * CACHE_BYTES + paths * PATH_BYTES) + out->light_select;
    /* connections with the sky through a window (vcache.h): pools of at most
     * one vertex per light path, kept within their budget; the door's kind
     * keeps a few vertices per sample index (door, 1024 spp: 0.15 MB) */
    if (s->has_environment && s->environment_map.path) {
      out->connect = (uint64_t)IRIS_VCACHE_SKY_BUDGET;
      out->guide += out->connect;
    }
    for (size_t m = 0; m < s->material_count; m++)
      if (may_be_smooth(&s->materials[m])) { /* glints: at most one set of 65536 paths */
        out->guide += (uint64_t)GLINT_BYTES;
        break;
      }
  }
  out->film = (uint64_t)(FILM_BYTES_PER_PIXEL * (double)width * height);
  /* light tracing's sums (light_trace.h: 6 doubles per pixel) where a
   * material may be a glossy reflector; its tables, 5 bytes per triangle,
   * are not counted (a few percent of the BVH's) */
  for (size_t m = 0; m < s->material_count; m++)
    if (s->materials[m].type != IRIS_MATERIAL_DIFFUSE &&
        (s->materials[m].roughness <= IRIS_LIGHT_TRACE_ROUGHNESS || s->materials[m].metallic_roughness_texture >= 0)) {
      out->film += (uint64_t)(48.0 * (double)width * height);
      break;
    }
  out->base = (uint64_t)BASE_BYTES;
  out->total = out->scene + out->accel + out->textures + out->lights + out->guide + out->film + out->base;
}

static bool read_kb(const char *path, const char *key, uint64_t *bytes) {
  FILE *fp = fopen(path, "r");
  if (!fp) return false;
  char line[256];
  size_t n = strlen(key);
  bool found = false;
  while (fgets(line, sizeof line, fp))
    if (!strncmp(line, key, n) && line[n] == ':') {
      unsigned long long kb = 0;
      if (sscanf(line + n + 1, "%llu", &kb) == 1) *bytes = (uint64_t)kb * 1024ull, found = true;
      break;
    }
  fclose(fp);
  return found;
}

bool iris_memory_available(uint64_t *bytes, char *why, size_t why_size) {
  uint64_t best = UINT64_MAX, v = 0;
  const char *name = NULL;
  if (read_kb("/proc/meminfo", "MemAvailable", &v)) best = v, name = "MemAvailable";
  struct rlimit rl;
  if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
    uint64_t used = 0;
    read_kb("/proc/self/status", "VmSize", &used);
    uint64_t left = (uint64_t)rl.rlim_cur > used ? (uint64_t)rl.rlim_cur - used : 0;
    if (left < best) best = left, name = "RLIMIT_AS";
  }
  *bytes = best;
  if (why && why_size) snprintf(why, why_size, "%s", name ? name : "unknown");
  return name != NULL;
}

static double gb(uint64_t b) { return (double)b / 1e9; }

iris_status iris_memory_check(const iris_memory_estimate *est, const char *what, iris_error *err) {
  uint64_t avail = 0;
  char why[32];
  if (!iris_memory_available(&avail, why, sizeof why)) return IRIS_OK;
  /* the scene and the process are already in memory: the rest must fit */
  uint64_t need = est->total - est->scene - est->base;
  if (need <= avail) return IRIS_OK;
  return iris_error_set(err, IRIS_ERR_NOMEM, what, 0, NULL,
                        "needs about %.2f GB, %.2f GB available (%s; BVH %.2f GB for %llu world triangles)",
                        gb(need), gb(avail), why, gb(est->accel), (unsigned long long)est->world_triangles);
}

void iris_memory_format(const iris_memory_estimate *est, char *buf, size_t size) {
  uint64_t avail = 0;
  char why[32];
  bool known = iris_memory_available(&avail, why, sizeof why);
  int n = snprintf(buf, size,
                   "about %.3f GB (BVH %.3f, scene %.3f, textures %.3f, lights %.3f, guide %.3f, film %.3f, "
                   "process %.3f)",
                   gb(est->total), gb(est->accel), gb(est->scene), gb(est->textures), gb(est->lights),
                   gb(est->guide), gb(est->film), gb(est->base));
  if (known && n > 0 && (size_t)n < size) snprintf(buf + n, size - (size_t)n, ", %.2f GB available (%s)", gb(avail), why);
}
