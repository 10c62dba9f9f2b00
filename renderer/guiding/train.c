/* Training passes from camera paths; train.h and docs/guiding.md ("Training"). */
#include "renderer/guiding/train.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/cancel.h"
#include "core/log.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "renderer/guiding/vertex.h"

#define TRAIN_SEED 0x747261696e696e67ULL /* "training": streams apart from the render's */
#define TRAIN_TILE 8
#define TRAIN_BATCH_TILES 256 /* tiles traced between two merges: bounds the sample buffers */
#define TRAIN_BATCH_SPP 4     /* ... and samples per pixel of each batch */
/* Samples a cache needs before its learned selection probability is used. */
#define ALPHA_MIN_SAMPLES 64
/* Light samples a cache's vertices must have traced, none of them bringing
 * light, before light sampling there becomes optional (params.light_min). */
#define LIGHT_MIN_TRIES 32
/* Share of the render's samples spent on training when train_spp is automatic. */
#define TRAIN_SHARE 0.05

/* ---- selection probability --------------------------------------------------- */

void iris_alpha_learner_add(iris_alpha_learner *l, float h, float q, float pb, float pc) {
  l->n++;
  if (!(h != 0.0f) || !(q > 0.0f) || !isfinite(h) || !isfinite(pc) || !isfinite(pb)) return;
  double h2 = (double)h * (double)h / (double)q;
  for (int j = 0; j < IRIS_ALPHA_GRID; ++j) {
    double a = iris_alpha_grid_value(j);
    double qa = (1.0 - a) * (double)pb + a * (double)pc;
    /* qa = 0 where h != 0 cannot happen for a > 0 and BSDF-covered h (pb > 0);
     * guard anyway: such an alpha would be infinitely bad. */
    l->m[j] += qa > 0.0 ? h2 / qa : INFINITY;
  }
}

float iris_alpha_learner_best(const iris_alpha_learner *l, float fallback, uint32_t min_samples) {
  if (l->n < min_samples) return fallback;
  int best = -1;
  for (int j = 0; j < IRIS_ALPHA_GRID; ++j)
    if (l->m[j] > 0.0 && isfinite(l->m[j]) && (best < 0 || l->m[j] < l->m[best])) best = j;
  return best < 0 ? fallback : iris_alpha_grid_value(best);
}

/* ---- schedule ------------------------------------------------------------------ */

int iris_guiding_train_budget(int spp) {
  if (spp <= 0) return 0;
  return (int)floor(TRAIN_SHARE * (double)spp);
}

int iris_guiding_train_iteration_spp(int iteration, int done, int total) {
  int n = iteration < 20 ? 1 << iteration : 1 << 20;
  return n < total - done ? n : total - done;
}

/* ---- one training pass --------------------------------------------------------- */

/* What a merge needs of one recorded vertex. */
typedef struct train_sample {
  uint32_t ids[IRIS_GUIDING_PICK_K];
  uint8_t m;
  iris_vec3 wi;
  float li;  /* incident radiance along wi per unit throughput, mean of RGB */
  float h;   /* mean over RGB of f * cos * Li: the integrand of the one-sample MIS estimator */
  float q;   /* density the direction was sampled with */
  float pb;  /* BSDF density */
  float pc;  /* the tied caches' density (tables of this pass) */
  int8_t light; /* the vertex's light sample (iris_path_vertex.light) */
  uint32_t light_leaf; /* ... the light-tree leaf of the light it chose (UINT32_MAX: none, no tree) */
  float light_value;   /* ... and its value (iris_path_vertex.light_value) */
  iris_vec3 p;         /* the vertex: where the tied caches' portals are seen from */
  float alpha;         /* the guide's share there (the mixture without a portal: (1 - alpha) pb + alpha pc) */
  uint8_t portal_faces; /* tied caches whose portal faces the vertex (iris_guide_vertex_state) */
} train_sample;

typedef struct sample_buffer {
  train_sample *s;
  size_t count, cap;
  bool failed; /* could not grow */
} sample_buffer;

typedef struct pass_ctx {
  const iris_guiding *g;
  const iris_integrator *it;
  const iris_pinhole *cam;
  iris_sampler_kind sampler;
  uint64_t seed;
  uint64_t s0, s1;       /* training sample indices of this pass */
  int tiles_x;
  uint64_t tile0;        /* first tile of the batch */
  sample_buffer *buf;    /* per tile of the batch */
  bool all_light;        /* record emission MIS gave to light sampling too */
  iris_film *film;       /* training samples kept in the image (NULL: discarded) */
  iris_pixel_bounds win; /* the film's window in the frame */
} pass_ctx;

