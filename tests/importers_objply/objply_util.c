#include "objply_util.h"

#include <math.h>
#include <string.h>

#include "core/log.h"

static iris_status validated(iris_status st, iris_scene **out, const char *name, iris_error *err) {
  if (st != IRIS_OK) return st;
  st = iris_scene_validate(*out, name, err);
  if (st != IRIS_OK) iris_scene_destroy(*out), *out = NULL;
  return st;
}

iris_status objply_import(const char *path, iris_scene **out, iris_error *err) {
  iris_import_options o = iris_import_options_default();
  size_t n = strlen(path);
  iris_error_clear(err);
  if (n > 4 && !strcmp(path + n - 4, ".obj")) return validated(iris_import_obj(path, &o, out, err), out, path, err);
  return validated(iris_import_ply(path, &o, out, err), out, path, err);
}

iris_status objply_import_memory(const char *ext, const char *text, size_t size, iris_scene **out,
                                 iris_error *err) {
  iris_import_options o = iris_import_options_default();
  iris_error_clear(err);
  if (!strcmp(ext, "obj")) return validated(iris_import_obj_memory(text, size, NULL, &o, out, err), out, "mem.obj", err);
  return validated(iris_import_ply_memory(text, size, NULL, &o, out, err), out, "mem.ply", err);
}

uint64_t objply_vertices(const iris_scene *s) {
  uint64_t n = 0;
  for (size_t i = 0; i < s->mesh_count; i++) n += s->meshes[i].vertex_count;
  return n;
}

uint64_t objply_triangles(const iris_scene *s) {
  uint64_t n = 0;
  for (size_t i = 0; i < s->mesh_count; i++) n += s->meshes[i].triangle_count;
  return n;
}

const iris_mesh *objply_mesh_named(const iris_scene *s, const char *name) {
  for (size_t i = 0; i < s->mesh_count; i++)
    if (s->meshes[i].name && !strcmp(s->meshes[i].name, name)) return &s->meshes[i];
  return NULL;
}

double objply_mesh_area(const iris_mesh *m, double nsum[3]) {
  double area = 0;
  if (nsum) nsum[0] = nsum[1] = nsum[2] = 0;
  for (uint32_t t = 0; t < m->triangle_count; t++) {
    const float *a = m->positions + 3 * m->indices[3 * t], *b = m->positions + 3 * m->indices[3 * t + 1],
                *c = m->positions + 3 * m->indices[3 * t + 2];
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    area += 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (nsum)
      for (int k = 0; k < 3; k++) nsum[k] += 0.5 * n[k];
  }
  return area;
}
