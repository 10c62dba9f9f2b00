/* A map from strings to int32 values (stb_ds's string hash map), so that the
 * importers' look-ups by name (groups, materials, textures, libraries) cost
 * O(1) instead of a scan of everything seen so far (docs/fuzzing.md,
 * "Bounded work"). */
#ifndef IRIS_IMPORTERS_STRMAP_H
#define IRIS_IMPORTERS_STRMAP_H

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct iris_strmap {
  void *table; /* stb_ds hash map; NULL = empty (a zero-initialised map is valid) */
} iris_strmap;

/* Inserts a copy of key or overwrites its value. */
void iris_strmap_put(iris_strmap *m, const char *key, int32_t value);
/* The value stored for key, or NULL (valid until the next put). */
int32_t *iris_strmap_find(iris_strmap *m, const char *key);
void iris_strmap_free(iris_strmap *m);

#ifdef __cplusplus
}
#endif
#endif
