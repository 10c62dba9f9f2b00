/* Irradiance-cache guiding (thesis chapters 4-5): preprocessing (photons ->
 * cache placement -> filling -> cache kd-tree) and the guided direction
 * sampler the integrator calls: one-sample MIS between BSDF sampling
 * (probability 1 - alpha) and cache sampling (alpha = min(roughness,
 * alpha_max)), balance heuristic. docs/guiding.md derives the estimator and
 * gives the measured defaults. */
#ifndef IRIS_RENDERER_GUIDING_GUIDING_H
#define IRIS_RENDERER_GUIDING_GUIDING_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "renderer/guiding/cache.h"
#include "renderer/guiding/glints.h"
#include "renderer/guiding/kdtree.h"
#include "renderer/guiding/lamps.h"
#include "renderer/guiding/light_select.h"
#include "renderer/guiding/octmap.h"
#include "renderer/guiding/refine.h"
#include "renderer/guiding/photons.h"
#include "renderer/guiding/pickgrid.h"
#include "renderer/guiding/portal.h"
#include "renderer/integrator.h"
#include "renderer/render.h"
#include "renderer/guiding/skyvis.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IRIS_GUIDING_PICK_K 5 /* Algorithm 1: the 5 nearest caches */
/* Photons whose normal has a smaller cosine with the cache's are not splatted. */
#define IRIS_GUIDING_PHOTON_NORMAL_COS 0.5f
/* Light sampling's default probability where training found that it brings
 * nothing (params.light_min; docs/guiding.md, "Light sampling where no light
 * arrives"). */
#define IRIS_GUIDING_LIGHT_MIN 0.1f
/* Emitter groups the guide keeps a sphere of (iris_cache.lamp is a byte). */
#define IRIS_GUIDING_LAMP_GROUPS 64

/* Where caches lie on the film (`iris render --aov caches`). */
typedef struct iris_guiding_marks {
  int width, height;
  uint8_t *kind; /* [width * height]: 0 none, 1 cache from a camera ray, 2 cache from a photon */
} iris_guiding_marks;
void iris_guiding_marks_destroy(iris_guiding_marks *m);

/* Every parameter has a flag in `iris render`; <= 0 (or < 0 for the floor)
 * means "choose from the scene" (docs/guiding.md, "Budget"). */
