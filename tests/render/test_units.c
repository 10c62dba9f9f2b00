/* Units of the renderer core, each against values derived by hand:
 * texture wrap modes and bilinear filtering, mirrored and non-uniformly scaled
 * instances (winding, inverse-transpose normals), self-intersection-free ray
 * offsets far from the origin, the pinhole camera and auto-framing. */
#include <stdlib.h>

#include "check.h"
#include "chi2.h"
#include "renderer/accel.h"
#include "renderer/camera.h"
#include "renderer/normal_map.h"
#include "renderer/texture.h"
#include "scenes/builtin.h"

static void test_wrap(void) {
  CHECK_EQ_INT(iris_texture_wrap(-1, 4, IRIS_WRAP_REPEAT), 3);
  CHECK_EQ_INT(iris_texture_wrap(5, 4, IRIS_WRAP_REPEAT), 1);
  CHECK_EQ_INT(iris_texture_wrap(-1, 4, IRIS_WRAP_CLAMP), 0);
  CHECK_EQ_INT(iris_texture_wrap(9, 4, IRIS_WRAP_CLAMP), 3);
  CHECK_EQ_INT(iris_texture_wrap(4, 4, IRIS_WRAP_MIRROR), 3);
  CHECK_EQ_INT(iris_texture_wrap(-1, 4, IRIS_WRAP_MIRROR), 0);
  CHECK_EQ_INT(iris_texture_wrap(-5, 4, IRIS_WRAP_MIRROR), 3);
  CHECK_EQ_INT(iris_texture_wrap(8, 4, IRIS_WRAP_MIRROR), 0);
}

static void test_lookup(void) {
  /* 2x1 texture: black | white (R), alpha 255 */
  uint8_t px[8] = {0, 0, 0, 255, 255, 128, 255, 255};
  iris_textures tex;
  memset(&tex, 0, sizeof tex);
  for (int i = 0; i < 256; i++) tex.srgb_table[i] = iris_srgb_to_linear((float)i / 255.0f);
  iris_texture_image img;
  memset(&img, 0, sizeof img);
  img.width = 2, img.height = 1, img.rgba = px, img.wrap_s = img.wrap_t = IRIS_WRAP_CLAMP;
  tex.images = &img;
  tex.count = 1;
  float c[4];
  /* texel centres at u = 0.25 and 0.75; halfway is the average of decoded values */
  iris_texture_lookup(&tex, 0, 0.5f, 0.5f, false, c);
  CHECK_NEAR(c[0], 0.5, 1e-6);
  iris_texture_lookup(&tex, 0, 0.5f, 0.5f, true, c);
  CHECK_NEAR(c[0], 0.5, 1e-6); /* decode 0 -> 0, 255 -> 1, then filter */
  CHECK_NEAR(c[1], 0.5 * iris_srgb_to_linear(128.0f / 255.0f), 1e-6);
  CHECK_NEAR(c[3], 1.0, 1e-6);
  iris_texture_lookup(&tex, 0, 0.25f, 0.5f, true, c);
  CHECK_NEAR(c[0], 0.0, 1e-6);
  iris_texture_lookup(&tex, 0, 0.0f, 0.5f, true, c); /* clamp: the edge texel */
  CHECK_NEAR(c[0], 0.0, 1e-6);
  /* clamp is not periodic: u = -0.5 and -3.5 read the left edge, 1.5 the right one */
  iris_texture_lookup(&tex, 0, -0.5f, 0.5f, false, c);
  CHECK_NEAR(c[0], 0.0, 1e-6);
  iris_texture_lookup(&tex, 0, -3.5f, 0.5f, false, c);
  CHECK_NEAR(c[0], 0.0, 1e-6);
  iris_texture_lookup(&tex, 0, 1.5f, 0.5f, false, c);
  CHECK_NEAR(c[0], 1.0, 1e-6);
  /* uv set and transform: set 1 with offset (0.5, 0) reads u1 + 0.5 */
  img.uv_set = 1;
  iris_texture tdesc;
  memset(&tdesc, 0, sizeof tdesc);
  tdesc.has_transform = true, tdesc.offset[0] = 0.5f, tdesc.scale[0] = tdesc.scale[1] = 1.0f;
  img.has_transform = true;
  iris_texture_transform_matrix(&tdesc, img.xf);
  const float uv0[2] = {0.5f, 0.5f}, uv1[2] = {0.25f, 0.5f};
  iris_texture_sample(&tex, 0, uv0, uv1, false, c); /* u = 0.75: the white texel's centre */
  CHECK_NEAR(c[0], 1.0, 1e-6);
  img.uv_set = 0;
  iris_texture_sample(&tex, 0, uv1, uv0, false, c); /* set 0 = (0.25, 0.5) + 0.5 */
  CHECK_NEAR(c[0], 1.0, 1e-6);
  img.uv_set = 0, img.has_transform = false;
  img.wrap_s = IRIS_WRAP_REPEAT; /* repeat: u = 0 is halfway between last and first */
  iris_texture_lookup(&tex, 0, 0.0f, 0.5f, false, c);
  CHECK_NEAR(c[0], 0.5, 1e-6);
  iris_texture_lookup(&tex, 0, 1.75f, 0.5f, false, c);
  CHECK_NEAR(c[0], 1.0, 1e-6);
  img.nearest = true;
  iris_texture_lookup(&tex, 0, 0.6f, 0.5f, false, c);
  CHECK_NEAR(c[0], 1.0, 1e-6);
  iris_texture_lookup(&tex, 7, 0.6f, 0.5f, false, c); /* out of range: white */
  CHECK_NEAR(c[0], 1.0, 1e-6);
}

