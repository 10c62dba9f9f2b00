/* Normal maps; see normal_map.h. */
#include "renderer/normal_map.h"

#include <math.h>

iris_vec3 iris_normal_map_apply(iris_vec3 t, iris_vec3 b, iris_vec3 n, const float rgb[3], float scale) {
  float x = (2.0f * rgb[0] - 1.0f) * scale, y = (2.0f * rgb[1] - 1.0f) * scale, z = 2.0f * rgb[2] - 1.0f;
  iris_vec3 m = iris_add(iris_add(iris_scale(t, x), iris_scale(b, y)), iris_scale(n, z));
  float len = iris_length(m);
  if (!(len > 1e-12f) || !isfinite(len)) return n;
  return iris_scale(m, 1.0f / len);
}

/* With ng as z and n in the x-z plane (x = n's part orthogonal to ng), a
 * normal n' = (sqrt(1 - z^2), z) reflects wo = (ix, iz) to a direction of
 * height 2 (n'.wo) z - iz. Asking for height t gives a quadratic in z^2:
 * with a = ix^2 + iz^2, b = sqrt(ix^2 (a - t^2)), c = iz t + a, the roots are
 * z^2 = (c +- b) / (2a). Of the roots in (0, 1] the one that really reflects
 * upwards is taken, the shallower reflection when both do. */
iris_vec3 iris_normal_make_valid(iris_vec3 ng, iris_vec3 wo, iris_vec3 n) {
  float ndotwo = iris_dot(n, wo);
  iris_vec3 r = iris_sub(iris_scale(n, 2.0f * ndotwo), wo);
  float t = fminf(0.9f * iris_dot(ng, wo), 0.01f);
  if (iris_dot(ng, r) >= t) return n;
  iris_vec3 xd = iris_sub(n, iris_scale(ng, iris_dot(n, ng)));
  float xl = iris_length(xd);
  if (!(xl > 0.0f)) return ng;
  iris_vec3 x = iris_scale(xd, 1.0f / xl);
  float ix = iris_dot(wo, x), iz = iris_dot(wo, ng);
  float a = ix * ix + iz * iz;
  if (!(a > 0.0f)) return ng;
  float disc = ix * ix * (a - t * t);
  float b = disc > 0.0f ? sqrtf(disc) : 0.0f;
  float c = iz * t + a;
  float z2[2] = {0.5f * (c + b) / a, 0.5f * (c - b) / a};
  bool ok[2];
  float h[2], nx[2], nz[2];
  for (int k = 0; k < 2; k++) {
    ok[k] = z2[k] > 1e-5f && z2[k] <= 1.0f + 1e-5f;
    nz[k] = sqrtf(fminf(fmaxf(z2[k], 0.0f), 1.0f));
    nx[k] = sqrtf(fmaxf(1.0f - nz[k] * nz[k], 0.0f));
    h[k] = 2.0f * (nx[k] * ix + nz[k] * iz) * nz[k] - iz; /* reflection height */
  }
  int pick;
  if (ok[0] && ok[1]) {
    bool up0 = h[0] >= 1e-5f, up1 = h[1] >= 1e-5f;
    pick = up0 && up1 ? (h[0] < h[1] ? 0 : 1) : (h[0] > h[1] ? 0 : 1);
  } else if (ok[0] || ok[1]) {
    pick = ok[0] ? 0 : 1;
  } else {
    return ng;
  }
  return iris_add(iris_scale(x, nx[pick]), iris_scale(ng, nz[pick]));
}
