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


/* One branch-free pass over [lo, hi) (the outcome of each comparison is a
 * coin flip on random points): keys < a are compacted in place, keys in
 * [a, b] and keys > b go through tmp[lo, hi) (upwards and downwards; never
 * over a kept item, as fewer than hi - lo are kept) and are copied back
 * after them, so no load waits for an earlier comparison. The middle part
 * is [*mlo, *mhi). */
static inline void partition3(kd_rec *r, kd_rec *tmp, uint32_t lo, uint32_t hi, float a, float b, int ax,
                              uint32_t *mlo, uint32_t *mhi) {
  kd_rec *out_l = r + lo, *out_m = tmp + lo, *out_r = tmp + hi - 1;
  for (const kd_rec *x = r + lo, *end = r + hi; x < end; ++x) {
    kd_rec v; /* whole 16-byte copies (a struct assignment gets split in fields) */
    memcpy(&v, x, sizeof v);
    float k = v.p[ax];
    size_t lt = k < a, gt = k > b;
    memcpy(out_m, &v, sizeof v);
    memcpy(out_r, &v, sizeof v);
    memcpy(out_l, &v, sizeof v); /* out_l <= x: already read (the same item at worst) */
    out_l += lt;
    out_m += (lt | gt) ^ 1u;
    out_r -= gt;
  }
  uint32_t store = (uint32_t)(out_l - r), mc = (uint32_t)(out_m - (tmp + lo)), rc = hi - store - mc;
  memcpy(&r[store], &tmp[lo], sizeof(kd_rec) * mc);
  memcpy(&r[store + mc], &tmp[hi - rc], sizeof(kd_rec) * rc);
  *mlo = store;
  *mhi = store + mc;
}

/* Quickselect: puts an element of rank m (by coordinate ax) at m, keys <= it
 * before and >= it after. Long ranges (Floyd-Rivest style): two pivots from
 * a sorted sample bracket m's rank, so after one pass m almost always lies
 * in the short middle part; short ranges: a median-of-three pivot with
 * equal keys in the middle part (so runs of equal keys end the search
 * instead of making it quadratic); the last few by insertion. */
#define FR_MIN 1024u
static inline void select_nth(kd_rec *r, kd_rec *tmp, uint32_t lo, uint32_t hi, uint32_t m, int ax) {
  bool sample = true;
  while (hi - lo > 16) {
    const uint32_t n = hi - lo;
    float a, b;
    const bool used_sample = sample && n >= FR_MIN;
    if (used_sample) {
      enum { SMAX = 255 };
      const uint32_t S = n >= 65536 ? 255u : (n >= 4096 ? 63u : 31u), delta = n >= 65536 ? 16u : (n >= 4096 ? 8u : 5u);
      float key[SMAX];
      for (uint32_t j = 0; j < S; ++j) { /* insertion sort of the sample */
        float x = r[lo + (uint32_t)(((uint64_t)n * (2 * j + 1)) / (2 * S))].p[ax];
        uint32_t i = j;
        while (i > 0 && key[i - 1] > x) {
          key[i] = key[i - 1];
          --i;
        }
        key[i] = x;
      }
      uint32_t t = (uint32_t)(((uint64_t)(m - lo) * S) / n);
      a = key[t > delta ? t - delta : 0];
      b = key[t + delta < S ? t + delta : S - 1];
    } else {
      float x = r[lo].p[ax], y = r[lo + n / 2].p[ax], z = r[hi - 1].p[ax];
      a = x < y ? (y < z ? y : (x < z ? z : x)) : (x < z ? x : (y < z ? z : y));
      b = a;
    }
    uint32_t mlo, mhi;
    partition3(r, tmp, lo, hi, a, b, ax, &mlo, &mhi);
    if (m < mlo) {
      hi = mlo;
      sample = true;
    } else if (m >= mhi) {
      lo = mhi;
      sample = true;
    } else {
      if (a == b) return; /* the middle part is one key */
      if (mhi - mlo == n && !used_sample) return; /* only with NaN keys (positions must be finite) */
      sample = mhi - mlo < n; /* no progress (the sample spanned all): one pivot next */
      lo = mlo;
      hi = mhi;
    }
  }
  for (uint32_t i = lo + 1; i < hi; ++i) {
    kd_rec x = r[i];
    uint32_t j = i;
    while (j > lo && r[j - 1].p[ax] > x.p[ax]) {
      r[j] = r[j - 1];
      --j;
    }
    r[j] = x;
  }
}

