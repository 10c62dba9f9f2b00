/* Light tracing of glossy caustics into the camera; see light_trace.h. */
#include "renderer/light_trace.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/parallel.h"
#include "core/log.h"
#include "core/rng.h"
#include "renderer/bsdf.h"
#include "renderer/envmap.h"
#include "renderer/lights.h"

#define BLOCK 256 /* light paths per block: a block's splats are added in its order */
#define SALT 0x11e7a7ace5ULL

void iris_light_trace_destroy(iris_light_trace *lt) {
  if (!lt) return;
  free(lt->member);
  free(lt->tris);
  free(lt->dtris);
  iris_distrib1d_destroy(&lt->select);
  iris_distrib1d_destroy(&lt->dselect);
  free(lt);
}

static iris_status pilot_splats(iris_light_trace *lt, const iris_integrator *it, uint64_t count, uint64_t splats[2],
                                iris_error *err);

iris_status iris_light_trace_create(const iris_integrator *it, const iris_pinhole *cam, int x0, int y0, int x1,
                                    int y1, uint64_t seed, int threads, iris_light_trace **out, iris_error *err) {
  *out = NULL;
  if (it->method != IRIS_METHOD_MIS || it->lights->count == 0 || it->max_depth < 1) return IRIS_OK;
  size_t unique = 0, placed = 0;
  iris_accel_stats(it->accel, &unique, &placed);
  if (placed > 0) return IRIS_OK;
  const uint32_t n = iris_accel_triangle_count(it->accel);
  if (n == 0) return IRIS_OK;
  iris_light_trace *lt = calloc(1, sizeof *lt);
  float *w = lt ? malloc((size_t)n * sizeof *w) : NULL, *dw = lt ? malloc((size_t)n * sizeof *dw) : NULL;
  if (lt) {
    lt->member = calloc(n, 1);
    lt->tris = malloc((size_t)n * sizeof *lt->tris);
    lt->dtris = malloc((size_t)n * sizeof *lt->dtris);
  }
  if (!lt || !w || !dw || !lt->member || !lt->tris || !lt->dtris) {
    free(w), free(dw);
    iris_light_trace_destroy(lt);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory (light tracing)");
  }
  /* the second kind needs a map with a sun to aim at */
  const bool sky = it->lights->envmap != NULL;
  uint32_t m = 0, dm = 0;
  double area = 0.0, darea = 0.0;
  for (uint32_t i = 0; i < n; ++i) {
    /* cut-out and see-through surfaces are not where a camera ray always
     * stops: left to the camera */
    const int32_t mi = iris_accel_triangle_material(it->accel, i);
    if (mi >= 0 && (size_t)mi < it->scene->material_count && it->scene->materials[mi].alpha_mode != IRIS_ALPHA_OPAQUE)
      continue;
    iris_interaction si;
    iris_accel_surface_at(it->accel, i, 1.0f / 3.0f, 1.0f / 3.0f, &si);
    iris_shading_point sp;
    iris_integrator_shade(it, &si, si.ns, 1, &sp);
    /* a triangle whose centroid qualifies; each point is asked again
     * (iris_light_trace_starts: a texture may make parts rougher) */
    const bool glossy = iris_light_trace_starts(&sp), delta = sky && sp.delta;
    if (!glossy && !delta) continue;
    iris_vec3 v[3];
    iris_accel_triangle(it->accel, i, v);
    const float a = 0.5f * iris_length(iris_cross(iris_sub(v[1], v[0]), iris_sub(v[2], v[0])));
    if (!(a > 0.0f) || !isfinite(a)) continue;
    if (glossy) {
      lt->member[i] = IRIS_LIGHT_TRACE_GLOSSY;
      lt->tris[m] = i;
      w[m++] = a;
      area += a;
    } else {
      lt->member[i] = IRIS_LIGHT_TRACE_DELTA;
      lt->dtris[dm] = i;
      dw[dm++] = a;
      darea += a;
    }
  }
  iris_status st = IRIS_OK;
  if (m > 0) st = iris_distrib1d_create(&lt->select, w, m, err);
  if (st == IRIS_OK && dm > 0) st = iris_distrib1d_create(&lt->dselect, dw, dm, err);
  free(w), free(dw);
  lt->glossy = m > 0 && area > 0.0;
  lt->delta = dm > 0 && darea > 0.0;
  if (st != IRIS_OK || (!lt->glossy && !lt->delta)) {
    iris_light_trace_destroy(lt);
    return st;
  }
  lt->inv_area = lt->glossy ? (float)(1.0 / area) : 0.0f;
  lt->inv_darea = lt->delta ? (float)(1.0 / darea) : 0.0f;
  lt->sun_pdf = IRIS_LIGHT_TRACE_SUN / (4.0f * IRIS_PI);
  lt->cam = *cam;
  lt->x0 = x0, lt->y0 = y0, lt->x1 = x1, lt->y1 = y1;
  const double per = ceil((double)cam->width * (double)cam->height * IRIS_LIGHT_TRACE_PER_SAMPLE);
  lt->per_index = (uint64_t)per;
  lt->rho = (float)per;
  lt->pixel_area = (2.0f * cam->tan_half_yfov * cam->aspect / (float)cam->width) *
                   (2.0f * cam->tan_half_yfov / (float)cam->height);
  lt->seed = seed;
  lt->threads = threads;
  /* Where the reflectors' light seldom reaches what the camera sees (veach-mis's
   * plates send the lamps out of the frame: 0.03% of the paths land), the
   * light paths would only cost: a pilot of the first paths decides. */
  const uint64_t pn = 4 * lt->per_index < IRIS_LIGHT_TRACE_PILOT ? 4 * lt->per_index : IRIS_LIGHT_TRACE_PILOT;
  uint64_t hits[2] = {0, 0};
  st = pilot_splats(lt, it, pn, hits, err);
  lt->pilot_paths = pn, lt->pilot_splats[0] = hits[0], lt->pilot_splats[1] = hits[1];
  const double need = IRIS_LIGHT_TRACE_PILOT_SHARE * (double)pn;
  if (st == IRIS_OK && lt->glossy && (double)hits[0] < need) {
    iris_infof("light tracing off glossy reflectors: off (%llu of %llu light paths of a pilot reached the camera, < %.0f%%)",
               (unsigned long long)hits[0], (unsigned long long)pn, 100.0 * IRIS_LIGHT_TRACE_PILOT_SHARE);
    lt->glossy = false;
  }
  if (st == IRIS_OK && lt->delta && (double)hits[1] < need) {
    iris_infof("light tracing through glass and mirrors: off (%llu of %llu light paths of a pilot reached the camera, "
               "< %.0f%%)",
               (unsigned long long)hits[1], (unsigned long long)pn, 100.0 * IRIS_LIGHT_TRACE_PILOT_SHARE);
    lt->delta = false;
  }
  if (st != IRIS_OK || (!lt->glossy && !lt->delta)) {
    iris_light_trace_destroy(lt);
    return st;
  }
  /* the camera asks the table: a kind that does not run keeps its paths */
  for (uint32_t i = 0; i < n; ++i)
    if ((lt->member[i] == IRIS_LIGHT_TRACE_GLOSSY && !lt->glossy) || (lt->member[i] == IRIS_LIGHT_TRACE_DELTA && !lt->delta))
      lt->member[i] = 0;
  *out = lt;
  return IRIS_OK;
}

