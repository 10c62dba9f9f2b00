/* Glints (docs/guiding.md, "Glints"): the sun seen in a near-mirror sphere
 * from the ground, a lamp in a chrome fitting seen from a wall. Such light
 * reaches a rough surface off a smooth reflector (a mirror, metal of
 * roughness <= IRIS_GLINT_ROUGHNESS) from a spot far smaller than a cache's
 * texel, and the spot moves across the smooth surface as the receiving point
 * moves, so no per-cache map holds it. Glint photons are aimed at the points
 * where the guide's photons met smooth surfaces, follow the smooth vertices
 * and are kept where they land on a rough surface, with the smooth point they
 * left. At a path vertex the nearest of them say where its glints leave the
 * smooth surface: a small sphere (the spot), whose cone the guide samples
 * as a lamp's (lamps.h). The spot is a function of the vertex's position and
 * normal alone, so the sampler and the MIS density agree exactly; it needs
 * not be right to be unbiased, only to be small where it is right. */
#ifndef IRIS_RENDERER_GUIDING_GLINTS_H
#define IRIS_RENDERER_GUIDING_GLINTS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "renderer/guiding/kdtree.h"
#include "renderer/guiding/lamps.h"
#include "renderer/guiding/photons.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Of the guide's share at a vertex with a glint spot, the probability of the
 * spot's cone: the share of the cache's indirect photon energy that left a
 * smooth reflector last, at most the maximum; none below the minimum
 * (measured: docs/guiding.md, "Glints"). */
#define IRIS_GLINT_SHARE_MIN 0.1f
#define IRIS_GLINT_SHARE_MAX 0.5f
/* Glint photons a vertex looks at, and how many it needs for a spot. */
#define IRIS_GLINT_K 8
#define IRIS_GLINT_MIN 2

/* One glint photon (40 bytes). */
typedef struct iris_glint_photon {
  iris_vec3 p;   /* where it landed on a rough surface */
  iris_vec3 n;   /* the shading normal there, on the side it arrived from */
  iris_vec3 y;   /* the last smooth vertex it left */
  float energy;  /* mean of its RGB throughput x the light's radiance / pdf (relative weights only) */
} iris_glint_photon;

typedef struct iris_glints {
  iris_glint_photon *photons;
  uint32_t count;
  iris_kdtree tree;  /* over photons[i].p */
  float radius2;     /* a vertex looks this far (squared): the caches' spacing */
  uint64_t paths;    /* glint photon paths traced */
} iris_glints;

/* Traces `paths` glint photon paths aimed at map->smooth (nothing when it is
 * empty), keeps those that land on a rough surface after smooth reflections
 * only (iris_photon_smooth) and builds their tree. Deterministic for any thread count
 * (path i draws from a hash of (seed, i)). out->radius2 is left 0 (the
 * caller sets it once the caches' spacing is known). */
iris_status iris_glints_trace(const iris_guide_setup *setup, const iris_photon_map *map, uint64_t paths,
                              iris_glints *out, iris_error *err);
/* Builds the tree over out->photons[0..count) (after iris_glints_trace, or
 * after reading them from a guide file). */
iris_status iris_glints_index(iris_glints *gl, int threads, iris_error *err);
void iris_glints_destroy(iris_glints *gl);
/* Bytes of `count` glint photons with their tree. */
size_t iris_glints_bytes(size_t count);

/* The glint spot seen from (x, n): the nearest IRIS_GLINT_K glint photons
 * within radius2 on a surface facing like n (cos >= 0.9) that left a smooth
 * point above n; those that left the same part of the smooth surface as the
 * nearest one; a sphere around their energy-weighted centre holding every
 * one's point plus half its distance to x (a glint seen from x leaves the
 * surface about that much nearer: half on a flat mirror, less on a convex
 * one). False (no spot) when fewer than IRIS_GLINT_MIN are found or x lies
 * inside the sphere. */
bool iris_glints_spot(const iris_glints *gl, iris_vec3 x, iris_vec3 n, iris_guide_lamp *spot);

#ifdef __cplusplus
}
#endif
#endif
