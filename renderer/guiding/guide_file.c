/* Guide files: writing, reading and checking (guide_file.h); the format is
 * in docs/guiding.md, "The guide as a file". Everything is written field by
 * field in little-endian byte order (no struct is dumped), so the file does
 * not depend on the compiler's padding or the host's byte order. */
#include "renderer/guiding/guide_file.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "core/rng.h"
#include "renderer/lights.h"

static const unsigned char MAGIC[8] = {'I', 'R', 'I', 'S', 'G', 'D', 'E', '\n'};
#define HEADER_BYTES 48u     /* magic 8, version 4, flags 4, scene 8, settings 8, payload size 8, checksum 8 */
#define CHECKSUM_AT 40u      /* the checksum covers bytes [0, 40) and the payload */
#define CACHE_BYTES (138u + 5u * IRIS_CACHE_LAMPS) /* one cache record (v7: + the portal, 40 bytes) */
#define GLINT_BYTES 40u      /* one glint photon: p, n, y (9 f32), energy f32 */
#define REFINE_CACHE_BYTES (4u * IRIS_REFINE_MAX * IRIS_REFINE_SUB) /* refinement sub-tables per cache */
#define TEXEL_BYTES 12u      /* pdf f32 + alias q f32 + alias index u32 */
#define GUIDE_FLAG_LIGHTS 1u /* learned light tables follow the alias tables (light_select.h) */
#define LIGHTS_HEAD_BYTES 12u /* beta f32 + direct photons u64 */
#define LIGHTS_CACHE_BYTES (1u + 8u * IRIS_LIGHT_SELECT_SLOTS) /* count u8 + slots (leaf u32, cdf f32) */
#define REASON_MAX 159u

/* ---- checksum ---------------------------------------------------------------- */

/* 64-bit hash of a byte range, 8 bytes per step through iris_mix64 (core/rng.h),
 * the length folded in last, so a truncated or extended range differs. */
static uint64_t hash_bytes(uint64_t h, const unsigned char *p, size_t n) {
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    uint64_t w = 0;
    for (int b = 7; b >= 0; --b) w = (w << 8) | p[i + (size_t)b];
    h = iris_mix64(h ^ (w + 0x9e3779b97f4a7c15ULL));
  }
  uint64_t w = 0;
  for (size_t b = n; b > i; --b) w = (w << 8) | p[b - 1];
  h = iris_mix64(h ^ (w + 0x632be59bd9b4e019ULL));
  return iris_mix64(h ^ (uint64_t)n);
}

uint64_t iris_guide_file_checksum(const void *bytes, size_t size) {
  const unsigned char *data = bytes;
  if (size < HEADER_BYTES) return 0;
  uint64_t h = hash_bytes(0x67756964652d6631ULL, data, CHECKSUM_AT);
  return hash_bytes(h, data + HEADER_BYTES, size - HEADER_BYTES);
}

/* ---- writer -------------------------------------------------------------------- */

typedef struct writer {
  unsigned char *data;
  size_t size, cap;
  bool failed;
} writer;

static void put_bytes(writer *w, const void *src, size_t n) {
  if (w->failed) return;
  if (w->size + n > w->cap) {
    size_t cap = w->cap ? w->cap : 4096;
    while (cap < w->size + n) cap *= 2;
    unsigned char *d = realloc(w->data, cap);
    if (!d) {
      w->failed = true;
      return;
    }
    w->data = d;
    w->cap = cap;
  }
  memcpy(w->data + w->size, src, n);
  w->size += n;
}

static void put_u64(writer *w, uint64_t v) {
  unsigned char b[8];
  for (int i = 0; i < 8; ++i) b[i] = (unsigned char)(v >> (8 * i));
  put_bytes(w, b, 8);
}
static void put_u32(writer *w, uint32_t v) {
  unsigned char b[4];
  for (int i = 0; i < 4; ++i) b[i] = (unsigned char)(v >> (8 * i));
  put_bytes(w, b, 4);
}
static void put_u8(writer *w, uint8_t v) { put_bytes(w, &v, 1); }
static void put_i32(writer *w, int32_t v) { put_u32(w, (uint32_t)v); }
static void put_i64(writer *w, int64_t v) { put_u64(w, (uint64_t)v); }
static void put_f32(writer *w, float v) {
  uint32_t u;
  memcpy(&u, &v, 4);
  put_u32(w, u);
}
static void put_f64(writer *w, double v) {
  uint64_t u;
  memcpy(&u, &v, 8);
  put_u64(w, u);
}
static void put_vec3(writer *w, iris_vec3 v) {
  put_f32(w, v.x);
  put_f32(w, v.y);
  put_f32(w, v.z);
}

static uint32_t texels_of(const iris_guiding *g, const iris_cache *c) {
  return c->sphere ? g->sphere.texel_count : g->hemi.texel_count;
}

