/* The guide's budget and the rules that skip it (docs/guiding.md, "Budget
 * (scene-driven defaults) and skipping" and "--method auto"), shared by the
 * build in guiding.c and the rules in rules.c: how many caches, photons and
 * texels a scene gets, the pilot that decides before the full photon pass is
 * paid for, and the "lit mostly directly" rules with their exceptions (glints,
 * light focused through glass). Internal to renderer/guiding. */
#ifndef IRIS_RENDERER_GUIDING_RULES_H
#define IRIS_RENDERER_GUIDING_RULES_H

#include <stdbool.h>
#include <stddef.h>

#include "core/error.h"
#include "renderer/guiding/guiding.h"
#include "renderer/guiding/photons.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A camera ray's first non-specular hit (thesis 4.2.2), one per stride x
 * stride pixels: where camera caches go, and what the pilot checks is there. */
typedef struct iris_guide_seed_point {
  iris_vec3 p, n;
  uint8_t valid, transmits;
} iris_guide_seed_point;

/* The seed points of a cols x rows grid (row-major; malloc'd, NULL when out
 * of memory) and how many are valid. In guiding.c. */
iris_guide_seed_point *iris_guiding_camera_points(const iris_guide_setup *s, int stride, int *cols, int *rows,
                                                  size_t *valid);

/* Share of the environment in the lights' power (photon emission by power). */
double iris_guiding_environment_share(const iris_lights *L);
/* Fills the parameters left to the scene (<= 0 or < 0: caches, texels, k,
 * photons, floor, alpha cap) and the camera caches' pixel stride. */
void iris_guiding_choose_budget(iris_guiding_params *p, const iris_guide_setup *s, int *stride);
/* Marks the guide skipped, with the reason the stats report. */
void iris_guiding_skip(iris_guiding *g, const char *why);
/* Decides before paying: traces the pilot's photons into *photons (which the
 * full pass extends; empty and destroyed when the guide is skipped, or when
 * nothing decides) and skips the guide where a rule says so. camera_points:
 * the valid seed points of the camera caches (iris_guiding_camera_points; 0:
 * the camera sees nothing but mirrors and glass). */
iris_status iris_guiding_pilot(iris_guiding *g, const iris_guide_setup *s, size_t camera_points,
                               iris_photon_map *photons, iris_error *err);
/* The same rules on the full pass's photons (for a build without a pilot):
 * true when the guide was skipped. Sets the stats' indirect share. */
bool iris_guiding_declines(iris_guiding *g, const iris_guide_setup *s, const iris_photon_map *photons);

#ifdef __cplusplus
}
#endif

#endif
