/* Portals (docs/guiding.md, "Portals"): indirect light that reaches a cache
 * through an opening in a wall, a door into a lit room. A cache's directional
 * map smears the opening over texels that mostly hold the wall around it, so
 * the guide also draws, with a small fixed probability, points uniformly on a
 * rectangle spanning the opening, found once per cache by probe rays into the
 * cone its indirect photons came from. Exact density for any vertex: the
 * rectangle is a fixed piece of a plane in space, seen from wherever the
 * vertex is. */
#ifndef IRIS_RENDERER_GUIDING_PORTAL_H
#define IRIS_RENDERER_GUIDING_PORTAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/math.h"

#ifdef __cplusplus
extern "C" {
#endif

struct iris_accel;

/* Probability of a portal sample at a diffuse vertex one of whose tied caches
 * has a portal (measured on the door, docs/guiding.md: 0.1-0.2 best). */
#define IRIS_PORTAL_SHARE 0.15f

/* A cache that found no opening itself takes a joined one through which
 * some of its light came, as a candidate: training keeps it where the
 * samples say it lowers their second moment, and without enough samples it
 * is kept only if at least this share of the cache's light came through it
 * (docs/guiding.md, "Portals"). */
#define IRIS_PORTAL_MIN_SHARE 0.05f

/* A rectangle: centre o, orthogonal half-axes u and v (its normal
 * u x v); u = v = 0: none. */
typedef struct iris_portal {
  iris_vec3 o, u, v;
} iris_portal;

static inline bool iris_portal_present(const iris_portal *p) {
  return iris_dot(p->u, p->u) > 0.0f && iris_dot(p->v, p->v) > 0.0f;
}

/* Solid-angle density at x of iris_portal_sample's directions: distance^2 /
 * (area |cos|) where the ray (x, wi) crosses the rectangle, else 0. */
float iris_portal_pdf(const iris_portal *p, iris_vec3 x, iris_vec3 wi);

/* The direction from x to a point uniform on the rectangle (u1, u2 in [0, 1)). */
iris_vec3 iris_portal_sample(const iris_portal *p, iris_vec3 x, float u1, float u2);

/* Whether x sees the rectangle's front at all (at least 1 mm off its plane,
 * on the side the cache that found it lies on, `side`) and its centre is
 * above x's surface (normal n). */
bool iris_portal_faces(const iris_portal *p, iris_vec3 side, iris_vec3 x, iris_vec3 n);

/* Looks for an opening from a cache at c (normal n) into the cone (axis,
 * cos_max) its indirect light came from: IRIS_PORTAL_PROBES probe rays
 * (stratified, jittered by seed) find the wall most of the blocked ones hit
 * and the probes that pass its plane to land beyond it; the rectangle (in the
 * wall's plane) bounding where they pass, widened by half the probes'
 * spacing. None (false) when fewer than 4 probes are blocked by that wall or
 * pass it, when fewer than half of the probes inside the rectangle pass, or
 * when the rectangle is not at most 0.7 of the cone's solid angle seen from c. */
#define IRIS_PORTAL_PROBES 64
/* The light leaving a surface point (p, n facing the probe): the guide's
 * estimate, to tell an opening the light came through from one it leaves by. */
typedef float (*iris_portal_brightness)(void *ctx, iris_vec3 p, iris_vec3 n);
/* ... and the opening must be one the light came through: where the second
 * pass's probes land beyond it, `bright` must average at least
 * IRIS_PORTAL_CONTRAST times what it gives on the wall around it. */
#define IRIS_PORTAL_CONTRAST 2.0f
bool iris_portal_find(const struct iris_accel *accel, iris_vec3 c, iris_vec3 n, iris_vec3 axis, float cos_max,
                      uint64_t seed, iris_portal_brightness bright, void *bright_ctx, iris_portal *out);

/* Joining: caches see parts of one opening, each from its own cone. If b
 * lies in a's plane (normals within ~6 degrees, both turned towards their
 * finders' sides side_a, side_b; offset within 1 mm + 2% of a's size) and
 * overlaps a or comes within a tenth of its size, a becomes the rectangle in
 * a's plane bounding both (true); else a is unchanged (false). */
bool iris_portal_join(iris_portal *a, iris_vec3 side_a, const iris_portal *b, iris_vec3 side_b);

/* Shrinks a joined rectangle to the box of the points, on a regular
 * IRIS_PORTAL_TIGHTEN_GRID^2 grid over it, that some viewer (its finders: a
 * position above its surface, normal viewer_n) reaches in a straight line:
 * the bounds of joined parts are each a probe spacing wide and would reach
 * into the floor or the wall around the opening. False (p unchanged) when
 * no viewer reaches any grid point. */
#define IRIS_PORTAL_TIGHTEN_GRID 24
bool iris_portal_tighten(const struct iris_accel *accel, iris_portal *p, const iris_vec3 *viewer,
                         const iris_vec3 *viewer_n, int viewers);

/* Joins parts found by several finders into wholes: parts[i] (absent: not
 * a part), found from finder_p[i] (normal finder_n[i]), that lie in one plane
 * and overlap are joined serially, in order (deterministic), wholes that grew
 * into each other since are merged, and each whole is tightened to what up
 * to IRIS_PORTAL_VIEWERS of its finders (spread over the order) see through
 * it; one that none sees through is dropped (left absent). whole[] (and
 * side[], the first finder's position: the side it is seen from) get at most
 * `max` (<= 255) wholes; group[i] the whole of part i, 0xff for none (absent,
 * or past `max`). Returns the number of wholes. */
#define IRIS_PORTAL_VIEWERS 4
int iris_portal_join_all(const struct iris_accel *accel, const iris_portal *parts, const iris_vec3 *finder_p,
                         const iris_vec3 *finder_n, size_t n, iris_portal *whole, iris_vec3 *side, int max,
                         uint8_t *group);

/* A cache's density of incident light over world directions. */
typedef float (*iris_portal_density)(void *ctx, iris_vec3 wi);
/* The share of a cache's incident light (density `pdf`) that reaches a cache
 * at c (normal n) through p, by IRIS_PORTAL_PROBES probes to points
 * stratified over p (jittered by seed) that reach its plane unblocked and
 * above the surface; *reach: the fraction of the probes that do. */
float iris_portal_share(const struct iris_accel *accel, const iris_portal *p, iris_vec3 c, iris_vec3 n, uint64_t seed,
                        iris_portal_density pdf, void *pdf_ctx, float *reach);

#ifdef __cplusplus
}
#endif
#endif
