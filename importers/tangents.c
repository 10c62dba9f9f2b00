/* MikkTSpace-compatible tangent generation; see tangents.h and docs/import-gltf.md.
 *
 * The default path of MikkTSpace (mikktspace.c as shipped with Blender, with
 * its default angular threshold of 180 degrees, i.e. no splitting of smooth
 * groups by tangent direction):
 *  1. vertices are identified by equal position, normal and uv (not by index);
 *  2. each face gets the unit tangent dp/ds and its uv orientation (sign of the
 *     uv area, with t = -v: MikkTSpace works with v up, glTF stores v down);
 *  3. each corner adds the face tangent, projected onto the plane of the
 *     vertex normal and normalised, weighted by the corner's angle (measured
 *     between the edges projected onto the same plane), into the group of
 *     (vertex, face orientation);
 *  4. the group's sum, normalised, is the tangent; w = +1 for orientation
 *     preserving faces, -1 for mirrored ones.
 * Faces with zero uv area contribute nothing and join the positive group of
 * their vertices (MikkTSpace lets them join "any" group). */
#include "importers/tangents.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct dv3 {
  double x, y, z;
} dv3;

static dv3 dv(const float *p) { return (dv3){p[0], p[1], p[2]}; }
static dv3 dsub(dv3 a, dv3 b) { return (dv3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static dv3 dadd(dv3 a, dv3 b) { return (dv3){a.x + b.x, a.y + b.y, a.z + b.z}; }
static dv3 dscale(dv3 a, double s) { return (dv3){a.x * s, a.y * s, a.z * s}; }
static double ddot(dv3 a, dv3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static dv3 dcross(dv3 a, dv3 b) {
  return (dv3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static dv3 dnormalize(dv3 a) {
  double l = sqrt(ddot(a, a));
  return l > 0.0 && isfinite(l) ? dscale(a, 1.0 / l) : (dv3){0, 0, 0};
}
/* a minus its component along unit n, normalised (0 when parallel) */
static dv3 project(dv3 a, dv3 n) { return dnormalize(dsub(a, dscale(n, ddot(n, a)))); }

/* Vertex identity key: position, normal, uv as bit patterns (-0 taken as 0). */
typedef struct vkey {
  float f[8];
  uint32_t v;
} vkey;

static int compare_keys(const void *a, const void *b) {
  const vkey *x = a, *y = b;
  int c = memcmp(x->f, y->f, sizeof x->f);
  if (c) return c;
  return x->v < y->v ? -1 : x->v > y->v;
}

static bool grow_floats(float **a, size_t old_n, size_t new_n, size_t width) {
  if (!*a) return true;
  float *g = realloc(*a, new_n * width * sizeof(float));
  if (!g) return false;
  (void)old_n;
  *a = g;
  return true;
}

bool iris_mesh_generate_tangents(iris_mesh *m, int uv_set, uint32_t *split) {
  if (split) *split = 0;
  const float *uv = uv_set ? m->uvs1 : m->uvs;
  if (!m->normals || !uv || !m->owned) return false;
  const size_t nv = m->vertex_count, nt = m->triangle_count;
  vkey *keys = malloc((nv ? nv : 1) * sizeof *keys);
  uint32_t *canon = malloc((nv ? nv : 1) * sizeof *canon);
  dv3 *face_t = malloc((nt ? nt : 1) * sizeof *face_t);
  uint8_t *orient = malloc(nt ? nt : 1);
  dv3 *acc = calloc(2 * (nv ? nv : 1), sizeof *acc);
  uint8_t *used = calloc(nv ? nv : 1, 1);       /* bit o: vertex v is used by a face of orientation o */
  uint8_t *canon_used = calloc(nv ? nv : 1, 1); /* the same per canonical vertex, non-degenerate faces */
  uint32_t *twin = NULL;
  float *tangents = NULL;
  bool ok = false;
  if (!keys || !canon || !face_t || !orient || !acc || !used || !canon_used) goto done;

  /* 1. vertex identity by attributes */
  for (size_t v = 0; v < nv; v++) {
    vkey *k = &keys[v];
    memcpy(k->f, m->positions + 3 * v, 3 * sizeof(float));
    memcpy(k->f + 3, m->normals + 3 * v, 3 * sizeof(float));
    memcpy(k->f + 6, uv + 2 * v, 2 * sizeof(float));
    for (int c = 0; c < 8; c++)
      if (k->f[c] == 0.0f) k->f[c] = 0.0f;
    k->v = (uint32_t)v;
  }
  qsort(keys, nv, sizeof *keys, compare_keys);
  for (size_t i = 0, run = 0; i < nv; i++) {
    if (i > 0 && memcmp(keys[i].f, keys[run].f, sizeof keys[i].f) != 0) run = i;
    canon[keys[i].v] = keys[run].v;
  }

  /* 2. face tangents and orientations (t = -v) */
  const uint32_t *idx = m->indices;
  for (size_t f = 0; f < nt; f++) {
    const uint32_t i0 = idx[3 * f], i1 = idx[3 * f + 1], i2 = idx[3 * f + 2];
    dv3 d1 = dsub(dv(m->positions + 3 * (size_t)i1), dv(m->positions + 3 * (size_t)i0));
    dv3 d2 = dsub(dv(m->positions + 3 * (size_t)i2), dv(m->positions + 3 * (size_t)i0));
    double s1 = (double)uv[2 * (size_t)i1] - uv[2 * (size_t)i0];
    double t1 = -((double)uv[2 * (size_t)i1 + 1] - uv[2 * (size_t)i0 + 1]);
    double s2 = (double)uv[2 * (size_t)i2] - uv[2 * (size_t)i0];
    double t2 = -((double)uv[2 * (size_t)i2 + 1] - uv[2 * (size_t)i0 + 1]);
    double area = s1 * t2 - t1 * s2;
    dv3 os = dsub(dscale(d1, t2), dscale(d2, t1)); /* area * dp/ds */
    if (area != 0.0 && isfinite(area)) {
      orient[f] = area > 0.0 ? 1 : 0;
      face_t[f] = dnormalize(dscale(os, area > 0.0 ? 1.0 : -1.0));
      for (int k = 0; k < 3; k++) canon_used[canon[idx[3 * f + (size_t)k]]] |= (uint8_t)(1u << orient[f]);
    } else {
      orient[f] = 2; /* degenerate uv: resolved below */
      face_t[f] = (dv3){0, 0, 0};
    }
  }
  for (size_t f = 0; f < nt; f++) {
    if (orient[f] != 2) continue;
    uint8_t o = 1;
    for (int k = 0; k < 3; k++) {
      uint8_t u = canon_used[canon[idx[3 * f + (size_t)k]]];
      if (u) {
        o = (u & 2) ? 1 : 0;
        break;
      }
    }
    orient[f] = o;
  }

  /* 3. angle-weighted accumulation per (vertex, orientation) */
  for (size_t f = 0; f < nt; f++) {
    for (int k = 0; k < 3; k++) {
      const uint32_t v = idx[3 * f + (size_t)k];
      const uint32_t prev = idx[3 * f + (size_t)((k + 2) % 3)], next = idx[3 * f + (size_t)((k + 1) % 3)];
      used[v] |= (uint8_t)(1u << orient[f]);
      dv3 n = dnormalize(dv(m->normals + 3 * (size_t)v));
      dv3 t = project(face_t[f], n);
      dv3 p = dv(m->positions + 3 * (size_t)v);
      dv3 e0 = project(dsub(dv(m->positions + 3 * (size_t)prev), p), n);
      dv3 e1 = project(dsub(dv(m->positions + 3 * (size_t)next), p), n);
      double c = ddot(e0, e1);
      double angle = acos(c < -1.0 ? -1.0 : c > 1.0 ? 1.0 : c);
      dv3 *a = &acc[2 * (size_t)canon[v] + orient[f]];
      *a = dadd(*a, dscale(t, angle));
    }
  }

  /* 4. mirror seams: a vertex used by both orientations gets a twin for the negative one */
  size_t extra = 0;
  for (size_t v = 0; v < nv; v++) extra += used[v] == 3;
  if (nv + extra > (size_t)INT32_MAX) goto done;
  const size_t total = nv + extra;
  twin = malloc((total ? total : 1) * sizeof *twin); /* [0, nv): twin of v; [nv, total): origin */
  tangents = malloc(4 * (total ? total : 1) * sizeof(float));
  if (!twin || !tangents) goto done;
  for (size_t v = 0; v < nv; v++) twin[v] = (uint32_t)v;
  if (extra) {
    if (!grow_floats(&m->positions, nv, total, 3) || !grow_floats(&m->normals, nv, total, 3) ||
        !grow_floats(&m->uvs, nv, total, 2) || !grow_floats(&m->colors, nv, total, 3) ||
        !grow_floats(&m->uvs1, nv, total, 2) || !grow_floats(&m->alphas, nv, total, 1))
      goto done; /* arrays grown so far keep their old contents: the mesh is unchanged */
    size_t next = nv;
    for (size_t v = 0; v < nv; v++) {
      twin[v] = used[v] == 3 ? (uint32_t)next++ : (uint32_t)v;
      if (twin[v] == v) continue;
      size_t w = twin[v];
      twin[w] = (uint32_t)v;
      memcpy(m->positions + 3 * w, m->positions + 3 * v, 3 * sizeof(float));
      memcpy(m->normals + 3 * w, m->normals + 3 * v, 3 * sizeof(float));
      if (m->uvs) memcpy(m->uvs + 2 * w, m->uvs + 2 * v, 2 * sizeof(float));
      if (m->colors) memcpy(m->colors + 3 * w, m->colors + 3 * v, 3 * sizeof(float));
      if (m->uvs1) memcpy(m->uvs1 + 2 * w, m->uvs1 + 2 * v, 2 * sizeof(float));
      if (m->alphas) m->alphas[w] = m->alphas[v];
    }
    for (size_t f = 0; f < nt; f++)
      if (orient[f] == 0)
        for (int k = 0; k < 3; k++) m->indices[3 * f + (size_t)k] = twin[m->indices[3 * f + (size_t)k]];
  }
  for (size_t v = 0; v < total; v++) {
    /* vertex v < nv keeps the positive group when it has one; twins are negative */
    size_t orig = v;
    uint8_t o;
    if (v >= nv) {
      o = 0;
      orig = twin[v];
    } else {
      o = (used[v] & 2) || !used[v] ? 1 : 0;
    }
    dv3 n = dnormalize(dv(m->normals + 3 * orig));
    dv3 t = dnormalize(acc[2 * (size_t)canon[orig] + o]);
    if (ddot(t, t) == 0.0) { /* no uv information: any tangent perpendicular to n */
      dv3 axis = fabs(n.x) < 0.9 ? (dv3){1, 0, 0} : (dv3){0, 1, 0};
      t = dnormalize(dcross(dcross(n, axis), n));
      if (ddot(t, t) == 0.0) t = (dv3){1, 0, 0};
    }
    tangents[4 * v] = (float)t.x, tangents[4 * v + 1] = (float)t.y, tangents[4 * v + 2] = (float)t.z;
    tangents[4 * v + 3] = o ? 1.0f : -1.0f;
  }
  free(m->tangents);
  m->tangents = tangents;
  tangents = NULL;
  m->vertex_count = (uint32_t)total;
  if (split) *split = (uint32_t)extra;
  ok = true;
done:
  free(keys), free(canon), free(face_t), free(orient), free(acc), free(used), free(canon_used);
  free(twin), free(tangents);
  return ok;
}
