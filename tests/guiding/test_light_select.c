/* guiding.light_select: learned light selection (renderer/guiding/light_select.h,
 * docs/guiding.md "Learned light selection"), on the office's real caches:
 *  - at cache points and points between them, the choice passes chi-square
 *    against iris_light_select_pmf over all lights (cells of expected count
 *    < 5 pooled; "nothing chosen" a cell of its own), every sample's pmf equals
 *    the pmf function bit for bit, and equals what iris_lights (the hooks)
 *    and the MIS pdf of an emitter hit (iris_lights_pdf_triangle) use;
 *  - the pmfs sum to (1 - beta) x the tree's sum + beta where caches learned
 *    something (one with the tree's dead ends left out);
 *  - a light the caches never saw keeps (1 - beta) of its tree probability;
 *  - the tables are the same for 1 and 2 threads and learned something, and
 *    come back the same from a guide file (refused where a leaf is no leaf);
 *  - renders: mis, nee and guided-nee with learned selection agree with mis
 *    with the tree within statistical error (office, corridor-rooms; nee and
 *    mis on veach-mis), and a learned render is the same for 1 and 2 threads;
 *  - where the tree's descent ends in nothing, no light is chosen (corridor-rooms);
 *  - infinite lights (the sky) have slots of their own in the tables, pass
 *    the same chi-square, and come back from a guide file (sky-room with
 *    two lamps);
 *  - a scene whose tree's choices at what the camera sees are rarely hidden
 *    (the office) renders `learned` as the tree, bit for bit;
 *  - a trained guide's tables learn from the light samples (corridor-rooms):
 *    the same for 1 and 2 threads, and what they choose is hidden far less
 *    often than what the tree chooses. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "chi2.h"
#include "film_stats.h"
#include "render_run.h"
#include "renderer/guiding/guide_file.h"
#include "renderer/guiding/guiding.h"
#include "renderer/guiding/light_select.h"
#include "renderer/light_hidden.h"
#include "renderer/render.h"
#include "scenes/builtin.h"

#define N_POINTS 12
#define N_SAMPLES 200000

typedef struct world {
  iris_scene *s;
  iris_accel *accel;
  iris_textures tex;
  iris_lights lights;
  iris_pinhole cam;
  iris_guiding *g;
} world;

/* CHECK_OK as a condition */
static bool ok(iris_status st, iris_error *err) {
  CHECK_OK(st, err);
  return st == IRIS_OK;
}

static bool world_build_trained(world *w, const char *name, int threads, int train_spp);
static bool world_build(world *w, const char *name, int threads) { return world_build_trained(w, name, threads, 0); }

/* train_spp > 0: the guide of guided-nee, trained (its tables learn from the light samples too) */
/* sky-room with two point lamps under its ceiling: the sky through the
 * window is an infinite light beside the tree's two leaves */
static iris_status sky_room_lamps(iris_scene **s, iris_error *err) {
  iris_status st = iris_builtin_create("sky-room", s, err);
  for (int k = 0; st == IRIS_OK && k < 2; k++) {
    iris_light l;
    memset(&l, 0, sizeof l);
    l.type = IRIS_LIGHT_POINT;
    l.color[0] = l.color[1] = l.color[2] = 1.0f;
    l.intensity = 3.0f;
    l.position[0] = -1.5f;
    l.position[1] = 2.2f;
    l.position[2] = k ? 1.5f : -1.5f;
    if (iris_scene_add_light(*s, &l) < 0) st = iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory");
  }
  return st;
}

