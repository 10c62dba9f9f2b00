/* Sky-lit built-in scenes; see sky.h and docs/rendering.md. */
#include "scenes/sky.h"

#include <stdlib.h>
#include <string.h>

#include "scenes/builtin.h"

#ifndef IRIS_SKY_MAP
#define IRIS_SKY_MAP "../shared/assets/env/immenstadter_horn_1k.hdr"
#endif

const char *iris_sky_map_path(void) { return IRIS_SKY_MAP; }

static int32_t material(iris_scene *s, const char *name, iris_material_type type, float r, float g,
                        float b, float roughness) {
  iris_material m = iris_material_default(type);
  m.name = iris_strdup(name);
  m.color[0] = r, m.color[1] = g, m.color[2] = b;
  m.roughness = roughness;
  int32_t i = iris_scene_add_material(s, &m);
  if (i < 0) free(m.name);
  return i;
}

static bool camera(iris_scene *s, iris_vec3 eye, iris_vec3 target, float yfov_deg, float aspect) {
  iris_camera cam;
  cam.name = iris_strdup("camera");
  cam.to_world = iris_mat4_look_at(eye, target, iris_v3(0, 1, 0));
  cam.yfov = yfov_deg * (IRIS_PI / 180.0f);
  cam.aspect = aspect;
  if (iris_scene_add_camera(s, &cam) < 0) {
    free(cam.name);
    return false;
  }
  return true;
}

iris_status iris_sky_objects_build(iris_scene *s) {
  int32_t ground = material(s, "ground", IRIS_MATERIAL_DIFFUSE, 0.5f, 0.5f, 0.5f, 0.0f);
  int32_t matte = material(s, "matte", IRIS_MATERIAL_DIFFUSE, 0.8f, 0.6f, 0.4f, 0.0f);
  int32_t gloss = material(s, "glossy", IRIS_MATERIAL_GLOSSY, 0.9f, 0.9f, 0.9f, 0.3f);
  if (ground < 0 || matte < 0 || gloss < 0) return IRIS_ERR_NOMEM;
  bool ok = iris_builtin_add_quad(s, iris_v3(0, 0, 0), iris_v3(0, 0, 6), iris_v3(6, 0, 0), 1, ground, "ground") >= 0;
  ok = ok && iris_builtin_add_sphere(s, iris_v3(-1.1f, 1, 0), 1.0f, 64, matte, "matte") >= 0;
  ok = ok && iris_builtin_add_sphere(s, iris_v3(1.1f, 1, 0), 1.0f, 64, gloss, "glossy") >= 0;
  ok = ok && camera(s, iris_v3(0, 2.5f, 7), iris_v3(0, 0.8f, 0), 35.0f, 1.5f);
  ok = ok && iris_scene_set_environment_map(s, IRIS_SKY_MAP, 1.0f, 0.0f);
  if (!ok) return IRIS_ERR_NOMEM;
  s->render.width = 384;
  s->render.height = 256;
  return IRIS_OK;
}

/* Four spheres on a wide ground under the open sky, the camera seeing the
 * horizon and the sky above it: a diffuse one and three metals (glossy) of
 * rising roughness 0.05, 0.2 and 0.5, lit from the front right by the map's
 * sun (the environment benchmark of docs/benchmarks.md: sun, sharp and rough
 * metal, diffuse, sky seen directly). */
