/* The render loop: set-up, passes of samples over all pixels, output files. */
#include "renderer/render.h"
#include "renderer/light_hidden.h"
#include "renderer/vcache.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/cancel.h"
#include "core/image.h"
#include "core/log.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "renderer/camera_path.h"
#include "renderer/memory.h"
#include "renderer/light_trace.h"
#include "renderer/merge.h"

#define TILE 8
/* Aim for passes of about this many paths: short enough to stop quickly on a
 * signal or a time budget, long enough that thread start-up does not show. */
#define PASS_PATHS (1u << 18)

iris_render_params iris_render_params_default(void) {
  iris_render_params p;
  memset(&p, 0, sizeof p);
  p.spp = 0;
  p.method = IRIS_METHOD_COUNT;
  p.max_depth = -1;
  p.rr_depth = IRIS_DEFAULT_RR_DEPTH;
  p.threads = 0;
  p.keep_training = IRIS_KEEP_TRAINING_DEFAULT;
  p.light_sampler = IRIS_LIGHT_SAMPLER_DEFAULT;
  return p;
}

void iris_render_params_from_scene(iris_render_params *p, const iris_scene *scene) {
  const iris_render_settings *rs = &scene->render;
  if (p->spp <= 0) p->spp = rs->spp > 0 ? rs->spp : IRIS_RENDER_DEFAULT_SPP;
  if (p->max_depth < 0) p->max_depth = rs->max_depth >= 0 ? rs->max_depth : IRIS_DEFAULT_MAX_DEPTH;
  if (p->method == IRIS_METHOD_COUNT) {
    iris_method m;
    p->method = rs->method[0] && iris_method_parse(rs->method, &m) ? m : IRIS_METHOD_AUTO;
  }
}

typedef struct pass_ctx {
  const iris_integrator *it;
  const iris_pinhole *cam;
  iris_film *film;
  uint64_t seed;
  uint64_t s0, s1; /* sample indices of this pass */
  int x0, y0, x1, y1; /* the window; the film covers it */
  int tiles_x;
  iris_path_stats *stats; /* one per thread */
} pass_ctx;

static void render_tiles(void *vctx, uint64_t begin, uint64_t end, int thread) {
  pass_ctx *c = (pass_ctx *)vctx;
  /* Count on the stack and add once per chunk: the per-thread records sit
   * side by side, and updating them per ray would share a cache line. */
  iris_path_stats local = {0};
  iris_path_stats *st = &local;
  for (uint64_t t = begin; t < end; t++) {
    int tx = c->x0 + (int)(t % (uint64_t)c->tiles_x) * TILE;
    int ty = c->y0 + (int)(t / (uint64_t)c->tiles_x) * TILE;
    for (int y = ty; y < ty + TILE && y < c->y1; y++)
      for (int x = tx; x < tx + TILE && x < c->x1; x++)
        for (uint64_t s = c->s0; s < c->s1; s++)
          iris_film_add(c->film, x - c->x0, y - c->y0, iris_camera_path(c->it, c->cam, c->seed, x, y, s, st));
  }
  iris_path_stats_add(&c->stats[thread], &local);
}

/* Ends the phase before (a stop request there becomes "interrupted while
 * <that phase>") and enters the next one. */
static iris_status enter_phase(const iris_render_params *p, iris_status st, const char *key, const char *what,
                               double t0, iris_error *err) {
  if (st != IRIS_OK) return st;
  if (iris_cancel_requested()) return iris_cancel_error(err);
  iris_phase_begin(key, what);
  if (p->phase) p->phase(p->phase_ctx, what, iris_time_now() - t0, -1.0);
  return IRIS_OK;
}

/* What both kinds of connections share: the side tolerance and shortest
 * connection from the opening's size, pixels/8 light paths per sample index
 * (256-2048, of the whole frame: the same for any window or part), the seed. */
static void connect_settings(iris_vcache_params *vp, float size, float min_distance, const iris_pinhole *cam,
                             const iris_render_params *p) {
  const uint64_t frame = (uint64_t)cam->width * (uint64_t)cam->height / 8u;
  vp->eps = 1e-4f * size;
  vp->min_d2 = iris_sqr(min_distance * size);
  vp->paths = (uint32_t)(frame < 256 ? 256 : frame > 2048 ? 2048 : frame);
  vp->seed = p->seed;
  vp->threads = p->threads;
}

static iris_status render(const iris_scene *scene, const iris_render_params *params_in,
                          iris_render_result *res, iris_error *err);

iris_status iris_render(const iris_scene *scene, const iris_render_params *params_in,
                        iris_render_result *res, iris_error *err) {
  volatile sig_atomic_t *before = params_in->cancel ? iris_cancel_watch(params_in->cancel) : NULL;
  iris_status st = render(scene, params_in, res, err);
  if (params_in->cancel) iris_cancel_watch(before);
  return st;
}

