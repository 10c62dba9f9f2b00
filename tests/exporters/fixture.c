/* Exporter test helpers; see fixture.h. */
#include "fixture.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "check.h"
#include "core/fileio.h"
#include "core/image.h"

int32_t fixture_add_quad(iris_scene *scene, const char *name, const fixture_quad *q) {
  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.name = iris_strdup(name);
  m.vertex_count = 4;
  m.triangle_count = 2;
  m.positions = malloc(12 * sizeof(float));
  m.indices = malloc(6 * sizeof(uint32_t));
  /* Corners counter-clockwise seen from +z: bottom-left, bottom-right, top-right, top-left. */
  const float sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
  const float uv[8] = {0, 1, 1, 1, 1, 0, 0, 0};
  for (int i = 0; i < 4; i++) {
    m.positions[3 * i + 0] = q->cx + sx[i] * q->hx;
    m.positions[3 * i + 1] = q->cy + sy[i] * q->hy;
    m.positions[3 * i + 2] = q->cz;
  }
  const uint32_t up[6] = {0, 1, 2, 0, 2, 3}, down[6] = {0, 2, 1, 0, 3, 2};
  memcpy(m.indices, q->facing_down ? down : up, sizeof up);
  if (q->normals) {
    m.normals = malloc(12 * sizeof(float));
    for (int i = 0; i < 4; i++) {
      m.normals[3 * i + 0] = q->normal ? q->normal[0] : 0.0f;
      m.normals[3 * i + 1] = q->normal ? q->normal[1] : 0.0f;
      m.normals[3 * i + 2] = q->normal ? q->normal[2] : (q->facing_down ? -1.0f : 1.0f);
    }
  }
  if (q->uvs) {
    m.uvs = malloc(sizeof uv);
    memcpy(m.uvs, uv, sizeof uv);
  }
  if (q->color) {
    m.colors = malloc(12 * sizeof(float));
    for (int i = 0; i < 4; i++) memcpy(m.colors + 3 * i, q->color, 3 * sizeof(float));
  }
  m.material = q->material;
  m.owned = true;
  int32_t index = iris_scene_add_mesh(scene, &m);
  if (index < 0) abort();
  return index;
}

void fixture_add_instance(iris_scene *scene, int32_t mesh, float tx, float ty, float tz) {
  iris_instance inst;
  inst.mesh = (uint32_t)mesh;
  inst.transform = iris_mat4_identity();
  inst.transform.m[0][3] = tx;
  inst.transform.m[1][3] = ty;
  inst.transform.m[2][3] = tz;
  if (iris_scene_add_instance(scene, &inst) < 0) abort();
}

void fixture_add_top_camera(iris_scene *scene, float height, float half, float aspect) {
  iris_camera cam;
  memset(&cam, 0, sizeof cam);
  cam.name = iris_strdup("top");
  cam.to_world = iris_mat4_identity();
  cam.to_world.m[2][3] = height;
  cam.yfov = 2.0f * atanf(half / height);
  cam.aspect = aspect;
  if (iris_scene_add_camera(scene, &cam) < 0) abort();
}

void fixture_film_to_plane(float fx, float fy, int w, int h, float half, float aspect, float *x,
                           float *y) {
  *x = (2.0f * fx / (float)w - 1.0f) * half * aspect;
  *y = (1.0f - 2.0f * fy / (float)h) * half;
}

bool fixture_find_tool(const char *name, char *out, size_t size) {
  const char *path = getenv("PATH");
  if (!path) return false;
  const char *p = path;
  while (*p) {
    const char *end = strchr(p, ':');
    size_t len = end ? (size_t)(end - p) : strlen(p);
    if (len > 0 && len + strlen(name) + 2 < size) {
      snprintf(out, size, "%.*s/%s", (int)len, p, name);
      if (access(out, X_OK) == 0) return true;
    }
    if (!end) break;
    p = end + 1;
  }
  return false;
}

int fixture_run(const char *command, const char *log) {
  char *full = malloc(strlen(command) + (log ? strlen(log) : 0) + 32);
  if (!full) return -1;
  if (log)
    sprintf(full, "%s >'%s' 2>&1", command, log);
  else
    sprintf(full, "%s", command);
  int status = system(full);
  free(full);
  if (status == -1 || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

char *fixture_read_text(const char *path) {
  FILE *fp = fopen(path, "rb");
  if (!fp) return NULL;
  size_t cap = 4096, n = 0;
  char *buf = malloc(cap);
  size_t got;
  while (buf && (got = fread(buf + n, 1, cap - n - 1, fp)) > 0) {
    n += got;
    if (n + 1 == cap) {
      char *grown = realloc(buf, cap * 2);
      if (!grown) {
        free(buf);
        buf = NULL;
        break;
      }
      buf = grown;
      cap *= 2;
    }
  }
  fclose(fp);
  if (buf) buf[n] = '\0';
  return buf;
}

int32_t fixture_add_png_texture(iris_scene *scene, const char *dir, const char *name, const float texels[4][3],
                                bool nearest) {
  iris_image img;
  const char *names[3] = {"R", "G", "B"};
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_image_create(&img, 2, 2, 3, names, &err), &err);
  memcpy(img.data, texels, 12 * sizeof(float));
  char path[1200];
  snprintf(path, sizeof path, "%s/%s.png", dir, name);
  CHECK_OK(iris_png_write(path, &img, 0, 0.0f, &err), &err);
  iris_image_destroy(&img);
  iris_texture t;
  memset(&t, 0, sizeof t);
  t.name = iris_strdup(name);
  size_t size = 0;
  char *data = NULL;
  CHECK_OK(iris_file_read(path, 0, &data, &size, &err), &err);
  t.data = (uint8_t *)data;
  t.data_size = size;
  snprintf(t.mime, sizeof t.mime, "image/png");
  t.wrap_s = t.wrap_t = IRIS_WRAP_REPEAT;
  t.nearest = nearest;
  remove(path);
  int32_t i = iris_scene_add_texture(scene, &t);
  if (i < 0) abort();
  return i;
}
