/* Ray casting over the whole scene through Embree 3, two-level: a mesh placed
 * once is flattened into world-space triangles, a mesh placed two or more
 * times is built once in object space and placed by Embree instances
 * (docs/rendering.md, "Instancing"). A hit becomes a surface interaction:
 * position, geometric and shading normals, uv, vertex colour and material,
 * the same numbers whichever way its mesh was built. Triangles are numbered
 * globally over all placements in instance order (prim = the placement's
 * first prim + the mesh's triangle index), so lights, photons and caches see
 * every placement as its own geometry. */
#ifndef IRIS_RENDERER_ACCEL_H
#define IRIS_RENDERER_ACCEL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "core/math.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* d need not be unit length; t is measured in units of |d|. */
typedef struct iris_ray {
  iris_vec3 o;
  float tmin;
  iris_vec3 d;
  float tmax;
} iris_ray;

/* A hit: distance, barycentrics of vertices 1 and 2, the global triangle
 * index (over all instances, in instance order) and the scene instance. */
typedef struct iris_hit {
  float t, u, v;
  uint32_t prim;
  uint32_t instance;
} iris_hit;

/* What the renderer needs to know about a surface point. */
typedef struct iris_interaction {
  iris_vec3 p;       /* world position (from barycentrics, not o + t d) */
  iris_vec3 ng;      /* unit geometric normal of the front (counter-clockwise) face */
  iris_vec3 ns;      /* unit shading normal, flipped onto ng's side */
  float uv[2];       /* (0, 0) when the mesh has none */
  float uv1[2];      /* second uv set; = uv when the mesh has none */
  iris_vec3 color;   /* vertex colour; (1, 1, 1) when the mesh has none */
  int32_t material;  /* index into scene->materials, -1 = default */
  uint32_t prim;     /* global triangle index */
  uint32_t instance; /* scene instance */
  bool front;        /* the ray arrived on the front side (dot(d, ng) < 0) */
  bool has_tangent;  /* the mesh has tangents: the two vectors below are set */
  iris_vec3 tangent, bitangent; /* world-space normal-map frame (T, B = w N x T transformed,
                                   divided by the cube root of the placement's |det| so a
                                   uniform scale leaves their length), interpolated, not
                                   normalised; flipped with ns */
} iris_interaction;

typedef struct iris_accel iris_accel;

/* Builds the Embree scenes (world-space copies of the vertices of meshes
 * placed once, object-space copies of the others; index buffers are shared
 * with the scene, which must outlive the accel). An Embree failure ends in one
 * message naming what was being built (IRIS_ERR_NOMEM when out of memory). */
iris_status iris_accel_build(const iris_scene *scene, iris_accel **out, iris_error *err);
void iris_accel_destroy(iris_accel *accel);

/* Textures for the coverage (alpha) of MASK/BLEND materials' colour textures;
 * until set (or with NULL) only their alpha factor and vertex alpha count.
 * `tex` must outlive the accel's use. */
struct iris_textures;
void iris_accel_set_textures(iris_accel *accel, const struct iris_textures *tex);
/* The coverage alpha of a hit on triangle `prim` at barycentrics (b1, b2):
 * material alpha x vertex alpha x colour texture alpha (1 for opaque materials). */
float iris_accel_alpha(const iris_accel *accel, uint32_t prim, float b1, float b2);

/* Closest hit in (tmin, tmax); false on a miss. Surfaces of MASK materials
 * are skipped where alpha < cutoff, surfaces of BLEND materials with
 * probability 1 - alpha, decided by a hash of the ray and the triangle (so the
 * same ray always gets the same answer, whatever thread casts it);
 * docs/rendering.md, "Alpha". Opaque geometry has no filter and pays nothing. */
bool iris_accel_intersect(const iris_accel *accel, const iris_ray *ray, iris_hit *hit);
/* Any hit in (tmin, tmax). */
bool iris_accel_occluded(const iris_accel *accel, const iris_ray *ray);

/* The surface interaction of a hit made by iris_accel_intersect; `d` is the
 * direction of the ray that hit. */
