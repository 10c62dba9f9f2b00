/* Connections to a light-vertex cache: the pools of light vertices; vcache.h
 * and docs/guiding.md, "Connections to a light-vertex cache". The camera side
 * (what connects, what is left out or shared) is in integrator.c. */
#include "renderer/vcache.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "core/parallel.h"
#include "core/rng.h"
#include "renderer/accel.h"
#include "renderer/integrator.h"
#include "renderer/lights.h"
#include "renderer/sampling.h"

#define CHUNK 32u          /* sample indices built together */
#define MAX_CHUNKS 16384u  /* so sample indices below 524288 have pools */
#define MAX_WALK 64        /* vertices a light path may visit */
#define STREAM 0x76636163ULL /* "vcac": the light paths' streams, apart from the image's */

typedef struct chunk {
  iris_vcache_pool pool[CHUNK];
} chunk;

struct iris_vcache {
  iris_vcache_params p;
  const iris_integrator *it;
  chunk *_Atomic chunks[MAX_CHUNKS];
  pthread_mutex_t lock;
  atomic_uint_fast64_t rays;
};

bool iris_vcache_plain(const iris_shading_point *sp, iris_vec3 ng) {
  return !sp->delta && sp->lobes == (IRIS_LOBE_REFLECTION | IRIS_LOBE_DIFFUSE) &&
         fabsf(iris_dot(sp->si.ns, ng)) > 0.9999f;
}

iris_status iris_vcache_create(iris_vcache **out, const iris_vcache_params *p, const iris_integrator *it,
                               iris_error *err) {
  *out = NULL;
  iris_vcache *vc = calloc(1, sizeof *vc);
  if (!vc) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "connections", "out of memory for the light-vertex cache");
  vc->p = *p;
  vc->it = it;
  pthread_mutex_init(&vc->lock, NULL);
  *out = vc;
  return IRIS_OK;
}

void iris_vcache_destroy(iris_vcache *vc) {
  if (!vc) return;
  for (uint32_t c = 0; c < MAX_CHUNKS; ++c) {
    chunk *ch = atomic_load(&vc->chunks[c]);
    if (!ch) continue;
    for (uint32_t i = 0; i < CHUNK; ++i) free(ch->pool[i].v);
    free(ch);
  }
  pthread_mutex_destroy(&vc->lock);
  free(vc);
}

const iris_vcache_params *iris_vcache_settings(const iris_vcache *vc) { return &vc->p; }

uint64_t iris_vcache_rays(const iris_vcache *vc) { return atomic_load(&((iris_vcache *)vc)->rays); }

static bool push(iris_vcache_pool *pool, uint32_t *cap, const iris_vcache_vertex *v) {
  if (pool->count == *cap) {
    uint32_t n = *cap ? 2 * *cap : 64;
    iris_vcache_vertex *g = realloc(pool->v, sizeof *g * n);
    if (!g) return false;
    pool->v = g;
    *cap = n;
  }
  pool->v[pool->count++] = *v;
  return true;
}

/* With the sky: light path i from a point on a window (drawn with its
 * probability, dimension 4, where there are several) in a direction of the
 * map's own sampling, seen through it (cos > 0 along its outward normal),
 * carrying L cos area / (pdf prob); its first hit inside, if plain, is kept,
 * unless the ray from there back out leaves through another window first
 * (that window's light paths make the path: each once). */
