/* Built-in scenes; the numbers and their sources are in docs/rendering.md. */
#include "scenes/builtin.h"

#include <stdlib.h>
#include <string.h>

#include "scenes/door.h"
#include "scenes/glazing.h"
#include "scenes/office.h"
#include "scenes/rooms.h"
#include "scenes/sky.h"
#include "scenes/stress/stress.h"

static const char *const NAMES[] = {"cornell-box", "veach-mis", "door", "door-shielded", "furnace-diffuse",
                                    "furnace-glossy", "inside-sphere",
                                    /* the failure-stability scenes, scenes/stress/stress.h */
                                    "stress-gap", "stress-veach-lights", "stress-caustic",
                                    "stress-thin-walls", "stress-small-dim", "stress-closed-box",
                                    "stress-firefly", "stress-glossy-room",
                                    /* lit by the HDR sky of ../shared (scenes/sky.h) */
                                    "env-objects", "env-spheres", "sky-room", "sky-room-corner",
                                    /* light through glass (scenes/glazing.h) */
                                    "sky-room-glazed", "sky-room-pane", "lamp-shade",
                                    /* 400 ceiling lamps (scenes/office.h) */
                                    "office",
                                    /* rooms along a corridor, most lamps hidden (scenes/rooms.h) */
                                    "corridor-rooms", NULL};

const char *const *iris_builtin_names(void) { return NAMES; }

bool iris_builtin_exists(const char *name) {
  for (int i = 0; NAMES[i]; i++)
    if (strcmp(NAMES[i], name) == 0) return true;
  return false;
}

static int32_t add_mesh_instance(iris_scene *scene, iris_mesh *m) {
  int32_t mi = iris_scene_add_mesh(scene, m);
  if (mi < 0) {
    free(m->name);
    free(m->positions);
    free(m->normals);
    free(m->indices);
    return -1;
  }
  iris_instance inst;
  inst.mesh = (uint32_t)mi;
  inst.transform = iris_mat4_identity();
  return iris_scene_add_instance(scene, &inst) < 0 ? -1 : mi;
}

int32_t iris_builtin_add_diffuse(iris_scene *scene, const char *name, float r, float g, float b, float emission,
                                 const float tint[3]) {
  iris_material m = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  m.name = iris_strdup(name);
  m.color[0] = r;
  m.color[1] = g;
  m.color[2] = b;
  for (int k = 0; k < 3; k++) m.emission[k] = tint[k] * emission;
  m.emission_two_sided = false;
  return m.name ? iris_scene_add_material(scene, &m) : -1;
}

bool iris_builtin_add_lamps(iris_scene *scene, float base, const float tint[3], int32_t lamp[4]) {
  for (int k = 0; k < 4; k++) {
    char name[32];
    snprintf(name, sizeof name, "lamp_%d", 1 << k);
    lamp[k] = iris_builtin_add_diffuse(scene, name, 0.8f, 0.8f, 0.8f, base * (float)(1 << k), tint);
    if (lamp[k] < 0) return false;
  }
  return true;
}

int32_t iris_builtin_add_quad(iris_scene *scene, iris_vec3 c, iris_vec3 a, iris_vec3 b, int n,
                              int32_t material, const char *name) {
  if (n < 1) n = 1;
  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.name = iris_strdup(name);
  m.vertex_count = (uint32_t)((n + 1) * (n + 1));
  m.triangle_count = (uint32_t)(2 * n * n);
  m.positions = malloc(sizeof(float) * 3 * m.vertex_count);
  m.indices = malloc(sizeof(uint32_t) * 3 * m.triangle_count);
  m.material = material;
  m.owned = true;
  if (!m.positions || !m.indices) {
    free(m.name);
    free(m.positions);
    free(m.indices);
    return -1;
  }
  for (int j = 0; j <= n; j++)
    for (int i = 0; i <= n; i++) {
      float s = -1.0f + 2.0f * (float)i / (float)n, t = -1.0f + 2.0f * (float)j / (float)n;
      iris_vec3 p = iris_add(c, iris_add(iris_scale(a, s), iris_scale(b, t)));
      iris_v3_store(p, m.positions + 3 * (size_t)(j * (n + 1) + i));
    }
  uint32_t *ix = m.indices;
  for (int j = 0; j < n; j++)
    for (int i = 0; i < n; i++) {
      uint32_t v00 = (uint32_t)(j * (n + 1) + i), v10 = v00 + 1, v01 = v00 + (uint32_t)(n + 1),
               v11 = v01 + 1;
      /* counter-clockwise seen from the cross(a, b) side */
      *ix++ = v00; *ix++ = v10; *ix++ = v11;
      *ix++ = v00; *ix++ = v11; *ix++ = v01;
    }
  return add_mesh_instance(scene, &m);
}

