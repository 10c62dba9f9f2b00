#include "core/fileio.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

iris_status iris_file_read(const char *path, size_t max_size, char **data, size_t *size,
                           iris_error *err) {
  *data = NULL;
  *size = 0;
  FILE *fp = fopen(path, "rb");
  if (!fp) return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "cannot open: %s", strerror(errno));
  struct stat st;
  if (fstat(fileno(fp), &st) != 0 || !S_ISREG(st.st_mode)) {
    fclose(fp);
    return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "not a regular file");
  }
  size_t n = (size_t)st.st_size;
  if (max_size && n > max_size) {
    fclose(fp);
    return iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "file is too large (%zu bytes)", n);
  }
  char *buf = malloc(n + 1);
  if (!buf) {
    fclose(fp);
    return iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "out of memory reading %zu bytes", n);
  }
  if (n && fread(buf, 1, n, fp) != n) {
    free(buf);
    fclose(fp);
    return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "read failed");
  }
  fclose(fp);
  buf[n] = '\0';
  *data = buf;
  *size = n;
  return IRIS_OK;
}

iris_status iris_file_map_open(const char *path, iris_file_map *map, iris_error *err) {
  map->data = NULL;
  map->size = 0;
  int fd = open(path, O_RDONLY);
  if (fd < 0) return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "cannot open: %s", strerror(errno));
  struct stat st;
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    close(fd);
    return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "not a regular file");
  }
  if (st.st_size == 0) {
    close(fd);
    return IRIS_OK;
  }
  void *p = mmap(NULL, (size_t)st.st_size, PROT_READ, MAP_PRIVATE, fd, 0);
  close(fd);
  if (p == MAP_FAILED) return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "mmap failed: %s", strerror(errno));
  map->data = p;
  map->size = (size_t)st.st_size;
  return IRIS_OK;
}

void iris_file_map_close(iris_file_map *map) {
  if (map && map->data) munmap(map->data, map->size);
  if (map) {
    map->data = NULL;
    map->size = 0;
  }
}

iris_status iris_atomic_open(iris_atomic_file *f, const char *path, iris_error *err) {
  memset(f, 0, sizeof *f);
  if (strlen(path) >= sizeof f->final_path)
    return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "path is too long");
  strcpy(f->final_path, path);
  snprintf(f->temp_path, sizeof f->temp_path, "%s.tmp-XXXXXX", path);
  int fd = mkstemp(f->temp_path);
  if (fd < 0) return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "cannot create: %s", strerror(errno));
  /* mkstemp makes 0600 files; give outputs the usual umask-respecting mode. */
  mode_t mask = umask(0);
  umask(mask);
  fchmod(fd, 0666 & ~mask);
  f->fp = fdopen(fd, "wb");
  if (!f->fp) {
    close(fd);
    unlink(f->temp_path);
    return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "cannot open for writing");
  }
  return IRIS_OK;
}

iris_status iris_atomic_commit(iris_atomic_file *f, iris_error *err) {
  int bad = ferror(f->fp);
  if (fflush(f->fp) != 0) bad = 1;
  if (fclose(f->fp) != 0) bad = 1;
  f->fp = NULL;
  if (bad) {
    unlink(f->temp_path);
    return iris_error_set(err, IRIS_ERR_IO, f->final_path, 0, NULL, "write failed (disk full?)");
  }
  if (rename(f->temp_path, f->final_path) != 0) {
    int e = errno;
    unlink(f->temp_path);
    return iris_error_set(err, IRIS_ERR_IO, f->final_path, 0, NULL, "cannot rename into place: %s", strerror(e));
  }
  return IRIS_OK;
}

void iris_atomic_abort(iris_atomic_file *f) {
  if (f->fp) fclose(f->fp);
  f->fp = NULL;
  if (f->temp_path[0]) unlink(f->temp_path);
}

iris_status iris_file_write_atomic(const char *path, const void *data, size_t size, iris_error *err) {
  iris_atomic_file f;
  iris_status st = iris_atomic_open(&f, path, err);
  if (st != IRIS_OK) return st;
  if (size && fwrite(data, 1, size, f.fp) != size) {
    iris_atomic_abort(&f);
    return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "write failed");
  }
  return iris_atomic_commit(&f, err);
}

void iris_path_dir(const char *path, char *out, size_t size) {
  const char *slash = strrchr(path, '/');
  if (!slash) {
    snprintf(out, size, ".");
    return;
  }
  size_t n = (size_t)(slash - path);
  if (n == 0) n = 1; /* "/file" -> "/" */
  if (n >= size) n = size - 1;
  memcpy(out, path, n);
  out[n] = '\0';
}

void iris_path_stem(const char *path, char *out, size_t size) {
  const char *base = strrchr(path, '/');
  base = base ? base + 1 : path;
  const char *dot = strrchr(base, '.');
  size_t n = dot && dot != base ? (size_t)(dot - base) : strlen(base);
  if (n >= size) n = size - 1;
  memcpy(out, base, n);
  out[n] = '\0';
}

void iris_path_ext(const char *path, char *out, size_t size) {
  const char *base = strrchr(path, '/');
  base = base ? base + 1 : path;
  const char *dot = strrchr(base, '.');
  out[0] = '\0';
  if (!dot || dot == base) return;
  size_t i = 0;
  for (const char *c = dot + 1; *c && i + 1 < size; c++) out[i++] = (char)tolower((unsigned char)*c);
  out[i] = '\0';
}

void iris_path_join(const char *dir, const char *name, char *out, size_t size) {
  if (name[0] == '/' || !dir || !dir[0] || strcmp(dir, ".") == 0)
    snprintf(out, size, "%s", name);
  else
    snprintf(out, size, "%s/%s", dir, name);
}

bool iris_path_exists(const char *path) {
  struct stat st;
  return stat(path, &st) == 0;
}

iris_status iris_mkdir_p(const char *path, iris_error *err) {
  char buf[1024];
  if (strlen(path) >= sizeof buf) return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "path is too long");
  strcpy(buf, path);
  for (char *p = buf + 1; *p; p++) {
    if (*p != '/') continue;
    *p = '\0';
    if (mkdir(buf, 0777) != 0 && errno != EEXIST)
      return iris_error_set(err, IRIS_ERR_IO, buf, 0, NULL, "cannot create directory: %s", strerror(errno));
    *p = '/';
  }
  if (mkdir(buf, 0777) != 0 && errno != EEXIST)
    return iris_error_set(err, IRIS_ERR_IO, buf, 0, NULL, "cannot create directory: %s", strerror(errno));
  return IRIS_OK;
}