static bool buffer_push(sample_buffer *b, const train_sample *t) {
  if (b->count == b->cap) {
    size_t cap = b->cap ? 2 * b->cap : 256;
    train_sample *s = realloc(b->s, cap * sizeof *s);
    if (!s) return false;
    b->s = s;
    b->cap = cap;
  }
  b->s[b->count++] = *t;
  return true;
}

/* Turns a recorded path into samples: incident radiance per unit throughput
 * along each served vertex's direction, Li_c = (L_end - L + miss) / beta. */
static bool record_path(pass_ctx *c, const iris_path_record *rec, iris_vec3 L_end, sample_buffer *out) {
  for (int k = 0; k < rec->count; ++k) {
    const iris_path_vertex *pv = &rec->v[k];
    const iris_guide_vertex_state *v = iris_guide_vertex_get(&pv->guide);
    if (v->m <= 0) continue;
    iris_vec3 d = iris_sub(L_end, pv->L);
    if (c->all_light) d = iris_add(d, pv->miss);
    float li[3], dl[3] = {d.x, d.y, d.z}, b[3] = {pv->beta.x, pv->beta.y, pv->beta.z},
                 f[3] = {pv->f.x, pv->f.y, pv->f.z};
    float li_sum = 0.0f, h = 0.0f;
    for (int ch = 0; ch < 3; ++ch) {
      li[ch] = b[ch] > 0.0f ? fmaxf(dl[ch], 0.0f) / b[ch] : 0.0f;
      li_sum += li[ch];
      h += f[ch] * pv->cos * li[ch];
    }
    train_sample t;
    memcpy(t.ids, v->ids, sizeof t.ids);
    t.m = (uint8_t)v->m;
    t.wi = pv->wi;
    t.li = li_sum / 3.0f;
    t.h = h / 3.0f;
    t.q = pv->pdf;
    t.pb = pv->pdf_bsdf;
    t.pc = iris_guide_vertex_guide_pdf(c->g, v, pv->wi);
    t.p = v->p;
    t.alpha = v->alpha;
    t.portal_faces = v->portal_faces;
    t.light = pv->light;
    t.light_leaf = UINT32_MAX;
    t.light_value = 0.0f;
    const iris_light_tree *tree = c->it->lights->tree;
    if (pv->light > 0 && tree && pv->light_value > 0.0f && isfinite(pv->light_value)) {
      t.light_leaf = iris_light_select_leaf_of(tree, pv->light_id);
      t.light_value = pv->light_value;
    }
    if (!isfinite(t.li) || !isfinite(t.h) || !(t.q > 0.0f)) continue;
    if (!buffer_push(out, &t)) return false;
  }
  return true;
}

static void train_tiles(void *vctx, uint64_t begin, uint64_t end, int thread) {
  (void)thread;
  pass_ctx *c = vctx;
  iris_path_stats stats = {0};
  iris_path_record rec;
  const int w = c->cam->width, hgt = c->cam->height;
  for (uint64_t t = begin; t < end; ++t) {
    uint64_t tile = c->tile0 + t;
    sample_buffer *out = &c->buf[t];
    out->count = 0;
    out->failed = false;
    if (iris_cancel_requested()) continue; /* the batch is discarded */
    int tx = (int)(tile % (uint64_t)c->tiles_x) * TRAIN_TILE, ty = (int)(tile / (uint64_t)c->tiles_x) * TRAIN_TILE;
    for (int y = ty; y < ty + TRAIN_TILE && y < hgt; ++y)
      for (int x = tx; x < tx + TRAIN_TILE && x < w; ++x) {
        uint64_t pixel = (uint64_t)y * (uint64_t)w + (uint64_t)x;
        for (uint64_t s = c->s0; s < c->s1; ++s) {
          iris_sampler rng = iris_sampler_start_kind(c->sampler, c->seed, pixel, s);
          float ux, uy;
          iris_sampler_get2(&rng, IRIS_DIM_PIXEL, &ux, &uy);
          iris_ray ray = iris_pinhole_ray(c->cam, (float)x + ux, (float)y + uy);
          iris_vec3 L = iris_integrator_radiance_record(c->it, ray, &rng, &stats, &rec);
          if (!record_path(c, &rec, L, out)) out->failed = true;
          /* a pixel is in one tile, and its samples come in order: deterministic */
          if (c->film && x >= c->win.x0 && x < c->win.x1 && y >= c->win.y0 && y < c->win.y1)
            iris_film_add(c->film, x - c->win.x0, y - c->win.y0, L);
        }
      }
  }
}

