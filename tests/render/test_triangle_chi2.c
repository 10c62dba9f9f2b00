/* Solid-angle sampling of triangles (renderer/sampling.h,
 * iris_sample_spherical_triangle) against its density 1 / solid angle, with
 * the shared chi-square harness, for small, large, grazing (the reference
 * point close to the triangle's plane), obtuse and nearly degenerate
 * triangles (the harness resolves slivers down to about 70:1: thinner ones
 * fail it with area sampling and its exact pdf too); the density
 * integrates to 1 over the sphere; and the solid
 * angle formula against the angle excess of the spherical triangle. */
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "chi2.h"
#include "renderer/sampling.h"

typedef struct tri_ctx {
  iris_vec3 a, b, c;
  double omega;
} tri_ctx;

static bool sample_fn(void *vc, const double u[3], double dir[3]) {
  tri_ctx *t = vc;
  iris_vec3 w;
  if (!iris_sample_spherical_triangle(t->a, t->b, t->c, (float)u[0], (float)u[1], &w)) return false;
  dir[0] = w.x, dir[1] = w.y, dir[2] = w.z;
  return true;
}

/* Does the ray from the origin along d cross the triangle? (double precision) */
static bool inside(const tri_ctx *t, const double d[3]) {
  const iris_vec3 v[3] = {t->a, t->b, t->c};
  double s[3];
  for (int i = 0; i < 3; i++) {
    iris_vec3 p = v[i], q = v[(i + 1) % 3];
    double n[3] = {(double)p.y * q.z - (double)p.z * q.y, (double)p.z * q.x - (double)p.x * q.z,
                   (double)p.x * q.y - (double)p.y * q.x};
    s[i] = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
  }
  bool pos = s[0] >= 0 && s[1] >= 0 && s[2] >= 0, neg = s[0] <= 0 && s[1] <= 0 && s[2] <= 0;
  if (!pos && !neg) return false;
  /* the triangle's side, not the antipodal one: the ray meets its plane at t > 0 */
  iris_vec3 n = iris_cross(iris_sub(t->b, t->a), iris_sub(t->c, t->a));
  double nd = n.x * d[0] + n.y * d[1] + n.z * d[2];
  return (double)iris_dot(n, t->a) / nd > 0.0;
}

static double pdf_fn(void *vc, const double dir[3]) {
  tri_ctx *t = vc;
  return inside(t, dir) ? 1.0 / t->omega : 0.0;
}

/* Girard: the solid angle is the spherical excess alpha + beta + gamma - pi. */
static double excess(iris_vec3 a, iris_vec3 b, iris_vec3 c) {
  iris_vec3 v[3] = {iris_normalize(a), iris_normalize(b), iris_normalize(c)};
  double sum = 0;
  for (int i = 0; i < 3; i++) {
    iris_vec3 p = v[i], q = v[(i + 1) % 3], r = v[(i + 2) % 3];
    iris_vec3 n1 = iris_normalize(iris_cross(p, q)), n2 = iris_normalize(iris_cross(p, r));
    sum += acos(fmax(-1.0, fmin(1.0, (double)iris_dot(n1, n2))));
  }
  return sum - IRIS_PI;
}

int main(void) {
  static const struct {
    const char *name;
    iris_vec3 a, b, c;
  } cases[] = {
      {"small, far", {-0.05f, 1, 0}, {0.05f, 1, 0}, {0, 1, 0.06f}},
      {"large, close", {-2, 0.3f, -2}, {2, 0.3f, -2}, {0, 0.3f, 2}},
      {"grazing (point 0.01 from the plane)", {-1, 0.01f, 0.05f}, {1, 0.01f, 0.05f}, {0, 0.01f, 2}},
      {"obtuse", {-1.5f, 0.5f, 0.2f}, {1.5f, 0.6f, 0.1f}, {0, 0.4f, 0.5f}},
      {"nearly degenerate sliver (70:1)", {-1, 1, 0}, {1, 1, 0}, {0, 1, 0.03f}},
      {"huge, surrounding half the sphere", {-50, 0.2f, -50}, {50, 0.2f, -50}, {0, 0.2f, 80}},
  };
  const int n = (int)(sizeof cases / sizeof cases[0]);
  for (int i = 0; i < n; i++) {
    tri_ctx t = {cases[i].a, cases[i].b, cases[i].c, 0};
    t.omega = iris_spherical_triangle_area(t.a, t.b, t.c);
    double ex = excess(t.a, t.b, t.c);
    iris_check_record(fabs(t.omega - ex) <= 2e-3 * ex + 1e-6, __FILE__, __LINE__,
                      "%s: solid angle %.6g, spherical excess %.6g", cases[i].name, t.omega, ex);
    chi2_domain dom = {CHI2_SPHERE, 64, 128, 77 + (uint64_t)i};
    chi2_result r = chi2_run(&dom, sample_fn, pdf_fn, &t, 400000, 0.01, n);
    iris_check_record(r.passed, __FILE__, __LINE__, "%s: %s", cases[i].name, r.message);
    iris_check_record(fabs(r.pdf_integral - 1.0) < 2e-2, __FILE__, __LINE__,
                      "%s: pdf integrates to %.4f", cases[i].name, r.pdf_integral);
    iris_check_record(r.lost < 400, __FILE__, __LINE__, "%s: %zu samples lost", cases[i].name, r.lost);
    printf("%-40s omega %.5g sr: p = %.3g, pdf integral %.4f, lost %zu\n", cases[i].name, t.omega,
           r.p_value, r.pdf_integral, r.lost);
  }
  /* A triangle that is a point or a segment as seen from the origin is refused. */
  iris_vec3 w;
  CHECK(!iris_sample_spherical_triangle(iris_v3(0, 1, 0), iris_v3(0, 2, 0), iris_v3(0, 3, 0), 0.3f, 0.6f, &w));
  return iris_check_summary("render.triangle_chi2");
}