/* What one light path adds to one pixel. */
typedef struct splat {
  uint32_t pixel; /* in the window */
  float c[3];
} splat;

typedef struct block_out {
  splat *v;
  size_t n, cap;
  size_t kind_n[2]; /* splats of the glossy kind, of the delta kind */
  uint64_t rays;
  bool oom;
} block_out;

static void push(block_out *b, int kind, uint32_t pixel, iris_vec3 c) {
  b->kind_n[kind]++;
  if (b->n == b->cap) {
    size_t cap = b->cap ? 2 * b->cap : 64;
    splat *v = realloc(b->v, cap * sizeof *v);
    if (!v) {
      b->oom = true;
      return;
    }
    b->v = v, b->cap = cap;
  }
  b->v[b->n++] = (splat){pixel, {c.x, c.y, c.z}};
}

/* The power heuristic over three strategies, for the first. */
static float power3(float a, float b, float c) {
  if (!(a > 0.0f)) return 0.0f;
  if (!isfinite(a)) return 1.0f;
  return a * a / (a * a + b * b + c * c);
}

/* x0's pixel in the window (the pinhole's projection, camera.c's ray
 * inverted), seen from its front: false when outside or behind. */
static bool project(const iris_light_trace *lt, const iris_interaction *xs, iris_vec3 *dir, int *px, int *py) {
  const iris_pinhole *cam = &lt->cam;
  const iris_vec3 v = iris_sub(xs->p, cam->origin);
  const float dist = iris_length(v);
  if (!(dist > 0.0f)) return false;
  *dir = iris_scale(v, 1.0f / dist);
  const float zc = iris_dot(*dir, cam->forward);
  if (!(zc > 0.0f) || !(iris_dot(*dir, xs->ng) < 0.0f)) return false;
  const float rx = (iris_dot(*dir, cam->right) / zc / (cam->tan_half_yfov * cam->aspect) + 1.0f) * 0.5f * (float)cam->width;
  const float ry = (1.0f - iris_dot(*dir, cam->up) / zc / cam->tan_half_yfov) * 0.5f * (float)cam->height;
  if (!(rx >= (float)lt->x0 && rx < (float)lt->x1 && ry >= (float)lt->y0 && ry < (float)lt->y1)) return false;
  *px = (int)rx, *py = (int)ry;
  return *px >= lt->x0 && *px < lt->x1 && *py >= lt->y0 && *py < lt->y1;
}

