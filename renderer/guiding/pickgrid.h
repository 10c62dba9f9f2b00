/* A uniform grid that answers Algorithm 1's "k nearest caches within radius
 * R" in O(1) at render time: every cell stores the answer for its CENTRE (the
 * k nearest caches within R of the centre, kd-tree order), and a query returns
 * the answer of the cell that contains the point. The pick is therefore a
 * deterministic function of the shading point quantised to the grid (cell
 * edge = half the median distance between a cache and its 5th nearest), which
 * is all the unbiasedness argument needs (sampling and pdf see the same
 * caches); the caches' photon neighbourhoods are much larger than a cell, so
 * the guide barely changes. Consecutive cells along x with the same answer
 * share it. docs/guiding.md, "Cheaper lookup". */
#ifndef IRIS_RENDERER_GUIDING_PICKGRID_H
#define IRIS_RENDERER_GUIDING_PICKGRID_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "core/math.h"
#include "renderer/guiding/kdtree.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IRIS_PICK_GRID_MAX_K 7 /* answers hold at most this many ids (3 bits of count) */

typedef struct iris_pick_grid {
  int n[3];           /* cells per axis; 0: no grid (callers use the kd-tree) */
  float lo[3], inv_cell, cell;
  uint32_t k;         /* the k the grid was built for */
  float max_d2;       /* the radius it was built for (squared) */
  uint32_t *answer;   /* [cells]: first id (low 29 bits) | count << 29 */
  uint32_t *ids;      /* the answers' ids, cell after cell */
  size_t cells, id_count;
  size_t memory_bytes;
} iris_pick_grid;

/* Builds the grid over the points of `tree` for queries with this k (<=
 * IRIS_PICK_GRID_MAX_K) and max_d2 (finite). spacing: typical distance between
 * neighbouring points (the cell edge is half of it, enlarged so that there
 * are at most 64 cells per point). An empty tree, k out of range or an
 * infinite radius leave the grid empty (n[0] == 0), which is not an error. */
iris_status iris_pick_grid_build(iris_pick_grid *grid, const iris_kdtree *tree, uint32_t k,
                                 float max_d2, float spacing, int threads, iris_error *err);
void iris_pick_grid_destroy(iris_pick_grid *grid);

/* The centre of the cell containing q, false if q lies outside the grid (then
 * no point of the tree is within the radius of q). */
bool iris_pick_grid_cell_centre(const iris_pick_grid *grid, iris_vec3 q, iris_vec3 *centre);

/* The k nearest points (tree ids, ascending (distance, id)) within the build
 * radius of the centre of the cell containing q: exactly
 * iris_kdtree_knn(tree, centre, k, max_d2, ...). 0 outside the grid.
 * Requires a built grid (n[0] > 0). */
static inline uint32_t iris_pick_grid_query(const iris_pick_grid *g, iris_vec3 q, uint32_t *ids) {
  float fx = (q.x - g->lo[0]) * g->inv_cell, fy = (q.y - g->lo[1]) * g->inv_cell,
        fz = (q.z - g->lo[2]) * g->inv_cell;
  if (!(fx >= 0.0f && fy >= 0.0f && fz >= 0.0f)) return 0;
  int ix = (int)fx, iy = (int)fy, iz = (int)fz;
  if (ix >= g->n[0] || iy >= g->n[1] || iz >= g->n[2]) return 0;
  uint32_t a = g->answer[((size_t)iz * (size_t)g->n[1] + (size_t)iy) * (size_t)g->n[0] + (size_t)ix];
  uint32_t n = a >> 29;
  const uint32_t *src = g->ids + (a & 0x1fffffffu);
  for (uint32_t i = 0; i < n; ++i) ids[i] = src[i];
  return n;
}

/* Starts loading the answer of q's cell (a hint before iris_pick_grid_query). */
static inline void iris_pick_grid_prefetch(const iris_pick_grid *g, iris_vec3 q) {
  float fx = (q.x - g->lo[0]) * g->inv_cell, fy = (q.y - g->lo[1]) * g->inv_cell,
        fz = (q.z - g->lo[2]) * g->inv_cell;
  if (!(fx >= 0.0f && fy >= 0.0f && fz >= 0.0f)) return;
  int ix = (int)fx, iy = (int)fy, iz = (int)fz;
  if (ix >= g->n[0] || iy >= g->n[1] || iz >= g->n[2]) return;
  __builtin_prefetch(&g->answer[((size_t)iz * (size_t)g->n[1] + (size_t)iy) * (size_t)g->n[0] + (size_t)ix]);
}

#ifdef __cplusplus
}
#endif
#endif
