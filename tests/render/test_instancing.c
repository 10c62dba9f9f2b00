/* Instancing (issue 20, docs/rendering.md "Instancing"): a scene whose meshes
 * are placed several times (built once, placed by Embree instances) against
 * the same placements baked into separate world-space meshes (each placed
 * once, hence flattened):
 *  - images: every method (bsdf, nee, mis, guided, guided-nee) agrees per
 *    image and per 8x8 block (z-tests on the variance of each pixel's mean,
 *    Bonferroni-corrected as tests/render/test_unbiased.c), on a scene with
 *    rotated, uniformly scaled, mirrored (negative determinant) and
 *    non-uniformly scaled (also negative) placements, a normal-mapped mesh,
 *    an alpha (MASK) cut-out and an emissive mesh placed three times;
 *  - the hits themselves: a grid of rays gets the same distance, position,
 *    normals and (normal-map) tangent frame, up to float rounding of the
 *    object-space intersection;
 *  - lights: the emissive mesh placed N times is N lights of their own
 *    world-space power (= the baked scene's total, = N times one placement
 *    scaled by |det|^(2/3) for a uniform scale);
 *  - determinism: the instanced guided-nee render is bit-identical for 1 and
 *    2 threads, and a window of it (a partition) equals the same pixels of
 *    the whole frame bit for bit;
 *  - the scene hash (iris merge, guide files) changes when one placement's
 *    transform changes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "render_run.h"
#include "core/image.h"
#include "film_stats.h"
#include "renderer/accel.h"
#include "renderer/guiding/guiding.h"
#include "renderer/lights.h"
#include "renderer/merge.h"
#include "renderer/render.h"
#include "renderer/texture.h"

/* ---- the scene ---------------------------------------------------------- */

enum { MAT_FLOOR, MAT_NM, MAT_GLOSSY, MAT_MASK, MAT_LIGHT, MAT_COUNT };

static float *copy_floats(const float *src, size_t n) {
  float *p = malloc(n * sizeof *p);
  memcpy(p, src, n * sizeof *p);
  return p;
}

/* UV sphere of radius r: normals, uvs, optionally tangents along +u. */
static iris_mesh sphere(const char *name, float r, int seg, int rings, bool tangents, int32_t mat) {
  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.name = iris_strdup(name);
  m.owned = true;
  m.material = mat;
  m.vertex_count = (uint32_t)((seg + 1) * (rings + 1));
  m.triangle_count = (uint32_t)(2 * seg * rings);
  m.positions = malloc(3 * sizeof(float) * m.vertex_count);
  m.normals = malloc(3 * sizeof(float) * m.vertex_count);
  m.uvs = malloc(2 * sizeof(float) * m.vertex_count);
  if (tangents) m.tangents = malloc(4 * sizeof(float) * m.vertex_count);
  m.indices = malloc(3 * sizeof(uint32_t) * m.triangle_count);
  uint32_t v = 0;
  for (int j = 0; j <= rings; j++)
    for (int i = 0; i <= seg; i++, v++) {
      float phi = 2.0f * IRIS_PI * (float)i / (float)seg, th = IRIS_PI * (float)j / (float)rings;
      float n[3] = {sinf(th) * cosf(phi), cosf(th), -sinf(th) * sinf(phi)};
      for (int k = 0; k < 3; k++) m.positions[3 * v + k] = r * n[k], m.normals[3 * v + k] = n[k];
      m.uvs[2 * v] = 2.0f * (float)i / (float)seg; /* the normal map repeats twice around */
      m.uvs[2 * v + 1] = (float)j / (float)rings;
      if (tangents) {
        float t[4] = {-sinf(phi), 0.0f, -cosf(phi), 1.0f};
        memcpy(m.tangents + 4 * v, t, sizeof t);
      }
    }
  uint32_t *ix = m.indices;
  for (int j = 0; j < rings; j++)
    for (int i = 0; i < seg; i++) {
      uint32_t a = (uint32_t)(j * (seg + 1) + i), b = a + 1, c = a + (uint32_t)(seg + 1), d = c + 1;
      /* counter-clockwise seen from outside */
      *ix++ = a, *ix++ = c, *ix++ = b;
      *ix++ = b, *ix++ = c, *ix++ = d;
    }
  return m;
}

