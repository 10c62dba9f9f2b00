/* Light selection, next-event sampling, emission and photon emission of the
 * light list that light_build.c builds; see lights.h. */
#include "renderer/lights.h"

#include <stdlib.h>
#include <string.h>

#include "renderer/lights_private.h"

/* glTF KHR_lights_punctual spot attenuation (the specification's squared ramp). */
static float spot_falloff(const iris_light *l, iris_vec3 travel) {
  float cd = iris_dot(iris_v3_load(l->direction), travel);
  float co = cosf(l->outer_cone), ci = cosf(l->inner_cone);
  float scale = 1.0f / fmaxf(0.001f, ci - co);
  float a = iris_clampf((cd - co) * scale, 0.0f, 1.0f);
  return a * a;
}

/* Estimated irradiance of each group at ref (the selection weights); returns the sum. */
static double group_weights_at(const iris_lights *L, iris_vec3 ref, float *w) {
  double sum = 0.0;
  for (size_t k = 0; k < L->group_count; k++) {
    const iris_light_group *g = &L->groups[k];
    float v;
    if (g->kind == IRIS_LIGHT_KIND_DIRECTIONAL || g->kind == IRIS_LIGHT_KIND_ENVIRONMENT) {
      v = g->irradiance;
    } else {
      iris_vec3 d = iris_sub(g->center, ref);
      float d2 = fmaxf(iris_dot(d, d), g->radius * g->radius);
      d2 = fmaxf(d2, 1e-12f);
      /* triangles: power / (4 pi d^2); point and spot: I / d^2 = power_point / (4 pi d^2) */
      v = g->phi / (4.0f * IRIS_PI * d2);
    }
    w[k] = isfinite(v) && v > 0.0f ? v : 0.0f;
    sum += w[k];
  }
  return sum;
}

/* The weights of the last point this thread asked about: a path asks at a
 * vertex for light sampling and again, from the same point, for the MIS pdf of
 * the emitter its next ray hits. */
static _Thread_local struct {
  uint64_t id;
  iris_vec3 ref;
  double sum;
  float w[IRIS_LIGHTS_MAX_GROUPS + 1];
} weight_cache;

static const float *group_weights(const iris_lights *L, iris_vec3 ref, double *sum) {
  if (weight_cache.id != L->id || memcmp(&weight_cache.ref, &ref, sizeof ref) != 0) {
    weight_cache.sum = group_weights_at(L, ref, weight_cache.w);
    weight_cache.id = L->id;
    weight_cache.ref = ref;
  }
  *sum = weight_cache.sum;
  return weight_cache.w;
}

/* Selection probability at ref of an entry of group `group` whose probability
 * within the group is pe. */
static float select_pmf_at(const iris_lights *L, iris_vec3 ref, uint32_t group, float pe) {
  if (L->group_count == 1) return pe;
  double sum;
  const float *w = group_weights(L, ref, &sum);
  if (!(sum > 0.0)) return 0.0f;
  return (float)(w[group] / sum) * pe;
}

float iris_lights_select_pmf_at(const iris_lights *L, iris_vec3 ref, iris_vec3 n, uint32_t index) {
  if (index >= L->count) return 0.0f;
  if (L->learned.pmf) return L->learned.pmf(L->learned.ctx, L, ref, n, index);
  if (L->tree) return iris_light_tree_pmf(L->tree, ref, n, index);
  return select_pmf_at(L, ref, L->entries[index].group, entry_pmf_in_group(L, index));
}

/* Probability of entry i within its group. */
static float pmf_in_group(const iris_lights *L, uint32_t i) {
  return i < L->tri_count ? L->tris[i].pmf_in_group : entry_pmf_in_group(L, i);
}

/* Slot of a group's alias table from u in [0, 1): the entry index and the
 * remainder for the alias test (exact in double: u has 24 bits, n <= 2^29). */
static uint32_t alias_slot(const iris_light_group *g, float u, float *coin) {
  double f = (double)u * (double)g->count;
  uint32_t j = (uint32_t)f;
  if (j >= g->count) j = g->count - 1;
  *coin = (float)(f - (double)j);
  return g->first + j;
}

