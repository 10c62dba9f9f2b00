/* Connections to a light-vertex cache (docs/guiding.md, "Connections to a
 * light-vertex cache"): light that reaches the camera's side of an opening
 * after bouncing beyond it, carried by light paths instead of camera paths.
 *
 * Two regions are the sides of a plane (the opening's, from the guide's
 * portals): A, where the caches that keep the portal lie, and B. For every
 * image sample index s, `paths` light paths leave the emissive triangles (as
 * photons do), walk region B through plain surfaces (Lambertian reflectors
 * with flat shading, where cosine sampling is the adjoint's) with roulette, and
 * the pool of s keeps the plain vertex z where each enters region A after at
 * least one vertex in B. A camera vertex x whose path so far lies in A
 * connects to one z of its sample index's pool, drawn uniformly, when |x - z|
 * exceeds a minimum distance. The paths so made,
 *   camera, x_1 .. x_{k-1} in A (k >= 2), z = x_k in A and plain, then only
 *   plain vertices in B up to an emissive triangle, |x_{k-1} - x_k| > d_min,
 *   within the maximum depth,
 * are left out of the camera estimator (its light samples of triangles and
 * the triangles its rays hit): a partition of path space, each path made by
 * exactly one strategy, so no MIS weight is needed and the sum is unbiased for
 * any plane. Pools are functions of (seed, s) alone: the image does not depend
 * on the thread count or on how the samples are partitioned.
 *
 * The sky through a window (`sky`): region B is the outside and the light
 * the environment map seen through the window (a rectangle, sky visibility's,
 * skyvis.h). Light paths leave a point uniform on it in a direction from the
 * map's own sampling, seen through it, and keep the first vertex z they hit
 * inside (m = 0), if plain. A camera vertex connects to one z as above, at
 * any distance; the paths so made,
 *   camera, x_1 .. x_{k-1} in A (k >= 2, x_{k-1} not delta and left along a
 *   lobe that is not), z = x_k plain, then the map's light through a window,
 * the camera makes too: at such an x_k its light samples of the map whose
 * direction leaves through a window and its escapes through one. The two
 * share them by MIS (iris_vcache_sky_weight below): a short connection's
 * 1/d^2 goes to the camera, a long one's light mostly to the connections.
 * The camera goes on from x_k as before (its further bounces are its own). A
 * connection whose weighted unoccluded value is small against the pixel's
 * estimate is traced only with probability value / (IRIS_VCACHE_SKY_RR x
 * estimate), and a camera light sample whose share is below
 * IRIS_VCACHE_SKY_KEEP with probability share / IRIS_VCACHE_SKY_KEEP, each
 * weighted back. */
#ifndef IRIS_RENDERER_VCACHE_H
#define IRIS_RENDERER_VCACHE_H

#include <stdbool.h>
#include <stdint.h>

#include "core/error.h"
#include "core/math.h"