/* The bounds of [lo, hi): min in box[0..2], max in box[3..5]. */
static void range_box(const kd_rec *r, uint32_t lo, uint32_t hi, float box[6]) {
  float mn[4] = {INFINITY, INFINITY, INFINITY, INFINITY}, mx[4] = {-INFINITY, -INFINITY, -INFINITY, -INFINITY};
  for (uint32_t i = lo; i < hi; ++i) {
    float v[4]; /* all four lanes (the id's bits in the last, ignored) */
    memcpy(v, &r[i], sizeof v);
    for (int k = 0; k < 4; ++k) { /* plain compares: fminf is a libm call here */
      mn[k] = v[k] < mn[k] ? v[k] : mn[k];
      mx[k] = v[k] > mx[k] ? v[k] : mx[k];
    }
  }
  for (int k = 0; k < 3; ++k) box[k] = mn[k], box[3 + k] = mx[k];
}

/* Splits [lo, hi) at its median along the widest extent of its cell `box`
 * (the group's bounds cut at the medians above: no pass over the points),
 * and writes the children's cells. */
static uint32_t split_range(kd_rec *r, kd_rec *tmp, uint8_t *axis, uint32_t lo, uint32_t hi, const float box[6],
                            float lbox[6], float rbox[6]) {
  int ax = 0;
  for (int k = 1; k < 3; ++k)
    if (box[3 + k] - box[k] > box[3 + ax] - box[ax]) ax = k;
  uint32_t m = lo + (hi - lo) / 2;
  switch (ax) { /* a constant axis in each copy: keys at fixed offsets */
  case 0: select_nth(r, tmp, lo, hi, m, 0); break;
  case 1: select_nth(r, tmp, lo, hi, m, 1); break;
  default: select_nth(r, tmp, lo, hi, m, 2); break;
  }
  axis[m] = (uint8_t)ax;
  memcpy(lbox, box, sizeof(float) * 6);
  memcpy(rbox, box, sizeof(float) * 6);
  lbox[3 + ax] = r[m].p[ax];
  rbox[ax] = r[m].p[ax];
  return m;
}

/* tmp: scratch records, [lo, hi) used. */
static void build_range(kd_rec *r, kd_rec *tmp, uint8_t *axis, uint32_t lo, uint32_t hi, const float box[6]) {
  float cur[6];
  memcpy(cur, box, sizeof cur);
  while (hi - lo > LEAF) {
    float lbox[6], rbox[6];
    uint32_t m = split_range(r, tmp, axis, lo, hi, cur, lbox, rbox);
    build_range(r, tmp, axis, lo, m, lbox);
    lo = m + 1; /* loop instead of recursing on the right half */
    memcpy(cur, rbox, sizeof cur);
  }
}

typedef struct build_task {
  uint32_t lo, hi;
  float box[6];
} build_task;

typedef struct build_ctx {
  kd_rec *r, *tmp;
  uint8_t *axis;
  build_task *tasks;
  uint32_t task_count;
} build_ctx;

/* The top `depth` levels, serially; the ranges below become tasks. */
static void build_top(build_ctx *c, uint32_t lo, uint32_t hi, int depth, const float box[6]) {
  if (hi - lo <= LEAF) return;
  if (depth == 0) {
    build_task *t = &c->tasks[c->task_count++];
    t->lo = lo;
    t->hi = hi;
    memcpy(t->box, box, sizeof t->box);
    return;
  }
  float lbox[6], rbox[6];
  uint32_t m = split_range(c->r, c->tmp, c->axis, lo, hi, box, lbox, rbox);
  build_top(c, lo, m, depth - 1, lbox);
  build_top(c, m + 1, hi, depth - 1, rbox);
}