/* Quad in the x-z plane, size 2h, facing +y; vertex alphas 0 -> 1 along x when `alpha`. */
static iris_mesh quad(const char *name, float h, bool alpha, int32_t mat) {
  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.name = iris_strdup(name);
  m.owned = true;
  m.material = mat;
  m.vertex_count = 4;
  m.triangle_count = 2;
  const float p[12] = {-h, 0, h, h, 0, h, h, 0, -h, -h, 0, -h};
  const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
  const float a[4] = {0, 1, 1, 0};
  m.positions = copy_floats(p, 12);
  m.indices = malloc(sizeof idx);
  memcpy(m.indices, idx, sizeof idx);
  if (alpha) m.alphas = copy_floats(a, 4);
  return m;
}

/* T(t) R_y(ry) R_x(rx) S(s) */
static iris_mat4 placement(float tx, float ty, float tz, float ry, float rx, float sx, float sy, float sz) {
  iris_mat4 S = iris_mat4_identity(), Rx = iris_mat4_identity(), Ry = iris_mat4_identity();
  S.m[0][0] = sx, S.m[1][1] = sy, S.m[2][2] = sz;
  Rx.m[1][1] = cosf(rx), Rx.m[1][2] = -sinf(rx), Rx.m[2][1] = sinf(rx), Rx.m[2][2] = cosf(rx);
  Ry.m[0][0] = cosf(ry), Ry.m[0][2] = sinf(ry), Ry.m[2][0] = -sinf(ry), Ry.m[2][2] = cosf(ry);
  iris_mat4 m = iris_mat4_mul(&Rx, &S);
  m = iris_mat4_mul(&Ry, &m);
  m.m[0][3] = tx, m.m[1][3] = ty, m.m[2][3] = tz;
  return m;
}

/* `mesh` transformed by `x` into a new mesh of its own (the baked placement):
 * world positions by the same iris_mat4_point, normals by the (signed)
 * normal matrix, tangents by the 3x3 part (normalised, bitangent sign kept),
 * and the winding reversed for a mirror so that the front stays the front. */
static iris_mesh bake(const iris_mesh *mesh, const iris_mat4 *x) {
  iris_mesh m = *mesh;
  m.name = iris_strdup(mesh->name);
  m.owned = true;
  size_t nv = mesh->vertex_count;
  m.positions = malloc(3 * sizeof(float) * nv);
  iris_mat4 nm = iris_mat4_normal_matrix(x);
  for (size_t v = 0; v < nv; v++)
    iris_v3_store(iris_mat4_point(x, iris_v3_load(mesh->positions + 3 * v)), m.positions + 3 * v);
  /* The normal matrix is |det| x inverse transpose (outward normals, also
   * for mirrors). They are left unnormalised so that interpolating them is
   * interpolating the object-space normals, as an instance does. */
  float sign = iris_mat4_det3(x) < 0.0f ? -1.0f : 1.0f;
  if (mesh->normals) {
    m.normals = malloc(3 * sizeof(float) * nv);
    for (size_t v = 0; v < nv; v++) {
      iris_vec3 n = iris_mat4_vector(&nm, iris_v3_load(mesh->normals + 3 * v));
      /* with tangents (placed by rotations, uniform scales and mirrors only,
       * where |nm n| is the same for every n) unit, as glTF wants them:
       * the bitangent is w (n x t) */
      iris_v3_store(mesh->tangents ? iris_normalize(n) : n, m.normals + 3 * v);
    }
  }
  if (mesh->tangents) { /* (M^-T n) x (M t) = det M^-T (n x t): the bitangent sign follows det */
    m.tangents = malloc(4 * sizeof(float) * nv);
    for (size_t v = 0; v < nv; v++) {
      iris_v3_store(iris_normalize(iris_mat4_vector(x, iris_v3_load(mesh->tangents + 4 * v))), m.tangents + 4 * v);
      m.tangents[4 * v + 3] = sign * mesh->tangents[4 * v + 3];
    }
  }
  if (mesh->uvs) m.uvs = copy_floats(mesh->uvs, 2 * nv);
  if (mesh->alphas) m.alphas = copy_floats(mesh->alphas, nv);
  m.colors = m.uvs1 = NULL;
  m.indices = malloc(3 * sizeof(uint32_t) * mesh->triangle_count);
  bool mirror = iris_mat4_det3(x) < 0.0f;
  for (size_t t = 0; t < mesh->triangle_count; t++) {
    m.indices[3 * t] = mesh->indices[3 * t];
    m.indices[3 * t + 1] = mesh->indices[3 * t + (mirror ? 2 : 1)];
    m.indices[3 * t + 2] = mesh->indices[3 * t + (mirror ? 1 : 2)];
  }
  return m;
}