iris_status iris_sky_spheres_build(iris_scene *s) {
  int32_t ground = material(s, "ground", IRIS_MATERIAL_DIFFUSE, 0.5f, 0.5f, 0.5f, 0.0f);
  int32_t matte = material(s, "matte", IRIS_MATERIAL_DIFFUSE, 0.8f, 0.8f, 0.8f, 0.0f);
  int32_t m1 = material(s, "metal-0.05", IRIS_MATERIAL_GLOSSY, 0.95f, 0.9f, 0.8f, 0.05f);
  int32_t m2 = material(s, "metal-0.2", IRIS_MATERIAL_GLOSSY, 0.95f, 0.9f, 0.8f, 0.2f);
  int32_t m3 = material(s, "metal-0.5", IRIS_MATERIAL_GLOSSY, 0.95f, 0.9f, 0.8f, 0.5f);
  if (ground < 0 || matte < 0 || m1 < 0 || m2 < 0 || m3 < 0) return IRIS_ERR_NOMEM;
  bool ok = iris_builtin_add_quad(s, iris_v3(0, 0, 0), iris_v3(0, 0, 10), iris_v3(10, 0, 0), 1, ground, "ground") >= 0;
  ok = ok && iris_builtin_add_sphere(s, iris_v3(-2.1f, 0.6f, 0), 0.6f, 64, matte, "matte") >= 0;
  ok = ok && iris_builtin_add_sphere(s, iris_v3(-0.7f, 0.6f, 0), 0.6f, 64, m1, "metal-0.05") >= 0;
  ok = ok && iris_builtin_add_sphere(s, iris_v3(0.7f, 0.6f, 0), 0.6f, 64, m2, "metal-0.2") >= 0;
  ok = ok && iris_builtin_add_sphere(s, iris_v3(2.1f, 0.6f, 0), 0.6f, 64, m3, "metal-0.5") >= 0;
  ok = ok && camera(s, iris_v3(0, 1.4f, 6.5f), iris_v3(0, 0.7f, 0), 35.0f, 1.5f);
  ok = ok && iris_scene_set_environment_map(s, IRIS_SKY_MAP, 1.0f, 0.0f);
  if (!ok) return IRIS_ERR_NOMEM;
  s->render.width = 384;
  s->render.height = 256;
  return IRIS_OK;
}

/* A 4 x 2.5 x 4 m room; the window (1.2 x 1 m) in the +x wall faces the
 * map's sun (direction (0.66, 0.58, 0.48) at rotation 0), which falls through
 * it onto the floor; the camera in a corner by the window looks into the room
 * and does not see the sky. */
static iris_status sky_room(iris_scene *s, bool corner);

iris_status iris_sky_room_build(iris_scene *s) { return sky_room(s, false); }

/* sky-room with a second 1 x 1 m window, in the +z wall (x in [-0.5, 0.5],
 * y in [1, 2]), which the sun also shines through: connections with the sky
 * through two windows (docs/guiding.md). */
iris_status iris_sky_room_corner_build(iris_scene *s) { return sky_room(s, true); }

