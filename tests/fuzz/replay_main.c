/* Replay driver for the libFuzzer harnesses in ordinary (non-fuzzing)
 * builds: every file named on the command line, or found below a named
 * folder, is read into memory and passed once to LLVMFuzzerTestOneInput.
 * Crashes and sanitizer reports surface as a failed CTest; the harness's
 * return value is ignored, as libFuzzer does. */
#include <dirent.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
/* Optional in a harness, as in libFuzzer. */
int LLVMFuzzerInitialize(int *argc, char ***argv) __attribute__((weak));

#define REPLAY_MAX_FILE (64u << 20)

static long g_inputs, g_skipped;

static int replay_file(const char *path) {
  FILE *fp = fopen(path, "rb");
  if (!fp) {
    fprintf(stderr, "replay: %s: cannot open\n", path);
    return 1;
  }
  struct stat st;
  if (fstat(fileno(fp), &st) != 0 || st.st_size > (off_t)REPLAY_MAX_FILE) {
    fclose(fp);
    g_skipped++;
    return 0;
  }
  size_t n = (size_t)st.st_size;
  /* An exact-size allocation, so reads past the end are caught by ASan. */
  uint8_t *buf = malloc(n ? n : 1);
  if (!buf || (n && fread(buf, 1, n, fp) != n)) {
    fprintf(stderr, "replay: %s: cannot read\n", path);
    free(buf);
    fclose(fp);
    return 1;
  }
  fclose(fp);
  LLVMFuzzerTestOneInput(buf, n);
  free(buf);
  g_inputs++;
  return 0;
}

static int cmp_names(const void *a, const void *b) {
  return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* Replays a file, or every regular file below a folder (sorted, for
 * reproducible order). */
static int replay_path(const char *path) {
  struct stat st;
  if (stat(path, &st) != 0) {
    fprintf(stderr, "replay: %s: does not exist\n", path);
    return 1;
  }
  if (!S_ISDIR(st.st_mode)) return S_ISREG(st.st_mode) ? replay_file(path) : 0;
  DIR *d = opendir(path);
  if (!d) {
    fprintf(stderr, "replay: %s: cannot list\n", path);
    return 1;
  }
  char **names = NULL;
  size_t count = 0, cap = 0;
  struct dirent *e;
  while ((e = readdir(d)) != NULL) {
    if (e->d_name[0] == '.') continue;
    if (count == cap) {
      cap = cap ? cap * 2 : 32;
      char **grown = realloc(names, cap * sizeof *names);
      if (!grown) break;
      names = grown;
    }
    size_t len = strlen(path) + strlen(e->d_name) + 2;
    names[count] = malloc(len);
    if (!names[count]) break;
    snprintf(names[count], len, "%s/%s", path, e->d_name);
    count++;
  }
  closedir(d);
  if (count) qsort(names, count, sizeof *names, cmp_names);
  int failed = 0;
  for (size_t i = 0; i < count; i++) {
    failed |= replay_path(names[i]);
    free(names[i]);
  }
  free(names);
  return failed;
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: %s FILE_OR_DIR...\n", argv[0]);
    return 2;
  }
  if (LLVMFuzzerInitialize) LLVMFuzzerInitialize(&argc, &argv);
  int failed = 0;
  for (int i = 1; i < argc; i++) failed |= replay_path(argv[i]);
  printf("replayed %ld inputs (%ld skipped as larger than %u bytes)\n", g_inputs, g_skipped, REPLAY_MAX_FILE);
  return failed;
}
