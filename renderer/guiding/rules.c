/* The guide's budget and its skip rules (rules.h; docs/guiding.md, "Budget
 * (scene-driven defaults) and skipping" and "--method auto"). */
#include "renderer/guiding/rules.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/parallel.h"

double iris_guiding_environment_share(const iris_lights *L) {
  if (L->environment < 0 || !(L->total_power > 0.0)) return 0.0;
  return (double)L->entries[L->environment].power / L->total_power;
}

void iris_guiding_choose_budget(iris_guiding_params *p, const iris_guide_setup *s, int *stride) {
  int64_t pixels = (int64_t)s->camera->width * s->camera->height;
  if (p->caches <= 0) {
    int64_t c = pixels / 32; /* one camera cache per 8x8 pixels, as many from photons */
    p->caches = c < 1024 ? 1024 : (c > 65536 ? 65536 : c);
  }
  int64_t cam = p->caches / 2 > 0 ? p->caches / 2 : 1;
  int st = (int)lrint(sqrt((double)pixels / (double)cam));
  *stride = st < 1 ? 1 : st;
  /* 12-16 (thesis-like) cost more than they save on lamp-lit rooms, but a sky
   * seen through openings (its photons kept, below) puts the window and the
   * sun's patch into small solid angles: res 16 there (docs/guiding.md). */
  if (p->cache_res <= 0) p->cache_res = iris_guiding_environment_share(s->lights) >= 0.5 ? 16 : 8;
  if (p->cache_k <= 0) p->cache_k = 200;
  /* Off unless asked for: measured no better on door and stress-caustic and
   * worse on the glazed sky-room (docs/guiding.md, "Refinement"). */
  if (p->refine < 0) p->refine = 0;
  if (p->pdf_floor < 0.0f) p->pdf_floor = 2e-4f;
  if (p->photons <= 0) {
    /* light groups: emitting instances + punctual + sky, not triangles */
    p->photons = (int64_t)iris_guiding_photon_paths((double)p->caches, p->cache_k, s->lights->group_count,
                                                    iris_guiding_environment_share(s->lights));
  }
  /* Measured (docs/guiding.md, "Parameters around the defaults"): with light
   * sampling 0.5 is best; without it (`guided`) 0.7 is 6-23% more efficient
   * than 0.5 on door, door-shielded and Cornell. */
  if (!(p->alpha_max >= 0.0f)) p->alpha_max = p->use_nee ? 0.5f : 0.7f;
  if (p->alpha_max > 0.9999f) p->alpha_max = 0.9999f; /* BSDF sampling must keep some probability */
}

/* Photons on surfaces the camera sees: up to 4096 at an even stride through
 * the map, facing the camera's eye and unoccluded from it. Counts them and
 * their energy, and the part of both that arrived after a bounce. */
typedef struct seen_photons {
  size_t count, indirect;
  double energy, indirect_energy;
} seen_photons;

static seen_photons count_seen_photons(const iris_guide_setup *s, const iris_photon_map *ph) {
  seen_photons r = {0, 0, 0.0, 0.0};
  size_t step = ph->count > 4096 ? ph->count / 4096 : 1;
  iris_vec3 eye = s->camera->origin;
  for (size_t i = 0; i < ph->count; i += step) {
    const iris_photon *q = &ph->photons[i];
    iris_vec3 to_eye = iris_sub(eye, q->p);
    if (iris_dot(to_eye, q->n) <= 0.0f) continue;
    iris_ray ray = iris_spawn_ray_to(q->p, q->n, eye, iris_neg(iris_normalize(to_eye)));
    ray.tmax = 1.0f; /* the eye is a point, not a surface */
    if (iris_accel_occluded(s->accel, &ray)) continue;
    r.count++;
    r.energy += q->energy;
    if (q->bounce > 0) r.indirect++, r.indirect_energy += q->energy;
  }
  return r;
}