/* In-group choice of a group with count > 1: triangles through the alias
 * table (finished by alias_resolve), others (never more than one) directly. */
static uint32_t choose_in_group(const iris_light_group *g, float u, float *coin) {
  *coin = -1.0f;
  if (g->kind == IRIS_LIGHT_KIND_TRIANGLE) return alias_slot(g, u, coin);
  return g->first + (uint32_t)iris_distrib1d_sample(&g->select, u, NULL, NULL);
}

/* The alias redirection of a slot chosen by choose_in_group. */
static uint32_t alias_resolve(const iris_lights *L, uint32_t i, float coin) {
  if (coin < 0.0f || i >= L->tri_count) return i;
  const iris_light_tri *t = &L->tris[i];
  return coin < t->alias_q ? i : t->alias;
}

/* Two-step choice at ref; returns the entry (a slot to be resolved with
 * alias_resolve(coin)) and the probability of its group (the entry's
 * probability is that times pmf_in_group, which is left to the caller so that
 * the entry's record is not read here). */
static uint32_t select_at(const iris_lights *L, iris_vec3 ref, float u, float *pmf_group,
                          float *coin) {
  *coin = -1.0f;
  if (L->group_count == 1) {
    const iris_light_group *g = &L->groups[0];
    *pmf_group = 1.0f;
    if (g->count == 1) return 0;
    return choose_in_group(g, u, coin);
  }
  double sum;
  const float *w = group_weights(L, ref, &sum);
  *pmf_group = 0.0f;
  if (!(sum > 0.0)) return 0;
  double target = (double)u * sum, acc = 0.0;
  size_t k = 0, last = 0;
  for (; k < L->group_count; k++) {
    if (w[k] > 0.0f) last = k;
    if (w[k] > 0.0f && acc + w[k] > target) break;
    acc += w[k];
  }
  if (k == L->group_count) { /* rounding: the last group with weight */
    k = last;
    acc = sum - w[k];
  }
  const iris_light_group *g = &L->groups[k];
  float pg = (float)(w[k] / sum);
  uint32_t index = g->first;
  if (g->count > 1) {
    float ur = (float)((target - acc) / w[k]);
    ur = iris_clampf(ur, 0.0f, IRIS_ONE_MINUS_EPSILON);
    index = choose_in_group(g, ur, coin);
  }
  *pmf_group = pg;
  return index;
}

float iris_lights_select_pmf(const iris_lights *lights, uint32_t index) {
  if (index >= lights->count) return 0.0f;
  return iris_distrib1d_pmf(&lights->select, index);
}

uint32_t iris_lights_select(const iris_lights *lights, float u, float *pmf) {
  if (lights->count == 0) {
    *pmf = 0.0f;
    return 0;
  }
  return (uint32_t)iris_distrib1d_sample(&lights->select, u, pmf, NULL);
}

static iris_vec3 surface_emission(const iris_lights *lights, const iris_material *m,
                                  const iris_interaction *si) {
  iris_vec3 le = iris_v3_load(m->emission);
  if (m->emission_texture >= 0) {
    float t[4];
    iris_texture_sample(lights->textures, m->emission_texture, si->uv, si->uv1, true, t);
    le = iris_mul(le, iris_v3(t[0], t[1], t[2]));
  }
  if (m->unlit) le = iris_mul(le, si->color); /* KHR_materials_unlit: base colour x vertex colour */
  return le;
}

/* What of a MASK/BLEND emitter exists at (b1, b2) of prim, as a ray that reaches the point
 * sees it (renderer/accel.c's alpha filter): MASK 1 where alpha >= cutoff, else 0 (glTF:
 * "fully opaque or fully transparent"); BLEND alpha, the probability that a ray stops there.
 * A light sample's shadow ray ends just before the emitter, so without this next-event
 * estimation would count emission from cut-out parts that BSDF-sampled rays pass through. */
