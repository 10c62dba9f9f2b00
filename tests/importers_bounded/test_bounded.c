/* Importers do bounded work (docs/fuzzing.md, "Bounded work").
 *
 *   test_bounded findings FILE...        every shared/fuzz-findings input imports (or is
 *                                        refused) with triangulation work linear in its corners
 *   test_bounded scaling                 each generated worst case, imported at 2x and 8x its
 *                                        size (both past the caches: the OBJ grid steps out of
 *                                        them between 1x and 2x), takes at most 2.5 x the size
 *                                        ratio in CPU time (linear: 4x, quadratic: 16x); a
 *                                        ratio within one run, not a timing
 *   test_bounded report                  CPU seconds per MB of every case against normal files
 *                                        (the table in docs/performance.md)
 *   test_bounded write KIND SCALE FILE   writes one generated input (KIND: the enum below)
 *
 * The worst cases: degenerate n-gons (PLY and OBJ), one OBJ position with many
 * texture coordinates, many OBJ groups, a glTF whose primitives share one
 * vertex buffer and slices of one index buffer, many glTF nodes instancing one
 * mesh (with the scene bounds the exporters compute), a scene object with many keys. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <sys/resource.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "core/log.h"
#include "importers/import.h"
#include "importers/triangulate.h"

/* ---- a growable text/binary buffer ---------------------------------------- */

typedef struct buf {
  char *p;
  size_t n, cap;
} buf;

static void put(buf *b, const void *data, size_t n) {
  if (b->n + n + 1 > b->cap) {
    while (b->n + n + 1 > b->cap) b->cap = b->cap ? 2 * b->cap : 1 << 16;
    b->p = realloc(b->p, b->cap);
    if (!b->p) abort();
  }
  memcpy(b->p + b->n, data, n);
  b->n += n;
  b->p[b->n] = 0;
}

static void putf(buf *b, const char *fmt, ...) {
  char tmp[512];
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
  va_end(ap);
  put(b, tmp, (size_t)n);
}

static uint64_t rng;
static double uniform(void) {
  rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
  return (double)(rng >> 11) / 9007199254740992.0;
}

/* ---- generators: scale 1 is about 0.25-1 MB ------------------------------- */

/* Like shared/fuzz-findings/ply-degenerate-ngons.ply: n-gons of 3,000 corners
 * drawn from 1,000 of the vertices (repeats, crossings, no ears). */
static void gen_ngons(buf *b, int scale, bool obj) {
  const int nv = 4000, polys = 8 * scale, n = 3000, pool = 1000;
  rng = 12345;
  if (obj) putf(b, "# degenerate n-gons\n");
  else
    putf(b, "ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
            "property float z\nelement face %d\nproperty list ushort int vertex_indices\nend_header\n",
         nv, polys);
  for (int i = 0; i < nv; i++) putf(b, obj ? "v %.5f %.5f %.5f\n" : "%.5f %.5f %.5f\n", uniform(), uniform(), uniform());
  int ids[1000];
  for (int p = 0; p < polys; p++) {
    for (int k = 0; k < pool; k++) ids[k] = (int)(uniform() * nv);
    putf(b, obj ? "f" : "%d", n);
    for (int k = 0; k < n; k++) putf(b, " %d", ids[(int)(uniform() * pool)] + (obj ? 1 : 0));
    putf(b, "\n");
  }
}

