/* kd-tree: implicit balanced layout (median of each index range, leaves of at
 * most IRIS_KDTREE_LEAF points), bounded max-heap search. */
#include "renderer/guiding/kdtree.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "core/parallel.h"

#define LEAF IRIS_KDTREE_LEAF

/* ---- build ------------------------------------------------------------------ */

/* A point and its index moved as one 16-byte record while partitioning. */
typedef struct kd_rec {
  float p[3];
  uint32_t id;
} kd_rec;

static void swap_rec(kd_rec *a, kd_rec *b) {
  kd_rec t = *a;
  *a = *b;
  *b = t;
}

/* (coordinate ax, index) order: distinct keys, so equal coordinates cost
 * nothing special. Branch-free: the outcome is a coin flip on random points. */
static inline uint32_t rec_less(const kd_rec *a, float v, uint32_t vid, int ax) {
  float k = a->p[ax];
  return (uint32_t)(k < v) | ((uint32_t)(k == v) & (uint32_t)(a->id < vid));
}

#define SAMPLE 31

/* A pivot for finding rank m in [lo, hi): the element of about m's relative
 * rank among SAMPLE evenly spaced items (median of three for short ranges),
 * so each partition cuts close to m. */
static inline uint32_t choose_pivot(const kd_rec *r, uint32_t lo, uint32_t hi, uint32_t m, int ax) {
  uint32_t n = hi - lo;
  if (n < 1024) {
    uint32_t a = lo, b = lo + n / 2, c = hi - 1;
    if (rec_less(&r[b], r[a].p[ax], r[a].id, ax)) { uint32_t t = a; a = b; b = t; }
    if (rec_less(&r[c], r[b].p[ax], r[b].id, ax)) {
      b = c;
      if (rec_less(&r[b], r[a].p[ax], r[a].id, ax)) b = a;
    }
    return b;
  }
  uint32_t idx[SAMPLE];
  for (uint32_t j = 0; j < SAMPLE; ++j) { /* insertion sort of the sample by key */
    uint32_t x = lo + (uint32_t)(((uint64_t)n * (2 * j + 1)) / (2 * SAMPLE)), i = j;
    while (i > 0 && rec_less(&r[x], r[idx[i - 1]].p[ax], r[idx[i - 1]].id, ax)) {
      idx[i] = idx[i - 1];
      --i;
    }
    idx[i] = x;
  }
  return idx[(uint32_t)(((uint64_t)(m - lo) * SAMPLE) / n)];
}

/* Quickselect: puts the element of rank m (by key) at m, smaller keys before,
 * larger after. Branch-free partitions: the smaller keys are compacted in
 * place, the others go to tmp[lo, hi) and are copied back after them, so no load
 * waits for the previous comparison. Short ranges by insertion. */
static inline void select_nth(kd_rec *r, kd_rec *tmp, uint32_t lo, uint32_t hi, uint32_t m, int ax) {
  while (hi - lo > 16) {
    uint32_t piv = choose_pivot(r, lo, hi, m, ax), last = hi - 1;
    swap_rec(&r[piv], &r[last]);
    const kd_rec pv = r[last];
    uint32_t store = lo, right = 0;
    for (uint32_t i = lo; i < last; ++i) {
      kd_rec x = r[i];
      uint32_t lt = rec_less(&x, pv.p[ax], pv.id, ax);
      r[store] = x; /* store <= i: already read */
      tmp[lo + right] = x;
      store += lt;
      right += lt ^ 1u;
    }
    r[store] = pv;
    memcpy(&r[store + 1], &tmp[lo], sizeof(kd_rec) * right);
    if (store == m) return;
    if (m < store) hi = store;
    else lo = store + 1;
  }
  for (uint32_t i = lo + 1; i < hi; ++i) {
    kd_rec x = r[i];
    uint32_t j = i;
    while (j > lo && rec_less(&x, r[j - 1].p[ax], r[j - 1].id, ax)) {
      r[j] = r[j - 1];
      --j;
    }
    r[j] = x;
  }
}