/* Fraction of indirect photons the skip rule looks at. Over all stored
 * photons, except in scenes lit mostly by the environment: there most
 * photons land directly on outside surfaces the camera never sees (the roof
 * and walls of a room lit through a window), so the fraction is taken over
 * the photons on surfaces the camera sees. */
static double indirect_share(const iris_guide_setup *s, const iris_photon_map *ph) {
  if (ph->count == 0) return 0.0;
  double all = (double)ph->indirect / (double)ph->count;
  if (iris_guiding_environment_share(s->lights) < 0.5) return all;
  seen_photons seen = count_seen_photons(s, ph);
  return seen.count > 0 ? (double)seen.indirect / (double)seen.count : all;
}

/* --method auto's rule (docs/guiding.md, "--method auto"): the share of the
 * photon energy on surfaces the camera sees that arrived after at least one
 * bounce. Where most of what the camera sees is lit directly, light sampling
 * already finds the light and guided-nee's dearer samples do not pay
 * (cornell-box 48%); where it is mostly indirect they may (door 66%, sky-room
 * 61%, door-shielded 93%) and the race decides. Between 50% and 55% the share
 * cannot tell: stress-glossy-room (51%) is mis's, stress-thin-walls (51-53%)
 * guided-nee's by 1.14-1.24x, so 50%, not 55% (docs/guiding.md). -1 when no
 * photon is seen. */
static double seen_indirect_energy(const iris_guide_setup *s, const iris_photon_map *ph) {
  seen_photons seen = count_seen_photons(s, ph);
  return seen.energy > 0.0 ? seen.indirect_energy / seen.energy : -1.0;
}


void iris_guiding_skip(iris_guiding *g, const char *why) {
  g->stats.skipped = true;
  snprintf(g->stats.reason, sizeof g->stats.reason, "%s", why);
}

#define CAUSTIC_MIN 16 /* photons focused through glass that keep the guide */
#define CAUSTIC_SHARE_MIN 0.1 /* ... carrying this share of the indirect photon energy */
#define PILOT_EXTEND 2 /* doublings of a pilot whose caustic photons cannot decide (caustics_undecided) */

/* Photons of one mark (glint or caustic): how many, their energy, and the
 * energy of all indirect photons, which the keep rules compare it with. */
typedef struct marked_photons {
  size_t n;
  double energy, indirect;
} marked_photons;

static marked_photons count_marked(const iris_photon_map *photons, bool caustic) {
  marked_photons m = {0, 0.0, 0.0};
  for (size_t i = 0; i < photons->count; ++i) {
    const iris_photon *ph = &photons->photons[i];
    if (ph->bounce > 0) m.indirect += ph->energy;
    if (caustic ? ph->caustic : ph->glint) m.energy += ph->energy, m.n++;
  }
  return m;
}

/* The pilot's caustic photons carry the share but are fewer than
 * CAUSTIC_MIN: too few to decide on either way (env-spheres with a glass
 * sphere: 14-22 of them in a 16384-path pilot, the share 0.16-0.22 on every
 * seed), so the pilot goes on (pilot below). */
static bool caustics_undecided(const iris_photon_map *photons) {
  marked_photons m = count_marked(photons, true);
  return m.n > 0 && m.n < CAUSTIC_MIN && m.energy >= CAUSTIC_SHARE_MIN * m.indirect;
}

/* Light focused through glass onto what the guide serves (caustic photons:
 * delta vertices only from the light, one of them a refraction) is light
 * that light sampling cannot reach and the caches can, however little of the
 * scene's light is indirect: where CAUSTIC_MIN such photons carry at least
 * CAUSTIC_SHARE_MIN of the indirect photon energy, the "lit mostly directly"
 * rules keep the guide, and `auto` races (docs/guiding.md, "--method auto").
 * The stats then hold that share. */
static bool keeps_for_caustics(iris_guiding *g, const iris_photon_map *photons) {
  marked_photons m = count_marked(photons, true);
  if (!(m.n >= CAUSTIC_MIN && m.energy >= CAUSTIC_SHARE_MIN * m.indirect)) return false;
  g->stats.caustic_share = m.energy / m.indirect;
  return true;
}

