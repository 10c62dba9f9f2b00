/* Building the light list: the entries (emissive triangles per placement,
 * punctual lights, the environment), their groups and selection tables, the
 * triangles' alias tables, and the light tree's view of the entries; see
 * lights.h. Selection, sampling and evaluation are in lights.c. */
#include "renderer/lights.h"

#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "renderer/lights_private.h"

static float triangle_area(const iris_vec3 v[3]) {
  return 0.5f * iris_length(iris_cross(iris_sub(v[1], v[0]), iris_sub(v[2], v[0])));
}

/* Groups: consecutive triangle entries of one instance (or all triangles when
 * there would be too many groups), and one group per other light. */
static iris_status build_groups(iris_lights *L, iris_error *err) {
  size_t tri_groups = 0, others = 0;
  uint32_t prev = UINT32_MAX;
  for (size_t i = 0; i < L->count; i++) {
    if (L->entries[i].kind != IRIS_LIGHT_KIND_TRIANGLE) {
      others++;
    } else if (L->entries[i].group != prev) {
      tri_groups++;
      prev = L->entries[i].group;
    }
  }
  const bool merge = iris_lights_merge_groups(tri_groups, others);
  L->groups = calloc(iris_lights_group_count(tri_groups, others), sizeof *L->groups);
  if (!L->groups) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for light groups");
  size_t g = 0;
  prev = UINT32_MAX;
  for (size_t i = 0; i < L->count; i++) {
    iris_light_entry *e = &L->entries[i];
    bool tri = e->kind == IRIS_LIGHT_KIND_TRIANGLE;
    bool start = !tri || g == 0 || L->groups[g - 1].kind != IRIS_LIGHT_KIND_TRIANGLE ||
                 (!merge && e->group != prev);
    if (tri) prev = e->group;
    if (start) {
      L->groups[g].first = (uint32_t)i;
      L->groups[g].kind = e->kind;
      g++;
    }
    iris_light_group *gr = &L->groups[g - 1];
    gr->count++;
    gr->power += e->power;
    e->group = (uint32_t)(g - 1);
  }
  L->group_count = g;
  for (size_t k = 0; k < g; k++) {
    iris_light_group *gr = &L->groups[k];
    const iris_light_entry *e0 = &L->entries[gr->first];
    switch (gr->kind) {
      case IRIS_LIGHT_KIND_TRIANGLE: {
        iris_vec3 lo = iris_v3(INFINITY, INFINITY, INFINITY), hi = iris_neg(lo);
        for (uint32_t i = gr->first; i < gr->first + gr->count; i++) {
          iris_vec3 v[3];
          iris_accel_triangle(L->accel, L->entries[i].prim, v);
          for (int j = 0; j < 3; j++) {
            lo = iris_v3(fminf(lo.x, v[j].x), fminf(lo.y, v[j].y), fminf(lo.z, v[j].z));
            hi = iris_v3(fmaxf(hi.x, v[j].x), fmaxf(hi.y, v[j].y), fmaxf(hi.z, v[j].z));
          }
        }
        gr->center = iris_scale(iris_add(lo, hi), 0.5f);
        gr->radius = 0.5f * iris_length(iris_sub(hi, lo));
        gr->phi = gr->power;
        break;
      }
      case IRIS_LIGHT_KIND_POINT:
      case IRIS_LIGHT_KIND_SPOT:
        gr->center = iris_v3_load(L->scene->lights[e0->prim].position);
        gr->radius = 0.0f;
        gr->phi = 4.0f * IRIS_PI * iris_luminance(e0->radiance);
        break;
      case IRIS_LIGHT_KIND_DIRECTIONAL:
        gr->irradiance = iris_luminance(e0->radiance);
        break;
      case IRIS_LIGHT_KIND_ENVIRONMENT:
      default:
        gr->irradiance = IRIS_PI * iris_luminance(e0->radiance);
        break;
    }
    if (gr->count > 1) {
      float *w = malloc(sizeof(float) * gr->count);
      if (!w) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for light groups");
      for (uint32_t i = 0; i < gr->count; i++) w[i] = L->entries[gr->first + i].power;
      iris_status st = iris_distrib1d_create(&gr->select, w, gr->count, err);
      free(w);
      if (st != IRIS_OK) return st;
    }
  }
  return IRIS_OK;
}

