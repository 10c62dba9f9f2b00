/* The renderer's entry point: scene + params -> film. It runs the sequence
 * build_accel -> load_textures -> build_lights -> [prepare guide] -> passes of
 * samples over all pixels -> result, and writes EXR/PNG files. The `iris
 * render` command is a thin layer that fills iris_render_params. */
#ifndef IRIS_RENDERER_RENDER_H
#define IRIS_RENDERER_RENDER_H

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "renderer/adaptive.h"
#include "renderer/camera.h"
#include "renderer/film.h"
#include "renderer/integrator.h"
#include "renderer/method_race.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IRIS_RENDER_DEFAULT_SPP 64
/* Adaptive sampling's per-pixel cap when no --spp is given (Blender's default
 * Max Samples). */
#define IRIS_RENDER_ADAPTIVE_DEFAULT_CAP 4096
/* The per-pixel cap of adaptive sampling under a time budget by default
 * (`iris render --time` without --spp): the budget decides, as it does for
 * uniform passes, and iris bench's @adaptive uses the same. */
#define IRIS_RENDER_BUDGET_ADAPTIVE_CAP (1 << 20)
/* Whether the guide's training samples go into the image by default
 * (iris_render_params.keep_training; docs/guiding.md, "Training samples"). */
#define IRIS_KEEP_TRAINING_DEFAULT true
/* Connections to a light-vertex cache by default where the guide's opening is
 * kept by at least this share of the caches (door 0.23, door-shielded 0.18;
 * corridor-rooms 0.09 and the office 0.01-0.02, where they do not pay), and
 * not between points closer than this times the opening's longer side (0.3 m
 * at the door: closer connections' 1/d^2 stays with the camera). */
#define IRIS_CONNECT_MIN_SHARE 0.15f
#define IRIS_CONNECT_MIN_DISTANCE 0.15f
/* With the sky through windows (no opening to a lit room): on where the
 * windows together are drawn from by at least IRIS_CONNECT_MIN_SHARE of the
 * caches (sky-room 0.37); the camera and the connections share the map's
 * light by MIS with this constant (vcache.h, iris_vcache_sky_weight; of 0.5,
 * 1, 2, 4 and 8, 2 measured best per sample on sky-room and the corner,
 * docs/guiding.md). */
#define IRIS_CONNECT_SKY_MIS_C 2.0f
/* With the sky: a window whose entering power is below this share of the
 * brightest window's is left to the camera (render.c). */
#define IRIS_CONNECT_SKY_MIN_FLUX 0.01f

/* A window of the frame in pixels, half-open: x0 <= x < x1, y0 <= y < y1. */
typedef struct iris_pixel_bounds {
  int x0, y0, x1, y1;
} iris_pixel_bounds;

/* Everything the guided methods need to build their guide before the passes. */
typedef struct iris_guide_setup {
  const iris_scene *scene;
  const iris_accel *accel;
  const iris_lights *lights;
  const iris_textures *textures;
  const iris_pinhole *camera;
  const iris_integrator *integrator; /* for iris_integrator_shade */
  uint64_t seed;
  int threads;
  const void *options; /* the guide's own options (iris_render_params.guide_options) */
  int spp;             /* the render's samples per pixel (0 with a time budget) */
  double time_budget;  /* the render's wall-clock budget in seconds (0: spp decides) */
  iris_sampler_kind sampler; /* the render's sampler (training paths use it too) */
  bool deciding;       /* --method auto is deciding: the guide may decline the scene on rules
                          that only auto applies (docs/guiding.md, "--method auto") */
  /* Reports the phase the build is in (iris_render_params.phase; may be NULL). */
  void (*phase)(void *ctx, const char *what, double elapsed, double eta_first_image);
  void *phase_ctx;
  double t0; /* iris_time_now() when the render started: `elapsed` counts from it */
  /* Training passes add their camera paths' radiance to this film for the
   * pixels of `window` (full-frame coordinates; the film covers the window),
   * when not NULL: each training path is an unbiased sample of its pixel
   * (docs/guiding.md, "Training samples"). */
  iris_film *film;
  iris_pixel_bounds window;
  /* --light-sampler learned: the guide also learns which lights its caches
   * see (renderer/guiding/light_select.h) for iris_guide_provider.light_select. */
  bool learn_lights;
  /* --method auto: mis would trace light paths off glossy reflectors that
   * reach the camera (light_trace.h): the rule that keeps the guide for
   * light focused through glass yields to it (docs/guiding.md, "--method auto"). */
  bool mis_light_traces;
} iris_guide_setup;