static iris_status render(const iris_scene *scene, const iris_render_params *params_in,
                          iris_render_result *res, iris_error *err) {
  memset(res, 0, sizeof *res);
  res->light_hidden_share = -1.0;
  iris_render_params p = *params_in;
  const bool adaptive = p.adaptive.rule != IRIS_ADAPTIVE_OFF;
  if (adaptive && p.spp <= 0) p.spp = IRIS_RENDER_ADAPTIVE_DEFAULT_CAP; /* a cap, not the scene's count */
  iris_render_params_from_scene(&p, scene);
  if (p.threads <= 0) p.threads = iris_parallel_default_threads();
  res->method_requested = p.method;
  if (p.method == IRIS_METHOD_AUTO && (!p.guide || !p.guide->build || !p.guide->decision)) {
    /* nothing to decide with: mis, at no cost */
    p.method = IRIS_METHOD_MIS;
    snprintf(res->method_reason, sizeof res->method_reason, "auto: mis (the guiding module is not linked in)");
  }
  if (iris_method_uses_guiding(p.method) && (!p.guide || !p.guide->build))
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL,
                          "method '%s' needs the guiding module, which is not linked in",
                          iris_method_name(p.method));
  double t0 = iris_time_now();
  iris_status st = iris_pinhole_setup(scene, p.camera_name, p.width, p.height, &res->camera, err);
  if (st != IRIS_OK) return st;
  iris_pixel_bounds b = p.bounds;
  if (b.x0 == 0 && b.y0 == 0 && b.x1 == 0 && b.y1 == 0) {
    b.x1 = res->camera.width;
    b.y1 = res->camera.height;
  }
  if (b.x0 < 0 || b.y0 < 0 || b.x0 >= b.x1 || b.y0 >= b.y1 || b.x1 > res->camera.width ||
      b.y1 > res->camera.height)
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL,
                          "pixel bounds %d,%d,%d,%d are empty or outside the %dx%d frame", b.x0,
                          b.y0, b.x1, b.y1, res->camera.width, res->camera.height);
  if (p.sample_offset > (1ull << 52))
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "sample offset %llu is too large",
                          (unsigned long long)p.sample_offset);
  res->bounds = b;
  res->sample_offset = p.sample_offset;
  res->max_depth = p.max_depth;
  res->scene_hash = iris_merge_scene_hash(scene);
  {
    /* everything besides the scene, seed and method that changes the image */
    uint64_t h = iris_hash4((uint64_t)res->camera.width, (uint64_t)res->camera.height,
                            (uint64_t)p.max_depth, (uint64_t)p.rr_depth);
    for (const char *c = res->camera.name; *c; c++) h = iris_mix64(h ^ (unsigned char)*c);
    /* the independent sampler keeps the hash parts had before samplers existed */
    res->config_hash = iris_hash4(h, p.config_hash, 0x5eedULL, 1);
    if (p.sampler != IRIS_SAMPLER_INDEPENDENT || p.light_sampling != IRIS_TRIANGLE_SAMPLING_SOLID_ANGLE)
      res->config_hash = iris_hash4(res->config_hash, (uint64_t)p.sampler, (uint64_t)p.light_sampling, 0x5a3b1e7ULL);
    /* adaptive sampling decides each pixel's count: parts must agree on it */
    if (adaptive)
      res->config_hash = iris_hash4(res->config_hash, (uint64_t)p.adaptive.rule,
                                    (uint64_t)(p.adaptive.noise_threshold * 1e9), 0xada7ULL);
    /* the power sampler keeps the hash renders had before the light tree */
    if (p.light_sampler != IRIS_LIGHT_SAMPLER_POWER)
      res->config_hash = iris_hash4(res->config_hash, (uint64_t)p.light_sampler, 0x7ee11ULL, 2);
    /* connections asked for or refused: parts must agree (the default keeps the hash) */
    if (p.connect != IRIS_CONNECT_AUTO) res->config_hash = iris_hash4(res->config_hash, (uint64_t)p.connect, 0xc0ecULL, 3);
    if (p.connect_sky_map_q > 0.0f)
      res->config_hash = iris_hash4(res->config_hash, (uint64_t)(p.connect_sky_map_q * 1e9), 0xc0ecULL, 4);
    /* light tracing refused: parts must agree (the default keeps the hash) */
    if (p.light_trace != IRIS_LIGHT_TRACE_AUTO)
      res->config_hash = iris_hash4(res->config_hash, (uint64_t)p.light_trace, 0x11e7ULL, 5);
  }
  /* What the render will need against what the machine has, before any of it
   * is built (docs/performance.md, "Memory estimate"). Logged (with the
   * accel's line) only once the set-up succeeded: bad input stays one line. */
  char mem_line[400], accel_line[300] = "";
  {
    iris_memory_estimate est;
    iris_memory_estimate_scene(scene, b.x1 - b.x0, b.y1 - b.y0,
                               p.method == IRIS_METHOD_AUTO || iris_method_uses_guiding(p.method) ||
                                   p.light_sampler == IRIS_LIGHT_SAMPLER_LEARNED,
                               &est);
    if (adaptive) { /* the scout film (window and halo) and the per-pixel plans */
      uint64_t extra = (uint64_t)(IRIS_ADAPTIVE_BYTES_PER_PIXEL * (double)(b.x1 - b.x0 + 2) * (double)(b.y1 - b.y0 + 2));
      est.film += extra;
      est.total += extra;
    }
    iris_memory_format(&est, mem_line, sizeof mem_line);
    st = iris_memory_check(&est, scene->source_path ? scene->source_path : "scene", err);
    if (st != IRIS_OK) return st;
  }
  iris_accel *accel = NULL;
  iris_textures textures;
  iris_lights lights;
  memset(&textures, 0, sizeof textures);
  memset(&lights, 0, sizeof lights);
  void *guide_state = NULL;
  iris_path_stats *stats = NULL;
  st = enter_phase(&p, IRIS_OK, "bvh", "building the BVH", t0, err);
  if (st == IRIS_OK) st = iris_accel_build(scene, &accel, err);
  if (st == IRIS_OK) {
    size_t unique = 0, placed = 0;
    iris_accel_stats(accel, &unique, &placed);
    snprintf(accel_line, sizeof accel_line,
             "accel: %u triangles in the world; %zu meshes built once for %zu instanced placements, "
             "%zu placements flattened; BVH %.1f MB (Embree), vertex copies and tables %.1f MB",
             iris_accel_triangle_count(accel), unique, placed, scene->instance_count - placed,
             (double)iris_accel_embree_bytes(accel) / 1e6, (double)iris_accel_memory_bytes(accel) / 1e6);
  }
  st = enter_phase(&p, st, "textures", "decoding textures", t0, err);
  if (st == IRIS_OK) st = iris_textures_load(scene, &textures, err);
  if (st == IRIS_OK) iris_accel_set_textures(accel, &textures); /* alpha-textured surfaces */
  st = enter_phase(&p, st, "lights", "building the light tables", t0, err);
  if (st == IRIS_OK) st = iris_lights_build(scene, accel, &textures, &lights, err);
  if (st == IRIS_OK) iris_lights_set_triangle_sampling(&lights, p.light_sampling);
  if (st == IRIS_OK) st = iris_lights_set_sampler(&lights, p.light_sampler, err);
  iris_integrator it;
  if (st == IRIS_OK) {
    it = iris_integrator_default(scene, accel, &lights, &textures);
    it.method = p.method;
    it.sampler = p.sampler;
    it.max_depth = p.max_depth;
    it.rr_depth = p.rr_depth;
  }
  const bool resolve = p.method == IRIS_METHOD_AUTO;
  /* --light-sampler learned: the guide's caches learn which lights they see
   * (a tree of more than one leaf to learn over, a provider that can). */
  bool learned = st == IRIS_OK && p.light_sampler == IRIS_LIGHT_SAMPLER_LEARNED && lights.tree && p.guide &&
                 p.guide->light_select && p.guide->build_lights && iris_method_uses_nee(resolve ? IRIS_METHOD_MIS : p.method);
  if (learned) {
    /* Where the tree's choices at what the camera sees are rarely hidden,
     * there is nothing to learn: the tree alone, without the photons. */
    int valid = 0;
    double hidden = iris_lights_camera_hidden_share(&lights, accel, &res->camera, p.seed, &valid);
    res->light_hidden_share = hidden;
    if (hidden < IRIS_LIGHTS_HIDDEN_MIN) {
      learned = false;
      iris_infof("learned light selection: the tree alone (%.1f%% of its choices at %d points the camera sees are "
                 "hidden, < %.0f%%)",
                 100.0 * hidden, valid, 100.0 * IRIS_LIGHTS_HIDDEN_MIN);
    } else {
      iris_infof("learned light selection: %.1f%% of the tree's choices at %d points the camera sees are hidden",
                 100.0 * hidden, valid);
    }
  }
  void *light_state = NULL; /* the guide built for the light choice alone (nee, mis) */
  iris_vcache *vcache = NULL; /* connections to a light-vertex cache (vcache.h) */
  if (st == IRIS_OK && resolve) it.method = IRIS_METHOD_GUIDED_NEE; /* the guide builds for it */
  if (st == IRIS_OK && iris_cancel_requested()) st = iris_cancel_error(err); /* in the light tables */
  if (st == IRIS_OK) st = iris_film_create(&res->film, b.x1 - b.x0, b.y1 - b.y0, err);
  /* Training samples go into the image only for the render that owns sample
   * indices from 0 and trains its guide itself (docs/guiding.md). */
  const bool keep_training = p.keep_training && p.sample_offset == 0 && !p.no_passes;
  /* Light tracing (light_trace.h) for mis, and for auto before it decides:
   * where it runs, mis gets the reflectors' caustics that the caustic rule
   * kept the guide for (the glass spheres: 1.9x less relMSE than guided-nee
   * at 4 s), so auto's rules ask whether it does. */
  iris_light_trace *light_trace = NULL;
  if (st == IRIS_OK && p.light_trace != IRIS_LIGHT_TRACE_OFF && !p.no_passes &&
      (resolve || p.method == IRIS_METHOD_MIS)) {
    iris_integrator plain = it;
    plain.method = IRIS_METHOD_MIS;
    st = iris_light_trace_create(&plain, &res->camera, b.x0, b.y0, b.x1, b.y1, p.seed, p.threads, &light_trace, err);
  }
  if (st == IRIS_OK && (resolve || iris_method_uses_guiding(p.method))) {
    /* the guide sizes its training by the render's spp: with adaptive
     * sampling that is a cap, so it gets 4x the minimum instead */
    int guide_spp = p.spp;
    if (adaptive) {
      int m = p.adaptive.min_spp > 0             ? p.adaptive.min_spp
              : p.adaptive.noise_threshold > 0.0 ? iris_adaptive_auto_min_spp(p.adaptive.noise_threshold)
                                                 : IRIS_ADAPTIVE_MIN_SPP_NO_THRESHOLD;
      if (4 * m < guide_spp) guide_spp = 4 * m;
    }
    iris_guide_setup gs = {scene, accel, &lights, &textures, &res->camera, &it, p.seed, p.threads,
                           p.guide_options, p.time_budget > 0.0 ? 0 : guide_spp,
                           p.time_budget > 0.0 ? p.time_budget : 0.0, p.sampler, resolve,
                           p.phase, p.phase_ctx, t0, keep_training ? &res->film : NULL, b, learned,
                           light_trace != NULL};
    st = p.guide->build(&gs, &it.guide, &guide_state, err);
  }
  /* Connections to a light-vertex cache (docs/guiding.md, "Connections to a
   * light-vertex cache"): where the guide found an opening most caches'
   * light came through, with its plane as the regions' border. Its pools
   * depend on the seed and the whole frame only, not on windows, offsets or
   * threads. */
  if (st == IRIS_OK && p.connect != IRIS_CONNECT_OFF && it.guide.opening && lights.tri_count > 0) {
    iris_vcache_params vp;
    memset(&vp, 0, sizeof vp);
    float size = 0.0f, share = 0.0f;
    if (it.guide.opening(it.guide.ctx, &vp.o, &vp.n, &size, &share) &&
        (p.connect == IRIS_CONNECT_ON || share >= IRIS_CONNECT_MIN_SHARE) && size > 0.0f) {
      connect_settings(&vp, size, IRIS_CONNECT_MIN_DISTANCE, &res->camera, &p);
      st = iris_vcache_create(&vcache, &vp, &it, err);
      if (st == IRIS_OK) {
        it.vcache = vcache;
        iris_infof("connections: to a light-vertex cache behind the opening at (%.3g, %.3g, %.3g) kept by %.0f%% of "
                   "the caches, %u light paths per sample index",
                   vp.o.x, vp.o.y, vp.o.z, 100.0 * share, vp.paths);
      }
    }
  }
  /* ... else where the sky is seen through windows that together a share of
   * the caches draw from: light vertices the sky lit through them (vcache.h,
   * `sky`), the light paths shared among the windows by the power entering. */
  if (st == IRIS_OK && !vcache && p.connect != IRIS_CONNECT_OFF && it.guide.sky_windows && lights.envmap) {
    iris_vcache_params vp;
    memset(&vp, 0, sizeof vp);
    enum { K = IRIS_VCACHE_SKY_WINDOWS };
    iris_vec3 wo[K], wu[K], wv[K];
    float flux[K], share[K];
    int k = it.guide.sky_windows(it.guide.ctx, lights.envmap, K, wo, wu, wv, flux, share);
    /* a window of little power (none found, or a small share of the
     * brightest's) starts no light paths: the camera keeps its light, where
     * the few light paths it would get would weigh much (the list is by flux) */
    while (k > 1 && !(flux[k - 1] > IRIS_CONNECT_SKY_MIN_FLUX * flux[0])) --k;
    double total = 0.0;
    float size = 0.0f, shares = 0.0f;
    for (int j = 0; j < k; ++j) shares += share[j];
    bool ok = k > 0 && (p.connect == IRIS_CONNECT_ON || shares >= IRIS_CONNECT_MIN_SHARE);
    for (int j = 0; j < k && ok; ++j) {
      const iris_vec3 nn = iris_cross(wu[j], wv[j]);
      const float nl = iris_length(nn);
      ok = nl > 0.0f && isfinite(nl) && flux[j] >= 0.0f && isfinite(flux[j]);
      vp.window[j] = (iris_vcache_window){wo[j], iris_scale(nn, 1.0f / nl), wu[j], wv[j], 4.0f * nl, 0.0f};
      size = fmaxf(size, 2.0f * fmaxf(iris_length(wu[j]), iris_length(wv[j])));
      total += flux[j];
    }
    if (ok && size > 0.0f) {
      /* light paths start on each window in proportion to the power entering through it */
      for (int j = 0; j < k; ++j) vp.window[j].prob = k == 1 ? 1.0f : (float)(flux[j] / total);
      vp.windows = k;
      vp.sky = true;
      connect_settings(&vp, size, 0.0f, &res->camera, &p);
      vp.mis_c = IRIS_CONNECT_SKY_MIS_C;
      vp.map_q = p.connect_sky_map_q;
      st = iris_vcache_create(&vcache, &vp, &it, err);
      if (st == IRIS_OK && vcache) {
        it.vcache = vcache;
        char where[4 * 80]; /* up to four windows */
        int n = 0;
        for (int j = 0; j < k && n >= 0 && (size_t)n < sizeof where; ++j)
          n += snprintf(where + n, sizeof where - (size_t)n, "%s(%.3g, %.3g, %.3g) drawn from by %.0f%% of the caches",
                        j ? ", " : "", vp.window[j].o.x, vp.window[j].o.y, vp.window[j].o.z, 100.0 * share[j]);
        iris_infof("connections: to light vertices the sky lit through %s at %s, %u light paths per sample index",
                   k == 1 ? "the window" : k == 2 ? "two windows" : k == 3 ? "three windows" : "four windows", where,
                   vp.paths);
      }
    }
  }
  if (st == IRIS_OK && resolve) {
    /* --method auto: guided-nee where the guide says it is of use and it wins
     * the race (or the guide settles it), else mis
     * without keeping any of the guide (docs/guiding.md, "--method auto"). */
    char why[IRIS_METHOD_REASON_SIZE - 32];
    why[0] = 0;
    bool settled = false;
    bool use = p.guide->decision(guide_state, why, sizeof why, &settled);
    if (use && !settled && !p.no_passes) {
      /* the rules leave guided-nee: a race against mis decides (method_race.h) */
      st = enter_phase(&p, st, "race", "racing mis against guided-nee", t0, err);
      if (st == IRIS_OK && learned) lights.learned = p.guide->light_select(guide_state);
      iris_integrator plain = it;
      plain.method = IRIS_METHOD_MIS;
      memset(&plain.guide, 0, sizeof plain.guide);
      plain.vcache = NULL;
      it.method = IRIS_METHOD_GUIDED_NEE;
      if (st == IRIS_OK)
        st = iris_method_race(&plain, &it, &res->camera, p.seed, p.threads,
                              p.time_budget > 0.0 ? IRIS_RACE_BUDGET_SHARE * p.time_budget : 0.0, &res->race, why,
                              sizeof why, err);
      memset(&lights.learned, 0, sizeof lights.learned);
      if (st == IRIS_OK) {
        res->raced = true;
        use = res->race.guided;
        const iris_race_outcome *o = &res->race;
        const double np = (double)o->paths;
        iris_infof("auto: race of %llu paths each (%llu before it went on for a decision; speedup %.3f, log standard "
                   "error %.3f) (per path: rays, shadow rays, guide prepares, guide calls; seconds): "
                   "mis %.2f %.2f %.2f %.2f %.3f s, relative variance %.4g; guided-nee %.2f %.2f %.2f %.2f %.3f s, "
                   "relative variance %.4g; light guided-nee/mis %.3f (z %.1f); variance in the largest 0.1%%: "
                   "mis %.0f%%, guided-nee %.0f%%",
                   (unsigned long long)o->paths, (unsigned long long)o->base_paths, o->speedup, o->log_speedup_se,
                   o->rays[0] / np, o->shadow_rays[0] / np, o->prepares[0] / np,
                   o->guide_calls[0] / np, o->seconds[0], o->relvar[0], o->rays[1] / np, o->shadow_rays[1] / np,
                   o->prepares[1] / np, o->guide_calls[1] / np, o->seconds[1], o->relvar[1],
                   o->light[0] > 0.0 ? o->light[1] / o->light[0] : 1.0, o->short_z, 100.0 * o->tail_share[0],
                   100.0 * o->tail_share[1]);
      }
    }
    p.method = use ? IRIS_METHOD_GUIDED_NEE : IRIS_METHOD_MIS;
    it.method = p.method;
    snprintf(res->method_reason, sizeof res->method_reason, "auto: %s (%s)", iris_method_name(p.method), why);
    if (!use) {
      memset(&it.guide, 0, sizeof it.guide);
      it.vcache = NULL;
      /* The race chose mis: the trained guide's learned light tables serve it
       * (learned from the training's light samples too, and not built twice). */
      if (!(learned && res->raced)) {
        if (guide_state && p.guide->destroy) p.guide->destroy(guide_state);
        guide_state = NULL;
      }
    }
  }
  if (st == IRIS_OK && learned && guide_state) lights.learned = p.guide->light_select(guide_state);
  if (st == IRIS_OK && learned && !lights.learned.choose) { /* no guide, or one that skipped the scene */
    iris_guide_setup gs = {scene, accel, &lights, &textures, &res->camera, &it, p.seed, p.threads,
                           p.guide_options, p.time_budget > 0.0 ? 0 : p.spp,
                           p.time_budget > 0.0 ? p.time_budget : 0.0, p.sampler, false,
                           p.phase, p.phase_ctx, t0, NULL, b, true, false};
    st = p.guide->build_lights(&gs, &light_state, err);
    if (st == IRIS_OK) lights.learned = p.guide->light_select(light_state);
  }
  if (st == IRIS_OK && iris_cancel_requested()) st = iris_cancel_error(err); /* in the guide's last phase */
  if (st == IRIS_OK) {
    iris_infof("memory: %s", mem_line);
    iris_infof("%s", accel_line);
  }
  /* every pixel holds the same number of training samples (whole passes) */
  if (st == IRIS_OK && res->film.count) res->train_spp = (int)res->film.count[0];
  /* Light tracing of glossy caustics (light_trace.h, created above): with
   * mis only; the light paths of sample index s are [s P, (s + 1) P) (uniform
   * passes) or follow the rounds' samples from offset P (adaptive). */
  if (light_trace && (st != IRIS_OK || p.method != IRIS_METHOD_MIS)) {
    iris_light_trace_destroy(light_trace);
    light_trace = NULL;
  }
  if (st == IRIS_OK && light_trace) st = iris_film_light_paths_enable(&res->film, err);
  if (st == IRIS_OK && light_trace) {
    it.light_trace = light_trace;
    light_trace->next = p.sample_offset * light_trace->per_index;
    char kinds[240] = "", *k = kinds;
    if (light_trace->glossy)
      k += snprintf(k, 120, "off %zu glossy reflector triangles (%.3g m^2)", light_trace->select.count,
                    1.0 / light_trace->inv_area);
    if (light_trace->delta)
      snprintf(k, 120, "%sthe sun through %zu glass or mirror triangles (%.3g m^2)", light_trace->glossy ? ", and " : "",
               light_trace->dselect.count, 1.0 / light_trace->inv_darea);
    iris_infof("light tracing: %llu light paths per sample index %s", (unsigned long long)light_trace->per_index, kinds);
  }
  if (st == IRIS_OK) {
    stats = calloc((size_t)p.threads, sizeof *stats);
    if (!stats) st = iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory");
  }
  res->method = p.method;
  res->sampler = p.sampler;
  res->light_sampling = p.light_sampling;
  res->light_sampler = p.light_sampler;
  res->seed = p.seed;
  res->threads = p.threads;
  double t1 = iris_time_now();
  res->setup_seconds = t1 - t0;

  res->adaptive = p.adaptive;
  if (st == IRIS_OK && !p.no_passes && adaptive) {
    const bool timed = p.time_budget > 0.0;
    iris_adaptive_job job = {&it, &res->camera, &res->film, p.seed, p.sample_offset, b.x0, b.y0, b.x1, b.y1,
                             p.threads, stats, p.spp + res->train_spp,
                             timed ? p.time_budget - (p.budget_includes_setup ? res->setup_seconds : 0.0) : 0.0,
                             p.adaptive_progress, p.progress_ctx, p.adaptive, light_trace};
    if (timed && job.budget <= 0.0) job.budget = 1e-3; /* at least one round */
    iris_phase_begin("first-pass", "rendering the first image pass");
    if (p.phase) p.phase(p.phase_ctx, "rendering the first image pass", iris_time_now() - t0, 0.0);
    st = iris_adaptive_run(&job, &res->adaptive_outcome, err);
    if (st == IRIS_OK && res->adaptive_outcome.interrupted) {
      res->interrupted = true;
      /* a pixel without samples: no image, as when the first pass is cut */
      if (res->adaptive_outcome.rounds == 0 || res->adaptive_outcome.spp_min == 0) st = iris_cancel_error(err);
    }
    /* the reserved sample range (the cap): a part at the next offset cannot overlap */
    res->spp = p.spp;
    res->seconds = iris_time_now() - t1;
    for (int i = 0; i < p.threads; i++) iris_path_stats_add(&res->stats, &stats[i]);
  }
  if (st == IRIS_OK && !p.no_passes && !adaptive) {
    const uint64_t pixels = (uint64_t)res->film.width * (uint64_t)res->film.height;
    pass_ctx c;
    memset(&c, 0, sizeof c);
    c.it = &it;
    c.cam = &res->camera;
    c.film = &res->film;
    c.seed = p.seed;
    c.x0 = b.x0;
    c.y0 = b.y0;
    c.x1 = b.x1;
    c.y1 = b.y1;
    c.stats = stats;
    c.tiles_x = (res->film.width + TILE - 1) / TILE;
    int tiles_y = (res->film.height + TILE - 1) / TILE;
    uint64_t tiles = (uint64_t)c.tiles_x * (uint64_t)tiles_y;
    int pass_spp = (int)((PASS_PATHS + pixels - 1) / pixels);
    if (pass_spp < 1) pass_spp = 1;
    const bool timed = p.time_budget > 0.0;
    const double budget = p.time_budget - (p.budget_includes_setup ? res->setup_seconds : 0.0);
    const int target = timed ? 0 : p.spp;
    int done = 0;
    double sec_per_spp = 0.0;
    iris_phase_begin("first-pass", "rendering the first image pass");
    if (p.phase) p.phase(p.phase_ctx, "rendering the first image pass", iris_time_now() - t0, 0.0);
    for (;;) {
      if (iris_cancel_requested()) {
        if (done == 0) st = iris_cancel_error(err); /* no sample: nothing to write */
        res->interrupted = true;
        break;
      }
      int n = pass_spp;
      double elapsed = iris_time_now() - t1;
      if (timed) {
        if (done > 0) {
          double left = budget - elapsed;
          int fit = sec_per_spp > 0.0 ? (int)(left / sec_per_spp) : n;
          if (fit < 1) break; /* the next whole pass would overrun the budget */
          if (fit < n) n = fit;
        } else {
          n = 1; /* measure first */
        }
      } else {
        if (done >= target) break;
        if (n > target - done) n = target - done;
      }
      c.s0 = p.sample_offset + (uint64_t)done;
      c.s1 = c.s0 + (uint64_t)n;
      double tp = iris_time_now();
      uint64_t grain = tiles / (uint64_t)(8 * p.threads) + 1;
      if (grain > 4) grain = 4;
      iris_parallel_for(tiles, grain, p.threads, render_tiles, &c);
      if (light_trace) { /* the light paths of these sample indices */
        st = iris_light_trace_run(light_trace, &it, c.s0 * light_trace->per_index,
                                  (uint64_t)n * light_trace->per_index, &res->film, err);
        if (st != IRIS_OK) break;
      }
      double dt = iris_time_now() - tp;
      if (done == 0) iris_phase_begin("image", "rendering image passes");
      done += n;
      sec_per_spp = dt / n;
      double now = iris_time_now() - t1;
      if (p.progress) {
        int total = timed ? done + (int)((budget - now) / (sec_per_spp > 0 ? sec_per_spp : 1)) : target;
        if (total < done) total = done;
        double eta = timed ? (budget - now > 0 ? budget - now : 0)
                           : (target - done) * sec_per_spp;
        p.progress(p.progress_ctx, done, total, now, eta);
      }
    }
    res->spp = done;
    res->seconds = iris_time_now() - t1;
    for (int i = 0; i < p.threads; i++) iris_path_stats_add(&res->stats, &stats[i]);
  }
  free(stats);
  if (light_trace) { /* the light paths' rays count with the render's */
    res->light_trace_rays = light_trace->rays;
    iris_infof("light tracing: %.0f light paths, %llu (%.2f%%) added to a pixel, %.4g per pixel and path",
               res->film.light_paths, (unsigned long long)light_trace->splats,
               res->film.light_paths > 0 ? 100.0 * (double)light_trace->splats / res->film.light_paths : 0.0,
               res->film.light_paths > 0 ? light_trace->energy / res->film.light_paths /
                                              ((double)(b.x1 - b.x0) * (double)(b.y1 - b.y0)) : 0.0);
    res->stats.rays += light_trace->rays;
    iris_light_trace_destroy(light_trace);
  }
  if (vcache) { /* the light paths' rays count with the render's */
    res->connect_rays = iris_vcache_rays(vcache);
    res->stats.rays += res->connect_rays;
    iris_vcache_destroy(vcache);
  }
  memset(&lights.learned, 0, sizeof lights.learned);
  if (guide_state && p.guide && p.guide->destroy) p.guide->destroy(guide_state);
  if (light_state && p.guide && p.guide->destroy) p.guide->destroy(light_state);
  iris_lights_destroy(&lights);
  iris_textures_destroy(&textures);
  iris_accel_destroy(accel);
  if (st != IRIS_OK) iris_film_destroy(&res->film);
  return st;
}

