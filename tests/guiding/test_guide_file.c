/* guiding.guide_file: the guide as a file (renderer/guiding/guide_file.h).
 * A guide written and read back is the same guide: every cache, its pdf and
 * alias tables (compacted: veach-mis with few photons drops caches, leaving
 * holes in the in-memory tables), the kd-tree, the pick grid and the answers
 * of Algorithm 1 and of the cache pdf at 20k random points; a skipped guide
 * stays skipped. Every damaged file is refused with IRIS_ERR_PARSE and never
 * loads: another scene or settings hash, truncation at 260 lengths, a flipped
 * byte at 260 places, and forged files whose checksum is right but whose
 * counts, offsets, floats or alias entries are wrong (ASan runs this too, so
 * an out-of-range read fails). A write into a missing folder fails and leaves
 * nothing. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/fileio.h"
#include "core/rng.h"
#include "renderer/accel.h"
#include "renderer/guiding/guide_file.h"
#include "renderer/guiding/guiding.h"
#include "renderer/lights.h"
#include "renderer/render.h"
#include "renderer/texture.h"
#include "scenes/builtin.h"
#include "guide_fixture.h"

#define SCENE_HASH 0x1234567890abcdefULL
#define SETTINGS_HASH 0xfedcba0987654321ULL
#define CB (138 + 5 * IRIS_CACHE_LAMPS) /* bytes of one cache record */

static iris_guiding *build(const char *name, iris_method method, int64_t photons, bool force) {
  iris_scene *s = NULL;
  iris_error err;
  iris_error_clear(&err);
  if (iris_builtin_create(name, &s, &err) != IRIS_OK) return NULL;
  iris_guiding_params gp = iris_guiding_params_default();
  gp.photons = photons;
  gp.force = force;
  gp.refine = IRIS_REFINE_MAX; /* the file carries the refinement (off by default) */
  iris_guiding *g = test_guide_build(s, method, gp, 3, 2, 4);
  iris_scene_destroy(s);
  return g;
}

static uint32_t texels(const iris_guiding *g, const iris_cache *c) {
  return c->sphere ? g->sphere.texel_count : g->hemi.texel_count;
}

/* Same caches (every field but the table offset), same table contents. */
static bool same_caches(const iris_guiding *a, const iris_guiding *b) {
  if (a->cache_count != b->cache_count) return false;
  for (size_t i = 0; i < a->cache_count; ++i) {
    const iris_cache *x = &a->caches[i], *y = &b->caches[i];
    if (memcmp(&x->p, &y->p, sizeof x->p) || memcmp(&x->frame, &y->frame, sizeof x->frame) ||
        x->photons != y->photons || memcmp(&x->radiance, &y->radiance, sizeof(float)) ||
        memcmp(&x->alpha, &y->alpha, sizeof(float)) || memcmp(&x->light, &y->light, sizeof(float)) ||
        memcmp(&x->pane_share, &y->pane_share, sizeof(float)) || memcmp(x->pane, y->pane, sizeof x->pane) ||
        memcmp(&x->glint_share, &y->glint_share, sizeof(float)) || x->sphere != y->sphere || x->from_camera != y->from_camera)
      return false;
    uint32_t n = texels(a, x);
    if (memcmp(a->pdf + x->table, b->pdf + y->table, n * sizeof(float)) ||
        memcmp(a->alias + x->table, b->alias + y->table, n * sizeof(iris_cache_alias)))
      return false;
    if ((a->refine_slot == NULL) != (b->refine_slot == NULL)) return false;
    if (a->refine_slot && (memcmp(a->refine_slot + x->table, b->refine_slot + y->table, n) ||
                           memcmp(iris_guiding_sub(a, x), iris_guiding_sub(b, y),
                                  sizeof(float) * IRIS_REFINE_MAX * IRIS_REFINE_SUB)))
      return false;
  }
  return true;
}

static bool same_grid(const iris_pick_grid *a, const iris_pick_grid *b) {
  if (memcmp(a->n, b->n, sizeof a->n) || a->cells != b->cells || a->id_count != b->id_count) return false;
  if (a->n[0] == 0) return true;
  return memcmp(a->lo, b->lo, sizeof a->lo) == 0 && a->cell == b->cell && a->inv_cell == b->inv_cell &&
         a->k == b->k && a->max_d2 == b->max_d2 && memcmp(a->answer, b->answer, a->cells * sizeof(uint32_t)) == 0 &&
         memcmp(a->ids, b->ids, a->id_count * sizeof(uint32_t)) == 0;
}