void iris_accel_interaction(const iris_accel *accel, iris_vec3 d, const iris_hit *hit,
                            iris_interaction *si);
/* The interaction at barycentrics (b1, b2) of triangle `prim`, as seen from
 * the front (used by light sampling). */
void iris_accel_surface_at(const iris_accel *accel, uint32_t prim, float b1, float b2,
                           iris_interaction *si);

/* Ray origin that cannot re-hit the surface of `p`: p pushed a few ulps along
 * the geometric normal towards the side `w` leaves on (Waechter & Binder,
 * Ray Tracing Gems ch. 6), so the error is relative to the magnitude of p.
 * These three are inline: they run for every ray, and returning a ray through
 * memory from another translation unit cost a store-forwarding stall each. */
static inline float iris_offset_component_(float p, float n) {
  const float origin = 1.0f / 32.0f, float_scale = 1.0f / 65536.0f, int_scale = 256.0f;
  if (fabsf(p) < origin) return p + float_scale * n;
  int32_t of = (int32_t)(int_scale * n);
  union {
    float f;
    int32_t i;
  } bits;
  bits.f = p;
  bits.i += p < 0.0f ? -of : of;
  return bits.f;
}
static inline iris_vec3 iris_offset_origin(iris_vec3 p, iris_vec3 ng, iris_vec3 w) {
  iris_vec3 n = iris_dot(w, ng) < 0.0f ? iris_neg(ng) : ng;
  return iris_v3(iris_offset_component_(p.x, n.x), iris_offset_component_(p.y, n.y),
                 iris_offset_component_(p.z, n.z));
}
/* Ray from a surface point leaving along w (unit). */
static inline iris_ray iris_spawn_ray(const iris_interaction *si, iris_vec3 w) {
  iris_ray r;
  r.o = iris_offset_origin(si->p, si->ng, w);
  r.d = w;
  r.tmin = 0.0f;
  r.tmax = INFINITY;
  return r;
}
/* Shadow ray between two surface points, each offset along its normal
 * towards the other; the ray ends at t = 1 just before the target. */
static inline iris_ray iris_spawn_ray_to(iris_vec3 p, iris_vec3 ng, iris_vec3 target,
                                         iris_vec3 target_ng) {
  iris_vec3 o = iris_offset_origin(p, ng, iris_sub(target, p));
  iris_vec3 t = iris_offset_origin(target, target_ng, iris_sub(p, target));
  iris_ray r;
  r.o = o;
  r.d = iris_sub(t, o);
  r.tmin = 0.0f;
  r.tmax = 1.0f - 1e-5f;
  return r;
}

/* Scene facts the lights and the camera need. */
uint32_t iris_accel_triangle_count(const iris_accel *accel);
/* World-space vertices of a triangle. */
void iris_accel_triangle(const iris_accel *accel, uint32_t prim, iris_vec3 v[3]);
int32_t iris_accel_triangle_material(const iris_accel *accel, uint32_t prim);
/* World bounds of all triangles (false when there are none). */
bool iris_accel_bounds(const iris_accel *accel, iris_vec3 *lo, iris_vec3 *hi);
/* Bytes held by iris (vertex copies, tables); Embree's BVH is reported by
 * iris_accel_embree_bytes (from Embree's memory monitor). */
size_t iris_accel_memory_bytes(const iris_accel *accel);
size_t iris_accel_embree_bytes(const iris_accel *accel);

/* Placements (= scene instances): the global triangle range [first, first +
 * count) of placement `instance` and its mesh's material. Enumerating
 * emissive geometry per placement costs the number of placements, not of
 * world triangles. */
size_t iris_accel_instance_count(const iris_accel *accel);
void iris_accel_instance_prims(const iris_accel *accel, size_t instance, uint32_t *first,
                               uint32_t *count);
int32_t iris_accel_instance_material(const iris_accel *accel, size_t instance);
/* Meshes built once for instancing, and placements made by Embree instances
 * (the others are flattened). */
void iris_accel_stats(const iris_accel *accel, size_t *unique_meshes, size_t *instanced_placements);

#ifdef __cplusplus
}
#endif
#endif