/* ---- accumulation and rebuild -------------------------------------------------- */

typedef struct train_state {
  float *radiance_photons;     /* per cache: the photons' radiance estimate, before training */
  float *acc;                  /* per texel (pdf layout): sum of Li cos / q */
  uint32_t *n;                 /* per cache: samples at vertices it served */
  double *irr;                 /* per cache: sum of Li cos / q over all directions */
  iris_alpha_learner *learner; /* per cache, this pass's samples */
  float *fine_acc, *photon_sub; /* refinement (refine.h), iris_guiding_sub layout: samples, photons' tables */
  uint32_t *fine_n;             /* per sub-table: samples */
  uint32_t *light_tries, *light_lit; /* per cache, over all passes: light samples traced at the
                                        vertices it served, and those that brought light */
  iris_light_select_nee *nee;        /* per cache, IRIS_LIGHT_SELECT_NEE_SLOTS: what the light samples
                                        brought by tree leaf (NULL: no learned light selection) */
  double *portal_m;                  /* per cache, over all passes, 2 each: the second moment of the
                                        samples where its portal faces the vertex without it and with it */
  uint32_t *portal_n;                /* ... and how many samples */
} train_state;

/* ---- portals kept by training ------------------------------------------------ */

/* Samples a cache's portal needs before training decides whether it stays. */
#define PORTAL_MIN_SAMPLES 64

/* One sample at a vertex that a cache's portal faces: its contribution to
 * the second moment sum h^2 / (q p') of the vertex's mixture p' without the
 * portal, (1 - alpha) pb + alpha pc, and with it at IRIS_PORTAL_SHARE (the
 * importance-weighted estimate of the integral of h^2 / p' from samples
 * drawn with density q, as the selection probability alpha is learned). */
static void portal_add(train_state *ts, uint32_t id, const iris_portal *portal, const train_sample *t) {
  if (!(t->h != 0.0f) || !(t->q > 0.0f) || !isfinite(t->h) || !isfinite(t->pb) || !isfinite(t->pc)) return;
  const double rest = (1.0 - (double)t->alpha) * (double)t->pb + (double)t->alpha * (double)t->pc;
  const double with = (1.0 - (double)IRIS_PORTAL_SHARE) * rest +
                      (double)IRIS_PORTAL_SHARE * (double)iris_portal_pdf(portal, t->p, t->wi);
  if (!(rest > 0.0) || !(with > 0.0)) return;
  const double h2 = (double)t->h * (double)t->h / (double)t->q;
  ts->portal_m[2 * (size_t)id] += h2 / rest;
  ts->portal_m[2 * (size_t)id + 1] += h2 / with;
  ts->portal_n[id]++;
}

/* After training: a cache keeps its portal where the samples at vertices it
 * faces had a lower second moment with it than without it; where fewer than
 * PORTAL_MIN_SAMPLES were seen (or no training ran: m = NULL), where at least
 * IRIS_PORTAL_MIN_SHARE of its light came through it (every finder's does). */
static void settle_portals(iris_guiding *g, const double *m, const uint32_t *n) {
  g->stats.portal_caches = 0;
  for (size_t i = 0; i < g->cache_count; ++i) {
    iris_cache *c = &g->caches[i];
    if (!(c->portal_weight > 0.0f)) continue;
    const bool keep = m && n[i] >= PORTAL_MIN_SAMPLES ? m[2 * i + 1] < m[2 * i]
                                                       : c->portal_weight >= IRIS_PORTAL_MIN_SHARE;
    if (keep) {
      g->stats.portal_caches++;
    } else {
      memset(&c->portal, 0, sizeof c->portal);
      c->portal_weight = 0.0f;
    }
  }
}

/* Adds a tile's samples to the caches whose id is `lane` modulo `lanes`:
 * every cache receives its samples in tile order, whatever the lanes. */
