/* The sky through one refracting plane ("Sky through a pane", docs/guiding.md):
 * a window modelled as a single glass quad bends the sky's light once, so the
 * radiance arriving in the room from direction w_room is the map's along the
 * direction that plane refracts it into, and the map's importance sampling,
 * carried through that refraction, finds the sun behind the pane. n is the
 * plane's unit normal on the sky's side, eta = n_room / n_sky (the relative
 * index the light enters with). Directions point away from the surface that
 * receives the light (towards the sky). */
#ifndef IRIS_RENDERER_GUIDING_PANE_H
#define IRIS_RENDERER_GUIDING_PANE_H

#include <math.h>
#include <stdbool.h>

#include "core/math.h"

/* The room-side direction of sky direction w_sky (unit); false where no light
 * from w_sky passes the plane into the room (w_sky below the plane, or eta < 1
 * and w_sky outside the cone the room side can receive). */
static inline bool iris_pane_to_room(iris_vec3 n, float eta, iris_vec3 w_sky, iris_vec3 *w_room) {
  const float c = iris_dot(w_sky, n);
  if (!(c > 0.0f) || !(eta > 0.0f)) return false;
  const iris_vec3 t = iris_scale(iris_sub(w_sky, iris_scale(n, c)), 1.0f / eta);
  const float t2 = iris_dot(t, t);
  if (!(t2 < 1.0f)) return false;
  *w_room = iris_normalize(iris_add(t, iris_scale(n, sqrtf(1.0f - t2))));
  return true;
}

/* The inverse: the sky direction light arriving along w_room (unit) came
 * from, and *jacobian = d omega_sky / d omega_room = eta^2 cos_room / cos_sky
 * (the etendue n^2 cos d omega is kept), so that a density p over sky
 * directions is p(w_sky) * *jacobian over room directions. False where the
 * room side cannot see the sky through the plane (below it, or beyond the
 * critical angle). */
static inline bool iris_pane_to_sky(iris_vec3 n, float eta, iris_vec3 w_room, iris_vec3 *w_sky, float *jacobian) {
  const float c = iris_dot(w_room, n);
  if (!(c > 0.0f) || !(eta > 0.0f)) return false;
  const iris_vec3 t = iris_scale(iris_sub(w_room, iris_scale(n, c)), eta);
  const float t2 = iris_dot(t, t);
  if (!(t2 < 1.0f)) return false;
  const float co = sqrtf(1.0f - t2);
  if (!(co > 1e-6f)) return false;
  *w_sky = iris_normalize(iris_add(t, iris_scale(n, co)));
  *jacobian = eta * eta * c / co;
  return true;
}

#endif
