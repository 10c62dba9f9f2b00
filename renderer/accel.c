/* Embree 3 two-level scene: meshes placed once flattened into world space,
 * meshes placed more often built once and instanced; see accel.h. */
#include "renderer/accel.h"

#include <embree3/rtcore.h>
#include <float.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/cancel.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "renderer/texture.h"

/* One placement of a mesh. A mesh placed once is flattened: `positions`
 * holds its world-space vertices and its triangles sit in the top-level
 * scene. A mesh placed two or more times is built once in object space into
 * its own Embree scene (accel_mesh) and each placement is an Embree instance
 * geometry carrying `xf`; `positions` is NULL and world-space vertices are
 * computed from the mesh's own with the same arithmetic as flattening, so an
 * interaction is bit-identical either way. The top-level geometry ID is the
 * scene instance index in both cases. */
typedef struct accel_instance {
  const iris_mesh *mesh;
  uint32_t mesh_index;
  float *positions;  /* world space, 3 * vertex_count (+ padding), or NULL when instanced */
  iris_mat4 xf;      /* object to world */
  float nm[3][3];    /* normal matrix (cofactor form, sign kept for mirrors) */
  bool mirrored;     /* det < 0: object-space CCW is world-space CW */
  float tscale;      /* 1 / cbrt |det|: tangents keep their object-space length under a
                        uniform scale, so a normal map's strength does not grow with it */
  uint32_t first_prim;
  const iris_material *alpha_material; /* MASK/BLEND material, else NULL (no filter) */
} accel_instance;

/* A mesh built once in object space for instancing. */
typedef struct accel_mesh {
  RTCScene rtc;      /* NULL unless placed two or more times */
  float *positions;  /* object-space copy with Embree's padding */
  uint32_t placements;
  float box[6];      /* object-space bounds (lo, hi), for placements >= 2 */
} accel_mesh;

struct iris_accel {
  const iris_scene *scene;
  RTCDevice device;
  RTCScene rtc;
  accel_instance *instances;
  size_t instance_count;
  accel_mesh *meshes;
  size_t mesh_count;
  uint32_t triangle_count;
  size_t unique_meshes, instanced_placements;
  iris_vec3 lo, hi;
  bool has_bounds;
  size_t own_bytes;
  atomic_llong embree_bytes;
  const iris_textures *textures; /* for alpha textures; may be NULL */
  /* Embree's first error, from its error callback, and what was being built. */
  atomic_int rtc_error; /* enum RTCError */
  char rtc_message[160];
  char building[200];
};

static bool memory_monitor(void *ptr, ssize_t bytes, bool post) {
  (void)post;
  iris_accel *a = (iris_accel *)ptr;
  atomic_fetch_add(&a->embree_bytes, (long long)bytes);
  return true;
}

static void error_callback(void *ptr, enum RTCError code, const char *str) {
  iris_accel *a = (iris_accel *)ptr;
  int none = RTC_ERROR_NONE;
  if (code == RTC_ERROR_NONE || !atomic_compare_exchange_strong(&a->rtc_error, &none, (int)code))
    return; /* keep the first */
  snprintf(a->rtc_message, sizeof a->rtc_message, "%s", str ? str : "");
}

static float instance_alpha(const iris_accel *a, const accel_instance *ai, uint32_t local, float b1,
                            float b2) {
  const iris_material *m = ai->alpha_material;
  const iris_mesh *mesh = ai->mesh;
  const uint32_t *idx = mesh->indices + 3 * (size_t)local;
  float b0 = 1.0f - b1 - b2;
  float alpha = m->alpha;
  if (mesh->alphas)
    alpha *= b0 * mesh->alphas[idx[0]] + b1 * mesh->alphas[idx[1]] + b2 * mesh->alphas[idx[2]];
  if (m->color_texture >= 0 && a->textures) {
    float uv[2] = {0, 0}, uv1[2];
    if (mesh->uvs) {
      const float *t = mesh->uvs;
      uv[0] = b0 * t[2 * idx[0]] + b1 * t[2 * idx[1]] + b2 * t[2 * idx[2]];
      uv[1] = b0 * t[2 * idx[0] + 1] + b1 * t[2 * idx[1] + 1] + b2 * t[2 * idx[2] + 1];
    }
    uv1[0] = uv[0], uv1[1] = uv[1];
    if (mesh->uvs1) {
      const float *t = mesh->uvs1;
      uv1[0] = b0 * t[2 * idx[0]] + b1 * t[2 * idx[1]] + b2 * t[2 * idx[2]];
      uv1[1] = b0 * t[2 * idx[0] + 1] + b1 * t[2 * idx[1] + 1] + b2 * t[2 * idx[2] + 1];
    }
    float rgba[4];
    iris_texture_sample(a->textures, m->color_texture, uv, uv1, false, rgba);
    alpha *= rgba[3];
  }
  return alpha;
}