/* Each build's id: a thread's cached group weights (lights.c) belong to one light list. */
static atomic_ullong next_lights_id = 1;

/* Vose's alias table over the group's entries in proportion to their power
 * (sanitised as iris_distrib1d does; uniform when all are zero), in double. */
static iris_status build_alias(iris_lights *L, const iris_light_group *g) {
  uint32_t n = g->count;
  double *p = malloc(sizeof(double) * n);
  uint32_t *small = malloc(sizeof(uint32_t) * n), *large = malloc(sizeof(uint32_t) * n);
  if (!p || !small || !large) {
    free(p), free(small), free(large);
    return IRIS_ERR_NOMEM;
  }
  double sum = 0.0;
  for (uint32_t i = 0; i < n; i++) {
    float w = L->entries[g->first + i].power;
    p[i] = isfinite(w) && w > 0.0f ? (double)w : 0.0;
    sum += p[i];
  }
  uint32_t ns = 0, nl = 0;
  for (uint32_t i = 0; i < n; i++) {
    p[i] = sum > 0.0 ? p[i] * n / sum : 1.0;
    if (p[i] < 1.0)
      small[ns++] = i;
    else
      large[nl++] = i;
  }
  while (ns > 0 && nl > 0) {
    uint32_t s = small[--ns], l = large[--nl];
    L->tris[g->first + s].alias_q = (float)p[s];
    L->tris[g->first + s].alias = g->first + l;
    p[l] -= 1.0 - p[s];
    if (p[l] < 1.0)
      small[ns++] = l;
    else
      large[nl++] = l;
  }
  /* what is left is full up to rounding */
  while (nl > 0) {
    uint32_t l = large[--nl];
    L->tris[g->first + l].alias_q = 2.0f;
    L->tris[g->first + l].alias = g->first + l;
  }
  while (ns > 0) {
    uint32_t s = small[--ns];
    L->tris[g->first + s].alias_q = 2.0f;
    L->tris[g->first + s].alias = g->first + s;
  }
  free(p), free(small), free(large);
  return IRIS_OK;
}

/* The emissive triangles of placement `instance` (nothing when its mesh does
 * not emit) appended as entries from *n, and its slots in light_of_prim from
 * *slot. Each placement's triangles are world-space lights of their own: its
 * transform scales their area, hence their power. */
static void add_emissive_placement(iris_lights *out, size_t instance, size_t *n, size_t *slot) {
  const iris_accel *accel = out->accel;
  out->light_base[instance] = UINT32_MAX;
  const iris_material *m = material_of(out->scene, iris_accel_instance_material(accel, instance));
  if (!is_emissive(m)) return;
  uint32_t first, count;
  iris_accel_instance_prims(accel, instance, &first, &count);
  out->light_base[instance] = (uint32_t)*slot;
  for (uint32_t t = first; t < first + count; t++) {
    uint32_t *light = &out->light_of_prim[(*slot)++];
    *light = UINT32_MAX;
    iris_vec3 v[3];
    iris_accel_triangle(accel, t, v);
    float area = triangle_area(v);
    if (!(area > 0.0f) || !isfinite(area)) continue; /* degenerate: never sampled, never hit */
    iris_light_entry *e = &out->entries[*n];
    e->kind = IRIS_LIGHT_KIND_TRIANGLE;
    e->prim = t;
    e->group = (uint32_t)instance; /* provisional: the instance, turned into a group later */
    e->area = area;
    e->two_sided = m->emission_two_sided;
    e->radiance = iris_v3_load(m->emission);
    e->power = iris_luminance(e->radiance) * IRIS_PI * area * (e->two_sided ? 2.0f : 1.0f);
    e->v0 = v[0];
    e->e1 = iris_sub(v[1], v[0]);
    e->e2 = iris_sub(v[2], v[0]);
    e->ng = iris_normalize(iris_cross(e->e1, e->e2));
    /* evaluated per point: a texture, vertex colours, or alpha coverage (a MASK emitter's
     * cut-out parts do not exist, so they do not emit; a BLEND one is seen with
     * probability alpha: surface_coverage) */
    e->textured = m->emission_texture >= 0 || m->unlit || m->alpha_mode != IRIS_ALPHA_OPAQUE;
    *light = (uint32_t)*n;
    (*n)++;
  }
}

