/* Unidirectional path tracing with three estimators of direct light
 * (--method bsdf | nee | mis) and room for the guided ones. The path loop
 * chooses every next direction through ONE function,
 * iris_integrator_sample_direction, and MIS with light sampling asks ONE
 * function, iris_integrator_direction_pdf, how likely the path's direction
 * sampler was to produce a given direction. Guiding plugs in there through an
 * iris_direction_sampler (a small table of function pointers), nowhere else.
 * Formulas, Russian roulette and the bounce convention: docs/rendering.md. */
#ifndef IRIS_RENDERER_INTEGRATOR_H
#define IRIS_RENDERER_INTEGRATOR_H

#include <stdbool.h>
#include <stdint.h>

#include "core/math.h"
#include "core/rng.h"
#include "renderer/accel.h"
#include "renderer/bsdf.h"
#include "renderer/lights.h"
#include "renderer/texture.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum iris_method {
  IRIS_METHOD_BSDF = 0,   /* BSDF sampling only; emitters count when hit */
  IRIS_METHOD_NEE,        /* light sampling for direct light; hits count only from the
                             camera and after delta bounces */
  IRIS_METHOD_MIS,        /* both, power heuristic */
  IRIS_METHOD_GUIDED,     /* guided direction sampling, emitters count when hit */
  IRIS_METHOD_GUIDED_NEE, /* guided direction sampling + light sampling with MIS */
  IRIS_METHOD_AUTO,       /* guided-nee or mis, chosen per scene by iris_render before any
                             path is traced (docs/guiding.md, "--method auto"); the default.
                             The integrator never sees it. */
  IRIS_METHOD_COUNT       /* iris_render_params: unset */
} iris_method;

/* "bsdf", "nee", "mis", "guided", "guided-nee", "auto". */
const char *iris_method_name(iris_method method);
/* False when `name` is not a method name. */
bool iris_method_parse(const char *name, iris_method *out);
/* Whether a method samples lights explicitly / samples directions with a guide. */
bool iris_method_uses_nee(iris_method method);
bool iris_method_uses_guiding(iris_method method);

/* Dimension layout of a path (docs/rendering.md, "Dimension layout"): the
 * sampler pairs dimensions (2k, 2k+1), so every 2D decision starts at an even
 * dimension and gets a well-stratified pair; each 1D decision gets the first
 * dimension of a pair of its own (cheaper with the sobol sampler, and no
 * decision shares a pair). Dimensions 0-1 are the position in the pixel;
 * bounce b (0 at the first hit) draws dimension
 * IRIS_DIM_BOUNCE0 + b * IRIS_DIMS_PER_BOUNCE + slot, the slots below. */
enum {
  IRIS_DIM_PIXEL = 0,          /* 2D: position in the pixel */
  IRIS_DIM_BOUNCE0 = 2,
  IRIS_SLOT_LIGHT_CHOICE = 0,  /* NEE: which light */
  IRIS_SLOT_SKY_SHARE = 1,     /* NEE of the map through a window: whether a small MIS share of it
                                  (vcache.h) is traced (the light choice's pair) */
  IRIS_SLOT_LOBE = 2,          /* BSDF: which lobe */
  IRIS_SLOT_LIGHT_SKIP = 3,    /* light sampling at a vertex where the guide makes it optional
                                  (the lobe's pair: two independent 1D decisions) */
  IRIS_SLOT_LIGHT_POS = 4,     /* 2D: NEE point on the light */
  IRIS_SLOT_DIRECTION = 6,     /* 2D: BSDF direction, or the position in the guide's texel */
  IRIS_SLOT_RR = 8,            /* Russian roulette */
  IRIS_SLOT_CONNECT = 9,       /* connections (vcache.h): which pool vertex, or whether the path goes on
                                  (the roulette's pair: two independent 1D decisions) */
  IRIS_SLOT_GUIDE_SELECT = 10, /* guided: BSDF or cache */
  IRIS_SLOT_GUIDE_CACHE = 12,  /* 2D: guided: which of the tied caches, and the texel (alias table) */
  IRIS_SLOT_GUIDE_TEXEL = 13,
  IRIS_DIMS_PER_BOUNCE = 14
};
/* Positions the sampler's base at bounce `bounce` of the layout. */
static inline void iris_sampler_set_bounce(iris_sampler *rng, int bounce) {
  rng->dimension = IRIS_DIM_BOUNCE0 + (uint32_t)bounce * IRIS_DIMS_PER_BOUNCE;
}

