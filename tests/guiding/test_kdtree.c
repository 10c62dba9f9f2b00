/* kd-tree k-NN against brute force, including duplicates and ties. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "renderer/guiding/kdtree.h"
#include "renderer/guiding/pickgrid.h"

static int failures = 0;

static int cmp_pair(const void *a, const void *b) {
  const float *x = a, *y = b;
  if (x[0] != y[0]) return x[0] < y[0] ? -1 : 1;
  return x[1] < y[1] ? -1 : (x[1] > y[1]);
}

static void run(uint32_t n, int grid, uint64_t seed) {
  iris_vec3 *pts = malloc(sizeof(iris_vec3) * n);
  for (uint32_t i = 0; i < n; ++i) {
    iris_sampler s = iris_sampler_start(seed, i, 0);
    float x = iris_sampler_next(&s), y = iris_sampler_next(&s), z = iris_sampler_next(&s);
    if (grid) { /* many duplicates and equal distances */
      x = floorf(x * 4) / 4;
      y = floorf(y * 4) / 4;
      z = 0.0f;
    }
    pts[i] = iris_v3(x, y, z);
  }
  iris_kdtree t;
  if (iris_kdtree_build(&t, pts, sizeof(iris_vec3), n, NULL) != IRIS_OK) {
    ++failures;
    return;
  }
  float (*brute)[2] = malloc(sizeof(float) * 2 * n);
  uint32_t ids[40];
  float d2[40];
  for (int q = 0; q < 200; ++q) {
    iris_sampler s = iris_sampler_start(seed + 1, (uint64_t)q, 0);
    iris_vec3 p = iris_v3(iris_sampler_next(&s) * 1.2f - 0.1f, iris_sampler_next(&s), grid ? 0.0f : iris_sampler_next(&s));
    uint32_t k = 1 + (uint32_t)q % 40;
    float maxd2 = (q % 3 == 0) ? 0.05f : INFINITY;
    uint32_t got = iris_kdtree_knn(&t, p, k, maxd2, ids, d2);
    uint32_t m = 0;
    for (uint32_t i = 0; i < n; ++i) {
      iris_vec3 d = iris_sub(pts[i], p);
      float dd = d.x * d.x + d.y * d.y + d.z * d.z;
      if (dd <= maxd2) {
        brute[m][0] = dd;
        brute[m][1] = (float)i;
        ++m;
      }
    }
    qsort(brute, m, sizeof brute[0], cmp_pair);
    uint32_t want = m < k ? m : k;
    if (got != want) {
      fprintf(stderr, "FAIL n=%u q=%d: got %u neighbours, want %u\n", n, q, got, want);
      ++failures;
      continue;
    }
    for (uint32_t i = 0; i < got; ++i) {
      if (ids[i] != (uint32_t)brute[i][1] || d2[i] != brute[i][0]) {
        fprintf(stderr, "FAIL n=%u q=%d rank %u: id %u d2 %g, want %u %g\n", n, q, i, ids[i], d2[i],
                (uint32_t)brute[i][1], brute[i][0]);
        ++failures;
        break;
      }
    }
  }
  free(brute);
  iris_kdtree_destroy(&t);
  free(pts);
}

/* The pick grid answers, for any point, exactly what the kd-tree answers for
 * the centre of the point's cell (same ids, same tie order; the centre is
 * computed here from the grid's origin and cell size), and points outside the
 * grid have no point within the radius. Points lie on the six faces of a
 * 4 x 3 x 2 box, some duplicated (ties). */