/* A light path's start: a triangle of `tris` by area (`select`), a uniform
 * point on it (the sampler's dimensions 0-2). */
static void start_point(const iris_integrator *it, const iris_distrib1d *select, const uint32_t *tris,
                        const iris_sampler *r, iris_interaction *y) {
  float pmf, u_rest;
  const size_t k = iris_distrib1d_sample(select, iris_sampler_get(r, 0), &pmf, &u_rest);
  float b1 = iris_sampler_get(r, 1), b2 = iris_sampler_get(r, 2);
  if (b1 + b2 > 1.0f) b1 = 1.0f - b1, b2 = 1.0f - b2;
  iris_accel_surface_at(it->accel, tris[k], b1, b2, y);
}

/* Light path `index`: y on a reflector, a light sample there, the reflection
 * to x0, x0 into the camera (the formulas: docs/rendering.md). */
static void trace_glossy(const iris_light_trace *lt, const iris_integrator *it, uint64_t index, block_out *out) {
  const iris_sampler r = iris_sampler_start(lt->seed ^ SALT, index, 0);
  iris_interaction ys;
  start_point(it, &lt->select, lt->tris, &r, &ys);
  /* the light as next-event estimation at y draws it (light_normal there:
   * the geometric normal of a reflect-only BSDF) */
  iris_light_choice choice;
  iris_lights_choose(it->lights, ys.p, ys.ng, iris_sampler_get(&r, 3), &choice);
  iris_light_sample ls;
  if (!iris_lights_sample_choice(it->lights, ys.p, &choice, iris_sampler_get(&r, 4), iris_sampler_get(&r, 5), &ls))
    return;
  const iris_vec3 wl = ls.wi; /* towards the light */
  if (!(iris_dot(wl, ys.ng) > 0.0f) || !(ls.pdf > 0.0f)) return;
  /* y lit from wl reflects towards wout, drawn by its BSDF with wl as the
   * outgoing direction (reciprocity) */
  iris_shading_point yl;
  iris_integrator_shade(it, &ys, wl, 1, &yl);
  if (!iris_light_trace_starts(&yl)) return;
  iris_direction_sample ds;
  if (!iris_integrator_sample_bsdf_u(&yl, iris_sampler_get(&r, 6), iris_sampler_get(&r, 7), iris_sampler_get(&r, 8),
                                     &ds) ||
      ds.delta || !(ds.pdf > 0.0f))
    return;
  const iris_vec3 wout = ds.wi;
  const float cos_yg = iris_dot(wout, ys.ng);
  if (!(cos_yg > 0.0f)) return;
  iris_ray ray = iris_spawn_ray(&ys, wout);
  iris_hit hit;
  out->rays++;
  if (!iris_accel_intersect(it->accel, &ray, &hit)) return;
  iris_interaction xs;
  iris_accel_interaction(it->accel, ray.d, &hit, &xs);
  if (!xs.front) return; /* x0 lit from its front, as the camera's bounce leaves it (no medium between) */
  iris_vec3 dir;
  int px, py;
  if (!project(lt, &xs, &dir, &px, &py)) return;
  iris_shading_point xp;
  iris_integrator_shade(it, &xs, iris_neg(dir), 0, &xp);
  if (xp.delta) return;
  const iris_vec3 w0 = iris_neg(wout); /* at x0, towards y */
  const iris_vec3 f0 = iris_integrator_bsdf_eval(&xp, w0);
  const float cos_x0g = fabsf(iris_dot(w0, xs.ng));
  const float W = iris_light_trace_camera_density(lt, xs.p, xs.ng);
  if (!(iris_max3(f0) > 0.0f) || !(cos_x0g > 0.0f) || !(W > 0.0f)) return;
  const iris_vec3 fy = iris_integrator_bsdf_eval(&yl, wout);
  if (!(iris_max3(fy) > 0.0f)) return;
  /* the camera's densities for the same path: its direction sampler at x0
   * towards y, and at y (seen from x0) its BSDF sampling towards the light */
  iris_integrator_prepare_direction(it, &xp);
  const float p_x0 = iris_integrator_direction_pdf(it, &xp, w0);
  iris_shading_point yc;
  iris_integrator_shade(it, &ys, wout, 1, &yc);
  if (!iris_light_trace_starts(&yc)) return; /* the camera's test, at its own shading of y */
  iris_integrator_prepare_direction(it, &yc);
  const float p_l = ls.delta ? 1.0f : ls.pdf;
  const float p_b = ls.delta ? 0.0f : iris_integrator_direction_pdf(it, &yc, wl);
  /* this strategy's density in the camera's units (light_trace.h's rho
   * paths per sample index against one camera sample of the pixel) */
  const float q = p_x0 > 0.0f ? lt->rho * lt->inv_area * p_l * ds.pdf * cos_x0g / (W * p_x0 * cos_yg) : INFINITY;
  const float weight = isfinite(q) ? power3(q, p_l, p_b) : 1.0f;
  if (!(weight > 0.0f)) return;
  /* unoccluded: y to the light, x0 to the camera */
  iris_ray sh;
  if (isfinite(ls.dist) && !ls.delta) {
    sh = iris_spawn_ray_to(ys.p, ys.ng, ls.p, ls.n);
  } else {
    sh = iris_spawn_ray(&ys, wl);
    if (isfinite(ls.dist)) sh.tmax = ls.dist * (1.0f - 1e-5f);
  }
  out->rays++;
  if (iris_accel_occluded(it->accel, &sh)) return;
  const iris_ray sc = iris_spawn_ray_to(xs.p, xs.ng, lt->cam.origin, iris_v3(0, 0, 0));
  out->rays++;
  if (iris_accel_occluded(it->accel, &sc)) return;
  iris_lights_sample_radiance(it->lights, &ls);
  /* L f_y |ns_y.wl| |ng_y.wout| / (p_A p_l p_y) * f_x0 |ns_x0.w0| / |ng_x0.w0| * W */
  const float s = fabsf(iris_dot(wl, ys.ns)) * cos_yg / (lt->inv_area * p_l * ds.pdf) *
                  fabsf(iris_dot(w0, xs.ns)) / cos_x0g * W * weight;
  const iris_vec3 c = iris_scale(iris_mul(iris_mul(ls.L, fy), f0), s);
  if (!iris_isfinite3(c) || !(iris_max3(c) > 0.0f)) return;
  push(out, 0, (uint32_t)((py - lt->y0) * (lt->x1 - lt->x0) + (px - lt->x0)), c);
}