/* The parameters that shape sampling (and those that describe the guide). */
static void put_params(writer *w, const iris_guiding_params *p) {
  put_i64(w, p->photons);
  put_i64(w, p->caches);
  put_i32(w, p->cache_res);
  put_i32(w, p->cache_k);
  put_f32(w, p->pdf_floor);
  put_f32(w, p->alpha_max);
  put_f32(w, p->cos_min);
  put_u32(w, (uint32_t)p->splat);
  put_u8(w, p->force);
  put_u8(w, p->use_nee);
  put_i32(w, p->direct_photons);
  put_u8(w, p->adjoint_rr);
  put_i32(w, p->train_spp);
  put_u8(w, p->learn_alpha);
  put_f32(w, p->train_prior);
  put_u8(w, p->train_all_light);
  put_u32(w, (uint32_t)p->photon_lights);
  put_i32(w, p->refine);
  put_f32(w, p->light_min);
}

static void put_stats(writer *w, const iris_guiding_stats *s) {
  put_u64(w, s->photon_paths);
  put_u64(w, s->photons_stored);
  put_u64(w, s->photons_indirect);
  put_u64(w, s->caches);
  put_u64(w, s->camera_caches);
  put_u64(w, s->empty_caches);
  put_i32(w, s->cache_res);
  put_i32(w, s->cache_k);
  put_i32(w, s->camera_stride);
  put_f32(w, s->pdf_floor);
  put_f64(w, s->photon_seconds);
  put_f64(w, s->cache_seconds);
  put_f64(w, s->total_seconds);
  put_i32(w, s->train_spp);
  put_i32(w, s->train_iterations);
  put_u64(w, s->train_samples);
  put_f64(w, s->train_seconds);
  put_f64(w, s->indirect_share);
  put_f64(w, s->seen_indirect_energy);
  put_f64(w, s->caustic_share);
  put_u8(w, s->skipped);
  size_t n = 0;
  while (n < REASON_MAX && s->reason[n]) ++n;
  put_u32(w, (uint32_t)n);
  put_bytes(w, s->reason, n);
}

iris_status iris_guiding_save(const iris_guiding *g, const char *path, uint64_t scene_hash,
                              uint64_t settings_hash, iris_error *err) {
  writer w = {NULL, 0, 0, false};
  put_bytes(&w, MAGIC, sizeof MAGIC);
  put_u32(&w, IRIS_GUIDE_FILE_VERSION);
  const bool lights = !g->stats.skipped && g->lights.count;
  put_u32(&w, lights ? GUIDE_FLAG_LIGHTS : 0);
  put_u64(&w, scene_hash);
  put_u64(&w, settings_hash);
  put_u64(&w, 0); /* payload size, set below */
  put_u64(&w, 0); /* checksum, set below */
  put_params(&w, &g->params);
  put_stats(&w, &g->stats);
  const bool skipped = g->stats.skipped;
  const size_t count = skipped ? 0 : g->cache_count;
  uint64_t texels = 0;
  for (size_t i = 0; i < count; ++i) texels += texels_of(g, &g->caches[i]);
  /* The pick grid is rebuilt on load from the caches, the radius and the
   * spacing argument; 2 x its cell edge is a spacing that reproduces the same
   * cell exactly (0.5 * 2 * cell is exact in float, and that cell already
   * passed the grid's cell-count cap), n and lo are stored to check it. */
  const bool grid = !skipped && g->grid.n[0] > 0;
  put_u32(&w, (uint32_t)g->params.cache_res);
  put_f32(&w, g->pick_radius2); /* 0 in a skipped guide */
  put_f32(&w, grid ? 2.0f * g->grid.cell : 0.0f);
  for (int a = 0; a < 3; ++a) put_i32(&w, grid ? g->grid.n[a] : 0);
  for (int a = 0; a < 3; ++a) put_f32(&w, grid ? g->grid.lo[a] : 0.0f);
  put_u32(&w, (uint32_t)g->lamp_count); /* the spheres the caches' lamp shares name */
  for (size_t i = 0; i < g->lamp_count; ++i) {
    put_vec3(&w, g->lamps[i].center);
    put_f32(&w, g->lamps[i].radius);
  }
  const uint32_t glints = skipped ? 0 : g->glints.count; /* glint photons ("Glints"), written last */
  put_f32(&w, glints ? g->glints.radius2 : 0.0f);
  put_u64(&w, glints ? g->glints.paths : 0);
  put_u32(&w, glints);
  put_u64(&w, (uint64_t)count);
  put_u64(&w, texels);
  /* Caches, with table offsets into the compacted tables (the in-memory
   * tables keep the holes of the caches dropped without photons). */
  uint32_t at = 0;
  for (size_t i = 0; i < count; ++i) {
    const iris_cache *c = &g->caches[i];
    put_vec3(&w, c->p);
    put_vec3(&w, c->frame.s);
    put_vec3(&w, c->frame.t);
    put_vec3(&w, c->frame.n);
    put_u32(&w, at);
    put_u32(&w, c->photons);
    put_f32(&w, c->radiance);
    put_f32(&w, c->alpha);
    put_f32(&w, c->light);
    put_u8(&w, c->sphere);
    put_u8(&w, c->from_camera);
    put_f32(&w, c->sky_through);
    for (int k = 0; k < IRIS_CACHE_LAMPS; ++k) {
      put_f32(&w, c->lamp_share[k]);
      put_u8(&w, c->lamp[k]);
    }
    put_f32(&w, c->pane_share);
    for (int k = 0; k < 4; ++k) put_f32(&w, c->pane[k]);
    put_f32(&w, c->glint_share);
    put_vec3(&w, c->portal.o);
    put_vec3(&w, c->portal.u);
    put_vec3(&w, c->portal.v);
    put_f32(&w, c->portal_weight);
    at += texels_of(g, c);
  }
  for (size_t i = 0; i < count; ++i) {
    const iris_cache *c = &g->caches[i];
    for (uint32_t t = 0; t < texels_of(g, c); ++t) put_f32(&w, g->pdf[c->table + t]);
  }
  for (size_t i = 0; i < count; ++i) {
    const iris_cache *c = &g->caches[i];
    for (uint32_t t = 0; t < texels_of(g, c); ++t) {
      put_f32(&w, g->alias[c->table + t].q);
      put_u32(&w, g->alias[c->table + t].alias);
    }
  }
  if (g->params.refine > 0 && g->refine_slot) { /* refinement (refine.h): slots, then sub-tables */
    for (size_t i = 0; i < count; ++i) {
      const iris_cache *c = &g->caches[i];
      put_bytes(&w, g->refine_slot + c->table, texels_of(g, c));
    }
    for (size_t i = 0; i < count; ++i) {
      const float *sub = iris_guiding_sub(g, &g->caches[i]);
      for (int k = 0; k < IRIS_REFINE_MAX * IRIS_REFINE_SUB; ++k) put_f32(&w, sub[k]);
    }
  }
  if (lights) {
    put_f32(&w, g->lights.beta);
    put_u64(&w, g->lights.direct_photons);
    for (size_t i = 0; i < count; ++i) {
      put_u8(&w, g->lights.count[i]);
      for (int k = 0; k < IRIS_LIGHT_SELECT_SLOTS; ++k) {
        const iris_light_select_slot *sl = &g->lights.slots[i * IRIS_LIGHT_SELECT_SLOTS + (size_t)k];
        put_u32(&w, sl->leaf);
        put_f32(&w, sl->cdf);
      }
    }
  }
  for (uint32_t i = 0; i < glints; ++i) {
    const iris_glint_photon *gp = &g->glints.photons[i];
    put_vec3(&w, gp->p);
    put_vec3(&w, gp->n);
    put_vec3(&w, gp->y);
    put_f32(&w, gp->energy);
  }
  if (w.failed) {
    free(w.data);
    return iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "out of memory writing the guide");
  }
  uint64_t payload = (uint64_t)(w.size - HEADER_BYTES);
  for (int i = 0; i < 8; ++i) w.data[32 + i] = (unsigned char)(payload >> (8 * i));
  uint64_t sum = iris_guide_file_checksum(w.data, w.size);
  for (int i = 0; i < 8; ++i) w.data[CHECKSUM_AT + i] = (unsigned char)(sum >> (8 * i));
  iris_status st = iris_file_write_atomic(path, w.data, w.size, err);
  free(w.data);
  return st;
}

