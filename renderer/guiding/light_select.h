/* Learned light selection (--light-sampler learned; docs/guiding.md,
 * "Learned light selection"): every irradiance cache keeps a distribution
 * over the light tree's leaves learned from the photons that arrived near it
 * (within half the caches' spacing) straight from a light, by emitter: what
 * is not hidden from the cache; and
 * next-event estimation chooses a light from the mixture
 *
 *     P(l | x, n) = (1 - beta) P_tree(l | x, n) + beta (1/m) sum_j q_j(leaf(l)) P_leaf(l),
 *
 * the caches j = 1..m those Algorithm 1 ties for (x, n) (iris_guiding_pick
 * with the normal light selection is told, the geometric one) that have a
 * table; beta = 0 where there are none (zero normal, no cache, nothing
 * learned). A cache keeps a table only where it learned from at least
 * IRIS_LIGHT_SELECT_MIN_PHOTONS photons and where shadow-ray probes of the
 * tree's own choice at the cache find at least IRIS_LIGHT_SELECT_HIDDEN_MIN
 * of it hidden: elsewhere the tree already chooses what is seen, and the
 * table would only add its noise. The tree keeps every light it would choose reachable, so a
 * light the caches never saw costs at most a factor 1/(1 - beta) of its
 * samples. The pmf is one function of (x, n, l): the sampler and the MIS
 * weight of a BSDF-sampled hit from the same vertex agree bit for bit. */
#ifndef IRIS_RENDERER_GUIDING_LIGHT_SELECT_H
#define IRIS_RENDERER_GUIDING_LIGHT_SELECT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "renderer/guiding/photons.h"
#include "renderer/lights.h"