/* Every triangle uses positions 1-3 with its own texture coordinates. */
static void gen_obj_shared_position(buf *b, int scale) {
  const int n = 100000 * scale;
  putf(b, "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  for (int i = 0; i < n; i++) putf(b, "vt %d %d\n", i % 1000, i / 1000);
  for (int i = 1; i <= n; i++) putf(b, "f 1/%d 2/%d 3/%d\n", i, i, i);
}

/* One triangle per group, every group named differently. */
static void gen_obj_groups(buf *b, int scale) {
  const int n = 64000 * scale;
  putf(b, "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  for (int i = 0; i < n; i++) putf(b, "g g%d\nusemtl m%d\nf 1 2 3\n", i, i % 7);
}

/* Normal files: a grid of quads (OBJ, ASCII PLY). */
static void gen_grid(buf *b, int scale, bool obj) {
  const int w = 100 * scale, h = 100;
  if (!obj)
    putf(b, "ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
            "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n",
         (w + 1) * (h + 1), w * h);
  for (int j = 0; j <= h; j++)
    for (int i = 0; i <= w; i++)
      putf(b, obj ? "v %.5f %.5f %.5f\n" : "%.5f %.5f %.5f\n", i / (double)w, j / (double)h, 0.01 * sin(i + j));
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      const int a = j * (w + 1) + i, o = obj ? 1 : 0;
      putf(b, obj ? "f %d %d %d %d\n" : "4 %d %d %d %d\n", a + o, a + 1 + o, a + w + 2 + o, a + w + 1 + o);
    }
}

/* A binary glTF: a grid of (w + 1) x 65 vertices in one POSITION accessor,
 * its triangles in one index bufferView; `prims` primitives each draw a slice
 * of it through their own index accessor and all share the vertices; `nodes`
 * root nodes instance the mesh. */
static void gen_gltf(buf *b, int scale, int prims_per_scale, int nodes) {
  const int w = 512 * scale, h = 64, prims = prims_per_scale * scale;
  const size_t nv = (size_t)(w + 1) * (h + 1), nt = 2 * (size_t)w * h;
  buf bin = {0};
  for (int j = 0; j <= h; j++)
    for (int i = 0; i <= w; i++) {
      const float p[3] = {(float)i / w, (float)j / h, 0};
      put(&bin, p, sizeof p);
    }
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      const uint32_t a = (uint32_t)(j * (w + 1) + i), t[6] = {a, a + 1, a + w + 2, a, a + w + 2, a + w + 1};
      put(&bin, t, sizeof t);
    }
  buf js = {0};
  putf(&js, "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu}],", bin.n);
  putf(&js, "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu},", 12 * nv);
  putf(&js, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}],", 12 * nv, 12 * nt);
  putf(&js, "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\","
            "\"min\":[0,0,0],\"max\":[1,1,0]}", nv);
  const size_t per = nt / (size_t)prims;
  for (int p = 0; p < prims; p++) {
    const size_t count = p + 1 == prims ? nt - per * (size_t)(prims - 1) : per;
    putf(&js, ",{\"bufferView\":1,\"byteOffset\":%zu,\"componentType\":5125,\"count\":%zu,\"type\":\"SCALAR\"}",
         12 * per * (size_t)p, 3 * count);
  }
  putf(&js, "],\"meshes\":[{\"primitives\":[");
  for (int p = 0; p < prims; p++) putf(&js, "%s{\"attributes\":{\"POSITION\":0},\"indices\":%d}", p ? "," : "", p + 1);
  putf(&js, "]}],\"nodes\":[");
  for (int i = 0; i < nodes; i++) putf(&js, "%s{\"mesh\":0,\"translation\":[%d,0,0]}", i ? "," : "", i);
  putf(&js, "],\"scenes\":[{\"nodes\":[");
  for (int i = 0; i < nodes; i++) putf(&js, "%s%d", i ? "," : "", i);
  putf(&js, "]}],\"scene\":0}");
  while (js.n % 4) put(&js, " ", 1);
  while (bin.n % 4) put(&bin, "", 1);
  const uint32_t header[3] = {0x46546C67u, 2, (uint32_t)(12 + 8 + js.n + 8 + bin.n)};
  const uint32_t jh[2] = {(uint32_t)js.n, 0x4E4F534Au}, bh[2] = {(uint32_t)bin.n, 0x004E4942u};
  put(b, header, sizeof header);
  put(b, jh, sizeof jh);
  put(b, js.p, js.n);
  put(b, bh, sizeof bh);
  put(b, bin.p, bin.n);
  free(js.p), free(bin.p);
}

