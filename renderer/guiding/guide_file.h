/* The guide as a file (`iris render --guide-out FILE`, `--guide-in FILE`):
 * the trained caches, their compacted pdf and alias tables and what shapes
 * sampling, in a versioned little-endian binary with a checksum, tagged with
 * the scene hash and a hash of the settings the guide depends on. Loading
 * checks everything and rebuilds what is derived (octahedral maps, cache
 * kd-tree, pick grid). docs/guiding.md, "The guide as a file". */
#ifndef IRIS_RENDERER_GUIDING_GUIDE_FILE_H
#define IRIS_RENDERER_GUIDING_GUIDE_FILE_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "renderer/guiding/guiding.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IRIS_GUIDE_FILE_VERSION 8u

/* Writes g atomically (a temporary next to path, renamed on success: a
 * failed write leaves no file). Errors: IRIS_ERR_IO naming path. */
iris_status iris_guiding_save(const iris_guiding *g, const char *path, uint64_t scene_hash,
                              uint64_t settings_hash, iris_error *err);

/* Reads path into a new guide (*out, free with iris_guiding_destroy). The
 * file must carry this scene_hash and settings_hash; anything else — another
 * version, truncation, a checksum mismatch, counts or offsets out of range,
 * NaN/Inf — is refused with IRIS_ERR_PARSE (IRIS_ERR_IO when unreadable),
 * one message naming path. `threads` builds the pick grid (the result does not
 * depend on it). */
iris_status iris_guiding_load(const char *path, uint64_t scene_hash, uint64_t settings_hash, int threads,
                              iris_guiding **out, iris_error *err);

/* The checksum stored at bytes 40..47: a 64-bit hash (iris_mix64 per 8 bytes)
 * of bytes [0, 40) and of the payload after the 48-byte header. Exposed for
 * the tests, which forge files with a valid checksum. */
uint64_t iris_guide_file_checksum(const void *data, size_t size);

/* Hash of what a guide depends on besides the scene: the full-frame camera,
 * seed, sampler, method (light sampling or not), depths, emitter-triangle
 * sampling and every guiding parameter as requested (not the thread count,
 * not the render's spp or time budget, not the inspection outputs or file
 * names). A file is only accepted by a render with the same hash. */
uint64_t iris_guiding_settings_hash(const iris_guide_setup *setup, const iris_guiding_params *params);

#ifdef __cplusplus
}
#endif
#endif
