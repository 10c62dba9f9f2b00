/* The path tracer; see integrator.h and docs/rendering.md. */
#include "renderer/integrator.h"
#include "renderer/light_trace.h"

#include <string.h>

#include "renderer/normal_map.h"
#include "renderer/vcache.h"

static const char *const METHOD_NAMES[IRIS_METHOD_COUNT] = {"bsdf", "nee", "mis", "guided",
                                                             "guided-nee", "auto"};

const char *iris_method_name(iris_method method) {
  return (unsigned)method < IRIS_METHOD_COUNT ? METHOD_NAMES[method] : "unknown";
}

bool iris_method_parse(const char *name, iris_method *out) {
  for (int i = 0; i < IRIS_METHOD_COUNT; i++)
    if (strcmp(name, METHOD_NAMES[i]) == 0) {
      *out = (iris_method)i;
      return true;
    }
  return false;
}

bool iris_method_uses_nee(iris_method m) {
  return m == IRIS_METHOD_NEE || m == IRIS_METHOD_MIS || m == IRIS_METHOD_GUIDED_NEE;
}
bool iris_method_uses_guiding(iris_method m) {
  return m == IRIS_METHOD_GUIDED || m == IRIS_METHOD_GUIDED_NEE;
}
/* Methods that weight emitters hit by sampled directions against light sampling. */
static bool method_uses_mis(iris_method m) {
  return m == IRIS_METHOD_MIS || m == IRIS_METHOD_GUIDED_NEE;
}

iris_integrator iris_integrator_default(const iris_scene *scene, const iris_accel *accel,
                                        const iris_lights *lights, const iris_textures *textures) {
  iris_integrator it;
  memset(&it, 0, sizeof it);
  it.scene = scene;
  it.accel = accel;
  it.lights = lights;
  it.textures = textures;
  it.method = IRIS_METHOD_MIS;
  it.sampler = IRIS_SAMPLER_SOBOL;
  it.max_depth = IRIS_DEFAULT_MAX_DEPTH;
  it.rr_depth = IRIS_DEFAULT_RR_DEPTH;
  it.default_material = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  return it;
}

/* KHR_materials_volume: a segment that ends on the back of a surface whose
 * material attenuates ran inside it (closed meshes), and its throughput is
 * exp(-sigma d), sigma = -ln(attenuation_color) / attenuation_distance. */
iris_vec3 iris_integrator_volume_transmittance(const iris_integrator *it, const iris_interaction *si, float d) {
  if (si->material < 0 || (size_t)si->material >= it->scene->material_count) return iris_v3(1, 1, 1);
  const iris_material *m = &it->scene->materials[si->material];
  if (!(m->attenuation_distance > 0.0f)) return iris_v3(1, 1, 1);
  float t[3];
  for (int k = 0; k < 3; k++)
    t[k] = m->attenuation_color[k] > 0.0f ? powf(m->attenuation_color[k], d / m->attenuation_distance) : 0.0f;
  return iris_v3(t[0], t[1], t[2]);
}

/* KHR_materials_clearcoat / _sheen values at the point (textures applied) into
 * the BSDF; the coat normal is the unmapped shading normal or the coat's own
 * normal map, expressed in the shading frame. Only for materials that have them. */
static bool shade_layers(const iris_integrator *it, const iris_material *m, const iris_interaction *si,
                         iris_shading_point *sp) {
  float t[4];
  bool coat_mapped = false;
  if (m->clearcoat > 0.0f) {
    float cc = m->clearcoat, ccr = m->clearcoat_roughness;
    if (m->clearcoat_texture >= 0) {
      iris_texture_sample(it->textures, m->clearcoat_texture, si->uv, si->uv1, false, t);
      cc *= t[0];
    }
    if (m->clearcoat_roughness_texture >= 0) {
      iris_texture_sample(it->textures, m->clearcoat_roughness_texture, si->uv, si->uv1, false, t);
      ccr *= t[1];
    }
    iris_vec3 cn = si->ns;
    coat_mapped = m->clearcoat_normal_texture >= 0 && si->has_tangent;
    if (coat_mapped) {
      iris_texture_sample(it->textures, m->clearcoat_normal_texture, si->uv, si->uv1, false, t);
      cn = iris_normal_map_apply(si->tangent, si->bitangent, si->ns, t, m->clearcoat_normal_scale);
    }
    if (iris_dot(sp->si.ns, si->ns) < 0.0f) cn = iris_neg(cn); /* flipped with the shading normal */
    if (coat_mapped) { /* the valid-reflection rule for the coat's own normal too, as Cycles */
      bool back = iris_dot(sp->wo, sp->si.ng) < 0.0f;
      iris_vec3 ngw = back ? iris_neg(sp->si.ng) : sp->si.ng;
      cn = iris_normal_make_valid(ngw, sp->wo, back ? iris_neg(cn) : cn);
      if (back) cn = iris_neg(cn);
    }
    sp->bsdf.clearcoat = cc;
    sp->bsdf.clearcoat_roughness = ccr;
    sp->bsdf.coat_n = iris_frame_to_local(&sp->frame, cn);
  }
  iris_vec3 sheen = iris_v3_load(m->sheen_color);
  if (iris_max3(sheen) > 0.0f) {
    float sr = m->sheen_roughness;
    if (m->sheen_color_texture >= 0) {
      iris_texture_sample(it->textures, m->sheen_color_texture, si->uv, si->uv1, true, t);
      sheen = iris_mul(sheen, iris_v3(t[0], t[1], t[2]));
    }
    if (m->sheen_roughness_texture >= 0) {
      iris_texture_sample(it->textures, m->sheen_roughness_texture, si->uv, si->uv1, false, t);
      sr *= t[3];
    }
    sp->bsdf.sheen_color = sheen;
    sp->bsdf.sheen_roughness = sr;
  }
  sp->lobes = iris_bsdf_lobes(&sp->bsdf);
  sp->delta = iris_bsdf_is_delta(&sp->bsdf);
  return coat_mapped;
}

/* KHR_materials_transmission / _specular textures at the point, into the BSDF
 * before its lobes are decided: transmission x R, specular x A (linear),
 * specular colour x RGB (sRGB). A factor of 0 needs no lookup; the specular
 * pair packed in one image with one placement (the extension's intended
 * layout: one scene texture) is one lookup, as sRGB decoding leaves alpha
 * linear. Only for materials that have one of these textures. */
