/* importers/triangulate: large simple polygons are ear-clipped exactly within
 * the default budget (triangles cover the polygon once, none flipped);
 * polygons without ears (corners drawn from a few points, collinear runs)
 * still give n - 2 triangles whose signed areas add up to the polygon's, with
 * work at most the budget (steps per corner), the rest fanned; a tiny budget
 * forces the fan on a simple polygon with the same guarantees. */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "importers/triangulate.h"

static uint64_t rng = 0x2545F4914F6CDD1Dull;
static double uniform(void) {
  rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
  return (double)(rng >> 11) / 9007199254740992.0;
}

enum { NMAX = 8192 };
static float pos[3 * NMAX];
static uint32_t corners[NMAX], tris[3 * NMAX];

static void star(uint32_t n) {
  for (uint32_t i = 0; i < n; i++) {
    const double a = 2 * 3.14159265358979 * (i + 0.3 * uniform()) / n, r = 0.2 + uniform();
    pos[3 * i] = (float)(r * cos(a)), pos[3 * i + 1] = (float)(r * sin(a)), pos[3 * i + 2] = 0;
  }
}

static void comb(uint32_t n) { /* (0,0) -> (T,0) -> teeth back along the top */
  const uint32_t teeth = (n - 2) / 2;
  for (uint32_t i = 0; i < n; i++) {
    double x = 0, y = 0;
    if (i == 1) x = teeth;
    else if (i >= 2) {
      const uint32_t k = i - 2, j = teeth - k / 2;
      x = (k % 2 == 0) ? j : j - 0.5, y = (k % 2 == 0) ? 2 : 1;
    }
    pos[3 * i] = (float)x, pos[3 * i + 1] = (float)y, pos[3 * i + 2] = 0;
  }
}

static void repeated(uint32_t n) { /* like shared/fuzz-findings/ply-degenerate-ngons.ply */
  static float px[NMAX], py[NMAX];
  const uint32_t m = n / 3;
  for (uint32_t k = 0; k < m; k++) px[k] = (float)uniform(), py[k] = (float)uniform();
  for (uint32_t i = 0; i < n; i++) {
    const uint32_t k = (uint32_t)(uniform() * m);
    pos[3 * i] = px[k], pos[3 * i + 1] = py[k], pos[3 * i + 2] = 0;
  }
}

static void collinear(uint32_t n) {
  for (uint32_t i = 0; i < n; i++) pos[3 * i] = (float)i, pos[3 * i + 1] = i % 97 == 0 ? 1.0f : 0.0f, pos[3 * i + 2] = 0;
}

static double cross(uint32_t a, uint32_t b, uint32_t c) {
  return ((double)pos[3 * b] - pos[3 * a]) * ((double)pos[3 * c + 1] - pos[3 * a + 1]) -
         ((double)pos[3 * b + 1] - pos[3 * a + 1]) * ((double)pos[3 * c] - pos[3 * a]);
}

/* Triangulates corners 0..n-1 with the given budget; checks the output and
 * returns the stats of this one call. exact: also no overlap, none flipped. */
static iris_triangulate_stats run(uint32_t n, uint32_t budget, bool exact, const char *what) {
  iris_polygon_triangulator *t = iris_polygon_triangulator_create();
  if (budget) iris_polygon_triangulator_set_budget(t, budget, IRIS_TRIANGULATE_FILE_STEPS_PER_CORNER);
  for (uint32_t i = 0; i < n; i++) corners[i] = i;
  const uint32_t nt = iris_polygon_triangulate(t, pos, corners, n, tris);
  const iris_triangulate_stats st = iris_polygon_triangulator_stats(t);
  iris_polygon_triangulator_destroy(t);
  CHECK_EQ_INT(nt, n - 2);
  double poly = 0, signed_sum = 0, abs_sum = 0;
  for (uint32_t i = 0; i < n; i++) {
    const uint32_t j = (i + 1) % n;
    poly += (double)pos[3 * i] * pos[3 * j + 1] - (double)pos[3 * j] * pos[3 * i + 1];
  }
  int bad = 0, flipped = 0;
  for (uint32_t k = 0; k < nt; k++) {
    const uint32_t a = tris[3 * k], b = tris[3 * k + 1], c = tris[3 * k + 2];
    if (a >= n || b >= n || c >= n || a == b || b == c || a == c) {
      bad++;
      continue;
    }
    const double cr = cross(a, b, c);
    signed_sum += cr, abs_sum += fabs(cr);
    if (cr * poly < 0) flipped++;
  }
  CHECK_EQ_INT(bad, 0);
  /* Any decomposition into triangles of the boundary's corners keeps the
   * signed area; an exact triangulation also has no overlap or flip. */
  const double scale = fmax(fabs(poly), 1e-3 * abs_sum + 1e-12);
  CHECK_NEAR(signed_sum / scale, poly / scale, 1e-6);
  if (exact) {
    CHECK_EQ_INT(flipped, 0);
    CHECK_NEAR(abs_sum / fabs(poly), 1.0, 1e-6);
  }
  const uint32_t k = budget ? budget : IRIS_TRIANGULATE_STEPS_PER_CORNER;
  printf("%-10s n=%5u budget %4u/corner: %8.1f steps/corner, %s\n", what, n, k, (double)st.steps / n,
         st.fallbacks ? "rest fanned" : "ear-clipped");
  /* The work bound of triangulate.h (+ one ear test's overrun and the fan). */
  CHECK(st.steps <= (uint64_t)(k + 8) * n + IRIS_TRIANGULATE_STEPS_BASE);
  return st;
}

int main(void) {
  /* Simple polygons up to 1024 corners are ear-clipped exactly by default. */
  for (uint32_t n = 16; n <= 1024; n *= 4) {
    star(n);
    CHECK_EQ_INT(run(n, 0, true, "star").fallbacks, 0);
    comb(n);
    CHECK_EQ_INT(run(n, 0, true, "comb").fallbacks, 0);
  }
  /* Beyond the budget the rest is fanned: still n - 2 triangles, signed area kept. */
  star(8192);
  run(8192, 0, false, "star");
  star(256);
  CHECK_EQ_INT(run(256, 2, false, "star").fallbacks, 1);
  /* No ears: bounded work whatever n. */
  for (uint32_t n = 300; n <= 8000; n *= 3) {
    repeated(n);
    CHECK_EQ_INT(run(n, 0, false, "repeated").fallbacks, 1);
    collinear(n);
    run(n, 0, false, "collinear");
  }
  return TEST_SUMMARY();
}