/* A 16x16 tangent-space normal map (bumps), written as a PNG. */
static bool write_normal_map(const char *path) {
  iris_image img;
  iris_error err;
  const char *names[3] = {"R", "G", "B"};
  if (iris_image_create(&img, 16, 16, 3, names, &err) != IRIS_OK) return false;
  for (int y = 0; y < 16; y++)
    for (int x = 0; x < 16; x++) {
      float nx = 0.6f * sinf(0.8f * (float)x), ny = 0.6f * cosf(0.7f * (float)y);
      float nz = sqrtf(fmaxf(1.0f - nx * nx - ny * ny, 0.05f));
      float *p = img.data + 3 * (y * 16 + x);
      p[0] = 0.5f * nx + 0.5f, p[1] = 0.5f * ny + 0.5f, p[2] = 0.5f * nz + 0.5f;
    }
  bool ok = iris_png_write(path, &img, 0, 0.0f, &err) == IRIS_OK;
  iris_image_destroy(&img);
  return ok;
}

typedef struct proto {
  iris_mesh mesh;
  int n;
  iris_mat4 x[4];
} proto;

/* The instanced scene (baked = false) or the baked one; `light_scale`
 * scales the emitters' placements (the power test). */
static iris_scene *make_scene(bool baked, const char *normal_map, int light_placements) {
  iris_scene *s = iris_scene_create();
  iris_texture tex;
  memset(&tex, 0, sizeof tex);
  tex.path = iris_strdup(normal_map);
  strcpy(tex.mime, "image/png");
  iris_scene_add_texture(s, &tex);
  iris_material mats[MAT_COUNT];
  mats[MAT_FLOOR] = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  mats[MAT_NM] = iris_material_default(IRIS_MATERIAL_GLTF);
  mats[MAT_NM].color[0] = 0.9f, mats[MAT_NM].color[1] = 0.6f, mats[MAT_NM].color[2] = 0.3f;
  mats[MAT_NM].roughness = 0.35f;
  mats[MAT_NM].normal_texture = 0;
  mats[MAT_GLOSSY] = iris_material_default(IRIS_MATERIAL_GLOSSY);
  mats[MAT_GLOSSY].roughness = 0.4f;
  mats[MAT_MASK] = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  mats[MAT_MASK].color[0] = 0.2f, mats[MAT_MASK].color[1] = 0.7f, mats[MAT_MASK].color[2] = 0.3f;
  mats[MAT_MASK].alpha_mode = IRIS_ALPHA_MASK;
  mats[MAT_MASK].alpha_cutoff = 0.4f;
  mats[MAT_LIGHT] = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  mats[MAT_LIGHT].emission[0] = 6.0f, mats[MAT_LIGHT].emission[1] = 5.0f, mats[MAT_LIGHT].emission[2] = 4.0f;
  mats[MAT_LIGHT].emission_two_sided = false;
  for (int i = 0; i < MAT_COUNT; i++) iris_scene_add_material(s, &mats[i]);

  const float deg = IRIS_PI / 180.0f;
  proto p[5];
  p[0].mesh = quad("floor", 3.0f, false, MAT_FLOOR);
  p[0].n = 1;
  p[0].x[0] = iris_mat4_identity();
  /* normal-mapped sphere: rotated, uniformly scaled, mirrored */
  p[1].mesh = sphere("nm-sphere", 0.5f, 12, 8, true, MAT_NM);
  p[1].n = 3;
  p[1].x[0] = placement(-1.3f, 0.5f, 0.4f, 30 * deg, 20 * deg, 1, 1, 1);
  p[1].x[1] = placement(0.0f, 0.7f, -0.6f, -50 * deg, 0, 1.4f, 1.4f, 1.4f);
  p[1].x[2] = placement(1.3f, 0.5f, 0.5f, 70 * deg, -15 * deg, -1, 1, 1);
  /* plain glossy sphere: non-uniform scales, one of them negative */
  p[2].mesh = sphere("glossy-sphere", 0.4f, 10, 6, false, MAT_GLOSSY);
  p[2].n = 2;
  p[2].x[0] = placement(-0.5f, 0.3f, 1.2f, 25 * deg, 0, 1.6f, 0.7f, 1.0f);
  p[2].x[1] = placement(0.8f, 0.35f, -1.5f, -40 * deg, 10 * deg, -1.2f, 0.8f, 0.6f);
  /* alpha cut-out quads, standing up */
  p[3].mesh = quad("mask", 0.6f, true, MAT_MASK);
  p[3].n = 2;
  p[3].x[0] = placement(-0.6f, 0.6f, -1.2f, 20 * deg, 90 * deg, 1, 1, 1);
  p[3].x[1] = placement(1.5f, 0.6f, -0.6f, -60 * deg, 90 * deg, -1.0f, 1.0f, 0.8f);
  /* the emitter, facing down */
  p[4].mesh = quad("light", 0.35f, false, MAT_LIGHT);
  p[4].n = light_placements;
  p[4].x[0] = placement(-1.0f, 2.5f, 0.0f, 0, 180 * deg, 1, 1, 1);
  p[4].x[1] = placement(1.0f, 2.4f, 0.5f, 40 * deg, 170 * deg, 1.5f, 1.0f, 0.7f);
  p[4].x[2] = placement(0.2f, 2.6f, -1.0f, 0, 0, 1.2f, -1.2f, 1.2f); /* mirrored: faces down */
  p[4].x[3] = placement(0.0f, 2.7f, 1.5f, 0, 180 * deg, 2.0f, 2.0f, 2.0f);
  for (int k = 0; k < 5; k++) {
    if (!baked) {
      uint32_t mi = (uint32_t)iris_scene_add_mesh(s, &p[k].mesh);
      for (int i = 0; i < p[k].n; i++) {
        iris_instance in = {mi, p[k].x[i]};
        iris_scene_add_instance(s, &in);
      }
    } else {
      for (int i = 0; i < p[k].n; i++) {
        iris_mesh b = bake(&p[k].mesh, &p[k].x[i]);
        iris_instance in = {(uint32_t)iris_scene_add_mesh(s, &b), iris_mat4_identity()};
        iris_scene_add_instance(s, &in);
      }
      iris_scene *tmp = iris_scene_create(); /* frees the prototype */
      iris_scene_add_mesh(tmp, &p[k].mesh);
      iris_scene_destroy(tmp);
    }
  }
  float env[3] = {0.15f, 0.2f, 0.3f};
  iris_scene_set_environment_color(s, env);
  iris_camera cam;
  memset(&cam, 0, sizeof cam);
  cam.name = iris_strdup("above");
  cam.to_world = placement(0.0f, 3.2f, 3.4f, 0, -42 * deg, 1, 1, 1);
  cam.yfov = 50 * deg;
  cam.aspect = 4.0f / 3.0f;
  iris_scene_add_camera(s, &cam);
  return s;
}