void iris_render_result_destroy(iris_render_result *r) {
  if (r) iris_film_destroy(&r->film);
}

iris_status iris_render_write_exr(const iris_render_result *r, const char *path,
                                  const char *scene_name, bool variance, iris_error *err) {
  iris_image img;
  const bool adaptive = r->adaptive.rule != IRIS_ADAPTIVE_OFF;
  iris_status st = iris_film_to_image_counts(&r->film, variance, adaptive, &img, err);
  if (st != IRIS_OK) return st;
  iris_image_meta meta[40];
  size_t n = 0;
#define META(k, ...) \
  do { \
    snprintf(meta[n].key, sizeof meta[n].key, "iris:%s", k); \
    snprintf(meta[n].value, sizeof meta[n].value, __VA_ARGS__); \
    n++; \
  } while (0)
  META("version", "%s", IRIS_VERSION_STRING);
  META("scene", "%s", scene_name ? scene_name : "");
  META("method", "%s", iris_method_name(r->method));
  META("method_requested", "%s", iris_method_name(r->method_requested));
  if (r->method_reason[0]) META("method_reason", "%s", r->method_reason);
  META("sampler", "%s", iris_sampler_kind_name(r->sampler));
  META("light_sampling", "%s", iris_triangle_sampling_name(r->light_sampling));
  META("light_sampler", "%s", iris_light_sampler_name(r->light_sampler));
  META("connect", "%s", r->connect_rays > 0 ? "on" : "off"); /* connections to a light-vertex cache ran */
  META("light_paths", "%.0f", r->film.light_paths); /* light tracing's paths (0: none ran) */
  META("spp", "%d", r->spp);
  META("train_spp", "%d", r->train_spp);
  META("seed", "%llu", (unsigned long long)r->seed);
  META("render_seconds", "%.3f", r->seconds);
  META("interrupted", "%s", r->interrupted ? "true" : "false");
  META("camera", "%s", r->camera.name);
  META("threads", "%d", r->threads);
  META("nan_count", "%llu", (unsigned long long)r->stats.nan_count);
  META("max_depth", "%d", r->max_depth);
  META("sample_offset", "%llu", (unsigned long long)r->sample_offset);
  META("window", "%d,%d,%d,%d", r->bounds.x0, r->bounds.y0, r->bounds.x1, r->bounds.y1);
  META("full_size", "%d,%d", r->camera.width, r->camera.height);
  META("scene_hash", "%016llx", (unsigned long long)r->scene_hash);
  META("config_hash", "%016llx", (unsigned long long)r->config_hash);
  if (adaptive) {
    const iris_adaptive_outcome *o = &r->adaptive_outcome;
    META("adaptive", "%s", iris_adaptive_rule_name(r->adaptive.rule));
    META("noise_threshold", "%g", r->adaptive.noise_threshold);
    META("target_error", "%g", r->adaptive.target_error);
    META("error_estimate", "%.6g", o->error_estimate);
    META("spp_mean", "%.3f", o->spp_mean);
    META("spp_range", "%d,%d", o->spp_min, o->spp_max);
    META("scout_spp_mean", "%.3f", o->scout_spp_mean);
    META("adaptive_stop", "%s", iris_adaptive_stop_name(o));
  }
#undef META
  st = iris_exr_write(path, &img, meta, n, err);
  iris_image_destroy(&img);
  return st;
}

iris_status iris_render_write_png(const iris_render_result *r, const char *path, float exposure,
                                  iris_error *err) {
  iris_image img;
  iris_status st = iris_film_to_image(&r->film, false, &img, err);
  if (st != IRIS_OK) return st;
  st = iris_png_write(path, &img, 0, exposure, err);
  iris_image_destroy(&img);
  return st;
}
