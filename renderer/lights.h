/* Everything that emits: emissive triangles (chosen in proportion to their
 * power, sampled uniformly in solid angle when close, else by area), KHR_lights_punctual point, spot and
 * directional lights, and the constant environment ("world"). One discrete
 * distribution over all of them serves next-event estimation (with the pdfs
 * MIS needs when a BSDF-sampled ray hits an emitter) and photon emission for
 * the guiding preprocess. Units are radiometric: docs/rendering.md, "Lights".
 * Emissive-triangle radiance is the material's emission (times its emission
 * texture) on the front face, and on both faces when emission_two_sided.
 * light_build.c builds the list and its tables; lights.c selects, samples and
 * evaluates. */
#ifndef IRIS_RENDERER_LIGHTS_H
#define IRIS_RENDERER_LIGHTS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "core/math.h"
#include "renderer/accel.h"
#include "renderer/envmap.h"
#include "renderer/light_tree.h"
#include "renderer/sampling.h"
#include "renderer/texture.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum iris_light_kind {
  IRIS_LIGHT_KIND_TRIANGLE = 0, /* an emissive triangle (area light) */
  IRIS_LIGHT_KIND_POINT,
  IRIS_LIGHT_KIND_SPOT,
  IRIS_LIGHT_KIND_DIRECTIONAL,
  IRIS_LIGHT_KIND_ENVIRONMENT
} iris_light_kind;

/* One entry of the light list. */
typedef struct iris_light_entry {
  iris_light_kind kind;
  uint32_t group;     /* index into iris_lights.groups */
  uint32_t prim;      /* triangle: global triangle index; punctual: scene light index */
  float power;        /* selection weight: luminance of the emitted power (W) */
  float area;         /* triangle area (0 for the others) */
  bool two_sided;     /* triangle emits from both faces */
  iris_vec3 radiance; /* triangle: emission factor (untextured); environment: radiance;
                         point/spot: radiant intensity (W/sr); directional: irradiance (W/m^2) */
  iris_vec3 v0, e1, e2; /* triangle: world vertex 0 and edges (counter-clockwise, front) */
  iris_vec3 ng;         /* triangle: unit front normal */
  bool textured;        /* triangle: the emission has a texture */
} iris_light_entry;

/* Lights are chosen for next-event estimation in two steps: a group (the
 * emissive triangles of one instance, or one punctual/environment light) with
 * probability proportional to an estimate of the irradiance it gives at the
 * shading point (power / (4 pi max(d^2, r^2)) for a group of bounding sphere
 * radius r at distance d; I / d^2 for point and spot lights; E, resp. pi L, for
 * directional lights and the environment), then an entry of the group in
 * proportion to power. docs/rendering.md, "Light selection". */
#define IRIS_LIGHTS_MAX_GROUPS 64
/* Past IRIS_LIGHTS_MAX_GROUPS groups the emitting instances' triangles share
 * one group (the others keep theirs); the memory estimate counts them so. */
static inline bool iris_lights_merge_groups(size_t tri_groups, size_t others) {
  return tri_groups + others > IRIS_LIGHTS_MAX_GROUPS;
}
static inline size_t iris_lights_group_count(size_t tri_groups, size_t others) {
  return (iris_lights_merge_groups(tri_groups, others) && tri_groups > 0 ? 1 : tri_groups) + others;
}
/* The punctual lights and constant environments the lights build an entry
 * for: those that emit (a black one is left out). An environment map's mean
 * is known only once it is loaded (a black map is left out then). */