__attribute__((noinline)) /* kept out of iris_integrator_shade: materials without them pay one branch */
static void shade_spec_trans(const iris_integrator *it, const iris_material *m, const iris_interaction *si,
                             iris_bsdf *b) {
  float t[4], c[4];
  bool have_c = false;
  if (m->transmission_texture >= 0 && b->transmission > 0.0f) {
    iris_texture_sample(it->textures, m->transmission_texture, si->uv, si->uv1, false, t);
    b->transmission *= iris_clampf(t[0], 0.0f, 1.0f);
  }
  if (m->specular_texture >= 0 && b->specular > 0.0f) {
    if (m->specular_texture == m->specular_color_texture) {
      iris_texture_sample(it->textures, m->specular_color_texture, si->uv, si->uv1, true, c);
      have_c = true;
      b->specular *= fmaxf(c[3], 0.0f);
    } else {
      iris_texture_sample(it->textures, m->specular_texture, si->uv, si->uv1, false, t);
      b->specular *= fmaxf(t[3], 0.0f);
    }
  }
  if (m->specular_color_texture >= 0 && iris_max3(b->specular_color) > 0.0f) {
    if (!have_c) iris_texture_sample(it->textures, m->specular_color_texture, si->uv, si->uv1, true, c);
    b->specular_color = iris_mul(b->specular_color, iris_v3(fmaxf(c[0], 0.0f), fmaxf(c[1], 0.0f), fmaxf(c[2], 0.0f)));
  }
}

/* KHR_materials_anisotropy at the point: strength x texture B, and the direction
 * (texture RG in [-1, 1], else the tangent) turned counter-clockwise by the
 * material's rotation in the mesh's (tangent, bitangent) plane, then expressed in
 * the shading frame. Called only for anisotropic materials on meshes with tangents. */
static void shade_anisotropy(const iris_integrator *it, const iris_material *m, const iris_interaction *si,
                             iris_shading_point *sp) {
  float strength = m->anisotropy, dx = 1.0f, dy = 0.0f;
  if (m->anisotropy_texture >= 0) {
    float t[4];
    iris_texture_sample(it->textures, m->anisotropy_texture, si->uv, si->uv1, false, t);
    dx = 2.0f * t[0] - 1.0f, dy = 2.0f * t[1] - 1.0f;
    strength *= t[2];
    if (!(dx * dx + dy * dy > 1e-12f)) dx = 1.0f, dy = 0.0f;
  }
  float c = cosf(m->anisotropy_rotation), s = sinf(m->anisotropy_rotation);
  iris_vec3 dir = iris_add(iris_scale(si->tangent, c * dx - s * dy), iris_scale(si->bitangent, s * dx + c * dy));
  iris_vec3 l = iris_frame_to_local(&sp->frame, dir);
  float len = sqrtf(l.x * l.x + l.y * l.y);
  if (!(strength > 0.0f) || !(len > 1e-6f) || !isfinite(len)) return; /* along the normal: isotropic */
  sp->bsdf.anisotropy = iris_clampf(strength, 0.0f, 1.0f);
  sp->bsdf.aniso_dir[0] = l.x / len;
  sp->bsdf.aniso_dir[1] = l.y / len;
  sp->lobes = iris_bsdf_lobes(&sp->bsdf);
  sp->delta = iris_bsdf_is_delta(&sp->bsdf);
}

void iris_integrator_shade(const iris_integrator *it, const iris_interaction *si, iris_vec3 wo,
                           int depth, iris_shading_point *sp) {
  const iris_material *m = si->material >= 0 && (size_t)si->material < it->scene->material_count
                               ? &it->scene->materials[si->material]
                               : &it->default_material;
  iris_vec3 color = iris_mul(iris_v3_load(m->color), si->color);
  if (m->color_texture >= 0) {
    float t[4];
    iris_texture_sample(it->textures, m->color_texture, si->uv, si->uv1, true, t);
    color = iris_mul(color, iris_v3(t[0], t[1], t[2]));
  }
  float roughness = m->roughness, metallic = m->metallic;
  if (m->type == IRIS_MATERIAL_GLTF && m->metallic_roughness_texture >= 0) {
    float t[4];
    iris_texture_sample(it->textures, m->metallic_roughness_texture, si->uv, si->uv1, false, t);
    roughness *= t[1];
    metallic *= t[2];
  }
  sp->si = *si;
  bool mapped = false;
  if (m->normal_texture >= 0 && si->has_tangent) { /* docs/rendering.md, "Normal maps" */
    float t[4];
    iris_texture_sample(it->textures, m->normal_texture, si->uv, si->uv1, false, t);
    iris_vec3 n = iris_normal_map_apply(si->tangent, si->bitangent, si->ns, t, m->normal_scale);
    /* seen from wo's side, as the BSDF will see it */
    bool back = iris_dot(wo, si->ng) < 0.0f;
    iris_vec3 ngw = back ? iris_neg(si->ng) : si->ng;
    n = iris_normal_make_valid(ngw, wo, back ? iris_neg(n) : n);
    sp->si.ns = back ? iris_neg(n) : n;
    mapped = true;
  }
  sp->bsdf = iris_bsdf_from_material(m, color, roughness, metallic);
  /* any of the three >= 0 (-1 = none): their AND is negative only when all are */
  if ((m->transmission_texture & m->specular_texture & m->specular_color_texture) >= 0 &&
      m->type == IRIS_MATERIAL_GLTF)
    shade_spec_trans(it, m, si, &sp->bsdf);
  sp->lobes = iris_bsdf_lobes(&sp->bsdf);
  sp->delta = iris_bsdf_is_delta(&sp->bsdf);
  sp->depth = depth;
  sp->wo = wo;
  /* Two-sided shading for everything that does not transmit: put both normals
   * on wo's side. Transmissive BSDFs keep the front (outward) normal, so that
   * wo.z < 0 means "inside". */
  if (!(sp->lobes & IRIS_LOBE_TRANSMISSION) && iris_dot(wo, si->ng) < 0.0f) {
    sp->si.ng = iris_neg(si->ng);
    sp->si.ns = iris_neg(si->ns);
  }
  sp->frame = iris_frame_from_normal(sp->si.ns);
  sp->wo_local = iris_frame_to_local(&sp->frame, wo);
  if (m->type == IRIS_MATERIAL_GLTF) {
    if (m->clearcoat > 0.0f || iris_max3(iris_v3_load(m->sheen_color)) > 0.0f)
      mapped = shade_layers(it, m, si, sp) || mapped; /* a coat normal map folds too */
    if (m->anisotropy > 0.0f && si->has_tangent) shade_anisotropy(it, m, si, sp);
  }
  sp->fold = mapped && !(sp->lobes & IRIS_LOBE_TRANSMISSION);
}

