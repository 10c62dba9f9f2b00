/* Guiding's per-vertex state (internal to renderer/guiding/): what
 * guided_prepare picks once per shading point and keeps in
 * iris_shading_point.guide, and the density of the picked caches. Shared by
 * the sampler (guided_sampler.c) and the training passes (train.c), which read the
 * state back from recorded path vertices. */
#ifndef IRIS_RENDERER_GUIDING_VERTEX_H
#define IRIS_RENDERER_GUIDING_VERTEX_H

#include <string.h>

#include "renderer/guiding/guiding.h"
#include "renderer/guiding/pane.h"

/* Alpha and the tied caches of Algorithm 1. Caches with the same frame and
 * map layout (coplanar caches: the usual tie) map a direction to the same
 * texel, so pdf evaluation computes that texel once per group. */
typedef struct iris_guide_vertex_state {
  float alpha;                          /* cache-sampling probability; 0: BSDF only */
  float radiance;                       /* tied caches' mean radiance estimate; < 0 none */
  float sky;                            /* of the guide's share alpha, the map's (sky behind glass) */
  float lamp;                           /* ... and the lamps' cones' (lamps behind glass) */
  float light;                          /* probability of light sampling here (the tied caches' largest) */
  int32_t m;                            /* tied caches */
  iris_vec3 p;                          /* the shading point (the lamps' cones are seen from it) */
  uint32_t ids[IRIS_GUIDING_PICK_K];
  uint8_t same_as[IRIS_GUIDING_PICK_K]; /* first tied cache with this one's frame */
  uint8_t pane;                         /* the tied cache (index into ids) whose refracting plane the
                                           map's directions pass ("Sky through a pane"); 0xff: none */
  float glint;                          /* ... and the glint spot's cone's ("Glints"); 0: no spot */
  iris_guide_lamp spot;                 /* the glint spot seen from p (glints.h) */
  float portal;                         /* probability of a portal sample, before the rest (portal.h) */
  uint8_t portal_of;                    /* the tied cache (index into ids) whose portal; 0xff: none */
  uint8_t portal_faces;                 /* bit i: tied cache i has a portal that faces the vertex (what
                                           training weighs: train.c, "Portals kept by training") */
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

/* Density of the lamps' component ("Lamps behind glass"): every tied cache's
 * lamp slots, chosen in proportion to their shares, each uniform in its
 * sphere's cone from the vertex: sum_k w_k [wi in cone_k] / (2 pi (1 - cos_k)) / sum_k w_k. */
static inline float iris_guide_vertex_lamp_pdf(const iris_guiding *g, const iris_guide_vertex_state *v,
                                               iris_vec3 wi) {
  float sum = 0.0f, total = 0.0f;
  for (int i = 0; i < v->m; ++i) {
    const iris_cache *c = &g->caches[v->ids[i]];
    for (int k = 0; k < IRIS_CACHE_LAMPS && c->lamp_share[k] > 0.0f; ++k) {
      const iris_guide_lamp *l = &g->lamps[c->lamp[k]];
      total += c->lamp_share[k];
      if (!iris_lamp_contains(l, v->p, wi)) continue;
      iris_lamp_cone cone = iris_lamp_cone_at(l, v->p);
      sum += c->lamp_share[k] * iris_lamp_cone_pdf(&cone);
    }
  }
  return total > 0.0f ? sum / total : 0.0f;
}

/* Samples iris_guide_vertex_lamp_pdf: a tied cache's lamp slot in
 * proportion to its share (u in [0, 1)), then a direction uniformly in that
 * lamp's cone (u1, u2). False when no tied cache has a lamp share. */
static inline bool iris_guide_vertex_lamp_sample(const iris_guiding *g, const iris_guide_vertex_state *v, float u,
                                                 float u1, float u2, iris_vec3 *wi) {
  float total = 0.0f;
  for (int i = 0; i < v->m; ++i) {
    const iris_cache *c = &g->caches[v->ids[i]];
    for (int k = 0; k < IRIS_CACHE_LAMPS && c->lamp_share[k] > 0.0f; ++k) total += c->lamp_share[k];
  }
  const iris_guide_lamp *chosen = NULL;
  float target = u * total, acc = 0.0f;
  for (int i = 0; i < v->m && !(chosen && acc > target); ++i) {
    const iris_cache *c = &g->caches[v->ids[i]];
    for (int k = 0; k < IRIS_CACHE_LAMPS && c->lamp_share[k] > 0.0f; ++k) {
      chosen = &g->lamps[c->lamp[k]]; /* the last one with a share when rounding runs past the end */
      acc += c->lamp_share[k];
      if (acc > target) break;
    }
  }
  if (!chosen) return false;
  iris_lamp_cone cone = iris_lamp_cone_at(chosen, v->p);
  *wi = iris_lamp_cone_sample(&cone, u1, u2);
  return true;
}

/* Density of the glint spot's component ("Glints"): uniform in its cone from the vertex. */
static inline float iris_guide_vertex_glint_pdf(const iris_guide_vertex_state *v, iris_vec3 wi) {
  if (!iris_lamp_contains(&v->spot, v->p, wi)) return 0.0f;
  iris_lamp_cone cone = iris_lamp_cone_at(&v->spot, v->p);
  return iris_lamp_cone_pdf(&cone);
}

/* Density of the map's component at the vertex: the map's own, or carried
 * through the plane of the tied cache v->pane ("Sky through a pane"). */
static inline float iris_guide_vertex_sky_pdf(const iris_guiding *g, const iris_guide_vertex_state *v,
                                              iris_vec3 wi) {
  if (v->pane == 0xff) return iris_envmap_pdf(g->env, wi);
  const float *pl = g->caches[v->ids[v->pane]].pane;
  iris_vec3 ws;
  float jac;
  if (!iris_pane_to_sky(iris_v3(pl[0], pl[1], pl[2]), pl[3], wi, &ws, &jac)) return 0.0f;
  return iris_envmap_pdf(g->env, ws) * jac;
}

/* Samples iris_guide_vertex_sky_pdf from (u1, u2); false where nothing is drawn. */
static inline bool iris_guide_vertex_sky_sample(const iris_guiding *g, const iris_guide_vertex_state *v, float u1,
                                                float u2, iris_vec3 *wi) {
  float pdf;
  iris_vec3 ws;
  if (!iris_envmap_sample(g->env, u1, u2, &ws, &pdf, NULL)) return false;
  if (v->pane == 0xff) {
    *wi = ws;
    return true;
  }
  const float *pl = g->caches[v->ids[v->pane]].pane;
  return iris_pane_to_room(iris_v3(pl[0], pl[1], pl[2]), pl[3], ws, wi);
}

/* Density of the guide's strategy: the tied caches', mixed with the map's
 * where sky light arrives through glass (docs/guiding.md, "Sky behind glass")
 * and with the lamps' cones where lamp light does ("Lamps behind glass"). */
static inline float iris_guide_vertex_guide_pdf(const iris_guiding *g, const iris_guide_vertex_state *v,
                                                iris_vec3 wi) {
  float pc = iris_guide_vertex_cache_pdf(g, v, wi);
  if (!(v->sky > 0.0f) && !(v->lamp > 0.0f) && !(v->glint > 0.0f)) return pc;
  float d = (1.0f - v->sky - v->lamp - v->glint) * pc;
  if (v->sky > 0.0f) d += v->sky * iris_guide_vertex_sky_pdf(g, v, wi);
  if (v->lamp > 0.0f) d += v->lamp * iris_guide_vertex_lamp_pdf(g, v, wi);
  if (v->glint > 0.0f) d += v->glint * iris_guide_vertex_glint_pdf(v, wi);
  return d;
}

#endif
