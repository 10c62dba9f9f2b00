/* Lamps behind glass (docs/guiding.md, "Lamps behind glass"): light sampling
 * cannot cross a glass shade, and a cache texel is far larger than a small
 * bulb, but a flat slab passes light on along the direction it entered, so
 * from a wall point the bulb seen through the shade is (nearly) where it would
 * be without glass. The guide keeps the emitter groups' bounding spheres and
 * draws directions uniformly in the cone a sphere subtends; this is that cone's
 * sampler and its density, exact and cheap enough for every pdf evaluation. */
#ifndef IRIS_RENDERER_GUIDING_LAMPS_H
#define IRIS_RENDERER_GUIDING_LAMPS_H

#include <math.h>
#include <stdbool.h>

#include "core/math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Emitter groups a cache keeps shares of (the brightest first). */
#define IRIS_CACHE_LAMPS 4

/* An emitter group's bounding sphere (iris_light_group: the emissive
 * triangles of one instance); radius 0: not a lamp the cones can aim at. */
typedef struct iris_guide_lamp {
  iris_vec3 center;
  float radius;
} iris_guide_lamp;

/* The cone of directions from x that meet the sphere: unit axis and
 * 1 - cos of its half-angle (2 for a point inside the sphere: the whole
 * sphere of directions). */
typedef struct iris_lamp_cone {
  iris_vec3 axis;
  float one_minus_cos;
} iris_lamp_cone;

/* 1 - sqrt(1 - x) without the cancellation that loses a small cone's width in float. */
static inline float iris_lamp_one_minus_sqrt(float x) { return x / (1.0f + sqrtf(fmaxf(0.0f, 1.0f - x))); }

static inline iris_lamp_cone iris_lamp_cone_at(const iris_guide_lamp *l, iris_vec3 x) {
  iris_lamp_cone c;
  iris_vec3 d = iris_sub(l->center, x);
  float d2 = iris_dot(d, d), r2 = l->radius * l->radius;
  if (!(d2 > r2)) {
    c.axis = iris_v3(0.0f, 0.0f, 1.0f);
    c.one_minus_cos = 2.0f;
    return c;
  }
  c.axis = iris_scale(d, 1.0f / sqrtf(d2));
  c.one_minus_cos = iris_lamp_one_minus_sqrt(r2 / d2);
  return c;
}

/* Whether direction wi from x meets the sphere: its line passes within the
 * radius of the centre, ahead of x. The same set as the cone, tested by the
 * distance |d x wi| (comparing cosines in float loses a cone of 1e-4 sr), with
 * a rim of slack for the rounding of a drawn direction and of the cross
 * product (~1e-7 |d| per component): every drawn direction is inside. The
 * rim (a relative width of 1e-4 + 1e-6 |d|^2 / r^2 in r^2) is never drawn, so
 * light arriving there is underestimated; a group's bounding sphere is wider
 * than its lamp, so none arrives there but a little shifted by glass. */
static inline bool iris_lamp_contains(const iris_guide_lamp *l, iris_vec3 x, iris_vec3 wi) {
  iris_vec3 d = iris_sub(l->center, x);
  float r2 = l->radius * l->radius, d2 = iris_dot(d, d);
  if (!(d2 > r2)) return true;
  iris_vec3 c = iris_cross(d, wi);
  return iris_dot(d, wi) > 0.0f && iris_dot(c, c) <= (r2 * 1.0001f + 1e-6f * d2) * iris_dot(wi, wi);
}

/* Density of iris_lamp_cone_sample (uniform in the cone). */
static inline float iris_lamp_cone_pdf(const iris_lamp_cone *c) {
  return 1.0f / (2.0f * 3.14159265358979f * c->one_minus_cos);
}

/* A direction uniformly in the cone from two uniform numbers. */
iris_vec3 iris_lamp_cone_sample(const iris_lamp_cone *c, float u1, float u2);

#ifdef __cplusplus
}
#endif
#endif
