/* Sky visibility per cache: light sampling of an environment map guided by
 * what each irradiance cache sees of it (docs/guiding.md, "Sky visibility").
 *
 * Inside a room lit through a window, sampling the map by its own luminance
 * mostly picks directions that hit the walls (and the sun, which only its
 * patch on the floor sees): the shadow ray fails and the sample is lost. At
 * build time every cache traces a few shadow rays into each region of the map
 * (rectangles of whole texels, iris_envmap_regions) and keeps, per region,
 * the map's probability times the cosine-weighted fraction of those rays that
 * escaped. Light sampling of the map at a vertex then picks one of the
 * vertex's tied caches uniformly (as the directional guide does) and, with
 * probability beta, a region from that cache's distribution and a direction
 * in it by the map; otherwise (and always for a cache that saw nothing, or
 * at least half of the sky it faces) the map as before. The density is the map's times the average over the tied
 * caches of (1 - beta) + beta P_cache(region) / P_map(region), which the
 * integrator also applies to escaping rays' MIS weights.
 *
 * Windows: a cache that sees part of the sky also looks for the opening it
 * sees it through (portal.h, into the cone of its escaping probes); the
 * caches' rectangles are joined into wholes, and a cache that has one (its
 * own, or the one it reaches best through) draws, with probability
 * IRIS_SKYVIS_WINDOW_SHARE, a point uniform on a window (its other branches
 * keep the rest): the sky through a window that is smaller than a region,
 * seen from afar, which the regions' directions mostly miss. With several
 * windows the window is its own with probability IRIS_SKYVIS_OWN_WINDOW,
 * else any the cache reaches (half of its probes to points on it get
 * there) by its solid angle from the vertex (area |cos| / (d^2 + area)): a
 * vertex also sees windows its cache does not draw from (the back wall of a
 * corner room sees the side window at a grazing angle). A vertex that no
 * cache covers (walls the camera does not see, where few photons land) draws
 * from the windows as a whole with that probability, else from the map. The
 * windows' density, distance^2 / (area |cos|) through a rectangle, adds to
 * the mixture's, at light samples and at escaping rays alike. */
#ifndef IRIS_RENDERER_GUIDING_SKYVIS_H
#define IRIS_RENDERER_GUIDING_SKYVIS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "renderer/accel.h"
#include "renderer/envmap.h"
#include "renderer/guiding/portal.h"

#ifdef __cplusplus
extern "C" {
#endif

struct iris_cache;

/* What a cache's probes saw: nothing; less than half of the sky its side
 * faces (weighted by the map and the cosine); at least half of it. */
enum { IRIS_SKYVIS_NONE = 0, IRIS_SKYVIS_PART = 1, IRIS_SKYVIS_OPEN = 2 };

/* Probability of a cache's window in its light sampling of the map (docs/guiding.md,
 * "Sky visibility": measured on sky-room), and at most this many windows. */
#define IRIS_SKYVIS_WINDOW_SHARE 0.25f
#define IRIS_SKYVIS_WINDOWS 16
/* With several windows, the probability of the cache's own among them
 * (docs/guiding.md, "Sky visibility": measured on sky-room-corner). */
#define IRIS_SKYVIS_OWN_WINDOW 0.5f

/* Built from one map, used with it: the guide keeps no pointer to the map
 * (the lights own it and may be built again around a guide that is kept);
 * sampling checks that the map it is given is the one it was built for. */
typedef struct iris_skyvis {
  bool built;                   /* false: no sky guiding (the map's own sampling) */
  bool probed;                  /* the probes ran (built false: fewer than 10% of the
                                   caches saw part of the sky; the counts stay) */
  int map_width, map_height;    /* the map it was built for ... */
  double map_mean;              /* ... and its mean luminance */
  iris_envmap_regions regions;
  int region_count;
  float beta;                   /* probability of a seeing cache's regions */
  float *cdf;                   /* cache_count rows of region_count floats: the CDF's upper ends */
  uint8_t *sees;                /* per cache, IRIS_SKYVIS_*: only a cache that saw part of
                                   the sky samples its regions; the others take the map */
  size_t cache_count;
  uint64_t probes, escaped;     /* shadow rays traced and not blocked */
  size_t part_caches;           /* caches that saw less than half of their sky (the ones that guide) */
  iris_portal window[IRIS_SKYVIS_WINDOWS]; /* the openings the sky is seen through (joined) */
  int window_count;
  uint8_t *cache_window;        /* per cache: its window, 0xff none (only "part" caches have one) */
  uint16_t *window_reach;       /* with several windows, per cache with one: bit j where at least half
                                   of its probes to points on window j get there (its own always);
                                   NULL: every window */
  size_t window_caches;         /* caches with a window */
  double seconds;
  size_t memory_bytes;
} iris_skyvis;

/* Settings: regions across (by = bx / 2, at least 1), probe rays per region,
 * beta. */
typedef struct iris_skyvis_params {
  int regions_x, probes;
  float beta;
} iris_skyvis_params;

/* Probes the map from every cache (in parallel; the same result for any
 * thread count: each cache's rays come from a hash of its index). With no
 * map, beta <= 0 or probes <= 0 it builds nothing (built false); when fewer
 * than 10% of the caches see part of the sky (the rest all of it, or none)
 * it keeps only the counts (built false, probed true). */
iris_status iris_skyvis_build(iris_skyvis *sv, const struct iris_cache *caches, size_t cache_count, const iris_accel *accel,
                              const iris_envmap *env, const iris_skyvis_params *p, uint64_t seed, int threads,
                              iris_error *err);
void iris_skyvis_destroy(iris_skyvis *sv);
/* The probes' counts for the guide's describe line ("; sky seen from the
 * caches: ..."), "" when they did not run. */
void iris_skyvis_describe(const iris_skyvis *sv, char *buf, size_t size);
/* Whether sv was built for env (and is in use). */
bool iris_skyvis_serves(const iris_skyvis *sv, const iris_envmap *env);

/* Light sampling of the map env (the one sv serves) at a vertex x whose tied caches are ids[0..m)
 * from the pair (u0, u1): u1 picks the cache, the branch, the region and the
 * column in it (rescaled after each choice), u0 the row, so that the pair's
 * stratification carries into each region; the map's branch takes u0 and
 * the rescaled u1 as iris_envmap_sample_st does. *pdf is the whole
 * strategy's solid-angle density (not the light choice's probability); *s, *t
 * the map coordinates. */
bool iris_skyvis_sample(const iris_skyvis *sv, const iris_envmap *env, const uint32_t *ids, int m, iris_vec3 x,
                        float u0, float u1, iris_vec3 *d, float *pdf, float *s, float *t);
/* Whether any of the tied caches ids[0..m) samples its own regions or a
 * window, or, with m = 0 (no cache), whether there are windows (else the
 * density is the map's: iris_skyvis_scale is 1 whatever the direction). */
bool iris_skyvis_guides(const iris_skyvis *sv, const uint32_t *ids, int m);
/* That density at x for the direction d at map coordinates (s, t) is
 * p_map(d) x the returned scale + *window (1 and 0 without a sky guide or
 * caches): the windows' part is not a multiple of the map's density. */
float iris_skyvis_scale(const iris_skyvis *sv, const iris_envmap *env, const uint32_t *ids, int m, iris_vec3 x,
                        iris_vec3 d, float s, float t, float *window);

#ifdef __cplusplus
}
#endif
#endif