iris_status iris_lights_build(const iris_scene *scene, const iris_accel *accel,
                              const iris_textures *textures, iris_lights *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  out->id = atomic_fetch_add(&next_lights_id, 1);
  out->scene = scene;
  out->accel = accel;
  out->textures = textures;
  out->environment = -1;
  iris_vec3 lo, hi;
  if (iris_accel_bounds(accel, &lo, &hi)) {
    out->center = iris_scale(iris_add(lo, hi), 0.5f);
    out->radius = fmaxf(0.5f * iris_length(iris_sub(hi, lo)), 1e-3f);
  } else {
    out->center = iris_v3(0, 0, 0);
    out->radius = 1.0f;
  }
  /* Emissive triangles, enumerated per placement (issue 20): each placement of
   * an emissive mesh is its own set of world-space lights. */
  size_t placements = iris_accel_instance_count(accel);
  size_t emissive = 0;
  for (size_t i = 0; i < placements; i++) {
    uint32_t first, count;
    iris_accel_instance_prims(accel, i, &first, &count);
    if (is_emissive(material_of(scene, iris_accel_instance_material(accel, i)))) emissive += count;
  }
  if (emissive >= UINT32_MAX)
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "more than 2^32 emissive triangles");
  bool env = iris_lights_constant_environment_emits(scene);
  iris_vec3 env_mean = iris_v3_load(scene->environment);
  if (scene->has_environment && scene->environment_map.path) {
    out->envmap = calloc(1, sizeof *out->envmap);
    if (!out->envmap) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for the environment");
    iris_status st = iris_envmap_load(&scene->environment_map, out->envmap, err);
    if (st != IRIS_OK) {
      free(out->envmap);
      out->envmap = NULL;
      return st;
    }
    env_mean = iris_v3_load(out->envmap->mean_rgb);
    env = out->envmap->mean_luminance > 0.0;
    if (!env) {
      iris_envmap_destroy(out->envmap);
      free(out->envmap);
      out->envmap = NULL;
    }
  }
  size_t cap = emissive + scene->light_count + (env ? 1 : 0);
  out->light_base = malloc(sizeof(uint32_t) * (placements ? placements : 1));
  out->light_of_prim = malloc(sizeof(uint32_t) * (emissive ? emissive : 1));
  out->entries = calloc(cap ? cap : 1, sizeof *out->entries);
  if (!out->light_base || !out->light_of_prim || !out->entries) {
    iris_lights_destroy(out);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL,
                          "out of memory for the light list (%zu emissive triangles)", emissive);
  }
  size_t n = 0, slot = 0;
  for (size_t i = 0; i < placements; i++) add_emissive_placement(out, i, &n, &slot);
  for (size_t i = 0; i < scene->light_count; i++) {
    const iris_light *l = &scene->lights[i];
    if (!iris_lights_punctual_emits(l)) continue;
    iris_vec3 c = iris_scale(iris_v3_load(l->color), l->intensity);
    iris_light_entry *e = &out->entries[n];
    e->prim = (uint32_t)i;
    e->radiance = c;
    switch (l->type) {
      case IRIS_LIGHT_POINT:
        e->kind = IRIS_LIGHT_KIND_POINT;
        e->power = iris_luminance(c) * 4.0f * IRIS_PI;
        break;
      case IRIS_LIGHT_SPOT:
        e->kind = IRIS_LIGHT_KIND_SPOT;
        e->power = iris_luminance(c) * 2.0f * IRIS_PI *
                   (1.0f - cosf(0.5f * (l->inner_cone + l->outer_cone)));
        break;
      case IRIS_LIGHT_DIRECTIONAL:
      default:
        e->kind = IRIS_LIGHT_KIND_DIRECTIONAL;
        e->power = iris_luminance(c) * IRIS_PI * out->radius * out->radius;
        break;
    }
    n++;
  }
  if (env) {
    iris_light_entry *e = &out->entries[n];
    e->kind = IRIS_LIGHT_KIND_ENVIRONMENT;
    e->radiance = env_mean; /* a map's mean over the sphere */
    /* Power of a sky of this mean radiance through the scene's bounding sphere (pbrt-v4). */
    e->power = iris_luminance(e->radiance) * 4.0f * IRIS_PI * IRIS_PI * out->radius * out->radius;
    out->environment = (int32_t)n;
    n++;
  }
  out->count = n;
  if (n > 0 && build_groups(out, err) != IRIS_OK) {
    iris_lights_destroy(out);
    return err ? err->status : IRIS_ERR_NOMEM;
  }
  size_t tris = 0;
  while (tris < n && out->entries[tris].kind == IRIS_LIGHT_KIND_TRIANGLE) tris++;
  if (tris > 0) {
    out->tris = aligned_alloc(64, tris * sizeof *out->tris);
    if (!out->tris) {
      iris_lights_destroy(out);
      return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for the light list");
    }
    for (size_t i = 0; i < tris; i++) {
      const iris_light_entry *e = &out->entries[i];
      iris_light_tri *t = &out->tris[i];
      memset(t, 0, sizeof *t);
      iris_v3_store(e->v0, t->v0);
      iris_v3_store(e->e1, t->e1);
      iris_v3_store(e->e2, t->e2);
      t->area = e->area;
      t->pmf_in_group = entry_pmf_in_group(out, (uint32_t)i);
      t->material = iris_accel_triangle_material(accel, e->prim);
      t->flags = (e->two_sided ? IRIS_LIGHT_TRI_TWO_SIDED : 0u) |
                 (e->textured ? IRIS_LIGHT_TRI_TEXTURED : 0u) | (e->group << 8);
    }
    out->tri_count = tris;
    for (size_t k = 0; k < out->group_count; k++)
      if (out->groups[k].kind == IRIS_LIGHT_KIND_TRIANGLE && build_alias(out, &out->groups[k]) != IRIS_OK) {
        iris_lights_destroy(out);
        return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for the light list");
      }
  }
  if (n > 0) {
    float *w = malloc(sizeof(float) * n);
    if (!w) {
      iris_lights_destroy(out);
      return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for the light list");
    }
    double total = 0.0;
    for (size_t i = 0; i < n; i++) {
      w[i] = out->entries[i].power;
      total += w[i];
    }
    out->total_power = total;
    iris_status st = iris_distrib1d_create(&out->select, w, n, err);
    free(w);
    if (st != IRIS_OK) {
      iris_lights_destroy(out);
      return st;
    }
  }
  return IRIS_OK;
}

