/* Cooperative cancellation and the phase a long job is in.
 *
 * A command that handles SIGINT/SIGTERM points iris_cancel_watch at the flag
 * its handler sets; every long loop in iris (importers, the BVH build through
 * Embree's progress monitor, texture decoding, photons, caches, training and
 * image passes) polls iris_cancel_requested() often enough to stop within
 * about a second and returns IRIS_ERR_INTERRUPTED through
 * iris_cancel_error(), whose message names the phase (docs/cli.md,
 * "Interrupting a render").
 *
 * Phases are static strings such as "loading the scene" or "tracing
 * photons"; iris_phase_begin records the current one. Test hook: when the
 * environment variable IRIS_TEST_INTERRUPT_IN names a phase key (the word
 * before the first space of iris_phase_begin's key argument: loading, bvh,
 * textures, lights, photons, caches, training, image), entering that phase
 * raises SIGINT (SIGTERM when IRIS_TEST_INTERRUPT_SIGNAL=TERM) in the
 * process, exactly as a user's Ctrl-C at that moment would, after writing
 * the CLOCK_MONOTONIC time to the file IRIS_TEST_INTERRUPT_STAMP names (if
 * set), so that a test can time the stop (tests/render/test_interrupt_phases.c). */
#ifndef IRIS_CORE_CANCEL_H
#define IRIS_CORE_CANCEL_H

#include <signal.h>
#include <stdbool.h>

#include "core/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The flag iris_cancel_requested() reads (NULL: none); returns the previous one. */
volatile sig_atomic_t *iris_cancel_watch(volatile sig_atomic_t *flag);
/* True once the watched flag is non-zero. Async-signal-safe to set, cheap to poll. */
bool iris_cancel_requested(void);

/* Enters a phase: `key` is the hook's name for it (see above), `what` the
 * words for messages ("building the BVH"). Both must be static strings. */
void iris_phase_begin(const char *key, const char *what);
/* The current phase's words ("" before any). */
const char *iris_phase_current(void);

/* Sets IRIS_ERR_INTERRUPTED, "interrupted while <phase>", and returns it. */
iris_status iris_cancel_error(iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