static float surface_coverage(const iris_lights *lights, const iris_material *m, uint32_t prim, float b1,
                              float b2) {
  float alpha = iris_accel_alpha(lights->accel, prim, b1, b2);
  if (m->alpha_mode == IRIS_ALPHA_MASK) return alpha >= m->alpha_cutoff ? 1.0f : 0.0f;
  return iris_clampf(alpha, 0.0f, 1.0f);
}

iris_vec3 iris_lights_emitted(const iris_lights *lights, const iris_interaction *si, iris_vec3 d) {
  const iris_material *m = material_of(lights->scene, si->material);
  if (!is_emissive(m)) return iris_v3(0, 0, 0);
  if (!m->emission_two_sided && iris_dot(d, si->ng) >= 0.0f) return iris_v3(0, 0, 0);
  return surface_emission(lights, m, si);
}

void iris_lights_choose(const iris_lights *lights, iris_vec3 ref, iris_vec3 n, float u_select,
                        iris_light_choice *c) {
  c->light = 0;
  c->pmf_group = 0.0f;
  c->pmf_is_entry = false;
  if (lights->count == 0) return;
  if (lights->learned.choose) {
    c->pmf_is_entry = true;
    if (!lights->learned.choose(lights->learned.ctx, lights, ref, n, u_select, &c->light, &c->pmf_group))
      c->pmf_group = 0.0f;
    if (c->light < lights->tri_count) __builtin_prefetch(&lights->tris[c->light]);
    return;
  }
  if (lights->tree) {
    c->pmf_is_entry = true;
    if (!iris_light_tree_sample(lights->tree, ref, n, u_select, &c->light, &c->pmf_group)) c->pmf_group = 0.0f;
    if (c->light < lights->tri_count) __builtin_prefetch(&lights->tris[c->light]);
    return;
  }
  float coin = -1.0f;
  uint32_t slot = select_at(lights, ref, u_select, &c->pmf_group, &coin);
  c->light = alias_resolve(lights, slot, coin);
  if (c->light < lights->tri_count) __builtin_prefetch(&lights->tris[c->light]);
}

/* Solid-angle or area sampling of an emitter triangle seen from ref
 * (docs/rendering.md, "Emitter triangles"): by solid angle when ref is
 * closer to the triangle's plane than its longest edge is long (Cycles'
 * rule: there the area density d^2 / cos varies most over the triangle)
 * and the solid angle is within pbrt-v4's bounds for accurate spherical
 * sampling (3e-4 to 6.22 sr), by area otherwise. Returns the solid angle
 * when it is to be used, else 0; the sampler and the pdf both ask this one
 * function. */
#define IRIS_SOLID_ANGLE_MIN 3e-4f
#define IRIS_SOLID_ANGLE_MAX 6.22f
float iris_lights_triangle_solid_angle(const iris_light_tri *t, iris_vec3 ref) {
  if (t->flags & IRIS_LIGHT_TRI_AREA_ONLY) return 0.0f;
  iris_vec3 e1 = iris_v3_load(t->e1), e2 = iris_v3_load(t->e2);
  iris_vec3 a = iris_sub(iris_v3_load(t->v0), ref);
  iris_vec3 n = iris_cross(e1, e2);
  float nn = iris_dot(n, n);
  float plane = iris_dot(n, a); /* |n| times the signed distance of ref to the plane (front < 0) */
  if (!(t->flags & IRIS_LIGHT_TRI_TWO_SIDED) && plane >= 0.0f) return 0.0f; /* behind: area path refuses */
  iris_vec3 e3 = iris_sub(e2, e1);
  float longest2 = fmaxf(iris_dot(e1, e1), fmaxf(iris_dot(e2, e2), iris_dot(e3, e3)));
  if (!(longest2 * nn > plane * plane)) return 0.0f;
  float omega = iris_spherical_triangle_area(a, iris_add(a, e1), iris_add(a, e2));
  return omega >= IRIS_SOLID_ANGLE_MIN && omega <= IRIS_SOLID_ANGLE_MAX ? omega : 0.0f;
}