/* 256 x scale accessors of 16384 x scale vertices, each with sparse
 * substitutions through the same index and value views (all read at validation). */
static void gen_gltf_sparse(buf *b, int scale) {
  const size_t nv = 16384 * (size_t)scale, na = 256 * (size_t)scale;
  buf bin = {0};
  for (size_t i = 0; i < nv; i++) {
    const float p[3] = {(float)(i % 64), (float)(i / 64), 0};
    put(&bin, p, sizeof p);
  }
  for (uint32_t i = 0; i < nv; i++) put(&bin, &i, sizeof i);
  for (size_t i = 0; i < nv; i++) {
    const float p[3] = {(float)(i % 64), (float)(i / 64), 1};
    put(&bin, p, sizeof p);
  }
  buf js = {0};
  putf(&js, "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":["
            "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},"
            "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}],\"accessors\":[",
       bin.n, 12 * nv, 12 * nv, 4 * nv, 16 * nv, 12 * nv);
  for (size_t a = 0; a < na; a++)
    putf(&js, "%s{\"bufferView\":0,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\",\"min\":[0,0,0],"
              "\"max\":[63,%zu,1],\"sparse\":{\"count\":%zu,\"indices\":{\"bufferView\":1,\"componentType\":5125},"
              "\"values\":{\"bufferView\":2}}}",
         a ? "," : "", nv, nv / 64, nv);
  putf(&js, "],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"mode\":4}]}],"
            "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],\"scene\":0}");
  while (js.n % 4) put(&js, " ", 1);
  const uint32_t header[3] = {0x46546C67u, 2, (uint32_t)(12 + 8 + js.n + 8 + bin.n)};
  const uint32_t jh[2] = {(uint32_t)js.n, 0x4E4F534Au}, bh[2] = {(uint32_t)bin.n, 0x004E4942u};
  put(b, header, sizeof header);
  put(b, jh, sizeof jh);
  put(b, js.p, js.n);
  put(b, bh, sizeof bh);
  put(b, bin.p, bin.n);
  free(js.p), free(bin.p);
}

/* A scene whose top-level object has many (unknown) keys. */
static void gen_scene_keys(buf *b, int scale) {
  const int n = 160000 * scale;
  putf(b, "{\"format\":\"iris-scene\",\"version\":1");
  for (int i = 0; i < n; i++) putf(b, ",\"k%d\":%d", i, i);
  putf(b, "}\n");
}

typedef enum kind {
  PLY_NGONS, OBJ_NGONS, OBJ_SHARED_POSITION, OBJ_GROUPS, GLTF_SHARED, GLTF_INSTANCES, GLTF_SPARSE,
  SCENE_KEYS, /* worst cases */
  PLY_GRID, OBJ_GRID, GLTF_ONE,                                                     /* normal files */
  KIND_COUNT
} kind;
static const char *kind_name[] = {"ply: degenerate n-gons", "obj: degenerate n-gons",
                                  "obj: one position, many vt", "obj: many groups",
                                  "glTF: primitives sharing buffers", "glTF: many nodes, one mesh",
                                  "glTF: accessors sharing sparse views",
                                  "scene: object with many keys",
                                  "ply: quad grid (normal)", "obj: quad grid (normal)",
                                  "glTF: one primitive (normal)"};
static const char *kind_ext[] = {"ply", "obj", "obj", "obj", "glb", "glb", "glb", "json", "ply", "obj", "glb"};
/* Kinds a valid importer refuses (at least at 4x): only their time is checked. */
static bool may_refuse(int k) { return k == GLTF_SPARSE; }

static void generate(kind k, int scale, buf *b) {
  switch (k) {
    case PLY_NGONS: gen_ngons(b, scale, false); break;
    case OBJ_NGONS: gen_ngons(b, scale, true); break;
    case OBJ_SHARED_POSITION: gen_obj_shared_position(b, scale); break;
    case OBJ_GROUPS: gen_obj_groups(b, scale); break;
    case GLTF_SHARED: gen_gltf(b, 4 * scale, 16, 1); break;
    case GLTF_INSTANCES: gen_gltf(b, scale, 1, 4096 * scale); break;
    case GLTF_SPARSE: gen_gltf_sparse(b, scale); break;
    case SCENE_KEYS: gen_scene_keys(b, scale); break;
    case PLY_GRID: gen_grid(b, 16 * scale, false); break;
    case OBJ_GRID: gen_grid(b, 16 * scale, true); break;
    case GLTF_ONE: gen_gltf(b, 8 * scale, 1, 1); break;
    default: break;
  }
}

/* User CPU time: the importer's own work. The kernel's share (page faults,
 * and on this VM the memory reclaim that runs when a process grows) is left
 * out: it grew the 73 MB OBJ grid's time 11-12x for 4.14x the size while its
 * user time stays linear, and no importer code can be super-linear there. */
static double cpu_now(void) {
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec;
}

static char g_dir[256];

/* Imports b as a file of kind k; returns its status, fills stats. */
static iris_status import_buf(kind k, const buf *b, iris_import_stats *stats) {
  iris_import_options opts = iris_import_options_default();
  opts.stats = stats;
  iris_scene *s = NULL;
  iris_error err;
  iris_error_clear(&err);
  iris_status st;
  if (!strcmp(kind_ext[k], "obj")) st = iris_import_obj_memory(b->p, b->n, NULL, &opts, &s, &err);
  else if (!strcmp(kind_ext[k], "ply")) st = iris_import_ply_memory(b->p, b->n, NULL, &opts, &s, &err);
  else if (!strcmp(kind_ext[k], "glb")) st = iris_import_gltf_memory(b->p, b->n, NULL, &opts, &s, &err);
  else {
    char path[512];
    snprintf(path, sizeof path, "%s/scene.json", g_dir);
    FILE *f = fopen(path, "wb");
    if (!f) return IRIS_ERR_IO;
    fwrite(b->p, 1, b->n, f);
    fclose(f);
    st = iris_import_file(path, &opts, &s, &err);
    unlink(path);
  }
  if (st != IRIS_OK && !may_refuse(k)) printf("  %s: %s\n", kind_name[k], err.message);
  iris_vec3 lo, hi; /* what framing and the exporters compute next */
  if (st == IRIS_OK && k != SCENE_KEYS) CHECK(iris_scene_bounds(s, &lo, &hi));
  iris_scene_destroy(s);
  return st;
}

/* Best of `reps` CPU times of importing kind k at `scale`. */
static double time_import(kind k, int scale, int reps, size_t *bytes, iris_status *st) {
  buf b = {0};
  generate(k, scale, &b);
  *bytes = b.n;
  double best = INFINITY;
  for (int r = 0; r < reps; r++) {
    iris_import_stats stats;
    memset(&stats, 0, sizeof stats);
    const double t0 = cpu_now();
    *st = import_buf(k, &b, &stats);
    const double dt = cpu_now() - t0;
    best = dt < best ? dt : best;
  }
  free(b.p);
  return best;
}

static void check_scaling(void) {
  for (int k = 0; k < KIND_COUNT; k++) {
    /* Up to three tries: other jobs on the machine can slow one run down;
     * super-linear work fails every try. */
    bool ok = false;
    for (int attempt = 0; attempt < 3 && !ok; attempt++) {
      size_t b1, b4;
      iris_status s1, s4;
      const double t1 = time_import((kind)k, 2, 3, &b1, &s1), t4 = time_import((kind)k, 8, 3, &b4, &s4);
      const double ratio = t4 / fmax(t1, 1e-6), size_ratio = (double)b4 / (double)b1;
      printf("%-34s %6.2f MB -> %6.2f MB: CPU %.3f s -> %.3f s, x%.2f for x%.2f the size\n", kind_name[k],
             b1 / 1e6, b4 / 1e6, t1, t4, ratio, size_ratio);
      /* Linear work gives a ratio near size_ratio (about 4; caches and page
       * faults can add a factor of 2), quadratic work about 16. */
      ok = ((s1 == IRIS_OK && s4 == IRIS_OK) || may_refuse(k)) && ratio < 2.5 * size_ratio;
    }
    CHECK(ok);
  }
}

static void report(void) {
  printf("| input | MB | CPU s | CPU s per MB |\n|---|---:|---:|---:|\n");
  for (int k = 0; k < KIND_COUNT; k++) {
    size_t bytes;
    iris_status st;
    const double t = time_import((kind)k, 4, 3, &bytes, &st);
    printf("| %s | %.2f | %.3f | %.3f%s |\n", kind_name[k], bytes / 1e6, t, t / (bytes / 1e6),
           st == IRIS_OK ? "" : " (refused)");
  }
}

/* Every finding imports (or is refused with an error) and its triangulation
 * stays within the budget: work linear in its corners, not a timing. */
static void check_findings(int count, char **paths) {
  for (int i = 0; i < count; i++) {
    iris_import_stats stats;
    memset(&stats, 0, sizeof stats);
    iris_import_options opts = iris_import_options_default();
    opts.stats = &stats;
    iris_scene *s = NULL;
    iris_error err;
    iris_error_clear(&err);
    const iris_status st = iris_import_file(paths[i], &opts, &s, &err);
    iris_scene_destroy(s);
    const double per_corner = stats.polygon_corners ? (double)stats.triangulation_steps / stats.polygon_corners : 0;
    printf("%s: %s; %llu polygons, %llu corners, %llu triangulation steps (%.1f per corner), %llu fanned\n",
           paths[i], st == IRIS_OK ? "imported" : err.message, (unsigned long long)stats.polygons,
           (unsigned long long)stats.polygon_corners, (unsigned long long)stats.triangulation_steps, per_corner,
           (unsigned long long)stats.triangulation_fallbacks);
    CHECK(st == IRIS_OK || st == IRIS_ERR_PARSE || st == IRIS_ERR_INVALID || st == IRIS_ERR_UNSUPPORTED);
    /* The file's budget (triangulate.h), plus per corner what is done before
     * any budget check (normal, projection, classification), what the last
     * test may overrun it by and the fan of the rest: 8 steps. */
    const uint64_t bound = (uint64_t)(IRIS_TRIANGULATE_FILE_STEPS_PER_CORNER + 8) * stats.polygon_corners +
                           IRIS_TRIANGULATE_FILE_STEPS_BASE;
    CHECK(stats.triangulation_steps <= bound);
  }
}

int main(int argc, char **argv) {
  if (argc < 2) return TEST_SKIP("usage: test_bounded findings FILE... | scaling | report");
  iris_log_set_level(IRIS_LOG_QUIET);
  const char *root = getenv("TMPDIR");
  snprintf(g_dir, sizeof g_dir, "%s/iris-bounded-XXXXXX", root && root[0] ? root : "/tmp");
  if (!mkdtemp(g_dir)) return TEST_SKIP("cannot create a temporary folder");
  if (!strcmp(argv[1], "findings")) check_findings(argc - 2, argv + 2);
  else if (!strcmp(argv[1], "scaling")) check_scaling();
  else if (!strcmp(argv[1], "report")) report();
  else if (!strcmp(argv[1], "write") && argc == 5) { /* write KIND SCALE FILE: one generated input */
    buf b = {0};
    generate((kind)atoi(argv[2]), atoi(argv[3]), &b);
    FILE *f = fopen(argv[4], "wb");
    CHECK(f && fwrite(b.p, 1, b.n, f) == b.n);
    if (f) fclose(f);
    free(b.p);
  }
  rmdir(g_dir);
  return TEST_SUMMARY();
}
