#include "fixture.h"

#include "core/fileio.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static float *floats(const float *v, size_t n) {
  float *p = malloc(n * sizeof *p);
  memcpy(p, v, n * sizeof *p);
  return p;
}

iris_mesh fixture_cube(const char *name, bool normals, bool uvs, bool colors) {
  static const float pos[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  static const uint32_t idx[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                   2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3};
  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.name = iris_strdup(name);
  m.vertex_count = 8;
  m.triangle_count = 12;
  m.positions = floats(pos, 24);
  if (normals) {
    float n[24];
    for (int i = 0; i < 24; i++) n[i] = (pos[i] - 0.5f) * 1.1547005f;
    m.normals = floats(n, 24);
  }
  if (uvs) {
    float t[16];
    for (int i = 0; i < 8; i++) t[2 * i] = pos[3 * i] * 0.25f, t[2 * i + 1] = 0.1f * (float)i;
    m.uvs = floats(t, 16);
  }
  if (colors) {
    float c[24];
    for (int i = 0; i < 24; i++) c[i] = (float)i / 23.0f;
    m.colors = floats(c, 24);
  }
  m.indices = malloc(sizeof idx);
  memcpy(m.indices, idx, sizeof idx);
  m.material = -1;
  m.owned = true;
  return m;
}

iris_mesh fixture_triangle(const char *name) {
  static const float pos[9] = {0.1f, 0.2f, 0.3f, 1.0f / 3.0f, -2.5f, 1e-7f, 1e5f, 7.0f, -0.0f};
  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.name = name ? iris_strdup(name) : NULL;
  m.vertex_count = 3;
  m.triangle_count = 1;
  m.positions = floats(pos, 9);
  m.indices = malloc(3 * sizeof *m.indices);
  m.indices[0] = 0, m.indices[1] = 1, m.indices[2] = 2;
  m.material = -1;
  m.owned = true;
  return m;
}

/* A PNG signature followed by junk is enough: the scene format only checks
 * the signature; decoding is the renderer's business. */
static const unsigned char FAKE_PNG[16] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 1, 2, 3, 4, 5, 6, 7, 8};
static const unsigned char FAKE_JPEG[8] = {0xFF, 0xD8, 0xFF, 0xE0, 9, 9, 9, 9};