/* ---- reader -------------------------------------------------------------------- */

typedef struct reader {
  const unsigned char *p;
  size_t left;
  bool short_read;
} reader;

static const unsigned char *take(reader *r, size_t n) {
  if (r->short_read || n > r->left) {
    r->short_read = true;
    return NULL;
  }
  const unsigned char *p = r->p;
  r->p += n;
  r->left -= n;
  return p;
}
static uint64_t get_u64(reader *r) {
  const unsigned char *b = take(r, 8);
  uint64_t v = 0;
  if (b)
    for (int i = 7; i >= 0; --i) v = (v << 8) | b[i];
  return v;
}
static uint32_t get_u32(reader *r) {
  const unsigned char *b = take(r, 4);
  uint32_t v = 0;
  if (b)
    for (int i = 3; i >= 0; --i) v = (v << 8) | b[i];
  return v;
}
static uint8_t get_u8(reader *r) {
  const unsigned char *b = take(r, 1);
  return b ? b[0] : 0;
}
static int32_t get_i32(reader *r) { return (int32_t)get_u32(r); }
static int64_t get_i64(reader *r) { return (int64_t)get_u64(r); }
static float get_f32(reader *r) {
  uint32_t u = get_u32(r);
  float v;
  memcpy(&v, &u, 4);
  return v;
}
static double get_f64(reader *r) {
  uint64_t u = get_u64(r);
  double v;
  memcpy(&v, &u, 8);
  return v;
}
static iris_vec3 get_vec3(reader *r) {
  float x = get_f32(r), y = get_f32(r);
  return iris_v3(x, y, get_f32(r));
}
static bool finite3(iris_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

/* Fills p from the file; false when a value is outside what a build makes. */
static bool get_params(reader *r, iris_guiding_params *p) {
  p->photons = get_i64(r);
  p->caches = get_i64(r);
  p->cache_res = get_i32(r);
  p->cache_k = get_i32(r);
  p->pdf_floor = get_f32(r);
  p->alpha_max = get_f32(r);
  p->cos_min = get_f32(r);
  uint32_t splat = get_u32(r);
  uint8_t force = get_u8(r), use_nee = get_u8(r);
  p->direct_photons = get_i32(r);
  uint8_t adjoint = get_u8(r);
  p->train_spp = get_i32(r);
  uint8_t learn = get_u8(r);
  p->train_prior = get_f32(r);
  uint8_t all_light = get_u8(r);
  uint32_t lights = get_u32(r);
  p->refine = get_i32(r);
  p->light_min = get_f32(r);
  p->train_all_light = all_light != 0;
  p->splat = (iris_splat_mode)splat;
  p->force = force != 0;
  p->use_nee = use_nee != 0;
  p->adjoint_rr = adjoint != 0;
  p->learn_alpha = learn != 0;
  p->photon_lights = (iris_emission_selection)lights;
  return splat <= IRIS_SPLAT_BILINEAR && force <= 1 && use_nee <= 1 && adjoint <= 1 && learn <= 1 && lights <= 1 &&
         all_light <= 1 && isfinite(p->train_prior) && p->train_prior >= 0.0f &&
         p->cache_res >= 1 && p->cache_res <= IRIS_OCTMAP_MAX_RES && p->cache_k >= 1 && isfinite(p->pdf_floor) &&
         p->pdf_floor >= 0.0f && p->pdf_floor <= 1.0f && isfinite(p->alpha_max) && p->alpha_max >= 0.0f &&
         p->alpha_max < 1.0f && isfinite(p->cos_min) && p->cos_min >= -1.0f && p->cos_min <= 1.0f &&
         p->direct_photons >= -1 && p->direct_photons <= 1 && p->refine >= 0 && p->refine <= IRIS_REFINE_MAX &&
         p->light_min > 0.0f && p->light_min <= 1.0f;
}

static bool get_stats(reader *r, iris_guiding_stats *s) {
  s->photon_paths = get_u64(r);
  s->photons_stored = get_u64(r);
  s->photons_indirect = get_u64(r);
  s->caches = get_u64(r);
  s->camera_caches = get_u64(r);
  s->empty_caches = get_u64(r);
  s->cache_res = get_i32(r);
  s->cache_k = get_i32(r);
  s->camera_stride = get_i32(r);
  s->pdf_floor = get_f32(r);
  s->photon_seconds = get_f64(r);
  s->cache_seconds = get_f64(r);
  s->total_seconds = get_f64(r);
  s->train_spp = get_i32(r);
  s->train_iterations = get_i32(r);
  s->train_samples = get_u64(r);
  s->train_seconds = get_f64(r);
  s->indirect_share = get_f64(r);
  s->seen_indirect_energy = get_f64(r);
  s->caustic_share = get_f64(r);
  s->pilot_share = -1.0;
  uint8_t skipped = get_u8(r);
  if (!(s->indirect_share >= -1.0 && s->indirect_share <= 1.0) ||
      !(s->seen_indirect_energy >= -1.0 && s->seen_indirect_energy <= 1.0) ||
      !(s->caustic_share == -1.0 || (s->caustic_share >= 0.0 && s->caustic_share <= 1.0)))
    return false;
  if (s->train_spp < 0 || s->train_iterations < 0) return false;
  uint32_t n = get_u32(r);
  s->skipped = skipped != 0;
  if (skipped > 1 || n > REASON_MAX) return false;
  const unsigned char *text = take(r, n);
  if (text) memcpy(s->reason, text, n);
  s->reason[n] = 0;
  for (uint32_t i = 0; i < n; ++i)
    if (s->reason[i] < 0x20 || s->reason[i] == 0x7f) return false;
  return isfinite(s->photon_seconds) && isfinite(s->cache_seconds) && isfinite(s->total_seconds);
}

static iris_status refuse(iris_error *err, const char *path, const char *what) {
  return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "%s", what);
}

