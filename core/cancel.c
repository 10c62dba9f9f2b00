/* Cooperative cancellation and phases; see cancel.h. */
#include "core/cancel.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static volatile sig_atomic_t *g_flag;
static const char *g_phase = "";

volatile sig_atomic_t *iris_cancel_watch(volatile sig_atomic_t *flag) {
  volatile sig_atomic_t *old = g_flag;
  g_flag = flag;
  return old;
}

bool iris_cancel_requested(void) {
  volatile sig_atomic_t *f = g_flag;
  return f && *f;
}

void iris_phase_begin(const char *key, const char *what) {
  g_phase = what ? what : "";
  const char *hook = getenv("IRIS_TEST_INTERRUPT_IN");
  if (hook && key && strcmp(hook, key) == 0) {
    const char *sig = getenv("IRIS_TEST_INTERRUPT_SIGNAL"), *stamp = getenv("IRIS_TEST_INTERRUPT_STAMP");
    FILE *f = stamp ? fopen(stamp, "w") : NULL;
    if (f) { /* when the signal was raised (CLOCK_MONOTONIC), for the test to time the stop */
      struct timespec ts;
      clock_gettime(CLOCK_MONOTONIC, &ts);
      fprintf(f, "%.6f\n", (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec);
      fclose(f);
    }
    raise(sig && strcmp(sig, "TERM") == 0 ? SIGTERM : SIGINT);
  }
}

const char *iris_phase_current(void) { return g_phase; }

iris_status iris_cancel_error(iris_error *err) {
  if (g_phase[0])
    return iris_error_set(err, IRIS_ERR_INTERRUPTED, NULL, 0, NULL, "interrupted while %s", g_phase);
  return iris_error_set(err, IRIS_ERR_INTERRUPTED, NULL, 0, NULL, "interrupted");
}
