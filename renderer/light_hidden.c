/* Hidden share of the light tree's choices at what the camera sees: light_hidden.h. */
#include "renderer/light_hidden.h"

#include <math.h>

#include "core/rng.h"

static float unit(uint64_t h) { return (float)(h >> 40) * 0x1p-24f; }

double iris_lights_camera_hidden_share(const iris_lights *L, const iris_accel *accel, const iris_pinhole *cam,
                                       uint64_t seed, int *valid) {
  *valid = 0;
  if (!L->tree || L->count == 0) return 0.0;
  const int side = 64;
  int hidden = 0;
  for (int i = 0; i < IRIS_LIGHTS_HIDDEN_PROBES; ++i) {
    const uint64_t h0 = iris_hash4(seed, (uint64_t)i, 0x41dde7ULL, 0), h1 = iris_mix64(h0), h2 = iris_mix64(h1);
    const float fx = ((float)(i % side) + unit(h0)) / (float)side * (float)cam->width,
                fy = ((float)(i / side) + unit(h1)) / (float)side * (float)cam->height;
    iris_ray ray = iris_pinhole_ray(cam, fx, fy);
    iris_hit hit;
    if (!iris_accel_intersect(accel, &ray, &hit)) continue;
    iris_interaction si;
    iris_accel_interaction(accel, ray.d, &hit, &si);
    const iris_vec3 n = si.front ? si.ng : iris_neg(si.ng); /* the side the camera sees */
    uint32_t light;
    float pmf;
    if (!iris_light_tree_sample(L->tree, si.p, n, unit(h2), &light, &pmf)) continue;
    iris_light_choice ch = {light, pmf, true};
    iris_light_sample ls;
    if (!iris_lights_sample_choice(L, si.p, &ch, unit(iris_mix64(h2)), unit(iris_mix64(h2 ^ 0x5bd1e995ULL)), &ls))
      continue;
    if (!(iris_dot(ls.wi, n) > 0.0f)) continue;
    iris_ray r;
    if (isfinite(ls.dist) && !ls.delta) {
      r = iris_spawn_ray_to(si.p, n, ls.p, ls.n);
    } else {
      r.o = iris_offset_origin(si.p, n, ls.wi);
      r.d = ls.wi;
      r.tmin = 0.0f;
      r.tmax = isfinite(ls.dist) ? ls.dist * (1.0f - 1e-5f) : INFINITY;
    }
    (*valid)++;
    hidden += iris_accel_occluded(accel, &r);
  }
  return *valid ? (double)hidden / (double)*valid : 0.0;
}