/* ---- checks ------------------------------------------------------------- */

static bool render(const iris_scene *s, iris_method method, int w, int h, int spp, int threads,
                   iris_pixel_bounds bounds, uint64_t seed, iris_render_result *r) {
  iris_render_params p = iris_test_params(w, h, spp, method, seed);
  iris_guiding_params gp = iris_guiding_params_default();
  gp.force = true;
  p.threads = threads;
  p.bounds = bounds;
  iris_test_attach_guide(&p, &gp);
  return iris_test_render(s, &p, r);
}

static void test_images(const iris_scene *inst, const iris_scene *baked) {
  const iris_method methods[] = {IRIS_METHOD_BSDF, IRIS_METHOD_NEE, IRIS_METHOD_MIS, IRIS_METHOD_GUIDED,
                                 IRIS_METHOD_GUIDED_NEE};
  const char *names[] = {"bsdf", "nee", "mis", "guided", "guided-nee"};
  const int nm = 5, w = 32, h = 24, spp = 64, bx = w / 8, by = h / 8;
  int n_tests = nm * 3 * (1 + bx * by);
  double z_max = fmax(3.0, z_for_alpha(1e-3 / n_tests));
  iris_pixel_bounds all = {0, 0, 0, 0};
  for (int m = 0; m < nm; m++) {
    iris_render_result a, b;
    bool oka = CHECK(render(inst, methods[m], w, h, spp, 0, all, 7, &a));
    bool okb = CHECK(render(baked, methods[m], w, h, spp, 0, all, 8, &b)); /* independent samples */
    if (oka && okb) {
      char pair[80];
      snprintf(pair, sizeof pair, "%s instanced vs baked", names[m]);
      double worst = iris_test_z_compare(&a.film, &b.film, bx, by, z_max, z_max, pair);
      double mean[3], var[3];
      region(&a.film, 0, 0, w, h, mean, var);
      CHECK(mean[0] > 0.05); /* the scene is lit: the comparison is not of two black images */
      printf("%-10s instanced vs baked: image mean %.4f, worst |z| = %.2f (limit %.2f)\n", names[m], mean[0],
             worst, z_max);
      CHECK_EQ_INT(a.stats.nan_count, 0);
    }
    if (oka) iris_render_result_destroy(&a);
    if (okb) iris_render_result_destroy(&b);
  }
}

