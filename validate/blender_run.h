/* Runs Blender headless on a script exported by exporters/blender.h and
 * collects what it printed: the "IRIS_BLENDER ..." timing line and Blender's
 * version. stdout and stderr go to a log file, kept for the user. */
#ifndef IRIS_VALIDATE_BLENDER_RUN_H
#define IRIS_VALIDATE_BLENDER_RUN_H

#include <stdbool.h>

#include "core/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct iris_blender_run_info {
  char version[64];       /* "3.4.1" ("" when not printed) */
  char command[2048];     /* the command line, shell-quoted for the provenance */
  double build_seconds;   /* from the IRIS_BLENDER line (-1 when missing) */
  double render_seconds;
  double wall_seconds;    /* the whole process, start-up included */
} iris_blender_run_info;

/* The Blender executable: `exe` if given, else $IRIS_BLENDER, else "blender". */
const char *iris_blender_executable(const char *exe);

/* Runs `blender -b --factory-startup --python-exit-code 1 -P script -- args...`
 * (args NULL-terminated). Fails with IRIS_ERR_USAGE when Blender cannot be
 * started, IRIS_ERR_INTERNAL when it exits non-zero (the message names the log). */
iris_status iris_blender_run(const char *exe, const char *script, const char *const *args,
                             const char *log_path, iris_blender_run_info *info, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
