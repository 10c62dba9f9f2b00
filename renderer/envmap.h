/* Equirectangular environment maps: the decoded, validated texels of an
 * OpenEXR or Radiance .hdr map (times its strength), the direction <-> (s, t)
 * mapping and the bilinear lookup of Blender 3.4's Environment Texture
 * (interpolation Linear, default mapping) for glTF scenes, and importance
 * sampling of directions in proportion to the interpolated luminance
 * integrated over each texel's cell x sin(theta) (a marginal CDF over rows and
 * one conditional CDF per row; piecewise constant, so the pdf in solid angle
 * is exact per cell). docs/format.md and docs/rendering.md. */
#ifndef IRIS_RENDERER_ENVMAP_H
#define IRIS_RENDERER_ENVMAP_H

#include <stdbool.h>
#include <stddef.h>

#include "core/error.h"
#include "core/math.h"
#include "renderer/sampling.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The sampling tables are laid out for the few cache lines a sample touches
 * (docs/rendering.md, "Environment maps"): the rows' CDF (small, stays in
 * cache), then per row a guide table (Chen & Asau 1974) of one entry per 16
 * cells (the first cell whose CDF interval holds j / entries) and the full
 * CDF, each row 64-byte aligned, so that a sample reads one guide entry and
 * usually one line of the CDF, and both can be prefetched while a ray is
 * traced (iris_envmap_prefetch). Probabilities are CDF differences, which are
 * exactly the measure of the numbers u that pick a cell, and the pdf reads
 * the same two entries. */
#define IRIS_ENVMAP_BLOCK 16
typedef struct iris_envmap {
  int width, height;
  float *rgb;             /* 3 * width * height, linear radiance (strength applied), row 0 top */
  float cos_rot, sin_rot; /* rotation about +Y */
  float *row_cdf;         /* height + 1 entries: marginal CDF over rows */
  uint32_t *row_guide;    /* height entries: largest row y with row_cdf[y] <= j / height */
  float *cdf;             /* height rows of `stride` floats: row y's CDF over its cells, width + 1 used */
  uint32_t *guide;        /* height rows of `blocks` entries: largest cell x with cdf[x] <= j / blocks */
  int stride, blocks;
  float pdf_scale;        /* width * height / (2 pi^2): cell probability to solid-angle density times sin */
  double mean_luminance;  /* (1 / 4pi) * integral of the luminance over the sphere */
  float mean_rgb[3];      /* the same per channel */
} iris_envmap;

/* Reads and checks the map (extension .exr or .hdr, or by the file's magic):
 * a missing, unreadable or empty file, or one with NaN, Inf or negative
 * texels is an error naming the file; a map that is not 2:1 gets a warning
 * (it is still usable). Then builds the sampling tables (uniform for a map
 * that is black everywhere, which iris_lights leaves out: mean_luminance 0). */
iris_status iris_envmap_load(const iris_environment_map *map, iris_envmap *out, iris_error *err);
/* Only the checks of iris_envmap_load (for commands that do not render). */
iris_status iris_envmap_check(const char *path, iris_error *err);
void iris_envmap_destroy(iris_envmap *env);

/* Map coordinates of unit direction d: s in [0,1) across, t in [0,1] down. */
void iris_envmap_dir_to_st(const iris_envmap *env, iris_vec3 d, float *s, float *t);
/* Unit direction of map coordinates (s, t). */
iris_vec3 iris_envmap_st_to_dir(const iris_envmap *env, float s, float t);

/* Radiance arriving from direction d (unit; travelling towards -d): the
 * bilinear interpolation of the four texels around (s, t), texel centres at
 * half-integers, wrapped periodically on both axes (Cycles' repeat). */
iris_vec3 iris_envmap_radiance(const iris_envmap *env, iris_vec3 d);
/* The same at map coordinates (s, t) (no trigonometry). */
iris_vec3 iris_envmap_radiance_st(const iris_envmap *env, float s, float t);
/* Samples a direction with two uniform numbers; returns false when nothing
 * can be sampled. *pdf is the solid-angle density; *radiance (optional) the
 * radiance from *d, as iris_envmap_radiance gives it. */
bool iris_envmap_sample(const iris_envmap *env, float u0, float u1, iris_vec3 *d, float *pdf,
                        iris_vec3 *radiance);
/* The same without the radiance: *s, *t are the map coordinates of *d, for
 * iris_envmap_radiance_st when the radiance is needed (after a shadow ray). */
bool iris_envmap_sample_st(const iris_envmap *env, float u0, float u1, iris_vec3 *d, float *pdf, float *s,
                           float *t);
/* Prefetching for iris_envmap_sample(u0, u1), in two steps a ray trace
 * apart: stage 0 starts loading the guide entry (the rows' CDF is small and
 * stays cached), stage 1 reads it and starts loading the CDF line the
 * search will read. Hints only: nothing else changes. */
void iris_envmap_prefetch(const iris_envmap *env, float u0, float u1, int stage);
/* Solid-angle density with which iris_envmap_sample returns d. */
float iris_envmap_pdf(const iris_envmap *env, iris_vec3 d);
/* Radiance from d and (optional) that density and d's map coordinates, with
 * one conversion of d. */
iris_vec3 iris_envmap_eval(const iris_envmap *env, iris_vec3 d, float *pdf, float st[2]);

/* Regions: the map's cells cut into bx x by rectangles of whole cells
 * (region column i holds the cell columns [col0[i], col0[i+1]), col0[i] =
 * i W / bx, rows likewise), for samplers that first choose a region and then
 * a direction in it in proportion to the map (guiding's sky visibility,
 * docs/guiding.md). A region of a map smaller than the grid may hold no
 * cell; its probability is 0. */
typedef struct iris_envmap_regions {
  int bx, by;
  int *col0, *row0;   /* bx + 1 and by + 1 entries (col0[bx] = W, row0[by] = H) */
  uint16_t *col_of;   /* W entries: the region column of a cell column */
  uint16_t *row_of;   /* H entries */
  float *prob;        /* bx * by (index j * bx + i): the map's probability of the region */
  float *row_cdf;     /* per region column i, per region row j, at i * (H + by) + row0[j] + j:
                         the CDF over the region's rows of the map's probability */
} iris_envmap_regions;

/* bx, by in [1, 4096]. */
iris_status iris_envmap_regions_build(const iris_envmap *env, int bx, int by, iris_envmap_regions *out,
                                      iris_error *err);
void iris_envmap_regions_destroy(iris_envmap_regions *r);
/* The region holding map coordinates (s, t) (the cell's). */
int iris_envmap_region_of(const iris_envmap *env, const iris_envmap_regions *r, float s, float t);
/* Samples a direction within `region` in proportion to the map: the map's own
 * density there divided by the region's probability. *pdf_map is the map's
 * own solid-angle density of *d (iris_envmap_pdf), *s, *t its coordinates.
 * False when the region holds no probability. */
bool iris_envmap_sample_region(const iris_envmap *env, const iris_envmap_regions *r, int region, float u0,
                               float u1, iris_vec3 *d, float *pdf_map, float *s, float *t);
/* iris_envmap_pdf at map coordinates. */
float iris_envmap_pdf_st(const iris_envmap *env, float s, float t);

#ifdef __cplusplus
}
#endif
#endif