static inline bool iris_lights_punctual_emits(const iris_light *l) {
  return iris_luminance(iris_scale(iris_v3_load(l->color), l->intensity)) > 0.0f;
}
static inline bool iris_lights_constant_environment_emits(const iris_scene *s) {
  return s->has_environment && !s->environment_map.path &&
         (s->environment[0] > 0 || s->environment[1] > 0 || s->environment[2] > 0);
}
typedef struct iris_light_group {
  uint32_t first, count;  /* entries [first, first + count) */
  iris_light_kind kind;
  iris_vec3 center;       /* bounding sphere of a triangle group */
  float radius;
  float power;            /* sum of the entries' power */
  float phi;              /* triangles: power; point/spot: 4 pi luminance(I) (weight numerator) */
  float irradiance;       /* directional / environment: the distance-free estimate */
  iris_distrib1d select;  /* over the group's entries (count > 1) */
} iris_light_group;

/* What next-event estimation reads of a triangle entry, packed into one
 * 64-byte cache line (the entries themselves are larger and, for emitters of
 * thousands of triangles, mostly out of cache). The choice within a group is
 * an alias table (Walker 1977, Vose 1991) stored in the same lines: slot j of
 * a group of n is picked with floor(u n), kept if the rest of u n is below
 * alias_q and else replaced by `alias`, so a choice costs one cache miss
 * (two when redirected) instead of a search through a CDF and then the record. */
typedef struct iris_light_tri {
  float v0[3], e1[3], e2[3]; /* world vertex 0 and edges (counter-clockwise, front);
                                the unit front normal is normalize(e1 x e2) */
  float area;
  float pmf_in_group;        /* probability of the entry within its group */
  int32_t material;          /* its emission is the untextured radiance */
  uint32_t flags;            /* IRIS_LIGHT_TRI_* | group << 8 */
  float alias_q;             /* keep this slot when the remainder is below */
  uint32_t alias;            /* else this entry (global index) */
  uint32_t pad_;
} iris_light_tri;
#define IRIS_LIGHT_TRI_TWO_SIDED 1u
#define IRIS_LIGHT_TRI_TEXTURED 2u
#define IRIS_LIGHT_TRI_AREA_ONLY 4u /* never by solid angle (iris_lights_set_triangle_sampling) */

/* A light choice learned where the lights are seen (--light-sampler learned;
 * renderer/guiding/light_select.h): when `choose` is set, next-event
 * estimation chooses through it and every selection probability (the MIS
 * weights of emitters and of the environment hit by BSDF sampling) asks
 * `pmf` at the same point and normal, so the two agree bit for bit. */
struct iris_lights;
typedef struct iris_light_learned {
  const void *ctx;
  /* false: nothing to choose at (ref, n); else the entry and its probability */
  bool (*choose)(const void *ctx, const struct iris_lights *L, iris_vec3 ref, iris_vec3 n, float u,
                 uint32_t *light, float *pmf);
  float (*pmf)(const void *ctx, const struct iris_lights *L, iris_vec3 ref, iris_vec3 n, uint32_t light);
} iris_light_learned;

typedef struct iris_lights {
  const iris_scene *scene;
  const iris_accel *accel;
  const iris_textures *textures;
  iris_light_entry *entries;
  size_t count;
  iris_light_tri *tris;   /* entries [0, tri_count) are the triangles (64-byte aligned) */
  size_t tri_count;
  iris_distrib1d select;  /* over entries, in proportion to power (photon emission) */
  iris_light_group *groups;
  size_t group_count;
  /* Emissive triangles per placement (scene instance): light_of_prim[
   * light_base[instance] + triangle index in the mesh] is the entry index or
   * UINT32_MAX (degenerate); light_base is UINT32_MAX for a placement of a
   * non-emissive mesh. Sized by placements and emissive triangles, never by
   * all triangles in the world. */
  uint32_t *light_base;
  uint32_t *light_of_prim;
  int32_t environment;    /* entry index of the environment, or -1 */
  iris_envmap *envmap;    /* the environment's map (owned), NULL for a constant one */
  iris_vec3 center;       /* scene bounding sphere (directional/environment photons) */
  float radius;
  double total_power;
  uint64_t id;            /* unique per build (keys the per-thread selection cache) */
  iris_light_tree *tree;  /* --light-sampler tree: NEE chooses through it (owned); NULL: by power */
  iris_light_learned learned; /* --light-sampler learned, once installed (not owned); zero: none */
} iris_lights;