/* KHR_texture_transform against the Khronos TextureTransformTest model's markers:
 * each quad spans uv (0,0)-(1,1) over its local [-0.5, 0.5]^2 (u = x + 0.5,
 * v = 0.5 - y); the arrow's tip is at texture uv (0.7778, 0.7778) (the "not
 * supported" marker, local (0.2778, -0.2778)); with the right transform the tip
 * shows at the "correct" marker, with the rotation reversed at the "error" one. */
static void test_texture_transform(void) {
  const float tip[2] = {0.77781746f, 0.77781746f};
  struct {
    float offset[2], rotation, scale[2];
    float x, y;   /* marker's local position */
    double tol;   /* the marker quads are 0.1-0.15 wide */
    bool hit;
  } cases[] = {
      {{0, 0}, 0.39269908f, {1, 1}, -0.07904822f, -0.51626749f, 1e-4, true},   /* Rotation - Correct */
      {{0, 0}, 0.39269908f, {1, 1}, 0.51626749f, 0.07904822f, 0.1, false},     /* Rotation - Error */
      {{0, 0}, 0, {1.5f, 1.5f}, 0.01854497f, -0.01854497f, 1e-4, true},        /* Scale - Correct */
      {{-0.2f, -0.1f}, 0.3f, {1.5f, 1.5f}, -0.07f, -0.25f, 0.05, true},        /* All - Correct */
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    iris_texture t;
    memset(&t, 0, sizeof t);
    t.has_transform = true;
    memcpy(t.offset, cases[i].offset, sizeof t.offset);
    t.rotation = cases[i].rotation;
    memcpy(t.scale, cases[i].scale, sizeof t.scale);
    float xf[2][3];
    iris_texture_transform_matrix(&t, xf);
    float u = cases[i].x + 0.5f, v = 0.5f - cases[i].y;
    float tu = xf[0][0] * u + xf[0][1] * v + xf[0][2], tv = xf[1][0] * u + xf[1][1] * v + xf[1][2];
    double dist = hypot(tu - tip[0], tv - tip[1]);
    if (cases[i].hit) {
      if (!CHECK(dist < cases[i].tol)) printf("  case %zu: tip at (%g, %g), distance %g\n", i, tu, tv, dist);
    } else {
      CHECK(dist > cases[i].tol);
    }
  }
}

/* Normal maps: the flat texel (0.5, 0.5, 1) gives N back; x along T, y along B;
 * a normal bent so far that wo's mirror image would go below the surface is
 * pulled back just enough (reflection height = min(0.9 cos, 0.01)), and valid
 * ones are kept. */
