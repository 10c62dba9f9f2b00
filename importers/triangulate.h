/* Polygon triangulation for the OBJ and PLY importers: ear clipping in the
 * plane of the Newell normal with a work budget linear in the corner count,
 * so that no polygon, however degenerate, costs more than a constant per
 * corner (docs/import-obj-ply.md, "Triangulation"). */
#ifndef IRIS_IMPORTERS_TRIANGULATE_H
#define IRIS_IMPORTERS_TRIANGULATE_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Work budgets, in steps (one step = one point-in-triangle test, one corner
 * visited or one triangle written). A polygon of n corners may take
 * IRIS_TRIANGULATE_STEPS_PER_CORNER * n + IRIS_TRIANGULATE_STEPS_BASE, and all
 * polygons of one triangulator (one file) together
 * IRIS_TRIANGULATE_FILE_STEPS_PER_CORNER per corner seen so far +
 * IRIS_TRIANGULATE_FILE_STEPS_BASE: a few large concave polygons are exact,
 * a file of them costs at most ~40 steps per corner. When the ear clipping
 * would exceed either, the corners still left are fan-triangulated. The
 * values come from bench/import/bench_triangulate and the fuzzers' timeouts
 * (docs/import-obj-ply.md, "Mesh processing"). */
#define IRIS_TRIANGULATE_STEPS_PER_CORNER 512u
#define IRIS_TRIANGULATE_STEPS_BASE 4096u
#define IRIS_TRIANGULATE_FILE_STEPS_PER_CORNER 32u
#define IRIS_TRIANGULATE_FILE_STEPS_BASE (1u << 21)

/* Reusable scratch space and work counters (one per importer call). */
typedef struct iris_polygon_triangulator iris_polygon_triangulator;
iris_polygon_triangulator *iris_polygon_triangulator_create(void);
void iris_polygon_triangulator_destroy(iris_polygon_triangulator *t);

/* What a triangulator has done since it was created. */
typedef struct iris_triangulate_stats {
  uint64_t polygons;  /* calls with n >= 4 */
  uint64_t corners;   /* their corners, summed */
  uint64_t steps;     /* work done, in the budget's steps */
  uint64_t fallbacks; /* polygons whose budget ran out (rest fan-triangulated) */
} iris_triangulate_stats;
iris_triangulate_stats iris_polygon_triangulator_stats(const iris_polygon_triangulator *t);
/* Replaces IRIS_TRIANGULATE_STEPS_PER_CORNER and
 * IRIS_TRIANGULATE_FILE_STEPS_PER_CORNER for this triangulator (UINT32_MAX: no
 * such budget); for the benchmark and the tests. */
void iris_polygon_triangulator_set_budget(iris_polygon_triangulator *t, uint32_t steps_per_corner,
                                          uint32_t file_steps_per_corner);

/* The importers' end of a file: adds t's counters to stats (when not NULL) and
 * warns once, naming path, when some polygons were partly fan-triangulated. */
struct iris_import_stats;
void iris_polygon_triangulator_report(const iris_polygon_triangulator *t, const char *path,
                                      struct iris_import_stats *stats);

/* Triangulates one polygon of n >= 3 corners; corner i sits at
 * positions[3 * corners[i]]. Writes n - 2 triangles as corner numbers
 * (0..n-1, the polygon's winding kept) to tris (room for 3 * (n - 2)) and
 * returns n - 2, or 0 when n < 3 or out of memory. Quads are split along 0-2
 * unless that diagonal lies outside (concave quad); larger polygons are
 * ear-clipped in the plane of their Newell normal, which handles concave
 * polygons and keyholes (repeated vertices). A polygon with no ear left
 * (self-intersecting, collinear or repeated corners) is clipped at a corner
 * anyway. Zero-area output is left for iris_mesh_remove_degenerate. */
uint32_t iris_polygon_triangulate(iris_polygon_triangulator *t, const float *positions,
                                  const uint32_t *corners, uint32_t n, uint32_t *tris);

#ifdef __cplusplus
}
#endif
#endif
