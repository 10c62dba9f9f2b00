/* Ear clipping with a work budget (see triangulate.h).
 *
 * Eberly, "Triangulation by Ear Clipping" (2002): a convex corner is an ear
 * when no reflex corner lies in its triangle, and clipping an ear changes the
 * status of its two neighbours only. So the corners are classified once
 * (O(n r) for r reflex corners), the ears and the reflex corners are kept in
 * linked lists, and each clip re-tests two corners against the reflex list:
 * O(n r) <= O(n^2) in all, and O(n) for convex polygons. A polygon without an
 * ear (self-intersecting or degenerate) is clipped at a corner anyway, after
 * which every corner is re-classified (removing a reflex corner can create
 * ears anywhere). All of that is counted in steps; once a polygon has used its
 * budget (linear in n) the corners left are fan-triangulated, which bounds
 * the work per corner whatever the input. */
#include "importers/triangulate.h"

#include "core/log.h"
#include "importers/import.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#define NIL UINT32_MAX

enum { IN_REFLEX = 1, IN_EARS = 2 };

typedef struct vec2 {
  double x, y;
} vec2;

struct iris_polygon_triangulator {
  size_t cap;
  vec2 *p;
  uint32_t *prev, *next;   /* the ring of corners left */
  uint32_t *lprev, *lnext; /* links in the reflex list or the ear list (never both: ears are convex) */
  uint8_t *flags;
  uint32_t steps_per_corner, file_steps_per_corner;
  iris_triangulate_stats stats;
};

/* One call's state. */
typedef struct clip {
  const vec2 *p;
  uint32_t *prev, *next, *lprev, *lnext;
  uint8_t *flags;
  uint32_t reflex, ears; /* list heads */
  uint64_t steps, budget;
} clip;