#ifdef __cplusplus
extern "C" {
#endif

struct iris_integrator;
struct iris_shading_point;

/* A stored vertex z: its position, its geometric normal on the side the
 * light arrived from, the light's throughput there times z's BSDF (f power),
 * the number m of region-B vertices before it, and with the sky the light
 * path's density's factor for the MIS weight (iris_vcache_sky_factor). */
typedef struct iris_vcache_vertex {
  iris_vec3 p, n, f_power;
  int32_t m;
  float mis;
} iris_vcache_vertex;

typedef struct iris_vcache_pool {
  uint32_t count;
  iris_vcache_vertex *v;
} iris_vcache_pool;

/* The connections' roulette against the pixel's estimate with the sky
 * (measured on sky-room: 0.5 best of 0.5, 1 and 2, docs/guiding.md). */
#define IRIS_VCACHE_SKY_RR 0.5f
/* With the sky nearly every light path keeps a vertex (44 bytes), and pools
 * are kept for the whole render: only the sample indices below this budget
 * over paths x 44 bytes have pools (about 1560 at 108 x 72, 730 at 1920 x
 * 1080); later ones neither connect nor share anything (unbiased). */
#define IRIS_VCACHE_SKY_BUDGET (64u << 20)

/* With the sky: the camera's light sample of the map through a window whose
 * MIS share is below this is traced with probability share / this, weighted
 * back (sky-room and the corner, 64 spp: 0.1, 0.25 and 0.5 the same error per
 * sample, 0.5 the fewest rays; without it 9% more rays per sample). */
#define IRIS_VCACHE_SKY_KEEP 0.5f
/* ... and where its share toward every window's centre is below that, it
 * samples the map at all only with probability share / IRIS_VCACHE_SKY_KEEP,
 * at least this (iris_vcache_sky_keep_centres; the density counts it; 0.1
 * with 0.5 above: 1.13-1.14x at equal time on sky-room and the corner, 0.05
 * with 1 the same per unit of work, docs/guiding.md). */
#define IRIS_VCACHE_SKY_MAP_MIN 0.1f

/* With the sky: at most this many windows (sky visibility's, render.c). */
#define IRIS_VCACHE_SKY_WINDOWS 4

/* A window of the sky: centre o, outward unit normal n, half-axes u and v,
 * its area (4 |u x v|) and the probability that a light path starts on it. */
typedef struct iris_vcache_window {
  iris_vec3 o, n, u, v;
  float area, prob;
} iris_vcache_window;

typedef struct iris_vcache_params {
  iris_vec3 o, n;   /* without the sky, the opening's plane: region A is its negative side */
  bool sky;         /* the sky through windows: region A the negative side of every one's plane */
  int windows;
  iris_vcache_window window[IRIS_VCACHE_SKY_WINDOWS];
  float eps;        /* a point within eps of the plane belongs to the side it is seen from */
  float min_d2;     /* without the sky, the shortest connection, squared */
  float mis_c;      /* with the sky, the MIS weight's constant (iris_vcache_sky_weight) */
  float map_q;      /* with the sky, > 0: the camera's probability of sampling the map where it
                       shares it (iris_render_params.connect_sky_map_q), instead of by its share */
  uint32_t paths;   /* light paths per sample index */
  uint64_t seed;
  int threads;
} iris_vcache_params;

typedef struct iris_vcache iris_vcache;

/* The integrator must outlive the cache (its lights, accel and shading). */
iris_status iris_vcache_create(iris_vcache **out, const iris_vcache_params *p, const struct iris_integrator *it,
                               iris_error *err);
void iris_vcache_destroy(iris_vcache *vc);
/* The pool of sample index s, built on first use (with the next 31 indices,
 * in parallel; thread-safe). NULL where s is past the cache's reach or memory
 * ran out: then the path neither connects nor shares anything. */
const iris_vcache_pool *iris_vcache_get(iris_vcache *vc, uint64_t s);
const iris_vcache_params *iris_vcache_settings(const iris_vcache *vc);
/* Rays the light paths traced so far. */
uint64_t iris_vcache_rays(const iris_vcache *vc);

static inline bool iris_vcache_in_half_(iris_vec3 o, iris_vec3 n, float eps, iris_vec3 x, iris_vec3 wo) {
  float d = iris_dot(iris_sub(x, o), n);
  return d < -eps || (d <= eps && iris_dot(wo, n) < 0.0f);
}
/* Whether x, reached along a ray whose reverse is wo, lies in region A. */
static inline bool iris_vcache_in_a(const iris_vcache_params *p, iris_vec3 x, iris_vec3 wo) {
  if (!p->sky) return iris_vcache_in_half_(p->o, p->n, p->eps, x, wo);
  for (int j = 0; j < p->windows; ++j)
    if (!iris_vcache_in_half_(p->window[j].o, p->window[j].n, p->eps, x, wo)) return false;
  return true;
}
/* Whether the ray from x along w leaves through the rectangle (o, n, u, v),
 * and where (*t, along w). */
static inline bool iris_vcache_through_one_(iris_vec3 o, iris_vec3 n, iris_vec3 u, iris_vec3 v, iris_vec3 x,
                                            iris_vec3 w, float *t_out) {
  const float dn = iris_dot(w, n);
  if (!(dn > 0.0f)) return false;
  const float t = iris_dot(iris_sub(o, x), n) / dn;
  if (!(t > 0.0f)) return false;
  const iris_vec3 q = iris_sub(iris_madd(x, w, t), o);
  *t_out = t;
  return fabsf(iris_dot(q, u)) <= iris_dot(u, u) && fabsf(iris_dot(q, v)) <= iris_dot(v, v);
}
/* With the sky, connections and the camera share the map's light at a
 * plain vertex z = x_k through MIS (docs/guiding.md, "Connections with the
 * sky through a window"). A light path makes (z, w), w the direction to the
 * sky, with density P_j |w.n_z| p_map(w) / (A_j (w.n_j)) over z's area and
 * w's solid angle (j the first window crossed from z along w, n_j its
 * outward normal, P_j its probability, A_j its area); the camera reaches z
 * from x_{k-1} with density p_dir |cos_in| / d^2 over z's area, and its
 * density of w at z stands in as mis_c p_map(w), so that the ratio of the
 * two is
 *   rho = factor d^2 / (p_dir |cos_in|),  factor = P_j |w.n_z| / (A_j (w.n_j))
 * and the connection's weight is rho^2 / (rho^2 + mis_c^2) (the power
 * heuristic), the camera's one minus that. Any weights that sum to one are
 * unbiased; the stand-in only decides how well the two share. The factor,
 * 0 where w leaves through no window: */
static inline float iris_vcache_sky_factor(const iris_vcache_params *p, iris_vec3 z, iris_vec3 w, iris_vec3 ng) {
  float best = INFINITY, factor = 0.0f, t;
  for (int j = 0; j < p->windows; ++j) {
    const iris_vcache_window *q = &p->window[j];
    if (iris_vcache_through_one_(q->o, q->n, q->u, q->v, z, w, &t) && t < best) {
      best = t;
      factor = q->prob * fabsf(iris_dot(w, ng)) / (q->area * iris_dot(w, q->n));
    }
  }
  return factor;
}
static inline float iris_vcache_sky_weight(const iris_vcache_params *p, float rho) {
  const float a = rho * rho;
  if (!(a < INFINITY)) return 1.0f; /* rho infinite (the camera cannot make the path), past range, or NaN */
  return a / (a + p->mis_c * p->mis_c);
}
/* With the sky: the camera's share of the map's light arriving at z
 * (geometric normal ng) from w, for the ratio's camera part g (1 where w
 * leaves through no window). */
static inline float iris_vcache_sky_keep(const iris_vcache_params *p, iris_vec3 z, iris_vec3 w, iris_vec3 ng, float g) {
  const float factor = iris_vcache_sky_factor(p, z, w, ng);
  return factor > 0.0f ? 1.0f - iris_vcache_sky_weight(p, factor * g) : 1.0f;
}
/* With the sky: the camera's largest share at z (geometric normal ng) over
 * the directions to the windows' centres that leave through them, for the
 * ratio's camera part g (0 where no window's outside faces z). */
static inline float iris_vcache_sky_keep_centres(const iris_vcache_params *p, iris_vec3 z, iris_vec3 ng, float g) {
  float keep = 0.0f;
  for (int j = 0; j < p->windows; ++j) {
    const iris_vcache_window *q = &p->window[j];
    const iris_vec3 d = iris_sub(q->o, z);
    const float dn = iris_dot(d, q->n);
    if (!(dn > 0.0f)) continue;
    const float factor = q->prob * fabsf(iris_dot(d, ng)) / (q->area * dn);
    keep = iris_fmaxf(keep, 1.0f - iris_vcache_sky_weight(p, factor * g));
  }
  return keep;
}
/* A plain vertex: a Lambertian reflector (no other lobe) with flat shading. */
bool iris_vcache_plain(const struct iris_shading_point *sp, iris_vec3 ng);

#ifdef __cplusplus
}
#endif
#endif
