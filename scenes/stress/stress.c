/* The stress scenes (scenes/stress/stress.h). Units: metres, y up. Every
 * scene renders at 128 x 96 by default (Veach's plates 120 x 80) so that the
 * whole suite runs in minutes. docs/stability.md describes each one. */
#include "scenes/stress/stress.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scenes/builtin.h"

static const iris_stress_info SCENES[] = {
    {"stress-gap",
     "light enters the visible room only through a 6 cm slit: BSDF paths rarely find the slit "
     "and light samples from the visible room are almost all occluded, so bsdf and nee starve; "
     "guiding should find the slit",
     false},
    {"stress-veach-lights",
     "Veach's plates (GGX alpha 0.001 to 0.25) with lights from 3 cm to 1 m radius: BSDF "
     "sampling misses the small bright lights on the rough plates, light sampling wastes its "
     "samples on the near-mirror plates",
     false},
    {"stress-caustic",
     "a glass sphere on a diffuse floor under a small light: the caustic is reachable only by "
     "BSDF-sampled paths that hit the 10 cm light after two refractions, so every method is "
     "noisy and nee (which ignores emitters hit after a diffuse bounce) must still agree",
     false},
    {"stress-thin-walls",
     "a 2 mm partition, a zero-thickness shelf and a box in the corner: surfaces 2 mm apart "
     "with opposite normals, where caches or ray offsets on the wrong side leak light into "
     "the dark half",
     false},
    {"stress-small-dim",
     "small curved objects (2 to 6 cm spheres) in the dim half of a room behind a low wall: few "
     "photons and no cache near them, so guiding must fall back to the BSDF without bias",
     false},
    {"stress-closed-box",
     "a closed double-walled box with the camera inside and every light (area, point, sky) "
     "outside: the exact answer is black, so any light leak, NaN or photon from outside is a "
     "bug",
     true},
    {"stress-firefly",
     "one very bright 3 mm light (radiance 30000) over glossy surfaces: BSDF paths that hit it "
     "are rare and huge (fireflies), diffuse-glossy-light paths are invisible to light sampling",
     false},
    {"stress-glossy-room",
     "a room where every surface is GGX glossy (roughness 0.3): guiding distributions learnt "
     "for irradiance do not match the narrow lobes, so guided methods can lose to plain path "
     "tracing at equal time",
     false},
};
#define SCENE_COUNT (sizeof SCENES / sizeof SCENES[0])

const iris_stress_info *iris_stress_scenes(size_t *count) {
  *count = SCENE_COUNT;
  return SCENES;
}

const iris_stress_info *iris_stress_find(const char *name) {
  for (size_t i = 0; i < SCENE_COUNT; i++)
    if (strcmp(SCENES[i].name, name) == 0) return &SCENES[i];
  return NULL;
}

/* ---- building blocks ---------------------------------------------------- */

static int32_t add_material(iris_scene *s, const char *name, iris_material_type type, float r,
                            float g, float b, float roughness) {
  iris_material m = iris_material_default(type);
  m.name = iris_strdup(name);
  if (!m.name) return -1;
  m.color[0] = r;
  m.color[1] = g;
  m.color[2] = b;
  m.roughness = roughness;
  int32_t i = iris_scene_add_material(s, &m);
  if (i < 0) free(m.name);
  return i;
}

/* An emitter: black diffuse with radiance (r, g, b), one-sided unless told. */
static int32_t add_emitter(iris_scene *s, const char *name, float r, float g, float b,
                           bool two_sided) {
  int32_t i = add_material(s, name, IRIS_MATERIAL_DIFFUSE, 0, 0, 0, 0.5f);
  if (i < 0) return -1;
  s->materials[i].emission[0] = r;
  s->materials[i].emission[1] = g;
  s->materials[i].emission[2] = b;
  s->materials[i].emission_two_sided = two_sided;
  return i;
}

