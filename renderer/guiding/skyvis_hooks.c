/* The guide's sky visibility (skyvis.h; docs/guiding.md, "Sky visibility"):
 * g->sky built from the guide's settings and caches, and the direction
 * sampler's hooks that sample the environment map from a vertex's tied
 * caches and weigh escaping rays by that density. The probes and the
 * per-cache tables are skyvis.c's. */
#include "renderer/guiding/guiding.h"
#include "renderer/guiding/skyvis.h"
#include "renderer/guiding/vertex.h"

/* Defaults measured in docs/guiding.md, "Sky visibility". */
#define SKY_REGIONS 16
#define SKY_PROBES 2
#define SKY_BETA 0.75f

iris_status iris_guiding_build_sky(iris_guiding *g, const iris_guide_setup *setup, iris_error *err) {
  iris_skyvis_destroy(&g->sky);
  const iris_guiding_params *p = &g->params;
  if (!p->use_nee || !setup->lights->envmap || g->stats.skipped || g->cache_count == 0) return IRIS_OK;
  iris_skyvis_params sp = {p->sky_regions >= 0 ? p->sky_regions : SKY_REGIONS,
                           p->sky_probes >= 0 ? p->sky_probes : SKY_PROBES,
                           p->sky_beta >= 0.0f ? p->sky_beta : SKY_BETA};
  iris_guiding_phase(setup, NULL, "probing the sky from the caches", -1.0);
  iris_status st = iris_skyvis_build(&g->sky, g->caches, g->cache_count, setup->accel, setup->lights->envmap, &sp,
                                     setup->seed, setup->threads, err);
  if (st == IRIS_OK) g->stats.memory_bytes += g->sky.memory_bytes;
  return st;
}

/* Light sampling of the map from the vertex's tied caches (or, at a vertex
 * no cache covers, from the windows as a whole). */
static int guided_sample_environment(void *ctx, const iris_envmap *env, const iris_shading_point *sp, float u0,
                                     float u1, iris_vec3 *wi, float *pdf, float *s, float *t) {
  const iris_guiding *g = ctx;
  const iris_guide_vertex_state *v = (const iris_guide_vertex_state *)sp->guide.bytes;
  if (!iris_skyvis_serves(&g->sky, env) || !iris_skyvis_guides(&g->sky, v->ids, v->m)) return -1;
  return iris_skyvis_sample(&g->sky, env, v->ids, v->m, sp->si.p, u0, u1, wi, pdf, s, t) ? 1 : 0;
}

static float guided_environment_scale(void *ctx, const iris_envmap *env, const iris_guide_vertex *gv, iris_vec3 wi,
                                      float s, float t, float *add) {
  const iris_guiding *g = ctx;
  const iris_guide_vertex_state *v = iris_guide_vertex_get(gv);
  *add = 0.0f;
  if (!iris_skyvis_serves(&g->sky, env)) return 1.0f;
  return iris_skyvis_scale(&g->sky, env, v->ids, v->m, v->p, wi, s, t, add);
}

/* The sky's power entering through a window: A times the map's radiance
 * times the cosine to the outward normal n, over the outward hemisphere
 * (64 x 64 stratified samples of the map's own sampling; nothing outside
 * the window is traced: a bound, the same for any thread count). */
static double window_flux(const iris_envmap *env, const iris_portal *p, iris_vec3 n) {
  enum { G = 64 };
  double sum = 0.0;
  for (int i = 0; i < G; ++i)
    for (int j = 0; j < G; ++j) {
      iris_vec3 d, L;
      float pdf;
      if (!iris_envmap_sample(env, ((float)i + 0.5f) / G, ((float)j + 0.5f) / G, &d, &pdf, &L) || !(pdf > 0.0f))
        continue;
      const float c = iris_dot(d, n);
      if (c > 0.0f) sum += (double)iris_avg3(L) * c / pdf;
    }
  return sum / (G * G) * 4.0 * iris_length(iris_cross(p->u, p->v));
}

/* The windows caches draw from, by the sky's power entering through them
 * (a window facing away from the sun lights the room less), at most max,
 * each turned to face away from its caches. */
static int guided_sky_windows(void *ctx, const iris_envmap *env, int max, iris_vec3 *o, iris_vec3 *u, iris_vec3 *v,
                              float *flux, float *share) {
  const iris_guiding *g = ctx;
  const iris_skyvis *sv = &g->sky;
  if (!sv->built || sv->window_count <= 0 || !sv->cache_window || g->cache_count == 0 || max <= 0) return 0;
  size_t count[IRIS_SKYVIS_WINDOWS] = {0};
  int side[IRIS_SKYVIS_WINDOWS] = {0};
  for (size_t i = 0; i < g->cache_count; ++i) {
    const uint8_t w = sv->cache_window[i];
    if (w == 0xff) continue;
    count[w]++;
    const iris_portal *p = &sv->window[w];
    side[w] += iris_dot(iris_sub(g->caches[i].p, p->o), iris_cross(p->u, p->v)) < 0.0f ? 1 : -1;
  }
  int n = 0;
  for (int j = 0; j < sv->window_count; ++j) {
    if (count[j] == 0) continue;
    const iris_portal *p = &sv->window[j];
    const iris_vec3 uj = side[j] >= 0 ? p->u : iris_neg(p->u);
    const float f = (float)window_flux(env, p, iris_normalize(iris_cross(uj, p->v)));
    /* insertion by flux, descending; the last place goes to a larger one */
    int k = n < max ? n++ : max;
    while (k > 0 && flux[k - 1] < f) {
      if (k < max) o[k] = o[k - 1], u[k] = u[k - 1], v[k] = v[k - 1], flux[k] = flux[k - 1], share[k] = share[k - 1];
      --k;
    }
    if (k < max) o[k] = p->o, u[k] = uj, v[k] = p->v, flux[k] = f, share[k] = (float)count[j] / (float)g->cache_count;
  }
  return n;
}

void iris_guiding_sky_hooks(iris_guiding *g, iris_direction_sampler *s) {
  if (g->sky.built) {
    s->sample_environment = guided_sample_environment;
    s->environment_scale = guided_environment_scale;
    s->sky_windows = guided_sky_windows;
  }
}
