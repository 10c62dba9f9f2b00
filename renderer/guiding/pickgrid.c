/* Candidate grid for Algorithm 1's k-nearest search (pickgrid.h). */
#include "renderer/guiding/pickgrid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/parallel.h"

#define NOT_BUILT UINT32_MAX

typedef struct build_ctx {
  iris_pick_grid *g;
  const iris_kdtree *tree;
  const uint8_t *wanted; /* [cells] */
  uint32_t *count;       /* [cells] candidates, NOT_BUILT for kd-tree cells */
  float *rho2;           /* [cells] */
  uint32_t *where;       /* caller's index -> tree order */
  uint32_t **ids;        /* per thread, CAP + 1 */
  float **d2;            /* per thread, CAP + 1 */
  int pass;
} build_ctx;

static iris_vec3 cell_centre(const iris_pick_grid *g, size_t c) {
  size_t ix = c % (size_t)g->n[0], iy = (c / (size_t)g->n[0]) % (size_t)g->n[1],
         iz = c / ((size_t)g->n[0] * (size_t)g->n[1]);
  return iris_v3(g->lo[0] + ((float)ix + 0.5f) * g->cell, g->lo[1] + ((float)iy + 0.5f) * g->cell,
                 g->lo[2] + ((float)iz + 0.5f) * g->cell);
}

static void build_cells(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  build_ctx *b = ctx;
  iris_pick_grid *g = b->g;
  uint32_t *ids = b->ids[thread_index];
  float *d2 = b->d2[thread_index];
  /* Half-diagonal, a little enlarged for rounding in the cell index and distances. */
  const float h = g->cell * 0.8660254f * 1.001f + 1e-6f * g->cell;
  const float r_max = sqrtf(g->max_d2);
  for (uint64_t c = begin; c < end; ++c) {
    if (b->pass == 0) {
      if (!b->wanted[c]) {
        b->count[c] = NOT_BUILT;
        continue;
      }
      iris_vec3 p = cell_centre(g, c);
      uint32_t m = iris_kdtree_knn(b->tree, p, g->k, g->max_d2, ids, d2);
      float rk = m == g->k ? sqrtf(d2[m - 1]) : r_max;
      float rho = fminf(rk + h, r_max) + h;
      rho = rho * 1.0001f;
      b->rho2[c] = rho * rho;
      uint32_t n = iris_kdtree_knn(b->tree, p, IRIS_PICK_GRID_CAP + 1, b->rho2[c], ids, d2);
      b->count[c] = n > IRIS_PICK_GRID_CAP ? NOT_BUILT : n;
      if (n > IRIS_PICK_GRID_CAP) g->fallback[c] = 1;
    } else {
      if (g->fallback[c]) continue;
      iris_vec3 p = cell_centre(g, c);
      uint32_t n = iris_kdtree_knn(b->tree, p, IRIS_PICK_GRID_CAP + 1, b->rho2[c], ids, d2);
      iris_pick_candidate *out = g->cand + g->start[c];
      for (uint32_t i = 0; i < n && i < b->count[c]; ++i) {
        const float *pt = &b->tree->points[3 * (size_t)b->where[ids[i]]];
        out[i].x = pt[0];
        out[i].y = pt[1];
        out[i].z = pt[2];
        out[i].id = ids[i];
      }
    }
  }
}