static bool add_camera(iris_scene *s, iris_vec3 eye, iris_vec3 target, float yfov_deg,
                       float aspect) {
  iris_camera cam;
  cam.name = iris_strdup("camera");
  if (!cam.name) return false;
  cam.to_world = iris_mat4_look_at(eye, target, iris_v3(0, 1, 0));
  cam.yfov = yfov_deg * (IRIS_PI / 180.0f);
  cam.aspect = aspect;
  if (iris_scene_add_camera(s, &cam) < 0) {
    free(cam.name);
    return false;
  }
  return true;
}

static iris_vec3 axis_vec(int axis, float len) {
  float v[3] = {0, 0, 0};
  v[axis] = len;
  return iris_v3_load(v);
}

/* The rectangle {p[axis] = at, p[u] in [u0, u1], p[v] in [v0, v1]} with
 * u = (axis + 1) % 3, v = (axis + 2) % 3, front face towards +axis when
 * facing > 0 and -axis otherwise, split into n x n quads. */
static bool rect(iris_scene *s, int axis, float at, float u0, float u1, float v0, float v1,
                 int facing, int n, int32_t mat, const char *name) {
  int u = (axis + 1) % 3, v = (axis + 2) % 3;
  float c[3];
  c[axis] = at;
  c[u] = 0.5f * (u0 + u1);
  c[v] = 0.5f * (v0 + v1);
  iris_vec3 a = axis_vec(u, 0.5f * (u1 - u0)), b = axis_vec(v, 0.5f * (v1 - v0));
  /* cross(e_u, e_v) = e_axis for the cyclic order */
  if (facing < 0) a = iris_neg(a);
  return iris_builtin_add_quad(s, iris_v3_load(c), a, b, n, mat, name) >= 0;
}

/* Axis-aligned box [lo, hi]: six rectangles, fronts outward (inward when
 * `inward`); bit k of `skip` leaves out face k (k = 2 * axis + (upper side)). */
static bool box(iris_scene *s, iris_vec3 lo3, iris_vec3 hi3, bool inward, unsigned skip, int n,
                int32_t mat, const char *name) {
  float lo[3], hi[3];
  iris_v3_store(lo3, lo);
  iris_v3_store(hi3, hi);
  for (int axis = 0; axis < 3; axis++) {
    int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int upper = 0; upper <= 1; upper++) {
      if (skip & (1u << (2 * axis + upper))) continue;
      int facing = upper ? 1 : -1;
      if (inward) facing = -facing;
      if (!rect(s, axis, upper ? hi[axis] : lo[axis], lo[u], hi[u], lo[v], hi[v], facing, n, mat,
                name))
        return false;
    }
  }
  return true;
}

#define FACE(axis, upper) (1u << (2 * (axis) + (upper)))

/* ---- the scenes ----------------------------------------------------------- */

/* Camera room x in [-2, 0], light room x in [0, 1]; y in [0, 2], z in [-1, 1].
 * The divider at x = 0 is open only in the slit y in [0.97, 1.03], z in
 * [-0.4, 0.4]; the light (0.3 m square, facing -x) hangs on the light room's
 * far wall in line with the slit, so the visible room gets a bright stripe on
 * its west wall and everything else by inter-reflection through the slit. */