/* Per-vertex scratch of a direction sampler: written once per shading point
 * by iris_direction_sampler.prepare, read by its sample and pdf at that
 * vertex (guiding keeps the caches it picked for the point here, so the
 * cache search runs once per bounce, not once per sample/pdf call). */
#define IRIS_GUIDE_VERTEX_BYTES 96
typedef struct iris_guide_vertex {
  _Alignas(16) unsigned char bytes[IRIS_GUIDE_VERTEX_BYTES];
} iris_guide_vertex;

/* A shading point: the interaction, its shading frame (z = shading normal,
 * turned towards wo for non-transmissive BSDFs), the BSDF, wo in both frames. */
typedef struct iris_shading_point {
  iris_interaction si;
  iris_frame frame;
  iris_bsdf bsdf;
  iris_vec3 wo;       /* world, unit, towards the previous vertex */
  iris_vec3 wo_local;
  uint32_t lobes;     /* iris_bsdf_lobes */
  bool delta;         /* iris_bsdf_is_delta */
  int depth;          /* bounces so far (0 at the first hit from the camera) */
  bool fold;          /* a normal map bent a reflect-only BSDF: directions below the
                         geometric surface fold back above it (docs/rendering.md,
                         "Normal maps"); set by iris_integrator_shade */
  iris_guide_vertex guide; /* direction sampler's per-vertex state (after prepare) */
} iris_shading_point;

/* A direction chosen by the path's direction sampler. */
typedef struct iris_direction_sample {
  iris_vec3 wi;       /* world, unit */
  iris_vec3 f;        /* BSDF value (for delta lobes including 1/|cos|) */
  float pdf;          /* solid-angle pdf of the WHOLE direction sampler (the mixture,
                         when guiding mixes BSDF and guide); for delta lobes the
                         discrete probability */
  uint32_t lobe;      /* IRIS_LOBE_* of the sample */
  bool delta;
  bool aimed;         /* drawn toward a lamp light sampling cannot reach (guiding's lamps
                         behind glass): its throughput is small because its density is
                         high, so Russian roulette waits for the next non-delta vertex
                         (docs/guiding.md, "Lamps behind glass"); false unless set */
} iris_direction_sample;

/* Pluggable direction sampler (the guiding module provides one). `sample`
 * must fill out->f with the BSDF value and out->pdf with the density of the
 * whole strategy; `pdf` returns that same density for any world direction
 * (0 for directions only a delta lobe reaches). All must be thread-safe.
 * `prepare` (optional, may be NULL) runs once per shading point, after
 * shading and before any sample/pdf call at that point, and may fill
 * sp->guide; it must not draw random numbers (so the sample stream does not
 * depend on it). */