const char *iris_triangle_sampling_name(iris_triangle_sampling m) {
  return m == IRIS_TRIANGLE_SAMPLING_AREA ? "area" : "solid-angle";
}
bool iris_triangle_sampling_parse(const char *name, iris_triangle_sampling *out) {
  for (int m = 0; m < IRIS_TRIANGLE_SAMPLING_COUNT; m++)
    if (strcmp(name, iris_triangle_sampling_name((iris_triangle_sampling)m)) == 0) {
      *out = (iris_triangle_sampling)m;
      return true;
    }
  return false;
}
void iris_lights_set_triangle_sampling(iris_lights *lights, iris_triangle_sampling m) {
  for (size_t i = 0; i < lights->tri_count; i++) {
    if (m == IRIS_TRIANGLE_SAMPLING_AREA)
      lights->tris[i].flags |= IRIS_LIGHT_TRI_AREA_ONLY;
    else
      lights->tris[i].flags &= ~IRIS_LIGHT_TRI_AREA_ONLY;
  }
}

/* Where the ray o + t w (o relative to v0 = a) meets the triangle's plane, as
 * coefficients of its edges (Moller-Trumbore), clamped into the triangle. */
static bool ray_triangle(iris_vec3 a, iris_vec3 e1, iris_vec3 e2, iris_vec3 w, float *b1, float *b2) {
  /* the ray starts at -a relative to v0 */
  iris_vec3 o = iris_neg(a);
  iris_vec3 pv = iris_cross(w, e2);
  float det = iris_dot(e1, pv);
  if (!(fabsf(det) > 0.0f)) return false;
  float inv = 1.0f / det;
  float u = iris_dot(o, pv) * inv;
  iris_vec3 qv = iris_cross(o, e1);
  float v = iris_dot(w, qv) * inv;
  if (!isfinite(u) || !isfinite(v)) return false;
  u = iris_clampf(u, 0.0f, 1.0f);
  v = iris_clampf(v, 0.0f, 1.0f);
  if (u + v > 1.0f) {
    float k = 1.0f / (u + v);
    u *= k;
    v *= k;
  }
  *b1 = u;
  *b2 = v;
  return true;
}

bool iris_lights_sample(const iris_lights *lights, iris_vec3 ref, iris_vec3 n, float u_select, float u0,
                        float u1, iris_light_sample *s) {
  iris_light_choice c;
  iris_lights_choose(lights, ref, n, u_select, &c);
  return iris_lights_sample_choice(lights, ref, &c, u0, u1, s);
}

static bool sample_choice(const iris_lights *lights, iris_vec3 ref, const iris_light_choice *c, float u0,
                          float u1, iris_light_sample *s, bool lazy);

bool iris_lights_sample_choice(const iris_lights *lights, iris_vec3 ref,
                               const iris_light_choice *c, float u0, float u1,
                               iris_light_sample *s) {
  return sample_choice(lights, ref, c, u0, u1, s, false);
}

bool iris_lights_sample_choice_lazy(const iris_lights *lights, iris_vec3 ref, const iris_light_choice *c,
                                    float u0, float u1, iris_light_sample *s) {
  return sample_choice(lights, ref, c, u0, u1, s, true);
}

void iris_lights_prefetch_environment(const iris_lights *lights, float u0, float u1, int stage) {
  if (lights->envmap) iris_envmap_prefetch(lights->envmap, u0, u1, stage);
}

void iris_lights_sample_radiance(const iris_lights *lights, iris_light_sample *s) {
  if (!s->L_pending) return;
  s->L = iris_envmap_radiance_st(lights->envmap, s->map_s, s->map_t);
  s->L_pending = false;
}

/* The probability of the light a choice names (its group's times its own in it). */
static float choice_pmf(const iris_lights *lights, const iris_light_choice *c) {
  return c->pmf_is_entry ? c->pmf_group : c->pmf_group * pmf_in_group(lights, c->light); /* 1 * pe = pe exactly */
}

bool iris_lights_choice_is_environment_map(const iris_lights *lights, const iris_light_choice *c) {
  return lights->envmap && lights->environment >= 0 && c->light == (uint32_t)lights->environment &&
         c->pmf_group > 0.0f;
}

