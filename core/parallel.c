#include "core/parallel.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

int iris_parallel_default_threads(void) {
  long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n > 0 ? (int)n : 1;
}

typedef struct job {
  uint64_t count, grain;
  atomic_uint_fast64_t next;
  void (*body)(void *, uint64_t, uint64_t, int);
  void *ctx;
} job;

typedef struct worker {
  job *job;
  int index;
} worker;

static void run_worker(job *j, int index) {
  for (;;) {
    uint64_t begin = atomic_fetch_add(&j->next, j->grain);
    if (begin >= j->count) break;
    uint64_t end = begin + j->grain < j->count ? begin + j->grain : j->count;
    j->body(j->ctx, begin, end, index);
  }
}

static void *thread_main(void *arg) {
  worker *w = (worker *)arg;
  run_worker(w->job, w->index);
  return NULL;
}

void iris_parallel_for(uint64_t count, uint64_t grain, int threads,
                       void (*body)(void *ctx, uint64_t begin, uint64_t end, int thread_index),
                       void *ctx) {
  if (count == 0) return;
  if (grain == 0) grain = 1;
  if (threads <= 0) threads = iris_parallel_default_threads();
  uint64_t chunks = (count + grain - 1) / grain;
  if ((uint64_t)threads > chunks) threads = (int)chunks;
  job j;
  j.count = count;
  j.grain = grain;
  atomic_init(&j.next, 0);
  j.body = body;
  j.ctx = ctx;
  if (threads <= 1) {
    run_worker(&j, 0);
    return;
  }
  pthread_t *tids = malloc(sizeof(pthread_t) * (size_t)threads);
  worker *ws = malloc(sizeof(worker) * (size_t)threads);
  int started = 0;
  if (tids && ws) {
    for (int i = 1; i < threads; i++) {
      ws[i].job = &j;
      ws[i].index = i;
      if (pthread_create(&tids[i], NULL, thread_main, &ws[i]) != 0) break;
      started = i;
    }
  }
  run_worker(&j, 0); /* the caller is worker 0; if threads failed to start it does all */
  for (int i = 1; i <= started; i++) pthread_join(tids[i], NULL);
  free(tids);
  free(ws);
}

double iris_time_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