typedef struct iris_direction_sampler {
  void *ctx;
  bool (*sample)(void *ctx, const iris_shading_point *sp, iris_sampler *rng,
                 iris_direction_sample *out);
  float (*pdf)(void *ctx, const iris_shading_point *sp, iris_vec3 wi);
  void (*prepare)(void *ctx, iris_shading_point *sp);
  /* Optional (may be NULL): after prepare, an estimate of the radiance a path
   * continuing from sp will still collect per unit throughput (guiding: the
   * caches' irradiance / pi; with light sampling only the indirect part), or
   * < 0 when unknown. Drives the guided methods' Russian roulette
   * (docs/guiding.md, "Russian roulette"). */
  float (*radiance_estimate)(void *ctx, const iris_shading_point *sp);
  /* Optional: a hint with the hit point, called as soon as the ray has hit
   * (before shading), to start loading what prepare will read. */
  void (*prefetch)(void *ctx, iris_vec3 p);
  /* Optional: light sampling of the environment map env (the lights') at a
   * prepared vertex (guiding's sky visibility). Returns -1 when it has nothing to add there
   * (the lights sample the map themselves), 0 when nothing could be sampled,
   * 1 with a direction, its solid-angle density (of the map alone, the light
   * choice left out) and its map coordinates, from the light sample's pair
   * (u0, u1), which also makes its own choices. */
  int (*sample_environment)(void *ctx, const struct iris_envmap *env, const iris_shading_point *sp, float u0,
                            float u1, iris_vec3 *wi, float *pdf, float *s, float *t);
  /* With sample_environment: its density for the direction wi at map
   * coordinates (s, t), at the vertex whose prepared state is v (for the MIS
   * weight of a ray that left that vertex and escaped), as the map's own
   * density times the returned scale plus *add (the part that is not a
   * multiple of the map's: sky visibility's windows). */
  float (*environment_scale)(void *ctx, const struct iris_envmap *env, const iris_guide_vertex *v, iris_vec3 wi,
                             float s, float t, float *add);
  /* Optional: after prepare, the probability in (0, 1] with which the vertex
   * samples a light at all (guiding: < 1 where training never saw a light
   * sample arrive, docs/guiding.md "Light sampling where no light arrives").
   * Light samples are divided by it and MIS counts light sampling's density
   * times it, at the vertex and at the emitter the next ray hits. */
  float (*light_probability)(void *ctx, const iris_shading_point *sp);
  /* Optional: the opening the guide found (guiding's portals) for
   * connections to a light-vertex cache (vcache.h): a point o on its plane,
   * the unit normal n pointing away from the side of the caches that keep it,
   * the opening's longer side, and the share of all caches that keep it.
   * false: none. */
  bool (*opening)(void *ctx, iris_vec3 *o, iris_vec3 *n, float *size, float *share);
  /* Optional: the windows the sky is seen through (sky visibility's) for
   * connections to light vertices the sky lit through them (vcache.h): of
   * those caches draw from, at most max by the map's power entering through
   * them (flux, descending), each one's centre o, half-axes u and v (u x v
   * pointing away from its caches' side) and the share of all caches that
   * draw from it. Returns how many (0: none). */
  int (*sky_windows)(void *ctx, const struct iris_envmap *env, int max, iris_vec3 *o, iris_vec3 *u, iris_vec3 *v,
                     float *flux, float *share);
} iris_direction_sampler;

/* Everything a path needs, shared read-only by all threads. */
typedef struct iris_integrator {
  const iris_scene *scene;
  const iris_accel *accel;
  const iris_lights *lights;
  const iris_textures *textures;
  iris_method method;
  iris_sampler_kind sampler; /* the camera paths' and the photon pass's sampler */
  int max_depth;      /* Cycles' bounces: 0 = direct light only, B = B+1 surface hits */
  int rr_depth;       /* Russian roulette from this bounce on (default 3) */
  iris_direction_sampler guide; /* used by the guided methods; sample == NULL: BSDF */
  struct iris_vcache *vcache;   /* connections to a light-vertex cache (renderer/vcache.h); NULL: none */
  /* light tracing of glossy caustics (renderer/light_trace.h; mis only):
   * the camera's MIS weights at a reflector it starts from count it; NULL: none */
  const struct iris_light_trace *light_trace;
  iris_material default_material; /* for meshes with material -1 (diffuse 0.8) */
} iris_integrator;

/* Per-thread counters (summed after the render; integer sums do not depend on
 * the order, so they are deterministic too). */
typedef struct iris_path_stats {
  uint64_t paths;
  uint64_t rays;        /* closest-hit rays */
  uint64_t shadow_rays; /* occlusion rays */
  uint64_t nan_count;   /* samples rejected as NaN/Inf */
} iris_path_stats;

#define IRIS_DEFAULT_MAX_DEPTH 64
#define IRIS_DEFAULT_RR_DEPTH 3

/* Defaults: mis, max depth 64, Russian roulette from bounce 3, no guide. */
iris_integrator iris_integrator_default(const iris_scene *scene, const iris_accel *accel,
                                        const iris_lights *lights, const iris_textures *textures);

/* Fills the shading point for a hit (material, textures, vertex colour, frame). */
/* KHR_materials_volume (docs/rendering.md): the throughput of a segment of
 * length d that ends at si, exp(-sigma d) when it ends on the back of an
 * attenuating material (the segment ran inside it), else 1. */
iris_vec3 iris_integrator_volume_transmittance(const iris_integrator *it, const iris_interaction *si, float d);

void iris_integrator_shade(const iris_integrator *it, const iris_interaction *si, iris_vec3 wo,
                           int depth, iris_shading_point *sp);

/* Runs the guide's prepare for a shaded point (guided methods with a guide
 * that has one; otherwise nothing). Call before sample_direction/direction_pdf. */