static inline double cross2(vec2 a, vec2 b, vec2 c) { /* (b - a) x (c - a) */
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

static inline bool same2(vec2 a, vec2 b) { return a.x == b.x && a.y == b.y; }

/* Inclusive point-in-triangle for a counter-clockwise triangle. */
static inline bool inside2(vec2 a, vec2 b, vec2 c, vec2 q) {
  return cross2(a, b, q) >= 0 && cross2(b, c, q) >= 0 && cross2(c, a, q) >= 0;
}

iris_polygon_triangulator *iris_polygon_triangulator_create(void) {
  iris_polygon_triangulator *t = calloc(1, sizeof *t);
  if (t) {
    t->steps_per_corner = IRIS_TRIANGULATE_STEPS_PER_CORNER;
    t->file_steps_per_corner = IRIS_TRIANGULATE_FILE_STEPS_PER_CORNER;
  }
  return t;
}

void iris_polygon_triangulator_set_budget(iris_polygon_triangulator *t, uint32_t steps_per_corner,
                                          uint32_t file_steps_per_corner) {
  t->steps_per_corner = steps_per_corner;
  t->file_steps_per_corner = file_steps_per_corner;
}

void iris_polygon_triangulator_destroy(iris_polygon_triangulator *t) {
  if (!t) return;
  free(t->p), free(t->prev), free(t->next), free(t->lprev), free(t->lnext), free(t->flags);
  free(t);
}

iris_triangulate_stats iris_polygon_triangulator_stats(const iris_polygon_triangulator *t) {
  return t->stats;
}

void iris_polygon_triangulator_report(const iris_polygon_triangulator *t, const char *path,
                                      struct iris_import_stats *stats) {
  if (!t) return;
  if (stats) {
    stats->polygons += t->stats.polygons;
    stats->polygon_corners += t->stats.corners;
    stats->triangulation_steps += t->stats.steps;
    stats->triangulation_fallbacks += t->stats.fallbacks;
  }
  if (t->stats.fallbacks)
    iris_warnf("%s: %llu polygon(s) without enough ears (repeated, collinear or crossing corners) "
               "were partly fan-triangulated",
               path ? path : "input", (unsigned long long)t->stats.fallbacks);
}

static bool reserve(iris_polygon_triangulator *t, size_t n) {
  if (n <= t->cap) return true;
  size_t cap = t->cap ? t->cap : 64;
  while (cap < n) cap *= 2;
  vec2 *p = realloc(t->p, cap * sizeof *p);
  if (p) t->p = p;
  uint32_t **u[4] = {&t->prev, &t->next, &t->lprev, &t->lnext};
  bool ok = p != NULL;
  for (int i = 0; i < 4 && ok; i++) {
    uint32_t *q = realloc(*u[i], cap * sizeof(uint32_t));
    if (q) *u[i] = q;
    ok = q != NULL;
  }
  uint8_t *f = ok ? realloc(t->flags, cap) : NULL;
  if (f) t->flags = f;
  if (!f) return false;
  t->cap = cap;
  return true;
}

static void list_push(clip *s, uint32_t *head, uint32_t v) {
  s->lprev[v] = NIL;
  s->lnext[v] = *head;
  if (*head != NIL) s->lprev[*head] = v;
  *head = v;
}

static void list_remove(clip *s, uint32_t *head, uint32_t v) {
  if (s->lprev[v] != NIL) s->lnext[s->lprev[v]] = s->lnext[v];
  else *head = s->lnext[v];
  if (s->lnext[v] != NIL) s->lprev[s->lnext[v]] = s->lprev[v];
}

static bool is_convex(const clip *s, uint32_t v) {
  return cross2(s->p[s->prev[v]], s->p[v], s->p[s->next[v]]) > 0;
}

/* v is convex; it is an ear when no reflex corner lies in its triangle.
 * Corners coinciding with the triangle's (keyhole bridges) do not block it. */
static bool is_ear(clip *s, uint32_t v) {
  const uint32_t a = s->prev[v], c = s->next[v];
  const vec2 pa = s->p[a], pv = s->p[v], pc = s->p[c];
  for (uint32_t q = s->reflex; q != NIL; q = s->lnext[q]) {
    s->steps++;
    if (q == a || q == c) continue;
    const vec2 pq = s->p[q];
    if (same2(pq, pa) || same2(pq, pv) || same2(pq, pc)) continue;
    if (inside2(pa, pv, pc, pq)) return false;
  }
  return true;
}

/* Re-classifies v after its neighbours changed. */
static void update(clip *s, uint32_t v) {
  s->steps++;
  const bool convex = is_convex(s, v);
  uint8_t *f = &s->flags[v];
  if (!convex) {
    if (*f & IN_EARS) list_remove(s, &s->ears, v), *f &= (uint8_t)~IN_EARS;
    if (!(*f & IN_REFLEX)) list_push(s, &s->reflex, v), *f |= IN_REFLEX;
    return;
  }
  if (*f & IN_REFLEX) list_remove(s, &s->reflex, v), *f &= (uint8_t)~IN_REFLEX;
  const bool ear = is_ear(s, v);
  if (ear && !(*f & IN_EARS)) list_push(s, &s->ears, v), *f |= IN_EARS;
  else if (!ear && (*f & IN_EARS)) list_remove(s, &s->ears, v), *f &= (uint8_t)~IN_EARS;
}

static uint32_t fan(uint32_t n, uint32_t *tris) {
  for (uint32_t i = 1; i + 1 < n; i++) *tris++ = 0, *tris++ = i, *tris++ = i + 1;
  return n - 2;
}

uint32_t iris_polygon_triangulate(iris_polygon_triangulator *t, const float *positions,
                                  const uint32_t *corners, uint32_t n, uint32_t *tris) {
  if (n < 3) return 0;
  if (n == 3) {
    tris[0] = 0, tris[1] = 1, tris[2] = 2;
    return 1;
  }
  t->stats.polygons++;
  t->stats.corners += n;
  if (!reserve(t, n)) return 0;
  uint64_t budget = t->steps_per_corner == UINT32_MAX
                        ? UINT64_MAX
                        : (uint64_t)t->steps_per_corner * n + IRIS_TRIANGULATE_STEPS_BASE;
  if (t->file_steps_per_corner != UINT32_MAX) { /* what the file has left */
    const uint64_t file = (uint64_t)t->file_steps_per_corner * t->stats.corners + IRIS_TRIANGULATE_FILE_STEPS_BASE;
    const uint64_t left = file > t->stats.steps ? file - t->stats.steps : 0;
    budget = left < budget ? left : budget;
  }
  clip s = {t->p, t->prev, t->next, t->lprev, t->lnext, t->flags, NIL, NIL, 0, budget};
  /* Newell normal: robust for non-planar and concave polygons. */
  double nx = 0, ny = 0, nz = 0;
  for (uint32_t i = 0; i < n; i++) {
    const float *a = positions + 3 * (size_t)corners[i];
    const float *b = positions + 3 * (size_t)corners[i + 1 == n ? 0 : i + 1];
    nx += ((double)a[1] - b[1]) * ((double)a[2] + b[2]);
    ny += ((double)a[2] - b[2]) * ((double)a[0] + b[0]);
    nz += ((double)a[0] - b[0]) * ((double)a[1] + b[1]);
  }
  s.steps += n;
  const double ax = fabs(nx), ay = fabs(ny), az = fabs(nz);
  if (!(ax + ay + az > 0) || !isfinite(ax + ay + az)) {
    t->stats.steps += s.steps + n;
    return fan(n, tris);
  }
  /* Drop the dominant axis; order the two kept axes so the polygon is
   * counter-clockwise in 2D. */
  const int k = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
  const double nk = k == 0 ? nx : (k == 1 ? ny : nz);
  int u = (k + 1) % 3, v = (k + 2) % 3;
  if (nk < 0) {
    const int w = u;
    u = v, v = w;
  }
  vec2 *p = t->p;
  for (uint32_t i = 0; i < n; i++) {
    const float *a = positions + 3 * (size_t)corners[i];
    p[i] = (vec2){a[u], a[v]};
  }
  s.steps += n;
  if (n == 4) {
    /* Cycles/Blender split quads along 0-2; keep that unless it leaves the quad. */
    const bool d02 = cross2(p[0], p[1], p[2]) > 0 && cross2(p[0], p[2], p[3]) > 0;
    if (d02 || (cross2(p[1], p[2], p[3]) > 0 && cross2(p[1], p[3], p[0]) > 0)) {
      const uint32_t q[2][6] = {{0, 1, 2, 0, 2, 3}, {1, 2, 3, 1, 3, 0}};
      memcpy(tris, q[d02 ? 0 : 1], sizeof q[0]);
      t->stats.steps += s.steps + 2;
      return 2;
    }
  }
  for (uint32_t i = 0; i < n; i++) {
    s.prev[i] = i == 0 ? n - 1 : i - 1;
    s.next[i] = i + 1 == n ? 0 : i + 1;
    s.flags[i] = 0;
  }
  /* Pushed from the last corner down, so that the lists run in corner order. */
  for (uint32_t i = n; i-- > 0;)
    if (!is_convex(&s, i)) list_push(&s, &s.reflex, i), s.flags[i] = IN_REFLEX;
  s.steps += n;
  for (uint32_t i = n; i-- > 0 && s.steps <= s.budget;)
    if (!(s.flags[i] & IN_REFLEX) && is_ear(&s, i)) list_push(&s, &s.ears, i), s.flags[i] |= IN_EARS;
  uint32_t remaining = n, out = 0, live = 0, hint = NIL;
  while (remaining > 3 && s.steps <= s.budget) {
    /* The next clip: the corner after the last one clipped when it is an ear
     * (the order of the unbounded version, and good strips), else any ear,
     * else any corner (no ear: degenerate input). */
    uint32_t c0;
    bool forced = false;
    if (hint != NIL && (s.flags[hint] & IN_EARS)) c0 = hint;
    else if (s.ears != NIL) c0 = s.ears;
    else c0 = live, forced = true;
    const uint32_t a = s.prev[c0], c = s.next[c0];
    tris[out++] = a, tris[out++] = c0, tris[out++] = c;
    if (s.flags[c0] & IN_EARS) list_remove(&s, &s.ears, c0);
    if (s.flags[c0] & IN_REFLEX) list_remove(&s, &s.reflex, c0);
    s.flags[c0] = 0;
    s.next[a] = c, s.prev[c] = a;
    remaining--;
    s.steps++;
    live = hint = c;
    if (!forced) {
      update(&s, a);
      update(&s, c);
    } else {
      uint32_t w = c;
      do {
        update(&s, w);
        w = s.next[w];
      } while (w != c && s.steps <= s.budget);
    }
  }
  if (remaining > 3) {
    /* Budget spent: fan the corners left from one of them. */
    t->stats.fallbacks++;
    const uint32_t v0 = live;
    for (uint32_t w = s.next[v0]; s.next[w] != v0; w = s.next[w])
      tris[out++] = v0, tris[out++] = w, tris[out++] = s.next[w];
    s.steps += remaining;
  } else {
    tris[out++] = s.prev[live], tris[out++] = live, tris[out++] = s.next[live];
  }
  t->stats.steps += s.steps;
  return n - 2;
}
