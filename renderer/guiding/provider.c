/* The guide for iris_render (iris_guiding_provider): built, or read from a
 * file and written to one, described in the log, and its direction sampler
 * handed to the renderer; the guide's describe line. docs/guiding.md. */
#include "renderer/guiding/guiding.h"

#include <stdio.h>
#include <string.h>

#include "core/log.h"
#include "renderer/guiding/guide_file.h"
#include "renderer/merge.h"

/* A cache's share of the light that its guided samples draw from the map
 * (straight or through a pane), from lamps' cones or from glint spots' cones. */
static float share_sky(const iris_cache *c) { return c->sky_through; }
static float share_pane(const iris_cache *c) { return c->pane_share; }
static float share_lamps(const iris_cache *c) {
  float s = 0.0f;
  for (int k = 0; k < IRIS_CACHE_LAMPS; ++k) s += c->lamp_share[k];
  return s;
}
static float share_glints(const iris_cache *c) { return c->glint_share; }

/* Appends "; WHAT: N caches (mean share M)" over the caches with a share > 0. */
static void append_shares(char *buf, size_t size, const iris_guiding *g, const char *what,
                          float (*share)(const iris_cache *)) {
  double sum = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < g->cache_count; ++i) {
    float v = share(&g->caches[i]);
    if (v > 0.0f) sum += v, n++;
  }
  if (!n) return;
  size_t l = strlen(buf);
  snprintf(buf + l, size - l, "; %s: %zu caches (mean share %.2f)", what, n, sum / (double)n);
}

void iris_guiding_describe(const iris_guiding *g, char *buf, size_t size) {
  const iris_guiding_stats *s = &g->stats;
  if (s->skipped) {
    snprintf(buf, size, "guiding skipped (BSDF sampling instead): %s", s->reason);
    return;
  }
  /* learned selection probabilities: their mean over the caches that learned one */
  double asum = 0.0;
  size_t learned = 0;
  for (size_t i = 0; i < g->cache_count; ++i)
    if (g->caches[i].alpha >= 0.0f) asum += g->caches[i].alpha, learned++;
  char alpha[96];
  if (learned)
    snprintf(alpha, sizeof alpha, "alpha learned by %zu caches (mean %.2f), else %g", learned,
             asum / (double)learned, (double)g->params.alpha_max);
  else
    snprintf(alpha, sizeof alpha, "alpha <= %g", (double)g->params.alpha_max);
  char sky[384];
  iris_skyvis_describe(&g->sky, sky, sizeof sky);
  append_shares(sky, sizeof sky, g, "sky behind glass", share_sky);  /* "Sky behind glass" */
  append_shares(sky, sizeof sky, g, "sky through a pane", share_pane); /* "Sky through a pane" */
  append_shares(sky, sizeof sky, g, "lamps behind glass", share_lamps); /* "Lamps behind glass" */
  append_shares(sky, sizeof sky, g, "glints", share_glints);             /* "Glints" */
  if (s->portal_caches) { /* "Portals" */
    size_t l = strlen(sky);
    snprintf(sky + l, sizeof sky - l, "; portals: %llu caches", (unsigned long long)s->portal_caches);
  }
  if (s->caustic_share >= 0.0) { /* "--method auto": light focused through glass kept the guide */
    size_t l = strlen(sky);
    snprintf(sky + l, sizeof sky - l, "; kept for light focused through glass (%.0f%% of the indirect photon energy)",
             100.0 * s->caustic_share);
  }
  /* caches where light sampling became optional ("Light sampling where no light arrives") */
  size_t dark = 0;
  for (size_t i = 0; i < g->cache_count; ++i) dark += g->caches[i].light < 1.0f;
  if (dark) {
    size_t l = strlen(sky);
    snprintf(sky + l, sizeof sky - l, "; light sampling at p %g in %zu caches where it brought nothing",
             (double)g->params.light_min, dark);
  }
  snprintf(buf, size,
           "guiding: %llu photon paths -> %llu photons (%.0f%% indirect); %llu caches (%llu from "
           "camera rays every %d px, %llu empty dropped), %dx%d maps (%llu texels refined 4x4 in %llu caches), k=%d, "
           "floor %g, %s; "
           "preprocessing %.2f s (photons %.2f s, training %d spp in %d passes %.2f s)%s; cache memory %.1f MiB",
           (unsigned long long)s->photon_paths, (unsigned long long)s->photons_stored,
           s->photons_stored ? 100.0 * (double)s->photons_indirect / (double)s->photons_stored : 0.0,
           (unsigned long long)s->caches, (unsigned long long)s->camera_caches, s->camera_stride,
           (unsigned long long)s->empty_caches, s->cache_res, s->cache_res, (unsigned long long)s->refined_texels,
           (unsigned long long)s->refined_caches, s->cache_k,
           (double)s->pdf_floor, alpha, s->total_seconds, s->photon_seconds, s->train_spp, s->train_iterations, s->train_seconds, sky,
           (double)s->memory_bytes / (1024.0 * 1024.0));
}

/* ---- iris_render provider ---------------------------------------------------- */

/* The guide from a file (--guide-in) or built, and written (--guide-out):
 * both keyed by the scene hash and the settings hash (guide_file.h). */