static void build_tasks(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  build_ctx *c = ctx;
  for (uint64_t t = begin; t < end; ++t) {
    build_task *k = &c->tasks[t];
    if (isnan(k->box[0])) range_box(c->r, k->lo, k->hi, k->box);
    build_range(c->r, c->tmp, c->axis, k->lo, k->hi, k->box);
  }
}

static int task_larger_first(const void *a, const void *b) {
  const build_task *x = a, *y = b;
  uint32_t nx = x->hi - x->lo, ny = y->hi - y->lo;
  if (nx != ny) return nx > ny ? -1 : 1;
  return x->lo < y->lo ? -1 : (x->lo > y->lo); /* distinct ranges: a total order */
}

#define COPY_CHUNK 16384u
typedef struct copy_ctx {
  iris_kdtree *tree;
  const kd_rec *r;
} copy_ctx;

static void copy_out(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  copy_ctx *c = ctx;
  uint32_t lo = (uint32_t)begin * COPY_CHUNK, hi = (uint32_t)end * COPY_CHUNK;
  if (hi > c->tree->count) hi = c->tree->count;
  for (uint32_t i = lo; i < hi; ++i) {
    memcpy(&c->tree->points[3 * (size_t)i], c->r[i].p, sizeof(float) * 3);
    c->tree->ids[i] = c->r[i].id;
  }
}

typedef struct scatter_ctx {
  const uint32_t *group; /* NULL: all in group 0 */
  uint32_t groups, total;
  uint32_t *at;          /* [chunk][group]: counts, then where the chunk's next item goes */
  const unsigned char *base;
  size_t stride;
  kd_rec *r;
} scatter_ctx;

static void count_chunks(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  scatter_ctx *c = ctx;
  for (uint64_t ch = begin; ch < end; ++ch) {
    uint32_t *at = c->at + ch * c->groups;
    memset(at, 0, sizeof(uint32_t) * c->groups);
    uint32_t lo = (uint32_t)ch * COPY_CHUNK, hi = c->total - lo < COPY_CHUNK ? c->total : lo + COPY_CHUNK;
    for (uint32_t i = lo; i < hi; ++i) {
      uint32_t g = c->group ? c->group[i] : 0;
      if (g < c->groups) at[g]++;
    }
  }
}