static iris_status sky_room(iris_scene *s, bool corner) {
  int32_t wall = material(s, "wall", IRIS_MATERIAL_DIFFUSE, 0.75f, 0.75f, 0.72f, 0.0f);
  int32_t floor_m = material(s, "floor", IRIS_MATERIAL_DIFFUSE, 0.6f, 0.45f, 0.3f, 0.0f);
  int32_t gloss = material(s, "glossy", IRIS_MATERIAL_GLOSSY, 0.8f, 0.8f, 0.8f, 0.25f);
  int32_t box_m = material(s, "box", IRIS_MATERIAL_DIFFUSE, 0.3f, 0.5f, 0.7f, 0.0f);
  if (wall < 0 || floor_m < 0 || gloss < 0 || box_m < 0) return IRIS_ERR_NOMEM;
  const float X = 2.0f, Y = 2.5f, Z = 2.0f;
  bool ok = true;
  /* floor, ceiling, -x, +z, -z walls (front faces inward) */
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 0, 0), iris_v3(0, 0, Z), iris_v3(X, 0, 0), 4, floor_m, "floor") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, Y, 0), iris_v3(X, 0, 0), iris_v3(0, 0, Z), 4, wall, "ceiling") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(-X, Y / 2, 0), iris_v3(0, Y / 2, 0), iris_v3(0, 0, Z), 4, wall, "back") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, Y / 2, -Z), iris_v3(X, 0, 0), iris_v3(0, Y / 2, 0), 4, wall, "left") >= 0;
  if (!corner) {
    ok = ok && iris_builtin_add_quad(s, iris_v3(0, Y / 2, Z), iris_v3(0, Y / 2, 0), iris_v3(X, 0, 0), 4, wall, "right") >= 0;
  } else { /* around the +z window x in [-0.5, 0.5], y in [1, 2] */
    ok = ok && iris_builtin_add_quad(s, iris_v3(0, 0.5f, Z), iris_v3(0, 0.5f, 0), iris_v3(X, 0, 0), 2, wall, "right-below") >= 0;
    ok = ok && iris_builtin_add_quad(s, iris_v3(0, (2.0f + Y) / 2, Z), iris_v3(0, (Y - 2.0f) / 2, 0), iris_v3(X, 0, 0), 2,
                                     wall, "right-above") >= 0;
    ok = ok && iris_builtin_add_quad(s, iris_v3(-1.25f, 1.5f, Z), iris_v3(0, 0.5f, 0), iris_v3(0.75f, 0, 0), 2, wall,
                                     "right-left") >= 0;
    ok = ok && iris_builtin_add_quad(s, iris_v3(1.25f, 1.5f, Z), iris_v3(0, 0.5f, 0), iris_v3(0.75f, 0, 0), 2, wall,
                                     "right-right") >= 0;
  }
  /* the +x wall around the window y in [1, 2], z in [-0.6, 0.6] */
  const float y0 = 1.0f, y1 = 2.0f, z0 = -0.6f, z1 = 0.6f;
  ok = ok && iris_builtin_add_quad(s, iris_v3(X, y0 / 2, 0), iris_v3(0, 0, Z), iris_v3(0, y0 / 2, 0), 2, wall, "window-below") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(X, (y1 + Y) / 2, 0), iris_v3(0, 0, Z), iris_v3(0, (Y - y1) / 2, 0), 2, wall, "window-above") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(X, (y0 + y1) / 2, (z0 - Z) / 2), iris_v3(0, 0, (Z + z0) / 2),
                                   iris_v3(0, (y1 - y0) / 2, 0), 2, wall, "window-left") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(X, (y0 + y1) / 2, (z1 + Z) / 2), iris_v3(0, 0, (Z - z1) / 2),
                                   iris_v3(0, (y1 - y0) / 2, 0), 2, wall, "window-right") >= 0;
  /* a glossy sphere and a box */
  ok = ok && iris_builtin_add_sphere(s, iris_v3(-0.8f, 0.5f, -0.9f), 0.5f, 48, gloss, "sphere") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(-0.6f, 0.6f, 1.0f), iris_v3(0.4f, 0, 0), iris_v3(0, 0, 0.4f), 1, box_m, "box-top") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(-0.6f, 0.3f, 1.4f), iris_v3(0.4f, 0, 0), iris_v3(0, 0.3f, 0), 1, box_m, "box-front") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(-0.6f, 0.3f, 0.6f), iris_v3(0, 0.3f, 0), iris_v3(0.4f, 0, 0), 1, box_m, "box-back") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(-0.2f, 0.3f, 1.0f), iris_v3(0, 0.3f, 0), iris_v3(0, 0, 0.4f), 1, box_m, "box-side") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(-1.0f, 0.3f, 1.0f), iris_v3(0, 0, 0.4f), iris_v3(0, 0.3f, 0), 1, box_m, "box-side2") >= 0;
  ok = ok && camera(s, iris_v3(1.8f, 1.4f, 1.8f), iris_v3(-1.0f, 0.6f, -1.0f), 60.0f, 1.5f);
  ok = ok && iris_scene_set_environment_map(s, IRIS_SKY_MAP, 1.0f, 0.0f);
  if (!ok) return IRIS_ERR_NOMEM;
  s->render.width = 384;
  s->render.height = 256;
  return IRIS_OK;
}