/* Builds a direction sampler (and its state) for the guided methods;
 * `destroy` frees the state. Provided by the guiding module. */
typedef struct iris_guide_provider {
  iris_status (*build)(const iris_guide_setup *setup, iris_direction_sampler *out,
                       void **state, iris_error *err);
  void (*destroy)(void *state);
  /* After build: whether the guide is in use (false: it skipped the scene and
   * the sampler is BSDF sampling), and in `why` a short phrase saying why,
   * e.g. "75% of the photons indirect" or "the scene has no lights".
   * `--method auto` resolves to mis when false; when true, to guided-nee if
   * *settled (the guide says a race is not needed or cannot measure: e.g.
   * --force-guiding, or light focused through glass) and otherwise to the
   * winner of a race of the two (renderer/method_race.h). */
  bool (*decision)(const void *state, char *why, size_t size, bool *settled);
  /* Optional (NULL: --light-sampler learned chooses with the tree alone).
   * build_lights: a guide built only for learned light selection (methods
   * without a guide of their own: photons and caches, no training);
   * light_select: the hooks for iris_lights.learned from a guide built with
   * setup->learn_lights (zero when it learned nothing), valid until destroy. */
  iris_status (*build_lights)(const iris_guide_setup *setup, void **state, iris_error *err);
  iris_light_learned (*light_select)(const void *state);
} iris_guide_provider;

typedef struct iris_render_params {
  int width, height;        /* <= 0: derive (camera.h) */
  int spp;                  /* samples per pixel (used when time_budget <= 0); 0: scene or 64 */
  double time_budget;       /* > 0: whole passes until this many seconds */
  uint64_t seed;
  int threads;              /* <= 0: all cores */
  iris_method method;       /* IRIS_METHOD_COUNT: the scene's, else auto */
  iris_sampler_kind sampler; /* default sobol (docs/rendering.md, "Samplers") */
  iris_triangle_sampling light_sampling; /* emitter triangles: default solid angle where it helps */
  iris_light_sampler light_sampler; /* NEE's light choice (default IRIS_LIGHT_SAMPLER_DEFAULT) */
  int max_depth;            /* Cycles' bounce count; < 0: the scene's, else 64 */
  int rr_depth;             /* first bounce with Russian roulette */
  const char *camera_name;  /* NULL: the scene's first camera */
  /* Set asynchronously (e.g. by a signal handler) to stop: iris_render watches
   * it (core/cancel.h) for its whole run, so every phase stops within about a
   * second. Stopped in the image passes: the passes done are the result, with
   * `interrupted` set. Stopped before the first pass finished: no result,
   * IRIS_ERR_INTERRUPTED "interrupted while <phase>". NULL: whatever
   * iris_cancel_watch already watches. */
  volatile sig_atomic_t *cancel;
  /* Called after each image pass from the calling thread (may be NULL). */
  void (*progress)(void *ctx, int spp_done, int spp_total, double elapsed, double eta);
  void *progress_ctx;
  /* Called when a set-up phase starts and during long ones (the guide's
   * training passes), from the calling thread (may be NULL): `what` says what
   * runs ("tracing photons", "training pass 3 of 9, 16 spp"), `elapsed` is
   * seconds since the render started, `eta_first_image` the estimated seconds
   * until the first image pass starts (< 0: not known yet). */
  void (*phase)(void *ctx, const char *what, double elapsed, double eta_first_image);
  void *phase_ctx;
  bool no_passes; /* build everything (the guide: --guide-out), run no image pass */
  /* Keep the guide's training samples in the image (docs/guiding.md,
   * "Training samples"): only a render that trains its guide itself and
   * starts at sample offset 0 has them. */
  bool keep_training;
  /* Connections to a light-vertex cache (vcache.h) for the guided methods:
   * IRIS_CONNECT_AUTO where the guide's opening is kept by at least
   * IRIS_CONNECT_MIN_SHARE of the caches, ON wherever the guide found one. */
  enum { IRIS_CONNECT_AUTO = 0, IRIS_CONNECT_OFF, IRIS_CONNECT_ON } connect;
  /* With the sky's connections: the probability with which a camera vertex
   * that shares the map's light with them samples the map, in place of the
   * one from its share (0, the default); tests set it to make that branch,
   * and its density, weigh. */
  float connect_sky_map_q;
  /* Light tracing of glossy caustics (light_trace.h) with mis: AUTO where
   * a surface qualifies and the scene places no instanced mesh, OFF never. */
  enum { IRIS_LIGHT_TRACE_AUTO = 0, IRIS_LIGHT_TRACE_OFF } light_trace;
  const iris_guide_provider *guide; /* needed by the guided methods */
  const void *guide_options;        /* handed to guide->build (guiding: iris_guiding_params) */
  /* Partitioned renders (docs/distributed.md): sample indices sample_offset ..
   * sample_offset + spp - 1 of the pixels in `bounds` only. Pixels keep their
   * full-frame index for the sampler, so a part equals the same samples and
   * pixels of the whole render bit for bit. Defaults: 0 and the whole frame. */
  uint64_t sample_offset;
  iris_pixel_bounds bounds;         /* all 0: the whole frame */
  uint64_t config_hash;             /* options iris_render cannot see (the guide's), for iris:config_hash */
  /* time_budget covers setup (accel, textures, lights, guide) too: wall-clock
   * budgets for iris bench. At least one pass always runs. Default false. */
  bool budget_includes_setup;
  /* Adaptive sampling (renderer/adaptive.h; rule OFF: every pixel `spp`).
   * With it, spp is the per-pixel cap (unset: IRIS_RENDER_ADAPTIVE_DEFAULT_CAP,
   * not the scene's spp) and time_budget a cap too. */
  iris_adaptive_params adaptive;
  /* Called after each adaptive round from the calling thread (may be NULL). */
  void (*adaptive_progress)(void *ctx, const iris_adaptive_progress *p);
} iris_render_params;