static uint32_t float_bits(float f) {
  uint32_t u;
  memcpy(&u, &f, sizeof u);
  return u;
}

/* Embree filter for MASK/BLEND geometry (registered on those only): rejects
 * the hit where the surface is cut out or, for BLEND, transparent this time.
 * The user pointer is the accel; the placement is the instance being
 * traversed (context->instID[0]) or, for a flattened mesh, the geometry ID.
 * Ray and hit packets are structures of arrays (Embree's RTCRayN/RTCHitN
 * layout; its accessors are C++ only): org x, y, z at 0, 1, 2 N, dir at
 * 4, 5, 6 N; hit u, v at 3, 4 N, primID at 5 N, geomID at 6 N. Inside an
 * instance the ray is in object space: still a function of the world ray
 * alone, so the BLEND decision stays deterministic. */
static void alpha_filter(const struct RTCFilterFunctionNArguments *args) {
  const iris_accel *a = (const iris_accel *)args->geometryUserPtr;
  const unsigned n = args->N;
  const float *ray = (const float *)args->ray, *hit = (const float *)args->hit;
  const unsigned *hit_u32 = (const unsigned *)args->hit;
  const unsigned inst_id = args->context ? args->context->instID[0] : RTC_INVALID_GEOMETRY_ID;
  for (unsigned i = 0; i < n; i++) {
    if (args->valid[i] != -1) continue;
    unsigned placement = inst_id != RTC_INVALID_GEOMETRY_ID ? inst_id : hit_u32[6 * n + i];
    const accel_instance *ai = &a->instances[placement];
    const iris_material *m = ai->alpha_material;
    if (!m) continue;
    uint32_t prim = hit_u32[5 * n + i];
    float alpha = instance_alpha(a, ai, prim, hit[3 * n + i], hit[4 * n + i]);
    bool keep;
    if (m->alpha_mode == IRIS_ALPHA_MASK) {
      keep = alpha >= m->alpha_cutoff;
    } else if (!(alpha < 1.0f)) {
      keep = true;
    } else {
      /* a uniform number from the ray and the triangle: deterministic per ray */
      uint64_t h = iris_hash4(((uint64_t)float_bits(ray[0 * n + i]) << 32) | float_bits(ray[1 * n + i]),
                              ((uint64_t)float_bits(ray[2 * n + i]) << 32) | float_bits(ray[4 * n + i]),
                              ((uint64_t)float_bits(ray[5 * n + i]) << 32) | float_bits(ray[6 * n + i]),
                              ((uint64_t)ai->first_prim + prim) ^ 0xa1fa0000000000ULL);
      float xi = (float)(h >> 40) * 0x1p-24f;
      keep = xi < alpha;
    }
    if (!keep) args->valid[i] = 0;
  }
}

void iris_accel_set_textures(iris_accel *a, const iris_textures *tex) { a->textures = tex; }

static const char *rtc_error_name(int e) {
  switch (e) {
    case RTC_ERROR_NONE: return "no error";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    default: return "unknown error";
  }
}

/* Embree reported an error (through the callback, or rtcGetDeviceError):
 * one message naming what was being built. */
static bool rtc_failed(iris_accel *a) {
  int none = RTC_ERROR_NONE, e = (int)rtcGetDeviceError(a->device);
  if (e != RTC_ERROR_NONE) atomic_compare_exchange_strong(&a->rtc_error, &none, e);
  return atomic_load(&a->rtc_error) != RTC_ERROR_NONE;
}

static iris_status rtc_error_status(iris_accel *a, iris_error *err) {
  const char *what = a->building[0] ? a->building : "the acceleration structure";
  int code = atomic_load(&a->rtc_error);
  if (code == RTC_ERROR_OUT_OF_MEMORY)
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL,
                          "out of memory building %s (Embree had %.2f GB)", what,
                          (double)atomic_load(&a->embree_bytes) / 1e9);
  return iris_error_set(err, IRIS_ERR_INTERNAL, NULL, 0, NULL, "Embree: %s building %s%s%s",
                        rtc_error_name(code), what, a->rtc_message[0] ? ": " : "",
                        a->rtc_message);
}

/* Gives up a build: destroys what was built and returns why (the user's
 * interrupt, noticed by the progress monitor or between placements, else
 * Embree's error). */
static iris_status abandon_build(iris_accel *a, iris_error *err) {
  iris_status st = iris_cancel_requested() ? iris_cancel_error(err) : rtc_error_status(a, err);
  iris_accel_destroy(a);
  return st;
}

/* Commits an Embree scene; false when the user interrupted the build or Embree
 * failed (the caller then abandons the build). */
static bool commit_scene(iris_accel *a, RTCScene s) {
  rtcCommitScene(s);
  return !iris_cancel_requested() && !rtc_failed(a);
}

static iris_status nomem(iris_accel *a, iris_error *err, const char *what) {
  iris_status st = iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for %s", what);
  iris_accel_destroy(a);
  return st;
}