/* A direction that leaves a non-transmissive surface below its geometric
 * plane would reflect through the surface (shading normals): both sampling
 * strategies reject it alike, so they estimate the same integral. */
static bool direction_allowed(const iris_shading_point *sp, iris_vec3 wi) {
  if (sp->lobes & IRIS_LOBE_TRANSMISSION) return true;
  return iris_dot(wi, sp->si.ng) > 0.0f;
}

/* The mirror image of w about the geometric plane of the shading point. */
static iris_vec3 fold_mirror(const iris_shading_point *sp, iris_vec3 w) {
  return iris_sub(w, iris_scale(sp->si.ng, 2.0f * iris_dot(w, sp->si.ng)));
}

/* |cos(ns, w)| below which a folded value is not divided by it (a set of
 * directions of measure ~1e-7 sr, which then get no light). */
#define FOLD_MIN_COS 1e-7f

/* The mirror term of the folded BSDF at a world direction wi above Ng: the
 * local M wi, and whether the BSDF can be non-zero there (a reflect-only BSDF
 * is zero below its shading plane and, with a coat, below the coat's plane),
 * so that the common case -- M wi below both -- costs no evaluation. */
static bool fold_term(const iris_shading_point *sp, iris_vec3 wi, iris_vec3 *ml) {
  *ml = iris_frame_to_local(&sp->frame, fold_mirror(sp, wi));
  if (ml->z > 0.0f) return true;
  return sp->bsdf.clearcoat > 0.0f && iris_dot(*ml, sp->bsdf.coat_n) > 0.0f;
}

/* A BSDF sample at a folded point into the folded BSDF's sample (out holds the
 * unfolded one). Kept out of line: only normal-mapped points come here. */
__attribute__((noinline)) static bool fold_sample(const iris_shading_point *sp, const struct iris_bsdf_sample *sample,
                                                  iris_direction_sample *out) {
  const struct iris_bsdf_sample bs = *sample;
  /* docs/rendering.md, "Normal maps": the folded BSDF. A non-delta sample's
   * f and pdf are the BSDF's value and density at bs.wi (iris_bsdf_sample's
   * contract), so only the other term of each sum is evaluated. */
  if (iris_dot(out->wi, sp->si.ng) < 0.0f) { /* mirrored: bs.wi is the mirror term */
    iris_vec3 up = iris_normalize(fold_mirror(sp, out->wi));
    iris_vec3 ul = iris_frame_to_local(&sp->frame, up);
    float c0 = fabsf(bs.wi.z), c1 = fabsf(ul.z);
    if (!(c1 > FOLD_MIN_COS)) return false;
    out->wi = up;
    out->f = iris_scale(bs.f, c0 / c1); /* a delta lobe's f holds 1/|cos|: the same rule */
    if (!out->delta) {
      out->f = iris_add(out->f, iris_bsdf_eval(&sp->bsdf, sp->wo_local, ul));
      out->pdf = bs.pdf + iris_bsdf_pdf(&sp->bsdf, sp->wo_local, ul);
    }
  } else if (!out->delta) {
    iris_vec3 ml;
    if (fold_term(sp, out->wi, &ml)) {
      float c = fabsf(bs.wi.z);
      if (!(c > FOLD_MIN_COS)) return false;
      out->f = iris_add(out->f, iris_scale(iris_bsdf_eval(&sp->bsdf, sp->wo_local, ml), fabsf(ml.z) / c));
      out->pdf += iris_bsdf_pdf(&sp->bsdf, sp->wo_local, ml);
    }
  }
  return true;
}

/* The body of both entry points below, inlined into each (the path loop calls the
 * first once per vertex). */
static inline bool sample_bsdf(const iris_shading_point *sp, float u_lobe, float u0, float u1,
                               iris_direction_sample *out) {
  struct iris_bsdf_sample bs;
  if (!iris_bsdf_sample(&sp->bsdf, sp->wo_local, u_lobe, u0, u1, &bs)) return false;
  if (!(bs.pdf > 0.0f)) return false;
  out->wi = iris_normalize(iris_frame_to_world(&sp->frame, bs.wi));
  out->f = bs.f;
  out->pdf = bs.pdf;
  out->lobe = bs.lobe;
  out->delta = (bs.lobe & IRIS_LOBE_DELTA) != 0;
  return sp->fold ? fold_sample(sp, &bs, out) : true;
}

bool iris_integrator_sample_bsdf(const iris_shading_point *sp, iris_sampler *rng,
                                 iris_direction_sample *out) {
  float u_lobe = iris_sampler_slot(rng, IRIS_SLOT_LOBE);
  float u0, u1;
  iris_sampler_slot2(rng, IRIS_SLOT_DIRECTION, &u0, &u1);
  return sample_bsdf(sp, u_lobe, u0, u1, out);
}

bool iris_integrator_sample_bsdf_u(const iris_shading_point *sp, float u_lobe, float u0, float u1,
                                   iris_direction_sample *out) {
  return sample_bsdf(sp, u_lobe, u0, u1, out);
}

/* The body of iris_integrator_bsdf_eval, inlined into light sampling. */
static inline iris_vec3 bsdf_eval(const iris_shading_point *sp, iris_vec3 wi) {
  if (!direction_allowed(sp, wi)) return iris_v3(0, 0, 0);
  iris_vec3 wl = iris_frame_to_local(&sp->frame, wi);
  iris_vec3 f = iris_bsdf_eval(&sp->bsdf, sp->wo_local, wl);
  iris_vec3 ml;
  if (!sp->fold || !fold_term(sp, wi, &ml)) return f;
  float c = fabsf(wl.z);
  if (!(c > FOLD_MIN_COS)) return iris_v3(0, 0, 0);
  return iris_add(f, iris_scale(iris_bsdf_eval(&sp->bsdf, sp->wo_local, ml), fabsf(ml.z) / c));
}

