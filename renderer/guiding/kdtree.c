/* kd-tree: implicit balanced layout (median of each index range), bounded
 * max-heap search. */
#include "renderer/guiding/kdtree.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

typedef struct build_ctx {
  float *p;      /* 3 * count */
  uint32_t *ids;
  uint8_t *axis;
} build_ctx;

static int key_less(const build_ctx *c, uint32_t a, uint32_t b, int ax) {
  float pa = c->p[3 * a + ax], pb = c->p[3 * b + ax];
  if (pa != pb) return pa < pb;
  return c->ids[a] < c->ids[b];
}

static void swap_items(build_ctx *c, uint32_t a, uint32_t b) {
  if (a == b) return;
  for (int k = 0; k < 3; ++k) {
    float t = c->p[3 * a + k];
    c->p[3 * a + k] = c->p[3 * b + k];
    c->p[3 * b + k] = t;
  }
  uint32_t t = c->ids[a];
  c->ids[a] = c->ids[b];
  c->ids[b] = t;
}

/* Quickselect: puts the element of rank m (by key) at m, smaller keys before. */
static void select_nth(build_ctx *c, uint32_t lo, uint32_t hi, uint32_t m, int ax) {
  while (hi - lo > 1) {
    uint32_t mid = lo + (hi - lo) / 2;
    swap_items(c, mid, hi - 1); /* pivot at the end */
    uint32_t store = lo;
    for (uint32_t i = lo; i < hi - 1; ++i) {
      if (key_less(c, i, hi - 1, ax)) swap_items(c, i, store++);
    }
    swap_items(c, store, hi - 1);
    if (store == m) return;
    if (m < store) hi = store;
    else lo = store + 1;
  }
}

static void build_range(build_ctx *c, uint32_t lo, uint32_t hi) {
  while (hi > lo) {
    float mn[3] = {INFINITY, INFINITY, INFINITY}, mx[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = lo; i < hi; ++i) {
      for (int k = 0; k < 3; ++k) {
        float v = c->p[3 * i + k]; /* plain compares: fminf is a libm call here */
        mn[k] = v < mn[k] ? v : mn[k];
        mx[k] = v > mx[k] ? v : mx[k];
      }
    }
    int ax = 0;
    for (int k = 1; k < 3; ++k)
      if (mx[k] - mn[k] > mx[ax] - mn[ax]) ax = k;
    uint32_t m = lo + (hi - lo) / 2;
    select_nth(c, lo, hi, m, ax);
    c->axis[m] = (uint8_t)ax;
    build_range(c, lo, m);
    lo = m + 1; /* loop instead of recursing on the right half */
  }
}

iris_status iris_kdtree_build(iris_kdtree *tree, const void *base, size_t stride, uint32_t count,
                              iris_error *err) {
  memset(tree, 0, sizeof(*tree));
  if (count == 0) return IRIS_OK;
  tree->points = malloc(sizeof(float) * 3 * (size_t)count);
  tree->ids = malloc(sizeof(uint32_t) * count);
  tree->axis = malloc(count);
  if (!tree->points || !tree->ids || !tree->axis) {
    iris_kdtree_destroy(tree);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for a kd-tree of %u points",
                          count);
  }
  tree->count = count;
  const unsigned char *b = base;
  for (uint32_t i = 0; i < count; ++i) {
    memcpy(&tree->points[3 * (size_t)i], b + (size_t)i * stride, sizeof(float) * 3);
    tree->ids[i] = i;
  }
  build_ctx c = {tree->points, tree->ids, tree->axis};
  build_range(&c, 0, count);
  return IRIS_OK;
}

void iris_kdtree_destroy(iris_kdtree *tree) {
  free(tree->points);
  free(tree->ids);
  free(tree->axis);
  memset(tree, 0, sizeof(*tree));
}

typedef struct knn_heap {
  uint32_t k, n;
  uint32_t *ids;
  float *d2;
  float max_d2;
  bool (*accept)(void *ctx, uint32_t id); /* NULL: every point */
  void *ctx;
} knn_heap;

/* Max-heap order on (d2, id): the root is the worst kept neighbour. */
static int worse(const knn_heap *h, uint32_t a, uint32_t b) {
  if (h->d2[a] != h->d2[b]) return h->d2[a] > h->d2[b];
  return h->ids[a] > h->ids[b];
}
static void heap_swap(knn_heap *h, uint32_t a, uint32_t b) {
  float t = h->d2[a];
  h->d2[a] = h->d2[b];
  h->d2[b] = t;
  uint32_t u = h->ids[a];
  h->ids[a] = h->ids[b];
  h->ids[b] = u;
}
static void sift_down(knn_heap *h, uint32_t i) {
  for (;;) {
    uint32_t l = 2 * i + 1, r = l + 1, w = i;
    if (l < h->n && worse(h, l, w)) w = l;
    if (r < h->n && worse(h, r, w)) w = r;
    if (w == i) return;
    heap_swap(h, i, w);
    i = w;
  }
}
static void heap_offer(knn_heap *h, uint32_t id, float d2) {
  if (d2 > h->max_d2) return;
  if (h->n == h->k && (d2 > h->d2[0] || (d2 == h->d2[0] && id > h->ids[0]))) return;
  if (h->accept && !h->accept(h->ctx, id)) return;
  if (h->n < h->k) {
    uint32_t i = h->n++;
    h->ids[i] = id;
    h->d2[i] = d2;
    while (i > 0) {
      uint32_t p = (i - 1) / 2;
      if (!worse(h, i, p)) break;
      heap_swap(h, i, p);
      i = p;
    }
    return;
  }
  if (d2 > h->d2[0] || (d2 == h->d2[0] && id > h->ids[0])) return;
  h->ids[0] = id;
  h->d2[0] = d2;
  sift_down(h, 0);
}
static float heap_bound(const knn_heap *h) { return h->n < h->k ? h->max_d2 : h->d2[0]; }