iris_status iris_pick_grid_build(iris_pick_grid *grid, const iris_kdtree *tree, uint32_t k,
                                 float max_d2, float spacing, int threads, iris_error *err) {
  memset(grid, 0, sizeof *grid);
  if (tree->count == 0 || k == 0 || k > IRIS_PICK_GRID_CAP || !isfinite(max_d2) || !(max_d2 > 0.0f) ||
      !(spacing > 0.0f) || !isfinite(spacing))
    return IRIS_OK; /* no grid: queries use the kd-tree */
  float bmin[3] = {INFINITY, INFINITY, INFINITY}, bmax[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (uint32_t i = 0; i < tree->count; ++i)
    for (int a = 0; a < 3; ++a) {
      bmin[a] = fminf(bmin[a], tree->points[3 * i + a]);
      bmax[a] = fmaxf(bmax[a], tree->points[3 * i + a]);
    }
  /* Points farther than R from every cache get no cache: the grid need only
   * cover the caches' box grown by R. */
  float r = sqrtf(max_d2), ext[3];
  for (int a = 0; a < 3; ++a) {
    bmin[a] -= r;
    bmax[a] += r;
    ext[a] = bmax[a] - bmin[a];
  }
  float cell = 0.5f * spacing;
  double max_cells = fmin(64.0 * (double)tree->count, 16777216.0);
  for (;;) {
    double cells = 1.0;
    for (int a = 0; a < 3; ++a) cells *= ceil((double)ext[a] / cell) + 1.0;
    if (cells <= max_cells) break;
    cell *= 1.25f;
  }
  for (int a = 0; a < 3; ++a) {
    grid->n[a] = (int)ceil((double)ext[a] / cell) + 1;
    grid->lo[a] = bmin[a];
  }
  grid->cell = cell;
  grid->inv_cell = 1.0f / cell;
  grid->k = k;
  grid->max_d2 = max_d2;
  size_t cells = (size_t)grid->n[0] * (size_t)grid->n[1] * (size_t)grid->n[2];
  grid->cells = cells;
  /* Cells that hold a cache and their 26 neighbours: where surface points are. */
  uint8_t *wanted = calloc(cells, 1);
  uint32_t *count = malloc(sizeof(uint32_t) * cells);
  float *rho2 = malloc(sizeof(float) * cells);
  grid->start = malloc(sizeof(uint32_t) * (cells + 1));
  int nt = threads > 0 ? threads : iris_parallel_default_threads();
  grid->fallback = malloc(cells);
  build_ctx b = {grid, tree, wanted, count, rho2, malloc(sizeof(uint32_t) * tree->count),
                 calloc((size_t)nt, sizeof(uint32_t *)), calloc((size_t)nt, sizeof(float *)), 0};
  bool ok = wanted && count && rho2 && grid->start && grid->fallback && b.where && b.ids && b.d2;
  for (int t = 0; ok && t < nt; ++t) {
    b.ids[t] = malloc(sizeof(uint32_t) * (IRIS_PICK_GRID_CAP + 1));
    b.d2[t] = malloc(sizeof(float) * (IRIS_PICK_GRID_CAP + 1));
    ok = b.ids[t] && b.d2[t];
  }
  iris_status st = IRIS_OK;
  if (ok) {
    for (uint32_t i = 0; i < tree->count; ++i) b.where[tree->ids[i]] = i; /* ids are 0..count-1 */
    for (uint32_t i = 0; i < tree->count; ++i) {
      int c[3];
      for (int a = 0; a < 3; ++a) c[a] = (int)((tree->points[3 * i + a] - grid->lo[a]) * grid->inv_cell);
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            int x = c[0] + dx, y = c[1] + dy, z = c[2] + dz;
            if (x < 0 || y < 0 || z < 0 || x >= grid->n[0] || y >= grid->n[1] || z >= grid->n[2]) continue;
            wanted[((size_t)z * (size_t)grid->n[1] + (size_t)y) * (size_t)grid->n[0] + (size_t)x] = 1;
          }
    }
    for (size_t c = 0; c < cells; ++c) grid->fallback[c] = !wanted[c];
    iris_parallel_for(cells, 256, nt, build_cells, &b);
    size_t total = 0;
    for (size_t c = 0; c < cells; ++c) {
      grid->start[c] = (uint32_t)total;
      if (grid->fallback[c]) grid->fallback_cells++;
      else total += count[c];
    }
    grid->start[cells] = (uint32_t)total;
    grid->candidates = total;
    grid->cand = malloc(sizeof(iris_pick_candidate) * (total ? total : 1));
    if (!grid->cand || total >= NOT_BUILT) {
      ok = false;
    } else {
      b.pass = 1;
      iris_parallel_for(cells, 256, nt, build_cells, &b);
    }
  }
  if (b.ids)
    for (int t = 0; t < nt; ++t) free(b.ids[t]);
  if (b.d2)
    for (int t = 0; t < nt; ++t) free(b.d2[t]);
  free(b.ids);
  free(b.d2);
  free(b.where);
  free(wanted);
  free(count);
  free(rho2);
  if (!ok) {
    iris_pick_grid_destroy(grid);
    st = iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for the cache grid");
  } else {
    grid->memory_bytes = (sizeof(uint32_t) + 1) * (cells + 1) + sizeof(iris_pick_candidate) * grid->candidates;
  }
  return st;
}

void iris_pick_grid_destroy(iris_pick_grid *grid) {
  free(grid->start);
  free(grid->fallback);
  free(grid->cand);
  memset(grid, 0, sizeof *grid);
}

uint32_t iris_pick_grid_knn(const iris_pick_grid *g, const iris_kdtree *tree, iris_vec3 q,
                            uint32_t k, float max_d2, uint32_t *ids, float *d2) {
  if (g->n[0] == 0 || k > g->k || max_d2 > g->max_d2 || k > IRIS_PICK_GRID_CAP)
    return iris_kdtree_knn(tree, q, k, max_d2, ids, d2);
  float fx = (q.x - g->lo[0]) * g->inv_cell, fy = (q.y - g->lo[1]) * g->inv_cell,
        fz = (q.z - g->lo[2]) * g->inv_cell;
  /* Outside the caches' box grown by R: no cache within R. */
  if (!(fx >= 0.0f && fy >= 0.0f && fz >= 0.0f)) return 0;
  int ix = (int)fx, iy = (int)fy, iz = (int)fz;
  if (ix >= g->n[0] || iy >= g->n[1] || iz >= g->n[2]) return 0;
  size_t c = ((size_t)iz * (size_t)g->n[1] + (size_t)iy) * (size_t)g->n[0] + (size_t)ix;
  if (g->fallback[c]) return iris_kdtree_knn(tree, q, k, max_d2, ids, d2);
  uint32_t s = g->start[c], e = g->start[c + 1];
  /* Insertion into a sorted list of at most k (k is small: 5). */
  uint32_t n = 0;
  for (uint32_t i = s; i < e; ++i) {
    const iris_pick_candidate *p = &g->cand[i];
    float dx = p->x - q.x, dy = p->y - q.y, dz = p->z - q.z;
    float dd = dx * dx + dy * dy + dz * dz;
    if (dd > max_d2) continue;
    if (n == k && (dd > d2[n - 1] || (dd == d2[n - 1] && p->id > ids[n - 1]))) continue;
    uint32_t j = n < k ? n++ : n - 1;
    while (j > 0 && (d2[j - 1] > dd || (d2[j - 1] == dd && ids[j - 1] > p->id))) {
      d2[j] = d2[j - 1];
      ids[j] = ids[j - 1];
      --j;
    }
    d2[j] = dd;
    ids[j] = p->id;
  }
  return n;
}
