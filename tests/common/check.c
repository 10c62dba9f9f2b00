#include "check.h"

#include <dirent.h>
#include <ftw.h>
#include <stdarg.h>
#include <stdlib.h>
#include <unistd.h>

int iris_check_failures = 0;
long iris_check_count = 0;

int iris_check_record(int ok, const char *file, int line, const char *fmt, ...) {
  iris_check_count++;
  if (ok) return 1;
  iris_check_failures++;
  fprintf(stderr, "%s:%d: FAILED: ", file, line);
  va_list ap;
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
  return 0;
}

int iris_check_summary(const char *name) {
  const char *base = strrchr(name, '/');
  printf("%s: %ld checks, %d failed\n", base ? base + 1 : name, iris_check_count, iris_check_failures);
  return iris_check_failures ? 1 : 0;
}

int iris_test_tmpdir(char *out, size_t size, const char *tag) {
  const char *root = getenv("TMPDIR");
  if (!root || !root[0]) root = "/tmp";
  int n = snprintf(out, size, "%s/iris-test-%s-XXXXXX", root, tag ? tag : "tmp");
  if (n < 0 || (size_t)n >= size) return -1;
  return mkdtemp(out) ? 0 : -1;
}

static int remove_entry(const char *path, const struct stat *sb, int flag, struct FTW *ftw) {
  (void)sb;
  (void)flag;
  (void)ftw;
  return remove(path);
}

void iris_test_rmtree(const char *path) {
  if (path && path[0]) nftw(path, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
}

int iris_test_count_entries(const char *dir, const char *needle) {
  DIR *d = opendir(dir);
  if (!d) return -1;
  int n = 0;
  struct dirent *e;
  while ((e = readdir(d)) != NULL)
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") && strstr(e->d_name, needle)) n++;
  closedir(d);
  return n;
}
