/* A minimal fork-join parallel-for on pthreads. Work is handed out in chunks
 * from an atomic counter; results must be written per item (never reduced in
 * completion order) so that output does not depend on the thread count. */
#ifndef IRIS_CORE_PARALLEL_H
#define IRIS_CORE_PARALLEL_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Number of online CPUs (at least 1). */
int iris_parallel_default_threads(void);

/* Calls body(ctx, begin, end, thread_index) over [0, count) in chunks of at most
 * `grain` items, on `threads` threads (<= 0 means all cores). thread_index is in
 * [0, threads) and may be used to pick per-thread scratch memory. */
void iris_parallel_for(uint64_t count, uint64_t grain, int threads,
                       void (*body)(void *ctx, uint64_t begin, uint64_t end, int thread_index),
                       void *ctx);

/* Seconds from a monotonic clock. */
double iris_time_now(void);

#ifdef __cplusplus
}
#endif
#endif
