/* What a render will need in memory, estimated before anything is built, and
 * what the machine has (docs/performance.md, "Memory estimate"): `iris info`
 * prints both, `iris render` logs them and refuses a scene that cannot fit
 * (one line "<scene>: needs about N GB, M GB available", exit 2) instead of
 * failing half-way through a BVH build. The per-item costs are measured
 * (Embree's memory monitor and peak RSS on flattened and instanced scenes). */
#ifndef IRIS_RENDERER_MEMORY_H
#define IRIS_RENDERER_MEMORY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct iris_memory_estimate {
  uint64_t scene;    /* meshes and placements as loaded (already in memory when rendering) */
  uint64_t accel;    /* BVHs, vertex copies, placement tables, the build's peak extra */
  uint64_t textures; /* decoded RGBA8 textures and the environment map */
  uint64_t lights;   /* emissive triangle tables */
  uint64_t guide;    /* photons and caches (guided methods and auto), light_select included */
  uint64_t light_select; /* the caches' learned light tables (--light-sampler learned) */
  uint64_t connect;  /* with a map: the light vertices of connections through a window, at most (part of guide) */
  uint64_t film;     /* film sums and the output images */
  uint64_t base;     /* the process itself (code, libraries, thread stacks) */
  uint64_t total;
  uint64_t unique_triangles, world_triangles, flattened_triangles, instanced_placements;
} iris_memory_estimate;

/* The estimate for rendering `scene` at width x height (<= 0: 640 x 480),
 * with the guide's photons and caches when `guided`. Placements are counted
 * as iris_accel_build will build them (IRIS_INSTANCE_MIN included). */
void iris_memory_estimate_scene(const iris_scene *scene, int width, int height, bool guided,
                                iris_memory_estimate *out);

/* Bytes this process can still allocate: the smaller of /proc/meminfo's
 * MemAvailable and RLIMIT_AS minus the address space in use. `why` names
 * the binding limit ("MemAvailable" or "RLIMIT_AS"). False when neither can
 * be read (then *bytes = UINT64_MAX). */
bool iris_memory_available(uint64_t *bytes, char *why, size_t why_size);

/* IRIS_ERR_NOMEM with "needs about N GB, M GB available (...)" when the
 * estimate's part still to be allocated exceeds what is available; `what`
 * names the scene in the message. */
iris_status iris_memory_check(const iris_memory_estimate *est, const char *what, iris_error *err);

/* One line: "about N GB (BVH ..., textures ..., ...), M GB available". */
void iris_memory_format(const iris_memory_estimate *est, char *buf, size_t size);

#ifdef __cplusplus
}
#endif
#endif