/* The caustic exception, but not for `auto` where mis traces light paths
 * off glossy reflectors that reach the camera (s->mis_light_traces,
 * renderer/light_trace.h): there mis carries the reflectors' caustics, which
 * the guide finds only through its glint spots, and on env-spheres with a
 * glass sphere it had 1.9x less relMSE than guided-nee at 4 s (docs/guiding.md,
 * "--method auto"). */
static bool caustics_keep(iris_guiding *g, const iris_guide_setup *s, const iris_photon_map *photons) {
  if (s->deciding && s->mis_light_traces) return false;
  return keeps_for_caustics(g, photons);
}

/* What a skip's reason adds where light tracing made the caustic exception yield. */
static const char *light_trace_note(const iris_guide_setup *s) {
  return s->deciding && s->mis_light_traces ? "; mis traces light paths off the glossy reflectors" : "";
}

/* --method auto only (s->deciding; an explicit guided-nee is built anyway):
 * skips the guide where what the camera sees is lit mostly directly, on the
 * first photons it is given (the pilot's, or the full pass's without one). */
static bool auto_declines(iris_guiding *g, const iris_guide_setup *s, const iris_photon_map *photons) {
  if (!s->deciding || g->params.force || g->stats.seen_indirect_energy >= 0.0) return false;
  g->stats.seen_indirect_energy = seen_indirect_energy(s, photons);
  if (!(g->stats.seen_indirect_energy >= 0.0 && g->stats.seen_indirect_energy < IRIS_GUIDING_AUTO_SEEN_INDIRECT_MIN)) return false;
  if (caustics_keep(g, s, photons)) return false;
  char why[160];
  snprintf(why, sizeof why, "what the camera sees is lit mostly directly: %.0f%% of its photon energy indirect (< %.0f%%)%s",
           100.0 * g->stats.seen_indirect_energy, 100.0 * IRIS_GUIDING_AUTO_SEEN_INDIRECT_MIN, light_trace_note(s));
  iris_guiding_skip(g, why);
  return true;
}

#define INDIRECT_MIN 0.3 /* the "lit mostly directly" threshold */
#define GLINT_PILOT_MIN 16 /* photons a smooth reflector sent that keep a named guided method's guide */

/* A guided method asked for by name keeps its guide in a scene lit mostly
 * directly where photons met mirrors or near-mirror metal and the glints
 * they reflect carry at least IRIS_GLINT_SHARE_MIN of the indirect light
 * (env-spheres 0.18, veach-mis's plates 0.01): light only the guide finds
 * ("Glints"). `auto` decides by its rules. */
static bool keeps_for_glints(const iris_guiding *g, const iris_guide_setup *s, const iris_photon_map *photons) {
  if (!g->params.glints || s->deciding) return false;
  marked_photons m = count_marked(photons, false);
  return m.n >= GLINT_PILOT_MIN && m.energy >= IRIS_GLINT_SHARE_MIN * m.indirect;
}

double iris_guiding_photon_paths(double caches, int cache_k, size_t light_groups, double sky_share) {
  /* Enough photons that each cache's k nearest stay local: about 2.5 stored
   * photons per path on the benchmark scenes, so paths = caches * k / 20
   * gives every cache ~ 1/8 of its neighbourhood to itself; more lights
   * need more photons to cover each one. At least 50 000 (docs/guiding.md,
   * "Budget": 100 000 until 2026-12-04, no better per sample). */
  double n = floor(caches * (double)cache_k / 20.0);
  n = floor(n * (1.0 + 0.05 * (double)(light_groups > 1 ? light_groups - 1 : 0)));
  if (n < 50000.0) n = 50000.0;
  /* Environment photons leave a disk covering the whole scene, and many of
   * them hit nothing or only the outside of what the camera sees: in
   * proportion to the sky's share of the power, up to twice as many paths. */
  n = floor(n * (1.0 + sky_share));
  return n > 4000000.0 ? 4000000.0 : n;
}

