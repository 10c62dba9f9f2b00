/* Quantised answer grid for Algorithm 1's k-nearest search (pickgrid.h). */
#include "renderer/guiding/pickgrid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/parallel.h"

#define MAX_IDS 0x1fffffffu

/* One x-row of cells: its answers, consecutive equal answers shared. */
typedef struct row_out {
  uint32_t *answer; /* [n[0]]: first id within this row | count << 29 */
  uint32_t *ids;
  uint32_t id_count;
} row_out;

typedef struct build_ctx {
  iris_pick_grid *g;
  const iris_kdtree *tree;
  row_out *rows;
  int failed; /* out of memory in a worker (read after the join) */
} build_ctx;

static void build_rows(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  build_ctx *b = ctx;
  iris_pick_grid *g = b->g;
  const int nx = g->n[0];
  for (uint64_t r = begin; r < end; ++r) {
    row_out *o = &b->rows[r];
    o->answer = malloc(sizeof(uint32_t) * (size_t)nx);
    o->ids = malloc(sizeof(uint32_t) * (size_t)nx * g->k);
    o->id_count = 0;
    if (!o->answer || !o->ids) {
      b->failed = 1;
      continue;
    }
    const int iy = (int)(r % (uint64_t)g->n[1]), iz = (int)(r / (uint64_t)g->n[1]);
    uint32_t prev_first = 0, prev_n = UINT32_MAX;
    for (int ix = 0; ix < nx; ++ix) {
      iris_vec3 c = iris_v3(g->lo[0] + ((float)ix + 0.5f) * g->cell, g->lo[1] + ((float)iy + 0.5f) * g->cell,
                            g->lo[2] + ((float)iz + 0.5f) * g->cell);
      uint32_t ids[IRIS_PICK_GRID_MAX_K];
      float d2[IRIS_PICK_GRID_MAX_K];
      uint32_t n = iris_kdtree_knn(b->tree, c, g->k, g->max_d2, ids, d2);
      if (n == prev_n && memcmp(ids, o->ids + prev_first, sizeof(uint32_t) * n) == 0) {
        o->answer[ix] = prev_first | (n << 29);
        continue;
      }
      prev_first = o->id_count;
      prev_n = n;
      memcpy(o->ids + o->id_count, ids, sizeof(uint32_t) * n);
      o->id_count += n;
      o->answer[ix] = prev_first | (n << 29);
    }
  }
}

iris_status iris_pick_grid_build(iris_pick_grid *grid, const iris_kdtree *tree, uint32_t k,
                                 float max_d2, float spacing, int threads, iris_error *err) {
  memset(grid, 0, sizeof *grid);
  if (tree->count == 0 || k == 0 || k > IRIS_PICK_GRID_MAX_K || !isfinite(max_d2) || !(max_d2 > 0.0f) ||
      !(spacing > 0.0f) || !isfinite(spacing))
    return IRIS_OK; /* no grid: queries use the kd-tree */
  float bmin[3] = {INFINITY, INFINITY, INFINITY}, bmax[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (uint32_t i = 0; i < tree->count; ++i)
    for (int a = 0; a < 3; ++a) {
      bmin[a] = fminf(bmin[a], tree->points[3 * i + a]);
      bmax[a] = fmaxf(bmax[a], tree->points[3 * i + a]);
    }
  /* A cell whose centre is farther than R from every cache has no answer; the
   * grid covers the caches' box grown by R (plus one cell for the centres). */
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
  grid->cells = (size_t)grid->n[0] * (size_t)grid->n[1] * (size_t)grid->n[2];
  size_t nrows = (size_t)grid->n[1] * (size_t)grid->n[2];
  build_ctx b = {grid, tree, calloc(nrows, sizeof(row_out)), 0};
  grid->answer = malloc(sizeof(uint32_t) * grid->cells);
  bool ok = b.rows && grid->answer;
  if (ok) {
    int nt = threads > 0 ? threads : iris_parallel_default_threads();
    iris_parallel_for(nrows, 16, nt, build_rows, &b);
    ok = !b.failed;
  }
  size_t total = 0;
  for (size_t r2 = 0; ok && r2 < nrows; ++r2) total += b.rows[r2].id_count;
  if (ok && total >= MAX_IDS) ok = false;
  if (ok) grid->ids = malloc(sizeof(uint32_t) * (total ? total : 1));
  if (ok && grid->ids) {
    size_t at = 0;
    for (size_t r2 = 0; r2 < nrows; ++r2) {
      const row_out *o = &b.rows[r2];
      memcpy(grid->ids + at, o->ids, sizeof(uint32_t) * o->id_count);
      uint32_t *dst = grid->answer + r2 * (size_t)grid->n[0];
      for (int ix = 0; ix < grid->n[0]; ++ix) dst[ix] = o->answer[ix] + (uint32_t)at;
      at += o->id_count;
    }
    grid->id_count = total;
  } else {
    ok = false;
  }
  if (b.rows)
    for (size_t r2 = 0; r2 < nrows; ++r2) {
      free(b.rows[r2].answer);
      free(b.rows[r2].ids);
    }
  free(b.rows);
  if (!ok) {
    iris_pick_grid_destroy(grid);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for the cache grid");
  }
  grid->memory_bytes = sizeof(uint32_t) * (grid->cells + grid->id_count);
  return IRIS_OK;
}

void iris_pick_grid_destroy(iris_pick_grid *grid) {
  free(grid->answer);
  free(grid->ids);
  memset(grid, 0, sizeof *grid);
}

bool iris_pick_grid_cell_centre(const iris_pick_grid *g, iris_vec3 q, iris_vec3 *centre) {
  if (g->n[0] == 0) return false;
  float f[3] = {(q.x - g->lo[0]) * g->inv_cell, (q.y - g->lo[1]) * g->inv_cell, (q.z - g->lo[2]) * g->inv_cell};
  int i[3];
  for (int a = 0; a < 3; ++a) {
    if (!(f[a] >= 0.0f)) return false;
    i[a] = (int)f[a];
    if (i[a] >= g->n[a]) return false;
  }
  *centre = iris_v3(g->lo[0] + ((float)i[0] + 0.5f) * g->cell, g->lo[1] + ((float)i[1] + 0.5f) * g->cell,
                    g->lo[2] + ((float)i[2] + 0.5f) * g->cell);
  return true;
}