static iris_status build_gap(iris_scene *s) {
  int32_t wall = add_material(s, "wall", IRIS_MATERIAL_DIFFUSE, 0.75f, 0.74f, 0.72f, 0.5f);
  int32_t floor_m = add_material(s, "floor", IRIS_MATERIAL_DIFFUSE, 0.6f, 0.5f, 0.4f, 0.5f);
  int32_t light = add_emitter(s, "light", 300.0f, 290.0f, 260.0f, false);
  if (wall < 0 || floor_m < 0 || light < 0) return IRIS_ERR_NOMEM;
  bool ok = box(s, iris_v3(-2, 0, -1), iris_v3(1, 2, 1), true, FACE(1, 0), 2, wall, "shell");
  ok = ok && rect(s, 1, 0.0f, -1, 1, -2, 1, 1, 2, floor_m, "floor"); /* axis y: u = z, v = x */
  ok = ok && rect(s, 0, 0.0f, 0.0f, 0.97f, -1, 1, -1, 1, wall, "divider_low");
  ok = ok && rect(s, 0, 0.0f, 1.03f, 2.0f, -1, 1, -1, 1, wall, "divider_high");
  ok = ok && rect(s, 0, 0.0f, 0.97f, 1.03f, -1, -0.4f, -1, 1, wall, "divider_left");
  ok = ok && rect(s, 0, 0.0f, 0.97f, 1.03f, 0.4f, 1, -1, 1, wall, "divider_right");
  ok = ok && rect(s, 0, 0.98f, 0.85f, 1.15f, -0.15f, 0.15f, -1, 1, light, "light");
  ok = ok && add_camera(s, iris_v3(-0.2f, 1.6f, 0.85f), iris_v3(-2.0f, 0.8f, -0.3f), 60.0f, 4.0f / 3.0f);
  if (!ok) return IRIS_ERR_NOMEM;
  s->render.width = 128;
  s->render.height = 96;
  return IRIS_OK;
}

/* Veach's plates (the plate edges of the built-in veach-mis scene, Veach 1997
 * fig. 9.2) with lights of radius 3 cm (radiance 1111) to 1 m at equal power
 * (radiance x radius^2 = 1) and plates from GGX alpha 0.001 (near mirror) to
 * 0.25 (wider than Veach's 0.005 to 0.1). The smallest light still covers a
 * third of a pixel at 120 x 80, so its direct view is not itself a rare event. */
static iris_status build_veach_lights(iris_scene *s) {
  static const float xs[4] = {-3.75f, -1.25f, 1.25f, 3.75f};
  static const float radii[4] = {0.03f, 0.1f, 0.3f, 1.0f};
  static const float alpha[4] = {0.001f, 0.01f, 0.05f, 0.25f};
  static const float edges[4][4] = {{-2.70651f, 0.25609f, -2.08375f, -0.526323f},
                                    {-3.28825f, 1.36972f, -2.83856f, 0.476536f},
                                    {-3.73096f, 2.70046f, -3.43378f, 1.74564f},
                                    {-3.99615f, 4.0667f, -3.82069f, 3.08221f}};
  int32_t diffuse = add_material(s, "diffuse", IRIS_MATERIAL_DIFFUSE, 0.4f, 0.4f, 0.4f, 0.5f);
  bool ok = diffuse >= 0;
  for (int i = 0; ok && i < 4; i++) {
    char name[32];
    snprintf(name, sizeof name, "light%d", i + 1);
    float L = 1.0f / (radii[i] * radii[i]);
    int32_t m = add_emitter(s, name, L, L, L, false);
    ok = m >= 0 && iris_builtin_add_sphere(s, iris_v3(xs[i], 0, 0), radii[i], 48, m, name) >= 0;
  }
  for (int i = 0; ok && i < 4; i++) {
    char name[32];
    snprintf(name, sizeof name, "plate%d", i + 1);
    int32_t m = add_material(s, name, IRIS_MATERIAL_GLOSSY, 0.3f, 0.3f, 0.3f, sqrtf(alpha[i]));
    if (m < 0) return IRIS_ERR_NOMEM;
    iris_vec3 e1 = iris_v3(0, edges[i][0], edges[i][1]), e2 = iris_v3(0, edges[i][2], edges[i][3]);
    iris_vec3 c = iris_scale(iris_add(e1, e2), 0.5f);
    iris_vec3 a = iris_v3(4, 0, 0), b = iris_scale(iris_sub(e1, e2), 0.5f);
    if (iris_cross(a, b).y < 0.0f) b = iris_neg(b);
    ok = iris_builtin_add_quad(s, c, a, b, 1, m, name) >= 0;
  }
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, -4.14615f, 0), iris_v3(0, 0, 10), iris_v3(10, 0, 0),
                                   1, diffuse, "floor") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 0, -2), iris_v3(10, 0, 0), iris_v3(0, 10, 0), 1,
                                   diffuse, "back") >= 0;
  ok = ok && add_camera(s, iris_v3(0, 2, 15), iris_v3(0, -2, 2.5f), 28.0f, 1.5f);
  if (!ok) return IRIS_ERR_NOMEM;
  s->render.width = 120;
  s->render.height = 80;
  return IRIS_OK;
}