/* Splits [lo, hi) at its median along the widest extent of its points. */
static uint32_t split_range(kd_rec *r, kd_rec *tmp, uint8_t *axis, uint32_t lo, uint32_t hi) {
  float mn[4] = {INFINITY, INFINITY, INFINITY, INFINITY}, mx[4] = {-INFINITY, -INFINITY, -INFINITY, -INFINITY};
  for (uint32_t i = lo; i < hi; ++i) {
    float v[4]; /* all four lanes (the id's bits in the last, ignored): one vector min/max */
    memcpy(v, &r[i], sizeof v);
    for (int k = 0; k < 4; ++k) { /* plain compares: fminf is a libm call here */
      mn[k] = v[k] < mn[k] ? v[k] : mn[k];
      mx[k] = v[k] > mx[k] ? v[k] : mx[k];
    }
  }
  int ax = 0;
  for (int k = 1; k < 3; ++k)
    if (mx[k] - mn[k] > mx[ax] - mn[ax]) ax = k;
  uint32_t m = lo + (hi - lo) / 2;
  switch (ax) { /* a constant axis in each copy: keys at fixed offsets */
  case 0: select_nth(r, tmp, lo, hi, m, 0); break;
  case 1: select_nth(r, tmp, lo, hi, m, 1); break;
  default: select_nth(r, tmp, lo, hi, m, 2); break;
  }
  axis[m] = (uint8_t)ax;
  return m;
}

/* tmp: scratch records, [lo, hi) used. */
static void build_range(kd_rec *r, kd_rec *tmp, uint8_t *axis, uint32_t lo, uint32_t hi) {
  while (hi - lo > LEAF) {
    uint32_t m = split_range(r, tmp, axis, lo, hi);
    build_range(r, tmp, axis, lo, m);
    lo = m + 1; /* loop instead of recursing on the right half */
  }
}

typedef struct build_task {
  uint32_t lo, hi;
} build_task;

typedef struct build_ctx {
  kd_rec *r, *tmp;
  uint8_t *axis;
  build_task *tasks;
  uint32_t task_count;
} build_ctx;

/* The top `depth` levels, serially; the ranges below become tasks. */
static void build_top(build_ctx *c, uint32_t lo, uint32_t hi, int depth) {
  if (hi - lo <= LEAF) return;
  if (depth == 0) {
    c->tasks[c->task_count].lo = lo;
    c->tasks[c->task_count].hi = hi;
    c->task_count++;
    return;
  }
  uint32_t m = split_range(c->r, c->tmp, c->axis, lo, hi);
  build_top(c, lo, m, depth - 1);
  build_top(c, m + 1, hi, depth - 1);
}

static void build_tasks(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  build_ctx *c = ctx;
  for (uint64_t t = begin; t < end; ++t) build_range(c->r, c->tmp, c->axis, c->tasks[t].lo, c->tasks[t].hi);
}

/* Tasks for one group's range [lo, hi): subtrees of at least ~16k points per
 * task are worth a thread; 2 tasks per thread balance the load. The layout
 * does not depend on who builds what. */
static int group_depth(uint32_t n, int threads) {
  int depth = 0;
  if (threads > 1)
    while (depth < 8 && (1 << depth) < 2 * threads && (n >> (depth + 1)) >= 16384) ++depth;
  return depth;
}

iris_status iris_kdtree_build_grouped(iris_kdtree *tree, const void *base, size_t stride, uint32_t count,
                                      const uint32_t *group, uint32_t group_count, int threads,
                                      iris_error *err) {
  memset(tree, 0, sizeof(*tree));
  if (count == 0) return IRIS_OK;
  if (threads <= 0) threads = iris_parallel_default_threads();
  uint32_t groups = group ? group_count : 1;
  uint32_t *start = calloc((size_t)groups + 1, sizeof(uint32_t));
  if (!start) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for a kd-tree");
  for (uint32_t i = 0; i < count; ++i) start[(group ? group[i] : 0) + 1]++;
  size_t max_tasks = 0;
  for (uint32_t g = 0; g < groups; ++g) {
    max_tasks += (size_t)1 << group_depth(start[g + 1], threads);
    start[g + 1] += start[g];
  }
  kd_rec *r = malloc(sizeof(kd_rec) * (size_t)count), *tmp = malloc(sizeof(kd_rec) * (size_t)count);
  build_task *tasks = malloc(sizeof(build_task) * max_tasks);
  uint32_t *at = malloc(sizeof(uint32_t) * groups);
  tree->points = malloc(sizeof(float) * 3 * (size_t)count);
  tree->ids = malloc(sizeof(uint32_t) * count);
  tree->axis = calloc(count, 1);
  if (!r || !tmp || !tasks || !at || !tree->points || !tree->ids || !tree->axis) {
    free(r);
    free(tmp);
    free(tasks);
    free(at);
    free(start);
    iris_kdtree_destroy(tree);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for a kd-tree of %u points",
                          count);
  }
  tree->count = count;
  memcpy(at, start, sizeof(uint32_t) * groups);
  const unsigned char *b = base;
  for (uint32_t i = 0; i < count; ++i) { /* counting sort by group, index order within */
    kd_rec *o = &r[at[group ? group[i] : 0]++];
    memcpy(o->p, b + (size_t)i * stride, sizeof(float) * 3);
    o->id = i;
  }
  free(at);
  build_ctx c = {r, tmp, tree->axis, tasks, 0};
  for (uint32_t g = 0; g < groups; ++g) build_top(&c, start[g], start[g + 1], group_depth(start[g + 1] - start[g], threads));
  if (c.task_count) iris_parallel_for(c.task_count, 1, threads, build_tasks, &c);
  for (uint32_t i = 0; i < count; ++i) {
    memcpy(&tree->points[3 * (size_t)i], r[i].p, sizeof(float) * 3);
    tree->ids[i] = r[i].id;
  }
  free(tasks);
  free(tmp);
  free(r);
  if (group) {
    tree->group_count = groups;
    tree->group_start = start;
  } else {
    free(start);
  }
  return IRIS_OK;
}

