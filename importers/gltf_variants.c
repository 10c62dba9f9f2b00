/* KHR_materials_variants: the root's variant names and each primitive's
 * mappings {material, variants}, validated strictly, and the material a
 * primitive uses when iris_import_options.variant chooses a variant (the
 * mapping's that lists it, else the primitive's own material, as the
 * extension says). docs/import-gltf.md, "Material variants". */
#include <stdlib.h>
#include <string.h>

#include "importers/gltf_private.h"

#define ROOT "KHR_materials_variants"

/* "\"a\", \"b\", \"c\"", cut with "..." when longer than the buffer allows. */
static void list_names(const iris_gltf_doc *d, char *buf, size_t size) {
  size_t used = 0;
  buf[0] = '\0';
  for (size_t i = 0; i < d->variant_count; i++) {
    int w = snprintf(buf + used, size - used, "%s\"%s\"", i ? ", " : "", d->variant_names[i]);
    if (w < 0 || (size_t)w >= size - used) {
      if (size > 4) memcpy(buf + size - 4, "...", 4);
      return;
    }
    used += (size_t)w;
  }
}

static iris_status check_primitive(gltf_ctx *c, size_t mi, size_t pi, uint32_t *seen, uint32_t stamp) {
  const iris_gltf_doc *d = c->doc;
  const iris_gltf_primitive *p = &d->meshes[mi].primitives[pi];
  char el[96];
  ELEMENT(el, "mesh %zu primitive %zu", mi, pi);
  if (p->variants_bad) return gltf_fail(c, IRIS_ERR_INVALID, el, ROOT " %s", p->variants_bad);
  for (size_t k = 0; k < p->mapping_count; k++) {
    const iris_gltf_variant_mapping *m = &p->mappings[k];
    if (m->bad) return gltf_fail(c, IRIS_ERR_INVALID, el, ROOT " mapping %zu: %s", k, m->bad);
    if (m->material < 0 || (size_t)m->material >= d->material_count)
      return gltf_fail(c, IRIS_ERR_INVALID, el, ROOT " mapping %zu: material %d does not exist (%zu materials)", k,
                       m->material, d->material_count);
    for (size_t j = 0; j < m->variant_count; j++) {
      int v = m->variants[j];
      if (v < 0 || (size_t)v >= d->variant_count)
        return gltf_fail(c, IRIS_ERR_INVALID, el, ROOT " mapping %zu: variant %d out of range (%zu variants)", k, v,
                         d->variant_count);
      /* One material per variant and primitive, or the choice would be ambiguous. */
      if (seen[v] == stamp)
        return gltf_fail(c, IRIS_ERR_INVALID, el, ROOT " mapping %zu: variant %d is mapped twice", k, v);
      seen[v] = stamp;
    }
  }
  return IRIS_OK;
}

iris_status gltf_validate_variants(gltf_ctx *c) {
  const iris_gltf_doc *d = c->doc;
  c->variant = -1;
  if (d->variants_bad) return gltf_fail(c, IRIS_ERR_INVALID, ROOT, "%s", d->variants_bad);
  for (size_t i = 0; i < d->variant_count; i++)
    if (!d->variant_names[i]) {
      char el[64];
      ELEMENT(el, ROOT " variant %zu", i);
      return gltf_fail(c, IRIS_ERR_INVALID, el, "has no string \"name\"");
    }
  uint32_t *seen = calloc(d->variant_count ? d->variant_count : 1, sizeof *seen);
  if (!seen) return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
  iris_status st = IRIS_OK;
  uint32_t stamp = 0;
  for (size_t mi = 0; mi < d->mesh_count && !st; mi++)
    for (size_t pi = 0; pi < d->meshes[mi].primitive_count && !st; pi++)
      st = check_primitive(c, mi, pi, seen, ++stamp);
  free(seen);
  if (st) return st;

  const char *want = c->opts->variant;
  if (!want) return IRIS_OK;
  for (size_t i = 0; i < d->variant_count; i++)
    if (strcmp(d->variant_names[i], want) == 0) { /* the first of equal names */
      c->variant = (int32_t)i;
      return IRIS_OK;
    }
  if (!d->variant_count)
    return gltf_fail(c, IRIS_ERR_USAGE, NULL, "no material variant \"%s\" (the file has no " ROOT ")", want);
  char list[480];
  list_names(d, list, sizeof list);
  return gltf_fail(c, IRIS_ERR_USAGE, NULL, "no material variant \"%s\" (variants: %s)", want, list);
}

int gltf_variant_material(const gltf_ctx *c, size_t mi, size_t pi) {
  const iris_gltf_primitive *p = &c->doc->meshes[mi].primitives[pi];
  if (c->variant >= 0)
    for (size_t k = 0; k < p->mapping_count; k++)
      for (size_t j = 0; j < p->mappings[k].variant_count; j++)
        if (p->mappings[k].variants[j] == c->variant) return p->mappings[k].material;
  return p->material;
}

iris_status gltf_store_variants(gltf_ctx *c) {
  const iris_gltf_doc *d = c->doc;
  iris_material_variants *v = &c->scene->variants;
  if (!d->variant_count) return IRIS_OK;
  if (!(v->names = calloc(d->variant_count, sizeof *v->names)))
    return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
  for (; v->count < d->variant_count; v->count++)
    if (!(v->names[v->count] = iris_strdup(d->variant_names[v->count])))
      return gltf_fail(c, IRIS_ERR_NOMEM, NULL, "out of memory");
  v->applied = c->variant;
  return IRIS_OK;
}