/* A smooth glass sphere (radius 0.5, ior 1.5) resting on a diffuse floor with
 * a back wall, under a 10 cm square light 2.5 m above it (nothing else lit). */
static iris_status build_caustic(iris_scene *s) {
  int32_t floor_m = add_material(s, "floor", IRIS_MATERIAL_DIFFUSE, 0.8f, 0.8f, 0.8f, 0.5f);
  int32_t glass = add_material(s, "glass", IRIS_MATERIAL_GLASS, 1, 1, 1, 0.0f);
  int32_t light = add_emitter(s, "light", 600.0f, 580.0f, 520.0f, false);
  if (floor_m < 0 || glass < 0 || light < 0) return IRIS_ERR_NOMEM;
  s->materials[glass].ior = 1.5f;
  bool ok = rect(s, 1, 0.0f, -2, 2, -2, 2, 1, 1, floor_m, "floor");
  ok = ok && rect(s, 2, -2.0f, -2, 2, 0, 3, 1, 1, floor_m, "back"); /* axis z: u = x, v = y */
  ok = ok && iris_builtin_add_sphere(s, iris_v3(0, 0.5f, 0), 0.5f, 64, glass, "sphere") >= 0;
  ok = ok && rect(s, 1, 2.5f, -0.05f, 0.05f, -0.05f, 0.05f, -1, 1, light, "light");
  ok = ok && add_camera(s, iris_v3(0, 2.2f, 3.2f), iris_v3(0, 0.3f, 0), 40.0f, 4.0f / 3.0f);
  if (!ok) return IRIS_ERR_NOMEM;
  s->render.width = 128;
  s->render.height = 96;
  return IRIS_OK;
}

/* A room x in [-1, 1], y in [0, 2], z in [-1, 1], open at the front (+z). A
 * 2 mm partition at x = 0 runs from the back wall to z = 0.3, floor to
 * ceiling; the light is on the ceiling of the left half only. In the left
 * half a zero-thickness shelf at y = 1 (lit above, dark below); in the right
 * half's back corner a box touching both walls. */
static iris_status build_thin_walls(iris_scene *s) {
  int32_t wall = add_material(s, "wall", IRIS_MATERIAL_DIFFUSE, 0.75f, 0.75f, 0.75f, 0.5f);
  int32_t red = add_material(s, "red", IRIS_MATERIAL_DIFFUSE, 0.65f, 0.1f, 0.08f, 0.5f);
  int32_t shelf = add_material(s, "shelf", IRIS_MATERIAL_DIFFUSE, 0.3f, 0.5f, 0.7f, 0.5f);
  int32_t light = add_emitter(s, "light", 12.0f, 11.0f, 10.0f, false);
  if (wall < 0 || red < 0 || shelf < 0 || light < 0) return IRIS_ERR_NOMEM;
  bool ok = box(s, iris_v3(-1, 0, -1), iris_v3(1, 2, 1), true, FACE(2, 1), 2, wall, "room");
  ok = ok && box(s, iris_v3(-0.001f, 0, -1), iris_v3(0.001f, 2, 0.3f), false, 0, 1, red, "partition");
  ok = ok && rect(s, 1, 1.0f, -1, -0.2f, -1, -0.001f, 1, 1, shelf, "shelf"); /* u = z, v = x */
  ok = ok && box(s, iris_v3(0.6f, 0, -1), iris_v3(1, 0.4f, -0.6f), false, 0, 1, wall, "corner_box");
  ok = ok && rect(s, 1, 1.99f, -0.6f, -0.2f, -0.8f, -0.2f, -1, 1, light, "light");
  ok = ok && add_camera(s, iris_v3(0.5f, 1.1f, 3.4f), iris_v3(-0.1f, 0.9f, 0), 40.0f, 4.0f / 3.0f);
  if (!ok) return IRIS_ERR_NOMEM;
  s->render.width = 128;
  s->render.height = 96;
  return IRIS_OK;
}