/* Parses and checks the payload into g (caches, tables, params, stats). */
static iris_status read_payload(reader *r, const char *path, iris_guiding *g, uint32_t *res_out, float *spacing,
                                int grid_n[3], float grid_lo[3], bool lights, iris_error *err) {
  if (!get_params(r, &g->params) || r->short_read)
    return refuse(err, path, "guide file has invalid guiding parameters (corrupted)");
  if (!get_stats(r, &g->stats) || r->short_read)
    return refuse(err, path, "guide file has invalid statistics (corrupted)");
  uint32_t res = get_u32(r);
  g->pick_radius2 = get_f32(r);
  *spacing = get_f32(r);
  for (int a = 0; a < 3; ++a) grid_n[a] = get_i32(r);
  for (int a = 0; a < 3; ++a) grid_lo[a] = get_f32(r);
  uint32_t lamps = get_u32(r);
  if (r->short_read) return refuse(err, path, "guide file is truncated");
  if (lamps > IRIS_GUIDING_LAMP_GROUPS) return refuse(err, path, "guide file has too many lamps (corrupted)");
  if (lamps) {
    g->lamps = calloc(lamps, sizeof *g->lamps);
    if (!g->lamps) return iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "out of memory for lamps");
    g->lamp_count = lamps;
  }
  for (uint32_t i = 0; i < lamps; ++i) {
    g->lamps[i].center = get_vec3(r);
    g->lamps[i].radius = get_f32(r);
    if (!finite3(g->lamps[i].center) || !(g->lamps[i].radius >= 0.0f && isfinite(g->lamps[i].radius)))
      return refuse(err, path, "guide file has an invalid lamp (corrupted)");
  }
  const float glint_r2 = get_f32(r);
  const uint64_t glint_paths = get_u64(r);
  const uint32_t glints = get_u32(r);
  uint64_t count = get_u64(r), texels = get_u64(r);
  if (r->short_read) return refuse(err, path, "guide file is truncated");
  if (!(glints == 0 ? glint_r2 == 0.0f && glint_paths == 0 : glint_r2 > 0.0f && isfinite(glint_r2) && glint_paths >= glints))
    return refuse(err, path, "guide file has invalid glint photon counts (corrupted)");
  if (res != (uint32_t)g->params.cache_res)
    return refuse(err, path, "guide file's map size differs from its cache resolution (corrupted)");
  if (isnan(g->pick_radius2) || !(g->pick_radius2 > 0.0f || (g->stats.skipped && g->pick_radius2 == 0.0f)) ||
      !isfinite(*spacing) || *spacing < 0.0f)
    return refuse(err, path, "guide file has an invalid cache search radius (corrupted)");
  for (int a = 0; a < 3; ++a)
    if (grid_n[a] < 0 || !isfinite(grid_lo[a]))
      return refuse(err, path, "guide file has an invalid cache grid (corrupted)");
  /* Counts bounded by the bytes that remain before anything is allocated. */
  const uint64_t light_bytes = lights ? LIGHTS_HEAD_BYTES + count * LIGHTS_CACHE_BYTES : 0;
  const bool refined = g->params.refine > 0;
  const uint64_t cache_bytes = CACHE_BYTES + (refined ? REFINE_CACHE_BYTES : 0);
  const uint64_t texel_bytes = TEXEL_BYTES + (refined ? 1u : 0u);
  const uint64_t glint_bytes = (uint64_t)glints * GLINT_BYTES;
  if (count > r->left / cache_bytes || texels > r->left / texel_bytes || glint_bytes > r->left ||
      count * cache_bytes + texels * texel_bytes + light_bytes + glint_bytes != r->left)
    return refuse(err, path, "guide file's cache and texel counts do not match its size (corrupted)");
  if (count > UINT32_MAX || texels > UINT32_MAX)
    return refuse(err, path, "guide file has too many caches or texels");
  if (g->stats.skipped && count != 0)
    return refuse(err, path, "guide file of a skipped guide holds caches (corrupted)");
  *res_out = res;
  g->caches = calloc(count ? (size_t)count : 1, sizeof(iris_cache));
  g->pdf = malloc(sizeof(float) * (texels ? (size_t)texels : 1));
  g->alias = malloc(sizeof(iris_cache_alias) * (texels ? (size_t)texels : 1));
  if (refined) {
    g->refine_slot = malloc(texels ? (size_t)texels : 1);
    /* indexed by table / hemisphere texels, as iris_guiding_sub does */
    g->refine_sub = calloc((size_t)(texels / ((uint64_t)res * res)) + 1, REFINE_CACHE_BYTES);
  }
  if (!g->caches || !g->pdf || !g->alias || (refined && (!g->refine_slot || !g->refine_sub)))
    return iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "out of memory for %llu caches",
                          (unsigned long long)count);
  g->cache_count = (size_t)count;
  const uint32_t hemi = res * res, sphere = 2u * res * res;
  uint64_t at = 0;
  for (size_t i = 0; i < g->cache_count; ++i) {
    iris_cache *c = &g->caches[i];
    c->p = get_vec3(r);
    c->frame.s = get_vec3(r);
    c->frame.t = get_vec3(r);
    c->frame.n = get_vec3(r);
    c->table = get_u32(r);
    c->photons = get_u32(r);
    c->radiance = get_f32(r);
    c->alpha = get_f32(r);
    c->light = get_f32(r);
    uint8_t sph = get_u8(r), cam = get_u8(r);
    c->sphere = sph;
    c->from_camera = cam;
    c->sky_through = get_f32(r);
    float through = c->sky_through;
    bool lamps_ok = true;
    for (int k = 0; k < IRIS_CACHE_LAMPS; ++k) {
      c->lamp_share[k] = get_f32(r);
      c->lamp[k] = get_u8(r);
      /* a share names a lamp with a sphere; slots after an empty one are empty */
      if (!(c->lamp_share[k] >= 0.0f && c->lamp_share[k] <= 1.0f) ||
          (c->lamp_share[k] > 0.0f && (c->lamp[k] >= lamps || !(g->lamps[c->lamp[k]].radius > 0.0f) ||
                                       (k > 0 && !(c->lamp_share[k - 1] > 0.0f)))))
        lamps_ok = false;
      through += c->lamp_share[k];
    }
    c->pane_share = get_f32(r);
    for (int k = 0; k < 4; ++k) c->pane[k] = get_f32(r);
    through += c->pane_share;
    c->glint_share = get_f32(r);
    through += c->glint_share;
    c->portal.o = get_vec3(r);
    c->portal.u = get_vec3(r);
    c->portal.v = get_vec3(r);
    c->portal_weight = get_f32(r);
    /* a weight names a rectangle (orthogonal half-axes); none: all zero */
    const bool portal_ok =
        finite3(c->portal.o) && finite3(c->portal.u) && finite3(c->portal.v) &&
        (c->portal_weight == 0.0f ? !iris_portal_present(&c->portal)
                                  : c->portal_weight > 0.0f && c->portal_weight <= 1.0f &&
                                        iris_portal_present(&c->portal) &&
                                        fabsf(iris_dot(c->portal.u, c->portal.v)) <=
                                            1e-4f * iris_length(c->portal.u) * iris_length(c->portal.v));
    /* a share asks the vertex for a spot among glint photons: there must be some */
    const bool glint_ok = c->glint_share == 0.0f || (c->glint_share > 0.0f && c->glint_share <= 1.0f && glints > 0);
    const float pn2 = c->pane[0] * c->pane[0] + c->pane[1] * c->pane[1] + c->pane[2] * c->pane[2];
    /* a share names a plane: a unit normal and an index ratio a build makes (1/4 to 4) */
    const bool pane_ok = (c->pane_share == 0.0f && pn2 == 0.0f && c->pane[3] == 0.0f) || /* none: all zero */
                         (c->pane_share > 0.0f && c->pane_share <= 1.0f && fabsf(pn2 - 1.0f) < 1e-3f &&
                          c->pane[3] >= 0.25f && c->pane[3] <= 4.0f);
    if (!finite3(c->p) || !finite3(c->frame.s) || !finite3(c->frame.t) || !finite3(c->frame.n))
      return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "cache %zu: position or frame is not finite (corrupted)", i);
    if (sph > 1 || cam > 1 || c->photons == 0 || !isfinite(c->radiance) || c->radiance < 0.0f ||
        !isfinite(c->alpha) || c->alpha > 1.0f || !(c->sky_through >= 0.0f && c->sky_through <= 1.0f) ||
        !(c->light > 0.0f && c->light <= 1.0f))
      return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "cache %zu: invalid values (corrupted)", i);
    if (!pane_ok)
      return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "cache %zu: invalid pane (corrupted)", i);
    if (!glint_ok)
      return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "cache %zu: invalid glint share (corrupted)", i);
    if (!portal_ok)
      return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "cache %zu: invalid portal (corrupted)", i);
    g->stats.portal_caches += c->portal_weight > 0.0f;
    if (!lamps_ok || !(through <= 1.001f)) /* the shares are of the same photons' energy */
      return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "cache %zu: invalid lamp shares (corrupted)", i);
    /* Tables are stored back to back in cache order: exactly one offset is right. */
    uint32_t n = sph ? sphere : hemi;
    if ((uint64_t)c->table != at || at + n > texels)
      return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL,
                            "cache %zu: table offset %u out of place (expected %llu of %llu texels; corrupted)",
                            i, c->table, (unsigned long long)at, (unsigned long long)texels);
    at += n;
  }
  if (at != texels) return refuse(err, path, "guide file's tables do not add up to its texel count (corrupted)");
  for (size_t t = 0; t < (size_t)texels; ++t) {
    g->pdf[t] = get_f32(r);
    if (!isfinite(g->pdf[t]) || g->pdf[t] < 0.0f)
      return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "pdf texel %zu is negative or not finite (corrupted)", t);
  }
  for (size_t i = 0; i < g->cache_count; ++i) {
    const iris_cache *c = &g->caches[i];
    uint32_t n = c->sphere ? sphere : hemi;
    for (uint32_t t = 0; t < n; ++t) {
      iris_cache_alias *a = &g->alias[c->table + t];
      a->q = get_f32(r);
      a->alias = get_u32(r);
      if (!(a->q >= 0.0f && a->q <= 1.0f) || a->alias >= n)
        return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "cache %zu: alias table entry %u out of range (corrupted)",
                              i, t);
    }
  }
  if (refined) {
    for (size_t t = 0; t < (size_t)texels; ++t) {
      g->refine_slot[t] = get_u8(r);
      if (g->refine_slot[t] > g->params.refine)
        return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "refinement slot of texel %zu out of range (corrupted)", t);
    }
    for (size_t i = 0; i < g->cache_count; ++i) {
      float *sub = g->refine_sub + (size_t)(g->caches[i].table / hemi) * IRIS_REFINE_MAX * IRIS_REFINE_SUB;
      for (int k = 0; k < IRIS_REFINE_MAX * IRIS_REFINE_SUB; ++k) {
        sub[k] = get_f32(r);
        if (!isfinite(sub[k]) || sub[k] < 0.0f || sub[k] > (float)IRIS_REFINE_SUB)
          return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "cache %zu: refinement table out of range (corrupted)", i);
      }
    }
  }
  if (lights) { /* checked against the lights' tree when the render attaches them (light_select.h) */
    iris_light_select *sel = &g->lights;
    sel->beta = get_f32(r);
    sel->direct_photons = get_u64(r);
    sel->cache_count = g->cache_count;
    sel->count = calloc(g->cache_count ? g->cache_count : 1, 1);
    sel->slots = calloc((g->cache_count ? g->cache_count : 1) * IRIS_LIGHT_SELECT_SLOTS, sizeof *sel->slots);
    if (!sel->count || !sel->slots) return iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "out of memory");
    for (size_t i = 0; i < g->cache_count; ++i) {
      sel->count[i] = get_u8(r);
      sel->learned_caches += sel->count[i] > 0;
      for (size_t k = 0; k < IRIS_LIGHT_SELECT_SLOTS; ++k) {
        sel->slots[i * IRIS_LIGHT_SELECT_SLOTS + k].leaf = get_u32(r);
        sel->slots[i * IRIS_LIGHT_SELECT_SLOTS + k].cdf = get_f32(r);
      }
    }
  }
  if (glints) {
    g->glints.photons = malloc((size_t)glints * sizeof *g->glints.photons);
    if (!g->glints.photons) return iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "out of memory for glint photons");
    g->glints.count = glints;
    g->glints.radius2 = glint_r2;
    g->glints.paths = glint_paths;
    for (uint32_t i = 0; i < glints; ++i) {
      iris_glint_photon *gp = &g->glints.photons[i];
      gp->p = get_vec3(r);
      gp->n = get_vec3(r);
      gp->y = get_vec3(r);
      gp->energy = get_f32(r);
      if (!finite3(gp->p) || !finite3(gp->n) || !finite3(gp->y) || !(gp->energy > 0.0f && isfinite(gp->energy)))
        return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "glint photon %u: invalid values (corrupted)", i);
    }
  }
  if (r->short_read || r->left != 0) return refuse(err, path, "guide file is truncated");
  return IRIS_OK;
}

