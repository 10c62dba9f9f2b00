/* Warnings and progress messages on stderr, silenced by --quiet. The level is
 * process-wide because it mirrors one command-line flag of the `iris` tool. */
#ifndef IRIS_CORE_LOG_H
#define IRIS_CORE_LOG_H

#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum iris_log_level { IRIS_LOG_QUIET = 0, IRIS_LOG_WARN = 1, IRIS_LOG_INFO = 2 } iris_log_level;

void iris_log_set_level(iris_log_level level);
iris_log_level iris_log_get_level(void);
/* "iris: warning: ..." on stderr unless quiet. */
void iris_warnf(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;
/* "iris: ..." on stderr at info level. */
void iris_infof(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;
/* True when progress bars should be drawn: info level and stderr is a terminal. */
bool iris_log_progress_enabled(void);
/* Says that a progress line ending in '\r'-style redrawing (no newline) is on
 * screen: the next warning or message starts on a new line below it. */
void iris_log_progress_drawn(void);
/* Ends an open progress line with its newline (nothing when none is open). */
void iris_log_progress_end(void);

#ifdef __cplusplus
}
#endif
#endif
