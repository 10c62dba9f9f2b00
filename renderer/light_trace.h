/* Light tracing of glossy caustics into the camera (docs/rendering.md, "Light
 * tracing off glossy reflectors"). A light path starts at a point y on a
 * glossy reflector (a reflect-only, non-delta BSDF of GGX roughness at most
 * IRIS_LIGHT_TRACE_ROUGHNESS: polished metal, a lacquered plate), drawn by
 * area; takes a light sample there exactly as next-event estimation at y
 * would; reflects it by sampling y's BSDF; and where the reflected ray lands
 * on a point x0 the camera sees, adds its value to x0's pixel (bidirectional
 * path tracing's strategy t = 1 for paths camera -> x0 -> y -> light). The
 * camera path finds the same paths with light sampling or BSDF sampling at y
 * after BSDF sampling at x0; the three are combined by the power heuristic
 * (renderer/integrator.c): a sun's highlight in a metal sphere seen from the
 * ground, which the camera finds only when its bounce at x0 happens to hit
 * the highlight, is the light path's. A second kind carries the sun
 * through clear glass and off mirrors (below). With `mis` only.
 *
 * Deterministic: light path i draws from a hash of (seed, i); each call's
 * paths go in blocks whose splats are added in index order, whatever the
 * threads. With uniform passes the paths of sample indices [s0, s1) are
 * [s0 P, s1 P), P = iris_light_trace_per_index, of the whole frame, so a
 * window or a later range of sample indices traces the same paths as the
 * whole render. */
#ifndef IRIS_RENDERER_LIGHT_TRACE_H
#define IRIS_RENDERER_LIGHT_TRACE_H

#include <stdbool.h>
#include <stdint.h>

#include "core/error.h"
#include "renderer/bsdf.h"
#include "renderer/camera.h"
#include "renderer/film.h"
#include "renderer/integrator.h"
#include "renderer/sampling.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The roughest reflector light paths start from (GGX roughness, as
 * iris_bsdf_guiding_roughness). */
#define IRIS_LIGHT_TRACE_ROUGHNESS 0.3f
/* Light paths per camera sample (of the whole frame, whatever the window). */
#define IRIS_LIGHT_TRACE_PER_SAMPLE 0.25f
/* The pilot: up to this many of the first light paths (4 sample indices'),
 * of which at least this share must reach the camera. */
#define IRIS_LIGHT_TRACE_PILOT 16384u
#define IRIS_LIGHT_TRACE_PILOT_SHARE 0.01

/* The second kind: the sun focused by clear glass or a mirror (delta
 * surfaces) onto what the camera sees. A light path starts at a point y of
 * a delta surface (by area), takes a light sample of the environment map
 * there in a direction where the map's density is at least
 * IRIS_LIGHT_TRACE_SUN times the uniform one (the sun), and follows y's and
 * the next delta surfaces' reflections and refractions (at most
 * IRIS_LIGHT_TRACE_CHAIN of them) to the first other surface x0. These paths
 * (camera -> x0 -> delta surfaces only -> the map in such a direction) are
 * the light paths' alone: the camera leaves them out (a partition, no MIS:
 * the camera cannot aim through glass). */
#define IRIS_LIGHT_TRACE_SUN 16.0f
#define IRIS_LIGHT_TRACE_CHAIN 8
enum { IRIS_LIGHT_TRACE_GLOSSY = 1, IRIS_LIGHT_TRACE_DELTA = 2 }; /* iris_light_trace.member bits */

typedef struct iris_light_trace {
  iris_pinhole cam;
  int x0, y0, x1, y1;   /* the render's window (full-frame pixels) */
  uint8_t *member;      /* per triangle: IRIS_LIGHT_TRACE_GLOSSY / _DELTA where light paths start (the camera asks) */
  uint32_t *tris;       /* the glossy reflectors' triangles, in order */
  iris_distrib1d select; /* a reflector triangle, by area */
  float inv_area;       /* 1 / the reflectors' area: the starting point's density */
  bool glossy, delta;   /* which kinds run (each its pilot) */
  uint32_t *dtris;      /* the delta surfaces' triangles (the second kind) */
  iris_distrib1d dselect;
  float inv_darea;
  float sun_pdf;        /* the map's density from which a direction is the sun's (IRIS_LIGHT_TRACE_SUN / 4 pi) */
  float rho;            /* light paths per sample index: the MIS ratio's count */
  float pixel_area;     /* one pixel's area on the image plane at distance 1 */
  uint64_t per_index;   /* light paths per sample index (rho, whole) */
  uint64_t seed;
  int threads;
  uint64_t next;        /* the next light path's index (adaptive rounds) */
  uint64_t rays;        /* rays the light paths traced */
  uint64_t splats;      /* light paths that added to a pixel */
  uint64_t pilot_paths, pilot_splats[2]; /* the pilot's paths, and those of each kind that reached the camera */
  double energy;        /* what they added, summed over the pixels (mean of R, G, B) */
} iris_light_trace;

/* Light tracing for a render with integrator `it` (method mis), camera `cam`
 * and window [x0, x1) x [y0, y1): *out stays NULL where no surface
 * qualifies, or the scene places instanced meshes (their triangles are not
 * told apart), or the method is not mis, or fewer than
 * IRIS_LIGHT_TRACE_PILOT_SHARE of a pilot's light paths (the first ones, not
 * kept) reach the camera anywhere in the frame. */
iris_status iris_light_trace_create(const iris_integrator *it, const iris_pinhole *cam, int x0, int y0, int x1,
                                    int y1, uint64_t seed, int threads, iris_light_trace **out, iris_error *err);
void iris_light_trace_destroy(iris_light_trace *lt);

/* Traces light paths [first, first + count) and adds what lands in the
 * window to the film's light-path sums (iris_film_light_paths_enable). */
iris_status iris_light_trace_run(iris_light_trace *lt, const iris_integrator *it, uint64_t first, uint64_t count,
                                 iris_film *film, iris_error *err);

/* Where light paths start: a reflect-only glossy BSDF, not a delta (a
 * mirror has no light sample to reflect) and smooth enough that the camera's
 * bounce finds its highlight only by chance; no normal map (folded
 * directions). A property of the material at the point, whatever wo: the
 * light path and the camera ask it of the same point. */
static inline bool iris_light_trace_starts(const iris_shading_point *sp) {
  return !sp->delta && !sp->fold && !(sp->lobes & (IRIS_LOBE_TRANSMISSION | IRIS_LOBE_DIFFUSE)) &&
         (sp->lobes & IRIS_LOBE_GLOSSY) && iris_bsdf_guiding_roughness(&sp->bsdf) <= IRIS_LIGHT_TRACE_ROUGHNESS;
}

/* The camera's density, per unit area, of first hits at p (geometric normal
 * ng) for a sample of p's pixel: 0 behind the camera. */
static inline float iris_light_trace_camera_density(const iris_light_trace *lt, iris_vec3 p, iris_vec3 ng) {
  const iris_vec3 v = iris_sub(p, lt->cam.origin);
  const float d2 = iris_dot(v, v);
  if (!(d2 > 0.0f)) return 0.0f;
  const iris_vec3 dir = iris_scale(v, 1.0f / sqrtf(d2));
  const float c = iris_dot(dir, lt->cam.forward);
  if (!(c > 0.0f)) return 0.0f;
  return fabsf(iris_dot(ng, dir)) / (lt->pixel_area * c * c * c * d2);
}

#ifdef __cplusplus
}
#endif
#endif