static bool same_tree(const iris_kdtree *a, const iris_kdtree *b) {
  return a->count == b->count && memcmp(a->points, b->points, 3 * sizeof(float) * a->count) == 0 &&
         memcmp(a->ids, b->ids, sizeof(uint32_t) * a->count) == 0;
}

static bool same_params(const iris_guiding_params *a, const iris_guiding_params *b) {
  return a->photons == b->photons && a->caches == b->caches && a->cache_res == b->cache_res &&
         a->cache_k == b->cache_k && a->pdf_floor == b->pdf_floor && a->alpha_max == b->alpha_max &&
         a->cos_min == b->cos_min && a->splat == b->splat && a->force == b->force && a->use_nee == b->use_nee &&
         a->direct_photons == b->direct_photons && a->adjoint_rr == b->adjoint_rr && a->train_spp == b->train_spp &&
         a->learn_alpha == b->learn_alpha && a->photon_lights == b->photon_lights;
}

/* Algorithm 1 and the cache pdf at random points near the caches, with the
 * caches' own normals and random ones: equal answers, equal pdf bits. */
static int pick_mismatches(const iris_guiding *a, const iris_guiding *b) {
  int bad = 0;
  for (uint64_t i = 0; i < 20000 && a->cache_count; ++i) {
    iris_sampler r = iris_sampler_start(9, i, 0);
    const iris_cache *c = &a->caches[(size_t)(iris_sampler_get(&r, 0) * (float)a->cache_count) % a->cache_count];
    float s = 0.3f;
    iris_vec3 p = iris_v3(c->p.x + s * (iris_sampler_get(&r, 1) - 0.5f), c->p.y + s * (iris_sampler_get(&r, 2) - 0.5f),
                          c->p.z + s * (iris_sampler_get(&r, 3) - 0.5f));
    iris_vec3 n = c->frame.n;
    if (i & 1)
      n = iris_normalize(iris_v3(iris_sampler_get(&r, 4) - 0.5f, iris_sampler_get(&r, 5) - 0.5f,
                                 iris_sampler_get(&r, 6) - 0.5f));
    uint32_t ia[IRIS_GUIDING_PICK_K], ib[IRIS_GUIDING_PICK_K];
    int ma = iris_guiding_pick(a, p, n, ia), mb = iris_guiding_pick(b, p, n, ib);
    if (ma != mb || memcmp(ia, ib, sizeof(uint32_t) * (size_t)ma)) {
      bad++;
      continue;
    }
    iris_vec3 w = iris_normalize(iris_v3(iris_sampler_get(&r, 7) - 0.5f, iris_sampler_get(&r, 8) - 0.5f,
                                         iris_sampler_get(&r, 9) - 0.5f));
    float pa = iris_guiding_cache_pdf(a, ia, ma, w), pb = iris_guiding_cache_pdf(b, ib, mb, w);
    bad += memcmp(&pa, &pb, sizeof pa) != 0;
  }
  return bad;
}

static iris_status load(const char *path, iris_guiding **g, iris_error *err) {
  iris_error_clear(err);
  return iris_guiding_load(path, SCENE_HASH, SETTINGS_HASH, 2, g, err);
}

