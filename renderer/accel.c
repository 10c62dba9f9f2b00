/* Embree 3 scene with every instance flattened into world space; see accel.h. */
#include "renderer/accel.h"

#include <embree3/rtcore.h>
#include <float.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "core/cancel.h"
#include "core/rng.h"
#include "renderer/texture.h"

typedef struct accel_instance {
  const iris_mesh *mesh;
  float *positions;  /* world space, 3 * vertex_count (+ padding for Embree) */
  float nm[3][3];    /* normal matrix (cofactor form, sign kept for mirrors) */
  float m3[3][3];    /* upper 3x3 of the transform (tangents are surface directions) */
  bool mirrored;     /* det < 0: object-space CCW is world-space CW */
  uint32_t first_prim;
  const iris_material *alpha_material; /* MASK/BLEND material, else NULL (no filter) */
  const struct iris_accel *owner;
} accel_instance;

struct iris_accel {
  const iris_scene *scene;
  RTCDevice device;
  RTCScene rtc;
  accel_instance *instances;
  size_t instance_count;
  uint32_t triangle_count;
  iris_vec3 lo, hi;
  bool has_bounds;
  size_t own_bytes;
  atomic_llong embree_bytes;
  const iris_textures *textures; /* for alpha textures; may be NULL */
};

static bool memory_monitor(void *ptr, ssize_t bytes, bool post) {
  (void)post;
  iris_accel *a = (iris_accel *)ptr;
  atomic_fetch_add(&a->embree_bytes, (long long)bytes);
  return true;
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
 * Ray and hit packets are structures of arrays (Embree's RTCRayN/RTCHitN
 * layout; its accessors are C++ only): org x, y, z at 0, 1, 2 N, dir at
 * 4, 5, 6 N; hit u, v at 3, 4 N, primID at 5 N. */
static void alpha_filter(const struct RTCFilterFunctionNArguments *args) {
  const accel_instance *ai = (const accel_instance *)args->geometryUserPtr;
  const iris_material *m = ai->alpha_material;
  const unsigned n = args->N;
  const float *ray = (const float *)args->ray, *hit = (const float *)args->hit;
  const unsigned *hit_u32 = (const unsigned *)args->hit;
  for (unsigned i = 0; i < n; i++) {
    if (args->valid[i] != -1) continue;
    uint32_t prim = hit_u32[5 * n + i];
    float alpha = instance_alpha(ai->owner, ai, prim, hit[3 * n + i], hit[4 * n + i]);
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

static const char *rtc_error_text(RTCDevice device) {
  switch (rtcGetDeviceError(device)) {
    case RTC_ERROR_NONE: return "no error";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    default: return "unknown error";
  }
}

/* Embree calls this during the build: false cancels it (Ctrl-C, core/cancel.h). */
static bool build_progress(void *ptr, double fraction) {
  (void)ptr;
  (void)fraction;
  return !iris_cancel_requested();
}

iris_status iris_accel_build(const iris_scene *scene, iris_accel **out, iris_error *err) {
  *out = NULL;
  iris_accel *a = calloc(1, sizeof *a);
  if (!a) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory building the BVH");
  a->scene = scene;
  atomic_init(&a->embree_bytes, 0);
  a->device = rtcNewDevice("verbose=0");
  if (!a->device) {
    free(a);
    return iris_error_set(err, IRIS_ERR_INTERNAL, NULL, 0, NULL, "Embree: cannot create a device");
  }
  rtcSetDeviceMemoryMonitorFunction(a->device, memory_monitor, a);
  a->rtc = rtcNewScene(a->device);
  /* ROBUST: watertight edges (no light leaks along the shared edges of walls). */
  rtcSetSceneFlags(a->rtc, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(a->rtc, RTC_BUILD_QUALITY_HIGH);
  rtcSetSceneProgressMonitorFunction(a->rtc, build_progress, NULL);

  a->instance_count = scene->instance_count;
  a->instances = calloc(scene->instance_count ? scene->instance_count : 1, sizeof *a->instances);
  if (!a->instances) {
    iris_accel_destroy(a);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory building the BVH");
  }
  a->own_bytes = sizeof *a + a->instance_count * sizeof *a->instances;
  iris_vec3 lo = iris_v3(FLT_MAX, FLT_MAX, FLT_MAX), hi = iris_v3(-FLT_MAX, -FLT_MAX, -FLT_MAX);
  uint64_t prims = 0;
  for (size_t i = 0; i < scene->instance_count; i++) {
    const iris_instance *inst = &scene->instances[i];
    const iris_mesh *mesh = &scene->meshes[inst->mesh];
    accel_instance *ai = &a->instances[i];
    if ((i & 255) == 255 && iris_cancel_requested()) {
      iris_accel_destroy(a);
      return iris_cancel_error(err);
    }
    ai->mesh = mesh;
    ai->first_prim = (uint32_t)prims;
    prims += mesh->triangle_count;
    if (prims >= UINT32_MAX) {
      iris_accel_destroy(a);
      return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL,
                            "more than 2^32 triangles after flattening instances");
    }
    ai->mirrored = iris_mat4_det3(&inst->transform) < 0.0f;
    iris_mat4 nm = iris_mat4_normal_matrix(&inst->transform);
    for (int r = 0; r < 3; r++)
      for (int c = 0; c < 3; c++) ai->nm[r][c] = nm.m[r][c], ai->m3[r][c] = inst->transform.m[r][c];
    /* Embree reads vertices with 16-byte loads: pad one float past the end. */
    ai->positions = malloc(sizeof(float) * (3 * (size_t)mesh->vertex_count + 4));
    if (!ai->positions) {
      iris_accel_destroy(a);
      return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory building the BVH");
    }
    a->own_bytes += sizeof(float) * (3 * (size_t)mesh->vertex_count + 4);
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
      iris_vec3 p = iris_mat4_point(&inst->transform, iris_v3_load(mesh->positions + 3 * v));
      iris_v3_store(p, ai->positions + 3 * v);
      lo = iris_v3(fminf(lo.x, p.x), fminf(lo.y, p.y), fminf(lo.z, p.z));
      hi = iris_v3(fmaxf(hi.x, p.x), fmaxf(hi.y, p.y), fmaxf(hi.z, p.z));
    }
    memset(ai->positions + 3 * (size_t)mesh->vertex_count, 0, 4 * sizeof(float));
    if (mesh->triangle_count == 0) continue;
    RTCGeometry g = rtcNewGeometry(a->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, ai->positions, 0,
                               3 * sizeof(float), mesh->vertex_count);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh->indices, 0,
                               3 * sizeof(uint32_t), mesh->triangle_count);
    ai->owner = a;
    if (mesh->material >= 0 && (size_t)mesh->material < scene->material_count &&
        scene->materials[mesh->material].alpha_mode != IRIS_ALPHA_OPAQUE) {
      ai->alpha_material = &scene->materials[mesh->material];
      rtcSetGeometryUserData(g, ai);
      rtcSetGeometryIntersectFilterFunction(g, alpha_filter);
      rtcSetGeometryOccludedFilterFunction(g, alpha_filter);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(a->rtc, g, (unsigned)i);
    rtcReleaseGeometry(g);
  }
  a->triangle_count = (uint32_t)prims;
  rtcCommitScene(a->rtc);
  if (iris_cancel_requested()) { /* the progress monitor cancelled the build */
    iris_accel_destroy(a);
    return iris_cancel_error(err);
  }
  if (rtcGetDeviceError(a->device) != RTC_ERROR_NONE) {
    iris_status st = iris_error_set(err, IRIS_ERR_INTERNAL, NULL, 0, NULL, "Embree: %s",
                                    rtc_error_text(a->device));
    iris_accel_destroy(a);
    return st;
  }
  a->has_bounds = prims > 0;
  a->lo = lo;
  a->hi = hi;
  *out = a;
  return IRIS_OK;
}

void iris_accel_destroy(iris_accel *a) {
  if (!a) return;
  if (a->rtc) rtcReleaseScene(a->rtc);
  if (a->device) rtcReleaseDevice(a->device);
  if (a->instances)
    for (size_t i = 0; i < a->instance_count; i++) free(a->instances[i].positions);
  free(a->instances);
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
  hit->t = rh.ray.tfar;
  hit->u = rh.hit.u;
  hit->v = rh.hit.v;
  hit->prim = a->instances[rh.hit.geomID].first_prim + rh.hit.primID;
  hit->instance = rh.hit.geomID;
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

static void fill_interaction(const iris_accel *a, size_t inst, uint32_t local, float b1, float b2,
                             iris_interaction *si) {
  const accel_instance *ai = &a->instances[inst];
  const iris_mesh *m = ai->mesh;
  const uint32_t *idx = m->indices + 3 * (size_t)local;
  float b0 = 1.0f - b1 - b2;
  iris_vec3 p0 = iris_v3_load(ai->positions + 3 * (size_t)idx[0]);
  iris_vec3 p1 = iris_v3_load(ai->positions + 3 * (size_t)idx[1]);
  iris_vec3 p2 = iris_v3_load(ai->positions + 3 * (size_t)idx[2]);
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
      iris_vec3 tw = iris_v3(ai->m3[0][0] * to.x + ai->m3[0][1] * to.y + ai->m3[0][2] * to.z,
                             ai->m3[1][0] * to.x + ai->m3[1][1] * to.y + ai->m3[1][2] * to.z,
                             ai->m3[2][0] * to.x + ai->m3[2][1] * to.y + ai->m3[2][2] * to.z);
      iris_vec3 bw = iris_v3(ai->m3[0][0] * bo.x + ai->m3[0][1] * bo.y + ai->m3[0][2] * bo.z,
                             ai->m3[1][0] * bo.x + ai->m3[1][1] * bo.y + ai->m3[1][2] * bo.z,
                             ai->m3[2][0] * bo.x + ai->m3[2][1] * bo.y + ai->m3[2][2] * bo.z);
      si->tangent = flipped ? iris_neg(tw) : tw;
      si->bitangent = flipped ? iris_neg(bw) : bw;
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
  for (int k = 0; k < 3; k++) v[k] = iris_v3_load(ai->positions + 3 * (size_t)idx[k]);
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