/* The second kind (light_trace.h): the sun through clear glass and off
 * mirrors. y by area on a delta surface, a light sample of the map there in a
 * sun's direction, then the delta surfaces' own sampling (reflection or
 * refraction by Fresnel) to the first other surface x0. By the conservation
 * of etendue (|n_g . w| dA dw along a ray and through specular interfaces;
 * the refractions' n^2 cancel between entering and leaving), the camera's
 * integral over x0 and its bounce equals one over y and the light's
 * direction: the value is L |n_g(y).w_l| / (p_A p_l) times each delta
 * vertex's f |cos| / p, then f_x0 |n_s(x0).w_0| / |n_g(x0).w_0| W(x0). */
static void trace_delta(const iris_light_trace *lt, const iris_integrator *it, uint64_t index, block_out *out) {
  const iris_sampler r = iris_sampler_start(lt->seed ^ SALT ^ 0xde17aULL, index, 0);
  iris_interaction ys;
  start_point(it, &lt->dselect, lt->dtris, &r, &ys);
  /* the map, as light sampling draws it, in a sun's direction only */
  iris_light_choice choice;
  iris_lights_choose(it->lights, ys.p, iris_v3(0, 0, 0), iris_sampler_get(&r, 3), &choice);
  if (!iris_lights_choice_is_environment_map(it->lights, &choice)) return;
  iris_light_sample ls;
  if (!iris_lights_sample_choice(it->lights, ys.p, &choice, iris_sampler_get(&r, 4), iris_sampler_get(&r, 5), &ls) ||
      !(ls.pdf > 0.0f) || ls.delta || isfinite(ls.dist))
    return;
  const iris_vec3 wl = ls.wi;
  if (!(iris_envmap_pdf(it->lights->envmap, wl) >= lt->sun_pdf)) return;
  const float cos_l = fabsf(iris_dot(wl, ys.ng));
  if (!(cos_l > 0.0f)) return;
  iris_ray sh = iris_spawn_ray(&ys, wl);
  out->rays++;
  if (iris_accel_occluded(it->accel, &sh)) return;
  iris_lights_sample_radiance(it->lights, &ls);
  iris_vec3 beta = iris_scale(ls.L, cos_l / (lt->inv_darea * ls.pdf));
  iris_interaction cur = ys;
  iris_vec3 wo = wl; /* at the current vertex, towards where the light came from */
  int refractions = 0;
  for (int depth = 1;; ++depth) {
    if (depth > IRIS_LIGHT_TRACE_CHAIN || depth > it->max_depth) return;
    if (lt->member[cur.prim] != IRIS_LIGHT_TRACE_DELTA) return;
    iris_shading_point sp;
    iris_integrator_shade(it, &cur, wo, depth, &sp);
    if (!sp.delta) return;
    iris_direction_sample ds;
    if (!iris_integrator_sample_bsdf_u(&sp, iris_sampler_get(&r, 6 + 3 * (uint32_t)depth),
                                       iris_sampler_get(&r, 7 + 3 * (uint32_t)depth),
                                       iris_sampler_get(&r, 8 + 3 * (uint32_t)depth), &ds) ||
        !ds.delta || !(ds.pdf > 0.0f))
      return;
    beta = iris_mul(beta, iris_scale(ds.f, fabsf(iris_dot(ds.wi, sp.si.ns)) / ds.pdf));
    if (!(iris_max3(beta) > 0.0f) || !iris_isfinite3(beta)) return;
    refractions += (ds.lobe & IRIS_LOBE_TRANSMISSION) != 0;
    iris_ray ray = iris_spawn_ray(&sp.si, ds.wi);
    iris_hit hit;
    out->rays++;
    if (!iris_accel_intersect(it->accel, &ray, &hit)) return;
    iris_interaction next;
    iris_accel_interaction(it->accel, ray.d, &hit, &next);
    /* inside coloured glass (KHR_materials_volume), as the camera's path
     * weighs the same segment the other way */
    if (!next.front) beta = iris_mul(beta, iris_integrator_volume_transmittance(it, &next, hit.t * iris_length(ray.d)));
    wo = iris_neg(iris_normalize(ray.d));
    if (lt->member[next.prim] == IRIS_LIGHT_TRACE_DELTA) { /* on through the glass */
      cur = next;
      continue;
    }
    /* x0: the first other surface, lit on its front, seen by the camera;
     * after an even number of refractions only (in and out of the glass:
     * their n^2 cancel; a pane of one surface bends the light once, and its
     * light stays the camera's) */
    if (!next.front || refractions % 2 != 0) return;
    iris_vec3 dir;
    int px, py;
    if (!project(lt, &next, &dir, &px, &py)) return;
    iris_shading_point xp;
    iris_integrator_shade(it, &next, iris_neg(dir), 0, &xp);
    if (xp.delta) return;
    const iris_vec3 f0 = iris_integrator_bsdf_eval(&xp, wo);
    const float cos_x0g = fabsf(iris_dot(wo, next.ng));
    const float W = iris_light_trace_camera_density(lt, next.p, next.ng);
    if (!(iris_max3(f0) > 0.0f) || !(cos_x0g > 0.0f) || !(W > 0.0f)) return;
    const iris_ray sc = iris_spawn_ray_to(next.p, next.ng, lt->cam.origin, iris_v3(0, 0, 0));
    out->rays++;
    if (iris_accel_occluded(it->accel, &sc)) return;
    const iris_vec3 c = iris_scale(iris_mul(beta, f0), fabsf(iris_dot(wo, next.ns)) / cos_x0g * W);
    if (!iris_isfinite3(c) || !(iris_max3(c) > 0.0f)) return;
    push(out, 1, (uint32_t)((py - lt->y0) * (lt->x1 - lt->x0) + (px - lt->x0)), c);
    return;
  }
}

