/* Static 3D kd-tree for k-nearest-neighbour queries over photons and caches
 * (thesis 4.2.1, 4.2.4). Built once from a point array, deterministic (the
 * layout depends only on the input, never on the thread count), and query
 * results are exact and sorted by (distance, index): the answer is the k
 * smallest (squared distance, index) pairs, so it does not depend on the
 * tree's layout at all. */
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

/* Index ranges of at most this many points are leaves: unordered, scanned. */
#define IRIS_KDTREE_LEAF 16

typedef struct iris_kdtree {
  uint32_t count;
  float *points;  /* 3 * count, in tree order (node m of range [lo,hi) is the median) */
  uint32_t *ids;  /* tree order -> caller's index */
  uint8_t *axis;  /* split axis of each node (ranges of <= IRIS_KDTREE_LEAF points: unused) */
  unsigned char *payload; /* optional per-point data in tree order (iris_kdtree_set_payload) */
  size_t payload_size;    /* bytes per point, 0 without payload */
  uint32_t group_count;   /* 0: one tree over [0, count); else one implicit tree per group */
  uint32_t *group_start;  /* group g is [group_start[g], group_start[g + 1]); group_count + 1 */
} iris_kdtree;

/* Builds over `count` positions read at `base + i * stride` bytes (so a field
 * of an array of structs can be indexed directly). Positions must be finite. */
iris_status iris_kdtree_build(iris_kdtree *tree, const void *base, size_t stride, uint32_t count,
                              iris_error *err);
/* The same tree, the subtrees below the top levels built on `threads`
 * threads (<= 0: all cores). */
iris_status iris_kdtree_build_threads(iris_kdtree *tree, const void *base, size_t stride, uint32_t count,
                                      int threads, iris_error *err);
/* A forest: point i goes to group[i] (>= group_count: left out of the tree),
 * each group gets its own tree, and a query may search only some groups (the
 * photons whose normals can pass a cache's filter). ids stay the caller's
 * indices; queries over all groups answer exactly as one tree over the
 * points in groups. */
iris_status iris_kdtree_build_grouped(iris_kdtree *tree, const void *base, size_t stride, uint32_t count,
                                      const uint32_t *group, uint32_t group_count, int threads,
                                      iris_error *err);
void iris_kdtree_destroy(iris_kdtree *tree);

/* Copies `size` bytes per point, read at `base + id * stride`, into tree
 * order, so that a filter (iris_kdtree_knn_payload_if) reads them next to
 * the points instead of chasing the caller's array (on `threads` threads,
 * <= 0: all cores). Replaces any earlier payload. */
iris_status iris_kdtree_set_payload(iris_kdtree *tree, const void *base, size_t stride, size_t size, int threads,
                                    iris_error *err);

/* Up to k nearest points to q within squared distance max_d2 (INFINITY for
 * none), written to ids/d2 sorted by (distance, index); returns how many. */
uint32_t iris_kdtree_knn(const iris_kdtree *tree, iris_vec3 q, uint32_t k, float max_d2,
                         uint32_t *ids, float *d2);

/* The same among the points for which accept(ctx, id) is true (photons a
 * cache can use); accept is called only for points that would be kept. */
uint32_t iris_kdtree_knn_if(const iris_kdtree *tree, iris_vec3 q, uint32_t k, float max_d2,
                            bool (*accept)(void *ctx, uint32_t id), void *ctx, uint32_t *ids,
                            float *d2);

/* The same with the filter reading the point's payload (requires
 * iris_kdtree_set_payload); same answers as iris_kdtree_knn_if with an
 * equivalent accept. slots (NULL: not wanted) receives each answer's tree
 * position, so the caller reads its payload at
 * tree->payload + slots[j] * tree->payload_size. */
uint32_t iris_kdtree_knn_payload_if(const iris_kdtree *tree, iris_vec3 q, uint32_t k, float max_d2,
                                    bool (*accept)(void *ctx, const void *payload), void *ctx,
                                    uint32_t *ids, float *d2, uint32_t *slots);

/* The same among the points of the listed groups only (searched in this
 * order: the most promising first tightens the bound sooner); the answer is
 * the k smallest (d2, id) over those groups' accepted points. */
uint32_t iris_kdtree_knn_groups_payload_if(const iris_kdtree *tree, iris_vec3 q, uint32_t k, float max_d2,
                                           const uint32_t *groups, uint32_t group_count,
                                           bool (*accept)(void *ctx, const void *payload), void *ctx,
                                           uint32_t *ids, float *d2, uint32_t *slots);

#ifdef __cplusplus
}
#endif
#endif