static bool world_build_trained(world *w, const char *name, int threads, int train_spp) {
  memset(w, 0, sizeof *w);
  iris_error err;
  iris_error_clear(&err);
  if (!ok(strcmp(name, "sky-room-lamps") == 0 ? sky_room_lamps(&w->s, &err) : iris_builtin_create(name, &w->s, &err),
          &err))
    return false;
  if (!ok(iris_pinhole_setup(w->s, NULL, 96, 64, &w->cam, &err), &err)) return false;
  if (!ok(iris_accel_build(w->s, &w->accel, &err), &err)) return false;
  if (!ok(iris_textures_load(w->s, &w->tex, &err), &err)) return false;
  if (!ok(iris_lights_build(w->s, w->accel, &w->tex, &w->lights, &err), &err)) return false;
  if (!ok(iris_lights_set_sampler(&w->lights, IRIS_LIGHT_SAMPLER_LEARNED, &err), &err)) return false;
  if (!CHECK(w->lights.tree != NULL)) return false;
  iris_integrator it = iris_integrator_default(w->s, w->accel, &w->lights, &w->tex);
  it.method = train_spp > 0 ? IRIS_METHOD_GUIDED_NEE : IRIS_METHOD_MIS;
  iris_guiding_params gp = iris_guiding_params_default();
  gp.use_nee = true;
  gp.force = true;
  gp.train_spp = train_spp;
  gp.pilot_paths = 0;
  iris_guide_setup gs = {w->s, w->accel, &w->lights, &w->tex, &w->cam, &it, 7, threads, NULL, 16, 0.0,
                         IRIS_SAMPLER_SOBOL, false, NULL, NULL, 0.0, NULL, {0, 0, 0, 0}, true, false};
  if (!ok(iris_guiding_build(&gs, &gp, &w->g, &err), &err)) return false;
  w->lights.learned = iris_light_select_hooks(&w->g->lights);
  return CHECK(w->lights.learned.choose != NULL);
}

static void world_destroy(world *w) {
  iris_guiding_destroy(w->g);
  iris_lights_destroy(&w->lights);
  iris_textures_destroy(&w->tex);
  iris_accel_destroy(w->accel);
  iris_scene_destroy(w->s);
}

/* The MIS side: the pdf of an emitter hit at a point of entry `light`, over
 * the solid-angle density of that point, is the selection pmf. */
static float mis_pmf(const world *w, iris_vec3 p, iris_vec3 n, uint32_t light) {
  const iris_light_entry *e = &w->lights.entries[light];
  iris_interaction si;
  iris_accel_surface_at(w->accel, e->prim, 0.25f, 0.25f, &si);
  iris_vec3 to = iris_sub(si.p, p);
  float d2 = iris_dot(to, to);
  float cos_l = fabsf(iris_dot(to, si.ng)) / sqrtf(d2);
  const iris_light_tri *t = &w->lights.tris[light];
  float omega = iris_lights_triangle_solid_angle(t, p);
  float dens = omega > 0.0f ? 1.0f / omega : d2 / (cos_l * t->area);
  float pdf = iris_lights_pdf_triangle(&w->lights, p, n, &si);
  return pdf / dens;
}

