/* The office scene (scenes/office.h). Units: metres; y is up, the floor is
 * y = 0, the room x, z in [-12, 12]. */
#include "scenes/office.h"

#include <stdio.h>

#include "scenes/builtin.h"

/* The lamps' warm white. */
static const float TINT[3] = {1.0f, 0.95f, 0.85f};

static int32_t add_material(iris_scene *s, const char *name, float r, float g, float b, float emission) {
  return iris_builtin_add_diffuse(s, name, r, g, b, emission, TINT);
}

#define LAMPS 20          /* per side */
#define LAMP_PITCH 1.2f   /* metres between lamp centres */
#define LAMP_HALF 0.15f   /* half the lamp's side */

iris_status iris_office_scene_build(iris_scene *s) {
  int32_t wall = add_material(s, "wall", 0.7f, 0.7f, 0.68f, 0.0f);
  int32_t floor = add_material(s, "floor", 0.45f, 0.42f, 0.38f, 0.0f);
  int32_t partition = add_material(s, "partition", 0.35f, 0.45f, 0.55f, 0.0f);
  int32_t off = add_material(s, "lamp_off", 0.8f, 0.8f, 0.8f, 0.0f);
  int32_t lamp[4];
  if (!iris_builtin_add_lamps(s, 2.5f, TINT, lamp)) return IRIS_ERR_NOMEM;
  if (wall < 0 || floor < 0 || partition < 0 || off < 0) return IRIS_ERR_NOMEM;
  bool ok = true;
  /* The shell; quads are shaded from both sides, fronts face inwards. */
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 0, 0), iris_v3(0, 0, 12), iris_v3(12, 0, 0), 12, floor, "floor") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 3, 0), iris_v3(12, 0, 0), iris_v3(0, 0, 12), 12, wall, "ceiling") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(-12, 1.5f, 0), iris_v3(0, 1.5f, 0), iris_v3(0, 0, 12), 4, wall, "west") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(12, 1.5f, 0), iris_v3(0, 0, 12), iris_v3(0, 1.5f, 0), 4, wall, "east") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 1.5f, -12), iris_v3(12, 0, 0), iris_v3(0, 1.5f, 0), 4, wall, "north") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 1.5f, 12), iris_v3(0, 1.5f, 0), iris_v3(12, 0, 0), 4, wall, "south") >= 0;
  /* Partitions 1.5 m high on the lines x, z = -8, -4, 0, 4, 8: 3 m pieces
   * with 1 m gaps between them. */
  for (int line = -2; line <= 2 && ok; line++)
    for (int piece = -3; piece < 3 && ok; piece++) {
      float at = 4.0f * (float)line, mid = 4.0f * (float)piece + 2.0f;
      ok = iris_builtin_add_quad(s, iris_v3(at, 0.75f, mid), iris_v3(0, 0.75f, 0), iris_v3(0, 0, 1.5f), 1, partition,
                                 "partition_x") >= 0 &&
           iris_builtin_add_quad(s, iris_v3(mid, 0.75f, at), iris_v3(1.5f, 0, 0), iris_v3(0, 0.75f, 0), 1, partition,
                                 "partition_z") >= 0;
    }
  /* The lamps, facing down (cross(a, b) = -y), just under the ceiling. */
  int lit = 0;
  for (int i = 0; i < LAMPS && ok; i++)
    for (int j = 0; j < LAMPS && ok; j++) {
      float x = LAMP_PITCH * ((float)i - 0.5f * (LAMPS - 1)), z = LAMP_PITCH * ((float)j - 0.5f * (LAMPS - 1));
      unsigned h = (unsigned)(i * 7 + j * 13 + i * j);
      int32_t m = h % 23 == 5 ? off : lamp[h % 4];
      lit += m != off;
      char name[32];
      snprintf(name, sizeof name, "lamp_%d_%d", i, j);
      ok = iris_builtin_add_quad(s, iris_v3(x, 2.99f, z), iris_v3(LAMP_HALF, 0, 0), iris_v3(0, 0, LAMP_HALF), 1, m, name) >= 0;
    }
  if (!ok) return IRIS_ERR_NOMEM;
  iris_camera cam;
  cam.name = iris_strdup("camera");
  cam.to_world = iris_mat4_look_at(iris_v3(-10.5f, 1.6f, 10.5f), iris_v3(-2.0f, 1.1f, 2.0f), iris_v3(0, 1, 0));
  cam.yfov = 50.0f * 3.14159265f / 180.0f;
  cam.aspect = 1.5f;
  if (!cam.name || iris_scene_add_camera(s, &cam) < 0) return IRIS_ERR_NOMEM;
  s->render.width = 384;
  s->render.height = 256;
  return IRIS_OK;
}
