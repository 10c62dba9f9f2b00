/* Deterministic sample values: every value is a pure function of
 * (seed, stream, sample index, dimension), so an image does not depend on the
 * thread count, the order in which pixels are rendered or how the sample
 * range is partitioned. Two samplers (docs/rendering.md, "Samplers"):
 *  - sobol (default): Owen-scrambled Sobol points, padded in pairs. Dimensions
 *    2k and 2k+1 are the first two Sobol dimensions of the sample index after
 *    a nested uniform shuffle of that index (Burley 2020, "Practical Hash-based
 *    Owen Scrambling"), each coordinate Owen-scrambled, with seeds hashed from
 *    (seed, stream, k): the first 2^m samples of one stream form a (0, m, 2)-net
 *    in every pair, and different pairs and streams are decorrelated.
 *  - independent: every dimension an independent hash (the previous sampler). */
#ifndef IRIS_CORE_RNG_H
#define IRIS_CORE_RNG_H

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

/* A strong 64-bit mixer (splitmix64 finaliser / Stafford variant 13). */
static inline uint64_t iris_mix64(uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return x;
}

static inline uint64_t iris_hash4(uint64_t a, uint64_t b, uint64_t c, uint64_t d) {
  uint64_t h = iris_mix64(a + 0x9e3779b97f4a7c15ULL);
  h = iris_mix64(h ^ (b + 0x632be59bd9b4e019ULL));
  h = iris_mix64(h ^ (c + 0x8cb92ba72f3d8dd7ULL));
  h = iris_mix64(h ^ (d + 0xd6e8feb86659fd93ULL));
  return h;
}

/* Uniform float in [0, 1) from the top 24 bits of a hash. */
static inline float iris_u64_to_unit(uint64_t h) { return (float)(h >> 40) * 0x1p-24f; }
/* Uniform float in [0, 1) from the top 24 bits of a 32-bit fraction. */
static inline float iris_u32_to_unit(uint32_t v) { return (float)(v >> 8) * 0x1p-24f; }

/* ---- Sobol points and hash-based Owen scrambling ------------------------ */

static inline uint32_t iris_reverse_bits32(uint32_t x) {
  x = __builtin_bswap32(x);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  return ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
}

/* Burley 2020, listing 4 (after Laine and Karras 2011): a hash in which each
 * bit depends only on itself and the bits below it, so that applied to the
 * bit-reversed value it acts as an Owen scramble (each digit permuted by a
 * function of the digits above it). */
