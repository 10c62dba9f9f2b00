/* A uniform grid that answers Algorithm 1's "k nearest caches within radius
 * R" without walking the kd-tree: the k-nearest set is piecewise constant in
 * space, so each cell stores the few caches that can be among the k nearest
 * of ANY point in it, and a query runs an exact k-nearest search over those
 * (same (distance, index) order as the kd-tree, so the answer is identical).
 *
 * Candidates of a cell with centre c and half-diagonal h: with r_k(c) the
 * distance of c's k-th nearest cache (R if fewer than k lie within R), any
 * point q of the cell has r_k(q) <= r_k(c) + h, so every cache among q's k
 * nearest within R lies within rho = min(r_k(c) + h, R) + h of c.
 * Only cells that hold a cache or touch such a cell are built (where surface
 * points are); other cells, and cells with more than IRIS_PICK_GRID_CAP
 * candidates, fall back to the kd-tree. docs/guiding.md, "Cheaper lookup". */
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

#define IRIS_PICK_GRID_CAP 48 /* candidates per cell; more: the cell uses the kd-tree */

typedef struct iris_pick_candidate {
  float x, y, z;
  uint32_t id;
} iris_pick_candidate;

typedef struct iris_pick_grid {
  int n[3];                  /* cells per axis; 0: no grid (every query uses the kd-tree) */
  float lo[3], inv_cell, cell;
  uint32_t k;                /* the k the grid was built for */
  float max_d2;              /* the radius it was built for (squared) */
  uint32_t *start;           /* [cells + 1] first candidate of each cell */
  uint8_t *fallback;         /* [cells] 1: this cell asks the kd-tree */
  iris_pick_candidate *cand; /* candidates of every built cell */
  size_t cells, candidates, fallback_cells;
  size_t memory_bytes;
} iris_pick_grid;

/* Builds the grid over the points of `tree` for queries with this k and
 * max_d2 (must be finite). spacing: typical distance between neighbouring
 * points (the cell edge is half of it, enlarged so that there are at most
 * 64 cells per point). */
iris_status iris_pick_grid_build(iris_pick_grid *grid, const iris_kdtree *tree, uint32_t k,
                                 float max_d2, float spacing, int threads, iris_error *err);
void iris_pick_grid_destroy(iris_pick_grid *grid);

/* Exactly iris_kdtree_knn(tree, q, k, max_d2, ...) for the k and max_d2 of
 * the build (k <= the build's k is allowed too). */
uint32_t iris_pick_grid_knn(const iris_pick_grid *grid, const iris_kdtree *tree, iris_vec3 q,
                            uint32_t k, float max_d2, uint32_t *ids, float *d2);

#ifdef __cplusplus
}
#endif
#endif