static const char *mesh_label(const iris_scene *scene, uint32_t mesh, char *buf, size_t size) {
  const iris_mesh *m = &scene->meshes[mesh];
  if (m->name && m->name[0])
    snprintf(buf, size, "mesh %u '%.60s' (%u triangles)", mesh, m->name, m->triangle_count);
  else
    snprintf(buf, size, "mesh %u (%u triangles)", mesh, m->triangle_count);
  return buf;
}

/* Copies `count` vertices into a fresh array with the padding Embree's
 * 16-byte vertex loads need (one float past the end, zeroed). */
static float *padded_positions(const float *src, uint32_t count, size_t *bytes) {
  size_t n = 3 * (size_t)count + 4;
  float *p = malloc(sizeof(float) * n);
  if (!p) return NULL;
  if (src) memcpy(p, src, sizeof(float) * 3 * (size_t)count);
  memset(p + 3 * (size_t)count, 0, 4 * sizeof(float));
  *bytes += sizeof(float) * n;
  return p;
}

static bool has_alpha(const iris_scene *scene, const iris_mesh *mesh) {
  return mesh->material >= 0 && (size_t)mesh->material < scene->material_count &&
         scene->materials[mesh->material].alpha_mode != IRIS_ALPHA_OPAQUE;
}

static RTCGeometry triangle_geometry(iris_accel *a, const iris_mesh *mesh, const float *positions) {
  RTCGeometry g = rtcNewGeometry(a->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  if (!g) return NULL;
  rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, positions, 0,
                             3 * sizeof(float), mesh->vertex_count);
  rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh->indices, 0,
                             3 * sizeof(uint32_t), mesh->triangle_count);
  if (has_alpha(a->scene, mesh)) {
    rtcSetGeometryUserData(g, a);
    rtcSetGeometryIntersectFilterFunction(g, alpha_filter);
    rtcSetGeometryOccludedFilterFunction(g, alpha_filter);
  }
  rtcCommitGeometry(g);
  return g;
}

/* Scene flags and build quality (docs/performance.md, "Instancing" gives the
 * measurements behind them): ROBUST for watertight edges (no light leaks
 * along the shared edges of walls); not COMPACT, which halves the BVH (36
 * instead of 67 bytes per triangle) but cost about 10% of the rays per
 * second; HIGH quality (MEDIUM measured the same size). */
/* Embree calls this during a build: false cancels it (Ctrl-C, core/cancel.h). */
static bool build_progress(void *ptr, double fraction) {
  (void)ptr;
  (void)fraction;
  return !iris_cancel_requested();
}