iris_status iris_kdtree_build_threads(iris_kdtree *tree, const void *base, size_t stride, uint32_t count,
                                      int threads, iris_error *err) {
  return iris_kdtree_build_grouped(tree, base, stride, count, NULL, 0, threads, err);
}

iris_status iris_kdtree_build(iris_kdtree *tree, const void *base, size_t stride, uint32_t count,
                              iris_error *err) {
  return iris_kdtree_build_threads(tree, base, stride, count, 1, err);
}

iris_status iris_kdtree_set_payload(iris_kdtree *tree, const void *base, size_t stride, size_t size,
                                    iris_error *err) {
  free(tree->payload);
  tree->payload = NULL;
  tree->payload_size = 0;
  if (tree->count == 0 || size == 0) return IRIS_OK;
  tree->payload = malloc(size * tree->count);
  if (!tree->payload)
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for a kd-tree payload");
  tree->payload_size = size;
  const unsigned char *b = base;
  for (uint32_t i = 0; i < tree->count; ++i)
    memcpy(tree->payload + (size_t)i * size, b + (size_t)tree->ids[i] * stride, size);
  return IRIS_OK;
}

void iris_kdtree_destroy(iris_kdtree *tree) {
  free(tree->points);
  free(tree->ids);
  free(tree->axis);
  free(tree->payload);
  free(tree->group_start);
  memset(tree, 0, sizeof(*tree));
}

/* ---- search ----------------------------------------------------------------- */

/* The heap holds tree positions ("slots"); ties in distance are broken by the
 * caller's index, looked up only when two distances are equal. */
typedef struct knn_heap {
  uint32_t k, n;
  uint32_t *slots; /* the caller's ids array until the end */
  float *d2;
  float max_d2;
  const uint32_t *tids; /* tree->ids */
  bool (*accept)(void *ctx, uint32_t id); /* by id; NULL: see accept_payload */
  bool (*accept_payload)(void *ctx, const void *payload); /* NULL with accept NULL: every point */
  const unsigned char *payload;
  size_t payload_size;
  void *ctx;
} knn_heap;

