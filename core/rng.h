/* Deterministic random numbers: every value is a pure function of
 * (seed, pixel, sample index, dimension), so an image does not depend on the
 * thread count or on the order in which pixels are rendered. */
#ifndef IRIS_CORE_RNG_H
#define IRIS_CORE_RNG_H

#include <stdint.h>

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

/* A sampler positioned at one (seed, stream, sample): `stream` is the pixel
 * index for camera paths and the photon/path index for preprocessing. Each
 * call to iris_sampler_next returns the next dimension. */
typedef struct iris_sampler {
  uint64_t key;
  uint32_t dimension;
} iris_sampler;

static inline iris_sampler iris_sampler_start(uint64_t seed, uint64_t stream, uint64_t sample) {
  iris_sampler s;
  s.key = iris_hash4(seed, stream, sample, 0x1215ULL);
  s.dimension = 0;
  return s;
}

/* Value of dimension `dim` without advancing: the pure function itself. */
static inline float iris_sampler_get(const iris_sampler *s, uint32_t dim) {
  return iris_u64_to_unit(iris_mix64(s->key ^ iris_mix64((uint64_t)dim + 0x51ed270b27d4f1a5ULL)));
}

static inline float iris_sampler_next(iris_sampler *s) { return iris_sampler_get(s, s->dimension++); }

#ifdef __cplusplus
}
#endif
#endif