static void round_trip(const char *dir, const char *tag, iris_guiding *g) {
  char path[1200];
  snprintf(path, sizeof path, "%s/%s.guide", dir, tag);
  iris_error err;
  iris_error_clear(&err);
  iris_status st = iris_guiding_save(g, path, SCENE_HASH, SETTINGS_HASH, &err);
  CHECK_OK(st, &err);
  iris_guiding *l = NULL;
  if (st == IRIS_OK) {
    st = load(path, &l, &err);
    CHECK_OK(st, &err);
  }
  if (st != IRIS_OK) return;
  iris_check_record(same_caches(g, l), __FILE__, __LINE__, "%s: caches and tables differ after the round trip", tag);
  CHECK(same_params(&g->params, &l->params));
  CHECK(memcmp(&g->pick_radius2, &l->pick_radius2, sizeof(float)) == 0);
  CHECK(l->stats.skipped == g->stats.skipped && strcmp(l->stats.reason, g->stats.reason) == 0);
  /* what --method auto decides from (provider_decision) */
  CHECK(memcmp(&l->stats.indirect_share, &g->stats.indirect_share, sizeof(double)) == 0 &&
        memcmp(&l->stats.seen_indirect_energy, &g->stats.seen_indirect_energy, sizeof(double)) == 0 &&
        memcmp(&l->stats.caustic_share, &g->stats.caustic_share, sizeof(double)) == 0);
  CHECK(l->stats.caches == g->stats.caches && l->stats.empty_caches == g->stats.empty_caches &&
        l->stats.photons_stored == g->stats.photons_stored && l->stats.camera_stride == g->stats.camera_stride);
  if (!g->stats.skipped) {
    iris_check_record(same_tree(&g->tree, &l->tree), __FILE__, __LINE__, "%s: cache kd-tree differs", tag);
    iris_check_record(same_grid(&g->grid, &l->grid), __FILE__, __LINE__, "%s: pick grid differs", tag);
    int bad = pick_mismatches(g, l);
    iris_check_record(bad == 0, __FILE__, __LINE__, "%s: %d of 20000 picks or pdfs differ", tag, bad);
  }
  iris_direction_sampler sa = iris_guiding_sampler(g), sb = iris_guiding_sampler(l);
  CHECK((sa.sample == NULL) == (sb.sample == NULL) && (sa.radiance_estimate == NULL) == (sb.radiance_estimate == NULL));
  iris_guiding_destroy(l);
}

/* ---- refusals -------------------------------------------------------------- */

static unsigned char *read_all(const char *path, size_t *size) {
  char *d = NULL;
  iris_error err;
  if (iris_file_read(path, 0, &d, size, &err) != IRIS_OK) return NULL;
  return (unsigned char *)d;
}

static bool write_all(const char *path, const void *d, size_t n) {
  FILE *f = fopen(path, "wb");
  if (!f) return false;
  bool ok = fwrite(d, 1, n, f) == n;
  return fclose(f) == 0 && ok;
}

/* Loads bytes d[0, n) as a file: true when refused with IRIS_ERR_PARSE naming it. */
static bool refused(const char *dir, const unsigned char *d, size_t n, const char *want) {
  char path[1200];
  snprintf(path, sizeof path, "%s/bad.guide", dir);
  if (!write_all(path, d, n)) return false;
  iris_guiding *g = NULL;
  iris_error err;
  iris_status st = load(path, &g, &err);
  bool ok = st == IRIS_ERR_PARSE && g == NULL && strcmp(err.file, path) == 0 && (!want || strstr(err.message, want));
  if (!ok) printf("  not refused as expected (status %d, want '%s'): %s\n", (int)st, want ? want : "", err.message);
  iris_guiding_destroy(g);
  return ok;
}

static void put64(unsigned char *p, uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = (unsigned char)(v >> (8 * i));
}
static void put32(unsigned char *p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = (unsigned char)(v >> (8 * i));
}
static void reseal(unsigned char *d, size_t n) {
  put64(d + 32, n - 48);
  put64(d + 40, iris_guide_file_checksum(d, n));
}