int32_t iris_builtin_add_sphere(iris_scene *scene, iris_vec3 center, float radius, int segments,
                                int32_t material, const char *name) {
  if (segments < 4) segments = 4;
  int rings = segments / 2;
  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.name = iris_strdup(name);
  /* rings - 1 latitude circles plus the two poles */
  m.vertex_count = (uint32_t)((rings - 1) * segments + 2);
  m.triangle_count = (uint32_t)(2 * segments * (rings - 1));
  m.positions = malloc(sizeof(float) * 3 * m.vertex_count);
  m.normals = malloc(sizeof(float) * 3 * m.vertex_count);
  m.indices = malloc(sizeof(uint32_t) * 3 * m.triangle_count);
  m.material = material;
  m.owned = true;
  if (!m.positions || !m.normals || !m.indices) {
    free(m.name);
    free(m.positions);
    free(m.normals);
    free(m.indices);
    return -1;
  }
  uint32_t v = 0;
  iris_vec3 dirs_top = iris_v3(0, 1, 0);
  iris_v3_store(dirs_top, m.normals + 3 * v);
  iris_v3_store(iris_madd(center, dirs_top, radius), m.positions + 3 * v);
  v++;
  for (int r = 1; r < rings; r++) {
    double theta = 3.14159265358979323846 * r / rings;
    for (int s = 0; s < segments; s++) {
      double phi = 2.0 * 3.14159265358979323846 * s / segments;
      iris_vec3 d = iris_v3((float)(sin(theta) * cos(phi)), (float)cos(theta),
                            (float)(-sin(theta) * sin(phi)));
      iris_v3_store(d, m.normals + 3 * v);
      iris_v3_store(iris_madd(center, d, radius), m.positions + 3 * v);
      v++;
    }
  }
  iris_vec3 dirs_bottom = iris_v3(0, -1, 0);
  iris_v3_store(dirs_bottom, m.normals + 3 * v);
  iris_v3_store(iris_madd(center, dirs_bottom, radius), m.positions + 3 * v);
  uint32_t bottom = v;
  uint32_t *ix = m.indices;
  /* phi grows counter-clockwise seen from +y (x towards -z), so walking s then
   * down a ring is counter-clockwise seen from outside. */
  for (int s = 0; s < segments; s++) {
    uint32_t a = 1 + (uint32_t)s, b = 1 + (uint32_t)((s + 1) % segments);
    *ix++ = 0; *ix++ = a; *ix++ = b;
  }
  for (int r = 0; r < rings - 2; r++)
    for (int s = 0; s < segments; s++) {
      uint32_t a = 1 + (uint32_t)(r * segments + s);
      uint32_t b = 1 + (uint32_t)(r * segments + (s + 1) % segments);
      uint32_t c = a + (uint32_t)segments, d = b + (uint32_t)segments;
      *ix++ = a; *ix++ = c; *ix++ = d;
      *ix++ = a; *ix++ = d; *ix++ = b;
    }
  uint32_t last = 1 + (uint32_t)((rings - 2) * segments);
  for (int s = 0; s < segments; s++) {
    uint32_t a = last + (uint32_t)s, b = last + (uint32_t)((s + 1) % segments);
    *ix++ = a; *ix++ = bottom; *ix++ = b;
  }
  return add_mesh_instance(scene, &m);
}

static int32_t add_material(iris_scene *scene, const char *name, iris_material_type type, float r,
                            float g, float b) {
  iris_material m = iris_material_default(type);
  m.name = iris_strdup(name);
  m.color[0] = r;
  m.color[1] = g;
  m.color[2] = b;
  int32_t i = iris_scene_add_material(scene, &m);
  if (i < 0) free(m.name);
  return i;
}

static bool add_camera(iris_scene *scene, const char *name, iris_vec3 eye, iris_vec3 target,
                       float yfov_deg, float aspect) {
  iris_camera cam;
  cam.name = iris_strdup(name);
  cam.to_world = iris_mat4_look_at(eye, target, iris_v3(0, 1, 0));
  cam.yfov = yfov_deg * (IRIS_PI / 180.0f);
  cam.aspect = aspect;
  if (iris_scene_add_camera(scene, &cam) < 0) {
    free(cam.name);
    return false;
  }
  return true;
}