static void merge_samples(iris_guiding *g, train_state *ts, const sample_buffer *b, uint32_t lane, uint32_t lanes) {
  for (size_t i = 0; i < b->count; ++i) {
    const train_sample *t = &b->s[i];
    for (int j = 0; j < t->m; ++j) {
      uint32_t id = t->ids[j];
      if (id % lanes != lane) continue;
      iris_cache *c = &g->caches[id];
      const iris_octmap *map = c->sphere ? &g->sphere : &g->hemi;
      iris_vec3 wl = iris_frame_to_local(&c->frame, t->wi);
      float cosc = fabsf(wl.z);
      ts->n[id]++;
      if (t->light >= 0) ts->light_tries[id]++, ts->light_lit[id] += (uint32_t)t->light;
      if (ts->nee && t->light_leaf != UINT32_MAX)
        iris_light_select_nee_add(ts->nee + (size_t)id * IRIS_LIGHT_SELECT_NEE_SLOTS, t->light_leaf, t->light_value);
      iris_alpha_learner_add(&ts->learner[id], t->h, t->q, t->pb, t->pc);
      if (t->portal_faces & (1u << j)) portal_add(ts, id, &c->portal, t);
      if (!(t->li > 0.0f)) continue;
      /* Li cos / q estimates the integral of Li cos over the sphere; splatted
       * at wi it estimates each texel's share (the photons' histogram is
       * incident power, also Li cos: the two are the same quantity). */
      float v = t->li * cosc / t->q;
      if (iris_cache_splat(map, ts->acc + c->table, wl, v, g->params.splat)) ts->irr[id] += v;
      if (ts->fine_acc) {
        const size_t sub = (size_t)(iris_guiding_sub(g, c) - g->refine_sub);
        iris_refine_train_add(map, g->refine_slot + c->table, ts->fine_acc + sub, ts->fine_n + sub / IRIS_REFINE_SUB,
                              wl, v);
      }
    }
  }
}

typedef struct merge_ctx {
  iris_guiding *g;
  train_state *ts;
  const sample_buffer *buf;
  uint64_t tiles;
  uint32_t lanes;
} merge_ctx;

static void merge_lanes(void *vctx, uint64_t begin, uint64_t end, int thread) {
  (void)thread;
  merge_ctx *c = vctx;
  for (uint64_t lane = begin; lane < end; ++lane)
    for (uint64_t t = 0; t < c->tiles; ++t) merge_samples(c->g, c->ts, &c->buf[t], (uint32_t)lane, c->lanes);
}

/* New tables for every cache: the photon histogram (normalised) and the path
 * samples' histogram (normalised) mixed with weight n / (n + prior). */
static void rebuild(iris_guiding *g, const train_state *ts, bool learn, float alpha_fallback, float alpha_cap,
                    float *hist) {
  const double prior = g->params.train_prior;
  for (size_t i = 0; i < g->cache_count; ++i) {
    iris_cache *c = &g->caches[i];
    const iris_octmap *map = c->sphere ? &g->sphere : &g->hemi;
    const uint32_t n = map->texel_count;
    const float *ph = g->photon_hist + c->table, *acc = ts->acc + c->table;
    double sum = 0.0;
    for (uint32_t t = 0; t < n; ++t) sum += acc[t];
    if (ts->n[i] > 0 && sum > 0.0 && isfinite(sum)) {
      double lambda = (double)ts->n[i] / ((double)ts->n[i] + prior);
      for (uint32_t t = 0; t < n; ++t) hist[t] = (float)((1.0 - lambda) * ph[t] + lambda * acc[t] / sum);
      iris_cache_build_tables(map, hist, g->params.pdf_floor, g->pdf + c->table, g->alias + c->table);
      if (ts->fine_acc) {
        const size_t sub = (size_t)(iris_guiding_sub(g, c) - g->refine_sub);
        iris_refine_train_rebuild(map, g->refine_slot + c->table, ph, ts->photon_sub + sub, ts->fine_acc + sub,
                                  ts->fine_n + sub / IRIS_REFINE_SUB, prior, IRIS_REFINE_MIX, g->refine_sub + sub);
      }
      /* The radiance still to come (Russian roulette): irradiance / pi from
       * the paths, mixed with the photons' estimate the same way. */
      double r = ts->irr[i] / (double)ts->n[i] / 3.14159265358979;
      c->radiance = (float)((1.0 - lambda) * ts->radiance_photons[i] + lambda * r);
    }
    if (learn) {
      float a = iris_alpha_learner_best(&ts->learner[i], c->alpha >= 0.0f ? c->alpha : alpha_fallback,
                                        ALPHA_MIN_SAMPLES);
      c->alpha = fminf(a, alpha_cap);
    }
  }
}