iris_vec3 iris_integrator_bsdf_eval(const iris_shading_point *sp, iris_vec3 wi) { return bsdf_eval(sp, wi); }

float iris_integrator_bsdf_pdf(const iris_shading_point *sp, iris_vec3 wi) {
  if (!sp->fold) return iris_bsdf_pdf(&sp->bsdf, sp->wo_local, iris_frame_to_local(&sp->frame, wi));
  if (!direction_allowed(sp, wi)) return 0.0f;
  float p = iris_bsdf_pdf(&sp->bsdf, sp->wo_local, iris_frame_to_local(&sp->frame, wi));
  iris_vec3 ml;
  if (fold_term(sp, wi, &ml)) p += iris_bsdf_pdf(&sp->bsdf, sp->wo_local, ml);
  return p;
}

void iris_integrator_prepare_direction(const iris_integrator *it, iris_shading_point *sp) {
  if (iris_method_uses_guiding(it->method) && it->guide.prepare) it->guide.prepare(it->guide.ctx, sp);
}

bool iris_integrator_sample_direction(const iris_integrator *it, const iris_shading_point *sp,
                                      iris_sampler *rng, iris_direction_sample *out) {
  if (iris_method_uses_guiding(it->method) && it->guide.sample)
    return it->guide.sample(it->guide.ctx, sp, rng, out);
  return iris_integrator_sample_bsdf(sp, rng, out);
}

float iris_integrator_direction_pdf(const iris_integrator *it, const iris_shading_point *sp,
                                    iris_vec3 wi) {
  if (iris_method_uses_guiding(it->method) && it->guide.pdf)
    return it->guide.pdf(it->guide.ctx, sp, wi);
  return iris_integrator_bsdf_pdf(sp, wi);
}

/* The normal light selection is told at a shading point (lights.h): the
 * geometric normal on wo's side for BSDFs that only reflect, since
 * direction_allowed refuses every direction below that plane whatever the
 * shading normal or a coat's normal say, so a light wholly below it gives
 * nothing; the zero vector (any direction) for transmissive BSDFs. */
static iris_vec3 light_normal(const iris_shading_point *sp) {
  return (sp->lobes & IRIS_LOBE_TRANSMISSION) ? iris_v3(0, 0, 0) : sp->si.ng;
}

/* Adjoint-driven Russian roulette: paths whose expected contribution is at
 * least 1/RR_WINDOW of the pixel estimate always survive (Vorba & Krivanek
 * 2016 use a window of width 5: lower end 2/(1+5) = 1/3 of the estimate). */
#define RR_WINDOW 3.0f

/* Power heuristic (beta = 2), Veach 1997 eq. 9.13, for one sample of each. */
static float power_heuristic(float pa, float pb) {
  if (!(pa > 0.0f)) return 0.0f;
  if (!isfinite(pa)) return 1.0f;
  float a = pa * pa, b = pb * pb;
  return a / (a + b);
}

/* The power heuristic over three strategies (the camera's two and light
 * tracing's, at a reflector light paths start from), for the first. */
static float power3(float pa, float pb, float pc) {
  if (!(pa > 0.0f)) return 0.0f;
  if (!isfinite(pa)) return 1.0f;
  float a = pa * pa;
  return a / (a + pb * pb + pc * pc);
}

/* Light tracing's density for the camera's path through reflector y (its
 * shading point, seen from x0) with light from wi, in the units of the
 * camera's light-sampling density there, per unit of that density: K (from
 * x0, set where y was hit) times the density with which y's BSDF, lit from
 * wi, reflects towards x0 (light_trace.c draws wout so). */
static float light_trace_ratio(const iris_shading_point *y, float K, iris_vec3 wi) {
  if (!(K > 0.0f)) return 0.0f;
  return K * iris_bsdf_pdf(&y->bsdf, iris_frame_to_local(&y->frame, wi), y->wo_local);
}

/* Direct light at a shading point by light sampling (NEE), MIS-weighted
 * against the path's direction sampler when `mis`. The light was chosen at
 * the hit with the vertex's IRIS_SLOT_LIGHT_CHOICE (`choice`, see the path loop). */
static iris_vec3 sample_direct(const iris_integrator *it, const iris_shading_point *sp,
                               const iris_light_choice *choice, const iris_sampler *rng, bool mis,
                               float p_light, iris_path_stats *stats, int8_t *outcome, float *value,
                               const iris_vcache_params *vp, float sky_g, float lt_K) {
  float u0, u1;
  iris_sampler_slot2(rng, IRIS_SLOT_LIGHT_POS, &u0, &u1);
  iris_light_sample ls;
  int guided = -1; /* the map sampled by the guide (its sky visibility), or not (-1) */
  if (it->guide.sample_environment && iris_method_uses_guiding(it->method) &&
      iris_lights_choice_is_environment_map(it->lights, choice)) {
    iris_vec3 wi;
    float pdf, s, t;
    guided = it->guide.sample_environment(it->guide.ctx, it->lights->envmap, sp, u0, u1, &wi, &pdf, &s, &t);
    if (guided == 0 || (guided > 0 && !iris_lights_environment_sample_at(it->lights, choice, sp->si.p, wi, pdf, s,
                                                                          t, &ls)))
      return iris_v3(0, 0, 0);
  }
  if (guided < 0 && !iris_lights_sample_choice_lazy(it->lights, sp->si.p, choice, u0, u1, &ls))
    return iris_v3(0, 0, 0);
  /* the map's light through a window at a vertex the connections reach:
   * shared with them by MIS (vcache.h), the camera's weight `keep` */
  float keep = 1.0f;
  if (sky_g > 0.0f && !isfinite(ls.dist) && iris_lights_choice_is_environment_map(it->lights, choice)) {
    keep = iris_vcache_sky_keep(vp, sp->si.p, ls.wi, sp->si.ng, sky_g);
    /* a small share is traced only sometimes, weighted back (no shadow ray
     * where the connections carry nearly all of it) */
    if (keep < IRIS_VCACHE_SKY_KEEP) {
      if (!(keep > 0.0f) || iris_sampler_slot(rng, IRIS_SLOT_SKY_SHARE) * IRIS_VCACHE_SKY_KEEP >= keep)
        return iris_v3(0, 0, 0);
      keep = IRIS_VCACHE_SKY_KEEP;
    }
  }
  iris_vec3 f = bsdf_eval(sp, ls.wi);
  if (f.x <= 0.0f && f.y <= 0.0f && f.z <= 0.0f) return iris_v3(0, 0, 0);
  iris_vec3 wl = iris_frame_to_local(&sp->frame, ls.wi);
  iris_ray shadow;
  if (isfinite(ls.dist) && !ls.delta) {
    shadow = iris_spawn_ray_to(sp->si.p, sp->si.ng, ls.p, ls.n);
  } else {
    shadow = iris_spawn_ray(&sp->si, ls.wi);
    if (isfinite(ls.dist)) shadow.tmax = ls.dist * (1.0f - 1e-5f);
  }
  stats->shadow_rays++;
  *outcome = 0;
  if (iris_accel_occluded(it->accel, &shadow)) return iris_v3(0, 0, 0);
  iris_lights_sample_radiance(it->lights, &ls); /* an environment map's lookup, only now */
  if (iris_max3(ls.L) > 0.0f) *outcome = 1;
  /* light sampling ran with probability p_light (1 unless the guide makes it
   * optional here): its density is p_light ls.pdf, for the weight too */
  const float pdf = p_light * ls.pdf;
  const iris_vec3 fl = iris_mul(f, ls.L);
  *value = iris_avg3(fl) * fabsf(wl.z) / pdf;
  float w = 1.0f;
  if (lt_K > 0.0f) { /* with light tracing (a delta light: the three share its discrete choice) */
    const float pl = ls.delta ? 1.0f : pdf;
    w = power3(pl, ls.delta ? 0.0f : iris_integrator_direction_pdf(it, sp, ls.wi), pl * light_trace_ratio(sp, lt_K, ls.wi));
  } else if (mis && !ls.delta) {
    w = power_heuristic(pdf, iris_integrator_direction_pdf(it, sp, ls.wi));
  }
  return iris_scale(fl, fabsf(wl.z) * w * keep / pdf);
}

