/* Small float vector, matrix and frame math used by every layer above core.
 * Matrices are row-major 4x4 acting on column vectors: p' = M * p. */
#ifndef IRIS_CORE_MATH_H
#define IRIS_CORE_MATH_H

#include <math.h>
#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

#define IRIS_PI 3.14159265358979323846f
#define IRIS_INV_PI 0.31830988618379067154f
#define IRIS_INV_2PI 0.15915494309189533577f
#define IRIS_INV_4PI 0.07957747154594766788f
/* The largest float below 1: where a rescaled sample number must stay in [0, 1). */
#define IRIS_ONE_MINUS_EPSILON 0x1.fffffep-1f

typedef struct iris_vec3 {
  float x, y, z;
} iris_vec3;

typedef struct iris_mat4 {
  float m[4][4];
} iris_mat4;

/* Orthonormal frame: s, t tangents, n normal (right-handed: s x t = n). */
typedef struct iris_frame {
  iris_vec3 s, t, n;
} iris_frame;

static inline iris_vec3 iris_v3(float x, float y, float z) {
  iris_vec3 r = {x, y, z};
  return r;
}
static inline iris_vec3 iris_v3_load(const float *p) { return iris_v3(p[0], p[1], p[2]); }
static inline void iris_v3_store(iris_vec3 v, float *p) {
  p[0] = v.x;
  p[1] = v.y;
  p[2] = v.z;
}
static inline iris_vec3 iris_add(iris_vec3 a, iris_vec3 b) { return iris_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline iris_vec3 iris_sub(iris_vec3 a, iris_vec3 b) { return iris_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline iris_vec3 iris_mul(iris_vec3 a, iris_vec3 b) { return iris_v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline iris_vec3 iris_scale(iris_vec3 a, float s) { return iris_v3(a.x * s, a.y * s, a.z * s); }
/* Rec. 709 luminance of linear RGB. */
static inline float iris_luminance(iris_vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
static inline iris_vec3 iris_neg(iris_vec3 a) { return iris_v3(-a.x, -a.y, -a.z); }
static inline iris_vec3 iris_madd(iris_vec3 a, iris_vec3 b, float s) {
  return iris_v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s);
}
static inline float iris_dot(iris_vec3 a, iris_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline iris_vec3 iris_cross(iris_vec3 a, iris_vec3 b) {
  return iris_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float iris_length(iris_vec3 a) { return sqrtf(iris_dot(a, a)); }
static inline iris_vec3 iris_normalize(iris_vec3 a) {
  float l = iris_length(a);
  return l > 0.0f ? iris_scale(a, 1.0f / l) : a;
}
/* fmaxf / fminf inline: glibc's x86-64 versions are calls (its maxss/minss
 * need a NaN fix-up that GCC inlines only under -ffinite-math-only). Same
 * results as those for every float but a signalling NaN (which no arithmetic
 * produces; glibc returns a NaN for it): a quiet NaN operand yields the other
 * one, and equal operands (+0 and -0) yield b, as maxss/minss do
 * (tests/core/test_math.c checks it against libm bit for bit). */
static inline float iris_fmaxf(float a, float b) { return (a > b || b != b) ? a : b; }
static inline float iris_fminf(float a, float b) { return (a < b || b != b) ? a : b; }
static inline float iris_max3(iris_vec3 a) { return iris_fmaxf(a.x, iris_fmaxf(a.y, a.z)); }
static inline float iris_avg3(iris_vec3 a) { return (a.x + a.y + a.z) * (1.0f / 3.0f); }
static inline bool iris_isfinite3(iris_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
static inline float iris_clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
/* Where u lies in [lo, hi), rescaled to [0, 1) (hi > lo): what is left of a
 * sample number after it chose the interval, for the next choice. */
static inline float iris_rescale_unit(float u, float lo, float hi) {
  return iris_clampf((u - lo) / (hi - lo), 0.0f, IRIS_ONE_MINUS_EPSILON);
}
static inline float iris_sqr(float v) { return v * v; }
static inline float iris_safe_sqrt(float v) { return sqrtf(v > 0.0f ? v : 0.0f); } /* NaN -> 0, as fmaxf, without its call */

/* Duff et al. 2017 branchless orthonormal basis around a unit normal. */
static inline iris_frame iris_frame_from_normal(iris_vec3 n) {
  float sign = copysignf(1.0f, n.z);
  float a = -1.0f / (sign + n.z);
  float b = n.x * n.y * a;
  iris_frame f;
  f.s = iris_v3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  f.t = iris_v3(b, sign + n.y * n.y * a, -n.y);
  f.n = n;
  return f;
}
static inline iris_vec3 iris_frame_to_local(const iris_frame *f, iris_vec3 v) {
  return iris_v3(iris_dot(v, f->s), iris_dot(v, f->t), iris_dot(v, f->n));
}
static inline iris_vec3 iris_frame_to_world(const iris_frame *f, iris_vec3 v) {
  return iris_add(iris_add(iris_scale(f->s, v.x), iris_scale(f->t, v.y)), iris_scale(f->n, v.z));
}

iris_mat4 iris_mat4_identity(void);
iris_mat4 iris_mat4_mul(const iris_mat4 *a, const iris_mat4 *b);
/* Returns false (and leaves *out untouched) when the matrix is singular. */
bool iris_mat4_inverse(const iris_mat4 *a, iris_mat4 *out);
iris_mat4 iris_mat4_transpose(const iris_mat4 *a);
iris_vec3 iris_mat4_point(const iris_mat4 *a, iris_vec3 p);
iris_vec3 iris_mat4_vector(const iris_mat4 *a, iris_vec3 v);
/* Determinant of the upper-left 3x3 (negative: the transform flips winding). */
float iris_mat4_det3(const iris_mat4 *a);
/* Matrix for transforming normals: inverse transpose of the upper-left 3x3 (unnormalised). */
iris_mat4 iris_mat4_normal_matrix(const iris_mat4 *a);
/* T * R * S from translation, unit quaternion (x, y, z, w) and scale (glTF order). */
iris_mat4 iris_mat4_trs(const float t[3], const float q[4], const float s[3]);
/* Camera-to-world matrix looking from `eye` at `target`: camera looks along -Z, +Y up. */
iris_mat4 iris_mat4_look_at(iris_vec3 eye, iris_vec3 target, iris_vec3 up);
bool iris_mat4_is_finite(const iris_mat4 *a);

#ifdef __cplusplus
}
#endif
#endif