static void configure_scene(RTCScene s) {
  rtcSetSceneFlags(s, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(s, RTC_BUILD_QUALITY_HIGH);
  rtcSetSceneProgressMonitorFunction(s, build_progress, NULL);
}
/* World-space bounds of each placement (and the world-space copy of each
 * flattened one), over the placements in parallel. */
typedef struct bounds_job {
  iris_accel *a;
  float (*box)[6];
} bounds_job;

/* iris_mat4_point for an affine transform, inline: the same products and
 * sums in the same order (C11 does not contract them), so the same floats. */
static inline iris_vec3 affine_point(const iris_mat4 *a, const float *p) {
  return iris_v3(a->m[0][0] * p[0] + a->m[0][1] * p[1] + a->m[0][2] * p[2] + a->m[0][3],
                 a->m[1][0] * p[0] + a->m[1][1] * p[1] + a->m[1][2] * p[2] + a->m[1][3],
                 a->m[2][0] * p[0] + a->m[2][1] * p[1] + a->m[2][2] * p[2] + a->m[2][3]);
}

static bool is_affine(const iris_mat4 *m) {
  return m->m[3][0] == 0.0f && m->m[3][1] == 0.0f && m->m[3][2] == 0.0f && m->m[3][3] == 1.0f;
}

/* The exact world box of placement i (its vertices through its transform),
 * storing the world-space copy of a flattened one on the way. */
static void exact_box(accel_instance *ai, float b[6]) {
  const iris_mesh *mesh = ai->mesh;
  float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
  const bool affine = is_affine(&ai->xf);
  for (uint32_t v = 0; v < mesh->vertex_count; v++) {
    const float *src = mesh->positions + 3 * (size_t)v;
    iris_vec3 q = affine ? affine_point(&ai->xf, src) : iris_mat4_point(&ai->xf, iris_v3_load(src));
    if (ai->positions) iris_v3_store(q, ai->positions + 3 * (size_t)v);
    /* plain comparisons: fminf is a libm call here */
    lo[0] = q.x < lo[0] ? q.x : lo[0], hi[0] = q.x > hi[0] ? q.x : hi[0];
    lo[1] = q.y < lo[1] ? q.y : lo[1], hi[1] = q.y > hi[1] ? q.y : hi[1];
    lo[2] = q.z < lo[2] ? q.z : lo[2], hi[2] = q.z > hi[2] ? q.z : hi[2];
  }
  b[0] = lo[0], b[1] = lo[1], b[2] = lo[2], b[3] = hi[0], b[4] = hi[1], b[5] = hi[2];
}

/* Flattened placements: the exact box (and the world-space copy). Instanced
 * ones: the 8 transformed corners of the mesh's object box, a box that
 * contains the exact one (refined where it matters by world_bounds). */
static void bounds_body(void *ctx, uint64_t begin, uint64_t end, int thread) {
  (void)thread;
  bounds_job *job = (bounds_job *)ctx;
  for (uint64_t i = begin; i < end; i++) {
    accel_instance *ai = &job->a->instances[i];
    float *b = job->box[i];
    if (ai->positions || ai->mesh->vertex_count == 0) {
      exact_box(ai, b);
      continue;
    }
    const float *ob = job->a->meshes[ai->mesh_index].box;
    b[0] = b[1] = b[2] = FLT_MAX, b[3] = b[4] = b[5] = -FLT_MAX;
    for (int c = 0; c < 8; c++) {
      float p[3] = {ob[c & 1 ? 3 : 0], ob[c & 2 ? 4 : 1], ob[c & 4 ? 5 : 2]};
      iris_vec3 q = affine_point(&ai->xf, p);
      float v[3] = {q.x, q.y, q.z};
      for (int k = 0; k < 3; k++) {
        /* one float step outwards: the corners' rounding must not cut a vertex off */
        b[k] = fminf(b[k], nextafterf(v[k], -INFINITY));
        b[3 + k] = fmaxf(b[3 + k], nextafterf(v[k], INFINITY));
      }
    }
  }
}

typedef struct side_key {
  float value;
  uint32_t index;
} side_key;

static int side_key_cmp(const void *pa, const void *pb) {
  const side_key *x = (const side_key *)pa, *y = (const side_key *)pb;
  if (x->value != y->value) return x->value < y->value ? -1 : 1;
  return x->index < y->index ? -1 : x->index > y->index;
}

/* Exact world bounds without transforming every vertex of every placement:
 * per side of the box, instanced placements in the order of their corner
 * boxes, made exact one by one until no remaining corner box can beat the
 * best exact value (branch and bound; in a forest only the placements along
 * the edges are visited). n log n in the placements. */
static bool world_bounds(iris_accel *a, float (*box)[6], iris_vec3 *out_lo, iris_vec3 *out_hi, bool *out_any) {
  size_t n = a->instance_count, m = 0;
  float best[6] = {FLT_MAX, FLT_MAX, FLT_MAX, -FLT_MAX, -FLT_MAX, -FLT_MAX};
  bool any = false;
  for (size_t i = 0; i < n; i++) {
    if (a->instances[i].mesh->vertex_count == 0) continue;
    any = true;
    if (!a->instances[i].positions) {
      m++;
      continue;
    }
    for (int k = 0; k < 3; k++) {
      best[k] = fminf(best[k], box[i][k]);
      best[3 + k] = fmaxf(best[3 + k], box[i][3 + k]);
    }
  }
  if (m > 0) {
    side_key *keys = malloc(m * sizeof *keys);
    bool *exact = calloc(n, sizeof *exact);
    if (!keys || !exact) {
      free(keys);
      free(exact);
      return false; /* out of memory */
    }
    for (int side = 0; side < 6; side++) {
      const bool low = side < 3;
      size_t j = 0;
      for (size_t i = 0; i < n; i++)
        if (!a->instances[i].positions && a->instances[i].mesh->vertex_count > 0)
          keys[j].value = low ? box[i][side] : -box[i][side], keys[j++].index = (uint32_t)i;
      qsort(keys, m, sizeof *keys, side_key_cmp);
      for (j = 0; j < m; j++) {
        uint32_t i = keys[j].index;
        if (!exact[i] && (low ? box[i][side] >= best[side] : box[i][side] <= best[side])) break;
        if (!exact[i]) {
          exact_box(&a->instances[i], box[i]);
          exact[i] = true;
        }
        best[side] = low ? fminf(best[side], box[i][side]) : fmaxf(best[side], box[i][side]);
      }
    }
    free(keys);
    free(exact);
  }
  *out_lo = iris_v3(best[0], best[1], best[2]);
  *out_hi = iris_v3(best[3], best[4], best[5]);
  *out_any = any;
  return true;
}

iris_status iris_accel_build(const iris_scene *scene, iris_accel **out, iris_error *err) {
  *out = NULL;
  iris_accel *a = calloc(1, sizeof *a);
  if (!a) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for the acceleration structure");
  a->scene = scene;
  atomic_init(&a->embree_bytes, 0);
  atomic_init(&a->rtc_error, RTC_ERROR_NONE);
  a->device = rtcNewDevice("verbose=0");
  if (!a->device) {
    free(a);
    return iris_error_set(err, IRIS_ERR_INTERNAL, NULL, 0, NULL, "Embree: cannot create a device");
  }
  rtcSetDeviceErrorFunction(a->device, error_callback, a);
  rtcSetDeviceMemoryMonitorFunction(a->device, memory_monitor, a);
  a->rtc = rtcNewScene(a->device);
  if (!a->rtc || rtc_failed(a)) return abandon_build(a, err);
  configure_scene(a->rtc);

  a->instance_count = scene->instance_count;
  a->mesh_count = scene->mesh_count;
  a->instances = calloc(scene->instance_count ? scene->instance_count : 1, sizeof *a->instances);
  a->meshes = calloc(scene->mesh_count ? scene->mesh_count : 1, sizeof *a->meshes);
  if (!a->instances || !a->meshes) return nomem(a, err, "the instance table");
  a->own_bytes = sizeof *a + a->instance_count * sizeof *a->instances + a->mesh_count * sizeof *a->meshes;
  /* A mesh is instanced from IRIS_INSTANCE_MIN placements on (default 2;
   * docs/performance.md, "Instancing", measures both ways with it). Embree
   * instances take affine transforms: a projective one (never from the
   * importers) is flattened, counting as a placement of its own. */
  uint32_t instance_min = 2;
  const char *env = getenv("IRIS_INSTANCE_MIN");
  if (env && atol(env) >= 1) instance_min = atol(env) > 1000000000 ? 1000000000u : (uint32_t)atol(env);
  for (size_t i = 0; i < scene->instance_count; i++) {
    const iris_mesh *mesh = &scene->meshes[scene->instances[i].mesh];
    if (mesh->triangle_count > 0 && is_affine(&scene->instances[i].transform))
      a->meshes[scene->instances[i].mesh].placements++;
  }
  uint64_t prims = 0;
  for (size_t i = 0; i < scene->instance_count; i++) {
    const iris_instance *inst = &scene->instances[i];
    const iris_mesh *mesh = &scene->meshes[inst->mesh];
    accel_instance *ai = &a->instances[i];
    if ((i & 255) == 255 && iris_cancel_requested()) return abandon_build(a, err);
    ai->mesh = mesh;
    ai->mesh_index = inst->mesh;
    ai->xf = inst->transform;
    ai->first_prim = (uint32_t)prims;
    prims += mesh->triangle_count;
    if (prims >= UINT32_MAX) {
      iris_accel_destroy(a);
      return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL,
                            "more than 2^32 triangles in the world (over all instances)");
    }
    float det = iris_mat4_det3(&inst->transform);
    ai->mirrored = det < 0.0f;
    ai->tscale = 1.0f / cbrtf(fabsf(det));
    if (!(ai->tscale > 0.0f) || !isfinite(ai->tscale)) ai->tscale = 1.0f;
    iris_mat4 nm = iris_mat4_normal_matrix(&inst->transform);
    for (int r = 0; r < 3; r++)
      for (int c = 0; c < 3; c++) ai->nm[r][c] = nm.m[r][c];
    if (has_alpha(scene, mesh)) ai->alpha_material = &scene->materials[mesh->material];
    if (a->meshes[inst->mesh].placements < instance_min || !is_affine(&inst->transform)) {
      ai->positions = padded_positions(NULL, mesh->vertex_count, &a->own_bytes);
      if (!ai->positions) {
        char label[128];
        snprintf(a->building, sizeof a->building, "the world-space copy of %s",
                 mesh_label(scene, inst->mesh, label, sizeof label));
        return nomem(a, err, a->building);
      }
    }
  }
  a->triangle_count = (uint32_t)prims;

  for (size_t k = 0; k < a->mesh_count; k++) { /* object boxes of the instanced meshes */
    accel_mesh *am = &a->meshes[k];
    const iris_mesh *mesh = &scene->meshes[k];
    if (am->placements < instance_min) continue;
    float *b = am->box;
    b[0] = b[1] = b[2] = FLT_MAX, b[3] = b[4] = b[5] = -FLT_MAX;
    for (uint32_t v = 0; v < mesh->vertex_count; v++)
      for (int c = 0; c < 3; c++) {
        float x = mesh->positions[3 * (size_t)v + c];
        b[c] = x < b[c] ? x : b[c], b[3 + c] = x > b[3 + c] ? x : b[3 + c];
      }
  }
  float(*box)[6] = malloc(sizeof *box * (a->instance_count ? a->instance_count : 1));
  if (!box) return nomem(a, err, "the instance bounds");
  bounds_job job = {a, box};
  iris_parallel_for(a->instance_count, 64, 0, bounds_body, &job);
  iris_vec3 lo, hi;
  bool any_vertex = false, bounds_ok = world_bounds(a, box, &lo, &hi, &any_vertex);
  free(box);
  if (!bounds_ok) return nomem(a, err, "the instance bounds");

  char label[128];
  for (size_t i = 0; i < scene->instance_count; i++) {
    const iris_instance *inst = &scene->instances[i];
    const iris_mesh *mesh = &scene->meshes[inst->mesh];
    accel_instance *ai = &a->instances[i];
    accel_mesh *am = &a->meshes[inst->mesh];
    if (mesh->triangle_count == 0) continue;
    RTCGeometry g;
    if (ai->positions) {
      snprintf(a->building, sizeof a->building, "the BVH of %s",
               mesh_label(scene, inst->mesh, label, sizeof label));
      g = triangle_geometry(a, mesh, ai->positions);
    } else {
      if (!am->rtc) { /* first placement: build the mesh once in object space */
        snprintf(a->building, sizeof a->building, "the BVH of %s",
                 mesh_label(scene, inst->mesh, label, sizeof label));
        am->positions = padded_positions(mesh->positions, mesh->vertex_count, &a->own_bytes);
        if (!am->positions) return nomem(a, err, a->building);
        am->rtc = rtcNewScene(a->device);
        if (!am->rtc || rtc_failed(a)) return abandon_build(a, err);
        configure_scene(am->rtc);
        RTCGeometry mg = triangle_geometry(a, mesh, am->positions);
        if (mg) {
          rtcAttachGeometry(am->rtc, mg);
          rtcReleaseGeometry(mg);
        }
        if (!commit_scene(a, am->rtc)) return abandon_build(a, err);
        a->unique_meshes++;
      }
      snprintf(a->building, sizeof a->building, "instance %zu of %s", i,
               mesh_label(scene, inst->mesh, label, sizeof label));
      g = rtcNewGeometry(a->device, RTC_GEOMETRY_TYPE_INSTANCE);
      if (g) {
        rtcSetGeometryInstancedScene(g, am->rtc);
        /* iris_mat4 is row-major: its first 12 floats are the 3x4 rows */
        rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &ai->xf.m[0][0]);
        rtcCommitGeometry(g);
      }
      a->instanced_placements++;
    }
    if (g) {
      rtcAttachGeometryByID(a->rtc, g, (unsigned)i);
      rtcReleaseGeometry(g);
    }
    if (!g || rtc_failed(a)) return abandon_build(a, err);
  }
  snprintf(a->building, sizeof a->building, "the top-level BVH (%zu placements, %u triangles)",
           a->instance_count, a->triangle_count);
  if (!commit_scene(a, a->rtc)) return abandon_build(a, err);
  a->building[0] = '\0';
  a->has_bounds = prims > 0;
  a->lo = lo;
  a->hi = hi;
  *out = a;
  return IRIS_OK;
}