iris_status iris_guiding_train(iris_guiding *g, const iris_guide_setup *s, iris_error *err) {
  double t0 = iris_time_now();
  const iris_guiding_params *p = &g->params;
  int total = p->train_spp;
  const bool timed = total < 0 && !(s->spp > 0) && s->time_budget > 0.0;
  if (total < 0) total = timed ? 1 : iris_guiding_train_budget(s->spp);
  if (total <= 0 || g->cache_count == 0 || !g->photon_hist) {
    free(g->photon_hist);
    g->photon_hist = NULL;
    settle_portals(g, NULL, NULL);
    return IRIS_OK;
  }
  const size_t caches = g->cache_count;
  size_t floats = 0;
  for (size_t i = 0; i < caches; ++i) {
    size_t end = g->caches[i].table + (g->caches[i].sphere ? g->sphere.texel_count : g->hemi.texel_count);
    floats = end > floats ? end : floats;
  }
  train_state ts = {malloc(caches * sizeof(float)), calloc(floats ? floats : 1, sizeof(float)),
                    calloc(caches, sizeof(uint32_t)), calloc(caches, sizeof(double)),
                    calloc(caches, sizeof(iris_alpha_learner)), NULL, NULL, NULL,
                    calloc(caches, sizeof(uint32_t)), calloc(caches, sizeof(uint32_t)), NULL,
                    calloc(2 * caches, sizeof(double)), calloc(caches, sizeof(uint32_t))};
  const bool learn_nee = p->light_samples && g->lights.count != NULL && g->lights.tree != NULL;
  if (learn_nee) ts.nee = calloc(caches * IRIS_LIGHT_SELECT_NEE_SLOTS, sizeof *ts.nee);
  if (ts.radiance_photons)
    for (size_t i = 0; i < caches; ++i) ts.radiance_photons[i] = g->caches[i].radiance;
  const size_t subs = g->refine_slot ? (floats / g->hemi.texel_count + 1) * IRIS_REFINE_MAX : 0;
  if (subs) { /* refinement: the path samples update the refined texels' sub-cells too */
    ts.fine_acc = calloc(subs * IRIS_REFINE_SUB, sizeof(float));
    ts.fine_n = calloc(subs, sizeof(uint32_t));
    ts.photon_sub = malloc(subs * IRIS_REFINE_SUB * sizeof(float));
    if (ts.photon_sub) memcpy(ts.photon_sub, g->refine_sub, subs * IRIS_REFINE_SUB * sizeof(float));
  }
  float *hist = malloc(sizeof(float) * g->sphere.texel_count);
  sample_buffer *buf = calloc(TRAIN_BATCH_TILES, sizeof *buf);
  iris_status st = IRIS_OK;
  if (!ts.radiance_photons || !ts.acc || !ts.n || !ts.irr || !ts.learner || !hist || !buf || !ts.light_tries ||
      !ts.light_lit || (learn_nee && !ts.nee) || !ts.portal_m || !ts.portal_n ||
      (subs && (!ts.fine_acc || !ts.fine_n || !ts.photon_sub)))
    st = iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for the training passes");

  iris_integrator it = *s->integrator;
  it.guide = iris_guiding_sampler(g);
  pass_ctx c;
  memset(&c, 0, sizeof c);
  c.g = g;
  c.it = &it;
  c.cam = s->camera;
  c.sampler = s->sampler;
  c.seed = iris_hash4(s->seed, TRAIN_SEED, 0, 0);
  c.tiles_x = (s->camera->width + TRAIN_TILE - 1) / TRAIN_TILE;
  c.buf = buf;
  c.all_light = p->train_all_light;
  c.film = s->film;
  c.win = s->window;
  const uint64_t tiles = (uint64_t)c.tiles_x * (uint64_t)((s->camera->height + TRAIN_TILE - 1) / TRAIN_TILE);
  const float alpha_fallback = p->alpha_max, alpha_cap = g->alpha_cap;
  int done = 0, iteration = 0;
  uint64_t samples = 0;
  double sec_per_spp = -1.0; /* measured on the passes so far: the ETA to the first image pass */
  while (st == IRIS_OK && done < total) {
    int n = iris_guiding_train_iteration_spp(iteration, done, total);
    double tp = iris_time_now();
    {
      int passes = iteration;
      for (int d = done; d < total; ++passes) d += iris_guiding_train_iteration_spp(passes, d, total);
      char what[96];
      snprintf(what, sizeof what, "training pass %d of %d, %d spp", iteration + 1, passes, n);
      if (iteration == 0) iris_phase_begin("training", "training the guide");
      iris_guiding_phase(s, NULL, what, sec_per_spp >= 0.0 ? sec_per_spp * (double)(total - done) : -1.0);
    }
    memset(ts.learner, 0, caches * sizeof *ts.learner); /* learn alpha for this pass's tables */
    /* Batches of tiles x at most TRAIN_BATCH_SPP samples: the sample buffers
     * stay bounded however long a pass is. */
    const uint64_t batches_per_chunk = (tiles + TRAIN_BATCH_TILES - 1) / TRAIN_BATCH_TILES,
                   chunks = (uint64_t)((n + TRAIN_BATCH_SPP - 1) / TRAIN_BATCH_SPP);
    for (uint64_t b = 0; b < chunks * batches_per_chunk && st == IRIS_OK; ++b) {
      const uint64_t chunk = b / batches_per_chunk, t0b = (b % batches_per_chunk) * TRAIN_BATCH_TILES; /* tiles fastest */
      const uint64_t count = tiles - t0b < TRAIN_BATCH_TILES ? tiles - t0b : TRAIN_BATCH_TILES;
      const uint64_t end = (uint64_t)done + (uint64_t)n;
      c.tile0 = t0b;
      c.s0 = (uint64_t)done + chunk * TRAIN_BATCH_SPP;
      c.s1 = c.s0 + TRAIN_BATCH_SPP < end ? c.s0 + TRAIN_BATCH_SPP : end;
      iris_parallel_for(count, 1, s->threads, train_tiles, &c);
      if (iris_cancel_requested()) {
        st = iris_cancel_error(err);
        break;
      }
      for (uint64_t t = 0; t < count; ++t)
        if (buf[t].failed) st = iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for training samples");
      if (st != IRIS_OK) break;
      /* Caches split into lanes, each fed in tile order: the same guide for any thread count. */
      merge_ctx mc = {g, &ts, buf, count, (uint32_t)(s->threads > 0 ? s->threads : iris_parallel_default_threads())};
      iris_parallel_for(mc.lanes, 1, s->threads, merge_lanes, &mc);
      for (uint64_t t = 0; t < count; ++t) samples += buf[t].count;
    }
    if (st != IRIS_OK) break;
    rebuild(g, &ts, p->learn_alpha, alpha_fallback, alpha_cap, hist);
    done += n;
    iteration++;
    sec_per_spp = (iris_time_now() - t0) / (double)done;
    if (!s->phase && iris_time_now() - t0 > 2.0) /* progress on long training, where no progress line shows it */
      iris_infof("guiding: training pass %d: %d of %d spp, %.1f s", iteration, done, total, iris_time_now() - t0);
    if (timed && iteration == 1) {
      /* One training spp costs about one render spp: spend TRAIN_SHARE of
       * the samples the rest of the budget is expected to hold. */
      double per_spp = iris_time_now() - tp, left = s->time_budget - (iris_time_now() - t0);
      int expected = per_spp > 0.0 ? (int)fmin(left / per_spp, 1e6) : 0;
      total = iris_guiding_train_budget(expected);
      if (total < done) total = done;
    }
  }
  /* Light sampling where it brought nothing: after all passes, so that every
   * pass traced its light samples and the counts cover them all. */
  if (st == IRIS_OK && p->light_min < 1.0f)
    for (size_t i = 0; i < caches; ++i)
      if (ts.light_tries[i] >= LIGHT_MIN_TRIES && ts.light_lit[i] == 0) g->caches[i].light = p->light_min;
  /* Portals: which stay, from all passes' samples (the candidates too, until now) */
  if (st == IRIS_OK) settle_portals(g, ts.portal_m, ts.portal_n);
  /* The learned light tables again, now with what the light samples brought */
  if (st == IRIS_OK && learn_nee) iris_light_select_learn_nee(&g->lights, ts.nee, ts.light_tries, ts.light_lit);
  for (int t = 0; t < TRAIN_BATCH_TILES && buf; ++t) free(buf[t].s);
  free(buf);
  free(hist);
  free(ts.radiance_photons);
  free(ts.acc);
  free(ts.n);
  free(ts.irr);
  free(ts.learner);
  free(ts.fine_acc);
  free(ts.fine_n);
  free(ts.photon_sub);
  free(ts.light_tries);
  free(ts.light_lit);
  free(ts.nee);
  free(ts.portal_m);
  free(ts.portal_n);
  free(g->photon_hist);
  g->photon_hist = NULL;
  g->stats.train_spp = done;
  g->stats.train_iterations = iteration;
  g->stats.train_samples = samples;
  g->stats.train_seconds = iris_time_now() - t0;
  return st;
}
