/* Photon tracing (thesis 4.2.1); docs/guiding.md "Photons". */
#include "renderer/guiding/photons.h"

#include <stdlib.h>
#include <string.h>

#include "core/cancel.h"
#include "core/parallel.h"
#include "core/rng.h"

#define BLOCK_PATHS 4096u
/* Paths whose first SMOOTH_PER_PATH smooth vertices become glint targets (iris_photon_map.smooth). */
#define SMOOTH_PATHS 262144u
#define SMOOTH_PER_PATH 4
/* Stream offset that keeps photon random numbers apart from camera pixels. */
#define PHOTON_SAMPLE_INDEX 0x70686f746f6eULL

typedef struct photon_block {
  iris_photon *items;
  size_t count, cap;
  size_t at;       /* offset in the concatenated array */
  iris_vec3 *smooth; /* smooth vertices met (iris_photon_map.smooth) */
  size_t smooth_count, smooth_cap, smooth_at;
  uint64_t indirect;
  bool oom;
} photon_block;

typedef struct trace_ctx {
  const iris_guide_setup *setup;
  const iris_distrib1d *select; /* light choice (lights->select, or the area one) */
  uint64_t first, paths;        /* path indices first .. paths - 1 */
  photon_block *blocks;
  iris_photon *all; /* concatenation target */
  iris_vec3 *smooth; /* ... of the smooth vertices */
} trace_ctx;

static void block_push(photon_block *b, const iris_photon *ph) {
  if (b->oom) return;
  if (b->count == b->cap) {
    /* ~4 photons per path on the benchmark scenes: one allocation usually;
     * pages never written are never touched. */
    size_t cap = b->cap ? 2 * b->cap : 4 * (size_t)BLOCK_PATHS;
    iris_photon *n = realloc(b->items, cap * sizeof *n);
    if (!n) {
      b->oom = true;
      return;
    }
    b->items = n;
    b->cap = cap;
  }
  b->items[b->count++] = *ph;
}

bool iris_photon_smooth(const iris_shading_point *sp) {
  if (sp->delta) return true; /* mirrors, and clear glass: a curved one bends a lamp into a spot too */
  if (sp->lobes & IRIS_LOBE_TRANSMISSION) return false; /* rough glass: its caustics are the caches' */
  return (sp->lobes & IRIS_LOBE_GLOSSY) && !(sp->lobes & IRIS_LOBE_DIFFUSE) &&
         iris_bsdf_guiding_roughness(&sp->bsdf) <= IRIS_GLINT_ROUGHNESS;
}

static void smooth_push(photon_block *b, iris_vec3 p) {
  if (b->oom) return;
  if (b->smooth_count == b->smooth_cap) {
    size_t cap = b->smooth_cap ? 2 * b->smooth_cap : 256;
    iris_vec3 *n = realloc(b->smooth, cap * sizeof *n);
    if (!n) {
      b->oom = true;
      return;
    }
    b->smooth = n;
    b->smooth_cap = cap;
  }
  b->smooth[b->smooth_count++] = p;
}