void iris_accel_destroy(iris_accel *a) {
  if (!a) return;
  if (a->rtc) rtcReleaseScene(a->rtc);
  if (a->meshes)
    for (size_t i = 0; i < a->mesh_count; i++) {
      if (a->meshes[i].rtc) rtcReleaseScene(a->meshes[i].rtc);
      free(a->meshes[i].positions);
    }
  if (a->device) rtcReleaseDevice(a->device);
  if (a->instances)
    for (size_t i = 0; i < a->instance_count; i++) free(a->instances[i].positions);
  free(a->instances);
  free(a->meshes);
  free(a);
}

bool iris_accel_intersect(const iris_accel *a, const iris_ray *ray, iris_hit *hit) {
  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  struct RTCRayHit rh;
  rh.ray.org_x = ray->o.x;
  rh.ray.org_y = ray->o.y;
  rh.ray.org_z = ray->o.z;
  rh.ray.tnear = ray->tmin;
  rh.ray.dir_x = ray->d.x;
  rh.ray.dir_y = ray->d.y;
  rh.ray.dir_z = ray->d.z;
  rh.ray.time = 0.0f;
  rh.ray.tfar = ray->tmax;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(a->rtc, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  unsigned placement = rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID ? rh.hit.instID[0] : rh.hit.geomID;
  hit->t = rh.ray.tfar;
  hit->u = rh.hit.u;
  hit->v = rh.hit.v;
  hit->prim = a->instances[placement].first_prim + rh.hit.primID;
  hit->instance = placement;
  return true;
}

bool iris_accel_occluded(const iris_accel *a, const iris_ray *ray) {
  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  struct RTCRay r;
  r.org_x = ray->o.x;
  r.org_y = ray->o.y;
  r.org_z = ray->o.z;
  r.tnear = ray->tmin;
  r.dir_x = ray->d.x;
  r.dir_y = ray->d.y;
  r.dir_z = ray->d.z;
  r.time = 0.0f;
  r.tfar = ray->tmax;
  r.mask = 0xFFFFFFFFu;
  r.id = 0;
  r.flags = 0;
  rtcOccluded1(a->rtc, &ctx, &r);
  return r.tfar < 0.0f;
}

/* Instance holding global triangle `prim` (binary search over first_prim). */
static size_t instance_of(const iris_accel *a, uint32_t prim) {
  size_t lo = 0, hi = a->instance_count;
  while (hi - lo > 1) {
    size_t mid = (lo + hi) / 2;
    if (a->instances[mid].first_prim <= prim)
      lo = mid;
    else
      hi = mid;
  }
  /* Skip empty meshes that share first_prim with the next instance. */
  while (lo + 1 < a->instance_count && a->instances[lo + 1].first_prim <= prim) lo++;
  return lo;
}

/* World-space vertices of triangle `idx` of a placement: the flattened copy,
 * or the object-space vertices through the same iris_mat4_point. */
static inline void world_vertex(const accel_instance *ai, const uint32_t *idx, iris_vec3 *p0,
                                iris_vec3 *p1, iris_vec3 *p2) {
  if (ai->positions) {
    *p0 = iris_v3_load(ai->positions + 3 * (size_t)idx[0]);
    *p1 = iris_v3_load(ai->positions + 3 * (size_t)idx[1]);
    *p2 = iris_v3_load(ai->positions + 3 * (size_t)idx[2]);
  } else {
    const float *p = ai->mesh->positions; /* instanced placements are affine */
    *p0 = affine_point(&ai->xf, p + 3 * (size_t)idx[0]);
    *p1 = affine_point(&ai->xf, p + 3 * (size_t)idx[1]);
    *p2 = affine_point(&ai->xf, p + 3 * (size_t)idx[2]);
  }
}

static void fill_interaction(const iris_accel *a, size_t inst, uint32_t local, float b1, float b2,
                             iris_interaction *si) {
  const accel_instance *ai = &a->instances[inst];
  const iris_mesh *m = ai->mesh;
  const uint32_t *idx = m->indices + 3 * (size_t)local;
  float b0 = 1.0f - b1 - b2;
  iris_vec3 p0, p1, p2;
  world_vertex(ai, idx, &p0, &p1, &p2);
  si->p = iris_add(iris_add(iris_scale(p0, b0), iris_scale(p1, b1)), iris_scale(p2, b2));
  iris_vec3 ng = iris_normalize(iris_cross(iris_sub(p1, p0), iris_sub(p2, p0)));
  if (ai->mirrored) ng = iris_neg(ng);
  si->ng = ng;
  if (m->normals) {
    const float *n = m->normals;
    iris_vec3 no = iris_add(iris_add(iris_scale(iris_v3_load(n + 3 * (size_t)idx[0]), b0),
                                     iris_scale(iris_v3_load(n + 3 * (size_t)idx[1]), b1)),
                            iris_scale(iris_v3_load(n + 3 * (size_t)idx[2]), b2));
    iris_vec3 nw = iris_v3(ai->nm[0][0] * no.x + ai->nm[0][1] * no.y + ai->nm[0][2] * no.z,
                           ai->nm[1][0] * no.x + ai->nm[1][1] * no.y + ai->nm[1][2] * no.z,
                           ai->nm[2][0] * no.x + ai->nm[2][1] * no.y + ai->nm[2][2] * no.z);
    float len = iris_length(nw);
    bool flipped = false;
    if (len > 0.0f && isfinite(len)) {
      nw = iris_scale(nw, 1.0f / len);
      flipped = iris_dot(nw, ng) < 0.0f;
      if (flipped) nw = iris_neg(nw);
      si->ns = nw;
    } else {
      si->ns = ng;
    }
    si->has_tangent = m->tangents != NULL;
    if (m->tangents) { /* B = w (n x t) in object space, both carried by the transform */
      const float *tg = m->tangents;
      iris_vec3 to = iris_add(iris_add(iris_scale(iris_v3_load(tg + 4 * (size_t)idx[0]), b0),
                                       iris_scale(iris_v3_load(tg + 4 * (size_t)idx[1]), b1)),
                              iris_scale(iris_v3_load(tg + 4 * (size_t)idx[2]), b2));
      iris_vec3 bo = iris_scale(iris_cross(no, to), tg[4 * (size_t)idx[0] + 3]);
      const float(*m3)[4] = ai->xf.m; /* tangents are surface directions: the upper 3x3 */
      iris_vec3 tw = iris_v3(m3[0][0] * to.x + m3[0][1] * to.y + m3[0][2] * to.z,
                             m3[1][0] * to.x + m3[1][1] * to.y + m3[1][2] * to.z,
                             m3[2][0] * to.x + m3[2][1] * to.y + m3[2][2] * to.z);
      iris_vec3 bw = iris_v3(m3[0][0] * bo.x + m3[0][1] * bo.y + m3[0][2] * bo.z,
                             m3[1][0] * bo.x + m3[1][1] * bo.y + m3[1][2] * bo.z,
                             m3[2][0] * bo.x + m3[2][1] * bo.y + m3[2][2] * bo.z);
      float ts = flipped ? -ai->tscale : ai->tscale;
      si->tangent = iris_scale(tw, ts);
      si->bitangent = iris_scale(bw, ts);
    }
  } else {
    si->ns = ng;
    si->has_tangent = false;
  }
  if (m->uvs) {
    const float *t = m->uvs;
    si->uv[0] = b0 * t[2 * idx[0]] + b1 * t[2 * idx[1]] + b2 * t[2 * idx[2]];
    si->uv[1] = b0 * t[2 * idx[0] + 1] + b1 * t[2 * idx[1] + 1] + b2 * t[2 * idx[2] + 1];
  } else {
    si->uv[0] = si->uv[1] = 0.0f;
  }
  if (m->uvs1) {
    const float *t = m->uvs1;
    si->uv1[0] = b0 * t[2 * idx[0]] + b1 * t[2 * idx[1]] + b2 * t[2 * idx[2]];
    si->uv1[1] = b0 * t[2 * idx[0] + 1] + b1 * t[2 * idx[1] + 1] + b2 * t[2 * idx[2] + 1];
  } else {
    si->uv1[0] = si->uv[0], si->uv1[1] = si->uv[1];
  }
  if (m->colors) {
    const float *c = m->colors;
    si->color = iris_add(iris_add(iris_scale(iris_v3_load(c + 3 * (size_t)idx[0]), b0),
                                  iris_scale(iris_v3_load(c + 3 * (size_t)idx[1]), b1)),
                         iris_scale(iris_v3_load(c + 3 * (size_t)idx[2]), b2));
  } else {
    si->color = iris_v3(1.0f, 1.0f, 1.0f);
  }
  si->material = m->material;
  si->prim = ai->first_prim + local;
  si->instance = (uint32_t)inst;
  si->front = true;
}

void iris_accel_interaction(const iris_accel *a, iris_vec3 d, const iris_hit *hit,
                            iris_interaction *si) {
  size_t inst = hit->instance; /* from iris_accel_intersect: no search */
  fill_interaction(a, inst, hit->prim - a->instances[inst].first_prim, hit->u, hit->v, si);
  si->front = iris_dot(d, si->ng) < 0.0f;
}

void iris_accel_surface_at(const iris_accel *a, uint32_t prim, float b1, float b2,
                           iris_interaction *si) {
  size_t inst = instance_of(a, prim);
  fill_interaction(a, inst, prim - a->instances[inst].first_prim, b1, b2, si);
}

float iris_accel_alpha(const iris_accel *a, uint32_t prim, float b1, float b2) {
  size_t inst = instance_of(a, prim);
  const accel_instance *ai = &a->instances[inst];
  if (!ai->alpha_material) return 1.0f;
  return instance_alpha(a, ai, prim - ai->first_prim, b1, b2);
}

uint32_t iris_accel_triangle_count(const iris_accel *a) { return a->triangle_count; }

void iris_accel_triangle(const iris_accel *a, uint32_t prim, iris_vec3 v[3]) {
  size_t inst = instance_of(a, prim);
  const accel_instance *ai = &a->instances[inst];
  const uint32_t *idx = ai->mesh->indices + 3 * (size_t)(prim - ai->first_prim);
  world_vertex(ai, idx, &v[0], &v[1], &v[2]);
  if (ai->mirrored) { /* keep v0, v1, v2 counter-clockwise around the front normal */
    iris_vec3 t = v[1];
    v[1] = v[2];
    v[2] = t;
  }
}

int32_t iris_accel_triangle_material(const iris_accel *a, uint32_t prim) {
  return a->instances[instance_of(a, prim)].mesh->material;
}

bool iris_accel_bounds(const iris_accel *a, iris_vec3 *lo, iris_vec3 *hi) {
  if (!a->has_bounds) return false;
  *lo = a->lo;
  *hi = a->hi;
  return true;
}

size_t iris_accel_memory_bytes(const iris_accel *a) { return a->own_bytes; }
size_t iris_accel_embree_bytes(const iris_accel *a) {
  long long b = atomic_load(&a->embree_bytes);
  return b > 0 ? (size_t)b : 0;
}

size_t iris_accel_instance_count(const iris_accel *a) { return a->instance_count; }

void iris_accel_instance_prims(const iris_accel *a, size_t instance, uint32_t *first, uint32_t *count) {
  *first = a->instances[instance].first_prim;
  *count = a->instances[instance].mesh->triangle_count;
}

int32_t iris_accel_instance_material(const iris_accel *a, size_t instance) {
  return a->instances[instance].mesh->material;
}

void iris_accel_stats(const iris_accel *a, size_t *unique_meshes, size_t *instanced_placements) {
  *unique_meshes = a->unique_meshes;
  *instanced_placements = a->instanced_placements;
}
