/* Sobol generator matrices from Joe and Kuo's direction numbers; see rng.h. */
#include "core/rng.h"

/* Joe and Kuo (2008), file new-joe-kuo-6.21201, dimensions 2..IRIS_SOBOL_DIMS
 * (their numbering; dimension 1 is van der Corput): degree s of the primitive
 * polynomial, its coefficients a, and the initial direction numbers m_1..m_s. */
static const struct {
  int s;
  unsigned a;
  unsigned m[5];
} JOE_KUO[IRIS_SOBOL_DIMS - 1] = {
    {1, 0, {1}},               {2, 1, {1, 3}},           {3, 1, {1, 3, 1}},
    {3, 2, {1, 1, 1}},         {4, 1, {1, 1, 3, 3}},     {4, 4, {1, 3, 5, 13}},
    {5, 2, {1, 1, 5, 5, 17}},
};

/* Per dimension, the product of the generator matrix with each byte of the
 * index (the matrix is linear over GF(2): four lookups and XORs per value). */
static uint32_t g_bytes[IRIS_SOBOL_DIMS][4][256];
static uint32_t g_bytes1_rev[4][256]; /* dimension 1, reversed columns */
/* Built before main (a constructor), so the per-sample look-ups need no
 * synchronisation; the tables are a pure function of JOE_KUO. */
__attribute__((constructor)) static void build_tables(void) {
  for (int d = 0; d < IRIS_SOBOL_DIMS; d++) {
    uint32_t v[32];
    if (d == 0) {
      for (int i = 0; i < 32; i++) v[i] = 1u << (31 - i);
    } else {
      const int s = JOE_KUO[d - 1].s;
      const unsigned a = JOE_KUO[d - 1].a;
      for (int i = 0; i < s && i < 32; i++) v[i] = (uint32_t)JOE_KUO[d - 1].m[i] << (31 - i);
      for (int i = s; i < 32; i++) {
        uint32_t x = v[i - s] ^ (v[i - s] >> s);
        for (int k = 1; k < s; k++)
          if ((a >> (s - 1 - k)) & 1u) x ^= v[i - k];
        v[i] = x;
      }
    }
    for (int byte = 0; byte < 4; byte++)
      for (unsigned b = 0; b < 256; b++) {
        uint32_t x = 0;
        for (int bit = 0; bit < 8; bit++)
          if (b & (1u << bit)) x ^= v[8 * byte + bit];
        g_bytes[d][byte][b] = x;
        if (d == 1) g_bytes1_rev[byte][b] = iris_reverse_bits32(x);
      }
  }
}

uint32_t iris_sobol_u32(uint32_t index, uint32_t dim) {
  if (dim >= IRIS_SOBOL_DIMS) return 0;
  return g_bytes[dim][0][index & 255u] ^ g_bytes[dim][1][(index >> 8) & 255u] ^
         g_bytes[dim][2][(index >> 16) & 255u] ^ g_bytes[dim][3][index >> 24];
}

uint32_t iris_sobol1_reversed_u32(uint32_t index) {
  return g_bytes1_rev[0][index & 255u] ^ g_bytes1_rev[1][(index >> 8) & 255u] ^
         g_bytes1_rev[2][(index >> 16) & 255u] ^ g_bytes1_rev[3][index >> 24];
}