/* Rays from the camera's side over the scene: both accels hit the same
 * placement at the same point with the same frame. */
static void test_hits(const iris_scene *inst, const iris_scene *baked) {
  iris_error err;
  iris_accel *a = NULL, *b = NULL;
  CHECK_OK(iris_accel_build(inst, &a, &err), &err);
  CHECK_OK(iris_accel_build(baked, &b, &err), &err);
  if (!a || !b) {
    iris_accel_destroy(a);
    iris_accel_destroy(b);
    return;
  }
  size_t unique = 0, placed = 0;
  iris_accel_stats(a, &unique, &placed);
  CHECK_EQ_INT(unique, 4);  /* two spheres, the mask quad, the light */
  CHECK_EQ_INT(placed, 10); /* 3 + 2 + 2 + 3 */
  iris_accel_stats(b, &unique, &placed);
  CHECK_EQ_INT(unique, 0);
  CHECK_EQ_INT(placed, 0);
  CHECK_EQ_INT(iris_accel_triangle_count(a), iris_accel_triangle_count(b));
  iris_vec3 la, ha, lb, hb;
  CHECK(iris_accel_bounds(a, &la, &ha) && iris_accel_bounds(b, &lb, &hb));
  CHECK(la.x == lb.x && la.y == lb.y && la.z == lb.z && ha.x == hb.x && ha.y == hb.y && ha.z == hb.z);
  int n = 0, same_prim = 0, hits = 0, tangents = 0, mirrored_tangents = 0;
  double worst_p = 0, worst_n = 0, worst_t = 0;
  for (int j = 0; j < 120; j++)
    for (int i = 0; i < 120; i++) {
      iris_ray ray;
      ray.o = iris_v3(0.0f, 4.0f, 3.5f);
      iris_vec3 target = iris_v3(-2.6f + 5.2f * (i + 0.5f) / 120.0f, 0.0f, -2.6f + 5.2f * (j + 0.5f) / 120.0f);
      ray.d = iris_normalize(iris_sub(target, ray.o));
      ray.tmin = 0.0f;
      ray.tmax = INFINITY;
      iris_hit ha_, hb_;
      bool hit_a = iris_accel_intersect(a, &ray, &ha_), hit_b = iris_accel_intersect(b, &ray, &hb_);
      n++;
      if (hit_a != hit_b) continue;
      if (!hit_a) {
        same_prim++;
        continue;
      }
      if (ha_.prim != hb_.prim || ha_.instance != hb_.instance) continue;
      same_prim++;
      hits++;
      iris_interaction sa, sb;
      iris_accel_interaction(a, ray.d, &ha_, &sa);
      iris_accel_interaction(b, ray.d, &hb_, &sb);
      worst_p = fmax(worst_p, iris_length(iris_sub(sa.p, sb.p)));
      worst_n = fmax(worst_n, iris_length(iris_sub(sa.ng, sb.ng)));
      worst_n = fmax(worst_n, iris_length(iris_sub(sa.ns, sb.ns)));
      CHECK(sa.front == sb.front);
      CHECK(sa.material == sb.material);
      CHECK(sa.has_tangent == sb.has_tangent);
      if (sa.has_tangent && sb.has_tangent) {
        tangents++;
        if (ha_.instance == 3) mirrored_tangents++;
        /* the baked tangents are unit; the instanced ones keep unit length
         * under uniform scale (the cube-root division) */
        worst_t = fmax(worst_t, iris_length(iris_sub(sa.tangent, sb.tangent)));
        worst_t = fmax(worst_t, iris_length(iris_sub(sa.bitangent, sb.bitangent)));
      }
    }
  printf("hits: %d rays, %d agree on the triangle (%d hits, %d with tangents, %d on the mirror); worst |dp| "
         "%.2g, |dn| %.2g, |dT|,|dB| %.2g\n",
         n, same_prim, hits, tangents, mirrored_tangents, worst_p, worst_n, worst_t);
  CHECK(same_prim >= n - 5); /* a grazing ray may round to the neighbouring triangle */
  CHECK(hits > n / 2);
  CHECK(tangents > 200 && mirrored_tangents > 20);
  CHECK(worst_p < 1e-4);
  CHECK(worst_n < 1e-3);
  CHECK(worst_t < 0.05); /* interpolated vs per-vertex-normalised tangents */
  iris_accel_destroy(a);
  iris_accel_destroy(b);
}