/* Max-heap order on (d2, id): the root is the worst kept neighbour. */
static int worse(const knn_heap *h, uint32_t a, uint32_t b) {
  if (h->d2[a] != h->d2[b]) return h->d2[a] > h->d2[b];
  return h->tids[h->slots[a]] > h->tids[h->slots[b]];
}
static void heap_swap(knn_heap *h, uint32_t a, uint32_t b) {
  float t = h->d2[a];
  h->d2[a] = h->d2[b];
  h->d2[b] = t;
  uint32_t u = h->slots[a];
  h->slots[a] = h->slots[b];
  h->slots[b] = u;
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
static float heap_bound(const knn_heap *h) { return h->n < h->k ? h->max_d2 : h->d2[0]; }

/* Offers tree node i at squared distance d2 (already <= heap_bound). */
static void heap_offer(knn_heap *h, const iris_kdtree *t, uint32_t i, float d2) {
  (void)t;
  if (h->n == h->k && d2 == h->d2[0] && h->tids[i] > h->tids[h->slots[0]]) return;
  if (h->accept && !h->accept(h->ctx, h->tids[i])) return;
  if (h->accept_payload && !h->accept_payload(h->ctx, h->payload + (size_t)i * h->payload_size)) return;
  if (h->n < h->k) {
    uint32_t j = h->n++;
    h->slots[j] = i;
    h->d2[j] = d2;
    while (j > 0) {
      uint32_t p = (j - 1) / 2;
      if (!worse(h, j, p)) break;
      heap_swap(h, j, p);
      j = p;
    }
    return;
  }
  h->slots[0] = i;
  h->d2[0] = d2;
  sift_down(h, 0);
}

static inline float dist2(const float *p, const float q[3]) {
  float dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
  return dx * dx + dy * dy + dz * dz;
}

static void search(const iris_kdtree *t, uint32_t lo, uint32_t hi, const float q[3], knn_heap *h) {
  while (hi - lo > LEAF) {
    uint32_t m = lo + (hi - lo) / 2;
    const float *p = &t->points[3 * (size_t)m];
    float d2 = dist2(p, q);
    if (d2 <= heap_bound(h)) heap_offer(h, t, m, d2);
    int ax = t->axis[m];
    float diff = q[ax] - p[ax];
    /* <= keeps equal-distance points reachable for the index tie-break. */
    if (diff < 0.0f) {
      search(t, lo, m, q, h);
      if (!(diff * diff <= heap_bound(h))) return;
      lo = m + 1;
    } else {
      search(t, m + 1, hi, q, h);
      if (!(diff * diff <= heap_bound(h))) return;
      hi = m;
    }
  }
  for (uint32_t i = lo; i < hi; ++i) {
    float d2 = dist2(&t->points[3 * (size_t)i], q);
    if (d2 <= heap_bound(h)) heap_offer(h, t, i, d2);
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
  while (hi - lo > LEAF) {
    uint32_t m = lo + (hi - lo) / 2;
    const float *p = &t->points[3 * (size_t)m];
    float d2 = dist2(p, q);
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
  for (uint32_t i = lo; i < hi; ++i) { /* a leaf */
    float d2 = dist2(&t->points[3 * (size_t)i], q);
    if (d2 <= s->bound) small_offer(s, t->ids[i], d2);
  }
}

/* Searches the listed groups (NULL: every group; a tree without groups is one). */
static uint32_t knn_heap_run(const iris_kdtree *tree, iris_vec3 q, knn_heap *h, const uint32_t *groups,
                             uint32_t ngroups, uint32_t *slots) {
  float qq[3] = {q.x, q.y, q.z};
  if (!tree->group_count) {
    search(tree, 0, tree->count, qq, h);
  } else if (!groups) {
    for (uint32_t g = 0; g < tree->group_count; ++g) search(tree, tree->group_start[g], tree->group_start[g + 1], qq, h);
  } else {
    for (uint32_t j = 0; j < ngroups; ++j) {
      uint32_t g = groups[j];
      if (g < tree->group_count) search(tree, tree->group_start[g], tree->group_start[g + 1], qq, h);
    }
  }
  /* Heap sort in place: ascending (d2, id). */
  uint32_t n = h->n;
  while (h->n > 1) {
    heap_swap(h, 0, h->n - 1);
    h->n--;
    sift_down(h, 0);
  }
  for (uint32_t j = 0; j < n; ++j) {
    if (slots) slots[j] = h->slots[j];
    h->slots[j] = tree->ids[h->slots[j]];
  }
  return n;
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
    if (!tree->group_count) search_small(tree, 0, tree->count, qq, &s);
    for (uint32_t g = 0; g < tree->group_count; ++g)
      search_small(tree, tree->group_start[g], tree->group_start[g + 1], qq, &s);
    for (uint32_t i = 0; i < s.n; ++i) {
      ids[i] = s.ids[i];
      d2[i] = s.d2[i];
    }
    return s.n;
  }
  knn_heap h = {k, 0, ids, d2, max_d2, tree->ids, accept, NULL, NULL, 0, ctx};
  return knn_heap_run(tree, q, &h, NULL, 0, NULL);
}

uint32_t iris_kdtree_knn_payload_if(const iris_kdtree *tree, iris_vec3 q, uint32_t k, float max_d2,
                                    bool (*accept)(void *ctx, const void *payload), void *ctx,
                                    uint32_t *ids, float *d2, uint32_t *slots) {
  return iris_kdtree_knn_groups_payload_if(tree, q, k, max_d2, NULL, 0, accept, ctx, ids, d2, slots);
}

uint32_t iris_kdtree_knn_groups_payload_if(const iris_kdtree *tree, iris_vec3 q, uint32_t k, float max_d2,
                                           const uint32_t *groups, uint32_t group_count,
                                           bool (*accept)(void *ctx, const void *payload), void *ctx,
                                           uint32_t *ids, float *d2, uint32_t *slots) {
  if (k == 0 || tree->count == 0 || !tree->payload) return 0;
  knn_heap h = {k, 0, ids, d2, max_d2, tree->ids, NULL, accept, tree->payload, tree->payload_size, ctx};
  return knn_heap_run(tree, q, &h, groups, group_count, slots);
}