static void check_point(const world *w, iris_vec3 p, iris_vec3 n, int k, int n_tests) {
  const iris_light_select *sel = &w->g->lights;
  const size_t nl = w->lights.count;
  double *pmf = calloc(nl, sizeof *pmf);
  size_t *hits = calloc(nl, sizeof *hits);
  double sum = 0.0, tree_sum = 0.0;
  for (size_t i = 0; i < nl; i++) {
    pmf[i] = iris_light_select_pmf(sel, p, n, (uint32_t)i);
    tree_sum += iris_light_tree_pmf(w->lights.tree, p, n, (uint32_t)i);
    sum += pmf[i];
  }
  /* the learned part sums to one where caches serve; the tree keeps its dead ends */
  uint32_t ids[IRIS_GUIDING_PICK_K];
  int m = iris_guiding_pick(w->g, p, n, ids), learned = 0;
  for (int j = 0; j < m; j++) learned += sel->count[ids[j]] > 0;
  double want = learned ? (1.0 - sel->beta) * tree_sum + sel->beta : tree_sum;
  iris_check_record(fabs(sum - want) < 1e-4, __FILE__, __LINE__, "point %d: pmfs sum to %.6f, want %.6f (%d caches learned)",
                    k, sum, want, learned);
  uint64_t rs = 1234 + (uint64_t)k;
  size_t got = 0, mismatch = 0, mis_mismatch = 0;
  for (int s = 0; s < N_SAMPLES; s++) {
    uint32_t light;
    float q;
    iris_light_choice c;
    float u = (float)chi2_uniform(&rs);
    bool ok = iris_light_select_choose(sel, p, n, u, &light, &q);
    iris_lights_choose(&w->lights, p, n, u, &c); /* through the hooks: the same */
    if (c.light != light || c.pmf_group != (ok ? q : 0.0f) || !c.pmf_is_entry) mismatch++;
    if (!ok) continue;
    got++;
    if (q != iris_light_select_pmf(sel, p, n, light) || q != iris_lights_select_pmf_at(&w->lights, p, n, light))
      mismatch++;
    if ((s & 63) == 0 && light < w->lights.tri_count) {
      float mq = mis_pmf(w, p, n, light);
      if (fabsf(mq - q) > 1e-5f * q) mis_mismatch++;
    }
    hits[light]++;
  }
  iris_check_record(mismatch == 0, __FILE__, __LINE__, "point %d: %zu samples whose pmf differs from the pmf function", k,
                    mismatch);
  iris_check_record(mis_mismatch == 0, __FILE__, __LINE__, "point %d: %zu MIS pdfs not from the same pmf", k, mis_mismatch);
  double chi;
  int dof;
  double pv = chi2_discrete(pmf, hits, nl, N_SAMPLES, got, &chi, &dof);
  double sig = 1.0 - pow(1.0 - 0.01, 1.0 / n_tests);
  printf("point %d (%d caches learned): pmfs sum %.6f, chi2 %.1f dof %d p %.3g\n", k, learned, sum, chi, dof, pv);
  iris_check_record(pv > sig, __FILE__, __LINE__, "point %d: chi2 %.1f dof %d p %.3g < %.3g", k, chi, dof, pv, sig);
  free(pmf);
  free(hits);
}

static bool render(const iris_scene *s, iris_method m, iris_light_sampler ls, int threads, int w, int h, int spp,
                   uint64_t seed, iris_render_result *r) {
  return iris_test_render_light(s, m, ls, threads, w, h, spp, seed, &iris_guiding_provider, r);
}

static void compare(const char *name, const char *what, const iris_render_result *a, const iris_render_result *b,
                    double z_max) {
  double worst = 0.0;
  int w = a->film.width, h = a->film.height;
  for (int blk = -1; blk < 9; blk++) {
    int x0 = 0, y0 = 0, x1 = w, y1 = h;
    if (blk >= 0) {
      x0 = (blk % 3) * w / 3, y0 = (blk / 3) * h / 3;
      x1 = x0 + w / 3, y1 = y0 + h / 3;
    }
    double ma[3], va[3], mb[3], vb[3];
    region(&a->film, x0, y0, x1, y1, ma, va);
    region(&b->film, x0, y0, x1, y1, mb, vb);
    for (int k = 0; k < 3; k++) {
      double sd = sqrt(va[k] + vb[k]);
      double z = sd > 0 ? (ma[k] - mb[k]) / sd : (ma[k] == mb[k] ? 0.0 : INFINITY);
      if (fabs(z) > worst) worst = fabs(z);
      iris_check_record(fabs(z) <= z_max, __FILE__, __LINE__, "%s %s: block %d channel %d: %.5f vs %.5f, z = %.2f", name,
                        what, blk, k, ma[k], mb[k], z);
    }
  }
  printf("%s: %s: worst |z| = %.2f\n", name, what, worst);
}