void iris_integrator_prepare_direction(const iris_integrator *it, iris_shading_point *sp);

/* THE direction choice of a path: the BSDF's sampling routine, or the guide for
 * guided methods. False ends the path. */
bool iris_integrator_sample_direction(const iris_integrator *it, const iris_shading_point *sp,
                                      iris_sampler *rng, iris_direction_sample *out);
/* BSDF sampling alone (what the non-guided methods use; guides mix it in).
 * Draws the slots IRIS_SLOT_LOBE and IRIS_SLOT_DIRECTION of rng's base. */
bool iris_integrator_sample_bsdf(const iris_shading_point *sp, iris_sampler *rng,
                                 iris_direction_sample *out);
/* The same from three given uniform numbers (lobe choice, direction). */
bool iris_integrator_sample_bsdf_u(const iris_shading_point *sp, float u_lobe, float u0, float u1,
                                   iris_direction_sample *out);
/* The BSDF as every method sees it, for a world direction wi (unit): the value
 * f such that f |cos(ns, wi)| is the scattered radiance per unit incident
 * radiance, and the density of iris_integrator_sample_bsdf. Both are 0 for a
 * direction a reflect-only BSDF may not take (below the geometric surface). At
 * a folded point (sp->fold) they are the folded BSDF: f(wi) |cos wi| +
 * f(M wi) |cos M wi| and p(wi) + p(M wi), M the mirror about the geometric
 * plane. */
iris_vec3 iris_integrator_bsdf_eval(const iris_shading_point *sp, iris_vec3 wi);
float iris_integrator_bsdf_pdf(const iris_shading_point *sp, iris_vec3 wi);

/* THE density of that choice for a given world direction (for MIS weights of
 * light samples and of emitters hit by the path). */
float iris_integrator_direction_pdf(const iris_integrator *it, const iris_shading_point *sp,
                                    iris_vec3 wi);

/* Radiance along a camera ray. Never returns NaN/Inf: such samples are
 * replaced by 0 and counted in stats->nan_count. */
iris_vec3 iris_integrator_radiance(const iris_integrator *it, iris_ray ray, iris_sampler *rng,
                                   iris_path_stats *stats);

/* One non-delta vertex of a recorded path (guide training, docs/guiding.md
 * "Training"): what the direction sampler chose there and what the rest of
 * the path brought back along it. The incident radiance along wi, per unit
 * throughput, is (L_end - L + miss) / beta per channel, where L_end is the
 * path's final estimate: `L` is the estimate after this vertex's light sample,
 * `beta` the throughput after scattering here (and after Russian roulette's
 * 1/q), `miss` the part of the emission found at the next vertex that MIS
 * gave to light sampling ((1 - w) beta Le; 0 without light sampling). */
typedef struct iris_path_vertex {
  iris_guide_vertex guide; /* the direction sampler's per-vertex state */
  iris_vec3 wi;            /* world, unit */
  iris_vec3 f;             /* BSDF value */
  float cos;               /* |cos| with the shading normal */
  float pdf;               /* density of the whole direction sampler */
  float pdf_bsdf;          /* density of BSDF sampling alone */
  iris_vec3 beta, L, miss;
  int8_t light;            /* this vertex's light sample: -1 none traced, 0 its shadow ray was
                              blocked (or it brought nothing), 1 it brought light */
  uint32_t light_id;       /* ... the light it chose (where light >= 0) */
  float light_value;       /* ... mean over RGB of f Le |cos| V / pdf, without the MIS weight: an
                              unbiased estimate of the direct light the vertex reflects, whose
                              share by light tells which lights matter there (0 where blocked) */
} iris_path_vertex;

#define IRIS_PATH_RECORD_MAX 16
typedef struct iris_path_record {
  int count; /* vertices recorded (the first IRIS_PATH_RECORD_MAX non-delta ones) */
  iris_path_vertex v[IRIS_PATH_RECORD_MAX];
} iris_path_record;

/* iris_integrator_radiance that also records the path's non-delta vertices
 * (same samples, same estimate; `rec` is reset first). */
iris_vec3 iris_integrator_radiance_record(const iris_integrator *it, iris_ray ray, iris_sampler *rng,
                                          iris_path_stats *stats, iris_path_record *rec);

#ifdef __cplusplus
}
#endif
#endif
