/* Photon tracing for the guiding preprocess (thesis 4.2.1): photons leave the
 * lights in proportion to power, follow BSDF sampling with Russian roulette up
 * to 32 bounces, and one photon is stored at every non-specular hit. Parallel
 * and deterministic: photon path i draws from iris_sampler_start(seed, i, ...)
 * and paths are processed in fixed blocks concatenated in order, so the photon
 * array does not depend on the thread count. */
#ifndef IRIS_RENDERER_GUIDING_PHOTONS_H
#define IRIS_RENDERER_GUIDING_PHOTONS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "core/math.h"
#include "renderer/render.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IRIS_PHOTON_MAX_BOUNCES 32
/* The largest roughness of a glossy lobe whose reflection of a light is a
 * glint: a spot too small for a cache's texels (docs/guiding.md, "Glints"). */
#define IRIS_GLINT_ROUGHNESS 0.1f

/* One stored photon (64 bytes). Energy is a single float, the mean
 * of the RGB power (the thesis's choice): the caches only need the relative
 * distribution of incident power over directions, not its colour. */
typedef struct iris_photon {
  iris_vec3 p;      /* hit position */
  iris_vec3 n;      /* shading normal, on the side the photon arrived from (transmissive: front) */
  iris_vec3 wi;     /* unit world direction back towards where the photon came from */
  float energy;     /* mean of the RGB photon power */
  uint8_t bounce;   /* 0: straight from the light (direct illumination) */
  uint8_t transmits : 1; /* the surface has transmission lobes (full-sphere cache) */
  uint8_t caustic : 1;   /* it left its light through delta vertices only, one of them at least
                            a refraction: light focused through glass, which light sampling
                            cannot find ("--method auto", caustics) */
  uint8_t glint : 1;     /* its last vertex sent it off a smooth surface (iris_photon_smooth), not
                            straight on through glass after delta vertices only (a slab's parallel
                            faces: sky_through, lamp_through) nor through a pane: the light glint
                            spots find (glints.h) */
  uint8_t sky_through; /* from the environment map after delta vertices only (bounce > 0),
                          arriving along its emission direction (through a flat glass slab):
                          light that sampling the map as a direction finds and light
                          sampling cannot (docs/guiding.md, "Sky behind glass") */
  uint8_t lamp_through; /* the same for a photon of an emissive triangle (a lamp): the lamp's
                           cone from the surface finds that light ("Lamps behind glass") */
  uint32_t light;   /* the light entry it left (iris_lights; learned light selection) */
  float pane[4];    /* from the environment map through exactly one refracting plane (a window
                       modelled as one glass quad): the plane's normal on the sky's side and
                       eta = n_room / n_sky; pane[3] = 0 for every other photon (pane.h) */
} iris_photon;

typedef struct iris_photon_map {
  iris_photon *photons;
  size_t count;
  iris_vec3 *smooth;    /* where photon paths met smooth reflectors (iris_photon_smooth): the
                           first 4 such points of each of the first 262144 paths, in path
                           order: the targets of the glint photons (glints.h) */
  size_t smooth_count;
  uint64_t paths;     /* photon paths emitted */
  uint64_t indirect;  /* stored photons with bounce >= 1 */
} iris_photon_map;

/* Traces `paths` photon paths, choosing lights as `by` says. */
iris_status iris_photons_trace(const iris_guide_setup *setup, iris_emission_selection by, uint64_t paths,
                               iris_photon_map *out, iris_error *err);
/* Extends `map` (its first map->paths paths) to `paths` paths: the result is
 * the map one iris_photons_trace of `paths` gives, bit for bit (path i's
 * random numbers depend on i alone), so a pilot's photons are not traced
 * twice. On failure the map keeps what it had. */
iris_status iris_photons_trace_more(const iris_guide_setup *setup, iris_emission_selection by, uint64_t paths,
                                    iris_photon_map *map, iris_error *err);
void iris_photons_destroy(iris_photon_map *map);
/* A smooth surface: a delta BSDF (a mirror, clear glass), or glossy lobes of
 * roughness <= IRIS_GLINT_ROUGHNESS without a diffuse or a transmission one
 * (near-mirror metal); what turns a light into a glint. Clear glass counts
 * where it bends the light (a lamp seen through a shade modelled as one
 * curved surface); light straight on through a slab is not a glint
 * (iris_photon.glint), the lamp and sky cones find it (docs/guiding.md,
 * "Glints"). */
bool iris_photon_smooth(const iris_shading_point *sp);

/* A photon that passed delta vertices only and arrives within this cosine of
 * its emission direction came straight on through glass (a slab's parallel
 * faces): 0.5 degrees. */
#define IRIS_PHOTON_STRAIGHT_COS 0.99996f

#ifdef __cplusplus
}
#endif
#endif
