/* Running the iris command from a test as a user would: in a folder, with
 * stdout and stderr captured. */
#ifndef IRIS_TESTS_CLI_RUN_H
#define IRIS_TESTS_CLI_RUN_H

#include <stdbool.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Runs `'bin' ARGS` with `dir` as working folder (args go through the shell);
 * fills out/err (NUL-terminated, truncated to their sizes) and returns the
 * exit code, -1 when the process did not exit normally. */
int iris_test_run_cli(const char *dir, const char *bin, const char *args, char *out, size_t out_size,
                      char *err, size_t err_size);
/* Whether dir/name exists. */
bool iris_test_file_exists(const char *dir, const char *name);

#ifdef __cplusplus
}
#endif
#endif