static void search(const iris_kdtree *t, uint32_t lo, uint32_t hi, const float q[3], knn_heap *h) {
  while (hi > lo) {
    uint32_t m = lo + (hi - lo) / 2;
    const float *p = &t->points[3 * (size_t)m];
    float dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
    heap_offer(h, t->ids[m], dx * dx + dy * dy + dz * dz);
    int ax = t->axis[m];
    float diff = q[ax] - p[ax];
    uint32_t nlo, nhi, flo, fhi; /* near and far halves */
    if (diff < 0.0f) {
      nlo = lo; nhi = m; flo = m + 1; fhi = hi;
    } else {
      nlo = m + 1; nhi = hi; flo = lo; fhi = m;
    }
    search(t, nlo, nhi, q, h);
    /* <= keeps equal-distance points reachable for the index tie-break. */
    if (diff * diff <= heap_bound(h)) {
      lo = flo;
      hi = fhi;
    } else {
      return;
    }
  }
}

/* Small k (cache picking, Algorithm 1, runs once per path vertex): the k best
 * kept sorted by insertion, (d2, id) order as in the heap version. */
#define SMALL_K 8
typedef struct small_set {
  uint32_t k, n;
  float bound; /* d2 of the worst kept when full, else max_d2 */
  float d2[SMALL_K];
  uint32_t ids[SMALL_K];
} small_set;

static void small_offer(small_set *s, uint32_t id, float d2) {
  uint32_t i;
  if (s->n < s->k) {
    i = s->n++;
  } else {
    i = s->k - 1; /* full: replace the worst kept, if this one ranks better */
    if (d2 > s->d2[i] || (d2 == s->d2[i] && id > s->ids[i])) return;
  }
  while (i > 0 && (s->d2[i - 1] > d2 || (s->d2[i - 1] == d2 && s->ids[i - 1] > id))) {
    s->d2[i] = s->d2[i - 1];
    s->ids[i] = s->ids[i - 1];
    --i;
  }
  s->d2[i] = d2;
  s->ids[i] = id;
  if (s->n == s->k) s->bound = s->d2[s->k - 1];
}

static void search_small(const iris_kdtree *t, uint32_t lo, uint32_t hi, const float q[3],
                         small_set *s) {
  while (hi > lo) {
    if (hi - lo <= 8) { /* small ranges: a linear scan beats descending further */
      for (uint32_t i = lo; i < hi; ++i) {
        const float *p = &t->points[3 * (size_t)i];
        float dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
        float d2 = dx * dx + dy * dy + dz * dz;
        if (d2 <= s->bound) small_offer(s, t->ids[i], d2);
      }
      return;
    }
    uint32_t m = lo + (hi - lo) / 2;
    const float *p = &t->points[3 * (size_t)m];
    float dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
    float d2 = dx * dx + dy * dy + dz * dz;
    if (d2 <= s->bound) small_offer(s, t->ids[m], d2);
    int ax = t->axis[m];
    float diff = q[ax] - p[ax];
    if (diff < 0.0f) {
      search_small(t, lo, m, q, s);
      if (!(diff * diff <= s->bound)) return;
      lo = m + 1;
    } else {
      search_small(t, m + 1, hi, q, s);
      if (!(diff * diff <= s->bound)) return;
      hi = m;
    }
  }
}

uint32_t iris_kdtree_knn(const iris_kdtree *tree, iris_vec3 q, uint32_t k, float max_d2,
                         uint32_t *ids, float *d2) {
  return iris_kdtree_knn_if(tree, q, k, max_d2, NULL, NULL, ids, d2);
}

uint32_t iris_kdtree_knn_if(const iris_kdtree *tree, iris_vec3 q, uint32_t k, float max_d2,
                            bool (*accept)(void *ctx, uint32_t id), void *ctx, uint32_t *ids,
                            float *d2) {
  if (k == 0 || tree->count == 0) return 0;
  if (k <= SMALL_K && !accept) {
    small_set s;
    s.k = k;
    s.n = 0;
    s.bound = max_d2;
    float qq[3] = {q.x, q.y, q.z};
    search_small(tree, 0, tree->count, qq, &s);
    for (uint32_t i = 0; i < s.n; ++i) {
      ids[i] = s.ids[i];
      d2[i] = s.d2[i];
    }
    return s.n;
  }
  knn_heap h = {k, 0, ids, d2, max_d2, accept, ctx};
  float qq[3] = {q.x, q.y, q.z};
  search(tree, 0, tree->count, qq, &h);
  /* Heap sort in place: ascending (d2, id). */
  uint32_t n = h.n;
  while (h.n > 1) {
    heap_swap(&h, 0, h.n - 1);
    h.n--;
    sift_down(&h, 0);
  }
  return n;
}