static double total_triangle_power(const iris_scene *s, size_t *groups) {
  iris_error err;
  iris_accel *a = NULL;
  iris_textures tx;
  iris_lights l;
  memset(&tx, 0, sizeof tx);
  memset(&l, 0, sizeof l);
  double p = -1;
  *groups = 0;
  if (iris_accel_build(s, &a, &err) == IRIS_OK && iris_textures_load(s, &tx, &err) == IRIS_OK &&
      iris_lights_build(s, a, &tx, &l, &err) == IRIS_OK) {
    p = 0;
    for (size_t i = 0; i < l.count; i++)
      if (l.entries[i].kind == IRIS_LIGHT_KIND_TRIANGLE) p += l.entries[i].power;
    *groups = l.group_count;
  } else {
    fprintf(stderr, "lights: %s\n", err.message);
  }
  iris_lights_destroy(&l);
  iris_textures_destroy(&tx);
  iris_accel_destroy(a);
  return p;
}

static void test_power(const char *nmap) {
  double one = 0;
  for (int n = 1; n <= 4; n++) {
    iris_scene *si = make_scene(false, nmap, n), *sb = make_scene(true, nmap, n);
    size_t gi, gb;
    double pi = total_triangle_power(si, &gi), pb = total_triangle_power(sb, &gb);
    if (n == 1) one = pi;
    /* placements 1..4 scale the area by 1, 1.05 (1.5 x 0.7), 1.44, 4 */
    const double area_scale[4] = {1.0, 1.05, 1.44, 4.0};
    double expect = 0;
    for (int k = 0; k < n; k++) expect += one * area_scale[k];
    printf("emitter placed %d times: power %.4f (baked %.4f, expected %.4f), %zu light groups\n", n, pi, pb,
           expect, gi);
    CHECK(pi > 0);
    CHECK_NEAR(pi, pb, 1e-5 * pb);
    CHECK_NEAR(pi, expect, 1e-4 * expect);
    CHECK_EQ_INT(gi, gb);
    iris_scene_destroy(si);
    iris_scene_destroy(sb);
  }
}