static void run_grid(uint32_t n, float radius, uint64_t seed) {
  iris_vec3 *pts = malloc(sizeof(iris_vec3) * n);
  const float ext[3] = {4.0f, 3.0f, 2.0f};
  for (uint32_t i = 0; i < n; ++i) {
    iris_sampler s = iris_sampler_start(seed, i, 0);
    float c[3] = {iris_sampler_next(&s) * ext[0], iris_sampler_next(&s) * ext[1], iris_sampler_next(&s) * ext[2]};
    int face = (int)(iris_sampler_next(&s) * 6.0f) % 6;
    c[face / 2] = (face & 1) ? ext[face / 2] : 0.0f;
    pts[i] = i % 17 == 3 && i > 0 ? pts[i - 1] : iris_v3(c[0], c[1], c[2]);
  }
  iris_kdtree t;
  iris_pick_grid g;
  if (iris_kdtree_build(&t, pts, sizeof(iris_vec3), n, NULL) != IRIS_OK ||
      iris_pick_grid_build(&g, &t, 5, radius * radius, 0.25f, 2, NULL) != IRIS_OK) {
    ++failures;
    return;
  }
  if (g.n[0] == 0 || g.id_count == 0 || g.id_count >= g.cells * 5) {
    fprintf(stderr, "FAIL grid not built or not shared (%zu cells, %zu ids)\n", g.cells, g.id_count);
    ++failures;
  }
  int bad = 0, outside = 0;
  for (int q = 0; q < 20000; ++q) {
    iris_sampler s = iris_sampler_start(seed + 7, (uint64_t)q, 0);
    float c[3] = {iris_sampler_next(&s) * (ext[0] + 4.0f * radius) - 2.0f * radius,
                  iris_sampler_next(&s) * (ext[1] + 4.0f * radius) - 2.0f * radius,
                  iris_sampler_next(&s) * (ext[2] + 4.0f * radius) - 2.0f * radius};
    if (q % 4 != 0) { /* on a face, slightly off it */
      int face = (int)(iris_sampler_next(&s) * 6.0f) % 6;
      c[face / 2] = ((face & 1) ? ext[face / 2] : 0.0f) + (iris_sampler_next(&s) - 0.5f) * 0.02f;
    }
    if (q % 97 == 5) { /* exactly on a stored point */
      uint32_t i = (uint32_t)q % n;
      c[0] = pts[i].x, c[1] = pts[i].y, c[2] = pts[i].z;
    }
    iris_vec3 p = iris_v3(c[0], c[1], c[2]);
    uint32_t ia[5], ib[5];
    float da[5];
    int cell[3];
    bool inside = true, edge = false;
    for (int a = 0; a < 3; ++a) {
      double x = ((double)c[a] - (double)g.lo[a]) / (double)g.cell, f = floor(x);
      cell[a] = (int)f;
      inside = inside && f >= 0.0 && f < (double)g.n[a];
      edge = edge || x - f < 1e-3 || f + 1.0 - x < 1e-3; /* float rounding may pick the neighbour */
    }
    if (edge) continue;
    uint32_t nb = iris_pick_grid_query(&g, p, ib);
    uint32_t na;
    if (inside) {
      iris_vec3 centre = iris_v3(g.lo[0] + ((float)cell[0] + 0.5f) * g.cell, g.lo[1] + ((float)cell[1] + 0.5f) * g.cell,
                                 g.lo[2] + ((float)cell[2] + 0.5f) * g.cell);
      na = iris_kdtree_knn(&t, centre, 5, radius * radius, ia, da);
    } else { /* outside the grid nothing lies within the radius */
      ++outside;
      na = iris_kdtree_knn(&t, p, 5, radius * radius, ia, da);
      if (na != 0 && bad++ < 5) fprintf(stderr, "FAIL grid q=%d outside the grid with %u neighbours\n", q, na);
      na = 0;
    }
    bool same = na == nb;
    for (uint32_t i = 0; same && i < na; ++i) same = ia[i] == ib[i];
    if (!same && bad++ < 5)
      fprintf(stderr, "FAIL grid q=%d (%g %g %g): tree %u, grid %u neighbours\n", q, c[0], c[1], c[2], na, nb);
  }
  if (outside == 0) {
    fprintf(stderr, "FAIL grid: no query outside the grid\n");
    ++failures;
  }
  failures += bad;
  iris_pick_grid_destroy(&g);
  iris_kdtree_destroy(&t);
  free(pts);
}

/* Filtered kNN (by id and by tree-order payload, the photon filter's two
 * forms) and the threaded build against brute force: points with many exact
 * ties (a coarse lattice) and a filter that drops about half of them. */
typedef struct filt_point {
  float p[3];
  float w;   /* payload: the filter keeps w >= 0.5 */
  uint32_t tag;
} filt_point;

static bool keep_id(void *ctx, uint32_t id) { return ((const filt_point *)ctx)[id].w >= 0.5f; }
static bool keep_payload(void *ctx, const void *payload) {
  (void)ctx;
  filt_point fp;
  memcpy(&fp, payload, sizeof fp);
  return fp.w >= 0.5f;
}