static void test_normal_map(void) {
  iris_vec3 t = iris_v3(1, 0, 0), b = iris_v3(0, 1, 0), n = iris_v3(0, 0, 1);
  const float flat[3] = {0.5f, 0.5f, 1.0f}, tilt[3] = {1.0f, 0.5f, 0.5f + 0.5f * 1.0f};
  iris_vec3 r = iris_normal_map_apply(t, b, n, flat, 1.0f);
  CHECK(fabsf(r.z - 1.0f) < 1e-6f);
  r = iris_normal_map_apply(t, b, n, tilt, 1.0f); /* (1, 0, 1) normalised */
  CHECK(fabsf(r.x - 0.70710678f) < 1e-5f && fabsf(r.z - 0.70710678f) < 1e-5f);
  r = iris_normal_map_apply(t, b, n, tilt, 0.0f); /* scale 0: flat */
  CHECK(fabsf(r.z - 1.0f) < 1e-6f);
  iris_vec3 ng = iris_v3(0, 0, 1);
  for (int i = 0; i < 200; i++) {
    float th = 0.05f + 1.4f * (float)i / 200.0f, ph = 0.7f * (float)i;
    iris_vec3 wo = iris_v3(sinf(th) * cosf(ph), sinf(th) * sinf(ph), cosf(th));
    float bend = 1.5f * (float)((i * 37) % 200) / 200.0f;
    iris_vec3 sn = iris_normalize(iris_v3(sinf(bend) * cosf(ph + 2.0f), sinf(bend) * sinf(ph + 2.0f), cosf(bend)));
    iris_vec3 v = iris_normal_make_valid(ng, wo, sn);
    iris_vec3 refl = iris_sub(iris_scale(sn, 2.0f * iris_dot(sn, wo)), wo);
    float thr = fminf(0.9f * wo.z, 0.01f);
    if (refl.z >= thr) {
      CHECK(v.x == sn.x && v.y == sn.y && v.z == sn.z);
    } else {
      iris_vec3 rv = iris_sub(iris_scale(v, 2.0f * iris_dot(v, wo)), wo);
      if (!CHECK(fabsf(iris_length(v) - 1.0f) < 1e-4f && rv.z >= thr - 2e-4f && v.z > 0.0f))
        printf("  case %d: reflection height %g (threshold %g)\n", i, rv.z, thr);
    }
  }
}

/* One triangle in the z = 0 plane, front +z, with a vertex normal field. */
static iris_scene *triangle_scene(const iris_mat4 *transform) {
  iris_scene *s = iris_scene_create();
  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.name = iris_strdup("tri");
  m.vertex_count = 3;
  m.triangle_count = 1;
  m.positions = malloc(9 * sizeof(float));
  m.normals = malloc(9 * sizeof(float));
  m.indices = malloc(3 * sizeof(uint32_t));
  const float p[9] = {-1, -1, 0, 1, -1, 0, 0, 1, 0};
  const float r2 = 0.70710678f;
  const float n[9] = {r2, 0, r2, r2, 0, r2, r2, 0, r2}; /* tilted towards +x */
  memcpy(m.positions, p, sizeof p);
  memcpy(m.normals, n, sizeof n);
  m.indices[0] = 0, m.indices[1] = 1, m.indices[2] = 2;
  m.material = -1;
  m.owned = true;
  iris_scene_add_mesh(s, &m);
  iris_instance inst = {0, *transform};
  iris_scene_add_instance(s, &inst);
  return s;
}

static void test_instances(void) {
  /* Mirror in x and stretch x by 2: the front stays +z (the winding flips twice:
   * once by the mirror, once back by iris), and the normal (1, 0, 1)/sqrt2
   * transforms with the inverse transpose diag(-1/2, 1, 1) -> (-1/2, 0, 1). */
  iris_mat4 t = iris_mat4_identity();
  t.m[0][0] = -2.0f;
  iris_scene *s = triangle_scene(&t);
  iris_accel *a = NULL;
  iris_error err;
  CHECK(iris_accel_build(s, &a, &err) == IRIS_OK);
  if (a) {
    iris_ray r = {iris_v3(0.1f, -0.2f, 5), 0.0f, iris_v3(0, 0, -1), INFINITY};
    iris_hit h;
    CHECK(iris_accel_intersect(a, &r, &h));
    CHECK_NEAR(h.t, 5.0, 1e-5);
    iris_interaction si;
    iris_accel_interaction(a, r.d, &h, &si);
    CHECK(si.front);
    CHECK_NEAR(si.ng.z, 1.0, 1e-6);
    iris_vec3 expect = iris_normalize(iris_v3(-0.5f, 0, 1));
    CHECK_NEAR(si.ns.x, expect.x, 1e-5);
    CHECK_NEAR(si.ns.z, expect.z, 1e-5);
    CHECK_NEAR(si.p.x, 0.1, 1e-6);
    /* the light-sampling view of the same triangle: counter-clockwise around +z */
    iris_vec3 v[3];
    iris_accel_triangle(a, 0, v);
    CHECK(iris_cross(iris_sub(v[1], v[0]), iris_sub(v[2], v[0])).z > 0.0f);
    iris_accel_destroy(a);
  }
  iris_scene_destroy(s);
}