/* A long closed room x in [-3, 3], y in [0, 2], z in [-1, 1]; the light is
 * under the ceiling at the east end, a wall 1.4 m high at x = 0 keeps direct
 * light off the west floor, where seven small spheres (2 to 6 cm, diffuse and
 * glossy) lie, some under a low table top. */
static iris_status build_small_dim(iris_scene *s) {
  int32_t wall = add_material(s, "wall", IRIS_MATERIAL_DIFFUSE, 0.7f, 0.7f, 0.7f, 0.5f);
  int32_t table = add_material(s, "table", IRIS_MATERIAL_DIFFUSE, 0.5f, 0.35f, 0.2f, 0.5f);
  int32_t diffuse = add_material(s, "ball", IRIS_MATERIAL_DIFFUSE, 0.8f, 0.3f, 0.2f, 0.5f);
  int32_t glossy = add_material(s, "glossy_ball", IRIS_MATERIAL_GLOSSY, 0.9f, 0.9f, 0.9f, 0.25f);
  int32_t light = add_emitter(s, "light", 40.0f, 38.0f, 34.0f, false);
  if (wall < 0 || table < 0 || diffuse < 0 || glossy < 0 || light < 0) return IRIS_ERR_NOMEM;
  bool ok = box(s, iris_v3(-3, 0, -1), iris_v3(3, 2, 1), true, 0, 2, wall, "room");
  ok = ok && rect(s, 0, 0.0f, 0.0f, 1.4f, -1, 1, -1, 1, wall, "low_wall");
  ok = ok && rect(s, 1, 0.3f, -0.9f, -0.3f, -2.9f, -2.1f, 1, 1, table, "table_top");
  ok = ok && rect(s, 1, 1.99f, -0.3f, 0.3f, 2.3f, 2.9f, -1, 1, light, "light");
  static const float balls[7][4] = {{-2.5f, 0.02f, -0.5f, 0.02f}, {-2.3f, 0.04f, -0.7f, 0.04f},
                                    {-2.7f, 0.06f, -0.4f, 0.06f}, {-2.0f, 0.03f, -0.2f, 0.03f},
                                    {-1.6f, 0.05f, 0.3f, 0.05f},  {-2.8f, 0.025f, 0.2f, 0.025f},
                                    {-1.2f, 0.04f, -0.8f, 0.04f}};
  for (int i = 0; ok && i < 7; i++) {
    char name[16];
    snprintf(name, sizeof name, "ball%d", i + 1);
    ok = iris_builtin_add_sphere(s, iris_v3(balls[i][0], balls[i][1], balls[i][2]), balls[i][3], 24,
                                 i % 2 ? glossy : diffuse, name) >= 0;
  }
  ok = ok && add_camera(s, iris_v3(-0.4f, 0.7f, 0.8f), iris_v3(-2.4f, 0.1f, -0.4f), 35.0f, 4.0f / 3.0f);
  if (!ok) return IRIS_ERR_NOMEM;
  s->render.width = 128;
  s->render.height = 96;
  return IRIS_OK;
}

/* The camera inside a closed box [-1, 1]^3 (fronts inward) nested in a box
 * [-1.1, 1.1]^3 (fronts outward): walls 10 cm thick with no gaps. Outside: a
 * 1 m square light above, a point light, a uniform sky. Inside: a diffuse
 * sphere on a glossy floor panel. Every pixel must be exactly 0. */