typedef struct run_ctx {
  const iris_light_trace *lt;
  const iris_integrator *it;
  uint64_t first, count;
  block_out *blocks;
} run_ctx;

static void run_blocks(void *vctx, uint64_t begin, uint64_t end, int thread) {
  (void)thread;
  run_ctx *c = (run_ctx *)vctx;
  for (uint64_t b = begin; b < end; ++b) {
    const uint64_t i0 = b * BLOCK, i1 = i0 + BLOCK < c->count ? i0 + BLOCK : c->count;
    for (uint64_t i = i0; i < i1; ++i) {
      if (c->lt->glossy) trace_glossy(c->lt, c->it, c->first + i, &c->blocks[b]);
      if (c->lt->delta) trace_delta(c->lt, c->it, c->first + i, &c->blocks[b]);
    }
  }
}

/* The pilot (iris_light_trace_create): how many of the first light paths
 * add to a pixel anywhere in the frame (a function of the scene, camera and
 * seed alone: every window and part decides alike). */
static iris_status pilot_splats(iris_light_trace *lt, const iris_integrator *it, uint64_t count, uint64_t splats[2],
                                iris_error *err) {
  const int x0 = lt->x0, y0 = lt->y0, x1 = lt->x1, y1 = lt->y1;
  lt->x0 = 0, lt->y0 = 0, lt->x1 = lt->cam.width, lt->y1 = lt->cam.height;
  const uint64_t nb = (count + BLOCK - 1) / BLOCK;
  run_ctx c = {lt, it, 0, count, calloc((size_t)nb, sizeof(block_out))};
  if (c.blocks) iris_parallel_for(nb, 1, lt->threads, run_blocks, &c);
  splats[0] = splats[1] = 0;
  bool oom = !c.blocks;
  for (uint64_t b = 0; c.blocks && b < nb; ++b) {
    splats[0] += c.blocks[b].kind_n[0];
    splats[1] += c.blocks[b].kind_n[1];
    oom |= c.blocks[b].oom;
    free(c.blocks[b].v);
  }
  free(c.blocks);
  lt->x0 = x0, lt->y0 = y0, lt->x1 = x1, lt->y1 = y1;
  return oom ? iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory (light tracing)") : IRIS_OK;
}

iris_status iris_light_trace_run(iris_light_trace *lt, const iris_integrator *it, uint64_t first, uint64_t count,
                                 iris_film *film, iris_error *err) {
  if (count == 0) return IRIS_OK;
  const uint64_t nb = (count + BLOCK - 1) / BLOCK;
  run_ctx c = {lt, it, first, count, calloc((size_t)nb, sizeof(block_out))};
  if (!c.blocks) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory (light tracing)");
  iris_parallel_for(nb, 1, lt->threads, run_blocks, &c);
  bool oom = false;
  for (uint64_t b = 0; b < nb; ++b) { /* in index order: the same sums for any threads */
    const block_out *o = &c.blocks[b];
    oom |= o->oom;
    lt->rays += o->rays;
    lt->splats += o->n;
    for (size_t j = 0; j < o->n; ++j) {
      iris_film_add_light_path(film, o->v[j].pixel, o->v[j].c);
      lt->energy += ((double)o->v[j].c[0] + o->v[j].c[1] + o->v[j].c[2]) / 3.0;
    }
    free(o->v);
  }
  free(c.blocks);
  if (oom) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory (light tracing)");
  film->light_paths += (double)count;
  return IRIS_OK;
}
