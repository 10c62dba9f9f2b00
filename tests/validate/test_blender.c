/* validate.blender: `iris validate --blender` end to end with real Blender
 * (SKIP when it is not installed): a tiny Cornell box, Cycles in 8 batches;
 * the comparison must be made (exit 0 or 1: at 16 spp the verdict is noise),
 * with the exported script, the batch logs, a report and a summary that names
 * Blender as the reference source and carries a reference variance.
 * argv[1]: the iris executable. */
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "check.h"
#include "core/fileio.h"

extern char **environ;

int main(int argc, char **argv) {
  if (argc < 2) return 2;
  char dir[512], out[700], path[800];
  if (iris_test_tmpdir(dir, sizeof dir, "validate-blender") != 0) return 1;
  snprintf(out, sizeof out, "%s/out", dir);
  const char *args[] = {argv[1], "validate", "cornell-box", "--blender", "--blender-spp", "16",
                        "--spp", "16", "--width", "48", "--height", "48", "--threads", "2",
                        "--quiet", "--out", out, NULL};
  pid_t pid;
  if (posix_spawn(&pid, argv[1], NULL, NULL, (char *const *)args, environ) != 0) return 1;
  int status = 0;
  waitpid(pid, &status, 0);
  int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  snprintf(path, sizeof path, "%s/cycles/batch00.log", out);
  if (code == 2 && !iris_path_exists(path)) {
    iris_test_rmtree(dir);
    return TEST_SKIP("Blender is not installed");
  }
  CHECK(code == 0 || code == 1);
  snprintf(path, sizeof path, "%s/cycles/scene.py", out);
  CHECK(iris_path_exists(path));
  snprintf(path, sizeof path, "%s/cycles/batch07.log", out);
  CHECK(iris_path_exists(path));
  snprintf(path, sizeof path, "%s/report.html", out);
  CHECK(iris_path_exists(path));
  snprintf(path, sizeof path, "%s/summary.json", out);
  char *text = NULL;
  size_t size = 0;
  CHECK(iris_file_read(path, 0, &text, &size, NULL) == IRIS_OK);
  if (text) {
    CHECK(strstr(text, "\"source\":\t\"blender\"") != NULL);
    CHECK(strstr(text, "\"has_variance\":\ttrue") != NULL);
    CHECK(strstr(text, "in 8 batches") != NULL);
  }
  free(text);
  iris_test_rmtree(dir);
  return TEST_SUMMARY();
}