bool iris_lights_environment_sample_at(const iris_lights *lights, const iris_light_choice *c, iris_vec3 ref,
                                       iris_vec3 wi, float pdf_dir, float s, float t, iris_light_sample *out) {
  if (!iris_lights_choice_is_environment_map(lights, c)) return false;
  float pmf = choice_pmf(lights, c);
  out->light = c->light;
  out->delta = false;
  out->wi = wi;
  out->map_s = s;
  out->map_t = t;
  out->L_pending = true;
  out->pdf = pmf * pdf_dir;
  out->dist = INFINITY;
  out->p = iris_madd(ref, wi, 2.0f * lights->radius);
  out->n = iris_neg(wi);
  return isfinite(out->pdf) && out->pdf > 0.0f;
}

static bool sample_choice(const iris_lights *lights, iris_vec3 ref, const iris_light_choice *c, float u0,
                          float u1, iris_light_sample *s, bool lazy) {
  s->L_pending = false;
  if (!(c->pmf_group > 0.0f) || c->light >= lights->count) return false;
  uint32_t i = c->light;
  float pmf = choice_pmf(lights, c);
  if (!(pmf > 0.0f)) return false;
  s->light = i;
  if (i < lights->tri_count) { /* a triangle: only its cache line is read */
    const iris_light_tri *t = &lights->tris[i];
    s->delta = false;
    float omega = iris_lights_triangle_solid_angle(t, ref);
    float b1, b2; /* p = v0 + b1 e1 + b2 e2 */
    iris_interaction si;
    if (omega > 0.0f) {
      iris_vec3 v0 = iris_v3_load(t->v0), e1 = iris_v3_load(t->e1), e2 = iris_v3_load(t->e2);
      iris_vec3 a = iris_sub(v0, ref), wi;
      if (!iris_sample_spherical_triangle(a, iris_add(a, e1), iris_add(a, e2), u0, u1, &wi))
        return false;
      if (!ray_triangle(a, e1, e2, wi, &b1, &b2)) return false;
    } else {
      float b0;
      iris_sample_uniform_triangle(u0, u1, &b0, &b1);
      b2 = 1.0f - b0 - b1;
    }
    if (t->flags & IRIS_LIGHT_TRI_TEXTURED) {
      iris_accel_surface_at(lights->accel, lights->entries[i].prim, b1, b2, &si);
    } else { /* position and normal are all an untextured emitter needs */
      si.ng = iris_normalize(iris_cross(iris_v3_load(t->e1), iris_v3_load(t->e2)));
      si.p = iris_add(iris_v3_load(t->v0), iris_add(iris_scale(iris_v3_load(t->e1), b1),
                                                    iris_scale(iris_v3_load(t->e2), b2)));
    }
    iris_vec3 to = iris_sub(si.p, ref);
    float d2 = iris_dot(to, to);
    if (!(d2 > 0.0f)) return false;
    float dist = sqrtf(d2);
    iris_vec3 wi = iris_scale(to, 1.0f / dist);
    float cos_l = -iris_dot(wi, si.ng);
    if (!(t->flags & IRIS_LIGHT_TRI_TWO_SIDED) && cos_l <= 0.0f) return false;
    cos_l = fabsf(cos_l);
    if (!(cos_l > 0.0f)) return false;
    s->wi = wi;
    s->dist = dist;
    s->p = si.p;
    s->n = si.ng;
    const iris_material *m = material_of(lights->scene, t->material);
    s->L = (t->flags & IRIS_LIGHT_TRI_TEXTURED) ? surface_emission(lights, m, &si)
                                                : iris_v3_load(m->emission);
    if (m->alpha_mode != IRIS_ALPHA_OPAQUE) { /* the shadow ray stops short of the emitter */
      float c = surface_coverage(lights, m, lights->entries[i].prim, b1, b2);
      if (!(c > 0.0f)) return false;
      s->L = iris_scale(s->L, c);
    }
    s->pdf = omega > 0.0f ? pmf / omega : pmf * d2 / (cos_l * t->area);
    return isfinite(s->pdf) && s->pdf > 0.0f;
  }
  const iris_light_entry *e = &lights->entries[i];
  s->delta = e->kind != IRIS_LIGHT_KIND_TRIANGLE && e->kind != IRIS_LIGHT_KIND_ENVIRONMENT;
  switch (e->kind) {
    case IRIS_LIGHT_KIND_TRIANGLE: /* all triangles are in tris */
      return false;
    case IRIS_LIGHT_KIND_POINT:
    case IRIS_LIGHT_KIND_SPOT: {
      const iris_light *l = &lights->scene->lights[e->prim];
      iris_vec3 p = iris_v3_load(l->position);
      iris_vec3 to = iris_sub(p, ref);
      float d2 = iris_dot(to, to);
      if (!(d2 > 0.0f)) return false;
      float dist = sqrtf(d2);
      s->wi = iris_scale(to, 1.0f / dist);
      s->dist = dist;
      s->p = p;
      s->n = iris_neg(s->wi);
      float fall = e->kind == IRIS_LIGHT_KIND_SPOT ? spot_falloff(l, iris_neg(s->wi)) : 1.0f;
      if (!(fall > 0.0f)) return false;
      s->L = iris_scale(e->radiance, fall / d2);
      s->pdf = pmf;
      return true;
    }
    case IRIS_LIGHT_KIND_DIRECTIONAL: {
      const iris_light *l = &lights->scene->lights[e->prim];
      s->wi = iris_neg(iris_normalize(iris_v3_load(l->direction)));
      s->dist = INFINITY;
      s->p = iris_madd(ref, s->wi, 2.0f * lights->radius);
      s->n = iris_neg(s->wi);
      s->L = e->radiance;
      s->pdf = pmf;
      return true;
    }
    case IRIS_LIGHT_KIND_ENVIRONMENT:
    default: {
      if (lights->envmap) {
        float pdf;
        if (!iris_envmap_sample_st(lights->envmap, u0, u1, &s->wi, &pdf, &s->map_s, &s->map_t)) return false;
        if (lazy) s->L_pending = true;
        else s->L = iris_envmap_radiance_st(lights->envmap, s->map_s, s->map_t);
        s->pdf = pmf * pdf;
      } else {
        s->wi = iris_sample_uniform_sphere(u0, u1);
        s->L = e->radiance;
        s->pdf = pmf * iris_sample_uniform_sphere_pdf();
      }
      s->dist = INFINITY;
      s->p = iris_madd(ref, s->wi, 2.0f * lights->radius);
      s->n = iris_neg(s->wi);
      return s->pdf > 0.0f;
    }
  }
}