static void trace_path(const iris_guide_setup *s, const iris_distrib1d *select, uint64_t index,
                       photon_block *out) {
  const iris_sampler_kind kind = s->integrator ? s->integrator->sampler : IRIS_SAMPLER_SOBOL;
  float us, u0, u1, u2, u3;
  iris_sampler rng;
  if (kind == IRIS_SAMPLER_SOBOL && index <= UINT32_MAX) {
    /* Quasi-random photons (docs/guiding.md, "Preprocessing"): the emission is
     * one 5D Owen-scrambled Sobol point of the photon index (position on the
     * light from the (0,2)-sequence pair, then direction, then the light
     * choice), the bounces padded pairs of the same index. */
    uint32_t i = (uint32_t)index;
    uint64_t h = iris_hash4(s->seed, PHOTON_SAMPLE_INDEX, 0x9e0705ULL, 5);
    u0 = iris_sobol_owen(i, 0, (uint32_t)h);
    u1 = iris_sobol_owen(i, 1, (uint32_t)(h >> 32));
    h = iris_mix64(h);
    u2 = iris_sobol_owen(i, 2, (uint32_t)h);
    u3 = iris_sobol_owen(i, 3, (uint32_t)(h >> 32));
    us = iris_sobol_owen(i, 4, (uint32_t)iris_mix64(h));
    rng = iris_sampler_start_kind(IRIS_SAMPLER_SOBOL, s->seed, PHOTON_SAMPLE_INDEX, index);
  } else {
    rng = iris_sampler_start(s->seed, index, PHOTON_SAMPLE_INDEX);
    us = iris_sampler_get(&rng, 0);
    u0 = iris_sampler_get(&rng, 1);
    u1 = iris_sampler_get(&rng, 2);
    u2 = iris_sampler_get(&rng, 3);
    u3 = iris_sampler_get(&rng, 4);
  }
  iris_photon_emission e;
  if (!iris_lights_sample_emission_with(s->lights, select, us, u0, u1, u2, u3, &e)) return;
  iris_vec3 beta = e.power;
  if (!iris_isfinite3(beta) || !(iris_max3(beta) > 0.0f)) return;
  iris_ray ray = {e.p, 0.0f, e.dir, INFINITY};
  /* Until the first non-delta vertex: whether a photon of the map still
   * travels along its emission direction having passed only delta vertices
   * (IRIS_PHOTON_STRAIGHT_COS: a flat slab's faces are parallel). */
  bool specular_only = s->lights->envmap && s->lights->environment >= 0 && e.light == (uint32_t)s->lights->environment;
  /* The same for a lamp (an emissive triangle): from a wall behind a glass
   * shade, the bulb is where it would be without the glass ("Lamps behind glass"). */
  bool lamp_only = s->lights->entries[e.light].kind == IRIS_LIGHT_KIND_TRIANGLE;
  /* ... and for a map photon, the one refracting plane it passed, if it passed
   * exactly one delta vertex and that bent it (a single glass quad) */
  int deltas = 0;
  float pane[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  bool smooth_reflected = false; /* the last vertex sent it off a smooth surface ("Glints") */
  int smooth_seen = 0;           /* smooth vertices recorded as glint targets */
  bool delta_only = true, refracted = false; /* the vertices so far (iris_photon.caustic) */
  for (int bounce = 0; bounce < IRIS_PHOTON_MAX_BOUNCES; ++bounce) {
    /* the emission's numbers come first: bounce b draws layout bounce b + 1 */
    iris_sampler_set_bounce(&rng, bounce + 1);
    iris_hit hit;
    if (!iris_accel_intersect(s->accel, &ray, &hit)) return;
    iris_interaction si;
    iris_accel_interaction(s->accel, ray.d, &hit, &si);
    if (!si.front) beta = iris_mul(beta, iris_integrator_volume_transmittance(s->integrator, &si, hit.t * iris_length(ray.d)));
    iris_vec3 wo = iris_normalize(iris_neg(ray.d));
    iris_shading_point sp;
    iris_integrator_shade(s->integrator, &si, wo, bounce, &sp);
    if (!sp.delta) {
      iris_photon ph;
      ph.p = si.p;
      ph.n = sp.frame.n;
      ph.wi = wo;
      ph.energy = iris_avg3(beta);
      ph.bounce = (uint8_t)(bounce > 255 ? 255 : bounce);
      ph.transmits = (sp.lobes & IRIS_LOBE_TRANSMISSION) ? 1 : 0;
      ph.light = e.light;
      const bool straight = bounce > 0 && iris_dot(wo, e.dir) < -IRIS_PHOTON_STRAIGHT_COS;
      ph.sky_through = specular_only && straight;
      ph.lamp_through = lamp_only && straight;
      const bool paned = specular_only && deltas == 1 && !straight && pane[3] > 0.0f;
      for (int k = 0; k < 4; ++k) ph.pane[k] = paned ? pane[k] : 0.0f;
      ph.glint = smooth_reflected && !(delta_only && straight) && !paned;
      ph.caustic = delta_only && refracted;
      block_push(out, &ph);
      delta_only = false;
      specular_only = lamp_only = false;
    }
    const bool smooth = iris_photon_smooth(&sp);
    /* the glints' targets: a path's first SMOOTH_PER_PATH smooth vertices, of
     * the first SMOOTH_PATHS paths (bounded: a hall of mirrors would
     * otherwise keep up to 32 points of every path) */
    if (smooth && smooth_seen < SMOOTH_PER_PATH && index < SMOOTH_PATHS) smooth_push(out, si.p), smooth_seen++;
    iris_direction_sample ds;
    if (!iris_integrator_sample_bsdf(&sp, &rng, &ds)) return;
    /* off a mirror, or through clear glass (what glass reflects is faint);
     * straight on through a slab is not a glint (above) */
    smooth_reflected = smooth && (!(sp.lobes & IRIS_LOBE_TRANSMISSION) || (ds.lobe & IRIS_LOBE_TRANSMISSION));
    refracted |= sp.delta && (ds.lobe & IRIS_LOBE_TRANSMISSION);
    if (sp.delta && specular_only && ++deltas == 1 && (ds.lobe & IRIS_LOBE_TRANSMISSION) && sp.bsdf.ior > 0.0f &&
        sp.bsdf.ior != 1.0f) {
      /* n on the side the photon came from (the sky's); entering the
       * surface's front it enters a medium of index ior, else it leaves one */
      iris_vec3 n = iris_dot(si.ng, ray.d) < 0.0f ? si.ng : iris_neg(si.ng);
      n = iris_normalize(n);
      pane[0] = n.x, pane[1] = n.y, pane[2] = n.z;
      pane[3] = si.front ? sp.bsdf.ior : 1.0f / sp.bsdf.ior;
    }
    /* f |cos| / pdf for every lobe: a delta lobe's f carries 1/|cos wi|
     * (bsdf.c), so its weight is the lobe's colour, as on camera paths;
     * weighting it by f alone gained 1/|cos| at every glass interface. */
    float cosv = fabsf(iris_dot(ds.wi, sp.frame.n));
    beta = iris_scale(iris_mul(beta, iris_scale(ds.f, cosv)), 1.0f / ds.pdf);
    if (!iris_isfinite3(beta)) return;
    /* Russian roulette on the throughput relative to the emitted power. */
    if (bounce >= 2) {
      float q = fminf(1.0f, iris_max3(beta) / fmaxf(iris_max3(e.power), 1e-30f));
      if (!(iris_sampler_slot(&rng, IRIS_SLOT_RR) < q)) return;
      beta = iris_scale(beta, 1.0f / q);
    }
    if (!(iris_max3(beta) > 0.0f)) return;
    ray = iris_spawn_ray(&sp.si, ds.wi);
  }
}

static void trace_blocks(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  trace_ctx *c = ctx;
  for (uint64_t b = begin; b < end; ++b) {
    if (iris_cancel_requested()) return; /* the caller notices and discards the pass */
    uint64_t lo = c->first + b * BLOCK_PATHS, hi = lo + BLOCK_PATHS;
    if (hi > c->paths) hi = c->paths;
    for (uint64_t i = lo; i < hi; ++i) trace_path(c->setup, c->select, i, &c->blocks[b]);
    for (size_t i = 0; i < c->blocks[b].count; ++i) c->blocks[b].indirect += c->blocks[b].items[i].bounce > 0;
  }
}

/* Copies blocks into their place in the concatenated array (in parallel: the
 * array is the same for any thread count) and frees them. */
static void copy_blocks(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  trace_ctx *c = ctx;
  for (uint64_t b = begin; b < end; ++b) {
    photon_block *blk = &c->blocks[b];
    if (blk->count) memcpy(c->all + blk->at, blk->items, blk->count * sizeof *c->all);
    if (blk->smooth_count) memcpy(c->smooth + blk->smooth_at, blk->smooth, blk->smooth_count * sizeof *c->smooth);
    free(blk->items);
    free(blk->smooth);
    blk->items = NULL;
    blk->smooth = NULL;
  }
}

iris_status iris_photons_trace(const iris_guide_setup *setup, iris_emission_selection by,
                               uint64_t paths, iris_photon_map *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  return iris_photons_trace_more(setup, by, paths, out, err);
}

iris_status iris_photons_trace_more(const iris_guide_setup *setup, iris_emission_selection by,
                                    uint64_t paths, iris_photon_map *out, iris_error *err) {
  if (paths <= out->paths || setup->lights->count == 0) return IRIS_OK;
  const uint64_t first = out->paths;
  uint64_t nblocks = (paths - first + BLOCK_PATHS - 1) / BLOCK_PATHS;
  /* By power: the lights' own selection; by area: one built for this pass only. */
  iris_distrib1d area_select;
  memset(&area_select, 0, sizeof area_select);
  if (by == IRIS_EMIT_BY_AREA) {
    iris_status st = iris_lights_emission_selection(setup->lights, by, &area_select, err);
    if (st != IRIS_OK) return st;
  }
  photon_block *blocks = calloc(nblocks, sizeof *blocks);
  if (!blocks) {
    iris_distrib1d_destroy(&area_select);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for photons");
  }
  trace_ctx c = {setup, by == IRIS_EMIT_BY_AREA ? &area_select : &setup->lights->select, first, paths, blocks,
                 NULL, NULL};
  iris_parallel_for(nblocks, 1, setup->threads, trace_blocks, &c);
  iris_distrib1d_destroy(&area_select);
  if (iris_cancel_requested()) {
    for (uint64_t b = 0; b < nblocks; ++b) free(blocks[b].items), free(blocks[b].smooth);
    free(blocks);
    return iris_cancel_error(err);
  }
  size_t total = out->count, smooth = out->smooth_count; /* the new ones go after those already traced */
  uint64_t indirect = 0;
  bool oom = false;
  for (uint64_t b = 0; b < nblocks; ++b) {
    blocks[b].at = total;
    total += blocks[b].count;
    blocks[b].smooth_at = smooth;
    smooth += blocks[b].smooth_count;
    indirect += blocks[b].indirect;
    oom |= blocks[b].oom;
  }
  iris_photon *all = oom ? NULL : realloc(out->photons, (total ? total : 1) * sizeof *all);
  if (all) out->photons = all;
  iris_vec3 *sm = all ? realloc(out->smooth, (smooth ? smooth : 1) * sizeof *sm) : NULL;
  if (sm) {
    out->smooth = sm;
    c.all = all;
    c.smooth = sm;
    iris_parallel_for(nblocks, 1, setup->threads, copy_blocks, &c);
  }
  for (uint64_t b = 0; b < nblocks; ++b) free(blocks[b].items), free(blocks[b].smooth);
  free(blocks);
  if (!sm)
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for %zu photons", total);
  out->count = total;
  out->smooth_count = smooth;
  out->paths = paths;
  out->indirect += indirect;
  return IRIS_OK;
}

void iris_photons_destroy(iris_photon_map *map) {
  free(map->photons);
  free(map->smooth);
  memset(map, 0, sizeof *map);
}
