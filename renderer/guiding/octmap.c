/* Octahedral maps: thesis eqs. 4.1-4.2 with z as the up axis, exact texel solid
 * angles and uniform sampling inside a texel (docs/guiding.md, "Octahedral map"). */
#include "renderer/guiding/octmap.h"

#include <math.h>
#include <stdlib.h>

#define PI_D 3.14159265358979323846

/* Point on the unit octahedron |x|+|y|+|z| = 1 for continuous texel
 * coordinates (u, v): (a, b) in [-1,1]^2 is the thesis's rotated square,
 * x = (a+b)/2, y = (b-a)/2 (inverse of a = x-y, b = x+y). The lower half of a
 * sphere map is mirrored in a so the two halves meet along the equator. */
static void octahedron_point(int res, double u, double v, double p[3]) {
  double a, sign = 1.0;
  if (u <= res) {
    a = 2.0 * u / res - 1.0;
  } else {
    a = 1.0 - 2.0 * (u - res) / res;
    sign = -1.0;
  }
  double b = 2.0 * v / res - 1.0;
  double x = 0.5 * (a + b), y = 0.5 * (b - a);
  p[0] = x;
  p[1] = y;
  p[2] = sign * fmax(0.0, 1.0 - fabs(x) - fabs(y));
}

double iris_octmap_triangle_solid_angle(const double a[3], const double b[3], const double c[3]) {
  double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
  double lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  double bxc[3] = {b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2], b[0] * c[1] - b[1] * c[0]};
  double triple = fabs(a[0] * bxc[0] + a[1] * bxc[1] + a[2] * bxc[2]);
  double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  double ac = a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
  double bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2];
  double den = la * lb * lc + ab * lc + ac * lb + bc * la;
  return 2.0 * atan2(triple, den);
}

/* The four triangles of texel (i, j): apex at the centre, base one texel edge.
 * Each lies on a single octahedron face because face boundaries (x = 0, y = 0,
 * i.e. a = -b, a = b) only ever run along texel diagonals. */
static void texel_triangles(int res, int i, int j, double tri[4][3][3]) {
  double c[3], p[4][3];
  octahedron_point(res, i + 0.5, j + 0.5, c);
  /* The centre of a lower-half texel uses the lower branch even at u = res. */
  octahedron_point(res, i, j, p[0]);
  octahedron_point(res, i + 1, j, p[1]);
  octahedron_point(res, i + 1, j + 1, p[2]);
  octahedron_point(res, i, j + 1, p[3]);
  if (i >= res) { /* corners on u = res belong to the equator: z = 0 either way */
    for (int k = 0; k < 4; ++k)
      if (p[k][2] > 0.0) p[k][2] = -p[k][2];
  }
  for (int k = 0; k < 4; ++k) {
    for (int d = 0; d < 3; ++d) {
      tri[k][0][d] = c[d];
      tri[k][1][d] = p[k][d];
      tri[k][2][d] = p[(k + 1) & 3][d];
    }
  }
}

iris_status iris_octmap_create(iris_octmap *map, int res, bool sphere, iris_error *err) {
  map->solid_angle = NULL;
  if (res < 1 || res > IRIS_OCTMAP_MAX_RES)
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, "guiding",
                          "octahedral map resolution %d outside [1, %d]", res, IRIS_OCTMAP_MAX_RES);
  map->res = res;
  map->sphere = sphere;
  map->width = sphere ? 2 * res : res;
  map->height = res;
  map->texel_count = (uint32_t)map->width * (uint32_t)map->height;
  map->solid_angle = malloc(sizeof(double) * map->texel_count);
  if (!map->solid_angle) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory");
  for (int j = 0; j < map->height; ++j) {
    for (int i = 0; i < map->width; ++i) {
      double tri[4][3][3];
      texel_triangles(res, i, j, tri);
      double sum = 0.0;
      for (int k = 0; k < 4; ++k) sum += iris_octmap_triangle_solid_angle(tri[k][0], tri[k][1], tri[k][2]);
      map->solid_angle[(size_t)j * map->width + i] = sum;
    }
  }
  return IRIS_OK;
}

void iris_octmap_destroy(iris_octmap *map) {
  free(map->solid_angle);
  map->solid_angle = NULL;
}

bool iris_octmap_dir_to_uv(const iris_octmap *map, iris_vec3 d, float *u, float *v) {
  if (!map->sphere && d.z < 0.0f) return false;
  float l1 = fabsf(d.x) + fabsf(d.y) + fabsf(d.z);
  float x = d.x / l1, y = d.y / l1; /* eq. 4.1 */
  float a = x - y, b = x + y;       /* eq. 4.2, rotated square in [-1,1]^2 */
  float n = (float)map->res;
  float uu = d.z >= 0.0f ? 0.5f * (a + 1.0f) * n : n + 0.5f * (1.0f - a) * n;
  float vv = 0.5f * (b + 1.0f) * n;
  /* Keep the exact upper edges inside the last texel. */
  float wmax = nextafterf((float)map->width, 0.0f), hmax = nextafterf((float)map->height, 0.0f);
  *u = iris_clampf(uu, 0.0f, wmax);
  *v = iris_clampf(vv, 0.0f, hmax);
  return true;
}

int32_t iris_octmap_dir_to_texel(const iris_octmap *map, iris_vec3 d) {
  float u, v;
  if (!iris_octmap_dir_to_uv(map, d, &u, &v)) return -1;
  int i = (int)u, j = (int)v;
  if (i >= map->width) i = map->width - 1;
  if (j >= map->height) j = map->height - 1;
  return j * map->width + i;
}