static void test_offsets(void) {
  /* A triangle far from the origin: rays leaving it in any direction (also
   * grazing ones) must not hit it again; rays from below must hit it. */
  iris_mat4 t = iris_mat4_identity();
  t.m[0][3] = 12345.0f;
  t.m[1][3] = -5432.0f;
  t.m[2][3] = 777.0f;
  iris_scene *s = triangle_scene(&t);
  iris_accel *a = NULL;
  iris_error err;
  CHECK(iris_accel_build(s, &a, &err) == IRIS_OK);
  if (!a) return;
  uint64_t state = 1;
  int self_hits = 0, misses = 0;
  for (int i = 0; i < 20000; i++) {
    float b1 = (float)chi2_uniform(&state), b2 = (float)chi2_uniform(&state);
    if (b1 + b2 > 1.0f) b1 = 1.0f - b1, b2 = 1.0f - b2;
    iris_interaction si;
    iris_accel_surface_at(a, 0, b1, b2, &si);
    float phi = 6.2831853f * (float)chi2_uniform(&state);
    float z = (i % 2 ? 1.0f : -1.0f) * (1e-3f + 0.2f * (float)chi2_uniform(&state));
    float rr = sqrtf(1 - z * z);
    iris_vec3 w = iris_v3(rr * cosf(phi), rr * sinf(phi), z);
    iris_ray ray = iris_spawn_ray(&si, w);
    if (iris_accel_occluded(a, &ray)) self_hits++;
    /* from 1 unit below, straight up through the point: must hit */
    iris_ray up = {iris_sub(si.p, iris_v3(0, 0, 1)), 0.0f, iris_v3(0, 0, 1), INFINITY};
    iris_hit h;
    if (b1 > 0.01f && b2 > 0.01f && b1 + b2 < 0.99f && !iris_accel_intersect(a, &up, &h)) misses++;
  }
  CHECK_EQ_INT(self_hits, 0);
  CHECK_EQ_INT(misses, 0);
  iris_accel_destroy(a);
  iris_scene_destroy(s);
}

static void test_camera(void) {
  iris_scene *s = NULL;
  iris_error err;
  CHECK(iris_builtin_create("veach-mis", &s, &err) == IRIS_OK);
  if (!s) return;
  iris_pinhole cam;
  CHECK(iris_pinhole_setup(s, NULL, 0, 0, &cam, &err) == IRIS_OK);
  CHECK_EQ_INT(cam.width, 768);
  CHECK_EQ_INT(cam.height, 512);
  CHECK(iris_pinhole_setup(s, NULL, 300, 0, &cam, &err) == IRIS_OK);
  CHECK_EQ_INT(cam.height, 200); /* 3:2 */
  /* the centre ray looks at the target; the top edge is 14 degrees above it */
  iris_ray r = iris_pinhole_ray(&cam, 150.0f, 100.0f);
  iris_vec3 fwd = iris_normalize(iris_v3(0, -4, -12.5f));
  CHECK_NEAR(iris_dot(r.d, fwd), 1.0, 1e-6);
  r = iris_pinhole_ray(&cam, 150.0f, 0.0f);
  CHECK_NEAR(acos(iris_dot(r.d, fwd)) * 180.0 / 3.14159265358979, 14.0, 1e-3);
  CHECK(iris_pinhole_setup(s, "nope", 0, 0, &cam, &err) == IRIS_ERR_USAGE);
  /* no camera: the whole bounding box must be in view */
  free(s->cameras[0].name);
  s->camera_count = 0;
  s->render.width = s->render.height = 0;
  CHECK(iris_pinhole_setup(s, NULL, 64, 48, &cam, &err) == IRIS_OK);
  CHECK(cam.automatic);
  iris_vec3 lo, hi;
  CHECK(iris_scene_bounds(s, &lo, &hi));
  for (int i = 0; i < 8; i++) {
    iris_vec3 c = iris_v3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    iris_vec3 d = iris_sub(c, cam.origin);
    float z = iris_dot(d, cam.forward);
    float x = iris_dot(d, cam.right) / z, y = iris_dot(d, cam.up) / z;
    CHECK(z > 0.0f);
    CHECK(fabsf(y) <= cam.tan_half_yfov * 1.0001f);
    CHECK(fabsf(x) <= cam.tan_half_yfov * cam.aspect * 1.0001f);
  }
  iris_scene_destroy(s);
}

int main(void) {
  test_wrap();
  test_lookup();
  test_texture_transform();
  test_normal_map();
  test_instances();
  test_offsets();
  test_camera();
  return iris_check_summary("render.units");
}