/* Mitsuba's unit cube [-1, 1]^3 under a 3x4 toWorld matrix (Bitterli's boxes). */
static bool add_box(iris_scene *scene, const float mtx[12], int32_t material, const char *name) {
  iris_mat4 t = iris_mat4_identity();
  for (int r = 0; r < 3; r++)
    for (int c = 0; c < 4; c++) t.m[r][c] = mtx[4 * r + c];
  iris_vec3 centre = iris_mat4_point(&t, iris_v3(0, 0, 0));
  for (int axis = 0; axis < 3; axis++)
    for (int sign = -1; sign <= 1; sign += 2) {
      float fc[3] = {0, 0, 0}, fa[3] = {0, 0, 0}, fb[3] = {0, 0, 0};
      fc[axis] = (float)sign;
      fa[(axis + 1) % 3] = 1.0f;
      fb[(axis + 2) % 3] = 1.0f;
      iris_vec3 c = iris_mat4_point(&t, iris_v3_load(fc));
      iris_vec3 a = iris_mat4_vector(&t, iris_v3_load(fa));
      iris_vec3 b = iris_mat4_vector(&t, iris_v3_load(fb));
      /* front face outward, whatever the handedness of the matrix */
      if (iris_dot(iris_cross(a, b), iris_sub(c, centre)) < 0.0f) a = iris_neg(a);
      if (iris_builtin_add_quad(scene, c, a, b, 1, material, name) < 0) return false;
    }
  return true;
}

/* Bitterli's "Cornell Box" (CC0; ../shared/assets/scenes/bitterli-cornell-box):
 * walls at x = +-1, y in [0, 2], z in [-1, 1], McGuire/Bitterli reflectances,
 * a one-sided light of radiance (17, 12, 4) facing down at y = 1.98. */
static iris_status build_cornell(iris_scene *s) {
  int32_t white = add_material(s, "white", IRIS_MATERIAL_DIFFUSE, 0.725f, 0.71f, 0.68f);
  int32_t red = add_material(s, "red", IRIS_MATERIAL_DIFFUSE, 0.63f, 0.065f, 0.05f);
  int32_t green = add_material(s, "green", IRIS_MATERIAL_DIFFUSE, 0.14f, 0.45f, 0.091f);
  int32_t light = add_material(s, "light", IRIS_MATERIAL_DIFFUSE, 0.0f, 0.0f, 0.0f);
  if (white < 0 || red < 0 || green < 0 || light < 0) return IRIS_ERR_NOMEM;
  s->materials[light].emission[0] = 17.0f;
  s->materials[light].emission[1] = 12.0f;
  s->materials[light].emission[2] = 4.0f;
  s->materials[light].emission_two_sided = false;
  bool ok = true;
  /* cross(a, b) gives the front (inward) side of each wall */
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 0, 0), iris_v3(0, 0, 1), iris_v3(1, 0, 0), 1, white, "floor") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 2, 0), iris_v3(1, 0, 0), iris_v3(0, 0, 1), 1, white, "ceiling") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 1, -1), iris_v3(1, 0, 0), iris_v3(0, 1, 0), 1, white, "back") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(-1, 1, 0), iris_v3(0, 1, 0), iris_v3(0, 0, 1), 1, red, "left") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(1, 1, 0), iris_v3(0, 0, 1), iris_v3(0, 1, 0), 1, green, "right") >= 0;
  static const float short_box[12] = {0.0851643f, 0.289542f, 0, 0.328631f, 0, 0, -0.3f, 0.3f,
                                      -0.284951f, 0.0865363f, 0, 0.374592f};
  static const float tall_box[12] = {0.286776f, 0.098229f, 0, -0.335439f, 0, 0, -0.6f, 0.6f,
                                     -0.0997984f, 0.282266f, 0, -0.291415f};
  ok = ok && add_box(s, short_box, white, "short_box") && add_box(s, tall_box, white, "tall_box");
  /* The light: x in [-0.24, 0.23], z in [-0.22, 0.16], facing -y; 4 x 4 quads so
   * that no edge (0.12 x 0.095) is longer than the distance to the walls and boxes. */
  ok = ok && iris_builtin_add_quad(s, iris_v3(-0.005f, 1.98f, -0.03f), iris_v3(0.235f, 0, 0),
                                   iris_v3(0, 0, 0.19f), 4, light, "light") >= 0;
  ok = ok && add_camera(s, "camera", iris_v3(0, 1, 6.8f), iris_v3(0, 1, 0), 19.5f, 1.0f);
  if (!ok) return IRIS_ERR_NOMEM;
  s->render.width = 512;
  s->render.height = 512;
  return IRIS_OK;
}