/* Builds the light list. A scene without emitters gives count == 0 (renders black
 * unless something is added). An environment map is read and checked here
 * (iris_envmap_load): a bad map is an error naming its file. */
iris_status iris_lights_build(const iris_scene *scene, const iris_accel *accel,
                              const iris_textures *textures, iris_lights *out, iris_error *err);
void iris_lights_destroy(iris_lights *lights);

/* Probability with which photon emission picks entry `index` (power-proportional). */
float iris_lights_select_pmf(const iris_lights *lights, uint32_t index);
/* Picks an entry in proportion to power with one uniform number; returns its
 * index and the pmf (0 when there is no light). */
uint32_t iris_lights_select(const iris_lights *lights, float u, float *pmf);
/* Probability with which iris_lights_sample, called at `ref` with normal `n`, picks entry `index`. */
float iris_lights_select_pmf_at(const iris_lights *lights, iris_vec3 ref, iris_vec3 n, uint32_t index);

/* How next-event estimation chooses a light at a shading point: by power
 * (groups by estimated irradiance, then entries by power, above) or through
 * the light tree (renderer/light_tree.h: position, orientation and the
 * receiver's normal). Every NEE function takes the shading point `ref` and
 * its normal `n`: the shading normal on wo's side for reflecting BSDFs, the
 * zero vector where light may come from any direction (transmission,
 * volumes); the power sampler ignores n. docs/rendering.md, "Light tree". */
typedef enum iris_light_sampler {
  IRIS_LIGHT_SAMPLER_POWER = 0,
  IRIS_LIGHT_SAMPLER_TREE = 1,
  IRIS_LIGHT_SAMPLER_LEARNED = 2, /* the tree mixed with what the guide's caches learned
                                     (renderer/guiding/light_select.h); until the
                                     renderer installs that (iris_lights.learned): the tree */
  IRIS_LIGHT_SAMPLER_COUNT
} iris_light_sampler;
/* The choice of renders that do not say (measured: docs/performance.md, "Light tree"). */
#define IRIS_LIGHT_SAMPLER_DEFAULT IRIS_LIGHT_SAMPLER_TREE
const char *iris_light_sampler_name(iris_light_sampler s); /* "power", "tree", "learned" */
bool iris_light_sampler_parse(const char *name, iris_light_sampler *out);
/* Switches the NEE light choice (builds or frees the tree; a tree that
 * would be a single leaf is not kept: lights->tree stays NULL and the power
 * sampler, which chooses the same, serves). */
iris_status iris_lights_set_sampler(iris_lights *lights, iris_light_sampler s, iris_error *err);
/* The bounds the tree is given for entry i (exposed for tests). */
iris_light_bounds iris_lights_bounds(const iris_lights *lights, uint32_t i);

/* ---- next-event estimation -------------------------------------------- */

typedef struct iris_light_sample {
  iris_vec3 wi;      /* unit direction from the reference point to the light */
  float dist;        /* distance to the light point; INFINITY for directional/environment */
  iris_vec3 p;       /* point on the light (triangle, point, spot) */
  iris_vec3 n;       /* light's geometric normal at p (triangle), else -wi */
  iris_vec3 L;       /* incident radiance (area, environment) or, for delta lights,
                        the irradiance-producing value I / dist^2 resp. E */
  float pdf;         /* solid-angle pdf including the selection pmf; for delta
                        lights the selection pmf alone */
  bool delta;        /* point, spot, directional: cannot be hit by BSDF sampling */
  bool L_pending;    /* L not looked up yet (iris_lights_sample_choice_lazy on an
                        environment map): iris_lights_sample_radiance does it */
  uint32_t light;    /* entry index */
  float map_s, map_t;/* environment map coordinates of wi (L_pending) */
} iris_light_sample;