struct iris_guiding;
typedef struct iris_guiding_params {
  int64_t photons;      /* photon paths emitted (--photons) */
  int64_t caches;       /* caches, half from camera rays, half from photons (--caches) */
  int cache_res;        /* octahedral map texels per side (--cache-res) */
  int cache_k;          /* photons per cache (--cache-k) */
  float pdf_floor;      /* minimum texel probability before renormalising (--pdf-floor) */
  float alpha_max;      /* cap on the cache-sampling probability (--alpha-max); < 0: 0.5 with
                           light sampling, 0.7 without (thesis 0.9) */
  float cos_min;        /* Algorithm 1 threshold (--cos-min), default 0.9 */
  iris_splat_mode splat;/* nearest (thesis) or bilinear */
  bool force;           /* build caches even where the budget would skip guiding */
  bool use_nee;         /* the render also samples lights (guided-nee): skip if lit only directly */
  int direct_photons;   /* splat photons straight from a light: -1 auto (not with NEE), 0 no, 1 yes */
  bool adjoint_rr;      /* Russian roulette from the caches' radiance estimates (default on) */
  int train_spp;        /* training passes from camera paths (--train-spp): total samples per
                           pixel spent on training; -1 auto (from the render's spp / time),
                           0 photons only (docs/guiding.md, "Training") */
  bool learn_alpha;     /* learn each cache's selection probability from the training samples
                           (default on; off: alpha = min(roughness, alpha_max)) */
  float train_prior;    /* photon-equivalent weight of a cache's photon histogram against its
                           n path samples: mixed with weight n / (n + prior) (--train-prior) */
  bool train_all_light; /* train towards all incident light, not only what light sampling's MIS
                           leaves to the sampled direction (--train-all-light) */
  bool discard_training; /* leave the training paths out of the image (--discard-training;
                            iris_render_params.keep_training is the renderer's switch) */
  /* Sky visibility (skyvis.h; docs/guiding.md, "Sky visibility"): light
   * sampling of an environment map from what each cache sees of it, with
   * light sampling only. -1: the default; sky_probes or sky_beta 0: off. */
  int sky_regions;      /* map regions across (--sky-regions; down: half as many) */
  int sky_probes;       /* probe rays per cache and region (--sky-probes; 0: off) */
  float sky_beta;       /* probability of a cache's regions (--sky-beta; 0: off) */
  int refine;           /* most texels per cache refined into 4 x 4 sub-cells where the light is
                           concentrated (--refine; -1 auto: 0 (measured), 0 off; refine.h) */
  bool lamp_glass;      /* lamps behind glass: caches learn which emitter groups' light reached
                           them straight through glass, and the guide draws directions in
                           those groups' cones (default on; --no-lamp-glass; lamps.h) */
  bool glints;          /* glints: photons aimed at smooth surfaces (mirrors, glass, near-mirror
                           metal) mark where their reflections of the lights land, and the guide
                           draws directions in the cone of the spot a vertex's nearest ones left
                           (default on; --no-glints; glints.h, docs/guiding.md "Glints") */
  bool portals;         /* portals: where a cache's indirect light came through an opening in a
                           wall (a door), the guide also draws points on a rectangle spanning it
                           (default on; --no-portals; portal.h, docs/guiding.md "Portals") */
  bool light_samples;   /* --light-sampler learned: training's light samples teach the caches' light
                           tables too (default on; --no-light-samples: the photons alone;
                           light_select.h, docs/guiding.md "Learned light selection") */
  float light_min;      /* light sampling's probability at vertices whose caches' training traced
                           >= 32 light samples and none brought light (--light-min; 1: always
                           sample lights; docs/guiding.md, "Light sampling where no light arrives") */
  iris_emission_selection photon_lights; /* photons leave lights by power (default) or by
                                            area (thesis; --photon-lights) */
  /* The guide as a file (docs/guiding.md, "The guide as a file"; NULL = off):
   * guide_in: read the guide from this file instead of building it (refused
   * unless it was written for the same scene and settings); guide_out: write
   * the built guide to this file. */
  const char *guide_in, *guide_out;
  int64_t pilot_paths;  /* with light sampling, the skip rules are decided before the full
                           photon pass on its first pilot_paths paths; -1 auto
                           (iris_guiding_pilot_paths), 0 no pilot (docs/guiding.md,
                           "--method auto") */
  /* Inspection (outputs of the build, NULL = off): */
  const char *dump_dir;       /* --dump-caches DIR: pdf and photon-count PNGs of the caches
                                 serving a 4 x 3 grid of pixels (docs/guiding.md) */
  iris_guiding_marks *marks;  /* --aov caches: filled with the visible cache positions */
  /* Called at the end of a build that was not skipped, while the photons
   * still exist, when dump_dir or marks is set (NULL: nothing is written).
   * The inspection module provides it (iris_guiding_inspect, inspect.h), so
   * guiding depends on no inspection code and inspection on guiding alone. */
  iris_status (*inspect)(const struct iris_guiding *g, const iris_guide_setup *setup,
                         const struct iris_guiding_params *params, const iris_photon_map *photons,
                         const iris_kdtree *photon_tree, iris_error *err);
} iris_guiding_params;

iris_guiding_params iris_guiding_params_default(void);