float iris_lights_pdf_triangle(const iris_lights *lights, iris_vec3 ref, iris_vec3 n,
                               const iris_interaction *si) {
  if (!lights->light_base || si->instance >= iris_accel_instance_count(lights->accel)) return 0.0f;
  uint32_t base = lights->light_base[si->instance];
  if (base == UINT32_MAX) return 0.0f;
  uint32_t first, count;
  iris_accel_instance_prims(lights->accel, si->instance, &first, &count);
  if (si->prim < first || si->prim - first >= count) return 0.0f;
  uint32_t i = lights->light_of_prim[base + (si->prim - first)];
  if (i >= lights->tri_count) return 0.0f;
  const iris_light_tri *t = &lights->tris[i];
  iris_vec3 to = iris_sub(si->p, ref);
  if (!(t->flags & IRIS_LIGHT_TRI_TWO_SIDED) && iris_dot(to, si->ng) >= 0.0f)
    return 0.0f; /* never sampled from behind */
  float pmf = lights->learned.pmf ? lights->learned.pmf(lights->learned.ctx, lights, ref, n, i)
               : lights->tree   ? iris_light_tree_pmf(lights->tree, ref, n, i)
                                : select_pmf_at(lights, ref, t->flags >> 8, t->pmf_in_group);
  float omega = iris_lights_triangle_solid_angle(t, ref);
  if (omega > 0.0f) return pmf / omega;
  float d2 = iris_dot(to, to);
  float cos_l = fabsf(iris_dot(to, si->ng)) / sqrtf(d2);
  if (!(cos_l > 0.0f) || !(d2 > 0.0f)) return 0.0f;
  return pmf * d2 / (cos_l * t->area);
}

