/* Static 3D kd-tree for k-nearest-neighbour queries over photons and caches
 * (thesis 4.2.1, 4.2.4). Built once from a point array, deterministic: the
 * median split orders points by (coordinate, index), and query results are
 * sorted by (distance, index), so equal inputs give identical answers. */
#ifndef IRIS_RENDERER_GUIDING_KDTREE_H
#define IRIS_RENDERER_GUIDING_KDTREE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "core/math.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct iris_kdtree {
  uint32_t count;
  float *points;  /* 3 * count, in tree order (node m of range [lo,hi) is the median) */
  uint32_t *ids;  /* tree order -> caller's index */
  uint8_t *axis;  /* split axis of each node */
} iris_kdtree;

/* Builds over `count` positions read at `base + i * stride` bytes (so a field
 * of an array of structs can be indexed directly). Positions must be finite. */
iris_status iris_kdtree_build(iris_kdtree *tree, const void *base, size_t stride, uint32_t count,
                              iris_error *err);
void iris_kdtree_destroy(iris_kdtree *tree);

/* Up to k nearest points to q within squared distance max_d2 (INFINITY for
 * none), written to ids/d2 sorted by (distance, index); returns how many. */
uint32_t iris_kdtree_knn(const iris_kdtree *tree, iris_vec3 q, uint32_t k, float max_d2,
                         uint32_t *ids, float *d2);

/* The same among the points for which accept(ctx, id) is true (photons a
 * cache can use); accept is called only for points that would be kept. */
uint32_t iris_kdtree_knn_if(const iris_kdtree *tree, iris_vec3 q, uint32_t k, float max_d2,
                            bool (*accept)(void *ctx, uint32_t id), void *ctx, uint32_t *ids,
                            float *d2);

#ifdef __cplusplus
}
#endif
#endif