static iris_status build_closed_box(iris_scene *s) {
  int32_t wall = add_material(s, "wall", IRIS_MATERIAL_DIFFUSE, 0.8f, 0.8f, 0.8f, 0.5f);
  int32_t glossy = add_material(s, "glossy", IRIS_MATERIAL_GLOSSY, 0.8f, 0.8f, 0.8f, 0.2f);
  int32_t light = add_emitter(s, "light", 50.0f, 50.0f, 50.0f, false);
  if (wall < 0 || glossy < 0 || light < 0) return IRIS_ERR_NOMEM;
  bool ok = box(s, iris_v3(-1, -1, -1), iris_v3(1, 1, 1), true, 0, 2, wall, "inner");
  ok = ok && box(s, iris_v3(-1.1f, -1.1f, -1.1f), iris_v3(1.1f, 1.1f, 1.1f), false, 0, 2, wall, "outer");
  ok = ok && rect(s, 1, -0.99f, -0.8f, 0.8f, -0.8f, 0.8f, 1, 1, glossy, "panel");
  ok = ok && iris_builtin_add_sphere(s, iris_v3(0.2f, -0.6f, -0.3f), 0.3f, 32, wall, "sphere") >= 0;
  ok = ok && rect(s, 1, 1.5f, -0.5f, 0.5f, -0.5f, 0.5f, -1, 1, light, "light");
  iris_light pl;
  memset(&pl, 0, sizeof pl);
  pl.name = iris_strdup("point");
  pl.type = IRIS_LIGHT_POINT;
  pl.color[0] = pl.color[1] = pl.color[2] = 1.0f;
  pl.intensity = 100.0f;
  pl.position[0] = 2.0f;
  ok = ok && pl.name && iris_scene_add_light(s, &pl) >= 0;
  s->has_environment = true;
  s->environment[0] = s->environment[1] = s->environment[2] = 1.0f;
  ok = ok && add_camera(s, iris_v3(0, 0, 0.8f), iris_v3(0, -0.3f, -1), 70.0f, 4.0f / 3.0f);
  if (!ok) return IRIS_ERR_NOMEM;
  s->render.width = 128;
  s->render.height = 96;
  return IRIS_OK;
}

/* A room x in [-1, 1], y in [0, 2], z in [-1, 1], open at the front, lit only
 * by a sphere of radius 3 mm and radiance 30000 (power ~10.7 W per channel,
 * about the Cornell box's light); a glossy floor and a glossy sphere make
 * diffuse-glossy-light paths. */
static iris_status build_firefly(iris_scene *s) {
  int32_t wall = add_material(s, "wall", IRIS_MATERIAL_DIFFUSE, 0.7f, 0.7f, 0.7f, 0.5f);
  int32_t floor_m = add_material(s, "floor", IRIS_MATERIAL_GLOSSY, 0.6f, 0.6f, 0.6f, 0.2f);
  int32_t ball = add_material(s, "ball", IRIS_MATERIAL_GLOSSY, 0.9f, 0.7f, 0.4f, 0.1f);
  int32_t light = add_emitter(s, "light", 30000.0f, 30000.0f, 30000.0f, false);
  if (wall < 0 || floor_m < 0 || ball < 0 || light < 0) return IRIS_ERR_NOMEM;
  bool ok = box(s, iris_v3(-1, 0, -1), iris_v3(1, 2, 1), true, FACE(2, 1) | FACE(1, 0), 2, wall, "room");
  ok = ok && rect(s, 1, 0.0f, -1, 1, -1, 1, 1, 1, floor_m, "floor");
  ok = ok && iris_builtin_add_sphere(s, iris_v3(-0.3f, 0.35f, -0.2f), 0.35f, 48, ball, "ball") >= 0;
  ok = ok && iris_builtin_add_sphere(s, iris_v3(0.3f, 1.6f, 0.0f), 0.003f, 16, light, "light") >= 0;
  ok = ok && add_camera(s, iris_v3(0, 1.0f, 3.4f), iris_v3(0, 0.9f, 0), 40.0f, 4.0f / 3.0f);
  if (!ok) return IRIS_ERR_NOMEM;
  s->render.width = 128;
  s->render.height = 96;
  return IRIS_OK;
}

