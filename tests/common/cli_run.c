/* tests/common/cli_run.h */
#include "cli_run.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/wait.h>

#include "core/fileio.h"

static void slurp(const char *path, char *buf, size_t size) {
  FILE *fp = fopen(path, "rb");
  size_t n = fp ? fread(buf, 1, size - 1, fp) : 0;
  if (fp) fclose(fp);
  buf[n] = '\0';
}

int iris_test_run_cli(const char *dir, const char *bin, const char *args, char *out, size_t out_size,
                      char *err, size_t err_size) {
  char cmd[4096], o[700], e[700];
  snprintf(o, sizeof o, "%s/stdout.txt", dir);
  snprintf(e, sizeof e, "%s/stderr.txt", dir);
  snprintf(cmd, sizeof cmd, "cd '%s' && '%s' %s >'%s' 2>'%s'", dir, bin, args, o, e);
  int status = system(cmd);
  slurp(o, out, out_size);
  slurp(e, err, err_size);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool iris_test_file_exists(const char *dir, const char *name) {
  char p[1200];
  snprintf(p, sizeof p, "%s/%s", dir, name);
  return iris_path_exists(p);
}