/* Samples a light as seen from `ref` (a surface point, normal n) with three uniform
 * numbers. Returns false when nothing was sampled (no lights, back face of a
 * one-sided emitter, zero-area triangle, outside a spot cone...). */
bool iris_lights_sample(const iris_lights *lights, iris_vec3 ref, iris_vec3 n, float u_select, float u0,
                        float u1, iris_light_sample *s);

/* iris_lights_sample in two halves, so that the path tracer can choose the
 * light as soon as it knows the shading point and do the shading while the
 * chosen emitter's record (usually a cache miss in scenes with thousands of
 * emitter triangles) is being loaded: choose + sample_choice with the same
 * numbers give exactly what iris_lights_sample gives. The selection weights of
 * the last point a thread asked about are cached, so the MIS pdf of an
 * emitter hit from that point (iris_lights_pdf_triangle) does not recompute them. */
typedef struct iris_light_choice {
  uint32_t light;   /* entry index */
  float pmf_group;  /* probability of its group at ref; 0 = nothing to sample */
  bool pmf_is_entry;/* the tree chose: pmf_group is the entry's own probability */
} iris_light_choice;
void iris_lights_choose(const iris_lights *lights, iris_vec3 ref, iris_vec3 n, float u_select,
                        iris_light_choice *c);
bool iris_lights_sample_choice(const iris_lights *lights, iris_vec3 ref,
                               const iris_light_choice *c, float u0, float u1,
                               iris_light_sample *s);
/* The same, but an environment map's radiance is left for
 * iris_lights_sample_radiance (s->L_pending): the caller looks it up only
 * for samples that pass their shadow ray (a room lit through a window sees
 * most map samples blocked, and the lookup is a cache miss or two). */
bool iris_lights_sample_choice_lazy(const iris_lights *lights, iris_vec3 ref, const iris_light_choice *c,
                                    float u0, float u1, iris_light_sample *s);
/* With an environment map: starts loading what sampling the map with
 * (u0, u1) will read (iris_envmap_prefetch's stages); a hint, nothing else changes. */
void iris_lights_prefetch_environment(const iris_lights *lights, float u0, float u1, int stage);
/* Fills s->L of a lazily drawn sample; nothing to do for the others. */
void iris_lights_sample_radiance(const iris_lights *lights, iris_light_sample *s);

/* How next-event estimation samples emitter triangles: by solid angle where
 * that lowers variance and by area elsewhere (the default), or always by area
 * (for comparison: --light-sampling area). */
typedef enum iris_triangle_sampling {
  IRIS_TRIANGLE_SAMPLING_SOLID_ANGLE = 0,
  IRIS_TRIANGLE_SAMPLING_AREA = 1,
  IRIS_TRIANGLE_SAMPLING_COUNT
} iris_triangle_sampling;
const char *iris_triangle_sampling_name(iris_triangle_sampling m); /* "solid-angle", "area" */
bool iris_triangle_sampling_parse(const char *name, iris_triangle_sampling *out);
void iris_lights_set_triangle_sampling(iris_lights *lights, iris_triangle_sampling m);

/* The solid angle of emitter triangle t seen from ref when next-event
 * estimation samples it by solid angle there, else 0 (it samples by area).
 * docs/rendering.md, "Emitter triangles". */
float iris_lights_triangle_solid_angle(const iris_light_tri *t, iris_vec3 ref);

/* Radiance leaving surface point `si` towards -d (the direction of the ray
 * that hit it); zero for non-emissive materials and for the back face of
 * one-sided emitters. */
iris_vec3 iris_lights_emitted(const iris_lights *lights, const iris_interaction *si, iris_vec3 d);
/* Solid-angle pdf (selection included) that iris_lights_sample, called at
 * `ref` with normal n, returns the point si->p of an emissive triangle. */
