/* Scenes of light through glass; see glazing.h. */
#include "scenes/glazing.h"

#include <stdlib.h>

#include "scenes/builtin.h"
#include "scenes/sky.h"

static int32_t glass(iris_scene *s, const char *name, float r, float g, float b) {
  iris_material m = iris_material_default(IRIS_MATERIAL_GLASS);
  m.name = iris_strdup(name);
  m.color[0] = r, m.color[1] = g, m.color[2] = b;
  m.roughness = 0.0f;
  m.ior = 1.5f;
  int32_t i = iris_scene_add_material(s, &m);
  if (i < 0) free(m.name);
  return i;
}

/* A closed box of half extents h around c, every face's front outward. */
static bool slab(iris_scene *s, iris_vec3 c, iris_vec3 h, int32_t mat, const char *name) {
  const iris_vec3 X = iris_v3(h.x, 0, 0), Y = iris_v3(0, h.y, 0), Z = iris_v3(0, 0, h.z);
  bool ok = iris_builtin_add_quad(s, iris_add(c, X), Y, Z, 1, mat, name) >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_sub(c, X), Z, Y, 1, mat, name) >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_add(c, Y), Z, X, 1, mat, name) >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_sub(c, Y), X, Z, 1, mat, name) >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_add(c, Z), X, Y, 1, mat, name) >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_sub(c, Z), Y, X, 1, mat, name) >= 0;
  return ok;
}

/* The sky-room's window is y in [1, 2], z in [-0.6, 0.6] of the wall x = 2. */
iris_status iris_sky_room_glazed_build(iris_scene *s) {
  iris_status st = iris_sky_room_build(s);
  if (st != IRIS_OK) return st;
  int32_t g = glass(s, "window-glass", 1.0f, 1.0f, 1.0f);
  if (g < 0 || !slab(s, iris_v3(2.0f, 1.5f, 0.0f), iris_v3(0.01f, 0.5f, 0.6f), g, "pane")) return IRIS_ERR_NOMEM;
  return IRIS_OK;
}

iris_status iris_sky_room_pane_build(iris_scene *s) {
  iris_status st = iris_sky_room_build(s);
  if (st != IRIS_OK) return st;
  int32_t g = glass(s, "window-glass", 1.0f, 1.0f, 1.0f);
  /* one quad, front towards the sky (+x) */
  if (g < 0 || iris_builtin_add_quad(s, iris_v3(2.0f, 1.5f, 0.0f), iris_v3(0, 0.5f, 0), iris_v3(0, 0, 0.6f), 1, g,
                                     "pane") < 0)
    return IRIS_ERR_NOMEM;
  return IRIS_OK;
}

static int32_t diffuse(iris_scene *s, const char *name, float r, float g, float b) {
  iris_material m = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  m.name = iris_strdup(name);
  m.color[0] = r, m.color[1] = g, m.color[2] = b;
  int32_t i = iris_scene_add_material(s, &m);
  if (i < 0) free(m.name);
  return i;
}

/* A 4 x 3 x 4 m room; a bulb (a 4 cm sphere) inside a 40 x 40 x 40 cm shade
 * of 1 cm amber glass slabs, open below, hanging 1.4-1.8 m up; the floor
 * below the opening is the only surface light sampling reaches. */
iris_status iris_lamp_shade_build(iris_scene *s) {
  int32_t wall = diffuse(s, "wall", 0.75f, 0.75f, 0.72f), floor_m = diffuse(s, "floor", 0.6f, 0.45f, 0.3f);
  int32_t shade = glass(s, "shade-glass", 0.95f, 0.8f, 0.5f), bulb = diffuse(s, "bulb", 0, 0, 0);
  if (wall < 0 || floor_m < 0 || shade < 0 || bulb < 0) return IRIS_ERR_NOMEM;
  s->materials[bulb].emission[0] = 2000.0f;
  s->materials[bulb].emission[1] = 1800.0f;
  s->materials[bulb].emission[2] = 1500.0f;
  const float X = 2.0f, Y = 3.0f, Z = 2.0f;
  bool ok = iris_builtin_add_quad(s, iris_v3(0, 0, 0), iris_v3(0, 0, Z), iris_v3(X, 0, 0), 4, floor_m, "floor") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, Y, 0), iris_v3(X, 0, 0), iris_v3(0, 0, Z), 4, wall, "ceiling") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(-X, Y / 2, 0), iris_v3(0, Y / 2, 0), iris_v3(0, 0, Z), 4, wall, "back") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(X, Y / 2, 0), iris_v3(0, 0, Z), iris_v3(0, Y / 2, 0), 4, wall, "front") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, Y / 2, -Z), iris_v3(X, 0, 0), iris_v3(0, Y / 2, 0), 4, wall, "left") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, Y / 2, Z), iris_v3(0, Y / 2, 0), iris_v3(X, 0, 0), 4, wall, "right") >= 0;
  /* the shade: top and four sides, 1 cm glass */
  const float h = 0.2f, t = 0.005f, yc = 1.6f;
  ok = ok && slab(s, iris_v3(0, yc + h - t, 0), iris_v3(h, t, h), shade, "shade-top");
  ok = ok && slab(s, iris_v3(h - t, yc - t, 0), iris_v3(t, h - t, h - 2 * t), shade, "shade-px");
  ok = ok && slab(s, iris_v3(-h + t, yc - t, 0), iris_v3(t, h - t, h - 2 * t), shade, "shade-nx");
  ok = ok && slab(s, iris_v3(0, yc - t, h - t), iris_v3(h, h - t, t), shade, "shade-pz");
  ok = ok && slab(s, iris_v3(0, yc - t, -h + t), iris_v3(h, h - t, t), shade, "shade-nz");
  ok = ok && iris_builtin_add_sphere(s, iris_v3(0, yc + 0.05f, 0), 0.04f, 24, bulb, "bulb") >= 0;
  iris_camera cam;
  cam.name = iris_strdup("camera");
  cam.to_world = iris_mat4_look_at(iris_v3(1.8f, 1.3f, 1.8f), iris_v3(-1.0f, 1.2f, -1.0f), iris_v3(0, 1, 0));
  cam.yfov = 65.0f * (IRIS_PI / 180.0f);
  cam.aspect = 1.5f;
  ok = ok && cam.name && iris_scene_add_camera(s, &cam) >= 0;
  if (!ok) return IRIS_ERR_NOMEM;
  s->render.width = 384;
  s->render.height = 256;
  return IRIS_OK;
}