int main(void) {
  world w, w2;
  if (world_build(&w, "office", 2)) {
    const iris_light_select *sel = &w.g->lights;
    printf("office: %zu lights, %zu caches, %llu learned from %llu direct photons\n", w.lights.count, sel->cache_count,
           (unsigned long long)sel->learned_caches, (unsigned long long)sel->direct_photons);
    CHECK(sel->learned_caches > sel->cache_count / 8);
    /* the same tables for 1 and 2 threads */
    if (world_build(&w2, "office", 1)) {
      CHECK(w2.g->lights.cache_count == sel->cache_count &&
            memcmp(w2.g->lights.count, sel->count, sel->cache_count) == 0 &&
            memcmp(w2.g->lights.slots, sel->slots, sel->cache_count * IRIS_LIGHT_SELECT_SLOTS * sizeof *sel->slots) == 0);
      world_destroy(&w2);
    }
    /* the tables through a guide file: the same, and refused when they do not fit the lights' tree */
    {
      iris_error err;
      iris_error_clear(&err);
      const char *path = "test_light_select.guide";
      iris_guiding *back = NULL;
      CHECK_OK(iris_guiding_save(w.g, path, 1, 2, &err), &err);
      CHECK_OK(iris_guiding_load(path, 1, 2, 1, &back, &err), &err);
      if (CHECK(back != NULL)) {
        CHECK(back->lights.cache_count == sel->cache_count && back->lights.beta == sel->beta &&
              memcmp(back->lights.count, sel->count, sel->cache_count) == 0 &&
              memcmp(back->lights.slots, sel->slots, sel->cache_count * IRIS_LIGHT_SELECT_SLOTS * sizeof *sel->slots) == 0);
        CHECK(iris_light_select_attach(&back->lights, back, &w.lights));
        CHECK(iris_light_select_pmf(&back->lights, w.g->caches[0].p, w.g->caches[0].frame.n, 3) ==
              iris_light_select_pmf(sel, w.g->caches[0].p, w.g->caches[0].frame.n, 3));
        size_t i = 0;
        while (i < sel->cache_count && !sel->count[i]) i++;
        back->lights.slots[i * IRIS_LIGHT_SELECT_SLOTS].leaf = 1; /* the root's first child: not a leaf here */
        CHECK(!iris_light_select_attach(&back->lights, back, &w.lights));
        iris_guiding_destroy(back);
      }
      remove(path);
    }
    /* points: caches with a table (their own position and normal), and
     * points beside them (between caches, another normal) */
    int k = 0;
    for (size_t c = 0; c < sel->cache_count && k < N_POINTS; c += sel->cache_count / N_POINTS + 1) {
      size_t i = c;
      while (i < sel->cache_count && !sel->count[i]) i++;
      if (i == sel->cache_count) break;
      const iris_cache *cache = &w.g->caches[i];
      iris_vec3 p = cache->p, n = cache->frame.n;
      if (k % 3 == 2) p = iris_add(p, iris_scale(cache->frame.t, 0.05f));
      if (k % 4 == 3) n = iris_v3(0, 0, 0); /* no hemisphere: the tree alone */
      check_point(&w, p, n, k, N_POINTS);
      k++;
    }
    CHECK(k == N_POINTS);
    /* A light the caches never saw at a point with a table keeps its tree share. */
    {
      size_t i = 0;
      while (i < sel->cache_count && !sel->count[i]) i++;
      const iris_cache *cache = &w.g->caches[i];
      uint32_t ids[IRIS_GUIDING_PICK_K];
      int m = iris_guiding_pick(w.g, cache->p, cache->frame.n, ids);
      size_t unseen = 0;
      for (uint32_t l = 0; l < w.lights.count; l++) {
        uint32_t leaf = w.lights.tree->node_of_light[l];
        bool seen = false;
        for (int j = 0; j < m; j++)
          for (int s = 0; s < sel->count[ids[j]]; s++)
            seen |= sel->slots[(size_t)ids[j] * IRIS_LIGHT_SELECT_SLOTS + s].leaf == leaf;
        float tp = iris_light_tree_pmf(w.lights.tree, cache->p, cache->frame.n, l);
        if (seen || !(tp > 0.0f)) continue;
        unseen++;
        float q = iris_light_select_pmf(sel, cache->p, cache->frame.n, l);
        iris_check_record(q == (1.0f - sel->beta) * tp, __FILE__, __LINE__,
                          "light %u, unseen: pmf %g, tree %g", l, (double)q, (double)tp);
      }
      printf("cache %zu: %zu lights with tree probability its caches never saw\n", i, unseen);
      CHECK(unseen > 0);
    }
    world_destroy(&w);
  }

  /* Points where the tree's descent sometimes ends in nothing (lights only
   * behind the surface: its pmfs sum below 1): a failed descent chooses no
   * light, also with a table (once it named light 0 with the mixture's pmf,
   * 2x too bright in corridor-rooms' dim corners). */
  if (world_build(&w, "corridor-rooms", 2)) {
    const iris_light_select *sel = &w.g->lights;
    int k = 0;
    for (size_t i = 0; i < sel->cache_count && k < 4; ++i) {
      const iris_cache *cache = &w.g->caches[i];
      if (!sel->count[i]) continue;
      double tree_sum = 0.0;
      for (uint32_t l = 0; l < w.lights.count; l++) tree_sum += iris_light_tree_pmf(w.lights.tree, cache->p, cache->frame.n, l);
      if (!(tree_sum < 0.97)) continue;
      printf("corridor-rooms cache %zu: the tree's pmfs sum to %.4f\n", i, tree_sum);
      check_point(&w, cache->p, cache->frame.n, 100 + k, 4);
      k++;
    }
    CHECK(k == 4);
    world_destroy(&w);
  }

  /* Learning from the training's light samples (corridor-rooms: rooms whose
   * lamps the walls hide from the corridor and the other rooms). */
  if (world_build_trained(&w, "corridor-rooms", 2, 8)) {
    const iris_light_select *sel = &w.g->lights;
    printf("corridor-rooms, trained: %llu caches with a table, %llu of them from the light samples\n",
           (unsigned long long)sel->learned_caches, (unsigned long long)sel->nee_caches);
    CHECK(sel->nee_caches > sel->cache_count / 8);
    /* the same tables for 1 and 2 threads */
    if (world_build_trained(&w2, "corridor-rooms", 1, 8)) {
      CHECK(w2.g->lights.nee_caches == sel->nee_caches &&
            memcmp(w2.g->lights.count, sel->count, sel->cache_count) == 0 &&
            memcmp(w2.g->lights.slots, sel->slots, sel->cache_count * IRIS_LIGHT_SELECT_SLOTS * sizeof *sel->slots) == 0);
      world_destroy(&w2);
    }
    /* mis and nee train no guide: the tables built for them alone
     * (build_lights) run light-only training passes (guided-nee's first
     * vertex; --train-spp, by default 5% of the render's spp) and learn from
     * their light samples too; with --no-light-samples none run. */
    {
      iris_integrator it = iris_integrator_default(w.s, w.accel, &w.lights, &w.tex);
      it.method = IRIS_METHOD_MIS;
      for (int samples = 1; samples >= 0; samples--) {
        iris_guiding_params gp = iris_guiding_params_default();
        gp.light_samples = samples != 0;
        gp.train_spp = 4; /* the render's 16 spp would give 5% of them: none */
        iris_guide_setup gs = {w.s, w.accel, &w.lights, &w.tex, &w.cam, &it, 7, 2, &gp, 16, 0.0,
                               IRIS_SAMPLER_SOBOL, false, NULL, NULL, 0.0, NULL, {0, 0, 0, 0}, true, false};
        iris_error err;
        iris_error_clear(&err);
        void *state = NULL;
        CHECK_OK(iris_guiding_provider.build_lights(&gs, &state, &err), &err);
        if (CHECK(state != NULL)) {
          const iris_guiding *lg = state;
          printf("corridor-rooms, mis's own tables (light samples %s): %llu tables, %llu from light samples, "
                 "%d training spp\n", samples ? "on" : "off", (unsigned long long)lg->lights.learned_caches,
                 (unsigned long long)lg->lights.nee_caches, lg->stats.train_spp);
          if (samples) CHECK(lg->lights.nee_caches > lg->lights.cache_count / 8 && lg->stats.train_spp > 0);
          else CHECK(lg->lights.nee_caches == 0 && lg->stats.train_spp == 0);
          iris_guiding_provider.destroy(state);
        }
      }
    }
    /* The grid's shortcut (a cell whose caches have no table reads none of
     * them) answers as reading them does: at points around every 4th cache,
     * with and without it, the same pmf of every 9th light. */
    {
      iris_light_select *ms = &w.g->lights;
      uint8_t *near = ms->near;
      size_t differ = 0, asked = 0, skipped = 0;
      uint64_t ps = 5;
      CHECK(near != NULL);
      for (size_t i = 0; i < ms->cache_count; i += 4) {
        const iris_cache *cache = &w.g->caches[i];
        iris_vec3 p = iris_add(cache->p, iris_v3((float)chi2_uniform(&ps) - 0.5f, (float)chi2_uniform(&ps) - 0.5f,
                                                 (float)chi2_uniform(&ps) - 0.5f));
        uint32_t ids[IRIS_GUIDING_PICK_K];
        int m = iris_guiding_pick(w.g, p, cache->frame.n, ids), with = 0;
        for (int j = 0; j < m; j++) with += ms->count[ids[j]] > 0;
        skipped += with == 0;
        for (uint32_t l = 0; l < w.lights.count; l += 9) {
          ms->near = near;
          float a = iris_light_select_pmf(ms, p, cache->frame.n, l);
          ms->near = NULL;
          float b = iris_light_select_pmf(ms, p, cache->frame.n, l);
          differ += a != b;
          asked++;
        }
      }
      ms->near = near;
      printf("corridor-rooms: the grid's shortcut: %zu of %zu pmfs differ (%zu points without a table near)\n", differ,
             asked, skipped);
      CHECK(differ == 0 && skipped > 0);
    }
    /* What the tables learned is what the walls let through: at the caches
     * that learned from light samples, the lights the tables alone choose (u <
     * beta) are hidden from the cache far less often than the tree's. Leaves
     * mixed up, or light samples' values ignored, fail this. */
    uint64_t rs = 99;
    size_t tries[2] = {0, 0}, hidden[2] = {0, 0}, points = 0;
    for (size_t i = 0; i < sel->cache_count && points < 64; i += 3) {
      const iris_cache *cache = &w.g->caches[i];
      if (!sel->count[i] || cache->sphere) continue;
      points++;
      for (int k = 0; k < 256; k++) {
        const int table = k & 1;
        float u = (float)chi2_uniform(&rs);
        u = table ? u * sel->beta * 0.999f : sel->beta + u * (1.0f - sel->beta);
        uint32_t light;
        float q;
        if (!iris_light_select_choose(sel, cache->p, cache->frame.n, u, &light, &q)) continue;
        iris_light_choice ch = {light, q, true};
        iris_light_sample ls;
        if (!iris_lights_sample_choice(&w.lights, cache->p, &ch, (float)chi2_uniform(&rs), (float)chi2_uniform(&rs), &ls))
          continue;
        if (!(iris_dot(ls.wi, cache->frame.n) > 0.0f)) continue;
        iris_ray r = iris_spawn_ray_to(cache->p, cache->frame.n, ls.p, ls.n);
        tries[table]++;
        hidden[table] += iris_accel_occluded(w.accel, &r);
      }
    }
    double h_table = tries[1] ? (double)hidden[1] / (double)tries[1] : 1.0,
           h_tree = tries[0] ? (double)hidden[0] / (double)tries[0] : 0.0;
    printf("corridor-rooms: %zu caches: hidden %.3f of the tables' choices (%zu), %.3f of the tree's (%zu)\n", points,
           h_table, tries[1], h_tree, tries[0]);
    CHECK(points >= 32);
    iris_check_record(h_table < 0.5 * h_tree, __FILE__, __LINE__, "tables' choices hidden %.3f, the tree's %.3f", h_table,
                      h_tree);
    world_destroy(&w);
  }

  /* Infinite lights in the tables: in sky-room with two lamps the caches by
   * the window learn the sky as a slot of its own (IRIS_LIGHT_SELECT_INFINITE |
   * k), so a table does not take beta of the sky's probability away where it
   * lights the room; the choice keeps its pmf there, and a guide file keeps
   * such slots and refuses one past the infinite lights. */
  if (world_build_trained(&w, "sky-room-lamps", 2, 8)) {
    const iris_light_select *sel = &w.g->lights;
    size_t sky = 0, first = SIZE_MAX;
    for (size_t i = 0; i < sel->cache_count; ++i)
      for (int k = 0; k < sel->count[i]; k++)
        if (sel->slots[i * IRIS_LIGHT_SELECT_SLOTS + k].leaf & IRIS_LIGHT_SELECT_INFINITE) {
          sky++;
          if (first == SIZE_MAX) first = i;
        }
    printf("sky-room-lamps: %llu tables, %zu with the sky's slot\n", (unsigned long long)sel->learned_caches, sky);
    if (CHECK(sky > 0)) {
      int k = 0;
      for (size_t i = first; i < sel->cache_count && k < 3; i += 7) {
        bool has = false;
        for (int j = 0; j < sel->count[i]; j++) has |= (sel->slots[i * IRIS_LIGHT_SELECT_SLOTS + j].leaf & IRIS_LIGHT_SELECT_INFINITE) != 0;
        if (!has) continue;
        check_point(&w, w.g->caches[i].p, w.g->caches[i].frame.n, 200 + k, 3);
        k++;
      }
      CHECK(k > 0);
      iris_error err;
      iris_error_clear(&err);
      const char *path = "test_light_select_sky.guide";
      iris_guiding *back = NULL;
      CHECK_OK(iris_guiding_save(w.g, path, 1, 2, &err), &err);
      CHECK_OK(iris_guiding_load(path, 1, 2, 1, &back, &err), &err);
      if (CHECK(back != NULL)) {
        CHECK(iris_light_select_attach(&back->lights, back, &w.lights));
        CHECK(memcmp(back->lights.slots, sel->slots, sel->cache_count * IRIS_LIGHT_SELECT_SLOTS * sizeof *sel->slots) == 0);
        for (int j = 0; j < back->lights.count[first]; j++)
          if (back->lights.slots[first * IRIS_LIGHT_SELECT_SLOTS + j].leaf & IRIS_LIGHT_SELECT_INFINITE)
            back->lights.slots[first * IRIS_LIGHT_SELECT_SLOTS + j].leaf =
                IRIS_LIGHT_SELECT_INFINITE | (uint32_t)w.lights.tree->infinite_count;
        CHECK(!iris_light_select_attach(&back->lights, back, &w.lights));
        iris_guiding_destroy(back);
      }
      remove(path);
    }
    world_destroy(&w);
  }

  /* Which scenes learn (renderer/light_hidden.h): the tree's choices at what
   * the camera sees are hidden 8% of the time on the office (lamps over
   * partitions) and 59% on corridor-rooms; the office keeps the tree alone,
   * so its learned render is the tree's bit for bit, without photons. */
  {
    iris_scene *s = NULL;
    iris_error err;
    if (CHECK(iris_builtin_create("office", &s, &err) == IRIS_OK)) {
      iris_render_result a, b;
      if (CHECK(render(s, IRIS_METHOD_MIS, IRIS_LIGHT_SAMPLER_LEARNED, 2, 24, 15, 8, 5, &a))) {
        if (CHECK(render(s, IRIS_METHOD_MIS, IRIS_LIGHT_SAMPLER_TREE, 2, 24, 15, 8, 5, &b))) {
          printf("office: the tree's choices hidden at %.3f of the camera's points\n", a.light_hidden_share);
          CHECK(a.light_hidden_share >= 0.0 && a.light_hidden_share < IRIS_LIGHTS_HIDDEN_MIN);
          CHECK(b.light_hidden_share == -1.0);
          iris_check_record(memcmp(a.film.sum, b.film.sum, 3 * 24 * 15 * sizeof(double)) == 0, __FILE__, __LINE__,
                            "office: learned differs from the tree where nothing is hidden");
          iris_render_result_destroy(&b);
        }
        iris_render_result_destroy(&a);
      }
      iris_scene_destroy(s);
    }
  }

  /* Renders: learned against the tree (mis), and the methods with learned among themselves. */
  {
    const struct {
      const char *name;
      int w, h, spp;
    } cases[3] = {{"office", 24, 15, 96}, {"veach-mis", 32, 24, 128}, {"corridor-rooms", 24, 16, 96}};
    /* (office and veach-mis keep the tree alone by the gate above: these
     * check that the gate's way renders right; corridor-rooms learns) */
    double z_max = z_for_alpha(1e-3 / (2 * 4 * 10 * 3));
    for (int c = 0; c < 3; c++) {
      iris_scene *s = NULL;
      iris_error err;
      if (!CHECK(iris_builtin_create(cases[c].name, &s, &err) == IRIS_OK)) continue;
      iris_render_result tree, r[3], r1;
      const iris_method methods[3] = {IRIS_METHOD_MIS, IRIS_METHOD_NEE, IRIS_METHOD_GUIDED_NEE};
      bool ok_tree = CHECK(render(s, IRIS_METHOD_MIS, IRIS_LIGHT_SAMPLER_TREE, 2, cases[c].w, cases[c].h,
                                  cases[c].spp, 11, &tree));
      int runs = c == 1 ? 2 : 3; /* veach-mis: the guide skips guided-nee (lit directly) */
      for (int m = 0; m < runs; m++) {
        if (!CHECK(render(s, methods[m], IRIS_LIGHT_SAMPLER_LEARNED, 2, cases[c].w, cases[c].h, cases[c].spp,
                          20 + (uint64_t)m, &r[m])))
          continue;
        CHECK(r[m].light_sampler == IRIS_LIGHT_SAMPLER_LEARNED);
        if (c == 2) CHECK(r[m].light_hidden_share >= IRIS_LIGHTS_HIDDEN_MIN);
        CHECK_EQ_INT(r[m].stats.nan_count, 0);
        /* veach-mis nee: the sharp plates' highlights are (rightly) noisy to light sampling alone */
        if (ok_tree && !(c == 1 && m == 1)) compare(cases[c].name, iris_method_name(methods[m]), &r[m], &tree, z_max);
        if (m == 0 && CHECK(render(s, IRIS_METHOD_MIS, IRIS_LIGHT_SAMPLER_LEARNED, 1, cases[c].w, cases[c].h,
                                   cases[c].spp, 20, &r1))) {
          size_t np = (size_t)r1.film.width * (size_t)r1.film.height;
          iris_check_record(memcmp(r1.film.sum, r[0].film.sum, 3 * np * sizeof(double)) == 0, __FILE__, __LINE__,
                            "%s: the learned render differs between 1 and 2 threads", cases[c].name);
          iris_render_result_destroy(&r1);
        }
        iris_render_result_destroy(&r[m]);
      }
      if (ok_tree) iris_render_result_destroy(&tree);
      iris_scene_destroy(s);
    }
  }
  return iris_check_summary("guiding.light_select");
}