static iris_vec3 trace_path(const iris_integrator *it, iris_ray ray, iris_sampler *rng,
                            iris_path_stats *stats, iris_path_record *rec) {
  iris_path_vertex *last = NULL; /* the recorded vertex the current ray left from */
  const bool nee = iris_method_uses_nee(it->method) && it->lights->count > 0;
  const bool mis = nee && method_uses_mis(it->method);
  const bool nee_env = nee && it->lights->envmap;
  const bool guide_prefetch = iris_method_uses_guiding(it->method) && it->guide.prefetch;
  /* light sampling of the map guided per vertex: escaping rays weigh against
   * the density at the vertex they left (its guide state kept in prev_guide) */
  const bool env_guided = nee_env && iris_method_uses_guiding(it->method) && it->guide.environment_scale;
  /* The map's tables are loaded ahead only where the map's own sampling is
   * the light sample's: with sky visibility most draw from regions and
   * windows, and the row search of the hint cost more than it hid
   * (sky-room and its glazed, pane and corner variants: render passes
   * 0.95-0.98x without it; mis on sky-room 1.05x slower without it). */
  const bool env_prefetch = nee_env && !env_guided;
  iris_guide_vertex prev_guide;
  iris_vec3 L = iris_v3(0, 0, 0), beta = iris_v3(1, 1, 1);
  const bool adjoint_rr = iris_method_uses_guiding(it->method) && it->guide.radiance_estimate;
  float pixel_estimate = 0.0f; /* adjoint-driven RR: L + est at the first estimated vertex */
  bool prev_delta = true; /* the camera "bounce" counts as delta: emitters seen directly count */
  bool aimed = false;     /* the last non-delta vertex aimed at a lamp (iris_direction_sample) */
  /* light sampling made optional by the guide (iris_direction_sampler.light_probability) */
  const bool light_optional = nee && iris_method_uses_guiding(it->method) && it->guide.light_probability;
  float prev_light = 1.0f; /* the probability with which the vertex the ray left sampled a light */
  float prev_env_q = 1.0f;  /* ... and, at a vertex that shares the sky with the connections, the map */
  float prev_pdf = 0.0f;
  iris_vec3 prev_p = ray.o, prev_n = iris_v3(0, 0, 0);
  stats->paths++;
  /* Connections to a light-vertex cache (vcache.h): only image paths (not
   * training's); the state says whether the path so far is one the
   * connections make, whose light the camera then leaves out (the door's)
   * or shares with them by MIS (the sky's). */
  const iris_vcache_pool *vpool = it->vcache && !rec ? iris_vcache_get(it->vcache, rng->sample) : NULL;
  const iris_vcache_params *vp = vpool ? iris_vcache_settings(it->vcache) : NULL;
  int vc_phase = 0, vc_k = 0; /* 0: every vertex so far in region A; 1: k >= 1 there, then only B; 2: other */
  iris_vec3 vc_prev = {0, 0, 0}, vc_last = {0, 0, 0}; /* x_{k-1}, x_k */
  bool vc_prev_nd = false, vc_last_nd = false, vc_last_plain = false;
  bool vc_made = false;       /* phase 1 and a path the connections make */
  /* with the sky: at this vertex, and at the one the ray left, the camera's
   * part of the MIS ratio with the connections (d^2 / (p_dir |cos_in|),
   * vcache.h) where it shares the map's light through a window with them,
   * 0 where it does not */
  float sky_g = 0.0f, prev_sky_g = 0.0f;
  iris_vec3 L_connect = iris_v3(0, 0, 0);
  /* Light tracing (light_trace.h): a path camera -> x0 -> y -> light with
   * y a reflector light paths start from is light tracing's too. At x0 the
   * camera's density of the hit (lt_W0) and of its bounce (lt_px0); at y,
   * lt_K, the ratio of light tracing's density to the camera's for that path
   * but for the parts that depend on the light's direction (light_trace_ratio). */
  const iris_light_trace *lt = it->light_trace && !rec && mis ? it->light_trace : NULL;
  float lt_W0 = 0.0f, lt_px0 = 0.0f, lt_K = 0.0f, prev_lt_K = 0.0f;
  iris_vec3 lt_ng0 = {0, 0, 0};
  bool lt_x0 = false; /* x0 not delta, nor its bounce */
  iris_shading_point lt_y; /* y, while prev_lt_K > 0 */
  /* The second kind (light through clear glass and mirrors): delta vertices
   * since x0 while the path may be one of its light paths, -1 when not. */
  int lt_chain = -1, lt_refr = 0; /* ... and the refractions among them */
  for (int bounce = 0;; bounce++) {
    iris_sampler_set_bounce(rng, bounce);
    /* The map's tables load while the ray is traced and the hit shaded
     * (sample_direct reads them): the guide entry now, the CDF line after. */
    float env_u0 = 0.0f, env_u1 = 0.0f;
    if (env_prefetch) {
      iris_sampler_slot2(rng, IRIS_SLOT_LIGHT_POS, &env_u0, &env_u1);
      iris_lights_prefetch_environment(it->lights, env_u0, env_u1, 0);
    }
    iris_hit hit;
    stats->rays++;
    if (!iris_accel_intersect(it->accel, &ray, &hit)) {
      float sky_keep = 1.0f; /* the camera's MIS weight against the connections (vcache.h) */
      if (prev_sky_g > 0.0f) { /* prev_n: a plain vertex's geometric normal */
        sky_keep = iris_vcache_sky_keep(vp, prev_p, ray.d, prev_n, prev_sky_g);
        if (!(sky_keep > 0.0f)) break;
      }
      /* the sun through glass or off a mirror seen from x0: the light paths' (light_trace.h) */
      if (lt_chain >= 1 && prev_delta && lt_refr % 2 == 0 &&
          iris_envmap_pdf(it->lights->envmap, iris_normalize(ray.d)) >= lt->sun_pdf)
        break;
      float env_pdf = 0.0f, st[2];
      iris_vec3 le = iris_lights_environment_pdf(it->lights, ray.d, prev_p, prev_n,
                                                 !prev_delta && mis ? &env_pdf : NULL, st);
      if (le.x > 0.0f || le.y > 0.0f || le.z > 0.0f) {
        if (env_guided && !prev_delta && mis && bounce > 0) { /* the map's coordinates of ray.d: st */
          float add;
          env_pdf *= it->guide.environment_scale(it->guide.ctx, it->lights->envmap, &prev_guide, iris_normalize(ray.d),
                                                 st[0], st[1], &add);
          if (add > 0.0f) /* the sky's windows: their density times the map's choice */
            env_pdf += add * iris_lights_select_pmf_at(it->lights, prev_p, prev_n, (uint32_t)it->lights->environment);
        }
        env_pdf *= prev_light * prev_env_q;
        float w = 1.0f;
        if (!prev_delta && prev_lt_K > 0.0f)
          w = power3(prev_pdf, env_pdf, env_pdf * light_trace_ratio(&lt_y, prev_lt_K, iris_normalize(ray.d)));
        else if (!prev_delta && nee)
          w = mis ? power_heuristic(prev_pdf, env_pdf) : 0.0f;
        L = iris_add(L, iris_scale(iris_mul(beta, le), w * sky_keep));
        if (last) last->miss = iris_scale(iris_mul(beta, le), 1.0f - w);
      }
      break;
    }
    if (env_prefetch) iris_lights_prefetch_environment(it->lights, env_u0, env_u1, 1);
    if (guide_prefetch) it->guide.prefetch(it->guide.ctx, iris_madd(ray.o, ray.d, hit.t));
    iris_interaction si;
    iris_accel_interaction(it->accel, ray.d, &hit, &si);
    if (!si.front) beta = iris_mul(beta, iris_integrator_volume_transmittance(it, &si, hit.t * iris_length(ray.d)));
    iris_vec3 le = iris_lights_emitted(it->lights, &si, ray.d);
    if (le.x > 0.0f || le.y > 0.0f || le.z > 0.0f) {
      float w = 1.0f;
      if (!prev_delta && prev_lt_K > 0.0f) {
        const float pt = prev_light * iris_lights_pdf_triangle(it->lights, prev_p, prev_n, &si);
        w = power3(prev_pdf, pt, pt * light_trace_ratio(&lt_y, prev_lt_K, iris_normalize(ray.d)));
      } else if (!prev_delta && nee) {
        w = mis ? power_heuristic(prev_pdf, prev_light * iris_lights_pdf_triangle(it->lights, prev_p, prev_n, &si))
                : 0.0f;
      }
      if (!(vc_phase == 1 && vc_made)) L = iris_add(L, iris_scale(iris_mul(beta, le), w));
      if (last) last->miss = iris_scale(iris_mul(beta, le), 1.0f - w);
    }
    last = NULL;
    if (bounce > it->max_depth) break;

    iris_shading_point sp;
    iris_integrator_shade(it, &si, iris_neg(iris_normalize(ray.d)), bounce, &sp);
    lt_K = 0.0f;
    if (lt && bounce == 0) {
      lt_W0 = si.front ? iris_light_trace_camera_density(lt, si.p, si.ng) : 0.0f;
      lt_ng0 = si.ng;
    } else if (lt && bounce == 1 && lt_x0 && si.front && lt->member[si.prim] == IRIS_LIGHT_TRACE_GLOSSY &&
               iris_light_trace_starts(&sp) && lt_W0 > 0.0f && lt_px0 > 0.0f) {
      /* rho p_A |ng_x0.w0| / (W0 p_x0 |ng_y.w0|): light_trace.c's q over the
       * light's density and the reflection's */
      const iris_vec3 w0 = iris_normalize(ray.d);
      const float cx = fabsf(iris_dot(w0, lt_ng0)), cy = fabsf(iris_dot(w0, si.ng));
      if (cy > 0.0f && iris_dot(sp.wo, si.ng) > 0.0f) {
        lt_K = lt->rho * lt->inv_area * cx / (lt_W0 * lt_px0 * cy);
        lt_y = sp;
      }
    }
    if (lt_chain >= 0 && bounce >= 1) /* on through delta surfaces the light paths start from */
      lt_chain = lt->member[si.prim] == IRIS_LIGHT_TRACE_DELTA && sp.delta && lt_chain < IRIS_LIGHT_TRACE_CHAIN
                     ? lt_chain + 1 : -1;
    if (vpool) {
      const bool in_a = iris_vcache_in_a(vp, si.p, iris_neg(ray.d)), plain = iris_vcache_plain(&sp, si.ng);
      if (vc_phase == 0 && in_a) {
        vc_k++;
        vc_prev = vc_last, vc_prev_nd = vc_last_nd;
        vc_last = si.p, vc_last_nd = !sp.delta, vc_last_plain = plain;
        if (vp->sky) { /* x_{k-1} connected (not delta, and the ray not a delta lobe's) */
          const iris_vec3 d = iris_sub(vc_last, vc_prev);
          const float d2 = iris_dot(d, d), cos_in = fabsf(iris_dot(d, si.ng));
          if (vc_k >= 2 && vc_prev_nd && !prev_delta && plain && vpool->count > 0 && prev_pdf > 0.0f && cos_in > 0.0f)
            sky_g = d2 * sqrtf(d2) / (prev_pdf * cos_in);
        }
      } else if (vc_phase == 0 && vp->sky) {
        vc_phase = 2; /* outside: no more connections, nothing shared */
      } else if (vc_phase == 0) {
        vc_phase = vc_k >= 1 ? 1 : 2;
        const iris_vec3 d = iris_sub(vc_last, vc_prev);
        vc_made = vc_k >= 2 && vc_prev_nd && vc_last_plain && plain && iris_dot(d, d) > vp->min_d2;
        /* What follows is the connections' until the path comes back to A:
         * go on with probability 0.1 only (weighted 10; unbiased). */
        if (vc_made) {
          if (iris_sampler_slot(rng, IRIS_SLOT_CONNECT) >= 0.1f) break;
          beta = iris_scale(beta, 10.0f);
        }
      } else if (vc_phase == 1 && (in_a || !plain)) {
        vc_made = false; /* back in A, or a vertex no light path walks: the camera's again */
      }
    }
    /* The connection's vertex is drawn now, with the number it is drawn
     * with below, so that its line of the pool (one pool per sample index,
     * out of cache) loads while the guide prepares and the light is sampled. */
    const bool connect = vpool && vc_phase == 0 && !sp.delta && vpool->count > 0;
    float vc_u = 0.0f; /* the pool number: its whole part the vertex, its fraction the roulette's */
    const iris_vcache_vertex *z = NULL;
    if (connect) {
      vc_u = iris_sampler_slot(rng, IRIS_SLOT_CONNECT) * (float)vpool->count;
      z = &vpool->v[(uint32_t)vc_u < vpool->count ? (uint32_t)vc_u : vpool->count - 1];
      __builtin_prefetch(z);
      __builtin_prefetch((const char *)z + sizeof *z - 1);
    }
    /* Choose the light for NEE now, with the number sample_direct will draw,
     * so that the emitter's record loads while the guide prepares. */
    iris_light_choice choice = {0, 0.0f, false};
    if (nee && !sp.delta)
      iris_lights_choose(it->lights, sp.si.p, light_normal(&sp), iris_sampler_slot(rng, IRIS_SLOT_LIGHT_CHOICE), &choice);
    iris_integrator_prepare_direction(it, &sp);
    int8_t light_outcome = -1; /* for the recorded vertex: -1 no shadow ray, 0 blocked, 1 lit */
    float light_value = 0.0f;  /* ... and what it brought before the MIS weight */
    float p_light = 1.0f, env_q = 1.0f;
    if (nee && !sp.delta) {
      if (light_optional) p_light = it->guide.light_probability(it->guide.ctx, &sp);
      /* where the connections carry most of the map's light here (its share
       * toward every window's centre small), the camera samples the map only
       * with probability env_q, which its density counts (vcache.h); known
       * whichever light was chosen, since the escapes' weight needs it */
      if (sky_g > 0.0f)
        env_q = vp->map_q > 0.0f ? iris_fminf(vp->map_q, 1.0f)
                                 : iris_clampf(iris_vcache_sky_keep_centres(vp, sp.si.p, sp.si.ng, sky_g) /
                                                   IRIS_VCACHE_SKY_KEEP,
                                               IRIS_VCACHE_SKY_MAP_MIN, 1.0f);
      const float p_eff =
          env_q < 1.0f && iris_lights_choice_is_environment_map(it->lights, &choice) ? p_light * env_q : p_light;
      if (p_eff >= 1.0f || iris_sampler_slot(rng, IRIS_SLOT_LIGHT_SKIP) < p_eff)
      {
        const iris_vec3 dl = iris_mul(beta, sample_direct(it, &sp, &choice, rng, mis, p_eff, stats,
                                                          &light_outcome, &light_value, vp, sky_g, lt_K));
        if (!(vc_phase == 1 && vc_made && it->lights->entries[choice.light].kind == IRIS_LIGHT_KIND_TRIANGLE))
          L = iris_add(L, dl);
      }
    }
    if (connect) {
      /* connect to z, drawn uniformly from the pool (above); the pool
       * holds what vp->paths light paths left, so each counts count / paths */
      const iris_vec3 d = iris_sub(z->p, sp.si.p);
      const float d2 = iris_dot(d, d);
      if ((vp->sky || d2 > vp->min_d2) && bounce + 2 + z->m <= it->max_depth + 1) {
        const iris_vec3 w = iris_scale(d, 1.0f / sqrtf(d2));
        const float cos_z = -iris_dot(w, z->n);
        const iris_vec3 fx = iris_integrator_bsdf_eval(&sp, w);
        /* the connection before its MIS weight, and with the sky the rest
         * of the pool number, which its roulette compares below */
        const float k = fabsf(iris_dot(w, sp.si.ns)) * cos_z / d2 * (float)vpool->count / (float)vp->paths;
        const iris_vec3 bf = iris_mul(iris_mul(beta, fx), z->f_power);
        const float u_rr = vc_u - (float)(z - vpool->v);
        const bool rr = vp->sky && pixel_estimate > 0.0f;
        /* The weight is at most 1, so a number the roulette of the unweighted
         * value already refuses (with a margin for rounding) refuses the
         * weighted one too: the guide's density, the weight's cost, is looked
         * up only for the others; the same connections are traced. */
        if (cos_z > 0.0f && iris_max3(fx) > 0.0f &&
            !(rr && u_rr >= 1.001f * iris_avg3(bf) * k / (IRIS_VCACHE_SKY_RR * pixel_estimate))) {
          /* with the sky, the MIS weight against the camera's own (vcache.h) */
          const float wc = vp->sky ? iris_vcache_sky_weight(vp, z->mis * d2 / (iris_integrator_direction_pdf(it, &sp, w) *
                                                                             cos_z))
                                   : 1.0f;
          const iris_vec3 c = iris_scale(bf, wc * fabsf(iris_dot(w, sp.si.ns)) * cos_z / d2 * (float)vpool->count /
                                                 (float)vp->paths);
          /* with the sky, small ones against the pixel's estimate only
           * sometimes (weighted back): the rest of the pool number decides */
          float q = 1.0f;
          if (rr) q = iris_fminf(1.0f, iris_avg3(c) / (IRIS_VCACHE_SKY_RR * pixel_estimate));
          if (q >= 1.0f || u_rr < q) {
            iris_ray sh = iris_spawn_ray_to(sp.si.p, sp.si.ng, z->p, z->n);
            stats->shadow_rays++;
            if (!iris_accel_occluded(it->accel, &sh)) L_connect = iris_add(L_connect, iris_scale(c, 1.0f / q));
          }
        }
      }
    }

    iris_direction_sample ds;
    memset(&ds, 0, sizeof ds);
    if (!iris_integrator_sample_direction(it, &sp, rng, &ds)) break;
    if (!direction_allowed(&sp, ds.wi)) break;
    if (!sp.delta) aimed = ds.aimed; /* kept through the glass to the next non-delta vertex */
    float cos_i = fabsf(iris_dot(ds.wi, sp.si.ns));
    const iris_vec3 beta_before = beta;
    beta = iris_mul(beta, iris_scale(ds.f, cos_i / ds.pdf));
    if (!iris_isfinite3(beta)) { /* a NaN/Inf from a sampler: count it, keep what is finite */
      stats->nan_count++;
      break;
    }
    if (iris_max3(beta) <= 0.0f) break;
    if (rec && !ds.delta && rec->count < IRIS_PATH_RECORD_MAX) {
      last = &rec->v[rec->count++];
      last->guide = sp.guide;
      last->wi = ds.wi;
      last->f = ds.f;
      last->cos = cos_i;
      last->pdf = ds.pdf;
      last->pdf_bsdf = iris_integrator_bsdf_pdf(&sp, ds.wi);
      last->L = L;
      last->miss = iris_v3(0, 0, 0);
      last->beta = beta; /* replaced after Russian roulette; a killed path brings 0 */
      last->light = light_outcome;
      last->light_id = choice.light;
      last->light_value = light_value;
    }
    if (lt && bounce == 0) {
      lt_x0 = !sp.delta && !ds.delta && iris_dot(ds.wi, si.ng) > 0.0f, lt_px0 = ds.pdf;
      lt_chain = lt->delta && lt_x0 && lt_W0 > 0.0f && lt->member[si.prim] != IRIS_LIGHT_TRACE_DELTA ? 0 : -1;
      lt_refr = 0;
    } else if (lt_chain >= 1 && (ds.lobe & IRIS_LOBE_TRANSMISSION)) {
      lt_refr++;
    }
    prev_lt_K = lt_K;
    prev_delta = ds.delta;
    prev_sky_g = sky_g;
    sky_g = 0.0f;
    prev_pdf = ds.pdf;
    prev_light = p_light;
    prev_env_q = env_q;
    prev_p = sp.si.p;
    prev_n = light_normal(&sp);
    if (env_guided) prev_guide = sp.guide;
    ray = iris_spawn_ray(&sp.si, ds.wi);

    /* Russian roulette (docs/rendering.md): survive with q = min(1, sqrt(max beta)),
     * Cycles' rule: paths end later than with q = max beta, which on the
     * Cornell box lowers relMSE at equal spp by 24% for 9% more rays.
     * Guided methods whose guide estimates the radiance still to come (est):
     * adjoint-driven survival (Vorba & Krivanek 2016, without splitting),
     * q = RR_WINDOW * beta_before_this_bounce * est / pixel_estimate, clamped
     * to [0.1 q_plain, 1]: a path is not killed for following the guide (which
     * lowers beta) nor in bright regions, and is killed early where little
     * light is left (docs/guiding.md, "Russian roulette"). At a delta vertex
     * (glass, a mirror) they have no estimate, and beta there still holds the
     * last guided vertex's density, which the plain rule would punish: the
     * roulette looks only at what the vertex itself takes,
     * q = min(1, sqrt(max beta / max beta_before)) (clear glass: 1).
     * Any q in (0, 1] with beta / q keeps the estimator unbiased. */
    float est = adjoint_rr ? it->guide.radiance_estimate(it->guide.ctx, &sp) : -1.0f;
    if (est >= 0.0f && !(pixel_estimate > 0.0f))
      pixel_estimate = iris_avg3(L) + iris_avg3(beta_before) * est;
    if (bounce + 1 >= it->rr_depth && !aimed) {
      float q = iris_fminf(1.0f, sqrtf(iris_max3(beta)));
      if (est >= 0.0f && pixel_estimate > 0.0f)
        q = iris_clampf(RR_WINDOW * iris_max3(beta_before) * est / pixel_estimate, 0.1f * q, 1.0f);
      else if (adjoint_rr && sp.delta)
        q = iris_fminf(1.0f, sqrtf(iris_max3(beta) / iris_max3(beta_before)));
      if (iris_sampler_slot(rng, IRIS_SLOT_RR) >= q) break;
      beta = iris_scale(beta, 1.0f / q);
    }
    if (last) last->beta = beta;
  }
  if (!iris_isfinite3(L)) {
    stats->nan_count++;
    if (rec) rec->count = 0;
    return iris_v3(0, 0, 0);
  }
  if (iris_isfinite3(L_connect)) L = iris_add(L, L_connect);
  else stats->nan_count++;
  return L;
}

iris_vec3 iris_integrator_radiance(const iris_integrator *it, iris_ray ray, iris_sampler *rng,
                                   iris_path_stats *stats) {
  return trace_path(it, ray, rng, stats, NULL);
}

iris_vec3 iris_integrator_radiance_record(const iris_integrator *it, iris_ray ray, iris_sampler *rng,
                                          iris_path_stats *stats, iris_path_record *rec) {
  rec->count = 0;
  return trace_path(it, ray, rng, stats, rec);
}