iris_status iris_guiding_load(const char *path, uint64_t scene_hash, uint64_t settings_hash, int threads,
                              iris_guiding **out, iris_error *err) {
  *out = NULL;
  char *data = NULL;
  size_t size = 0;
  iris_status st = iris_file_read(path, 0, &data, &size, err);
  if (st != IRIS_OK) return st;
  const unsigned char *d = (const unsigned char *)data;
  reader r = {d, size, false};
  /* Header: what the file is, then whether it is whole, then whether it is intact, then whose it is. */
  const unsigned char *magic = take(&r, sizeof MAGIC);
  if (!magic || memcmp(magic, MAGIC, sizeof MAGIC) != 0) {
    free(data);
    return refuse(err, path, "not an iris guide file (written by iris render --guide-out)");
  }
  uint32_t version = get_u32(&r);
  const uint32_t flags = get_u32(&r);
  uint64_t file_scene = get_u64(&r), file_settings = get_u64(&r), payload = get_u64(&r), sum = get_u64(&r);
  if (r.short_read) {
    free(data);
    return refuse(err, path, "guide file is truncated");
  }
  if (version != IRIS_GUIDE_FILE_VERSION) {
    free(data);
    return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL,
                          "guide file version %u, this iris reads version %u; write it again with --guide-out",
                          version, IRIS_GUIDE_FILE_VERSION);
  }
  if (payload != size - HEADER_BYTES) {
    free(data);
    return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL, "guide file is %s (%zu bytes, the header says %llu)",
                          payload > size - HEADER_BYTES ? "truncated" : "longer than written", size,
                          (unsigned long long)payload + HEADER_BYTES);
  }
  if (iris_guide_file_checksum(d, size) != sum) {
    free(data);
    return refuse(err, path, "guide file is corrupted (checksum mismatch)");
  }
  if (file_scene != scene_hash) {
    free(data);
    return iris_error_set(err, IRIS_ERR_PARSE, path, 0, NULL,
                          "guide file was made for another scene (scene hash %016llx, this scene %016llx)",
                          (unsigned long long)file_scene, (unsigned long long)scene_hash);
  }
  if (file_settings != settings_hash) {
    free(data);
    return refuse(err, path,
                  "guide file was made with other settings (camera, frame size, seed, sampler, method, depths or "
                  "guiding options differ)");
  }
  iris_guiding *g = calloc(1, sizeof *g);
  if (!g) {
    free(data);
    return iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "out of memory");
  }
  uint32_t res = 0;
  float spacing = 0.0f, grid_lo[3];
  int grid_n[3];
  st = read_payload(&r, path, g, &res, &spacing, grid_n, grid_lo, (flags & GUIDE_FLAG_LIGHTS) != 0, err);
  free(data);
  /* Derived and deterministic: rebuilt as iris_guiding_build makes them. */
  if (st == IRIS_OK) st = iris_octmap_create(&g->hemi, (int)res, false, err);
  if (st == IRIS_OK) st = iris_octmap_create(&g->sphere, (int)res, true, err);
  if (st == IRIS_OK && !g->stats.skipped)
    st = iris_kdtree_build(&g->tree, &g->caches[0].p, sizeof(iris_cache), (uint32_t)g->cache_count, err);
  if (st == IRIS_OK && !g->stats.skipped)
    st = iris_pick_grid_build(&g->grid, &g->tree, IRIS_GUIDING_PICK_K, g->pick_radius2, spacing, threads, err);
  if (st == IRIS_OK) st = iris_glints_index(&g->glints, threads, err);
  if (st == IRIS_OK && (g->grid.n[0] != grid_n[0] || g->grid.n[1] != grid_n[1] || g->grid.n[2] != grid_n[2] ||
                        (grid_n[0] && memcmp(g->grid.lo, grid_lo, sizeof grid_lo) != 0)))
    st = refuse(err, path, "the cache grid rebuilt from the guide file differs from the one written (corrupted)");
  if (st != IRIS_OK) {
    iris_guiding_destroy(g);
    return st;
  }
  /* As iris_guiding_build counts it, with the compacted tables. */
  size_t texels = 0;
  for (size_t i = 0; i < g->cache_count; ++i) texels += texels_of(g, &g->caches[i]);
  g->stats.memory_bytes = (sizeof(iris_cache) + sizeof(float) * 3 + sizeof(uint32_t) + 1) * g->cache_count +
                          (sizeof(float) + sizeof(iris_cache_alias)) * texels +
                          sizeof(double) * (g->hemi.texel_count + g->sphere.texel_count) + g->grid.memory_bytes +
                          (g->refine_sub ? texels + (size_t)REFINE_CACHE_BYTES * (texels / g->hemi.texel_count + 1) : 0) +
                          iris_glints_bytes(g->glints.count);
  iris_guiding_count_refined(g);
  *out = g;
  return IRIS_OK;
}

