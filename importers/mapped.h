/* The file entry points of the text importers (OBJ, PLY): map the file and
 * hand its bytes to the importer's _memory form, which does all the work.
 * Header-only, internal to importers/. */
#ifndef IRIS_IMPORTERS_MAPPED_H
#define IRIS_IMPORTERS_MAPPED_H

#include "core/fileio.h"
#include "importers/import.h"

typedef iris_status (*iris_import_memory_fn)(const char *data, size_t size, const char *path,
                                             const iris_import_options *opts, iris_scene **out,
                                             iris_error *err);

static inline iris_status iris_import_mapped(const char *path, iris_import_memory_fn import_memory,
                                             const iris_import_options *opts, iris_scene **out,
                                             iris_error *err) {
  *out = NULL;
  iris_file_map map;
  iris_status st = iris_file_map_open(path, &map, err);
  if (st != IRIS_OK) return st;
  st = import_memory(map.data, map.size, path, opts, out, err);
  iris_file_map_close(&map);
  return st;
}

#endif
