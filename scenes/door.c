/* The door scene (scenes/door.h). Units: metres. Room A (camera) spans
 * x in [-4, 0], room B (light) x in [0, 4]; both y in [0, 3] (up), z in [-2, 2].
 * The dividing wall at x = 0 has a door 0.6 m wide and 2 m high. */
#include "scenes/door.h"

#include "scenes/builtin.h"

static int32_t add_diffuse(iris_scene *s, const char *name, float r, float g, float b) {
  iris_material m = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  m.name = iris_strdup(name);
  m.color[0] = r;
  m.color[1] = g;
  m.color[2] = b;
  return m.name ? iris_scene_add_material(s, &m) : -1;
}

iris_status iris_door_scene_build(iris_scene *s) { return iris_door_scene_build_variant(s, IRIS_DOOR_LIT); }

iris_status iris_door_scene_build_variant(iris_scene *s, iris_door_variant variant) {
  int32_t wall = add_diffuse(s, "wall", 0.75f, 0.75f, 0.72f);
  int32_t floor = add_diffuse(s, "floor", 0.55f, 0.45f, 0.35f);
  int32_t box = add_diffuse(s, "box", 0.3f, 0.45f, 0.65f);
  int32_t light = add_diffuse(s, "light", 0.0f, 0.0f, 0.0f);
  if (wall < 0 || floor < 0 || box < 0 || light < 0) return IRIS_ERR_NOMEM;
  s->materials[light].emission[0] = 60.0f;
  s->materials[light].emission[1] = 55.0f;
  s->materials[light].emission[2] = 45.0f;
  s->materials[light].emission_two_sided = false;
  bool ok = true;
  /* Outer shell (quads are shaded from both sides; fronts face inwards). */
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 0, 0), iris_v3(0, 0, 2), iris_v3(4, 0, 0), 4, floor, "floor") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 3, 0), iris_v3(4, 0, 0), iris_v3(0, 0, 2), 4, wall, "ceiling") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(-4, 1.5f, 0), iris_v3(0, 1.5f, 0), iris_v3(0, 0, 2), 2, wall, "west") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(4, 1.5f, 0), iris_v3(0, 0, 2), iris_v3(0, 1.5f, 0), 2, wall, "east") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 1.5f, -2), iris_v3(4, 0, 0), iris_v3(0, 1.5f, 0), 4, wall, "north") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 1.5f, 2), iris_v3(0, 1.5f, 0), iris_v3(4, 0, 0), 4, wall, "south") >= 0;
  /* Dividing wall with the door z in [-0.3, 0.3], y in [0, 2]. */
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 1.5f, -1.15f), iris_v3(0, 1.5f, 0), iris_v3(0, 0, 0.85f), 2, wall, "divider_n") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 1.5f, 1.15f), iris_v3(0, 1.5f, 0), iris_v3(0, 0, 0.85f), 2, wall, "divider_s") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(0, 2.5f, 0), iris_v3(0, 0.5f, 0), iris_v3(0, 0, 0.3f), 1, wall, "lintel") >= 0;
  /* A box in room A so that the visible room has some occlusion. */
  ok = ok && iris_builtin_add_quad(s, iris_v3(-2.0f, 0.8f, -1.0f), iris_v3(0.4f, 0, 0), iris_v3(0, 0, 0.4f), 1, box, "box_top") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(-2.0f, 0.4f, -0.6f), iris_v3(0.4f, 0, 0), iris_v3(0, 0.4f, 0), 1, box, "box_front") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(-1.6f, 0.4f, -1.0f), iris_v3(0, 0.4f, 0), iris_v3(0, 0, 0.4f), 1, box, "box_east") >= 0;
  ok = ok && iris_builtin_add_quad(s, iris_v3(-2.4f, 0.4f, -1.0f), iris_v3(0, 0, 0.4f), iris_v3(0, 0.4f, 0), 1, box, "box_west") >= 0;
  if (variant == IRIS_DOOR_SHIELDED) {
    /* The light: 1 m x 1 m, upright in room B 0.4 m before the east wall and
     * facing it (cross(a, b) = +x); its black back faces the door, so no
     * point of room A sees it: room A gets light only after >= 1 bounce in
     * room B, through the door. 8 x 8 quads: triangle edges (0.18 m) stay
     * shorter than the 0.4 m to the wall they light. */
    ok = ok && iris_builtin_add_quad(s, iris_v3(3.6f, 1.5f, 0), iris_v3(0, 0.5f, 0), iris_v3(0, 0, 0.5f), 8, light, "light") >= 0;
  } else {
    /* The light: 1 m x 1 m under room B's ceiling, facing down (cross(a, b) = -y),
     * as 8 x 8 quads so that no emitter triangle is large next to the points it
     * lights (Cycles' solid-angle path for large triangles is 0.25% dark here,
     * docs/validation.md). */
    ok = ok && iris_builtin_add_quad(s, iris_v3(2.5f, 2.98f, 0), iris_v3(0.5f, 0, 0), iris_v3(0, 0, 0.5f), 8, light, "light") >= 0;
  }
  if (!ok) return IRIS_ERR_NOMEM;
  iris_camera cam;
  cam.name = iris_strdup("camera");
  cam.to_world = iris_mat4_look_at(iris_v3(-3.7f, 1.4f, 1.7f), iris_v3(0.0f, 1.0f, -0.2f), iris_v3(0, 1, 0));
  cam.yfov = 55.0f * 3.14159265f / 180.0f;
  cam.aspect = 4.0f / 3.0f;
  if (!cam.name || iris_scene_add_camera(s, &cam) < 0) return IRIS_ERR_NOMEM;
  s->render.width = 512;
  s->render.height = 384;
  return IRIS_OK;
}