static void refusals(const char *dir, iris_guiding *g) {
  char path[1200];
  snprintf(path, sizeof path, "%s/door.guide", dir);
  iris_guiding *l = NULL;
  iris_error err;
  iris_error_clear(&err);
  CHECK(iris_guiding_load(path, SCENE_HASH + 1, SETTINGS_HASH, 1, &l, &err) == IRIS_ERR_PARSE && !l &&
        strstr(err.message, "another scene"));
  iris_error_clear(&err);
  CHECK(iris_guiding_load(path, SCENE_HASH, SETTINGS_HASH ^ 1, 1, &l, &err) == IRIS_ERR_PARSE && !l &&
        strstr(err.message, "other settings"));
  size_t n = 0;
  unsigned char *d = read_all(path, &n);
  if (!CHECK(d && n > 1000)) return;
  unsigned char *c = malloc(n + 64);
  if (!CHECK(c)) return;
  /* Truncated: every length of the header and the start of the payload, and
   * 60 lengths spread over the rest (the last one byte short). */
  int bad = 0, tries = 0;
  for (size_t len = 0; len < n; len = len < 200 ? len + 1 : len + (n - 200) / 60 + 1) {
    tries++;
    bad += !refused(dir, d, len, NULL);
    if (len < n - 1 && len + (n - 200) / 60 + 1 >= n && len >= 200) {
      tries++;
      bad += !refused(dir, d, n - 1, "truncated");
    }
  }
  iris_check_record(bad == 0, __FILE__, __LINE__, "%d of %d truncated files loaded", bad, tries);
  /* One flipped byte anywhere: the header (magic, version, flags, hashes,
   * size, checksum) and 212 places spread over the payload. */
  bad = tries = 0;
  for (size_t at = 0; at < n; at = at < 48 ? at + 1 : at + (n - 48) / 212 + 1) {
    memcpy(c, d, n);
    c[at] ^= 0x10;
    tries++;
    bad += !refused(dir, c, n, NULL);
  }
  iris_check_record(bad == 0, __FILE__, __LINE__, "%d of %d files with a flipped byte loaded", bad, tries);
  memcpy(c, d, n);
  put32(c + 8, IRIS_GUIDE_FILE_VERSION + 1);
  CHECK(refused(dir, c, n, IRIS_GUIDE_FILE_VERSION == 4 ? "version 5" : "version"));
  memcpy(c, d, n);
  memset(c + n, 0, 16);
  reseal(c, n + 16);
  CHECK(refused(dir, c, n + 16, "do not match its size")); /* longer, checksum right */
  /* Forged with a valid checksum: locate the sections from the end. */
  size_t tex = 0;
  for (size_t i = 0; i < g->cache_count; ++i) tex += texels(g, &g->caches[i]);
  /* refinement (refine.h) after the alias tables: a slot byte per texel, the sub-tables per cache */
  const size_t refine_bytes = g->refine_slot ? tex + 4 * IRIS_REFINE_MAX * IRIS_REFINE_SUB * g->cache_count : 0;
  const size_t end = n - refine_bytes, slot_at = end, sub_at = end + tex;
  const size_t caches_at = end - CB * g->cache_count - 12 * tex, pdf_at = end - 12 * tex, alias_at = end - 8 * tex;
  CHECK(g->refine_slot != NULL); /* the default guide is refined: the forgeries below reach its tables */
  const size_t count_at = caches_at - 16, texels_at = caches_at - 8;
  struct forge {
    size_t at;
    int width; /* 8, 4 */
    uint64_t value;
    const char *want;
  } forges[] = {
      /* the stats' caustic share (header 48, params 69, then 128 bytes of stats before it) */
      {48 + 69 + 128, 8, 0x3ff8000000000000ull, "invalid statistics"}, /* 1.5 */
      {48 + 69 + 128, 8, 0xbfe0000000000000ull, "invalid statistics"}, /* -0.5 */
      {48 + 69 + 128, 8, 0x7ff8000000000000ull, "invalid statistics"}, /* NaN */
      {count_at, 8, (uint64_t)1 << 40, "do not match its size"},       /* huge count */
      {texels_at, 8, UINT64_MAX / 4, "do not match its size"},         /* huge texel count */
      {count_at, 8, g->cache_count - 1, "do not match its size"},      /* one cache fewer */
      {caches_at + 48 + CB, 4, 1, "table offset"},                     /* cache 1's table offset */
      {caches_at + 48 + CB * 5, 4, UINT32_MAX - 3, "table offset"},    /* far out of range */
      {caches_at + 4, 4, 0x7fc00000u, "not finite"},                   /* NaN position */
      {caches_at + CB * 2 + 36, 4, 0x7f800000u, "not finite"},         /* inf normal */
      {caches_at + CB * 3 + 56, 4, 0x7fc00000u, "invalid values"},     /* NaN radiance */
      {caches_at + CB * 3 + 64, 4, 0, "invalid values"},               /* light sampling probability 0 */
      {caches_at + CB * 4 + 64, 4, 0x3fc00000u, "invalid values"},     /* ... 1.5 */
      {caches_at + CB * 3 + 68, 1, 7, "invalid values"},               /* sphere flag 7 */
      {caches_at + CB * 4 + 70, 4, 0x3fc00000u, "invalid values"},     /* sky behind glass 1.5 */
      {caches_at + CB * 5 + 74, 4, 0x3fc00000u, "lamp shares"},         /* a lamp's share 1.5 */
      {caches_at + CB * 5 + 79, 4, 0x3e800000u, "lamp shares"},         /* 0.25 in slot 1, slot 0 empty */
      {caches_at + CB * 6 + 94, 4, 0x3e800000u, "invalid pane"},        /* a pane share 0.25 with no plane */
      {caches_at + CB * 6 + 94, 4, 0x3fc00000u, "invalid pane"},        /* a pane share 1.5 */
      {caches_at + CB * 7 + 114, 4, 0x3e800000u, "invalid glint share"}, /* a glint share 0.25 with no glint photons */
      {caches_at + CB * 7 + 114, 4, 0x7fc00000u, "invalid glint share"}, /* a NaN glint share */
      {caches_at + CB * 8 + 154, 4, 0x3fc00000u, "invalid portal"},    /* a portal weight 1.5 */
      {caches_at + CB * 8 + 118, 4, 0x7fc00000u, "invalid portal"},    /* a NaN portal centre */
      {caches_at + CB * 9 + 130, 4, 0x7f800000u, "invalid portal"},    /* an inf half-axis */
      {pdf_at + 4 * 17, 4, 0x7fc00000u, "not finite"},                 /* NaN pdf */
      {pdf_at + 4 * 18, 4, 0xbf800000u, "negative"},                   /* pdf -1 */
      {pdf_at + 4 * 19, 4, 0x7f800000u, "not finite"},                 /* inf pdf */
      {alias_at + 8 * 3 + 4, 4, 64, "alias"},                          /* alias index = texel count */
      {alias_at + 8 * 4, 4, 0x3fc00000u, "alias"},                     /* q = 1.5 */
      {slot_at + 5, 1, IRIS_REFINE_MAX + 1, "refinement slot"},        /* slot past the sub-tables */
      {sub_at + 4 * 3, 4, 0x7fc00000u, "refinement table"},            /* NaN multiplier */
      {sub_at + 4 * 7, 4, 0xbf800000u, "refinement table"},            /* multiplier -1 */
  };
  for (size_t f = 0; f < sizeof forges / sizeof forges[0]; ++f) {
    memcpy(c, d, n);
    if (forges[f].width == 8) put64(c + forges[f].at, forges[f].value);
    else if (forges[f].width == 4) put32(c + forges[f].at, (uint32_t)forges[f].value);
    else c[forges[f].at] = (unsigned char)forges[f].value;
    reseal(c, n);
    iris_check_record(refused(dir, c, n, forges[f].want), __FILE__, __LINE__, "forged file %zu loaded", f);
  }
  free(c);
  free(d);
  /* A failed write leaves nothing behind (not even a temporary). */
  char missing[1200];
  snprintf(missing, sizeof missing, "%s/no/such/folder/x.guide", dir);
  iris_error_clear(&err);
  CHECK(iris_guiding_save(g, missing, SCENE_HASH, SETTINGS_HASH, &err) == IRIS_ERR_IO);
  CHECK(iris_test_count_entries(dir, ".tmp") == 0);
}