static bool sky_path(const iris_vcache *vc, iris_sampler *r, iris_vcache_pool *pool, uint32_t *cap, uint64_t *rays) {
  const iris_integrator *it = vc->it;
  const iris_vcache_params *p = &vc->p;
  float u[4];
  for (uint32_t d = 0; d < 4; ++d) u[d] = iris_sampler_get(r, d);
  int j = 0;
  if (p->windows > 1) { /* one window: dimension 4 is not drawn */
    const float uw = iris_sampler_get(r, 4);
    float acc = 0.0f;
    for (j = 0; j < p->windows - 1; ++j) {
      acc += p->window[j].prob;
      if (uw < acc) break;
    }
  }
  const iris_vec3 wo = p->window[j].o, wn = p->window[j].n, wu = p->window[j].u, wv = p->window[j].v;
  const float prob = p->window[j].prob;
  if (!(prob > 0.0f)) return true;
  iris_vec3 d, Le;
  float pdf;
  if (!iris_envmap_sample(it->lights->envmap, u[2], u[3], &d, &pdf, &Le) || !(pdf > 0.0f)) return true;
  const float cw = iris_dot(d, wn);
  if (!(cw > 0.0f) || !(iris_max3(Le) > 0.0f)) return true;
  const iris_vec3 q = iris_add(wo, iris_add(iris_scale(wu, 2.0f * u[0] - 1.0f), iris_scale(wv, 2.0f * u[1] - 1.0f)));
  const float area = p->window[j].area;
  iris_ray out = {q, 0.0f, d, INFINITY};
  *rays += 2;
  if (iris_accel_occluded(it->accel, &out)) return true; /* the sky is not seen from there */
  iris_ray in = {q, 0.0f, iris_neg(d), INFINITY};
  iris_hit h;
  if (!iris_accel_intersect(it->accel, &in, &h)) return true;
  iris_interaction si;
  iris_accel_interaction(it->accel, in.d, &h, &si);
  iris_shading_point sp;
  iris_integrator_shade(it, &si, d, 1, &sp);
  if (!iris_vcache_plain(&sp, si.ng) || !iris_vcache_in_a(p, si.p, d)) return true;
  for (int i = 0; i < p->windows; ++i) { /* from z back out along d: is window j the first one crossed? */
    float t;
    const iris_vcache_window *w = &p->window[i];
    if (i != j && iris_vcache_through_one_(w->o, w->n, w->u, w->v, si.p, d, &t) && t < h.t) return true;
  }
  const iris_vec3 n = iris_dot(si.ng, d) < 0.0f ? iris_neg(si.ng) : si.ng;
  const iris_vec3 power = iris_scale(Le, cw * area / (pdf * prob));
  const iris_vcache_vertex z = {si.p, n, iris_mul(iris_integrator_bsdf_eval(&sp, n), power), 0,
                                prob * fabsf(iris_dot(d, n)) / (area * cw)};
  return push(pool, cap, &z);
}

/* The pool of sample index s: light path i draws from its own stream of
 * (seed, s, i), so the pool does not depend on who builds it. */