static iris_status provider_guide(const iris_guide_setup *setup, const iris_guiding_params *p, iris_guiding **g,
                                  iris_error *err) {
  uint64_t scene_hash = 0, settings_hash = 0;
  if (p->guide_in || p->guide_out) {
    scene_hash = iris_merge_scene_hash(setup->scene);
    settings_hash = iris_guiding_settings_hash(setup, p);
  }
  iris_status st = p->guide_in ? iris_guiding_load(p->guide_in, scene_hash, settings_hash, setup->threads, g, err)
                               : iris_guiding_build(setup, p, g, err);
  if (st == IRIS_OK && p->guide_in && (*g)->lights.count &&
      (!setup->learn_lights || !iris_light_select_attach(&(*g)->lights, *g, setup->lights)))
    st = iris_error_set(err, IRIS_ERR_PARSE, p->guide_in, 0, NULL,
                        "guide file's learned light tables do not fit this scene's lights (corrupted)");
  if (st == IRIS_OK && p->guide_in) { /* not in the file: derived from the caches and the scene */
    (*g)->params.use_nee = p->use_nee;
    (*g)->params.sky_regions = p->sky_regions;
    (*g)->params.sky_probes = p->sky_probes;
    (*g)->params.sky_beta = p->sky_beta;
    st = iris_guiding_build_sky(*g, setup, err);
  }
  if (st == IRIS_OK && p->guide_out) st = iris_guiding_save(*g, p->guide_out, scene_hash, settings_hash, err);
  if (st != IRIS_OK) {
    iris_guiding_destroy(*g);
    *g = NULL;
  }
  return st;
}

static iris_status provider_build(const iris_guide_setup *setup, iris_direction_sampler *out,
                                  void **state, iris_error *err) {
  iris_guiding_params p = setup->options ? *(const iris_guiding_params *)setup->options
                                         : iris_guiding_params_default();
  p.use_nee = setup->integrator && iris_method_uses_nee(setup->integrator->method);
  iris_guiding *g = NULL;
  iris_status st = provider_guide(setup, &p, &g, err);
  if (st != IRIS_OK) return st;
  char line[768]; /* the describe line at 1080p with the sky: ~470 characters */
  iris_guiding_describe(g, line, sizeof line);
  if (p.guide_in) iris_infof("%s (read from %s)", line, p.guide_in);
  else iris_infof("%s", line);
  if (g->lights.count)
    iris_infof("learned light selection: %llu of %zu caches learned%s from %llu direct photons%s, beta %.2f",
               (unsigned long long)g->lights.learned_caches, g->lights.cache_count, p.guide_in ? " (read)" : "",
               (unsigned long long)g->lights.direct_photons,
               g->lights.nee_caches ? " and, in training, from light samples" : "", (double)g->lights.beta);
  if (g->lights.nee_caches)
    iris_infof("learned light selection: %llu tables from the training's light samples too",
               (unsigned long long)g->lights.nee_caches);
  g->env = setup->lights->envmap; /* the map the caches' sky behind glass is sampled from */
  *out = iris_guiding_sampler(g);
  *state = g;
  return IRIS_OK;
}

/* For methods without a guide of their own: the caches (built whatever the
 * skip rules say, no file) for the learned light choice, and, unless
 * --no-light-samples, training passes of direct light alone (camera ray, a
 * light sample and a direction at the first surface: about three rays a
 * sample), as many samples as guided-nee's training would take
 * (--train-spp; by default 5% of the render's), whose light samples teach the
 * tables what the camera sees. */
static iris_status provider_build_lights(const iris_guide_setup *setup, void **state, iris_error *err) {
  iris_guiding_params p = setup->options ? *(const iris_guiding_params *)setup->options
                                         : iris_guiding_params_default();
  p.use_nee = true;
  p.force = true;
  if (!p.light_samples) p.train_spp = 0;
  p.pilot_paths = 0;
  p.sky_probes = 0;
  p.guide_in = p.guide_out = NULL;
  p.dump_dir = NULL;
  p.marks = NULL;
  iris_direction_sampler unused;
  iris_guide_setup s = *setup;
  iris_integrator direct;
  if (setup->integrator) { /* training traces guided-nee's first vertex only */
    direct = *setup->integrator;
    direct.method = IRIS_METHOD_GUIDED_NEE;
    direct.max_depth = 0;
    s.integrator = &direct;
  }
  s.options = &p;
  s.film = NULL;
  s.deciding = false;
  return provider_build(&s, &unused, state, err);
}

static iris_light_learned provider_light_select(const void *state) {
  const iris_guiding *g = state;
  return iris_light_select_hooks(g && !g->stats.skipped ? &g->lights : NULL);
}

static void provider_destroy(void *state) { iris_guiding_destroy(state); }

static bool provider_decision(const void *state, char *why, size_t size, bool *settled) {
  const iris_guiding *g = state;
  *settled = false;
  if (!g) {
    snprintf(why, size, "no guide");
    return false;
  }
  if (g->stats.skipped) {
    snprintf(why, size, "%s", g->stats.reason);
    return false;
  }
  if (g->params.force) {
    *settled = true;
    snprintf(why, size, "guiding forced");
    return true;
  }
  if (g->stats.caustic_share >= 0.0) {
    /* kept only for light focused through glass: mis finds it as single rare
     * paths and the race's few paths per pixel rarely carry it (env-spheres
     * with a glass sphere: the race said 0.71-0.80x on every seed where renders
     * measure guided-nee 1.2-1.5x mis), so no race (docs/guiding.md,
     * "--method auto") */
    *settled = true;
    snprintf(why, size,
             "light focused through glass carries %.0f%% of the indirect photon energy, which mis finds only "
             "by chance and a race too rarely to measure: no race",
             100.0 * g->stats.caustic_share);
    return true;
  }
  if (g->stats.seen_indirect_energy >= 0.0) {
    snprintf(why, size, "%.0f%% of the photon energy on what the camera sees indirect",
             100.0 * g->stats.seen_indirect_energy);
    return true;
  }
  snprintf(why, size, "%.0f%% of the photons indirect", 100.0 * g->stats.indirect_share);
  return true;
}

const iris_guide_provider iris_guiding_provider = {provider_build, provider_destroy, provider_decision,
                                                   provider_build_lights, provider_light_select};