/* Defaults: everything unset (taken from the scene, else 64 spp, auto, max
 * depth 64), seed 0, all cores, Russian roulette from bounce 3. */
iris_render_params iris_render_params_default(void);
/* Fills unset params (spp, max depth, method, seed) from the scene's render
 * settings and then from the defaults. */
void iris_render_params_from_scene(iris_render_params *p, const iris_scene *scene);

#define IRIS_METHOD_REASON_SIZE 240

typedef struct iris_render_result {
  iris_film film;
  iris_pinhole camera;
  iris_method method;           /* the method the paths used (auto resolved) */
  iris_method method_requested; /* the one asked for (flag, scene or default): may be auto */
  char method_reason[IRIS_METHOD_REASON_SIZE]; /* auto: "auto: guided-nee (75% of the photons
                                                  indirect)"; otherwise "" */
  bool raced;                   /* auto ran the race of mis against guided-nee */
  uint64_t connect_rays;        /* rays of the light paths the connections drew on (0: none ran; in stats.rays too) */
  uint64_t light_trace_rays;    /* rays of light tracing's paths (0: none ran; in stats.rays too); the
                                   paths are film.light_paths */
  iris_race_outcome race;       /* its measurements (when raced) */
  iris_sampler_kind sampler;
  iris_triangle_sampling light_sampling;
  iris_light_sampler light_sampler;
  double light_hidden_share; /* learned: the tree's hidden share at what the camera sees (light_hidden.h;
                                below IRIS_LIGHTS_HIDDEN_MIN the tree alone); -1 not measured */
  int spp;               /* samples per pixel completed in the image passes; adaptive: the
                            cap, the sample indices reserved (offset .. offset+spp-1; each
                            pixel's count is in the film) */
  iris_adaptive_params adaptive; /* as rendered (rule OFF: uniform) */
  iris_adaptive_outcome adaptive_outcome;
  int train_spp;         /* training samples per pixel also in the film (keep_training) */
  uint64_t seed;
  int threads;
  double seconds;        /* path tracing time (the passes) */
  double setup_seconds;  /* accel, textures, lights, guide */
  iris_path_stats stats;
  bool interrupted;
  uint64_t sample_offset;   /* first sample index */
  iris_pixel_bounds bounds; /* window rendered: the film covers it; camera.width/height is the frame */
  int max_depth;
  uint64_t scene_hash;      /* iris_merge_scene_hash */
  uint64_t config_hash;     /* frame size, camera, depths and params.config_hash */
} iris_render_result;

iris_status iris_render(const iris_scene *scene, const iris_render_params *params,
                        iris_render_result *result, iris_error *err);
void iris_render_result_destroy(iris_render_result *result);

/* EXR with R, G, B (+ var.R/G/B when `variance`; + a per-pixel sample count
 * channel "spp" when adaptive) and iris:version, scene,
 * method (the resolved one), method_requested, method_reason (auto), spp, seed, render_seconds, interrupted, ... metadata, and what
 * iris merge needs: sample_offset, window, full_size, scene_hash, config_hash. */
iris_status iris_render_write_exr(const iris_render_result *r, const char *path,
                                  const char *scene_name, bool variance, iris_error *err);
iris_status iris_render_write_png(const iris_render_result *r, const char *path, float exposure,
                                  iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
