/* core.fileio: atomic writes leave no temporary on success or abort and never
 * a partial target; whole-file reads and maps return the bytes written; path
 * helpers split names as documented. */
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "core/fileio.h"

static char dir[512];

static void slurp_check(const char *path, const char *want) {
  FILE *fp = fopen(path, "rb");
  char buf[256] = "";
  size_t n = fp ? fread(buf, 1, sizeof buf - 1, fp) : 0;
  if (fp) fclose(fp);
  buf[n] = '\0';
  CHECK_EQ_STR(buf, want);
}

static void test_atomic(void) {
  char path[600];
  iris_error err;
  snprintf(path, sizeof path, "%s/out.txt", dir);

  iris_error_clear(&err);
  CHECK_OK(iris_file_write_atomic(path, "hello", 5, &err), &err);
  slurp_check(path, "hello");
  CHECK_EQ_INT(iris_test_count_entries(dir, ".tmp-"), 0);

  /* Commit replaces an existing file; while open, the target keeps its old contents. */
  iris_atomic_file f;
  iris_error_clear(&err);
  CHECK_OK(iris_atomic_open(&f, path, &err), &err);
  CHECK_EQ_INT(iris_test_count_entries(dir, ".tmp-"), 1);
  CHECK(strncmp(f.temp_path, path, strlen(path)) == 0);
  fputs("new contents", f.fp);
  fflush(f.fp);
  slurp_check(path, "hello");
  CHECK_OK(iris_atomic_commit(&f, &err), &err);
  slurp_check(path, "new contents");
  CHECK_EQ_INT(iris_test_count_entries(dir, ".tmp-"), 0);

  /* Abort removes the temporary and leaves the target alone. */
  CHECK_OK(iris_atomic_open(&f, path, &err), &err);
  fputs("partial", f.fp);
  iris_atomic_abort(&f);
  slurp_check(path, "new contents");
  CHECK_EQ_INT(iris_test_count_entries(dir, ".tmp-"), 0);

  /* Abort of a never-committed new file leaves nothing at all. */
  char path2[600];
  snprintf(path2, sizeof path2, "%s/never.bin", dir);
  CHECK_OK(iris_atomic_open(&f, path2, &err), &err);
  iris_atomic_abort(&f);
  CHECK(!iris_path_exists(path2));
  CHECK_EQ_INT(iris_test_count_entries(dir, "never"), 0);

  /* A folder that does not exist: an I/O error naming the path. */
  char bad[700];
  snprintf(bad, sizeof bad, "%s/no/such/dir/x.txt", dir);
  iris_error_clear(&err);
  CHECK_EQ_INT(iris_file_write_atomic(bad, "x", 1, &err), IRIS_ERR_IO);
  CHECK_EQ_INT(err.status, IRIS_ERR_IO);
  CHECK_EQ_STR(err.file, bad);
}

static void test_read_and_map(void) {
  char path[600];
  iris_error err;
  snprintf(path, sizeof path, "%s/data.bin", dir);
  unsigned char bytes[300];
  for (int i = 0; i < 300; i++) bytes[i] = (unsigned char)(i * 7 + 1);
  bytes[100] = 0; /* embedded NUL */
  iris_error_clear(&err);
  CHECK_OK(iris_file_write_atomic(path, bytes, sizeof bytes, &err), &err);

  char *data = NULL;
  size_t size = 0;
  CHECK_OK(iris_file_read(path, 0, &data, &size, &err), &err);
  CHECK_EQ_INT(size, 300);
  CHECK(data && memcmp(data, bytes, 300) == 0);
  CHECK(data && data[300] == '\0');
  free(data);

  iris_error_clear(&err);
  CHECK_EQ_INT(iris_file_read(path, 299, &data, &size, &err), IRIS_ERR_NOMEM);
  CHECK(data == NULL);
  iris_error_clear(&err);
  CHECK_EQ_INT(iris_file_read(dir, 0, &data, &size, &err), IRIS_ERR_IO); /* a folder */
  char missing[600];
  snprintf(missing, sizeof missing, "%s/missing", dir);
  iris_error_clear(&err);
  CHECK_EQ_INT(iris_file_read(missing, 0, &data, &size, &err), IRIS_ERR_IO);
  CHECK_EQ_STR(err.file, missing);

  iris_file_map map;
  iris_error_clear(&err);
  CHECK_OK(iris_file_map_open(path, &map, &err), &err);
  CHECK_EQ_INT(map.size, 300);
  CHECK(map.data && memcmp(map.data, bytes, 300) == 0);
  iris_file_map_close(&map);
  CHECK(map.data == NULL);

  char empty[600];
  snprintf(empty, sizeof empty, "%s/empty", dir);
  CHECK_OK(iris_file_write_atomic(empty, "", 0, &err), &err);
  CHECK_OK(iris_file_map_open(empty, &map, &err), &err);
  CHECK(map.data == NULL && map.size == 0);
  iris_file_map_close(&map);
  CHECK_OK(iris_file_read(empty, 0, &data, &size, &err), &err);
  CHECK(size == 0 && data && data[0] == '\0');
  free(data);
}

static void test_paths(void) {
  char b[256];
  iris_path_dir("a/b/c.json", b, sizeof b);
  CHECK_EQ_STR(b, "a/b");
  iris_path_dir("c.json", b, sizeof b);
  CHECK_EQ_STR(b, ".");
  iris_path_dir("/c.json", b, sizeof b);
  CHECK_EQ_STR(b, "/");
  iris_path_stem("a/b/c.tar.gz", b, sizeof b);
  CHECK_EQ_STR(b, "c.tar");
  iris_path_stem("a/.hidden", b, sizeof b);
  CHECK_EQ_STR(b, ".hidden");
  iris_path_ext("a.b/C.OBJ", b, sizeof b);
  CHECK_EQ_STR(b, "obj");
  iris_path_ext("a.b/noext", b, sizeof b);
  CHECK_EQ_STR(b, "");
  iris_path_join("a/b", "c.png", b, sizeof b);
  CHECK_EQ_STR(b, "a/b/c.png");
  iris_path_join("a/b", "/abs/c.png", b, sizeof b);
  CHECK_EQ_STR(b, "/abs/c.png");
  iris_path_join(".", "c.png", b, sizeof b);
  CHECK_EQ_STR(b, "c.png");

  char deep[700];
  iris_error err;
  iris_error_clear(&err);
  snprintf(deep, sizeof deep, "%s/x/y/z", dir);
  CHECK_OK(iris_mkdir_p(deep, &err), &err);
  struct stat st;
  CHECK(stat(deep, &st) == 0 && S_ISDIR(st.st_mode));
  CHECK_OK(iris_mkdir_p(deep, &err), &err); /* existing is fine */
}

int main(void) {
  if (iris_test_tmpdir(dir, sizeof dir, "fileio") != 0) {
    fprintf(stderr, "cannot create a temporary directory\n");
    return 1;
  }
  test_atomic();
  test_read_and_map();
  test_paths();
  iris_test_rmtree(dir);
  return TEST_SUMMARY();
}