/* A room x in [-1.5, 1.5], y in [0, 2.5], z in [-1.5, 1.5], open at the
 * front; every surface GGX glossy (walls roughness 0.3, spheres 0.15) under a
 * 0.6 m square ceiling light. */
static iris_status build_glossy_room(iris_scene *s) {
  int32_t walls = add_material(s, "walls", IRIS_MATERIAL_GLOSSY, 0.8f, 0.8f, 0.75f, 0.3f);
  int32_t left = add_material(s, "left", IRIS_MATERIAL_GLOSSY, 0.8f, 0.3f, 0.25f, 0.3f);
  int32_t right = add_material(s, "right", IRIS_MATERIAL_GLOSSY, 0.25f, 0.6f, 0.3f, 0.3f);
  int32_t ball = add_material(s, "ball", IRIS_MATERIAL_GLOSSY, 0.9f, 0.9f, 0.9f, 0.15f);
  int32_t light = add_emitter(s, "light", 20.0f, 19.0f, 17.0f, false);
  if (walls < 0 || left < 0 || right < 0 || ball < 0 || light < 0) return IRIS_ERR_NOMEM;
  bool ok = box(s, iris_v3(-1.5f, 0, -1.5f), iris_v3(1.5f, 2.5f, 1.5f), true,
                FACE(2, 1) | FACE(0, 0) | FACE(0, 1), 2, walls, "room");
  ok = ok && rect(s, 0, -1.5f, 0, 2.5f, -1.5f, 1.5f, 1, 2, left, "left");
  ok = ok && rect(s, 0, 1.5f, 0, 2.5f, -1.5f, 1.5f, -1, 2, right, "right");
  ok = ok && iris_builtin_add_sphere(s, iris_v3(-0.6f, 0.5f, -0.4f), 0.5f, 48, ball, "ball1") >= 0;
  ok = ok && iris_builtin_add_sphere(s, iris_v3(0.7f, 0.35f, 0.2f), 0.35f, 48, ball, "ball2") >= 0;
  ok = ok && rect(s, 1, 2.49f, -0.3f, 0.3f, -0.3f, 0.3f, -1, 1, light, "light");
  ok = ok && add_camera(s, iris_v3(0, 1.25f, 5.0f), iris_v3(0, 1.1f, 0), 40.0f, 4.0f / 3.0f);
  if (!ok) return IRIS_ERR_NOMEM;
  s->render.width = 128;
  s->render.height = 96;
  return IRIS_OK;
}

iris_status iris_stress_build(const char *name, iris_scene *scene) {
  if (strcmp(name, "stress-gap") == 0) return build_gap(scene);
  if (strcmp(name, "stress-veach-lights") == 0) return build_veach_lights(scene);
  if (strcmp(name, "stress-caustic") == 0) return build_caustic(scene);
  if (strcmp(name, "stress-thin-walls") == 0) return build_thin_walls(scene);
  if (strcmp(name, "stress-small-dim") == 0) return build_small_dim(scene);
  if (strcmp(name, "stress-closed-box") == 0) return build_closed_box(scene);
  if (strcmp(name, "stress-firefly") == 0) return build_firefly(scene);
  if (strcmp(name, "stress-glossy-room") == 0) return build_glossy_room(scene);
  return IRIS_ERR_USAGE;
}

iris_status iris_stress_create(const char *name, iris_scene **out, iris_error *err) {
  *out = NULL;
  if (!iris_stress_find(name))
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "unknown stress scene '%s'", name);
  iris_scene *s = iris_scene_create();
  if (!s) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory");
  char src[64];
  snprintf(src, sizeof src, "builtin:%s", name);
  iris_status st = iris_stress_build(name, s);
  if (st != IRIS_OK) {
    iris_scene_destroy(s);
    return iris_error_set(err, st, NULL, 0, NULL, "cannot build the stress scene '%s'", name);
  }
  s->source_path = iris_strdup(src);
  st = iris_scene_validate(s, src, err);
  if (st != IRIS_OK) {
    iris_scene_destroy(s);
    return st;
  }
  *out = s;
  return IRIS_OK;
}
