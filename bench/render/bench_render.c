/* Renderer benchmarks (not tests):
 *   bench_render raw SCENE THREADS SPP W H RAYS_PER_PATH [SHADOW_PER_PATH]
 *       raw Embree loop: camera rays, then cosine bounces, and per hit an
 *       occlusion ray to a uniformly chosen point on a uniformly chosen emissive
 *       triangle (the kind of shadow ray next-event estimation casts), with as
 *       many closest-hit and occlusion rays per path as `iris render --method
 *       mis` casts on average (given on the command line), no shading: the
 *       ceiling for iris's ray rate. Without SHADOW_PER_PATH (or in scenes
 *       without emissive triangles) the old form: one occlusion ray per hit to
 *       a point about one unit above it.
 *   bench_render instancing N                N copies of the bunny: BVH memory and
 *       ray rate with flattened triangles vs Embree instances (one BLAS).
 *   bench_render write-bunny-box OUT.json    the "bunny in a box" scene file.
 * SCENE is a built-in name or an iris scene / importable file. */
#include <embree3/rtcore.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/parallel.h"
#include "core/rng.h"
#include "importers/import.h"
#include "renderer/accel.h"
#include "renderer/camera.h"
#include "renderer/lights.h"
#include "scenes/builtin.h"

static iris_scene *load(const char *name) {
  iris_scene *s = NULL;
  iris_error err;
  iris_error_clear(&err);
  iris_status st = iris_builtin_exists(name) ? iris_builtin_create(name, &s, &err)
                                             : iris_import_file(name, NULL, &s, &err);
  if (st != IRIS_OK) {
    fprintf(stderr, "bench_render: %s: %s\n", name, err.message);
    exit(2);
  }
  return s;
}

typedef struct raw_ctx {
  const iris_accel *accel;
  const iris_lights *lights; /* emissive triangles (lights->tris) */
  iris_pinhole cam;
  int spp;
  double p_continue; /* per hit: cast a bounce ray */
  double p_shadow;   /* per hit: cast an occlusion ray */
  bool to_emitters;  /* occlusion rays end on emissive triangles */
  uint64_t sample0;  /* first sample index (the calibration runs use others) */
  atomic_ullong rays, shadow_rays, hits, shadow_tries;
} raw_ctx;

/* An occlusion ray from p (normal n facing the arriving ray) to a point on an
 * emissive triangle that p can see from its side and that faces p (what
 * next-event estimation would cast); false after 4 tries without one. */
static bool emitter_ray(const iris_lights *L, iris_vec3 p, iris_vec3 n, iris_sampler *rng,
                        iris_ray *out) {
  for (int k = 0; k < 4; k++) {
    size_t i = (size_t)(iris_sampler_next(rng) * (float)L->tri_count);
    if (i >= L->tri_count) i = L->tri_count - 1;
    const iris_light_tri *t = &L->tris[i];
    float b0, b1;
    iris_sample_uniform_triangle(iris_sampler_next(rng), iris_sampler_next(rng), &b0, &b1);
    iris_vec3 q = iris_add(iris_v3_load(t->v0), iris_add(iris_scale(iris_v3_load(t->e1), b1),
                                                         iris_scale(iris_v3_load(t->e2), 1.0f - b0 - b1)));
    iris_vec3 ng = iris_normalize(iris_cross(iris_v3_load(t->e1), iris_v3_load(t->e2))), d = iris_sub(q, p);
    if (iris_dot(d, n) <= 0.0f) continue;
    if (!(t->flags & IRIS_LIGHT_TRI_TWO_SIDED) && iris_dot(d, ng) >= 0.0f) continue;
    *out = iris_spawn_ray_to(p, n, q, ng);
    return true;
  }
  return false;
}