static bool build_pool(const iris_vcache *vc, uint64_t s, iris_vcache_pool *pool, uint64_t *rays_out) {
  const iris_integrator *it = vc->it;
  const uint64_t key = iris_hash4(vc->p.seed, STREAM, s, 0);
  uint32_t cap = 0;
  uint64_t rays = 0;
  bool ok = true;
  for (uint32_t i = 0; i < vc->p.paths && ok; ++i) {
    iris_sampler r = iris_sampler_start(key, s, i);
    if (vc->p.sky) {
      ok = sky_path(vc, &r, pool, &cap, &rays);
      continue;
    }
    float u[5];
    for (uint32_t d = 0; d < 5; ++d) u[d] = iris_sampler_get(&r, d);
    iris_photon_emission e;
    if (!iris_lights_sample_emission(it->lights, u[0], u[1], u[2], u[3], u[4], &e) || !(iris_max3(e.power) > 0.0f))
      continue;
    if (it->lights->entries[e.light].kind != IRIS_LIGHT_KIND_TRIANGLE) continue; /* only triangles' light (vcache.h) */
    iris_ray ray = {e.p, 0.0f, e.dir, INFINITY};
    iris_vec3 power = e.power;
    for (int32_t m = 0; m < MAX_WALK && m <= it->max_depth; ++m) {
      iris_hit h;
      rays++;
      if (!iris_accel_intersect(it->accel, &ray, &h)) break;
      iris_interaction si;
      iris_accel_interaction(it->accel, ray.d, &h, &si);
      const iris_vec3 wo = iris_neg(iris_normalize(ray.d));
      iris_shading_point sp;
      iris_integrator_shade(it, &si, wo, m + 1, &sp);
      if (!iris_vcache_plain(&sp, si.ng)) break;
      iris_vec3 n = iris_dot(si.ng, wo) < 0.0f ? iris_neg(si.ng) : si.ng;
      if (iris_vcache_in_a(&vc->p, si.p, wo)) {
        if (m >= 1) {
          iris_vcache_vertex z = {si.p, n, iris_mul(iris_integrator_bsdf_eval(&sp, n), power), m, 0.0f};
          ok = push(pool, &cap, &z);
        }
        break;
      }
      /* region B: on by cosine sampling (the Lambertian's adjoint), f cos / pdf = albedo */
      iris_frame fr = iris_frame_from_normal(n);
      const float u0 = iris_sampler_get(&r, (uint32_t)(5 + 3 * m)), u1 = iris_sampler_get(&r, (uint32_t)(6 + 3 * m));
      iris_vec3 wl = iris_sample_cosine_hemisphere(u0, u1);
      if (!(wl.z > 0.0f)) break;
      iris_vec3 wi = iris_frame_to_world(&fr, wl);
      iris_vec3 t = iris_scale(iris_integrator_bsdf_eval(&sp, wi), IRIS_PI);
      const float q = iris_fminf(1.0f, iris_max3(t));
      if (!(q > 0.0f) || iris_sampler_get(&r, (uint32_t)(7 + 3 * m)) >= q) break;
      power = iris_scale(iris_mul(power, t), 1.0f / q);
      ray = iris_spawn_ray(&sp.si, wi);
    }
  }
  *rays_out = rays;
  return ok;
}

typedef struct build_ctx {
  iris_vcache *vc;
  chunk *ch;
  uint64_t first;
  uint64_t rays[CHUNK];
  bool ok[CHUNK];
} build_ctx;

static void build_task(void *vctx, uint64_t begin, uint64_t end, int thread) {
  (void)thread;
  build_ctx *b = vctx;
  for (uint64_t i = begin; i < end; ++i) b->ok[i] = build_pool(b->vc, b->first + i, &b->ch->pool[i], &b->rays[i]);
}

const iris_vcache_pool *iris_vcache_get(iris_vcache *vc, uint64_t s) {
  const uint64_t c = s / CHUNK;
  if (c >= MAX_CHUNKS) return NULL;
  /* with the sky, the pools' memory budget (deterministic: by index alone) */
  if (vc->p.sky && (c + 1) * CHUNK * (uint64_t)vc->p.paths * sizeof(iris_vcache_vertex) > IRIS_VCACHE_SKY_BUDGET)
    return NULL;
  chunk *ch = atomic_load_explicit(&vc->chunks[c], memory_order_acquire);
  if (!ch) {
    pthread_mutex_lock(&vc->lock);
    ch = atomic_load_explicit(&vc->chunks[c], memory_order_acquire);
    if (!ch && (ch = calloc(1, sizeof *ch)) != NULL) {
      build_ctx b;
      memset(&b, 0, sizeof b);
      b.vc = vc;
      b.ch = ch;
      b.first = c * CHUNK;
      iris_parallel_for(CHUNK, 1, vc->p.threads, build_task, &b);
      uint64_t rays = 0;
      bool ok = true;
      for (uint32_t i = 0; i < CHUNK; ++i) rays += b.rays[i], ok = ok && b.ok[i];
      atomic_fetch_add(&vc->rays, rays);
      if (ok) {
        atomic_store_explicit(&vc->chunks[c], ch, memory_order_release);
      } else { /* out of memory: these sample indices go without */
        for (uint32_t i = 0; i < CHUNK; ++i) free(ch->pool[i].v);
        free(ch);
        ch = NULL;
      }
    }
    pthread_mutex_unlock(&vc->lock);
    if (!ch) return NULL;
  }
  return &ch->pool[s % CHUNK];
}