static void run_filtered(uint32_t n, int lattice, int threads, uint64_t seed) {
  filt_point *pts = malloc(sizeof(filt_point) * n);
  for (uint32_t i = 0; i < n; ++i) {
    iris_sampler s = iris_sampler_start(seed, i, 0);
    float x = iris_sampler_next(&s), y = iris_sampler_next(&s), z = iris_sampler_next(&s);
    if (lattice) {
      x = floorf(x * 8) / 8;
      y = floorf(y * 8) / 8;
      z = floorf(z * 2) / 2;
    }
    pts[i].p[0] = x, pts[i].p[1] = y, pts[i].p[2] = z;
    pts[i].w = iris_sampler_next(&s);
    pts[i].tag = i * 7u + 1u;
  }
  iris_kdtree t;
  if (iris_kdtree_build_threads(&t, pts, sizeof(filt_point), n, threads, NULL) != IRIS_OK ||
      iris_kdtree_set_payload(&t, pts, sizeof(filt_point), sizeof(filt_point), threads, NULL) != IRIS_OK) {
    ++failures;
    return;
  }
  float (*brute)[2] = malloc(sizeof(float) * 2 * n);
  enum { KMAX = 260 };
  uint32_t ia[KMAX], ib[KMAX], slots[KMAX];
  float da[KMAX], db[KMAX];
  for (int q = 0; q < 60; ++q) {
    iris_sampler s = iris_sampler_start(seed + 1, (uint64_t)q, 0);
    iris_vec3 p = iris_v3(iris_sampler_next(&s), iris_sampler_next(&s), iris_sampler_next(&s));
    if (lattice && q % 2) p = iris_v3(pts[q].p[0], pts[q].p[1], pts[q].p[2]); /* on a lattice point */
    uint32_t k = q % 3 == 0 ? 200 : 1 + (uint32_t)q * 4 % KMAX;
    float maxd2 = (q % 4 == 1) ? 0.02f : INFINITY;
    uint32_t na = iris_kdtree_knn_if(&t, p, k, maxd2, keep_id, pts, ia, da);
    uint32_t nb = iris_kdtree_knn_payload_if(&t, p, k, maxd2, keep_payload, NULL, ib, db, slots);
    uint32_t m = 0;
    for (uint32_t i = 0; i < n; ++i) {
      float dx = pts[i].p[0] - p.x, dy = pts[i].p[1] - p.y, dz = pts[i].p[2] - p.z;
      float dd = dx * dx + dy * dy + dz * dz;
      if (dd <= maxd2 && pts[i].w >= 0.5f) {
        brute[m][0] = dd;
        brute[m][1] = (float)i;
        ++m;
      }
    }
    qsort(brute, m, sizeof brute[0], cmp_pair);
    uint32_t want = m < k ? m : k;
    if (na != want || nb != want) {
      fprintf(stderr, "FAIL filtered n=%u q=%d: got %u / %u neighbours, want %u\n", n, q, na, nb, want);
      ++failures;
      continue;
    }
    for (uint32_t i = 0; i < want; ++i) {
      uint32_t id = (uint32_t)brute[i][1];
      filt_point at;
      memcpy(&at, t.payload + (size_t)slots[i] * t.payload_size, sizeof at);
      if (ia[i] != id || da[i] != brute[i][0] || ib[i] != id || db[i] != brute[i][0] || t.ids[slots[i]] != id ||
          at.tag != pts[id].tag) {
        fprintf(stderr, "FAIL filtered n=%u q=%d rank %u: ids %u %u, want %u\n", n, q, i, ia[i], ib[i], id);
        ++failures;
        break;
      }
    }
  }
  free(brute);
  iris_kdtree_destroy(&t);
  free(pts);
}

/* Grouped trees (a forest, some points left out; points on a lattice, so
 * many distances tie): every-group queries equal
 * brute force over the points in groups, a query over some groups equals
 * brute force over those groups only; ids stay the caller's indices. Also
 * k > 512 (the heap path) and the small-k path. */
static bool keep_all(void *ctx, const void *payload) {
  (void)ctx;
  (void)payload;
  return true;
}