uint64_t iris_guiding_pilot_paths(uint64_t photons) {
  uint64_t n = photons / 16 > 16384 ? photons / 16 : 16384;
  n = (n + 4095) / 4096 * 4096;
  return n < photons ? n : photons;
}

/* Decide before paying (docs/guiding.md, "--method auto"): with light
 * sampling, a view of nothing but mirrors and glass (the camera pass below,
 * run alone first) and a scene lit mostly directly (the 30% rule on a pilot,
 * the first paths of the photon pass) are skipped before the full pass is
 * traced. `photons` keeps the pilot's photons, which the full pass extends. */
iris_status iris_guiding_pilot(iris_guiding *g, const iris_guide_setup *s, size_t camera_points,
                               iris_photon_map *photons, iris_error *err) {
  iris_guiding_params *p = &g->params;
  memset(photons, 0, sizeof *photons);
  if (!p->use_nee || p->force || p->pilot_paths == 0) return IRIS_OK;
  double t0 = iris_time_now();
  if (camera_points == 0) {
    iris_guiding_skip(g, "every visible surface is a perfect mirror or glass (or nothing is visible)");
    return IRIS_OK;
  }
  uint64_t n = p->pilot_paths > 0 ? (uint64_t)p->pilot_paths : iris_guiding_pilot_paths((uint64_t)p->photons);
  iris_status st = iris_photons_trace(s, p->photon_lights, n < (uint64_t)p->photons ? n : (uint64_t)p->photons,
                                      photons, err);
  if (st != IRIS_OK) return st;
  /* too few caustic photons to tell whether they keep the guide: up to
   * PILOT_EXTEND doublings more of the pilot (the full pass extends the same
   * paths, so nothing is traced twice when the guide is built) */
  const uint64_t all = (uint64_t)p->photons;
  for (int k = 0; k < PILOT_EXTEND && n < all && caustics_undecided(photons); ++k) {
    n = 2 * n < all ? 2 * n : all;
    st = iris_photons_trace_more(s, p->photon_lights, n, photons, err);
    if (st != IRIS_OK) return st;
  }
  g->stats.pilot_paths = photons->paths;
  g->stats.pilot_share = indirect_share(s, photons);
  g->stats.pilot_seconds = iris_time_now() - t0;
  if (photons->count > 0 && g->stats.pilot_share < INDIRECT_MIN && !keeps_for_glints(g, s, photons) &&
      !caustics_keep(g, s, photons)) {
    char why[160];
    snprintf(why, sizeof why, "the scene is lit mostly directly: %.0f%% indirect photons in a %llu-path pilot%s",
             100.0 * g->stats.pilot_share, (unsigned long long)photons->paths, light_trace_note(s));
    iris_guiding_skip(g, why);
    iris_photons_destroy(photons);
    return IRIS_OK;
  }
  if (auto_declines(g, s, photons)) iris_photons_destroy(photons);
  return IRIS_OK;
}
bool iris_guiding_declines(iris_guiding *g, const iris_guide_setup *s, const iris_photon_map *photons) {
  const iris_guiding_params *p = &g->params;
  /* Mostly direct light (Veach: 20% of the photons indirect) is light
   * sampling's job; there the guide costs more per sample than it saves
   * (docs/guiding.md, benchmark). Door 75%, Cornell 65%. */
  g->stats.indirect_share = indirect_share(s, photons);
  if (p->use_nee && !p->force && g->stats.indirect_share < INDIRECT_MIN && !keeps_for_glints(g, s, photons) &&
      !caustics_keep(g, s, photons)) {
    char why[160];
    snprintf(why, sizeof why, "the scene is lit mostly directly: %.0f%% indirect photons%s",
             100.0 * g->stats.indirect_share, light_trace_note(s));
    iris_guiding_skip(g, why);
    return true;
  }
  return auto_declines(g, s, photons);
}