/* A cache (thesis 4.2.4): position, frame, and an offset into the shared tables. */
typedef struct iris_cache {
  iris_vec3 p;
  iris_frame frame;
  uint32_t table;    /* first texel of this cache's tables in iris_guiding.pdf/.alias */
  uint32_t photons;  /* photons splatted */
  float radiance;    /* irradiance / pi from its k photons (mean of RGB, W m^-2 sr^-1): the
                        radiance a diffuse white surface here reflects (Russian roulette);
                        refined by training */
  float alpha;       /* learned cache-sampling probability (< 0: not learned, alpha_max) */
  float light;       /* probability of light sampling at the vertices it serves: 1, or
                        params.light_min where training's light samples all came back empty */
  float sky_through; /* share of its photons' energy that came from the environment
                        straight through glass (photons.h): the probability with which
                        its guided samples follow the map instead ("Sky behind glass") */
  float lamp_share[IRIS_CACHE_LAMPS]; /* the same for lamps: shares of its photons' energy that
                        came straight through glass from emitter group lamp[i] (brightest
                        first, 0: unused), drawn in that group's cone ("Lamps behind glass") */
  float pane_share;  /* share of its photons' energy that came from the environment through
                        one refracting plane (a single glass quad), drawn from the map carried
                        through pane[] ("Sky through a pane"); sky_through + pane_share +
                        the lamp shares <= 1 */
  float pane[4];     /* that plane: energy-weighted normal on the sky's side, eta = n_room / n_sky */
  float glint_share;  /* of the guide's share, the probability of drawing in the cone of the
                        glint spot a vertex finds among the glint photons near it (glints.h):
                        where a spot is found at the cache, the share of its indirect photon
                        energy that a smooth surface reflected last (photons.h, glint), within
                        [IRIS_GLINT_SHARE_MIN, IRIS_GLINT_SHARE_MAX]; else 0 ("Glints"); with
                        the shares above <= 1 */
  iris_portal portal;  /* the opening its indirect light came through (portal.h); none: u = v = 0 */
  float portal_weight; /* a finder's: the share of its indirect photon energy in the cone the
                          portal was looked for in; a cache that took a joined opening: the share
                          of its map's light through it (iris_portal_share); training keeps or
                          drops each portal (train.c); a vertex takes its tied caches' heaviest */
  uint8_t lamp[IRIS_CACHE_LAMPS]; /* index into iris_guiding.lamps */
  uint8_t sphere;    /* full-sphere map (transmissive surface) */
  uint8_t from_camera;
} iris_cache;

typedef struct iris_guiding_stats {
  uint64_t photon_paths, photons_stored, photons_indirect;
  uint64_t caches, camera_caches, empty_caches;
  uint64_t refined_texels, refined_caches; /* texels split into sub-cells, caches with any (refine.h) */
  uint64_t portal_caches;                  /* caches with a portal (portal.h) */
  int cache_res, cache_k, camera_stride;
  float pdf_floor;
  double photon_seconds, cache_seconds, total_seconds;
  int train_spp, train_iterations; /* training passes run (docs/guiding.md, "Training") */
  uint64_t train_samples;          /* path vertices recorded into caches */
  double train_seconds;
  double seen_indirect_energy; /* --method auto: share of the photon energy on surfaces the camera
                                  sees that arrived indirectly, from the pilot (-1: not measured) */
  size_t memory_bytes; /* caches + tables + kd-tree */
  bool skipped;        /* guiding off: sampler falls back to the BSDF */
  char reason[160];
  uint64_t pilot_paths;   /* photon paths of the pilot (0: none ran) */
  double pilot_share;     /* share of indirect photons the 30% rule saw in the pilot (-1: none) */
  double indirect_share;  /* ... and in the full pass (-1: the full pass did not run) */
  double caustic_share;   /* the share of the indirect photon energy focused through glass
                             where that kept the guide against the "lit mostly directly"
                             rules, else -1 (docs/guiding.md, "--method auto") */
  double pilot_seconds;
} iris_guiding_stats;

typedef struct iris_guiding {
  iris_guiding_params params;
  iris_octmap hemi, sphere;
  iris_cache *caches;
  size_t cache_count;
  float *pdf;              /* all tables: P * res^2 / 2 per texel (density / iris_cache_density_factor) */
  iris_cache_alias *alias; /* all alias tables (texel choice in O(1)) */
  iris_kdtree tree;    /* over caches[i].p */
  float pick_radius2;  /* Algorithm 1 ignores caches farther than this (squared) */
  iris_pick_grid grid; /* candidate caches per cell: Algorithm 1's search without the tree */
  float alpha_cap;     /* cap on learned selection probabilities: --alpha-max when given, else 0.95 */
  uint8_t *refine_slot; /* per texel (pdf layout): 0, or which of its cache's sub-tables (refine.h) */
  float *refine_sub;    /* IRIS_REFINE_MAX sub-tables of IRIS_REFINE_SUB per cache, at
                           iris_guiding_sub(g, cache); NULL: no refinement */
  float *photon_hist;  /* during training only: each cache's photon histogram, normalised (pdf layout) */
  iris_skyvis sky;     /* sky visibility per cache (env NULL: none) */
  const iris_envmap *env; /* the lights' map, sampled for caches with sky_through > 0: borrowed,
                             set by the build for training and by the provider for rendering
                             (NULL: none, and guided sampling ignores sky_through) */
  iris_guide_lamp *lamps;  /* the lights' groups' bounding spheres, by group index (owned; copied
                              at the build, stored in the guide file): what iris_cache.lamp names */
  size_t lamp_count;
  iris_light_select lights; /* learned light selection (setup->learn_lights; light_select.h) */
  iris_glints glints;       /* glint photons ("Glints"; glints.h): what iris_cache.glint_share asks for */
  iris_guiding_stats stats;
} iris_guiding;