static void run_grouped(uint32_t n, int threads, uint64_t seed) {
  enum { G = 5, KMAX = 700 };
  filt_point *pts = malloc(sizeof(filt_point) * n);
  uint32_t *group = malloc(sizeof(uint32_t) * n);
  for (uint32_t i = 0; i < n; ++i) {
    iris_sampler s = iris_sampler_start(seed, i, 0);
    pts[i].p[0] = floorf(iris_sampler_next(&s) * 16) / 16; /* ties */
    pts[i].p[1] = floorf(iris_sampler_next(&s) * 8) / 8;
    pts[i].p[2] = floorf(iris_sampler_next(&s) * 4) / 4;
    pts[i].w = iris_sampler_next(&s);
    pts[i].tag = i;
    group[i] = i % 11 == 0 ? UINT32_MAX : (uint32_t)(iris_sampler_next(&s) * G) % G; /* some left out */
  }
  iris_kdtree t;
  if (iris_kdtree_build_grouped(&t, pts, sizeof(filt_point), n, group, G, threads, NULL) != IRIS_OK ||
      iris_kdtree_set_payload(&t, pts, sizeof(filt_point), sizeof(filt_point), threads, NULL) != IRIS_OK) {
    ++failures;
    return;
  }
  float (*brute)[2] = malloc(sizeof(float) * 2 * n);
  uint32_t *ia = malloc(sizeof(uint32_t) * KMAX), *slots = malloc(sizeof(uint32_t) * KMAX);
  float *da = malloc(sizeof(float) * KMAX);
  for (int q = 0; q < 40; ++q) {
    iris_sampler s = iris_sampler_start(seed + 1, (uint64_t)q, 0);
    iris_vec3 p = iris_v3(iris_sampler_next(&s), iris_sampler_next(&s), iris_sampler_next(&s));
    const uint32_t ks[4] = {5, 200, 600, KMAX};
    uint32_t k = ks[q % 4];
    uint32_t sel[2] = {(uint32_t)q % G, (uint32_t)(q + 2) % G}; /* two of the groups */
    bool some = q % 3 != 0;
    float maxd2 = (q % 5 == 1) ? 0.05f : INFINITY;
    uint32_t got = some ? iris_kdtree_knn_groups_payload_if(&t, p, k, maxd2, sel, 2, keep_all, NULL, ia, da, slots)
                        : ((q / 4) % 2 ? iris_kdtree_knn(&t, p, k, maxd2, ia, da)
                                 : iris_kdtree_knn_payload_if(&t, p, k, maxd2, keep_all, NULL, ia, da, slots));
    uint32_t m = 0;
    for (uint32_t i = 0; i < n; ++i) {
      if (group[i] >= G || (some && group[i] != sel[0] && group[i] != sel[1])) continue;
      float dx = pts[i].p[0] - p.x, dy = pts[i].p[1] - p.y, dz = pts[i].p[2] - p.z;
      float dd = dx * dx + dy * dy + dz * dz;
      if (dd <= maxd2) {
        brute[m][0] = dd;
        brute[m][1] = (float)i;
        ++m;
      }
    }
    qsort(brute, m, sizeof brute[0], cmp_pair);
    uint32_t want = m < k ? m : k;
    if (got != want) {
      fprintf(stderr, "FAIL grouped n=%u q=%d k=%u: got %u neighbours, want %u\n", n, q, k, got, want);
      ++failures;
      continue;
    }
    for (uint32_t i = 0; i < want; ++i) {
      if (ia[i] != (uint32_t)brute[i][1] || da[i] != brute[i][0]) {
        fprintf(stderr, "FAIL grouped n=%u q=%d k=%u rank %u: id %u, want %u\n", n, q, k, i, ia[i],
                (uint32_t)brute[i][1]);
        ++failures;
        break;
      }
    }
  }
  free(ia);
  free(slots);
  free(da);
  free(brute);
  iris_kdtree_destroy(&t);
  free(group);
  free(pts);
}

int main(void) {
  run_grid(1500, 0.8f, 11);
  run_grid(300, 2.5f, 12); /* sparse: large radius, coarse cells */
  run(1, 0, 1);
  run(2, 0, 2);
  run(37, 0, 3);
  run(5000, 0, 4);
  run(3000, 1, 5); /* ties broken by index, as documented */
  run(70000, 0, 6); /* large enough for every select_nth path */
  run_filtered(5000, 0, 1, 21);
  run_filtered(40000, 1, 2, 22); /* threaded build (subtree tasks), lattice ties */
  run_filtered(40000, 0, 3, 23);
  run_grouped(3000, 1, 31);
  run_grouped(90000, 2, 32); /* groups big enough for threaded subtrees */
  iris_kdtree t;
  if (iris_kdtree_build(&t, NULL, 12, 0, NULL) != IRIS_OK || iris_kdtree_knn(&t, iris_v3(0, 0, 0), 3, INFINITY, NULL, NULL) != 0)
    ++failures;
  if (failures) fprintf(stderr, "%d failures\n", failures);
  return failures ? 1 : 0;
}