#ifdef __cplusplus
extern "C" {
#endif

struct iris_guiding;

/* Leaves a cache remembers (its brightest ones). */
#define IRIS_LIGHT_SELECT_SLOTS 16
/* Default share of the learned choice (docs/guiding.md, "Learned light selection"). */
#define IRIS_LIGHT_SELECT_BETA 0.5f
/* Photons a cache learns from lie within this factor of the caches' spacing
 * (the 90th percentile of the distance to the 5th nearest cache). */
#define IRIS_LIGHT_SELECT_RADIUS 0.5f
/* A cache keeps its table only where at least this share of the tree's light
 * samples at the cache (IRIS_LIGHT_SELECT_PROBES shadow rays) is hidden. */
#define IRIS_LIGHT_SELECT_HIDDEN_MIN 0.15
#define IRIS_LIGHT_SELECT_PROBES 32
/* ... and learned from at least this many direct photons. */
#define IRIS_LIGHT_SELECT_MIN_PHOTONS 32

/* Leaves whose light samples a cache's training vertices remember. */
#define IRIS_LIGHT_SELECT_NEE_SLOTS 32
/* Light samples a cache's vertices must have traced in training before they
 * re-learn its table (fewer: the photons' table and the probes decide). */
#define IRIS_LIGHT_SELECT_NEE_MIN 32
/* The light samples' share of a table is n / (n + this), n their number. */
#define IRIS_LIGHT_SELECT_NEE_PRIOR 32.0

/* What a cache's training vertices' light samples brought from one leaf: the
 * sum of their iris_path_vertex.light_value. leaf1 = leaf + 1 (0: empty). */
typedef struct iris_light_select_nee {
  uint32_t leaf1;
  double sum;
} iris_light_select_nee;

/* Adds one light sample's value to a cache's IRIS_LIGHT_SELECT_NEE_SLOTS
 * (open addressing; a sample of a 33rd leaf is not remembered). Callers add a
 * cache's samples in a fixed order: the sums are deterministic. */
void iris_light_select_nee_add(iris_light_select_nee *slots, uint32_t leaf, float value);

/* A table's slot names a light-tree leaf by its node index, or an infinite
 * light (environment map, distant light: beside the tree) k of
 * tree->infinite as IRIS_LIGHT_SELECT_INFINITE | k: without them a table
 * would take beta of the sky's probability away where it lights the cache. */
#define IRIS_LIGHT_SELECT_INFINITE 0x80000000u
/* The slot name of `light` (UINT32_MAX: none, e.g. zero power). */
uint32_t iris_light_select_leaf_of(const iris_light_tree *tree, uint32_t light);

typedef struct iris_light_select_slot {
  uint32_t leaf; /* node index of a light-tree leaf, or IRIS_LIGHT_SELECT_INFINITE | k */
  float cdf;     /* cumulative probability up to and including this slot (the last is 1) */
} iris_light_select_slot;

typedef struct iris_light_select {
  const struct iris_guiding *g;  /* its caches and pick grid */
  const iris_light_tree *tree;   /* the lights' tree the leaves belong to */
  size_t cache_count;
  uint8_t *count;                /* per cache: slots used (0: nothing learned) */
  uint8_t *photon_count;         /* per cache, until training re-learns the tables: slots the
                                    photons filled, kept or not by the probes */
  iris_light_select_slot *slots; /* per cache: IRIS_LIGHT_SELECT_SLOTS */
  uint8_t *near;                 /* per answer of the caches' pick grid (indexed by its first id's
                                    offset): 1 when one of its caches has a table; where none
                                    has, a light choice reads no cache (NULL: no grid) */
  float beta;
  uint64_t direct_photons;       /* photons the tables were learned from */
  uint64_t learned_caches;       /* caches with a table */
  uint64_t nee_caches;           /* ... of them re-learned from training's light samples */
} iris_light_select;

/* Learns the tables of g's caches from the photons' direct hits (the k =
 * cache_k nearest usable ones of each cache within IRIS_LIGHT_SELECT_RADIUS
 * of the spacing, filtered as the caches' own photons,
 * their energy summed by the tree leaf of the light they left). Needs
 * lights->tree (else the selection stays empty: the tree alone chooses).
 * Deterministic for any thread count. */
iris_status iris_light_select_build(iris_light_select *sel, const struct iris_guiding *g,
                                    const iris_lights *lights, const iris_photon_map *photons, int k,
                                    uint64_t seed, int threads, iris_error *err);
void iris_light_select_destroy(iris_light_select *sel);
/* After training (train.c): each cache whose vertices traced at least
 * IRIS_LIGHT_SELECT_NEE_MIN light samples (tries[i], of which lit[i] brought
 * light) learns its table again from the mixture of the photons' table and
 * what its light samples brought by leaf (nee, IRIS_LIGHT_SELECT_NEE_SLOTS per
 * cache), and keeps it where at least IRIS_LIGHT_SELECT_HIDDEN_MIN of those
 * samples (the tree's own choice) found their light hidden. Frees
 * photon_count. */
void iris_light_select_learn_nee(iris_light_select *sel, const iris_light_select_nee *nee, const uint32_t *tries,
                                 const uint32_t *lit);
/* Ties tables read from a guide file (guide_file.h) to g and the lights'
 * tree: false when they do not fit it (a leaf that is not one of the tree's
 * leaves, a cdf that does not rise to 1, beta outside [0, 1)). */
bool iris_light_select_attach(iris_light_select *sel, const struct iris_guiding *g, const iris_lights *lights);
/* Bytes of the tables of `caches` caches (iris info's memory estimate). */
size_t iris_light_select_bytes(size_t caches);

/* The hooks iris_lights calls (lights.h, iris_light_learned); zero when the
 * selection is empty. sel must outlive their use. */
iris_light_learned iris_light_select_hooks(const iris_light_select *sel);

/* The same functions, for tests. */
bool iris_light_select_choose(const iris_light_select *sel, iris_vec3 p, iris_vec3 n, float u, uint32_t *light,
                              float *pmf);
float iris_light_select_pmf(const iris_light_select *sel, iris_vec3 p, iris_vec3 n, uint32_t light);

#ifdef __cplusplus
}
#endif
#endif
