#include "core/math.h"

#include <string.h>

iris_mat4 iris_mat4_identity(void) {
  iris_mat4 r;
  memset(&r, 0, sizeof r);
  for (int i = 0; i < 4; i++) r.m[i][i] = 1.0f;
  return r;
}

iris_mat4 iris_mat4_mul(const iris_mat4 *a, const iris_mat4 *b) {
  iris_mat4 r;
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) {
      double s = 0.0;
      for (int k = 0; k < 4; k++) s += (double)a->m[i][k] * b->m[k][j];
      r.m[i][j] = (float)s;
    }
  return r;
}

iris_mat4 iris_mat4_transpose(const iris_mat4 *a) {
  iris_mat4 r;
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) r.m[i][j] = a->m[j][i];
  return r;
}

bool iris_mat4_inverse(const iris_mat4 *a, iris_mat4 *out) {
  /* Gauss-Jordan elimination with partial pivoting, in double. */
  double m[4][8];
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) {
      m[i][j] = a->m[i][j];
      m[i][j + 4] = i == j ? 1.0 : 0.0;
    }
  for (int c = 0; c < 4; c++) {
    int p = c;
    for (int r = c + 1; r < 4; r++)
      if (fabs(m[r][c]) > fabs(m[p][c])) p = r;
    if (fabs(m[p][c]) < 1e-30) return false;
    if (p != c)
      for (int j = 0; j < 8; j++) {
        double t = m[c][j];
        m[c][j] = m[p][j];
        m[p][j] = t;
      }
    double inv = 1.0 / m[c][c];
    for (int j = 0; j < 8; j++) m[c][j] *= inv;
    for (int r = 0; r < 4; r++) {
      if (r == c) continue;
      double f = m[r][c];
      if (f == 0.0) continue;
      for (int j = 0; j < 8; j++) m[r][j] -= f * m[c][j];
    }
  }
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) out->m[i][j] = (float)m[i][j + 4];
  return true;
}

iris_vec3 iris_mat4_point(const iris_mat4 *a, iris_vec3 p) {
  float x = a->m[0][0] * p.x + a->m[0][1] * p.y + a->m[0][2] * p.z + a->m[0][3];
  float y = a->m[1][0] * p.x + a->m[1][1] * p.y + a->m[1][2] * p.z + a->m[1][3];
  float z = a->m[2][0] * p.x + a->m[2][1] * p.y + a->m[2][2] * p.z + a->m[2][3];
  float w = a->m[3][0] * p.x + a->m[3][1] * p.y + a->m[3][2] * p.z + a->m[3][3];
  if (w != 1.0f && w != 0.0f) return iris_v3(x / w, y / w, z / w);
  return iris_v3(x, y, z);
}

iris_vec3 iris_mat4_vector(const iris_mat4 *a, iris_vec3 v) {
  return iris_v3(a->m[0][0] * v.x + a->m[0][1] * v.y + a->m[0][2] * v.z,
                 a->m[1][0] * v.x + a->m[1][1] * v.y + a->m[1][2] * v.z,
                 a->m[2][0] * v.x + a->m[2][1] * v.y + a->m[2][2] * v.z);
}

float iris_mat4_det3(const iris_mat4 *a) {
  const float(*m)[4] = a->m;
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

iris_mat4 iris_mat4_normal_matrix(const iris_mat4 *a) {
  /* Cofactor matrix of the 3x3 part = det * inverse transpose; the scale does not
   * matter for normals and the cofactor form never divides by zero. The sign is
   * kept so that mirrored transforms still give outward normals. */
  const float(*m)[4] = a->m;
  iris_mat4 r = iris_mat4_identity();
  r.m[0][0] = m[1][1] * m[2][2] - m[1][2] * m[2][1];
  r.m[0][1] = m[1][2] * m[2][0] - m[1][0] * m[2][2];
  r.m[0][2] = m[1][0] * m[2][1] - m[1][1] * m[2][0];
  r.m[1][0] = m[0][2] * m[2][1] - m[0][1] * m[2][2];
  r.m[1][1] = m[0][0] * m[2][2] - m[0][2] * m[2][0];
  r.m[1][2] = m[0][1] * m[2][0] - m[0][0] * m[2][1];
  r.m[2][0] = m[0][1] * m[1][2] - m[0][2] * m[1][1];
  r.m[2][1] = m[0][2] * m[1][0] - m[0][0] * m[1][2];
  r.m[2][2] = m[0][0] * m[1][1] - m[0][1] * m[1][0];
  if (iris_mat4_det3(a) < 0.0f)
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) r.m[i][j] = -r.m[i][j];
  return r;
}

iris_mat4 iris_mat4_trs(const float t[3], const float q[4], const float s[3]) {
  float x = q[0], y = q[1], z = q[2], w = q[3];
  float n = sqrtf(x * x + y * y + z * z + w * w);
  if (n > 0.0f) {
    x /= n;
    y /= n;
    z /= n;
    w /= n;
  }
  iris_mat4 r = iris_mat4_identity();
  r.m[0][0] = (1 - 2 * (y * y + z * z)) * s[0];
  r.m[0][1] = (2 * (x * y - z * w)) * s[1];
  r.m[0][2] = (2 * (x * z + y * w)) * s[2];
  r.m[1][0] = (2 * (x * y + z * w)) * s[0];
  r.m[1][1] = (1 - 2 * (x * x + z * z)) * s[1];
  r.m[1][2] = (2 * (y * z - x * w)) * s[2];
  r.m[2][0] = (2 * (x * z - y * w)) * s[0];
  r.m[2][1] = (2 * (y * z + x * w)) * s[1];
  r.m[2][2] = (1 - 2 * (x * x + y * y)) * s[2];
  r.m[0][3] = t[0];
  r.m[1][3] = t[1];
  r.m[2][3] = t[2];
  return r;
}

iris_mat4 iris_mat4_look_at(iris_vec3 eye, iris_vec3 target, iris_vec3 up) {
  iris_vec3 back = iris_normalize(iris_sub(eye, target)); /* camera +Z */
  iris_vec3 right = iris_cross(up, back);
  if (iris_length(right) < 1e-8f) right = iris_cross(iris_v3(0, 0, 1), back);
  if (iris_length(right) < 1e-8f) right = iris_cross(iris_v3(1, 0, 0), back);
  right = iris_normalize(right);
  iris_vec3 cup = iris_cross(back, right);
  iris_mat4 r = iris_mat4_identity();
  r.m[0][0] = right.x; r.m[0][1] = cup.x; r.m[0][2] = back.x; r.m[0][3] = eye.x;
  r.m[1][0] = right.y; r.m[1][1] = cup.y; r.m[1][2] = back.y; r.m[1][3] = eye.y;
  r.m[2][0] = right.z; r.m[2][1] = cup.z; r.m[2][2] = back.z; r.m[2][3] = eye.z;
  return r;
}

bool iris_mat4_is_finite(const iris_mat4 *a) {
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++)
      if (!isfinite(a->m[i][j])) return false;
  return true;
}
