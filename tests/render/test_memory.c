/* Memory (issue 20, docs/performance.md "Memory estimate"):
 *  - `iris info --json`'s estimate (memory.estimate_bytes) is within 25% of
 *    the peak RSS of `iris render --method mis` (wait4's ru_maxrss) on three
 *    scenes of different shape: the bunny (one mesh, flattened), a lumpy
 *    sphere placed 3,000 times (instanced: 59M triangles in the world) and
 *    the same sphere placed 150 times, flattened (IRIS_INSTANCE_MIN);
 *    skipped under AddressSanitizer (its shadow memory is RSS and address
 *    space of its own);
 *  - a render under an address-space limit (setrlimit RLIMIT_AS in the
 *    forked child) that the scene cannot fit ends with one line
 *    "<scene>: needs about N GB, M GB available", exit 2, no output file;
 *  - where the estimate is passed but the BVH build still runs out of address
 *    space (iris_accel_build called in a forked child under the limit), the
 *    error is one message naming what was being built, never "no error". */
#define _DEFAULT_SOURCE /* wait4, putenv */
#include <fcntl.h>
#include <stdarg.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "check.h"
#include "renderer/accel.h"
#include "renderer/memory.h"
#include "renderer/vcache.h"
#include "scene/scene.h"

static const char *iris_bin, *assets;
static char dir[512];

/* Runs iris with `args` (split at spaces) under an optional RLIMIT_AS and
 * extra environment variable; stdout and stderr to files; returns the exit
 * status (-1: killed) and the child's peak RSS in bytes. */
static int run(const char *env, rlim_t as_limit, const char *out, const char *errf, long *peak,
               const char *fmt, ...) __attribute__((format(printf, 6, 7)));