static void raw_rows(void *vc, uint64_t begin, uint64_t end, int thread) {
  (void)thread;
  raw_ctx *c = (raw_ctx *)vc;
  unsigned long long rays = 0, shadow = 0, hits = 0, tries = 0;
  for (uint64_t y = begin; y < end; y++)
    for (int x = 0; x < c->cam.width; x++)
      for (int s = 0; s < c->spp; s++) {
        iris_sampler rng = iris_sampler_start(1, y * (uint64_t)c->cam.width + (uint64_t)x, c->sample0 + (uint64_t)s);
        iris_ray ray = iris_pinhole_ray(&c->cam, (float)x + iris_sampler_next(&rng), (float)y + iris_sampler_next(&rng));
        for (;;) {
          iris_hit h;
          rays++;
          if (!iris_accel_intersect(c->accel, &ray, &h)) break;
          hits++;
          iris_vec3 v[3];
          iris_accel_triangle(c->accel, h.prim, v);
          iris_vec3 n = iris_normalize(iris_cross(iris_sub(v[1], v[0]), iris_sub(v[2], v[0])));
          if (iris_dot(n, ray.d) > 0) n = iris_neg(n);
          iris_vec3 p = iris_add(ray.o, iris_scale(ray.d, h.t));
          if (c->to_emitters) {
            iris_ray sh;
            if (iris_sampler_next(&rng) < c->p_shadow && (tries++, emitter_ray(c->lights, p, n, &rng, &sh))) {
              rays++;
              shadow++;
              (void)iris_accel_occluded(c->accel, &sh);
            }
          } else {
            /* occlusion ray to a random point about one unit above */
            iris_vec3 target = iris_add(p, iris_v3(iris_sampler_next(&rng) - 0.5f, 1.0f, iris_sampler_next(&rng) - 0.5f));
            iris_ray sh = {iris_offset_origin(p, n, iris_sub(target, p)), 0.0f, iris_sub(target, p), 1.0f};
            rays++;
            shadow++;
            (void)iris_accel_occluded(c->accel, &sh);
          }
          if (iris_sampler_next(&rng) >= c->p_continue) break;
          float u0 = iris_sampler_next(&rng), u1 = iris_sampler_next(&rng);
          float r = sqrtf(u0), phi = 6.2831853f * u1;
          iris_frame f = iris_frame_from_normal(n);
          iris_vec3 d = iris_frame_to_world(&f, iris_v3(r * cosf(phi), r * sinf(phi), sqrtf(fmaxf(0.0f, 1 - u0))));
          ray.o = iris_offset_origin(p, n, d);
          ray.d = d;
          ray.tmin = 0.0f;
          ray.tmax = INFINITY;
        }
      }
  atomic_fetch_add(&c->rays, rays);
  atomic_fetch_add(&c->shadow_rays, shadow);
  atomic_fetch_add(&c->hits, hits);
  atomic_fetch_add(&c->shadow_tries, tries);
}

static void raw_run(raw_ctx *c, int threads) {
  atomic_store(&c->rays, 0);
  atomic_store(&c->shadow_rays, 0);
  atomic_store(&c->hits, 0);
  atomic_store(&c->shadow_tries, 0);
  iris_parallel_for((uint64_t)c->cam.height, 1, threads, raw_rows, c);
}

static int cmd_raw(int argc, char **argv) {
  if (argc < 8) {
    fprintf(stderr, "usage: bench_render raw SCENE THREADS SPP W H RAYS_PER_PATH [SHADOW_PER_PATH]\n");
    return 2;
  }
  iris_scene *s = load(argv[2]);
  int threads = atoi(argv[3]);
  raw_ctx c;
  memset(&c, 0, sizeof c);
  c.spp = atoi(argv[4]);
  double rays_per_path = atof(argv[7]);
  iris_error err;
  iris_pinhole_setup(s, NULL, atoi(argv[5]), atoi(argv[6]), &c.cam, &err);
  iris_accel *a = NULL;
  if (iris_accel_build(s, &a, &err) != IRIS_OK) return 1;
  c.accel = a;
  iris_textures tex;
  memset(&tex, 0, sizeof tex);
  iris_lights lights;
  if (iris_lights_build(s, a, &tex, &lights, &err) != IRIS_OK) return 1;
  c.lights = &lights;
  atomic_init(&c.rays, 0);
  atomic_init(&c.shadow_rays, 0);
  atomic_init(&c.hits, 0);
  atomic_init(&c.shadow_tries, 0);
  if (argc >= 9 && lights.tri_count > 0) {
    /* Calibrate on 1-spp runs (other sample indices than the timed run) so the
     * loop casts iris's closest-hit and occlusion rays per path: with a
     * fraction h of closest-hit rays hitting, closest per path = 1 / (1 - p h);
     * occlusion rays per hit = p_shadow * (fraction of tries finding a point). */
    double shadow_target = atof(argv[8]), closest_target = rays_per_path - shadow_target;
    c.to_emitters = true;
    c.p_continue = closest_target > 1.0 ? 1.0 - 1.0 / closest_target : 0.0;
    c.p_shadow = 1.0;
    int spp = c.spp;
    c.spp = 1;
    for (int it = 0; it < 4; it++) {
      c.sample0 = 1000000u + (uint64_t)it;
      raw_run(&c, threads);
      double paths = (double)c.cam.width * c.cam.height;
      double closest = (double)(atomic_load(&c.rays) - atomic_load(&c.shadow_rays));
      double hits = (double)atomic_load(&c.hits), tries = (double)atomic_load(&c.shadow_tries);
      double h = closest > 0 ? hits / closest : 1.0;
      double found = tries > 0 ? (double)atomic_load(&c.shadow_rays) / tries : 1.0;
      c.p_continue = iris_clampf((float)((1.0 - 1.0 / closest_target) / (h > 0 ? h : 1.0)), 0.0f, 0.98f);
      c.p_shadow = iris_clampf((float)(shadow_target / (hits / paths) / (found > 0 ? found : 1.0)), 0.0f, 1.0f);
    }
    c.spp = spp;
    c.sample0 = 0;
  } else {
    /* rays_per_path = 1 + 2 * mean bounces: closest + occlusion per hit */
    c.p_continue = 1.0 - 2.0 / (rays_per_path + 1.0);
  }
  double t0 = iris_time_now();
  raw_run(&c, threads);
  double dt = iris_time_now() - t0;
  unsigned long long rays = atomic_load(&c.rays), shadow = atomic_load(&c.shadow_rays);
  double paths = (double)c.cam.width * c.cam.height * c.spp;
  printf("{\"scene\": \"%s\", \"threads\": %d, \"seconds\": %.3f, \"rays\": %llu, \"shadow_rays\": %llu, "
         "\"rays_per_path\": %.3f, \"shadow_per_path\": %.3f, \"to_emitters\": %s, \"rays_per_second\": %.0f}\n",
         argv[2], threads, dt, rays, shadow, rays / paths, shadow / paths, c.to_emitters ? "true" : "false", rays / dt);
  iris_lights_destroy(&lights);
  iris_accel_destroy(a);
  iris_scene_destroy(s);
  return 0;
}

