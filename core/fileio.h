/* File helpers: whole-file reads, read-only memory maps, and atomic writes
 * (a temporary file in the same folder renamed over the target on success, so
 * a failed or interrupted write never leaves a partial output file). */
#ifndef IRIS_CORE_FILEIO_H
#define IRIS_CORE_FILEIO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "core/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Reads a whole file into a malloc'ed buffer with a terminating NUL (not
 * counted in *size). Files larger than max_size are refused (0 = no limit). */
iris_status iris_file_read(const char *path, size_t max_size, char **data, size_t *size,
                           iris_error *err);

/* Read-only memory map of a whole file (an empty file maps to NULL, size 0). */
typedef struct iris_file_map {
  void *data;
  size_t size;
} iris_file_map;
iris_status iris_file_map_open(const char *path, iris_file_map *map, iris_error *err);
void iris_file_map_close(iris_file_map *map);

/* Atomic writer: iris_atomic_open creates "<path>.tmp-XXXXXX" next to path;
 * iris_atomic_commit flushes, closes and renames; iris_atomic_abort removes the
 * temporary. Exactly one of commit/abort must be called. */
typedef struct iris_atomic_file {
  FILE *fp;
  char final_path[1024];
  char temp_path[1040];
} iris_atomic_file;
iris_status iris_atomic_open(iris_atomic_file *f, const char *path, iris_error *err);
iris_status iris_atomic_commit(iris_atomic_file *f, iris_error *err);
void iris_atomic_abort(iris_atomic_file *f);

/* Writes a buffer to path atomically. */
iris_status iris_file_write_atomic(const char *path, const void *data, size_t size,
                                   iris_error *err);

/* Path helpers. dir_of("a/b/c.json") = "a/b", dir_of("c.json") = ".". */
void iris_path_dir(const char *path, char *out, size_t size);
/* File name without folder and without the last extension: "a/b/c.json" -> "c". */
void iris_path_stem(const char *path, char *out, size_t size);
/* Lower-case extension without dot ("" if none). */
void iris_path_ext(const char *path, char *out, size_t size);
/* Joins dir and a relative name; absolute names are returned unchanged. */
void iris_path_join(const char *dir, const char *name, char *out, size_t size);
bool iris_path_exists(const char *path);
/* Creates a directory and its parents (like mkdir -p). */
iris_status iris_mkdir_p(const char *path, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
