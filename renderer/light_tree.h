/* A light tree (Conty Estevez & Kulla 2018; pbrt-v4's BVHLightSampler and
 * LightBounds): a binary tree over every emitter with a position, each node
 * bounding its lights' positions (a box), emission directions (a normal cone
 * plus the emitters' own cutoff) and power, so that a light can be chosen in
 * proportion to an estimate of what it gives a shading point, descending the
 * tree with one uniform number. Lights without a position (environment,
 * distant) are chosen beside the tree with a probability of their own. The
 * module knows nothing of scenes: renderer/light_build.c hands it one bounds
 * record per light (iris_lights_bounds). docs/rendering.md, "Light tree". */
#ifndef IRIS_RENDERER_LIGHT_TREE_H
#define IRIS_RENDERER_LIGHT_TREE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "core/math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What the tree knows of one light. */
typedef struct iris_light_bounds {
  iris_vec3 lo, hi;   /* box of its positions (lo = hi for a point) */
  iris_vec3 w;        /* unit axis of its normal cone */
  float cos_o;        /* cosine of the normal cone's half angle (1: one normal, -1: all) */
  float cos_e;        /* cosine of the emission spread beyond the normals (0: Lambertian) */
  float phi;          /* power (importance scale); 0: never chosen */
  bool two_sided;     /* emits on both sides of its normals */
  bool infinite;      /* no position (environment, distant): chosen beside the tree in
                         proportion to phi, here a distance-free importance */
  uint32_t cluster;   /* lights of one cluster (the triangles of one mesh placement) may
                         share a leaf when they are close together; UINT32_MAX: never */
} iris_light_bounds;

/* One node, one 64-byte cache line; children of node i are i + 1 and
 * `index`. */
typedef struct iris_light_tree_node {
  float lo[3], hi[3], radius; /* box of the positions, half its diagonal */
  float w[3];
  float cos_o, sin_o, cos_e, phi;
  uint32_t index; /* leaf: its first light in leaf_lights; interior: the second child */
  uint32_t flags; /* IRIS_LIGHT_NODE_* | leaf: its light count << 8 (leaf_lights[index ..]) */
} iris_light_tree_node;
#define IRIS_LIGHT_NODE_LEAF 1u
#define IRIS_LIGHT_NODE_TWO_SIDED 2u

/* The descent's view of the binary tree: from each interior node, the nodes
 * up to IRIS_LIGHT_WIDE_LEVELS levels down (or the leaves above them) side
 * by side, so one step of the descent takes up to that many binary levels
 * and weighs up to IRIS_LIGHT_WIDE nodes at once, their bounds in a
 * structure of arrays so their importances are one vectorised computation.
 * Lane k's node is reached by the branches path[k] (bit j: the second child
 * at the j-th level) of len[k] levels; an empty lane has phi 0. */
#define IRIS_LIGHT_WIDE_LEVELS 2
#define IRIS_LIGHT_WIDE (1 << IRIS_LIGHT_WIDE_LEVELS)
typedef struct iris_light_tree_wide {
  _Alignas(64) float lo[3][IRIS_LIGHT_WIDE], hi[3][IRIS_LIGHT_WIDE], radius[IRIS_LIGHT_WIDE];
  float w[3][IRIS_LIGHT_WIDE];
  float cos_o[IRIS_LIGHT_WIDE], sin_o[IRIS_LIGHT_WIDE], cos_e[IRIS_LIGHT_WIDE], phi[IRIS_LIGHT_WIDE];
  float phi_r2[IRIS_LIGHT_WIDE]; /* the importance inside the bounding sphere, phi / radius^2 */
  float two_sided[IRIS_LIGHT_WIDE]; /* 1: |cos| to the normals, else 0 */
  float one_normal[IRIS_LIGHT_WIDE]; /* 1: one-sided emitters of one normal (the box's half-space test) */
  uint32_t child[IRIS_LIGHT_WIDE]; /* IRIS_LIGHT_WIDE_LEAF | a binary leaf's index, or a wide node's */
  uint32_t node[IRIS_LIGHT_WIDE];  /* the lane's binary node (tests; the importance without SSE) */
  uint8_t path[IRIS_LIGHT_WIDE], len[IRIS_LIGHT_WIDE];
} iris_light_tree_wide;
#define IRIS_LIGHT_WIDE_LEAF 0x80000000u

typedef struct iris_light_tree {
  iris_light_tree_node *nodes; /* depth first; node 0 is the root (64-byte aligned) */
  size_t node_count;
  iris_light_tree_wide *wide;  /* what the descent reads; wide[0] is the root's (none when the root is a leaf) */
  size_t wide_count;
  uint64_t *bits;              /* per light: its leaf's path from the root (bit k: second child at depth k) */
  uint32_t *leaf_lights;       /* the lights of the leaves, leaf by leaf */
  float *leaf_cdf;             /* beside them: cumulative power share within the leaf */
  float *pmf_in_leaf;          /* per light: its power share within its leaf */
  uint32_t *node_of_light;     /* per light: its leaf, or UINT32_MAX (infinite or zero power) */
  size_t light_count;
  uint32_t *infinite;          /* the infinite lights with phi > 0 */
  float *infinite_phi;
  size_t infinite_count;
  double infinite_sum;         /* sum of infinite_phi */
} iris_light_tree;

/* Leaves hold up to this many lights of one cluster, chosen in proportion to
 * power, when their bounding sphere's radius is at most the build's
 * leaf_radius: the descent is the cost of the tree, and the finest levels of
 * a tessellated emitter decide little (docs/rendering.md, "Light tree"). */
#define IRIS_LIGHT_LEAF_MAX 128

/* Builds the tree over `count` lights (deterministic: the same bounds give
 * the same tree). Depth at most 64. */
iris_status iris_light_tree_build(const iris_light_bounds *lights, size_t count, float leaf_radius,
                                  iris_light_tree *out, iris_error *err);
void iris_light_tree_destroy(iris_light_tree *tree);

/* Importance of bounds b at point p with unit normal n (n = 0: a sphere of
 * directions, for points without a hemisphere): phi cos' / d^2 times the
 * bound on the receiver's cosine (0 when every light of b is behind n or
 * emits away from p). */
float iris_light_bounds_importance(const iris_light_bounds *b, iris_vec3 p, iris_vec3 n);
/* The same importance for a node of the tree, and for the lanes of wide
 * node `wide` at once (the descent's vectorised form; tests compare the two). */
float iris_light_tree_node_importance(const iris_light_tree_node *node, iris_vec3 p, iris_vec3 n);
void iris_light_tree_wide_importance(const iris_light_tree *tree, size_t wide, iris_vec3 p, iris_vec3 n,
                                     float out[IRIS_LIGHT_WIDE]);

/* Chooses a light at (p, n) with one uniform number u in [0, 1); false when
 * nothing there can receive light. *pmf is the probability of the choice. */
bool iris_light_tree_sample(const iris_light_tree *tree, iris_vec3 p, iris_vec3 n, float u,
                            uint32_t *light, float *pmf);
/* The light of leaf node `leaf` whose cumulative power share first exceeds
 * v in [0, 1) (its probability within the leaf: pmf_in_leaf). */
uint32_t iris_light_tree_leaf_choose(const iris_light_tree *tree, uint32_t leaf, double v);
/* The probability that iris_light_tree_sample at (p, n) chooses `light`:
 * retraces its path with the same arithmetic, so the two agree bit for bit. */
float iris_light_tree_pmf(const iris_light_tree *tree, iris_vec3 p, iris_vec3 n, uint32_t light);

#ifdef __cplusplus
}
#endif
#endif