static void scatter_chunks(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  scatter_ctx *c = ctx;
  for (uint64_t ch = begin; ch < end; ++ch) {
    uint32_t *at = c->at + ch * c->groups;
    uint32_t lo = (uint32_t)ch * COPY_CHUNK, hi = c->total - lo < COPY_CHUNK ? c->total : lo + COPY_CHUNK;
    for (uint32_t i = lo; i < hi; ++i) {
      uint32_t g = c->group ? c->group[i] : 0;
      if (g >= c->groups) continue;
      kd_rec *o = &c->r[at[g]++];
      memcpy(o->p, c->base + (size_t)i * c->stride, sizeof(float) * 3);
      o->id = i;
    }
  }
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
  /* Counting sort by group (index order within), in fixed chunks: counts per
   * chunk in parallel, offsets, then each chunk scatters its points. */
  const uint32_t total = count, chunks = (total + COPY_CHUNK - 1) / COPY_CHUNK;
  uint32_t *start = calloc((size_t)groups + 1, sizeof(uint32_t));
  uint32_t *at = malloc(sizeof(uint32_t) * groups * (size_t)chunks);
  if (!start || !at) {
    free(start);
    free(at);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for a kd-tree");
  }
  scatter_ctx sc = {group, groups, total, at, base, stride, NULL};
  iris_parallel_for(chunks, 1, threads, count_chunks, &sc);
  for (uint32_t ch = 0; ch < chunks; ++ch)
    for (uint32_t g = 0; g < groups; ++g) start[g + 1] += at[(size_t)ch * groups + g];
  size_t max_tasks = 0;
  for (uint32_t g = 0; g < groups; ++g) {
    max_tasks += (size_t)1 << group_depth(start[g + 1], threads);
    start[g + 1] += start[g];
  }
  for (uint32_t g = 0; g < groups; ++g) { /* chunk offsets */
    uint32_t o = start[g];
    for (uint32_t ch = 0; ch < chunks; ++ch) {
      uint32_t n = at[(size_t)ch * groups + g];
      at[(size_t)ch * groups + g] = o;
      o += n;
    }
  }
  count = start[groups]; /* points in some group */
  if (count == 0) {
    free(start);
    free(at);
    return IRIS_OK;
  }
  kd_rec *r = malloc(sizeof(kd_rec) * (size_t)count), *tmp = malloc(sizeof(kd_rec) * (size_t)count);
  build_task *tasks = malloc(sizeof(build_task) * max_tasks);
  tree->points = malloc(sizeof(float) * 3 * (size_t)count);
  tree->ids = malloc(sizeof(uint32_t) * count);
  tree->axis = calloc(count, 1);
  if (!r || !tmp || !tasks || !tree->points || !tree->ids || !tree->axis) {
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
  sc.r = r;
  iris_parallel_for(chunks, 1, threads, scatter_chunks, &sc);
  free(at);
  build_ctx c = {r, tmp, tree->axis, tasks, 0};
  for (uint32_t g = 0; g < groups; ++g) {
    /* Only a group too big to balance as one task has its top levels split
     * here (serially); the others are whole tasks, their bounds found there. */
    uint32_t n = start[g + 1] - start[g];
    int depth = (uint64_t)n * 2u * (uint64_t)threads > count ? group_depth(n, threads) : 0;
    if (depth == 0 && n > LEAF) {
      build_task *t = &c.tasks[c.task_count++];
      t->lo = start[g];
      t->hi = start[g + 1];
      t->box[0] = NAN; /* bounds not known yet */
      continue;
    }
    float box[6];
    range_box(r, start[g], start[g + 1], box);
    build_top(&c, start[g], start[g + 1], depth, box);
  }
  /* Largest first: the last tasks to start are the short ones. */
  qsort(c.tasks, c.task_count, sizeof(build_task), task_larger_first);
  if (c.task_count) iris_parallel_for(c.task_count, 1, threads, build_tasks, &c);
  iris_parallel_for((count + COPY_CHUNK - 1) / COPY_CHUNK, 1, threads, copy_out, &(copy_ctx){tree, r});
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

typedef struct payload_ctx {
  iris_kdtree *tree;
  const unsigned char *base;
  size_t stride, size;
} payload_ctx;

static void gather_payload(void *ctx, uint64_t begin, uint64_t end, int thread_index) {
  (void)thread_index;
  payload_ctx *c = ctx;
  uint32_t lo = (uint32_t)begin * COPY_CHUNK, hi = (uint32_t)end * COPY_CHUNK;
  if (hi > c->tree->count) hi = c->tree->count;
  const uint32_t *ids = c->tree->ids;
  for (uint32_t i = lo; i < hi; ++i) { /* random reads: fetch a few items ahead */
    if (i + 8 < hi) __builtin_prefetch(c->base + (size_t)ids[i + 8] * c->stride);
    memcpy(c->tree->payload + (size_t)i * c->size, c->base + (size_t)ids[i] * c->stride, c->size);
  }
}

iris_status iris_kdtree_set_payload(iris_kdtree *tree, const void *base, size_t stride, size_t size, int threads,
                                    iris_error *err) {
  free(tree->payload);
  tree->payload = NULL;
  tree->payload_size = 0;
  if (tree->count == 0 || size == 0) return IRIS_OK;
  tree->payload = malloc(size * tree->count);
  if (!tree->payload)
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory for a kd-tree payload");
  tree->payload_size = size;
  payload_ctx c = {tree, base, stride, size};
  iris_parallel_for((tree->count + COPY_CHUNK - 1) / COPY_CHUNK, 1, threads, gather_payload, &c);
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

/* Large k (filling caches, k = 200): candidates better than the k-th best so
 * far are appended to a buffer of 2k; when it is full, a selection keeps the
 * k best and tightens the bound; at the end the k best are sorted. Keys are
 * (d2 bits << 32 | id): squared distances are >= +0, so integer order is
 * (distance, index) order, and every comparison is one integer compare. */
#define BUF_K_MAX 512
typedef struct kbuf_entry {
  uint64_t key;
  uint32_t slot;
} kbuf_entry;

typedef struct knn_buf {
  uint32_t k, n;
  kbuf_entry *e;   /* 2k */
  kbuf_entry *tmp; /* 2k scratch */
  float bound;        /* squared distance of bound_key */
  uint64_t bound_key; /* only keys below it can still be among the k best */
  uint64_t max_key;   /* bound_key from max_d2 alone */
  const uint32_t *tids;
  bool (*accept)(void *ctx, uint32_t id);
  bool (*accept_payload)(void *ctx, const void *payload);
  const unsigned char *payload;
  size_t payload_size;
  void *ctx;
} knn_buf;

static inline uint64_t make_key(float d2, uint32_t id) {
  uint32_t bits;
  memcpy(&bits, &d2, sizeof bits);
  return (uint64_t)bits << 32 | id;
}

/* Branch-free partition of e[lo, hi) around its median of three (keys are
 * distinct): smaller keys compacted in place, then the pivot, then the
 * larger ones (through tmp). Returns the pivot's position. */
static uint32_t partition_keys(kbuf_entry *e, kbuf_entry *tmp, uint32_t lo, uint32_t hi) {
  uint32_t a = lo, b = lo + (hi - lo) / 2, c = hi - 1;
  uint64_t x = e[a].key, y = e[b].key, z = e[c].key;
  uint32_t p = x < y ? (y < z ? b : (x < z ? c : a)) : (x < z ? a : (y < z ? c : b));
  kbuf_entry pv = e[p];
  e[p] = e[hi - 1];
  uint32_t store = lo, right = 0;
  for (uint32_t i = lo; i < hi - 1; ++i) {
    kbuf_entry xe = e[i];
    uint32_t lt = xe.key < pv.key;
    e[store] = xe; /* store <= i: already read */
    tmp[right] = xe;
    store += lt;
    right += lt ^ 1u;
  }
  e[store] = pv;
  memcpy(&e[store + 1], tmp, sizeof(kbuf_entry) * right);
  return store;
}

static void insertion_sort_keys(kbuf_entry *e, uint32_t lo, uint32_t hi) {
  for (uint32_t i = lo + 1; i < hi; ++i) {
    kbuf_entry x = e[i];
    uint32_t j = i;
    while (j > lo && e[j - 1].key > x.key) {
      e[j] = e[j - 1];
      --j;
    }
    e[j] = x;
  }
}

/* Puts the k-th smallest key at e[k - 1], smaller ones before (k >= 1). */
static void select_keys(kbuf_entry *e, kbuf_entry *tmp, uint32_t n, uint32_t k) {
  uint32_t lo = 0, hi = n, m = k - 1;
  while (hi - lo > 12) {
    uint32_t j = partition_keys(e, tmp, lo, hi);
    if (m == j) return;
    if (m < j) hi = j;
    else lo = j + 1;
  }
  insertion_sort_keys(e, lo, hi);
}

static void sort_keys(kbuf_entry *e, kbuf_entry *tmp, uint32_t lo, uint32_t hi) {
  while (hi - lo > 12) {
    uint32_t j = partition_keys(e, tmp, lo, hi);
    if (j - lo < hi - j) { /* recurse into the smaller side */
      sort_keys(e, tmp, lo, j);
      lo = j + 1;
    } else {
      sort_keys(e, tmp, j + 1, hi);
      hi = j;
    }
  }
  insertion_sort_keys(e, lo, hi);
}

static void buf_offer(knn_buf *b, uint32_t i, float d2) {
  uint64_t key = make_key(d2, b->tids[i]);
  if (key >= b->bound_key) return;
  if (b->accept && !b->accept(b->ctx, b->tids[i])) return;
  if (b->accept_payload && !b->accept_payload(b->ctx, b->payload + (size_t)i * b->payload_size)) return;
  b->e[b->n].key = key;
  b->e[b->n].slot = i;
  if (++b->n == b->k && b->bound_key == b->max_key) { /* the first k: the worst bounds the rest */
    uint64_t worst = 0;
    for (uint32_t j = 0; j < b->k; ++j) worst = b->e[j].key > worst ? b->e[j].key : worst;
    b->bound_key = worst; /* kept already: the next must be better */
    uint32_t bits = (uint32_t)(worst >> 32);
    memcpy(&b->bound, &bits, sizeof bits);
  } else if (b->n == 2 * b->k) {
    select_keys(b->e, b->tmp, b->n, b->k);
    b->n = b->k;
    b->bound_key = b->e[b->k - 1].key;
    uint32_t bits = (uint32_t)(b->bound_key >> 32);
    memcpy(&b->bound, &bits, sizeof bits);
  }
}

static void search_buf(const iris_kdtree *t, uint32_t lo, uint32_t hi, const float q[3], knn_buf *b) {
  while (hi - lo > LEAF) {
    uint32_t m = lo + (hi - lo) / 2;
    const float *p = &t->points[3 * (size_t)m];
    float d2 = dist2(p, q);
    if (d2 <= b->bound) buf_offer(b, m, d2);
    int ax = t->axis[m];
    float diff = q[ax] - p[ax];
    /* <= keeps equal-distance points reachable for the index tie-break. */
    if (diff < 0.0f) {
      search_buf(t, lo, m, q, b);
      if (!(diff * diff <= b->bound)) return;
      lo = m + 1;
    } else {
      search_buf(t, m + 1, hi, q, b);
      if (!(diff * diff <= b->bound)) return;
      hi = m;
    }
  }
  for (uint32_t i = lo; i < hi; ++i) {
    float d2 = dist2(&t->points[3 * (size_t)i], q);
    if (d2 <= b->bound) buf_offer(b, i, d2);
  }
}

static uint32_t knn_buf_run(const iris_kdtree *tree, iris_vec3 q, const knn_heap *h, const uint32_t *groups,
                            uint32_t ngroups, uint32_t *slots) {
  kbuf_entry e[2 * BUF_K_MAX], tmp[2 * BUF_K_MAX];
  const uint64_t max_key = make_key(h->max_d2, UINT32_MAX);
  knn_buf b = {h->k, 0, e, tmp, h->max_d2, max_key, max_key, tree->ids, h->accept, h->accept_payload,
               h->payload, h->payload_size, h->ctx};
  float qq[3] = {q.x, q.y, q.z};
  if (!tree->group_count) {
    search_buf(tree, 0, tree->count, qq, &b);
  } else if (!groups) {
    for (uint32_t g = 0; g < tree->group_count; ++g) search_buf(tree, tree->group_start[g], tree->group_start[g + 1], qq, &b);
  } else {
    for (uint32_t j = 0; j < ngroups; ++j) {
      uint32_t g = groups[j];
      if (g < tree->group_count) search_buf(tree, tree->group_start[g], tree->group_start[g + 1], qq, &b);
    }
  }
  if (b.n > b.k) {
    select_keys(b.e, b.tmp, b.n, b.k);
    b.n = b.k;
  }
  sort_keys(b.e, b.tmp, 0, b.n);
  for (uint32_t j = 0; j < b.n; ++j) {
    uint32_t bits = (uint32_t)(b.e[j].key >> 32);
    memcpy(&h->d2[j], &bits, sizeof bits);
    h->slots[j] = (uint32_t)b.e[j].key; /* the id */
    if (slots) slots[j] = b.e[j].slot;
  }
  return b.n;
}

/* Searches the listed groups (NULL: every group; a tree without groups is one). */
static uint32_t knn_heap_run(const iris_kdtree *tree, iris_vec3 q, knn_heap *h, const uint32_t *groups,
                             uint32_t ngroups, uint32_t *slots) {
  if (h->k <= BUF_K_MAX) return knn_buf_run(tree, q, h, groups, ngroups, slots);
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
