/* Private to the light list: what its build (light_build.c) and its sampling
 * and evaluation (lights.c) share. Not a public interface. */
#ifndef IRIS_RENDERER_LIGHTS_PRIVATE_H
#define IRIS_RENDERER_LIGHTS_PRIVATE_H

#include "renderer/lights.h"

static inline bool is_emissive(const iris_material *m) {
  return m && (m->emission[0] > 0.0f || m->emission[1] > 0.0f || m->emission[2] > 0.0f);
}

static inline const iris_material *material_of(const iris_scene *scene, int32_t index) {
  return index >= 0 && (size_t)index < scene->material_count ? &scene->materials[index] : NULL;
}

/* Probability of entry `index` within its group. */
static inline float entry_pmf_in_group(const iris_lights *L, uint32_t index) {
  const iris_light_group *g = &L->groups[L->entries[index].group];
  return g->count > 1 ? iris_distrib1d_pmf(&g->select, index - g->first) : 1.0f;
}

#endif
