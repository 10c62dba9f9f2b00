/* core.math: matrix inverse, TRS, normal matrix and look-at against values
 * worked out by hand, orthonormal frames around many normals, and the inline
 * min/max against libm's fmaxf/fminf bit for bit. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "check.h"
#include "core/math.h"
#include "core/rng.h"

static iris_mat4 mat(const float v[16]) {
  iris_mat4 m;
  for (int i = 0; i < 16; i++) m.m[i / 4][i % 4] = v[i];
  return m;
}

static void check_mat(const iris_mat4 *a, const float want[16], float tol, const char *what) {
  for (int i = 0; i < 16; i++)
    if (!iris_check_record(fabsf(a->m[i / 4][i % 4] - want[i]) <= tol, __FILE__, __LINE__,
                           "%s: element [%d][%d] = %.9g, want %.9g", what, i / 4, i % 4,
                           a->m[i / 4][i % 4], want[i]))
      return;
}

static void test_inverse(void) {
  /* Scale (2, 4, 8) then translate (1, 2, 3): the inverse is scale 1/s and -t/s. */
  const float a[16] = {2, 0, 0, 1, 0, 4, 0, 2, 0, 0, 8, 3, 0, 0, 0, 1};
  const float ainv[16] = {0.5f, 0, 0, -0.5f, 0, 0.25f, 0, -0.5f, 0, 0, 0.125f, -0.375f, 0, 0, 0, 1};
  iris_mat4 m = mat(a), inv;
  CHECK(iris_mat4_inverse(&m, &inv));
  check_mat(&inv, ainv, 1e-7f, "inverse of scale+translate");

  /* 2x2 block [[1,2],[3,4]] has inverse [[-2,1],[1.5,-0.5]] (det -2); needs pivoting. */
  const float b[16] = {1, 2, 0, 0, 3, 4, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  const float binv[16] = {-2, 1, 0, 0, 1.5f, -0.5f, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  m = mat(b);
  CHECK(iris_mat4_inverse(&m, &inv));
  check_mat(&inv, binv, 1e-6f, "inverse of 2x2 block");

  /* Zero on the diagonal: [[0,1],[1,0]] permutation is its own inverse. */
  const float p[16] = {0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0};
  m = mat(p);
  CHECK(iris_mat4_inverse(&m, &inv));
  check_mat(&inv, p, 0.0f, "inverse of permutation");

  /* A general matrix: M * inv(M) = I. */
  const float g[16] = {3, -1, 2, 5, 0.5f, 4, -2, 1, 1, 1, 6, -3, 0.25f, -0.5f, 1, 2};
  m = mat(g);
  CHECK(iris_mat4_inverse(&m, &inv));
  iris_mat4 prod = iris_mat4_mul(&m, &inv);
  const float id[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  check_mat(&prod, id, 1e-5f, "M * inverse(M)");

  /* Singular: rows 0 and 1 equal. Output must stay untouched. */
  const float s[16] = {1, 2, 3, 4, 1, 2, 3, 4, 0, 0, 1, 0, 0, 0, 0, 1};
  m = mat(s);
  iris_mat4 keep = mat(id);
  CHECK(!iris_mat4_inverse(&m, &keep));
  check_mat(&keep, id, 0.0f, "output after singular inverse");
}

static void test_trs(void) {
  /* 90 degrees about +Z: q = (0, 0, sin 45, cos 45). R = [[0,-1,0],[1,0,0],[0,0,1]].
   * M = T R S with S = diag(2,3,4), T = (1,2,3): point (1,1,1) -> R(2,3,4) + T = (-3,2,4) + T. */
  const float t[3] = {1, 2, 3}, s[3] = {2, 3, 4};
  const float q[4] = {0, 0, 0.70710678f, 0.70710678f};
  iris_mat4 m = iris_mat4_trs(t, q, s);
  const float want[16] = {0, -3, 0, 1, 2, 0, 0, 2, 0, 0, 4, 3, 0, 0, 0, 1};
  check_mat(&m, want, 1e-6f, "TRS");
  iris_vec3 p = iris_mat4_point(&m, iris_v3(1, 1, 1));
  CHECK_NEAR(p.x, -2, 1e-6);
  CHECK_NEAR(p.y, 4, 1e-6);
  CHECK_NEAR(p.z, 7, 1e-6);
  iris_vec3 v = iris_mat4_vector(&m, iris_v3(1, 1, 1));
  CHECK_NEAR(v.x, -3, 1e-6);
  CHECK_NEAR(v.y, 2, 1e-6);
  CHECK_NEAR(v.z, 4, 1e-6);
  CHECK_NEAR(iris_mat4_det3(&m), 24, 1e-5); /* rotation det 1 times 2*3*4 */

  /* An unnormalised quaternion is normalised: 2*(0,0,sin45,cos45) gives the same matrix. */
  const float q2[4] = {0, 0, 1.41421356f, 1.41421356f};
  iris_mat4 m2 = iris_mat4_trs(t, q2, s);
  check_mat(&m2, want, 1e-6f, "TRS with unnormalised quaternion");

  /* 180 degrees about +Y (Avocado's root node): (x, y, z) -> (-x, y, -z). */
  const float qy[4] = {0, 1, 0, 0}, zero[3] = {0, 0, 0}, one[3] = {1, 1, 1};
  iris_mat4 my = iris_mat4_trs(zero, qy, one);
  p = iris_mat4_point(&my, iris_v3(1, 2, 3));
  CHECK_NEAR(p.x, -1, 1e-6);
  CHECK_NEAR(p.y, 2, 1e-6);
  CHECK_NEAR(p.z, -3, 1e-6);
}

static void test_normal_matrix(void) {
  /* Non-uniform scale: normals transform by diag(1/2, 1/3, 1/4), up to a positive factor. */
  const float t[3] = {5, 6, 7}, s[3] = {2, 3, 4}, q[4] = {0, 0, 0, 1};
  iris_mat4 m = iris_mat4_trs(t, q, s);
  iris_mat4 nm = iris_mat4_normal_matrix(&m);
  iris_vec3 n = iris_normalize(iris_mat4_vector(&nm, iris_v3(1, 1, 1)));
  iris_vec3 want = iris_normalize(iris_v3(0.5f, 1.0f / 3.0f, 0.25f));
  CHECK_NEAR(n.x, want.x, 1e-6);
  CHECK_NEAR(n.y, want.y, 1e-6);
  CHECK_NEAR(n.z, want.z, 1e-6);

  /* Mirror in x (det < 0): the inverse transpose is diag(-1, 1, 1), so +x normals flip. */
  const float sm[3] = {-1, 1, 1};
  iris_mat4 mm = iris_mat4_trs(t, q, sm);
  CHECK(iris_mat4_det3(&mm) < 0);
  iris_mat4 nmm = iris_mat4_normal_matrix(&mm);
  n = iris_mat4_vector(&nmm, iris_v3(1, 0, 0));
  CHECK(n.x < 0);
  CHECK_NEAR(n.y, 0, 1e-7);

  /* General matrices: a tangent t with dot(t, n) = 0 stays perpendicular to N n. */
  iris_sampler rs = iris_sampler_start(7, 0, 0);
  for (int trial = 0; trial < 200; trial++) {
    iris_mat4 g = iris_mat4_identity();
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 4; j++) g.m[i][j] = 4.0f * iris_sampler_next(&rs) - 2.0f;
    if (fabsf(iris_mat4_det3(&g)) < 0.05f) continue;
    iris_vec3 nn = iris_normalize(iris_v3(iris_sampler_next(&rs) - 0.5f, iris_sampler_next(&rs) - 0.5f, 0.3f));
    iris_frame f = iris_frame_from_normal(nn);
    iris_mat4 gn = iris_mat4_normal_matrix(&g);
    iris_vec3 n2 = iris_normalize(iris_mat4_vector(&gn, nn));
    iris_vec3 t1 = iris_normalize(iris_mat4_vector(&g, f.s));
    iris_vec3 t2 = iris_normalize(iris_mat4_vector(&g, f.t));
    CHECK_NEAR(iris_dot(n2, t1), 0, 1e-4);
    CHECK_NEAR(iris_dot(n2, t2), 0, 1e-4);
    /* Direction is that of the inverse transpose (positive multiple), also when det < 0. */
    iris_mat4 inv, invt;
    CHECK(iris_mat4_inverse(&g, &inv));
    invt = iris_mat4_transpose(&inv);
    iris_vec3 n3 = iris_normalize(iris_mat4_vector(&invt, nn));
    CHECK_NEAR(iris_dot(n2, n3), 1, 1e-4);
  }
}

static void test_look_at(void) {
  /* From (0,0,5) at the origin, up +Y: camera axes are the world axes, position (0,0,5). */
  iris_mat4 m = iris_mat4_look_at(iris_v3(0, 0, 5), iris_v3(0, 0, 0), iris_v3(0, 1, 0));
  const float want[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 5, 0, 0, 0, 1};
  check_mat(&m, want, 1e-6f, "look_at down -Z");
  /* Looking along +X from the origin: camera -Z maps to world +X, camera +Y to world +Y. */
  m = iris_mat4_look_at(iris_v3(0, 0, 0), iris_v3(3, 0, 0), iris_v3(0, 1, 0));
  iris_vec3 fwd = iris_mat4_vector(&m, iris_v3(0, 0, -1));
  iris_vec3 up = iris_mat4_vector(&m, iris_v3(0, 1, 0));
  CHECK_NEAR(fwd.x, 1, 1e-6);
  CHECK_NEAR(up.y, 1, 1e-6);
  /* Up parallel to the view direction still gives an orthonormal frame. */
  m = iris_mat4_look_at(iris_v3(0, 5, 0), iris_v3(0, 0, 0), iris_v3(0, 1, 0));
  CHECK(iris_mat4_is_finite(&m));
  CHECK_NEAR(iris_mat4_det3(&m), 1, 1e-5);
  fwd = iris_mat4_vector(&m, iris_v3(0, 0, -1));
  CHECK_NEAR(fwd.y, -1, 1e-6);
}

static void check_frame(iris_vec3 n) {
  iris_frame f = iris_frame_from_normal(n);
  int ok = fabsf(iris_length(f.s) - 1) < 1e-5f && fabsf(iris_length(f.t) - 1) < 1e-5f &&
           fabsf(iris_dot(f.s, f.t)) < 1e-5f && fabsf(iris_dot(f.s, f.n)) < 1e-5f &&
           fabsf(iris_dot(f.t, f.n)) < 1e-5f;
  iris_vec3 c = iris_cross(f.s, f.t);
  ok = ok && fabsf(c.x - n.x) < 1e-5f && fabsf(c.y - n.y) < 1e-5f && fabsf(c.z - n.z) < 1e-5f;
  iris_vec3 v = iris_v3(0.3f, -0.7f, 0.2f);
  iris_vec3 back = iris_frame_to_world(&f, iris_frame_to_local(&f, v));
  ok = ok && fabsf(back.x - v.x) < 1e-5f && fabsf(back.y - v.y) < 1e-5f && fabsf(back.z - v.z) < 1e-5f;
  iris_vec3 ln = iris_frame_to_local(&f, n);
  ok = ok && fabsf(ln.z - 1) < 1e-5f;
  iris_check_record(ok, __FILE__, __LINE__, "frame around (%.9g, %.9g, %.9g) is not orthonormal/right-handed",
                    n.x, n.y, n.z);
}

static void test_frames(void) {
  check_frame(iris_v3(0, 0, 1));
  check_frame(iris_v3(0, 0, -1));
  check_frame(iris_v3(1, 0, 0));
  check_frame(iris_v3(0, -1, 0));
  check_frame(iris_normalize(iris_v3(1e-4f, 0, -1)));
  iris_sampler rs = iris_sampler_start(3, 1, 0);
  for (int i = 0; i < 20000; i++) {
    float z = 2 * iris_sampler_next(&rs) - 1, phi = 2 * IRIS_PI * iris_sampler_next(&rs);
    float r = sqrtf(fmaxf(0, 1 - z * z));
    check_frame(iris_v3(r * cosf(phi), r * sinf(phi), z));
  }
}

static uint32_t float_bits(float f) {
  uint32_t u;
  memcpy(&u, &f, sizeof u);
  return u;
}

/* iris_fmaxf / iris_fminf replace glibc's calls on the render path and must
 * give its results bit for bit (the images stay the same): the special values
 * (signed zeros, quiet NaNs, infinities, a subnormal) in every pair, then
 * random bit patterns, a third of them equal pairs; signalling NaNs are
 * excluded, where glibc returns a NaN (core/math.h). Through volatile
 * pointers, so that libm's own functions are called. */
static void test_min_max(void) {
  float (*volatile lmax)(float, float) = fmaxf, (*volatile lmin)(float, float) = fminf;
  const float sp[] = {0.0f, -0.0f, 1.0f, -1.0f, NAN, -NAN, INFINITY, -INFINITY, 1e-40f, 3.5f};
  const int n = (int)(sizeof sp / sizeof sp[0]);
  int bad = 0, tested = 0;
  for (int k = -n * n; k < 2000000; k++) {
    float a, b;
    if (k < 0) {
      a = sp[(k + n * n) / n];
      b = sp[(k + n * n) % n];
    } else {
      uint64_t h = iris_mix64((uint64_t)k + 1);
      uint32_t ua = (uint32_t)h, ub = (uint32_t)(h >> 32);
      memcpy(&a, &ua, sizeof a);
      memcpy(&b, &ub, sizeof b);
      if (k % 3 == 0) b = a;
      if ((a != a && !(ua & 0x400000u)) || (b != b && !(float_bits(b) & 0x400000u))) continue;
    }
    const float want[2] = {lmax(a, b), lmin(a, b)}, got[2] = {iris_fmaxf(a, b), iris_fminf(a, b)};
    for (int i = 0; i < 2; i++) {
      const bool same = (want[i] != want[i] && got[i] != got[i]) || float_bits(want[i]) == float_bits(got[i]);
      if (!same && bad++ < 4)
        iris_check_record(false, __FILE__, __LINE__, "%s(%08x, %08x): libm %08x, inline %08x", i ? "min" : "max",
                          float_bits(a), float_bits(b), float_bits(want[i]), float_bits(got[i]));
    }
    tested++;
  }
  CHECK(bad == 0);
  CHECK(tested > 1900000);
}

int main(void) {
  test_min_max();
  test_inverse();
  test_trs();
  test_normal_matrix();
  test_look_at();
  test_frames();
  return TEST_SUMMARY();
}
