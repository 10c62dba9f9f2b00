/* Fast, locale-independent number scanning for the text importers (OBJ, MTL,
 * ASCII PLY). Header-only so both readers inline it. Floats accept the usual
 * decimal/exponent forms plus the non-finite spellings found in real files
 * (nan, -nan, inf, infinity, 1.#IND, 1.#INF, 1.#QNAN) so the caller can
 * reject them with a precise message instead of a syntax error. */
#ifndef IRIS_IMPORTERS_NUMPARSE_H
#define IRIS_IMPORTERS_NUMPARSE_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static inline bool iris_np_is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

static inline const char *iris_np_skip_space(const char *p, const char *end) {
  while (p < end && iris_np_is_space(*p)) p++;
  return p;
}

static inline char iris_np_lower(char c) { return (c >= 'A' && c <= 'Z') ? (char)(c - 'A' + 'a') : c; }

/* Case-insensitive prefix match of the literal `word` at p. */
static inline bool iris_np_match(const char *p, const char *end, const char *word) {
  size_t n = strlen(word);
  if ((size_t)(end - p) < n) return false;
  for (size_t i = 0; i < n; i++)
    if (iris_np_lower(p[i]) != word[i]) return false;
  return true;
}

static inline bool iris_np_token_end(const char *p, const char *end) {
  return p >= end || iris_np_is_space(*p) || *p == '\n' || *p == '/' || *p == '#';
}

/* Parses a double at *pp (no leading space). On success advances *pp past the
 * number and returns true; a number must be followed by a token end. */
static inline bool iris_parse_double(const char **pp, const char *end, double *out) {
  static const double pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                   1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                   1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  const char *p = *pp, *start = p;
  bool neg = false;
  if (p < end && (*p == '-' || *p == '+')) neg = (*p++ == '-');
  if (p < end && (iris_np_lower(*p) == 'n' || iris_np_lower(*p) == 'i')) {
    double v;
    if (iris_np_match(p, end, "nan")) {
      p += 3;
      v = NAN;
      /* nan(chars) */
      if (p < end && *p == '(') {
        while (p < end && *p != ')' && *p != '\n') p++;
        if (p < end && *p == ')') p++;
      }
    } else if (iris_np_match(p, end, "infinity")) {
      p += 8, v = INFINITY;
    } else if (iris_np_match(p, end, "inf")) {
      p += 3, v = INFINITY;
    } else {
      return false;
    }
    if (!iris_np_token_end(p, end)) return false;
    *out = neg ? -v : v;
    *pp = p;
    return true;
  }
  uint64_t mant = 0;
  int digits = 0, exp10 = 0;
  bool any = false;
  while (p < end && *p >= '0' && *p <= '9') {
    any = true;
    if (digits < 19) {
      mant = mant * 10 + (uint64_t)(*p - '0');
      if (mant) digits++;
    } else {
      exp10++;
    }
    p++;
  }
  if (p < end && *p == '.') {
    p++;
    /* MSVC's printf spellings of non-finite values: 1.#INF, 1.#IND, 1.#QNAN */
    if (p < end && *p == '#') {
      p++;
      double v;
      if (iris_np_match(p, end, "inf")) p += 3, v = INFINITY;
      else if (iris_np_match(p, end, "ind")) p += 3, v = NAN;
      else if (iris_np_match(p, end, "qnan")) p += 4, v = NAN;
      else if (iris_np_match(p, end, "snan")) p += 4, v = NAN;
      else return false;
      while (p < end && *p >= '0' && *p <= '9') p++; /* 1.#INF00 */
      if (!iris_np_token_end(p, end)) return false;
      *out = neg ? -v : v;
      *pp = p;
      return true;
    }
    while (p < end && *p >= '0' && *p <= '9') {
      any = true;
      if (digits < 19) {
        mant = mant * 10 + (uint64_t)(*p - '0');
        if (mant) digits++;
        exp10--;
      }
      p++;
    }
  }
  if (!any) return false;
  if (p < end && (*p == 'e' || *p == 'E')) {
    const char *q = p + 1;
    bool eneg = false;
    if (q < end && (*q == '-' || *q == '+')) eneg = (*q++ == '-');
    if (!(q < end && *q >= '0' && *q <= '9')) return false;
    int e = 0;
    while (q < end && *q >= '0' && *q <= '9') {
      if (e < 100000) e = e * 10 + (*q - '0');
      q++;
    }
    exp10 += eneg ? -e : e;
    p = q;
  }
  if (!iris_np_token_end(p, end)) return false;
  double v;
  if (mant == 0) {
    v = 0.0;
  } else if (mant < (1ull << 53) && exp10 >= -22 && exp10 <= 22) {
    /* Both operands exact: one correctly rounded operation. */
    v = exp10 < 0 ? (double)mant / pow10[-exp10] : (double)mant * pow10[exp10];
  } else {
    /* Rare (long mantissas, big exponents): let the C library do it. The
     * token is copied so strtod cannot read past `end`. */
    char buf[96];
    size_t n = (size_t)(p - start);
    if (n >= sizeof buf) {
      v = (double)mant * pow(10.0, exp10);
    } else {
      memcpy(buf, start, n);
      buf[n] = 0;
      v = fabs(strtod(buf, NULL));
    }
  }
  *out = neg ? -v : v;
  *pp = p;
  return true;
}

static inline bool iris_parse_float(const char **pp, const char *end, float *out) {
  double d;
  if (!iris_parse_double(pp, end, &d)) return false;
  *out = (float)d;
  return true;
}

/* Parses a signed integer that fits in int64 (|value| < 2^62). */
static inline bool iris_parse_int(const char **pp, const char *end, int64_t *out) {
  const char *p = *pp;
  bool neg = false;
  if (p < end && (*p == '-' || *p == '+')) neg = (*p++ == '-');
  if (!(p < end && *p >= '0' && *p <= '9')) return false;
  int64_t v = 0;
  while (p < end && *p >= '0' && *p <= '9') {
    if (v > ((int64_t)1 << 58)) return false;
    v = v * 10 + (*p - '0');
    p++;
  }
  *out = neg ? -v : v;
  *pp = p;
  return true;
}

#endif