iris_scene *fixture_rich_scene(const char *dir) {
  iris_scene *s = iris_scene_create();
  char path[1024];

  iris_texture t;
  memset(&t, 0, sizeof t);
  t.name = iris_strdup("in-memory");
  t.data = malloc(sizeof FAKE_JPEG);
  memcpy(t.data, FAKE_JPEG, sizeof FAKE_JPEG);
  t.data_size = sizeof FAKE_JPEG;
  strcpy(t.mime, "image/jpeg");
  t.wrap_s = IRIS_WRAP_CLAMP;
  t.wrap_t = IRIS_WRAP_MIRROR;
  t.nearest = true;
  iris_scene_add_texture(s, &t);

  snprintf(path, sizeof path, "%s/assets", dir);
  if (iris_mkdir_p(path, NULL) != IRIS_OK) return NULL;
  snprintf(path, sizeof path, "%s/assets/wood.png", dir);
  fixture_write(path, FAKE_PNG, sizeof FAKE_PNG);
  memset(&t, 0, sizeof t);
  t.path = iris_strdup(path);
  strcpy(t.mime, "image/png");
  /* placed through the second uv set with a KHR_texture_transform */
  t.uv_set = 1;
  t.has_transform = true;
  t.offset[0] = 0.5f, t.offset[1] = -0.1f, t.rotation = 0.39269908f, t.scale[0] = 30.0f, t.scale[1] = -30.0f;
  iris_scene_add_texture(s, &t);

  iris_material m = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  m.name = iris_strdup("default-diffuse");
  iris_scene_add_material(s, &m);
  m = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  m.name = iris_strdup("light");
  m.color[0] = 0.78f, m.color[1] = 0.1f, m.color[2] = 0.0f;
  m.emission[0] = 17, m.emission[1] = 12, m.emission[2] = 4;
  m.emission_two_sided = false;
  m.color_texture = 1;
  iris_scene_add_material(s, &m);
  m = iris_material_default(IRIS_MATERIAL_GLOSSY);
  m.name = iris_strdup("metal");
  m.roughness = 0.05f;
  m.double_sided = true;
  iris_scene_add_material(s, &m);
  m = iris_material_default(IRIS_MATERIAL_GLASS);
  m.name = iris_strdup("glass");
  m.roughness = 0.0f;
  m.ior = 1.45f;
  m.color[0] = m.color[1] = m.color[2] = 1.0f;
  iris_scene_add_material(s, &m);
  m = iris_material_default(IRIS_MATERIAL_GLTF);
  m.name = NULL;
  m.color_texture = 0;
  m.metallic = 1.0f;
  m.metallic_roughness_texture = 1;
  m.specular = 0.5f;
  m.specular_color[1] = 0.25f;
  m.transmission = 0.125f;
  m.emission[2] = 1e-3f;
  m.emission_texture = 0;
  m.ior = 1.33f;
  m.normal_texture = 1;
  m.normal_scale = 0.75f;
  m.anisotropy = 0.625f;
  m.anisotropy_rotation = -1.25f;
  m.anisotropy_texture = 1;
  iris_scene_add_material(s, &m);

  iris_mesh cube = fixture_cube("cube", true, true, true);
  cube.material = 1;
  /* second uv set and tangents (w = -1 on mirrored-uv vertices) */
  cube.uvs1 = malloc(16 * sizeof(float));
  cube.tangents = malloc(32 * sizeof(float));
  for (int i = 0; i < 8; i++) {
    cube.uvs1[2 * i] = 1.0f - cube.uvs[2 * i], cube.uvs1[2 * i + 1] = cube.uvs[2 * i + 1] * 3.0f;
    const float tg[4] = {0.6f, 0.0f, -0.8f, i % 3 ? 1.0f : -1.0f};
    memcpy(cube.tangents + 4 * i, tg, sizeof tg);
  }
  iris_scene_add_mesh(s, &cube);
  cube = fixture_cube(NULL, false, true, false);
  cube.material = 4;
  iris_scene_add_mesh(s, &cube);
  iris_mesh tri = fixture_triangle("tri");
  iris_scene_add_mesh(s, &tri);

  iris_instance inst;
  inst.mesh = 0;
  inst.transform = iris_mat4_identity();
  iris_scene_add_instance(s, &inst);
  float q[4] = {0.1f, 0.7f, -0.2f, 0.6782330f}, tr[3] = {1.5f, -2.0f, 0.3f}, sc[3] = {2, 2, 0.5f};
  inst.transform = iris_mat4_trs(tr, q, sc);
  iris_scene_add_instance(s, &inst);
  inst.mesh = 1;
  iris_scene_add_instance(s, &inst);
  inst.mesh = 2;
  inst.transform = iris_mat4_identity();
  inst.transform.m[0][3] = 10.0f;
  iris_scene_add_instance(s, &inst);

  iris_camera c;
  memset(&c, 0, sizeof c);
  c.name = iris_strdup("front");
  c.to_world = iris_mat4_look_at(iris_v3(0, 1, 6.8f), iris_v3(0, 1, 0), iris_v3(0, 1, 0));
  c.yfov = 19.5f * IRIS_PI / 180.0f;
  c.aspect = 1.0f;
  iris_scene_add_camera(s, &c);
  c.name = iris_strdup("odd");
  float q2[4] = {0.3f, -0.4f, 0.1f, 0.8602325f}, t2[3] = {0.123f, 4.56f, -7.89f}, s2[3] = {1, 1, 1};
  c.to_world = iris_mat4_trs(t2, q2, s2);
  c.yfov = 0.6860516f;
  c.aspect = 0.0f;
  iris_scene_add_camera(s, &c);

  iris_light l;
  memset(&l, 0, sizeof l);
  l.name = iris_strdup("bulb");
  l.type = IRIS_LIGHT_POINT;
  l.color[0] = 1, l.color[1] = 0.9f, l.color[2] = 0.8f;
  l.intensity = 100;
  l.position[1] = 3;
  iris_scene_add_light(s, &l);
  memset(&l, 0, sizeof l);
  l.type = IRIS_LIGHT_SPOT;
  l.color[0] = l.color[1] = l.color[2] = 1;
  l.intensity = 5;
  l.position[2] = 2;
  l.direction[2] = -1;
  l.range = 20;
  l.inner_cone = 0.2f;
  l.outer_cone = 0.785398163f;
  iris_scene_add_light(s, &l);
  memset(&l, 0, sizeof l);
  l.name = iris_strdup("sun");
  l.type = IRIS_LIGHT_DIRECTIONAL;
  l.color[0] = l.color[1] = l.color[2] = 1;
  l.intensity = 3.5f;
  l.direction[0] = 0.6f, l.direction[1] = -0.8f;
  iris_scene_add_light(s, &l);

  s->has_environment = true;
  s->environment[0] = 0.05f, s->environment[1] = 0.1f, s->environment[2] = 0.2f;
  s->render.width = 640;
  s->render.height = 480;
  s->render.spp = 64;
  s->render.max_depth = 8;
  strcpy(s->render.method, "guided");
  s->render.seed = UINT64_C(18446744073709551557);
  s->render.has_seed = true;
  return s;
}

char *fixture_slurp(const char *path, size_t *size) {
  FILE *fp = fopen(path, "rb");
  if (!fp) return NULL;
  fseek(fp, 0, SEEK_END);
  long n = ftell(fp);
  fseek(fp, 0, SEEK_SET);
  char *buf = malloc((size_t)n + 1);
  size_t got = fread(buf, 1, (size_t)n, fp);
  fclose(fp);
  buf[got] = '\0';
  if (size) *size = got;
  return buf;
}

bool fixture_write(const char *path, const void *data, size_t size) {
  FILE *fp = fopen(path, "wb");
  if (!fp) return false;
  bool ok = fwrite(data, 1, size, fp) == size;
  return fclose(fp) == 0 && ok;
}

bool fixture_same_file(const char *a, const char *b) {
  size_t na = 0, nb = 0;
  char *da = fixture_slurp(a, &na), *db = fixture_slurp(b, &nb);
  bool same = da && db && na == nb && memcmp(da, db, na) == 0;
  free(da);
  free(db);
  return same;
}

bool fixture_replace(const char *path, const char *from, const char *to) {
  size_t n = 0;
  char *text = fixture_slurp(path, &n);
  if (!text) return false;
  char *hit = strstr(text, from);
  if (!hit) {
    free(text);
    return false;
  }
  size_t before = (size_t)(hit - text), lf = strlen(from), lt = strlen(to);
  char *out = malloc(n - lf + lt + 1);
  memcpy(out, text, before);
  memcpy(out + before, to, lt);
  memcpy(out + before + lt, hit + lf, n - before - lf);
  bool ok = fixture_write(path, out, n - lf + lt);
  free(text);
  free(out);
  return ok;
}
