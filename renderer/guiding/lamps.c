/* Lamps behind glass: the cone sampler (lamps.h). */
#include "renderer/guiding/lamps.h"

iris_vec3 iris_lamp_cone_sample(const iris_lamp_cone *c, float u1, float u2) {
  /* 1 - cos(theta) uniform in [0, 1 - cos(max)] (uniform in solid angle);
   * sin from (1 - cos)(1 + cos), which keeps a small cone's directions exact. */
  float omc = u1 * c->one_minus_cos, cosv = 1.0f - omc;
  float sinv = sqrtf(fmaxf(0.0f, omc * (2.0f - omc)));
  float phi = 2.0f * 3.14159265358979f * u2;
  iris_frame f = iris_frame_from_normal(c->axis);
  iris_vec3 local = iris_v3(sinv * cosf(phi), sinv * sinf(phi), cosv);
  return iris_normalize(iris_frame_to_world(&f, local));
}
