/* Partitioned renders and their exact merge: a render can cover a range of
 * sample indices (--sample-offset) and a window of the frame (--pixel-bounds);
 * its EXR says so in iris:* metadata, and iris_merge combines such parts into
 * the image one process would have rendered (sample-weighted means and
 * variances, windows placed), refusing parts that do not belong together.
 * docs/distributed.md gives the metadata keys and the formulas. */
#ifndef IRIS_RENDERER_MERGE_H
#define IRIS_RENDERER_MERGE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "core/image.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Hash of everything in a scene that changes its image (geometry, materials,
 * textures by path or bytes, cameras, lights, environment; not names of
 * meshes/materials nor the render settings, which are recorded separately).
 * Equal scenes loaded on different machines give equal hashes. */
uint64_t iris_merge_scene_hash(const iris_scene *scene);

/* What a part says about itself, parsed from its iris:* metadata. Parts
 * written before partitioning existed (no iris:window) count as the whole
 * frame from sample 0. */
typedef struct iris_merge_part_info {
  char scene_hash[32];  /* iris:scene_hash, hex */
  char config_hash[32]; /* iris:config_hash: size, camera, depths, guiding options */
  char method[32];      /* iris:method */
  char sampler[32];     /* iris:sampler ("independent" when absent) */
  char light_sampler[32]; /* iris:light_sampler ("power" when absent) */
  char seed[32];        /* iris:seed */
  int full_width, full_height; /* iris:full_size (default: the image size) */
  int x0, y0, x1, y1;   /* iris:window, half-open, in full-frame pixels */
  int64_t sample_offset; /* iris:sample_offset (default 0) */
  int64_t spp;          /* iris:spp: samples of every pixel, indices offset .. offset+spp-1 */
  int64_t train_spp;    /* iris:train_spp: the guide's training samples also in the image (only
                           at sample offset 0: docs/distributed.md; default 0) */
  bool has_variance;    /* var.R/G/B present (variance of the mean) */
  bool has_counts;      /* an "spp" channel: each pixel's sample count (adaptive sampling; training
                           samples included); its iris:spp is then the reserved index range */
} iris_merge_part_info;

/* Parses and checks a part's metadata against its image (window size equals
 * the image size, window inside the frame, R/G/B present). `path` names the
 * part in messages. */
iris_status iris_merge_part_info_parse(const iris_image *img, const iris_image_meta *meta,
                                       size_t meta_count, const char *path,
                                       iris_merge_part_info *out, iris_error *err);

/* A merge in progress: parts are added one at a time (so only one part image
 * is in memory), checked against the first, and accumulated per pixel as
 * (count, mean, sum of squared deviations) in double. */
typedef struct iris_merge_part {
  char path[512];
  iris_merge_part_info info;
} iris_merge_part;

typedef struct iris_merge {
  iris_merge_part *parts;
  size_t part_count, part_capacity;
  size_t window_count;   /* distinct windows (set by iris_merge_finish) */
  iris_image_meta *meta; /* the first part's metadata */
  size_t meta_count;
  double render_seconds; /* sum over parts */
  uint64_t nan_count;    /* sum over parts */
  bool all_variance;
  bool any_counts;       /* some part had per-pixel counts: the merge writes an "spp" channel */
  int64_t train_spp;     /* of the parts at sample offset 0 (all equal) */
  int width, height;
  double *n;    /* samples per pixel */
  double *mean; /* 3 per pixel */
  double *m2;   /* 3 per pixel: sum of squared deviations from the mean */
} iris_merge;

void iris_merge_init(iris_merge *m);
void iris_merge_destroy(iris_merge *m);

/* Adds one part (borrowed; may be freed afterwards). Fails (IRIS_ERR_INVALID,
 * naming `path`) when it was rendered from another scene, seed, method or
 * configuration than the first part, or for another frame size. */
iris_status iris_merge_add(iris_merge *m, const char *path, const iris_image *img,
                           const iris_image_meta *meta, size_t meta_count, iris_error *err);

/* Checks that the parts tile the frame exactly (no overlapping windows, no
 * pixel left out) and that every window has a contiguous, non-overlapping run
 * of sample ranges, the same run everywhere; then produces the merged image
 * (R, G, B and, when every part had it, var.R/G/B; "spp", each pixel's merged
 * sample count, when any part was adaptive) and its metadata
 * (malloc'ed; the caller frees *meta). */
iris_status iris_merge_finish(iris_merge *m, iris_image *out, iris_image_meta **meta,
                              size_t *meta_count, iris_error *err);

/* Reads every part file, merges and writes out_path atomically (nothing is
 * written on failure). */
typedef struct iris_merge_summary {
  int width, height;
  int64_t sample_offset, spp;
  size_t parts, windows;
  bool variance;
} iris_merge_summary;
iris_status iris_merge_files(const char *const *paths, size_t count, const char *out_path,
                             iris_merge_summary *summary, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
