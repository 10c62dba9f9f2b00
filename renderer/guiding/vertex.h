/* Guiding's per-vertex state (internal to renderer/guiding/): what
 * guided_prepare picks once per shading point and keeps in
 * iris_shading_point.guide, and the density of the picked caches. Shared by
 * the sampler (guided_sampler.c) and the training passes (train.c), which read the
 * state back from recorded path vertices. */
#ifndef IRIS_RENDERER_GUIDING_VERTEX_H
#define IRIS_RENDERER_GUIDING_VERTEX_H

#include <string.h>

#include "renderer/guiding/guiding.h"

/* Alpha and the tied caches of Algorithm 1. Caches with the same frame and
 * map layout (coplanar caches: the usual tie) map a direction to the same
 * texel, so pdf evaluation computes that texel once per group. */
typedef struct iris_guide_vertex_state {
  float alpha;                          /* cache-sampling probability; 0: BSDF only */
  float radiance;                       /* tied caches' mean radiance estimate; < 0 none */
  float sky;                            /* of the guide's share alpha, the map's (sky behind glass) */
  int32_t m;                            /* tied caches */
  uint32_t ids[IRIS_GUIDING_PICK_K];
  uint8_t same_as[IRIS_GUIDING_PICK_K]; /* first tied cache with this one's frame */
} iris_guide_vertex_state;
_Static_assert(sizeof(iris_guide_vertex_state) <= IRIS_GUIDE_VERTEX_BYTES, "guide vertex state too large");

static inline const iris_guide_vertex_state *iris_guide_vertex_get(const iris_guide_vertex *v) {
  return (const iris_guide_vertex_state *)v->bytes;
}

/* Cache-sampling density of the vertex's tied caches (their average). */
static inline float iris_guide_vertex_cache_pdf(const iris_guiding *g, const iris_guide_vertex_state *v,
                                                iris_vec3 wi) {
  int32_t texel[IRIS_GUIDING_PICK_K] = {-1, -1, -1, -1, -1};
  int sub[IRIS_GUIDING_PICK_K] = {0, 0, 0, 0, 0};
  float jac[IRIS_GUIDING_PICK_K];
  float sum = 0.0f;
  for (int i = 0; i < v->m; ++i) {
    const iris_cache *c = &g->caches[v->ids[i]];
    if (v->same_as[i] == i) {
      texel[i] = iris_cache_cell(g->hemi.res, c->sphere, iris_frame_to_local(&c->frame, wi), &jac[i], &sub[i]);
    } else {
      texel[i] = texel[v->same_as[i]];
      jac[i] = jac[v->same_as[i]];
      sub[i] = sub[v->same_as[i]];
    }
    if (texel[i] < 0) continue;
    const uint32_t t = c->table + (uint32_t)texel[i];
    float d = g->pdf[t] * jac[i];
    if (g->refine_slot && g->refine_slot[t]) /* a refined texel: its sub-cell's multiplier (refine.h) */
      d *= iris_guiding_sub(g, c)[(size_t)(g->refine_slot[t] - 1) * IRIS_REFINE_SUB + sub[i]];
    sum += d;
  }
  return v->m > 0 ? sum / (float)v->m : 0.0f;
}

/* Density of the guide's strategy: the tied caches', mixed with the map's
 * where sky light arrives through glass (docs/guiding.md, "Sky behind glass"). */
static inline float iris_guide_vertex_guide_pdf(const iris_guiding *g, const iris_guide_vertex_state *v,
                                                iris_vec3 wi) {
  float pc = iris_guide_vertex_cache_pdf(g, v, wi);
  if (!(v->sky > 0.0f)) return pc;
  return (1.0f - v->sky) * pc + v->sky * iris_envmap_pdf(g->env, wi);
}

#endif