static int run(const char *env, rlim_t as_limit, const char *out, const char *errf, long *peak,
               const char *fmt, ...) {
  char args[4096];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(args, sizeof args, fmt, ap);
  va_end(ap);
  char *argv[64];
  int n = 0;
  argv[n++] = (char *)iris_bin;
  for (char *t = strtok(args, " "); t && n < 63; t = strtok(NULL, " ")) argv[n++] = t;
  argv[n] = NULL;
  pid_t pid = fork();
  if (pid == 0) {
    int fo = open(out, O_WRONLY | O_CREAT | O_TRUNC, 0644), fe = open(errf, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fo, 1);
    dup2(fe, 2);
    if (env) putenv((char *)env);
    /* glibc reserves 64 MB of address space per malloc arena (up to 8 per core):
     * keep that from deciding the RLIMIT_AS cases on machines with many cores */
    setenv("MALLOC_ARENA_MAX", "2", 1);
    if (as_limit) {
      struct rlimit rl = {as_limit, as_limit};
      setrlimit(RLIMIT_AS, &rl);
    }
    execv(iris_bin, argv);
    _exit(127);
  }
  int status = 0;
  struct rusage ru;
  memset(&ru, 0, sizeof ru);
  wait4(pid, &status, 0, &ru);
  if (peak) *peak = ru.ru_maxrss * 1024L;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static char *slurp(const char *path) {
  static char buf[1 << 16];
  buf[0] = 0;
  FILE *fp = fopen(path, "r");
  if (!fp) return buf;
  size_t n = fread(buf, 1, sizeof buf - 1, fp);
  buf[n] = 0;
  fclose(fp);
  return buf;
}

/* A lumpy UV sphere of 4 rings^2 triangles. */
static iris_mesh lumpy(int rings) {
  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.name = iris_strdup("lumpy");
  m.owned = true;
  m.material = -1;
  int seg = 2 * rings;
  m.vertex_count = (uint32_t)((seg + 1) * (rings + 1));
  m.triangle_count = (uint32_t)(2 * seg * rings);
  m.positions = malloc(3 * sizeof(float) * m.vertex_count);
  m.indices = malloc(3 * sizeof(uint32_t) * m.triangle_count);
  uint32_t v = 0;
  for (int j = 0; j <= rings; j++)
    for (int i = 0; i <= seg; i++, v++) {
      float ph = 2.0f * 3.14159265f * (float)i / (float)seg, th = 3.14159265f * (float)j / (float)rings;
      float r = 1.0f + 0.1f * sinf(7 * ph) * sinf(5 * th);
      m.positions[3 * v] = r * sinf(th) * cosf(ph);
      m.positions[3 * v + 1] = r * cosf(th) + 1.0f;
      m.positions[3 * v + 2] = -r * sinf(th) * sinf(ph);
    }
  uint32_t *ix = m.indices;
  for (int j = 0; j < rings; j++)
    for (int i = 0; i < seg; i++) {
      uint32_t a = (uint32_t)(j * (seg + 1) + i), b = a + 1, c = a + (uint32_t)(seg + 1), d = c + 1;
      *ix++ = a, *ix++ = c, *ix++ = b;
      *ix++ = b, *ix++ = c, *ix++ = d;
    }
  return m;
}

/* `count` placements of a 20,000-triangle sphere on a grid, a camera above. */
static iris_scene *forest(int count) {
  iris_scene *s = iris_scene_create();
  iris_mesh m = lumpy(70); /* 19,600 triangles */
  uint32_t mi = (uint32_t)iris_scene_add_mesh(s, &m);
  int side = (int)ceil(sqrt((double)count));
  for (int k = 0; k < count; k++) {
    iris_instance in = {mi, iris_mat4_identity()};
    in.transform.m[0][3] = 2.5f * (float)(k % side);
    in.transform.m[2][3] = -2.5f * (float)(k / side);
    float sc = 0.8f + 0.4f * (float)((k * 37) % 11) / 10.0f;
    in.transform.m[0][0] = in.transform.m[1][1] = in.transform.m[2][2] = sc;
    iris_scene_add_instance(s, &in);
  }
  iris_camera cam;
  memset(&cam, 0, sizeof cam);
  cam.name = iris_strdup("view");
  cam.to_world = iris_mat4_identity();
  cam.to_world.m[0][3] = 0.5f * 2.5f * side, cam.to_world.m[1][3] = 6.0f, cam.to_world.m[2][3] = 8.0f;
  cam.yfov = 0.8f;
  cam.aspect = 1.5f;
  iris_scene_add_camera(s, &cam);
  float sky[3] = {1, 1, 1};
  iris_scene_set_environment_color(s, sky);
  s->render.width = 300, s->render.height = 200;
  return s;
}

static double json_number(const char *text, const char *key) {
  const char *p = strstr(text, key);
  if (!p) return -1;
  p = strchr(p, ':');
  return p ? atof(p + 1) : -1;
}

static void check_estimate(const char *label, const char *scene, const char *env) {
  char out[700], errf[700], exr[700];
  snprintf(out, sizeof out, "%s/out.txt", dir);
  snprintf(errf, sizeof errf, "%s/err.txt", dir);
  snprintf(exr, sizeof exr, "%s/estimate.exr", dir);
  int rc = run(env, 0, out, errf, NULL, "info %s --json", scene);
  CHECK_EQ_INT(rc, 0);
  double est = json_number(slurp(out), "\"estimate_bytes\"");
  long peak = 0;
  rc = run(env, 0, out, errf, &peak, "render %s --method mis --spp 1 --threads 2 --quiet -o %s", scene, exr);
  if (!CHECK(rc == 0)) printf("render: %s", slurp(errf));
  double rel = (est - (double)peak) / (double)peak;
  printf("%-22s estimate %.1f MB, peak RSS %.1f MB (%+.0f%%)\n", label, est / 1e6, (double)peak / 1e6, 100 * rel);
  iris_check_record(est > 0 && fabs(rel) <= 0.25, __FILE__, __LINE__, "%s: estimate %.1f MB vs peak %.1f MB",
                    label, est / 1e6, (double)peak / 1e6);
}

static void test_estimates(void) {
  char bunny[700], inst[700], flat[700];
  snprintf(bunny, sizeof bunny, "%s/ply/stanford-bunny/bun_zipper.ply", assets);
  snprintf(inst, sizeof inst, "%s/instanced.json", dir);
  snprintf(flat, sizeof flat, "%s/flat.json", dir);
  iris_error err;
  iris_scene *a = forest(3000), *b = forest(150);
  CHECK_OK(iris_scene_write(a, inst, &err), &err);
  CHECK_OK(iris_scene_write(b, flat, &err), &err);
  iris_scene_destroy(a);
  iris_scene_destroy(b);
  check_estimate("bunny (flattened)", bunny, NULL);
  check_estimate("3000 placements", inst, NULL);
  check_estimate("150 flattened", flat, "IRIS_INSTANCE_MIN=1000000");
}

/* The guide's photon paths grow with the light groups (docs/guiding.md,
 * "Budget"), but past IRIS_LIGHTS_MAX_GROUPS emitting instances the lights
 * merge theirs into one (renderer/light_build.c): the estimate must follow,
 * or a scene of thousands of lamps is estimated at the 4M-path cap (1.2 GB)
 * and refused under a limit it fits. `count` placements of a small emitting
 * sphere, 640 x 480 (9600 caches: 96 000 paths for one group). */
static void test_light_groups(void) {
  const int counts[6] = {1, 10, 100, 2000, 10, 10};
  uint64_t guide[6];
  for (int c = 0; c < 6; c++) {
    iris_scene *s = iris_scene_create();
    /* 4: black lights and a black sky beside the 10 placements (the lights
     * build no group for them); 5: a lit point light beside them */
    if (c >= 4) {
      iris_light l = {0};
      l.type = IRIS_LIGHT_POINT;
      l.color[0] = l.color[1] = l.color[2] = 1.0f;
      l.intensity = c == 5 ? 100.0f : 0.0f;
      iris_scene_add_light(s, &l);
      l.type = IRIS_LIGHT_DIRECTIONAL;
      l.intensity = 5.0f;
      l.color[0] = l.color[1] = l.color[2] = 0.0f;
      iris_scene_add_light(s, &l);
      s->has_environment = c == 4;
      s->environment[0] = s->environment[1] = s->environment[2] = 0.0f;
    }
    iris_material mat = iris_material_default(IRIS_MATERIAL_DIFFUSE);
    mat.name = iris_strdup("lamp");
    mat.emission[0] = mat.emission[1] = mat.emission[2] = 5.0f;
    iris_mesh m = lumpy(4);
    m.material = iris_scene_add_material(s, &mat);
    uint32_t mi = (uint32_t)iris_scene_add_mesh(s, &m);
    for (int k = 0; k < counts[c]; k++) {
      iris_instance in = {mi, iris_mat4_identity()};
      in.transform.m[0][3] = 3.0f * (float)k;
      iris_scene_add_instance(s, &in);
    }
    iris_memory_estimate est;
    iris_memory_estimate_scene(s, 640, 480, true, &est);
    guide[c] = est.guide;
    printf("%5d emitting placements: guide %.1f MB\n", counts[c], (double)est.guide / 1e6);
    iris_scene_destroy(s);
  }
  CHECK(guide[1] > guide[0]);  /* ten groups: more paths than one */
  CHECK_EQ_INT(guide[2], guide[0]); /* more than 64: merged into one group */
  CHECK_EQ_INT(guide[3], guide[0]);
  CHECK_EQ_INT(guide[4], guide[1]); /* black lights and sky: no group, no sky share */
  CHECK(guide[5] > guide[1]);       /* a lit one: a group more */
}

/* Connections with the sky through a window keep their light vertices for
 * the whole render, within IRIS_VCACHE_SKY_BUDGET (renderer/vcache.h): a
 * guided estimate of a scene lit by a map holds that bound, a constant sky
 * (no window connections: they sample the map) and the methods without a
 * guide do not. */
static void test_sky_connections(void) {
  iris_memory_estimate est[3];
  for (int c = 0; c < 3; c++) {
    iris_scene *s = iris_scene_create();
    iris_material mat = iris_material_default(IRIS_MATERIAL_DIFFUSE);
    mat.name = iris_strdup("wall");
    iris_mesh m = lumpy(4);
    m.material = iris_scene_add_material(s, &mat);
    iris_instance in = {(uint32_t)iris_scene_add_mesh(s, &m), iris_mat4_identity()};
    iris_scene_add_instance(s, &in);
    s->has_environment = true;
    s->environment[0] = s->environment[1] = s->environment[2] = 1.0f;
    if (c != 1) CHECK(iris_scene_set_environment_map(s, "sky.hdr", 1.0f, 0.0f));
    iris_memory_estimate_scene(s, 640, 480, c != 2, &est[c]);
    iris_scene_destroy(s);
  }
  printf("sky connections: %.1f MB of a %.1f MB guide (constant sky: guide %.1f MB)\n", (double)est[0].connect / 1e6,
         (double)est[0].guide / 1e6, (double)est[1].guide / 1e6);
  CHECK_EQ_INT(est[0].connect, IRIS_VCACHE_SKY_BUDGET);
  CHECK_EQ_INT(est[0].guide - est[1].guide, IRIS_VCACHE_SKY_BUDGET); /* both a sky group */
  CHECK_EQ_INT(est[1].connect, 0);
  CHECK_EQ_INT(est[2].connect, 0);
  CHECK_EQ_INT(est[2].guide, 0);
}

static void test_refused(void) {
  char out[700], errf[700], exr[700], flat[700];
  snprintf(out, sizeof out, "%s/out.txt", dir);
  snprintf(errf, sizeof errf, "%s/err.txt", dir);
  snprintf(exr, sizeof exr, "%s/refused.exr", dir);
  snprintf(flat, sizeof flat, "%s/big.json", dir);
  iris_error err;
  iris_scene *s = forest(1200); /* 24M triangles: about 2.4 GB flattened */
  CHECK_OK(iris_scene_write(s, flat, &err), &err);
  iris_scene_destroy(s);
  /* 1.2 GB of address space: iris itself fits, the flattened BVH does not */
  int rc = run("IRIS_INSTANCE_MIN=1000000", (rlim_t)1200 << 20, out, errf, NULL, "render %s --spp 1 --threads 2 --quiet -o %s",
               flat, exr);
  const char *e = slurp(errf);
  int lines = 0;
  for (const char *p = e; *p; p++) lines += *p == '\n';
  printf("refused: exit %d, stderr: %s", rc, e);
  CHECK_EQ_INT(rc, 2);
  CHECK(strstr(e, "big.json: needs about ") != NULL && strstr(e, "GB available") != NULL);
  CHECK(strstr(e, "no error") == NULL);
  CHECK_EQ_INT(lines, 1);
  struct stat st;
  CHECK(stat(exr, &st) != 0); /* no output file */
  /* the same scene instanced fits in the same limit and renders */
  rc = run(NULL, (rlim_t)1200 << 20, out, errf, NULL, "render %s --spp 1 --width 32 --height 24 --threads 2 --quiet -o %s",
           flat, exr);
  CHECK_EQ_INT(rc, 0);
  CHECK(stat(exr, &st) == 0);
}

/* The build itself under the limit, past the estimate: one message naming it. */
static void test_embree_oom(void) {
  iris_scene *s = forest(1200);
  int fds[2];
  if (pipe(fds) != 0) return;
  pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    setenv("IRIS_INSTANCE_MIN", "1000000", 1);
    struct rlimit rl = {(rlim_t)900 << 20, (rlim_t)900 << 20};
    setrlimit(RLIMIT_AS, &rl);
    iris_accel *a = NULL;
    iris_error err;
    iris_error_clear(&err);
    iris_status st = iris_accel_build(s, &a, &err);
    char msg[1400];
    iris_error_format(&err, msg, sizeof msg);
    if (write(fds[1], msg, strlen(msg)) < 0) _exit(3);
    _exit(st == IRIS_ERR_NOMEM ? 0 : st == IRIS_OK ? 1 : 2);
  }
  close(fds[1]);
  char msg[1500] = "";
  ssize_t n = read(fds[0], msg, sizeof msg - 1);
  msg[n > 0 ? n : 0] = 0;
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  printf("accel build under 900 MB: exit %d, \"%s\"\n", WIFEXITED(status) ? WEXITSTATUS(status) : -1, msg);
  CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  CHECK(strstr(msg, "out of memory") != NULL &&
        (strstr(msg, "lumpy") != NULL || strstr(msg, "top-level BVH (1200 placements") != NULL));
  CHECK(strstr(msg, "no error") == NULL && strchr(msg, '\n') == NULL);
  iris_scene_destroy(s);
}

#if defined(__SANITIZE_ADDRESS__)
#define IRIS_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define IRIS_ASAN 1
#endif
#endif

int main(int argc, char **argv) {
#ifdef IRIS_ASAN
  (void)argc, (void)argv;
  return TEST_SKIP("address-space limits and peak RSS mean nothing under AddressSanitizer");
#endif
  if (argc < 3) return TEST_SKIP("usage: test_render_memory IRIS ASSETS");
  iris_bin = argv[1];
  assets = argv[2];
  if (iris_test_tmpdir(dir, sizeof dir, "memory") != 0) return TEST_SKIP("no temporary directory");
  test_light_groups();
  test_sky_connections();
  test_embree_oom();
  test_refused();
  test_estimates();
  iris_test_rmtree(dir);
  return TEST_SUMMARY();
}