int main(void) {
  char dir[1024];
  if (iris_test_tmpdir(dir, sizeof dir, "guide-file") != 0) return TEST_SKIP("no temporary folder");
  iris_guiding *door = build("door", IRIS_METHOD_GUIDED_NEE, 60000, false);
  iris_guiding *holes = build("veach-mis", IRIS_METHOD_GUIDED, 300, true);
  iris_guiding *skipped = build("veach-mis", IRIS_METHOD_GUIDED_NEE, 20000, false);
  if (CHECK(door && holes && skipped)) {
    CHECK(!door->stats.skipped && door->cache_count > 100 && door->grid.n[0] > 0);
    /* the in-memory tables have holes where caches were dropped */
    CHECK(!holes->stats.skipped && holes->stats.empty_caches > 0);
    CHECK(skipped->stats.skipped);
    round_trip(dir, "door", door);
    round_trip(dir, "holes", holes);
    round_trip(dir, "skipped", skipped);
    door->stats.caustic_share = 0.25; /* as if light focused through glass had kept it */
    round_trip(dir, "door-caustic", door);
    door->stats.caustic_share = -1.0;
    refusals(dir, door);
    printf("door: %zu caches; veach-mis: %zu caches, %llu dropped; skipped: %s\n", door->cache_count,
           holes->cache_count, (unsigned long long)holes->stats.empty_caches, skipped->stats.reason);
  }
  iris_guiding_destroy(door);
  iris_guiding_destroy(holes);
  iris_guiding_destroy(skipped);
  iris_test_rmtree(dir);
  return iris_check_summary("guiding.guide_file");
}