/* The sub-tables of cache c (refine.h): tables are whole multiples of a
 * hemisphere map, so table / hemi texels numbers the caches. */
static inline float *iris_guiding_sub(const iris_guiding *g, const iris_cache *c) {
  return g->refine_sub + (size_t)(c->table / g->hemi.texel_count) * IRIS_REFINE_MAX * IRIS_REFINE_SUB;
}

iris_status iris_guiding_build(const iris_guide_setup *setup, const iris_guiding_params *params,
                               iris_guiding **out, iris_error *err);
void iris_guiding_destroy(iris_guiding *g);
/* Counts the refined texels and caches into g->stats. */
void iris_guiding_count_refined(iris_guiding *g);
/* (Re)builds g->sky for the setup's environment map, when the guide is used
 * with light sampling (a guide read from a file gets it here too);
 * skyvis_hooks.c. */
iris_status iris_guiding_build_sky(iris_guiding *g, const iris_guide_setup *setup, iris_error *err);
/* Installs the sampler's environment hooks (sample_environment,
 * environment_scale) when g->sky is built; skyvis_hooks.c. */
void iris_guiding_sky_hooks(iris_guiding *g, iris_direction_sampler *s);
/* Enters a phase of the build (key: core/cancel.h's hook name, NULL: only
 * report) and reports `what` through setup->phase. */
void iris_guiding_phase(const iris_guide_setup *s, const char *key, const char *what, double eta_first_image);

/* The integrator hook; sample == NULL when guiding was skipped. */
iris_direction_sampler iris_guiding_sampler(iris_guiding *g);

/* Algorithm 1 without the coin flips: the caches among the 5 nearest to p
 * (to the centre of p's pick-grid cell when there is a grid) whose normal has the best cosine with n (ties within 1e-4), none if that
 * cosine is <= cos_min. The guided strategy samples one of them uniformly
 * (with the path's sampler) and its density is their average, so `pdf`
 * evaluates exactly what `sample` does. Returns how many (<= 5). */
int iris_guiding_pick(const iris_guiding *g, iris_vec3 p, iris_vec3 n, uint32_t ids[IRIS_GUIDING_PICK_K]);
/* Solid-angle density of cache sampling for world direction wi at a point
 * with picked caches ids[0..m). */
float iris_guiding_cache_pdf(const iris_guiding *g, const uint32_t *ids, int m, iris_vec3 wi);

/* Builds the guide from `options` (an iris_guiding_params, NULL = defaults)
 * for iris_render; destroy frees it. */
extern const iris_guide_provider iris_guiding_provider;

/* --method auto: guided-nee (and the race) from this share of the photon
 * energy on what the camera sees arriving after a bounce; mis below it. */
#define IRIS_GUIDING_AUTO_SEEN_INDIRECT_MIN 0.50

/* The default photon paths of a guide (docs/guiding.md, "Budget") for this
 * many caches of k photons, light groups (emitting instances, punctual
 * lights, sky) and the sky's share of the power in [0, 1]; iris_memory's
 * estimate asks it too, with the share an upper bound. */
double iris_guiding_photon_paths(double caches, int cache_k, size_t light_groups, double sky_share);

/* Photon paths of the pilot for a full pass of `photons` paths: max(16384,
 * photons / 16) rounded up to whole blocks of 4096, at most `photons`. */
uint64_t iris_guiding_pilot_paths(uint64_t photons);

/* One-line summaries for `iris render`. */
void iris_guiding_describe(const iris_guiding *g, char *buf, size_t size);

#ifdef __cplusplus
}
#endif
#endif