/* ---- flattened vs instanced -------------------------------------------- */

static atomic_llong g_bytes;
static bool monitor(void *ptr, ssize_t bytes, bool post) {
  (void)ptr, (void)post;
  atomic_fetch_add(&g_bytes, (long long)bytes);
  return true;
}

static double cast(RTCScene scene, iris_vec3 lo, iris_vec3 hi, int n) {
  iris_vec3 c = iris_scale(iris_add(lo, hi), 0.5f);
  float r = 0.5f * iris_length(iris_sub(hi, lo));
  double t0 = iris_time_now();
  int hits = 0;
  for (int i = 0; i < n; i++) {
    iris_sampler rng = iris_sampler_start(5, (uint64_t)i, 0);
    iris_vec3 o = iris_add(c, iris_scale(iris_normalize(iris_v3(iris_sampler_next(&rng) - 0.5f, iris_sampler_next(&rng) - 0.5f, iris_sampler_next(&rng) - 0.5f)), 2 * r));
    iris_vec3 t = iris_add(c, iris_scale(iris_v3(iris_sampler_next(&rng) - 0.5f, iris_sampler_next(&rng) - 0.5f, iris_sampler_next(&rng) - 0.5f), r));
    iris_vec3 d = iris_normalize(iris_sub(t, o));
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRayHit rh;
    memset(&rh, 0, sizeof rh);
    rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
    rh.ray.tfar = INFINITY;
    rh.ray.mask = ~0u;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &ctx, &rh);
    hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
  }
  (void)hits;
  return n / (iris_time_now() - t0);
}