/* ---- settings hash ------------------------------------------------------------- */

static uint64_t mix_u64(uint64_t h, uint64_t v) { return iris_mix64(h ^ (v + 0x9e3779b97f4a7c15ULL)); }
static uint64_t mix_f32(uint64_t h, float f) {
  uint32_t u;
  memcpy(&u, &f, 4);
  return mix_u64(h, u);
}
static uint64_t mix_vec3(uint64_t h, iris_vec3 v) { return mix_f32(mix_f32(mix_f32(h, v.x), v.y), v.z); }

uint64_t iris_guiding_settings_hash(const iris_guide_setup *s, const iris_guiding_params *p) {
  uint64_t h = 0x67756964652d7331ULL;
  const iris_pinhole *c = s->camera;
  h = mix_vec3(h, c->origin);
  h = mix_vec3(h, c->right);
  h = mix_vec3(h, c->up);
  h = mix_vec3(h, c->forward);
  h = mix_f32(h, c->tan_half_yfov);
  h = mix_f32(h, c->aspect);
  h = mix_u64(h, (uint64_t)c->width);
  h = mix_u64(h, (uint64_t)c->height);
  h = mix_u64(h, s->seed);
  h = mix_u64(h, (uint64_t)s->sampler);
  if (s->integrator) {
    h = mix_u64(h, (uint64_t)s->integrator->method);
    h = mix_u64(h, s->deciding); /* --method auto applies a rule of its own */
    h = mix_u64(h, (uint64_t)(int64_t)s->integrator->max_depth);
    h = mix_u64(h, (uint64_t)(int64_t)s->integrator->rr_depth);
  }
  bool area_only = s->lights && s->lights->tri_count > 0 && (s->lights->tris[0].flags & IRIS_LIGHT_TRI_AREA_ONLY);
  h = mix_u64(h, area_only);
  /* training's light samples choose through the tree or by power; the power
   * sampler keeps the hash guides had before the tree */
  if (s->lights && s->lights->tree) h = mix_u64(h, 0x7ee11ULL);
  /* --light-sampler learned: the file holds the caches' light tables */
  if (s->learn_lights) h = mix_u64(h, 0x1ea4edULL);
  /* ... learned from training's light samples too (guides before that differ) */
  if (s->learn_lights && p->light_samples) h = mix_u64(h, 0x5a3b1eULL);
  /* The guiding options as requested (auto values resolve the same way from
   * the same scene and camera). train_spp enters as given: with -1 (auto)
   * the training budget follows the writer's spp/time, which are left out so
   * that partitions of other sizes can read the guide (docs/guiding.md). */
  h = mix_u64(h, (uint64_t)p->photons);
  h = mix_u64(h, (uint64_t)p->caches);
  h = mix_u64(h, (uint64_t)(int64_t)p->cache_res);
  h = mix_u64(h, (uint64_t)(int64_t)p->cache_k);
  h = mix_f32(h, p->pdf_floor);
  h = mix_f32(h, p->alpha_max);
  h = mix_f32(h, p->cos_min);
  h = mix_u64(h, (uint64_t)p->splat);
  h = mix_u64(h, p->force);
  h = mix_u64(h, p->use_nee);
  h = mix_u64(h, (uint64_t)(int64_t)p->direct_photons);
  h = mix_u64(h, p->adjoint_rr);
  h = mix_u64(h, (uint64_t)(int64_t)p->train_spp);
  h = mix_u64(h, p->learn_alpha);
  h = mix_f32(h, p->train_prior);
  h = mix_u64(h, p->train_all_light);
  h = mix_u64(h, (uint64_t)p->photon_lights);
  /* the sky visibility is rebuilt when the guide is read, with these */
  h = mix_u64(h, (uint64_t)(int64_t)p->sky_regions);
  h = mix_u64(h, (uint64_t)(int64_t)p->sky_probes);
  h = mix_f32(h, p->sky_beta);
  h = mix_u64(h, (uint64_t)(int64_t)p->refine);
  /* lamps behind glass: keeps the hash of guides without lamp light through glass */
  if (!p->lamp_glass) h = mix_u64(h, 0x1a3b91a55ULL);
  if (!p->glints) h = mix_u64(h, 0x611e75ULL);
  if (!p->portals) h = mix_u64(h, 0x9027a15ULL);
  h = mix_f32(h, p->light_min);
  return h;
}