iris_vec3 iris_lights_environment(const iris_lights *lights, iris_vec3 d) {
  if (lights->environment < 0) return iris_v3(0, 0, 0);
  if (lights->envmap) return iris_envmap_radiance(lights->envmap, iris_normalize(d));
  return lights->entries[lights->environment].radiance;
}

float iris_lights_pdf_environment(const iris_lights *lights, iris_vec3 ref, iris_vec3 n, iris_vec3 d) {
  if (lights->environment < 0) return 0.0f;
  float pdf = lights->envmap ? iris_envmap_pdf(lights->envmap, iris_normalize(d))
                             : iris_sample_uniform_sphere_pdf();
  return iris_lights_select_pmf_at(lights, ref, n, (uint32_t)lights->environment) * pdf;
}

iris_vec3 iris_lights_environment_pdf(const iris_lights *lights, iris_vec3 d, iris_vec3 ref, iris_vec3 n,
                                      float *pdf, float map_st[2]) {
  if (!pdf) return iris_lights_environment(lights, d);
  *pdf = 0.0f;
  if (lights->environment < 0) return iris_v3(0, 0, 0);
  float map_pdf = iris_sample_uniform_sphere_pdf();
  iris_vec3 L = lights->envmap ? iris_envmap_eval(lights->envmap, iris_normalize(d), &map_pdf, map_st)
                               : lights->entries[lights->environment].radiance;
  if (L.x > 0.0f || L.y > 0.0f || L.z > 0.0f)
    *pdf = iris_lights_select_pmf_at(lights, ref, n, (uint32_t)lights->environment) * map_pdf;
  return L;
}

iris_status iris_lights_emission_selection(const iris_lights *lights, iris_emission_selection by,
                                          iris_distrib1d *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  const size_t n = lights->count;
  if (n == 0) return IRIS_OK;
  float *w = malloc(sizeof(float) * n);
  if (!w) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for the light list");
  /* By area: the triangles keep their total share of the power, split by area. */
  double tri_power = 0.0, tri_area = 0.0;
  for (size_t i = 0; i < n; i++)
    if (lights->entries[i].kind == IRIS_LIGHT_KIND_TRIANGLE) {
      tri_power += lights->entries[i].power;
      tri_area += lights->entries[i].area;
    }
  for (size_t i = 0; i < n; i++) {
    const iris_light_entry *e = &lights->entries[i];
    w[i] = by == IRIS_EMIT_BY_AREA && e->kind == IRIS_LIGHT_KIND_TRIANGLE
               ? (tri_area > 0.0 ? (float)(tri_power * e->area / tri_area) : 0.0f)
               : e->power;
  }
  iris_status st = iris_distrib1d_create(out, w, n, err);
  free(w);
  return st;
}

bool iris_lights_sample_emission(const iris_lights *lights, float u_select, float u0, float u1,
                                 float u2, float u3, iris_photon_emission *e) {
  return iris_lights_sample_emission_with(lights, &lights->select, u_select, u0, u1, u2, u3, e);
}

