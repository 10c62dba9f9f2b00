/* Rooms along a corridor (scenes/rooms.h). Units: metres; y is up, the floor
 * is y = 0, the corridor x in [-16, 16], z in [-1, 1], rooms out to z = +-5. */
#include "scenes/rooms.h"

#include <stdio.h>

#include "scenes/builtin.h"

/* The lamps' warm white. */
static const float TINT[3] = {1.0f, 0.93f, 0.8f};

static int32_t add_material(iris_scene *s, const char *name, float r, float g, float b, float emission) {
  return iris_builtin_add_diffuse(s, name, r, g, b, emission, TINT);
}

#define ROOMS 8         /* per side */
#define ROOM 4.0f       /* room width along the corridor (and depth) */
#define HALF_LEN 16.0f  /* half the corridor's length */
#define DOOR_HALF 0.7f
#define DOOR_TOP 2.2f
#define H 3.0f

/* A wall piece in the plane z = at from x0 to x1, y0 to y1 (or x = at with
 * z0..z1 when along_z). */
static bool wall_piece(iris_scene *s, bool along_z, float at, float a0, float a1, float y0, float y1, int32_t m) {
  float mid = 0.5f * (a0 + a1), ha = 0.5f * (a1 - a0), hy = 0.5f * (y1 - y0);
  if (!(ha > 0.0f)) return true;
  if (along_z)
    return iris_builtin_add_quad(s, iris_v3(at, y0 + hy, mid), iris_v3(0, hy, 0), iris_v3(0, 0, ha), 1, m, "wall_x") >= 0;
  return iris_builtin_add_quad(s, iris_v3(mid, y0 + hy, at), iris_v3(ha, 0, 0), iris_v3(0, hy, 0), 1, m, "wall_z") >= 0;
}

iris_status iris_rooms_scene_build(iris_scene *s) {
  int32_t wall = add_material(s, "wall", 0.7f, 0.7f, 0.68f, 0.0f);
  int32_t floor = add_material(s, "floor", 0.45f, 0.4f, 0.35f, 0.0f);
  int32_t corridor_lamp = add_material(s, "corridor_lamp", 0.8f, 0.8f, 0.8f, 1.5f);
  int32_t lamp[4];
  if (!iris_builtin_add_lamps(s, 3.0f, TINT, lamp)) return IRIS_ERR_NOMEM;
  if (wall < 0 || floor < 0 || corridor_lamp < 0) return IRIS_ERR_NOMEM;
  const float D = 1.0f + ROOM; /* the rooms' far walls */
  bool ok = true;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 0, 0), iris_v3(0, 0, D), iris_v3(HALF_LEN, 0, 0), 8, floor, "floor") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, H, 0), iris_v3(HALF_LEN, 0, 0), iris_v3(0, 0, D), 8, wall, "ceiling") >= 0;
  for (int side = -1; side <= 1 && ok; side += 2) {
    ok = wall_piece(s, false, (float)side * D, -HALF_LEN, HALF_LEN, 0, H, wall);            /* far walls */
    ok = ok && wall_piece(s, true, (float)side * HALF_LEN, -D, D, 0, H, wall);               /* the ends */
    for (int r = 0; r < ROOMS && ok; r++) {
      float x0 = -HALF_LEN + ROOM * (float)r, xc = x0 + 0.5f * ROOM;
      /* the corridor wall with its doorway */
      ok = wall_piece(s, false, (float)side, x0, xc - DOOR_HALF, 0, H, wall) &&
           wall_piece(s, false, (float)side, xc + DOOR_HALF, x0 + ROOM, 0, H, wall) &&
           wall_piece(s, false, (float)side, xc - DOOR_HALF, xc + DOOR_HALF, DOOR_TOP, H, wall);
      /* the wall to the next room */
      if (r > 0) ok = ok && wall_piece(s, true, x0, side < 0 ? -D : 1.0f, side < 0 ? -1.0f : D, 0, H, wall);
      /* 2 x 2 lamps facing down (cross(a, b) = -y) */
      for (int i = 0; i < 2 && ok; i++)
        for (int j = 0; j < 2 && ok; j++) {
          float x = xc + (i ? 1.0f : -1.0f), z = (float)side * (1.0f + 0.5f * ROOM + (j ? 1.0f : -1.0f));
          unsigned h = (unsigned)(r * 5 + i * 3 + j * 7 + (side > 0) * 11);
          char name[40];
          snprintf(name, sizeof name, "lamp_%d_%d_%d%d", side, r, i, j);
          ok = iris_builtin_add_quad(s, iris_v3(x, H - 0.01f, z), iris_v3(0.2f, 0, 0), iris_v3(0, 0, 0.2f), 1,
                                     lamp[h % 4], name) >= 0;
        }
    }
  }
  for (int k = 0; k < 4 && ok; k++) /* the corridor's own dim lamps */
    ok = iris_builtin_add_quad(s, iris_v3(-12.0f + 8.0f * (float)k, H - 0.01f, 0), iris_v3(0.2f, 0, 0),
                               iris_v3(0, 0, 0.2f), 1, corridor_lamp, "corridor_lamp") >= 0;
  if (!ok) return IRIS_ERR_NOMEM;
  iris_camera cam;
  cam.name = iris_strdup("camera");
  cam.to_world = iris_mat4_look_at(iris_v3(-15.3f, 1.6f, -0.6f), iris_v3(-9.0f, 1.1f, 1.4f), iris_v3(0, 1, 0));
  cam.yfov = 55.0f * 3.14159265f / 180.0f;
  cam.aspect = 1.5f;
  if (!cam.name || iris_scene_add_camera(s, &cam) < 0) return IRIS_ERR_NOMEM;
  s->render.width = 384;
  s->render.height = 256;
  return IRIS_OK;
}