/* Veach's four-light MIS scene (Veach 1997 fig. 9.2 via Mitsuba's veach_mi,
 * ../shared/assets/README.md "(b)"). */
static iris_status build_veach(iris_scene *s) {
  static const float xs[4] = {-3.75f, -1.25f, 1.25f, 3.75f};
  static const float radii[4] = {0.03333f, 0.1f, 0.3f, 0.9f};
  static const float radiance[4] = {901.803f, 100.0f, 11.1111f, 1.23457f};
  static const float alpha[4] = {0.005f, 0.02f, 0.05f, 0.1f};
  static const float edges[4][4] = {{-2.70651f, 0.25609f, -2.08375f, -0.526323f},
                                    {-3.28825f, 1.36972f, -2.83856f, 0.476536f},
                                    {-3.73096f, 2.70046f, -3.43378f, 1.74564f},
                                    {-3.99615f, 4.0667f, -3.82069f, 3.08221f}};
  bool ok = true;
  int32_t floor_mat = add_material(s, "diffuse", IRIS_MATERIAL_DIFFUSE, 0.4f, 0.4f, 0.4f);
  ok = floor_mat >= 0;
  for (int i = 0; ok && i < 4; i++) {
    char name[32];
    snprintf(name, sizeof name, "light%d", i + 1);
    int32_t m = add_material(s, name, IRIS_MATERIAL_DIFFUSE, 0, 0, 0);
    if (m < 0) return IRIS_ERR_NOMEM;
    for (int c = 0; c < 3; c++) s->materials[m].emission[c] = radiance[i];
    s->materials[m].emission_two_sided = false; /* closed spheres: outward only */
    /* 64 segments: the smallest sphere's silhouette is off by < 0.12% of its radius */
    ok = iris_builtin_add_sphere(s, iris_v3(xs[i], 0, 0), radii[i], 64, m, name) >= 0;
  }
  int32_t fill = ok ? add_material(s, "fill_light", IRIS_MATERIAL_DIFFUSE, 0, 0, 0) : -1;
  if (fill < 0) return IRIS_ERR_NOMEM;
  for (int c = 0; c < 3; c++) s->materials[fill].emission[c] = 800.0f;
  s->materials[fill].emission_two_sided = false;
  ok = iris_builtin_add_sphere(s, iris_v3(10, 10, 4), 0.5f, 64, fill, "fill_light") >= 0;
  for (int i = 0; ok && i < 4; i++) {
    char name[32];
    snprintf(name, sizeof name, "plate%d", i + 1);
    int32_t m = add_material(s, name, IRIS_MATERIAL_GLOSSY, 0.3f, 0.3f, 0.3f);
    if (m < 0) return IRIS_ERR_NOMEM;
    s->materials[m].roughness = sqrtf(alpha[i]); /* GGX alpha = roughness^2 */
    iris_vec3 e1 = iris_v3(0, edges[i][0], edges[i][1]), e2 = iris_v3(0, edges[i][2], edges[i][3]);
    iris_vec3 c = iris_scale(iris_add(e1, e2), 0.5f);
    iris_vec3 a = iris_v3(4, 0, 0), b = iris_scale(iris_sub(e1, e2), 0.5f);
    if (iris_cross(a, b).y < 0.0f) b = iris_neg(b); /* front face up, towards the lights */
    ok = iris_builtin_add_quad(s, c, a, b, 1, m, name) >= 0;
  }
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, -4.14615f, 0), iris_v3(0, 0, 10), iris_v3(10, 0, 0),
                                   1, floor_mat, "floor") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 0, -2), iris_v3(10, 0, 0), iris_v3(0, 10, 0), 1,
                                   floor_mat, "back") >= 0;
  ok = ok && add_camera(s, "camera", iris_v3(0, 2, 15), iris_v3(0, -2, 2.5f), 28.0f, 1.5f);
  if (!ok) return IRIS_ERR_NOMEM;
  s->render.width = 768;
  s->render.height = 512;
  return IRIS_OK;
}