static int cmd_instancing(int argc, char **argv) {
  if (argc < 4) {
    fprintf(stderr, "usage: bench_render instancing BUNNY.ply N\n");
    return 2;
  }
  iris_scene *s = load(argv[2]);
  int n = atoi(argv[3]);
  const iris_mesh *m = &s->meshes[0];
  int side = 1;
  while (side * side < n) side++;
  iris_vec3 lo, hi;
  iris_scene_bounds(s, &lo, &hi);
  float step = 1.2f * iris_length(iris_sub(hi, lo));
  RTCDevice dev = rtcNewDevice("verbose=0");
  rtcSetDeviceMemoryMonitorFunction(dev, monitor, NULL);
  /* flattened: n world-space copies */
  atomic_store(&g_bytes, 0);
  RTCScene flat = rtcNewScene(dev);
  rtcSetSceneBuildQuality(flat, RTC_BUILD_QUALITY_HIGH);
  for (int i = 0; i < n; i++) {
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, m->vertex_count);
    float ox = step * (float)(i % side), oz = step * (float)(i / side);
    for (uint32_t k = 0; k < m->vertex_count; k++) {
      v[3 * k] = m->positions[3 * k] + ox;
      v[3 * k + 1] = m->positions[3 * k + 1];
      v[3 * k + 2] = m->positions[3 * k + 2] + oz;
    }
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m->indices, 0, 12, m->triangle_count);
    rtcCommitGeometry(g);
    rtcAttachGeometry(flat, g);
    rtcReleaseGeometry(g);
  }
  double t0 = iris_time_now();
  rtcCommitScene(flat);
  double build_flat = iris_time_now() - t0;
  long long mem_flat = atomic_load(&g_bytes);
  /* instanced: one bottom-level scene, n instances */
  atomic_store(&g_bytes, 0);
  RTCScene blas = rtcNewScene(dev);
  rtcSetSceneBuildQuality(blas, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, m->positions, 0, 12, m->vertex_count);
  rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m->indices, 0, 12, m->triangle_count);
  rtcCommitGeometry(g);
  rtcAttachGeometry(blas, g);
  rtcReleaseGeometry(g);
  t0 = iris_time_now();
  rtcCommitScene(blas);
  RTCScene top = rtcNewScene(dev);
  for (int i = 0; i < n; i++) {
    RTCGeometry ig = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(ig, blas);
    float xf[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, step * (float)(i % side), 0, step * (float)(i / side)};
    rtcSetGeometryTransform(ig, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xf);
    rtcCommitGeometry(ig);
    rtcAttachGeometry(top, ig);
    rtcReleaseGeometry(ig);
  }
  rtcCommitScene(top);
  double build_inst = iris_time_now() - t0;
  long long mem_inst = atomic_load(&g_bytes);
  iris_vec3 wlo = lo, whi = iris_add(hi, iris_v3(step * (float)(side - 1), 0, step * (float)(side - 1)));
  int rays = 2000000;
  double rate_flat = cast(flat, wlo, whi, rays), rate_inst = cast(top, wlo, whi, rays);
  double vcopy = (double)n * m->vertex_count * 12.0;
  printf("{\"copies\": %d, \"triangles\": %llu, \"flat\": {\"bvh_bytes\": %lld, \"vertex_copy_bytes\": %.0f, \"build_s\": %.3f, \"rays_per_s_1thread\": %.0f}, "
         "\"instanced\": {\"bvh_bytes\": %lld, \"build_s\": %.3f, \"rays_per_s_1thread\": %.0f}}\n",
         n, (unsigned long long)n * m->triangle_count, mem_flat, vcopy, build_flat, rate_flat, mem_inst, build_inst, rate_inst);
  rtcReleaseScene(top);
  rtcReleaseScene(blas);
  rtcReleaseScene(flat);
  rtcReleaseDevice(dev);
  iris_scene_destroy(s);
  return 0;
}

/* The bunny (scaled to 0.9 high, on the floor) in the Cornell box without its boxes. */
static int cmd_bunny_box(int argc, char **argv) {
  if (argc < 4) {
    fprintf(stderr, "usage: bench_render write-bunny-box BUNNY.ply OUT.json\n");
    return 2;
  }
  iris_scene *box = load("cornell-box");
  iris_scene *bunny = load(argv[2]);
  /* drop the instances of the two boxes (meshes "short_box"/"tall_box") */
  size_t kept = 0;
  for (size_t i = 0; i < box->instance_count; i++)
    if (!strstr(box->meshes[box->instances[i].mesh].name, "box")) box->instances[kept++] = box->instances[i];
  box->instance_count = kept;
  iris_vec3 lo, hi;
  iris_scene_bounds(bunny, &lo, &hi);
  float sc = 0.9f / (hi.y - lo.y);
  for (size_t i = 0; i < bunny->instance_count; i++) {
    iris_mat4 t = iris_mat4_identity();
    t.m[0][0] = t.m[1][1] = t.m[2][2] = sc;
    t.m[0][3] = -sc * 0.5f * (lo.x + hi.x);
    t.m[1][3] = -sc * lo.y;
    t.m[2][3] = -sc * 0.5f * (lo.z + hi.z);
    bunny->instances[i].transform = iris_mat4_mul(&t, &bunny->instances[i].transform);
  }
  for (size_t i = 0; i < bunny->material_count; i++) {
    bunny->materials[i].type = IRIS_MATERIAL_DIFFUSE;
    bunny->materials[i].color[0] = bunny->materials[i].color[1] = bunny->materials[i].color[2] = 0.725f;
  }
  iris_error err;
  iris_error_clear(&err);
  if (iris_scene_merge(box, bunny, &err) != IRIS_OK || iris_scene_write(box, argv[3], &err) != IRIS_OK) {
    fprintf(stderr, "bench_render: %s\n", err.message);
    return 1;
  }
  iris_scene_destroy(box);
  return 0;
}

int main(int argc, char **argv) {
  if (argc >= 2 && strcmp(argv[1], "raw") == 0) return cmd_raw(argc, argv);
  if (argc >= 2 && strcmp(argv[1], "instancing") == 0) return cmd_instancing(argc, argv);
  if (argc >= 2 && strcmp(argv[1], "write-bunny-box") == 0) return cmd_bunny_box(argc, argv);
  fprintf(stderr, "usage: bench_render raw|instancing|write-bunny-box ...\n");
  return 2;
}
