/* String map (see strmap.h) on stb_ds (Debian's libstb carries the
 * implementation), keys copied with sh_new_strdup. stb_ds aborts when out of
 * memory, like the other allocations of a few bytes per name. */
#include "importers/strmap.h"

#include <stddef.h>
#include <stb_ds.h>

typedef struct entry {
  char *key;
  int32_t value;
} entry;

void iris_strmap_put(iris_strmap *m, const char *key, int32_t value) {
  entry *t = m->table;
  if (!t) sh_new_strdup(t);
  shput(t, key, value);
  m->table = t;
}

int32_t *iris_strmap_find(iris_strmap *m, const char *key) {
  entry *t = m->table;
  if (!t) return NULL;
  ptrdiff_t i = shgeti(t, key);
  m->table = t; /* shgeti may update the table's bookkeeping */
  return i < 0 ? NULL : &t[i].value;
}

void iris_strmap_free(iris_strmap *m) {
  entry *t = m->table;
  shfree(t);
  m->table = NULL;
}
