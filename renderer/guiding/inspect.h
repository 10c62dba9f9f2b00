/* Seeing inside the guide: cache positions on the film (`--aov caches`) and
 * PNG dumps of the caches that serve chosen pixels (`--dump-caches DIR`).
 * Both run at the end of the build, while the photons still exist, so the
 * dumps can show photon counts next to the pdf. docs/guiding.md, "Seeing
 * inside". */
#ifndef IRIS_RENDERER_GUIDING_INSPECT_H
#define IRIS_RENDERER_GUIDING_INSPECT_H

#include "core/error.h"
#include "renderer/guiding/guiding.h"
#include "renderer/guiding/kdtree.h"
#include "renderer/guiding/photons.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Marks every cache on a film of the camera's size: camera-ray caches at the
 * pixel they were placed from, photon caches where they project, if visible. */
iris_status iris_guiding_mark_caches(const iris_guiding *g, const iris_guide_setup *setup,
                                     iris_guiding_marks *out, iris_error *err);

/* For a 4 x 3 grid of pixels: follows the camera ray to its first non-delta
 * hit, picks the caches there (Algorithm 1) and writes, for the first of
 * them, DIR/cache_pxXXXX_pyYYYY_pdf.png (texel probability, brightest =
 * largest) and ..._photons.png (photons per texel among its k nearest, the
 * same filter as the fill), plus DIR/caches.txt describing each. */
iris_status iris_guiding_dump_caches(const iris_guiding *g, const iris_guide_setup *setup,
                                     const iris_photon_map *photons, const iris_kdtree *photon_tree,
                                     const char *dir, iris_error *err);

/* The guide's inspection hook (iris_guiding_params.inspect): the dumps when
 * params->dump_dir is set, then the marks when params->marks is. */
iris_status iris_guiding_inspect(const iris_guiding *g, const iris_guide_setup *setup,
                                 const iris_guiding_params *params, const iris_photon_map *photons,
                                 const iris_kdtree *photon_tree, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