/* A sphere of radius 1 with an albedo-1 material under a constant sky of
 * radiance 1: every pixel must be 1 (white furnace). */
static iris_status build_furnace(iris_scene *s, iris_material_type type) {
  int32_t m = add_material(s, "white", type, 1, 1, 1);
  if (m < 0) return IRIS_ERR_NOMEM;
  s->materials[m].roughness = 0.5f;
  if (iris_builtin_add_sphere(s, iris_v3(0, 0, 0), 1.0f, 128, m, "sphere") < 0) return IRIS_ERR_NOMEM;
  s->has_environment = true;
  s->environment[0] = s->environment[1] = s->environment[2] = 1.0f;
  if (!add_camera(s, "camera", iris_v3(0, 0, 4), iris_v3(0, 0, 0), 40.0f, 1.0f)) return IRIS_ERR_NOMEM;
  return IRIS_OK;
}

/* Seen from its centre, a sphere emitting radiance 1 (and reflecting nothing)
 * is 1 in every pixel. */
static iris_status build_inside(iris_scene *s) {
  int32_t m = add_material(s, "emitter", IRIS_MATERIAL_DIFFUSE, 0, 0, 0);
  if (m < 0) return IRIS_ERR_NOMEM;
  for (int c = 0; c < 3; c++) s->materials[m].emission[c] = 1.0f;
  s->materials[m].emission_two_sided = true;
  if (iris_builtin_add_sphere(s, iris_v3(0, 0, 0), 1.0f, 32, m, "sphere") < 0) return IRIS_ERR_NOMEM;
  if (!add_camera(s, "camera", iris_v3(0, 0, 0), iris_v3(0, 0, -1), 90.0f, 1.0f)) return IRIS_ERR_NOMEM;
  return IRIS_OK;
}

iris_status iris_builtin_create(const char *name, iris_scene **out, iris_error *err) {
  *out = NULL;
  if (!iris_builtin_exists(name))
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "unknown built-in scene '%s'", name);
  iris_scene *s = iris_scene_create();
  if (!s) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory");
  iris_status st;
  if (strcmp(name, "cornell-box") == 0)
    st = build_cornell(s);
  else if (strcmp(name, "veach-mis") == 0)
    st = build_veach(s);
  else if (strcmp(name, "door") == 0)
    st = iris_door_scene_build(s);
  else if (strcmp(name, "door-shielded") == 0) /* light faces away from the door (docs/guiding.md) */
    st = iris_door_scene_build_variant(s, IRIS_DOOR_SHIELDED);
  else if (strcmp(name, "furnace-diffuse") == 0)
    st = build_furnace(s, IRIS_MATERIAL_DIFFUSE);
  else if (strcmp(name, "furnace-glossy") == 0)
    st = build_furnace(s, IRIS_MATERIAL_GLOSSY);
  else if (strcmp(name, "env-objects") == 0)
    st = iris_sky_objects_build(s);
  else if (strcmp(name, "env-spheres") == 0)
    st = iris_sky_spheres_build(s);
  else if (strcmp(name, "sky-room") == 0)
    st = iris_sky_room_build(s);
  else if (strcmp(name, "sky-room-corner") == 0)
    st = iris_sky_room_corner_build(s);
  else if (strcmp(name, "sky-room-glazed") == 0)
    st = iris_sky_room_glazed_build(s);
  else if (strcmp(name, "sky-room-pane") == 0)
    st = iris_sky_room_pane_build(s);
  else if (strcmp(name, "lamp-shade") == 0)
    st = iris_lamp_shade_build(s);
  else if (strcmp(name, "office") == 0)
    st = iris_office_scene_build(s);
  else if (strcmp(name, "corridor-rooms") == 0)
    st = iris_rooms_scene_build(s);
  else if (iris_stress_find(name))
    st = iris_stress_build(name, s);
  else
    st = build_inside(s);
  if (st == IRIS_OK) {
    char src[64];
    snprintf(src, sizeof src, "builtin:%s", name);
    s->source_path = iris_strdup(src);
    st = iris_scene_validate(s, src, err);
    if (st != IRIS_OK) {
      iris_scene_destroy(s);
      return st;
    }
  }
  if (st != IRIS_OK) {
    iris_scene_destroy(s);
    return iris_error_set(err, st, NULL, 0, NULL, "cannot build the built-in scene '%s'", name);
  }
  *out = s;
  return IRIS_OK;
}