static inline uint32_t iris_laine_karras_permutation(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

/* Nested uniform (Owen) scramble of a 32-bit binary fraction. Applied to a
 * sample index it maps every aligned block of 2^m indices onto an aligned
 * block of 2^m indices (bit j of the result depends only on bits >= j). */
static inline uint32_t iris_owen_scramble(uint32_t x, uint32_t seed) {
  return iris_reverse_bits32(iris_laine_karras_permutation(iris_reverse_bits32(x), seed));
}

/* Sobol dimensions 0 .. IRIS_SOBOL_DIMS-1 of index i as 32-bit fractions,
 * from the direction numbers of Joe and Kuo (2008, new-joe-kuo-6.21201);
 * dimension 0 is the van der Corput sequence. Defined in core/sobol.c. */
#define IRIS_SOBOL_DIMS 8
uint32_t iris_sobol_u32(uint32_t index, uint32_t dim);
/* iris_reverse_bits32(iris_sobol_u32(index, 1)), from tables of reversed
 * columns (the sampler scrambles in the bit-reversed domain). */
uint32_t iris_sobol1_reversed_u32(uint32_t index);
/* Owen-scrambled Sobol dimension `dim` (< IRIS_SOBOL_DIMS) of `index`. */
static inline float iris_sobol_owen(uint32_t index, uint32_t dim, uint32_t seed) {
  return iris_u32_to_unit(iris_owen_scramble(iris_sobol_u32(index, dim), seed));
}

/* ---- the per-sample sampler -------------------------------------------- */

typedef enum iris_sampler_kind {
  IRIS_SAMPLER_SOBOL = 0,       /* padded Owen-scrambled Sobol pairs (default) */
  IRIS_SAMPLER_INDEPENDENT = 1, /* independent hashed numbers */
  IRIS_SAMPLER_KIND_COUNT
} iris_sampler_kind;

/* "sobol", "independent". */
static inline const char *iris_sampler_kind_name(iris_sampler_kind k) {
  return k == IRIS_SAMPLER_SOBOL ? "sobol" : k == IRIS_SAMPLER_INDEPENDENT ? "independent" : "unknown";
}
static inline bool iris_sampler_kind_parse(const char *name, iris_sampler_kind *out) {
  for (int k = 0; k < IRIS_SAMPLER_KIND_COUNT; k++)
    if (strcmp(name, iris_sampler_kind_name((iris_sampler_kind)k)) == 0) {
      *out = (iris_sampler_kind)k;
      return true;
    }
  return false;
}

/* A sampler positioned at one (seed, stream, sample): `stream` is the pixel
 * index for camera paths and a fixed stream for preprocessing. `dimension`
 * is the next dimension iris_sampler_next returns, and the base that
 * iris_sampler_slot adds to (the path tracer sets it per bounce:
 * docs/rendering.md, "Dimension layout"). */
typedef struct iris_sampler {
  uint64_t key;       /* independent: hash(seed, stream, sample); sobol: hash(seed, stream, sample >> 32) */
  uint64_t sample;    /* the sample index (what is shared by all streams: a pass's light-vertex cache) */
  uint32_t index_rev; /* sobol: the sample index's low 32 bits, bit-reversed */
  uint32_t dimension;
  iris_sampler_kind kind;
} iris_sampler;

static inline iris_sampler iris_sampler_start_kind(iris_sampler_kind kind, uint64_t seed,
                                                   uint64_t stream, uint64_t sample) {
  iris_sampler s;
  s.kind = kind;
  s.dimension = 0;
  s.sample = sample;
  if (kind == IRIS_SAMPLER_SOBOL) {
    s.key = iris_hash4(seed, stream, sample >> 32, 0x50b01ULL);
    s.index_rev = iris_reverse_bits32((uint32_t)sample);
  } else {
    s.key = iris_hash4(seed, stream, sample, 0x1215ULL);
    s.index_rev = 0;
  }
  return s;
}

/* The independent sampler (preprocessing passes that want no correlation). */
static inline iris_sampler iris_sampler_start(uint64_t seed, uint64_t stream, uint64_t sample) {
  return iris_sampler_start_kind(IRIS_SAMPLER_INDEPENDENT, seed, stream, sample);
}

/* The sobol sampler's pair k = dim >> 1: the seeds of its index shuffle and
 * of its two coordinates' scrambles. */
static inline uint64_t iris_sampler_pair_hash_(const iris_sampler *s, uint32_t pair) {
  return iris_mix64(s->key ^ ((uint64_t)pair * 0x9e3779b97f4a7c15ULL + 0x2545f4914f6cdd1dULL));
}

/* The sobol sampler's pair with hash h: the index shuffle is a nested
 * uniform scramble, reverse(LK(reverse(i))). Coordinate 0, the van der
 * Corput value of the shuffled index, is therefore LK(reverse(i)) itself,
 * already an Owen-scrambled van der Corput point (a second scramble would
 * compose into just another one), so a 1D decision costs one permutation.
 * Coordinate 1 is Sobol dimension 1 of the shuffled index, Owen-scrambled
 * with its own seed (one more permutation in the bit-reversed domain). */
static inline uint32_t iris_sobol_pair_c0_(const iris_sampler *s, uint64_t h) {
  return iris_laine_karras_permutation(s->index_rev, (uint32_t)h);
}
static inline uint32_t iris_sobol_pair_c1_(uint32_t c0, uint64_t h) {
  uint32_t rev = iris_sobol1_reversed_u32(iris_reverse_bits32(c0));
  return iris_reverse_bits32(iris_laine_karras_permutation(rev, (uint32_t)(h >> 32)));
}

/* Value of dimension `dim` without advancing: the pure function itself.
 * With the sobol sampler an even dimension costs half an odd one (see above):
 * the layout gives 1D decisions even dimensions. */
static inline float iris_sampler_get(const iris_sampler *s, uint32_t dim) {
  if (s->kind == IRIS_SAMPLER_SOBOL) {
    uint64_t h = iris_sampler_pair_hash_(s, dim >> 1);
    uint32_t c0 = iris_sobol_pair_c0_(s, h);
    return iris_u32_to_unit((dim & 1u) ? iris_sobol_pair_c1_(c0, h) : c0);
  }
  return iris_u64_to_unit(iris_mix64(s->key ^ iris_mix64((uint64_t)dim + 0x51ed270b27d4f1a5ULL)));
}

/* Dimensions `dim` (even) and dim + 1 at once: equal to two iris_sampler_get
 * calls, with the sobol pair's hash and shuffle computed once. */
static inline void iris_sampler_get2(const iris_sampler *s, uint32_t dim, float *u0, float *u1) {
  if (s->kind == IRIS_SAMPLER_SOBOL && !(dim & 1u)) {
    uint64_t h = iris_sampler_pair_hash_(s, dim >> 1);
    uint32_t c0 = iris_sobol_pair_c0_(s, h);
    *u0 = iris_u32_to_unit(c0);
    *u1 = iris_u32_to_unit(iris_sobol_pair_c1_(c0, h));
    return;
  }
  *u0 = iris_sampler_get(s, dim);
  *u1 = iris_sampler_get(s, dim + 1);
}

static inline float iris_sampler_next(iris_sampler *s) { return iris_sampler_get(s, s->dimension++); }
/* Dimension `slot` after the current base (s->dimension), without advancing. */
static inline float iris_sampler_slot(const iris_sampler *s, uint32_t slot) {
  return iris_sampler_get(s, s->dimension + slot);
}
/* Slots `slot` (even) and slot + 1 (a stratified pair). */
static inline void iris_sampler_slot2(const iris_sampler *s, uint32_t slot, float *u0, float *u1) {
  iris_sampler_get2(s, s->dimension + slot, u0, u1);
}

#ifdef __cplusplus
}
#endif
#endif