iris_vec3 iris_octmap_uv_to_dir(const iris_octmap *map, float u, float v) {
  double p[3];
  octahedron_point(map->res, u, v, p);
  double l = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
  return iris_v3((float)(p[0] / l), (float)(p[1] / l), (float)(p[2] / l));
}

iris_vec3 iris_octmap_texel_to_dir(const iris_octmap *map, uint32_t texel, float s, float t) {
  uint32_t i = texel % (uint32_t)map->width, j = texel / (uint32_t)map->width;
  float u = (float)i + s, v = (float)j + t;
  if (i >= (uint32_t)map->res && u <= (float)map->res) u = nextafterf((float)map->res, 2.0f * map->res);
  return iris_octmap_uv_to_dir(map, u, v);
}

/* ---- uniform sampling of a spherical triangle (Arvo 1995), in double ---- */

static void v_norm(double v[3]) {
  double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (l > 0.0) {
    v[0] /= l;
    v[1] /= l;
    v[2] /= l;
  }
}
static double v_dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void v_cross(const double a[3], const double b[3], double r[3]) {
  r[0] = a[1] * b[2] - a[2] * b[1];
  r[1] = a[2] * b[0] - a[0] * b[2];
  r[2] = a[0] * b[1] - a[1] * b[0];
}
/* Angle between unit vectors, accurate for small and large angles. */
static double angle_between(const double a[3], const double b[3]) {
  double d = v_dot(a, b);
  if (d < 0.0) {
    double s[3] = {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
    return PI_D - 2.0 * asin(fmin(1.0, sqrt(v_dot(s, s)) * 0.5));
  }
  double s[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
  return 2.0 * asin(fmin(1.0, sqrt(v_dot(s, s)) * 0.5));
}
/* Component of v orthogonal to unit w, normalised. */
static void gram_schmidt(const double v[3], const double w[3], double r[3]) {
  double d = v_dot(v, w);
  for (int k = 0; k < 3; ++k) r[k] = v[k] - d * w[k];
  v_norm(r);
}

static void sample_spherical_triangle(const double va[3], const double vb[3], const double vc[3],
                                      double u0, double u1, double out[3]) {
  double a[3] = {va[0], va[1], va[2]}, b[3] = {vb[0], vb[1], vb[2]}, c[3] = {vc[0], vc[1], vc[2]};
  v_norm(a);
  v_norm(b);
  v_norm(c);
  double nab[3], nbc[3], nca[3];
  v_cross(a, b, nab);
  v_cross(b, c, nbc);
  v_cross(c, a, nca);
  v_norm(nab);
  v_norm(nbc);
  v_norm(nca);
  double neg_ca[3] = {-nca[0], -nca[1], -nca[2]};
  double neg_ab[3] = {-nab[0], -nab[1], -nab[2]};
  double neg_bc[3] = {-nbc[0], -nbc[1], -nbc[2]};
  double alpha = angle_between(nab, neg_ca);
  double beta = angle_between(nbc, neg_ab);
  double gamma = angle_between(nca, neg_bc);
  double area_pi = alpha + beta + gamma;
  double ap_pi = PI_D + u0 * (area_pi - PI_D); /* sub-triangle area + pi */
  double cos_alpha = cos(alpha), sin_alpha = sin(alpha);
  double sin_phi = sin(ap_pi) * cos_alpha - cos(ap_pi) * sin_alpha;
  double cos_phi = cos(ap_pi) * cos_alpha + sin(ap_pi) * sin_alpha;
  double k1 = cos_phi + cos_alpha;
  double k2 = sin_phi - sin_alpha * v_dot(a, b);
  double den = (k2 * sin_phi + k1 * cos_phi) * sin_alpha;
  double cos_bp = den != 0.0 ? (k2 + (k2 * cos_phi - k1 * sin_phi) * cos_alpha) / den : 1.0;
  cos_bp = fmin(1.0, fmax(-1.0, cos_bp));
  double sin_bp = sqrt(fmax(0.0, 1.0 - cos_bp * cos_bp));
  double cperp[3], cp[3];
  gram_schmidt(c, a, cperp);
  for (int k = 0; k < 3; ++k) cp[k] = cos_bp * a[k] + sin_bp * cperp[k];
  double cos_t = 1.0 - u1 * (1.0 - v_dot(cp, b));
  double sin_t = sqrt(fmax(0.0, 1.0 - cos_t * cos_t));
  double cpperp[3];
  gram_schmidt(cp, b, cpperp);
  for (int k = 0; k < 3; ++k) out[k] = cos_t * b[k] + sin_t * cpperp[k];
  v_norm(out);
}

iris_vec3 iris_octmap_sample_in_texel(const iris_octmap *map, uint32_t texel, float u0, float u1,
                                      float u2) {
  int i = (int)(texel % (uint32_t)map->width), j = (int)(texel / (uint32_t)map->width);
  double tri[4][3][3], w[4], total = 0.0;
  texel_triangles(map->res, i, j, tri);
  for (int k = 0; k < 4; ++k) {
    w[k] = iris_octmap_triangle_solid_angle(tri[k][0], tri[k][1], tri[k][2]);
    total += w[k];
  }
  double x = (double)u0 * total;
  int k = 0;
  while (k < 3 && x >= w[k]) {
    x -= w[k];
    ++k;
  }
  double out[3];
  sample_spherical_triangle(tri[k][0], tri[k][1], tri[k][2], u1, u2, out);
  return iris_v3((float)out[0], (float)out[1], (float)out[2]);
}