void iris_lights_destroy(iris_lights *lights) {
  if (!lights) return;
  iris_light_tree_destroy(lights->tree);
  free(lights->tree);
  lights->tree = NULL;
  for (size_t k = 0; k < lights->group_count; k++) iris_distrib1d_destroy(&lights->groups[k].select);
  free(lights->groups);
  lights->groups = NULL;
  lights->group_count = 0;
  free(lights->entries);
  free(lights->tris);
  lights->tris = NULL;
  lights->tri_count = 0;
  free(lights->light_of_prim);
  free(lights->light_base);
  lights->light_base = NULL;
  iris_distrib1d_destroy(&lights->select);
  iris_envmap_destroy(lights->envmap);
  free(lights->envmap);
  lights->envmap = NULL;
  lights->entries = NULL;
  lights->light_of_prim = NULL;
  lights->count = 0;
}

/* ---- the light tree's view of the entries (renderer/light_tree.h) --------- */

const char *iris_light_sampler_name(iris_light_sampler s) {
  return s == IRIS_LIGHT_SAMPLER_LEARNED ? "learned" : s == IRIS_LIGHT_SAMPLER_TREE ? "tree" : "power";
}
bool iris_light_sampler_parse(const char *name, iris_light_sampler *out) {
  for (int s = 0; s < IRIS_LIGHT_SAMPLER_COUNT; s++)
    if (strcmp(name, iris_light_sampler_name((iris_light_sampler)s)) == 0) {
      *out = (iris_light_sampler)s;
      return true;
    }
  return false;
}