float iris_lights_pdf_triangle(const iris_lights *lights, iris_vec3 ref, iris_vec3 n,
                               const iris_interaction *si);
/* Environment radiance along direction d (a ray that escaped), and the
 * solid-angle pdf that iris_lights_sample, called at `ref` with normal n, returns d. */
iris_vec3 iris_lights_environment(const iris_lights *lights, iris_vec3 d);
float iris_lights_pdf_environment(const iris_lights *lights, iris_vec3 ref, iris_vec3 n, iris_vec3 d);
/* Both with one lookup of d: the radiance, and in *pdf (when not NULL) the
 * value of iris_lights_pdf_environment(lights, ref, n, d); with a map and a
 * pdf asked for, map_st (when not NULL) gets d's map coordinates. */
iris_vec3 iris_lights_environment_pdf(const iris_lights *lights, iris_vec3 d, iris_vec3 ref, iris_vec3 n,
                                      float *pdf, float map_st[2]);
/* Whether a light choice is the environment map (which a direction sampler
 * may sample itself: iris_direction_sampler.sample_environment). */
bool iris_lights_choice_is_environment_map(const iris_lights *lights, const iris_light_choice *c);
/* A light sample of the environment map in direction wi drawn with density
 * pdf_dir by another sampler, at map coordinates (s, t): as
 * iris_lights_sample_choice_lazy fills it (the radiance pending), its pdf the
 * choice's probability times pdf_dir. */
bool iris_lights_environment_sample_at(const iris_lights *lights, const iris_light_choice *c, iris_vec3 ref,
                                       iris_vec3 wi, float pdf_dir, float s, float t, iris_light_sample *out);

/* ---- photon emission (guiding preprocess) ----------------------------- */

typedef struct iris_photon_emission {
  iris_vec3 p;       /* origin of the photon ray (offset off the emitter surface) */
  iris_vec3 dir;     /* unit direction */
  iris_vec3 n;       /* emitter normal at p (the side emitted from), or dir */
  iris_vec3 power;   /* photon energy Le cos / (pmf * pdf_pos * pdf_dir): the
                        average over many photons is the lights' total power */
  uint32_t light;    /* entry index */
  uint32_t prim;     /* triangle: global triangle index; else the entry's prim */
  float pdf_pos;     /* area density of p (1 for point/spot) */
  float pdf_dir;     /* solid-angle density of dir */
} iris_photon_emission;

/* How photon emission picks a light: in proportion to power (every photon of
 * a light-only scene carries the same energy) or, as the thesis does, emissive
 * triangles in proportion to area (docs/guiding.md, "Preprocessing"). */
typedef enum iris_emission_selection {
  IRIS_EMIT_BY_POWER = 0,
  IRIS_EMIT_BY_AREA = 1
} iris_emission_selection;

/* Samples a light in proportion to power, a point on it and an emission
 * direction (cosine-weighted for triangles, uniform for point/spot, a disk
 * covering the scene for directional/environment) from five uniform numbers. */
bool iris_lights_sample_emission(const iris_lights *lights, float u_select, float u0, float u1,
                                 float u2, float u3, iris_photon_emission *e);
/* A light choice over the entries for photon emission: by power (equal to
 * lights->select) or by area (emissive triangles in proportion to area,
 * sharing the triangles' total power share; other lights by power). Built on
 * demand, so scenes that do not ask for it carry none; free with
 * iris_distrib1d_destroy. */
iris_status iris_lights_emission_selection(const iris_lights *lights, iris_emission_selection by,
                                          iris_distrib1d *out, iris_error *err);
/* iris_lights_sample_emission with the light drawn from `select` (one of the
 * above); false when select does not cover the lights. */
bool iris_lights_sample_emission_with(const iris_lights *lights, const iris_distrib1d *select,
                                      float u_select, float u0, float u1, float u2, float u3,
                                      iris_photon_emission *e);

#ifdef __cplusplus
}
#endif
#endif