bool iris_lights_sample_emission_with(const iris_lights *lights, const iris_distrib1d *select,
                                      float u_select, float u0, float u1, float u2, float u3,
                                      iris_photon_emission *e) {
  if (lights->count == 0 || select->count != lights->count) return false;
  float pmf, u_side;
  uint32_t i = (uint32_t)iris_distrib1d_sample(select, u_select, &pmf, &u_side);
  if (!(pmf > 0.0f)) return false;
  const iris_light_entry *le = &lights->entries[i];
  memset(e, 0, sizeof *e);
  e->light = i;
  e->prim = le->prim;
  switch (le->kind) {
    case IRIS_LIGHT_KIND_TRIANGLE: {
      float b0, b1;
      iris_sample_uniform_triangle(u0, u1, &b0, &b1);
      iris_interaction si;
      iris_accel_surface_at(lights->accel, le->prim, b1, 1.0f - b0 - b1, &si);
      float p_side = 1.0f;
      iris_vec3 n = si.ng;
      if (le->two_sided) {
        p_side = 0.5f;
        if (u_side >= 0.5f) n = iris_neg(n);
      }
      iris_frame f = iris_frame_from_normal(n);
      iris_vec3 local = iris_sample_cosine_hemisphere(u2, u3);
      e->dir = iris_normalize(iris_frame_to_world(&f, local));
      e->n = n;
      e->p = iris_offset_origin(si.p, si.ng, e->dir);
      e->pdf_pos = 1.0f / le->area;
      e->pdf_dir = p_side * iris_sample_cosine_hemisphere_pdf(local.z);
      /* Le cos / (pmf pdf_pos pdf_dir) = Le pi area / (pmf p_side). */
      iris_vec3 L = surface_emission(lights, material_of(lights->scene, si.material), &si);
      e->power = iris_scale(L, IRIS_PI * le->area / (pmf * p_side));
      return true;
    }
    case IRIS_LIGHT_KIND_POINT:
    case IRIS_LIGHT_KIND_SPOT: {
      const iris_light *l = &lights->scene->lights[le->prim];
      e->p = iris_v3_load(l->position);
      e->pdf_pos = 1.0f;
      if (le->kind == IRIS_LIGHT_KIND_SPOT) {
        float cos_max = cosf(l->outer_cone);
        iris_frame f = iris_frame_from_normal(iris_normalize(iris_v3_load(l->direction)));
        iris_vec3 local = iris_sample_uniform_cone(u2, u3, cos_max);
        e->dir = iris_normalize(iris_frame_to_world(&f, local));
        e->pdf_dir = iris_sample_uniform_cone_pdf(local.z, cos_max);
        if (!(e->pdf_dir > 0.0f)) return false;
        e->power = iris_scale(le->radiance, spot_falloff(l, e->dir) / (pmf * e->pdf_dir));
      } else {
        e->dir = iris_sample_uniform_sphere(u2, u3);
        e->pdf_dir = iris_sample_uniform_sphere_pdf();
        e->power = iris_scale(le->radiance, 1.0f / (pmf * e->pdf_dir));
      }
      e->n = e->dir;
      return true;
    }
    case IRIS_LIGHT_KIND_DIRECTIONAL:
    case IRIS_LIGHT_KIND_ENVIRONMENT:
    default: {
      float r = lights->radius;
      iris_vec3 radiance = le->radiance;
      if (le->kind == IRIS_LIGHT_KIND_DIRECTIONAL) {
        e->dir = iris_normalize(iris_v3_load(lights->scene->lights[le->prim].direction));
        e->pdf_dir = 1.0f;
      } else if (lights->envmap) { /* photons travel against the sampled incident direction */
        iris_vec3 wi;
        if (!iris_envmap_sample(lights->envmap, u2, u3, &wi, &e->pdf_dir, &radiance)) return false;
        e->dir = iris_neg(wi);
      } else {
        e->dir = iris_sample_uniform_sphere(u2, u3);
        e->pdf_dir = iris_sample_uniform_sphere_pdf();
      }
      /* A disk of the bounding sphere's radius, facing along dir, behind the scene. */
      iris_frame f = iris_frame_from_normal(e->dir);
      float x, y;
      iris_sample_concentric_disk(u0, u1, &x, &y);
      e->p = iris_add(iris_madd(lights->center, e->dir, -r),
                      iris_add(iris_scale(f.s, x * r), iris_scale(f.t, y * r)));
      e->n = e->dir;
      e->pdf_pos = 1.0f / (IRIS_PI * r * r);
      e->power = iris_scale(radiance, 1.0f / (pmf * e->pdf_pos * e->pdf_dir));
      return true;
    }
  }
}