/* Triangles: their box, one normal, Lambertian spread, power pi L A (x2 when
 * two-sided); points: every direction, 4 pi I; spots: the axis with the outer
 * cone as cutoff, 4 pi I (pbrt-v4's Bounds()); directional lights and the
 * environment beside the tree with the distance-free irradiance estimate of
 * the power sampler, times pi as the tree's importance of a facing
 * Lambertian emitter is pi times its irradiance. */
iris_light_bounds iris_lights_bounds(const iris_lights *L, uint32_t i) {
  iris_light_bounds b;
  memset(&b, 0, sizeof b);
  b.cluster = UINT32_MAX;
  const iris_light_entry *e = &L->entries[i];
  b.w = iris_v3(0, 0, 1);
  b.cos_o = 1.0f;
  switch (e->kind) {
    case IRIS_LIGHT_KIND_TRIANGLE: {
      iris_vec3 v1 = iris_add(e->v0, e->e1), v2 = iris_add(e->v0, e->e2);
      b.lo = iris_v3(fminf(e->v0.x, fminf(v1.x, v2.x)), fminf(e->v0.y, fminf(v1.y, v2.y)),
                     fminf(e->v0.z, fminf(v1.z, v2.z)));
      b.hi = iris_v3(fmaxf(e->v0.x, fmaxf(v1.x, v2.x)), fmaxf(e->v0.y, fmaxf(v1.y, v2.y)),
                     fmaxf(e->v0.z, fmaxf(v1.z, v2.z)));
      b.w = e->ng;
      b.cos_e = 0.0f;
      iris_interaction c; /* its mesh placement */
      iris_accel_surface_at(L->accel, e->prim, 0.0f, 0.0f, &c);
      b.cluster = c.instance;
      b.phi = e->power;
      b.two_sided = e->two_sided;
      break;
    }
    case IRIS_LIGHT_KIND_POINT:
    case IRIS_LIGHT_KIND_SPOT: {
      const iris_light *l = &L->scene->lights[e->prim];
      b.lo = b.hi = iris_v3_load(l->position);
      b.phi = 4.0f * IRIS_PI * iris_luminance(e->radiance);
      if (e->kind == IRIS_LIGHT_KIND_SPOT) {
        b.w = iris_normalize(iris_v3_load(l->direction));
        b.cos_e = cosf(fminf(l->outer_cone, IRIS_PI));
      } else {
        b.cos_o = -1.0f;
        b.cos_e = 0.0f;
      }
      break;
    }
    case IRIS_LIGHT_KIND_DIRECTIONAL:
      b.infinite = true;
      b.phi = IRIS_PI * iris_luminance(e->radiance);
      break;
    case IRIS_LIGHT_KIND_ENVIRONMENT:
    default:
      b.infinite = true;
      b.phi = IRIS_PI * IRIS_PI * iris_luminance(e->radiance);
      break;
  }
  return b;
}

iris_status iris_lights_set_sampler(iris_lights *L, iris_light_sampler s, iris_error *err) {
  if (L->tree) {
    iris_light_tree_destroy(L->tree);
    free(L->tree);
    L->tree = NULL;
  }
  memset(&L->learned, 0, sizeof L->learned); /* the renderer installs it again */
  if (s == IRIS_LIGHT_SAMPLER_POWER || L->count == 0) return IRIS_OK; /* learned mixes with the tree */
  iris_light_bounds *b = malloc(sizeof *b * L->count);
  L->tree = calloc(1, sizeof *L->tree);
  if (!b || !L->tree) {
    free(b);
    free(L->tree);
    L->tree = NULL;
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory for the light tree");
  }
  for (size_t i = 0; i < L->count; i++) b[i] = iris_lights_bounds(L, (uint32_t)i);
  /* the triangles of one mesh placement within 1/4 of the scene's radius may share a leaf */
  iris_status st = iris_light_tree_build(b, L->count, L->radius / 4.0f, L->tree, err);
  free(b);
  /* A tree of one leaf has no choice to make that the power sampler does not
   * make as well (one cluster chosen by power), only costs (a Cornell-box
   * sample 11% more): keep choosing by power (docs/rendering.md, "Light tree"). */
  if (st != IRIS_OK || L->tree->node_count <= 1) {
    iris_light_tree_destroy(L->tree);
    free(L->tree);
    L->tree = NULL;
  }
  return st;
}