static bool films_equal(const iris_film *a, const iris_film *b, int ox, int oy) {
  for (int y = 0; y < a->height; y++)
    for (int x = 0; x < a->width; x++) {
      size_t i = (size_t)y * a->width + x, j = (size_t)(y + oy) * b->width + (x + ox);
      if (a->count[i] != b->count[j]) return false;
      for (int k = 0; k < 3; k++)
        if (a->sum[3 * i + k] != b->sum[3 * j + k] || a->sum2[3 * i + k] != b->sum2[3 * j + k]) return false;
    }
  return true;
}

static void test_determinism(const iris_scene *inst) {
  iris_pixel_bounds all = {0, 0, 0, 0}, window = {8, 8, 24, 16};
  const iris_method methods[] = {IRIS_METHOD_MIS, IRIS_METHOD_GUIDED_NEE};
  for (int m = 0; m < 2; m++) {
    iris_render_result one, two, part;
    bool ok1 = CHECK(render(inst, methods[m], 32, 24, 8, 1, all, 7, &one));
    bool ok2 = CHECK(render(inst, methods[m], 32, 24, 8, 2, all, 7, &two));
    bool okp = CHECK(render(inst, methods[m], 32, 24, 8, 2, window, 7, &part));
    if (ok1 && ok2) CHECK(films_equal(&one.film, &two.film, 0, 0));
    if (ok1 && okp) CHECK(part.film.width == 16 && part.film.height == 8 && films_equal(&part.film, &one.film, 8, 8));
    if (ok1) iris_render_result_destroy(&one);
    if (ok2) iris_render_result_destroy(&two);
    if (okp) iris_render_result_destroy(&part);
  }
}

static void test_hash(const char *nmap) {
  iris_scene *a = make_scene(false, nmap, 3), *b = make_scene(false, nmap, 3);
  CHECK(iris_merge_scene_hash(a) == iris_merge_scene_hash(b));
  b->instances[2].transform.m[0][3] += 1e-3f; /* one placement of a mesh placed three times moves */
  CHECK(iris_merge_scene_hash(a) != iris_merge_scene_hash(b));
  iris_scene_destroy(a);
  iris_scene_destroy(b);
}

int main(void) {
  char dir[512], nmap[600];
  if (iris_test_tmpdir(dir, sizeof dir, "instancing") != 0) return TEST_SKIP("no temporary directory");
  snprintf(nmap, sizeof nmap, "%s/bumps.png", dir);
  if (!CHECK(write_normal_map(nmap))) return TEST_SUMMARY();
  iris_scene *inst = make_scene(false, nmap, 3), *baked = make_scene(true, nmap, 3);
  iris_error err;
  CHECK_OK(iris_scene_validate(inst, "instanced", &err), &err);
  CHECK_OK(iris_scene_validate(baked, "baked", &err), &err);
  test_hits(inst, baked);
  test_power(nmap);
  test_hash(nmap);
  test_images(inst, baked);
  test_determinism(inst);
  iris_scene_destroy(inst);
  iris_scene_destroy(baked);
  iris_test_rmtree(dir);
  return TEST_SUMMARY();
}
