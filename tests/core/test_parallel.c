/* core.parallel: every item of [0, count) is visited exactly once, by a
 * thread index in range, for several thread counts, grains and counts. */
#include <stdatomic.h>
#include <stdlib.h>

#include "check.h"
#include "core/parallel.h"

typedef struct visit_ctx {
  atomic_int *hits;
  atomic_int bad_thread;
  atomic_int bad_chunk;
  int threads;
  uint64_t count, grain;
} visit_ctx;

static void visit(void *p, uint64_t begin, uint64_t end, int thread_index) {
  visit_ctx *c = p;
  if (thread_index < 0 || thread_index >= c->threads) atomic_fetch_add(&c->bad_thread, 1);
  if (begin >= end || end > c->count || end - begin > c->grain) atomic_fetch_add(&c->bad_chunk, 1);
  for (uint64_t i = begin; i < end && i < c->count; i++) atomic_fetch_add(&c->hits[i], 1);
}

int main(void) {
  const int threads[] = {1, 2, 3, 8, 0};
  const uint64_t grains[] = {1, 7, 64, 100000, 0};
  const uint64_t counts[] = {0, 1, 5, 1000, 54321};
  int max_threads = iris_parallel_default_threads();
  CHECK(max_threads >= 1);
  for (size_t ti = 0; ti < sizeof threads / sizeof *threads; ti++)
    for (size_t gi = 0; gi < sizeof grains / sizeof *grains; gi++)
      for (size_t ci = 0; ci < sizeof counts / sizeof *counts; ci++) {
        visit_ctx c;
        c.count = counts[ci];
        c.grain = grains[gi] ? grains[gi] : 1; /* grain 0 means 1 */
        c.threads = threads[ti] > 0 ? threads[ti] : max_threads;
        c.hits = calloc(c.count + 1, sizeof *c.hits);
        atomic_init(&c.bad_thread, 0);
        atomic_init(&c.bad_chunk, 0);
        iris_parallel_for(c.count, grains[gi], threads[ti], visit, &c);
        uint64_t wrong = 0;
        for (uint64_t i = 0; i < c.count; i++) wrong += atomic_load(&c.hits[i]) != 1;
        iris_check_record(wrong == 0, __FILE__, __LINE__,
                          "threads %d grain %llu count %llu: %llu items not visited exactly once",
                          threads[ti], (unsigned long long)grains[gi], (unsigned long long)c.count,
                          (unsigned long long)wrong);
        CHECK_EQ_INT(atomic_load(&c.bad_thread), 0);
        CHECK_EQ_INT(atomic_load(&c.bad_chunk), 0);
        free(c.hits);
      }
  double t0 = iris_time_now(), t1 = iris_time_now();
  CHECK(t1 >= t0);
  return TEST_SUMMARY();
}
