/* merge.library: partitioned renders and their exact merge.
 *  - synthetic parts built from known sample streams merge to the mean and
 *    variance of all samples computed directly (two-pass, double);
 *  - a windowed render equals the same window of the full render bit for bit
 *    (film sums), because pixels keep their full-frame sampler index;
 *  - sample partitions (uneven, different thread counts) and tiles merge to
 *    the single render to float rounding, for mis, for the guided method and
 *    for guided-nee with training passes
 *    (same seed -> same caches on every node);
 *  - parts that do not belong together are refused with a clear message;
 *  - the scene hash is stable across a JSON round trip and sees a changed value. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "render_run.h"
#include "core/fileio.h"
#include "core/rng.h"
#include "renderer/guiding/guiding.h"
#include "renderer/merge.h"
#include "renderer/render.h"
#include "scenes/builtin.h"

static char g_dir[512];

static void path_in(char *out, size_t size, const char *name) {
  snprintf(out, size, "%s/%s", g_dir, name);
}

/* ---- synthetic parts from known samples --------------------------------- */

#define SW 5
#define SH 4
#define SN 12

static double sample_value(int pixel, int s, int c) {
  /* heavy-tailed, different scale per pixel/channel: -log(u) * scale */
  iris_sampler r = iris_sampler_start(99, (uint64_t)pixel, (uint64_t)s);
  double u = 1.0 - (double)iris_sampler_get(&r, (uint32_t)c);
  return -log(u) * (1.0 + pixel % 7) * (c + 1) * 0.37;
}

static void set_meta(iris_image_meta *m, const char *k, const char *v) {
  snprintf(m->key, sizeof m->key, "%s", k);
  snprintf(m->value, sizeof m->value, "%s", v);
}

/* A part over window (x0,y0,x1,y1), samples [s0, s1), as film.c would store
 * it: float mean and float variance of the mean (s^2 / n, 0 when n = 1). */
static void add_synthetic_part(iris_merge *m, int x0, int y0, int x1, int y1, int s0, int s1) {
  static const char *const names[6] = {"R", "G", "B", "var.R", "var.G", "var.B"};
  iris_image img;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_image_create(&img, x1 - x0, y1 - y0, 6, names, &err), &err);
  int n = s1 - s0;
  for (int y = y0; y < y1; y++)
    for (int x = x0; x < x1; x++) {
      float *px = img.data + ((size_t)(y - y0) * (size_t)img.width + (size_t)(x - x0)) * 6;
      for (int c = 0; c < 3; c++) {
        double mu = 0.0, ss = 0.0;
        for (int s = s0; s < s1; s++) mu += sample_value(y * SW + x, s, c);
        mu /= n;
        for (int s = s0; s < s1; s++) {
          double d = sample_value(y * SW + x, s, c) - mu;
          ss += d * d;
        }
        px[c] = (float)mu;
        px[3 + c] = n > 1 ? (float)(ss / (n - 1) / n) : 0.0f;
      }
    }
  iris_image_meta meta[8];
  char spp[16], off[16], win[64];
  snprintf(spp, sizeof spp, "%d", n);
  snprintf(off, sizeof off, "%d", s0);
  snprintf(win, sizeof win, "%d,%d,%d,%d", x0, y0, x1, y1);
  set_meta(&meta[0], "iris:method", "mis");
  set_meta(&meta[1], "iris:seed", "5");
  set_meta(&meta[2], "iris:spp", spp);
  set_meta(&meta[3], "iris:sample_offset", off);
  set_meta(&meta[4], "iris:window", win);
  set_meta(&meta[5], "iris:full_size", "5,4");
  set_meta(&meta[6], "iris:scene_hash", "abcdef");
  set_meta(&meta[7], "iris:config_hash", "1234");
  char name[64];
  snprintf(name, sizeof name, "w%d%d%d%d-s%d-%d", x0, y0, x1, y1, s0, s1);
  CHECK_OK(iris_merge_add(m, name, &img, meta, 8, &err), &err);
  iris_image_destroy(&img);
}

static void test_synthetic(int order) {
  iris_merge m;
  iris_merge_init(&m);
  /* window A: columns 0-2, samples split 0-4 | 5-11; window B: columns 3-4,
   * samples split 0 | 1 | 2-11 (a one-sample part has no variance information
   * but its single sample is its mean); added in two different orders */
  if (order == 0) {
    add_synthetic_part(&m, 0, 0, 3, SH, 0, 5);
    add_synthetic_part(&m, 0, 0, 3, SH, 5, SN);
    add_synthetic_part(&m, 3, 0, SW, SH, 0, 1);
    add_synthetic_part(&m, 3, 0, SW, SH, 1, 2);
    add_synthetic_part(&m, 3, 0, SW, SH, 2, SN);
  } else {
    add_synthetic_part(&m, 3, 0, SW, SH, 2, SN);
    add_synthetic_part(&m, 0, 0, 3, SH, 5, SN);
    add_synthetic_part(&m, 3, 0, SW, SH, 1, 2);
    add_synthetic_part(&m, 0, 0, 3, SH, 0, 5);
    add_synthetic_part(&m, 3, 0, SW, SH, 0, 1);
  }
  iris_image out;
  iris_image_meta *meta = NULL;
  size_t mc = 0;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_merge_finish(&m, &out, &meta, &mc, &err), &err);
  CHECK_EQ_INT(out.width, SW);
  CHECK_EQ_INT(out.height, SH);
  CHECK_EQ_INT(out.channel_count, 6);
  double worst_mean = 0.0, worst_var = 0.0;
  for (int p = 0; p < SW * SH; p++)
    for (int c = 0; c < 3; c++) {
      double mu = 0.0, ss = 0.0;
      for (int s = 0; s < SN; s++) mu += sample_value(p, s, c);
      mu /= SN;
      for (int s = 0; s < SN; s++) ss += (sample_value(p, s, c) - mu) * (sample_value(p, s, c) - mu);
      double var = ss / (SN - 1) / SN;
      double em = fabs(out.data[p * 6 + c] - mu) / mu, ev = fabs(out.data[p * 6 + 3 + c] - var) / var;
      if (em > worst_mean) worst_mean = em;
      if (ev > worst_var) worst_var = ev;
    }
  /* float storage of each part (2^-24 relative) is the only rounding */
  CHECK(worst_mean < 3.0 * FLT_EPSILON);
  CHECK(worst_var < 1e-5);
  printf("synthetic (order %d): worst relative error mean %.2g, variance %.2g\n", order,
         worst_mean, worst_var);
  bool spp = false, off = false, win = false;
  for (size_t i = 0; i < mc; i++) {
    if (strcmp(meta[i].key, "iris:spp") == 0) spp = strcmp(meta[i].value, "12") == 0;
    if (strcmp(meta[i].key, "iris:sample_offset") == 0) off = strcmp(meta[i].value, "0") == 0;
    if (strcmp(meta[i].key, "iris:window") == 0) win = strcmp(meta[i].value, "0,0,5,4") == 0;
  }
  CHECK(spp && off && win);
  free(meta);
  iris_image_destroy(&out);
  iris_merge_destroy(&m);
}

/* Parts whose metadata is missing or inconsistent are refused before any
 * accumulation. */
static void expect_bad_meta(const char *key, const char *value, const char *needle) {
  static const char *const names[3] = {"R", "G", "B"};
  iris_image img;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_image_create(&img, 4, 3, 3, names, &err), &err);
  iris_image_meta meta[6];
  set_meta(&meta[0], "iris:method", "mis");
  set_meta(&meta[1], "iris:seed", "1");
  set_meta(&meta[2], "iris:spp", "4");
  set_meta(&meta[3], "iris:scene_hash", "ab");
  set_meta(&meta[4], "iris:window", "0,0,4,3");
  set_meta(&meta[5], "iris:full_size", "4,3");
  size_t n = 6;
  for (size_t i = 0; i < n; i++)
    if (strcmp(meta[i].key, key) == 0) {
      if (value)
        set_meta(&meta[i], key, value);
      else
        meta[i] = meta[--n];
    }
  iris_merge m;
  iris_merge_init(&m);
  iris_status st = iris_merge_add(&m, "bad.exr", &img, meta, n, &err);
  iris_check_record(st == IRIS_ERR_INVALID && strstr(err.message, needle) != NULL, __FILE__,
                    __LINE__, "%s=%s: status %s, message '%s' (want '%s')", key,
                    value ? value : "(absent)", iris_status_name(st), err.message, needle);
  iris_merge_destroy(&m);
  iris_image_destroy(&img);
}

static void test_bad_metadata(void) {
  expect_bad_meta("iris:scene_hash", NULL, "no iris:scene_hash");
  expect_bad_meta("iris:spp", NULL, "not an iris render");
  expect_bad_meta("iris:spp", "0", "not a sample count");
  expect_bad_meta("iris:spp", "4x", "not a sample count");
  expect_bad_meta("iris:window", "0,0,5,3", "outside the 4x3 frame");
  expect_bad_meta("iris:window", "0,0,2,3", "image is 4x3 but its window");
  expect_bad_meta("iris:window", "0,0,4", "not x0,y0,x1,y1");
  expect_bad_meta("iris:full_size", "65536,65536", "larger than any iris film");
  expect_bad_meta("iris:full_size", "-4,3", "not W,H");
}

/* ---- real renders ---------------------------------------------------------- */

typedef struct job {
  iris_method method;
  uint64_t seed;
  int spp, max_depth, threads;
  uint64_t offset;
  iris_pixel_bounds bounds;
} job;

static iris_guiding_params g_gp;
static iris_light_sampler g_light_sampler = IRIS_LIGHT_SAMPLER_DEFAULT; /* of every render_to */

static bool render_to(const iris_scene *s, job j, const char *name, iris_render_result *keep) {
  /* 40 x 24: not a multiple of the 8-pixel tiles */
  iris_render_params p = iris_test_params(40, 24, j.spp, j.method, j.seed);
  p.max_depth = j.max_depth;
  p.threads = j.threads;
  p.sample_offset = j.offset;
  p.bounds = j.bounds;
  p.light_sampler = g_light_sampler;
  iris_test_attach_guide(&p, &g_gp);
  iris_render_result r;
  if (!CHECK(iris_test_render(s, &p, &r))) return false;
  char path[600];
  path_in(path, sizeof path, name);
  iris_error err;
  iris_error_clear(&err);
  iris_status st = iris_render_write_exr(&r, path, "test", true, &err);
  CHECK_OK(st, &err);
  if (keep)
    *keep = r;
  else
    iris_render_result_destroy(&r);
  return st == IRIS_OK;
}

static iris_status merge_names(const char *const *names, size_t n, const char *out,
                               iris_error *err) {
  char paths[16][600];
  const char *pp[16];
  for (size_t i = 0; i < n; i++) {
    path_in(paths[i], sizeof paths[i], names[i]);
    pp[i] = paths[i];
  }
  char o[600];
  path_in(o, sizeof o, out);
  iris_error_clear(err);
  return iris_merge_files(pp, n, o, NULL, err);
}

/* Compares two EXRs of this dir: means within `ulps` float steps (0: bit for
 * bit), variances within relative `var_tol`. */
static void compare(const char *a, const char *b, int ulps, double var_tol, const char *what) {
  char pa[600], pb[600];
  path_in(pa, sizeof pa, a);
  path_in(pb, sizeof pb, b);
  iris_image ia, ib;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_exr_read(pa, &ia, NULL, NULL, &err), &err);
  CHECK_OK(iris_exr_read(pb, &ib, NULL, NULL, &err), &err);
  if (!CHECK(ia.width == ib.width && ia.height == ib.height && ia.channel_count == 6 &&
             ib.channel_count == 6))
    return;
  double worst_mean = 0.0, worst_var = 0.0;
  long differ = 0;
  size_t n = (size_t)ia.width * (size_t)ia.height;
  for (size_t i = 0; i < n; i++)
    for (int c = 0; c < 3; c++) {
      float x = ia.data[i * 6 + c], y = ib.data[i * 6 + c];
      double scale = fmax(fabs(x), fabs(y));
      double e = scale > 0 ? fabs((double)x - y) / (scale * FLT_EPSILON) : 0.0;
      if (x != y) differ++;
      if (e > worst_mean) worst_mean = e;
      float vx = ia.data[i * 6 + 3 + c], vy = ib.data[i * 6 + 3 + c];
      double vs = fmax(fabs(vx), fabs(vy));
      double ev = vs > 0 ? fabs((double)vx - vy) / vs : 0.0;
      if (ev > worst_var) worst_var = ev;
    }
  printf("%s: %ld of %zu means differ, worst %.2f float steps; worst variance rel. error %.2g\n",
         what, differ, 3 * n, worst_mean, worst_var);
  if (ulps == 0)
    CHECK_EQ_INT(differ, 0);
  else
    CHECK(worst_mean <= ulps);
  CHECK(worst_var <= var_tol);
  iris_image_destroy(&ia);
  iris_image_destroy(&ib);
}

/* The film sums of a windowed render equal those of the full render in the
 * window, bit for bit. */
static void check_window_bits(const iris_render_result *full, const iris_render_result *part) {
  const iris_film *f = &full->film, *w = &part->film;
  const iris_pixel_bounds b = part->bounds;
  CHECK_EQ_INT(w->width, b.x1 - b.x0);
  CHECK_EQ_INT(w->height, b.y1 - b.y0);
  long bad = 0;
  for (int y = b.y0; y < b.y1; y++) {
    size_t fi = (size_t)y * (size_t)f->width + (size_t)b.x0;
    size_t wi = (size_t)(y - b.y0) * (size_t)w->width;
    size_t k = (size_t)w->width;
    bad += memcmp(f->sum + 3 * fi, w->sum + 3 * wi, 3 * k * sizeof(double)) != 0;
    bad += memcmp(f->sum2 + 3 * fi, w->sum2 + 3 * wi, 3 * k * sizeof(double)) != 0;
    bad += memcmp(f->count + fi, w->count + wi, k * sizeof(uint32_t)) != 0;
  }
  CHECK_EQ_INT(bad, 0);
}

static void test_renders(const iris_scene *cornell, iris_method method, int spp, const char *tag) {
  char full[64], merged[64], tiles[64], n[8][64];
  snprintf(full, sizeof full, "%s-full.exr", tag);
  snprintf(merged, sizeof merged, "%s-merged.exr", tag);
  snprintf(tiles, sizeof tiles, "%s-tiles.exr", tag);
  for (int i = 0; i < 8; i++) snprintf(n[i], sizeof n[i], "%s-part%d.exr", tag, i);
  job base = {method, 3, spp, 4, 2, 0, {0, 0, 0, 0}};
  iris_render_result fr, wr;
  if (!render_to(cornell, base, full, &fr)) return;

  /* uneven sample partitions, on "nodes" with 1 and 2 threads */
  int cut1 = spp / 3, cut2 = spp / 3 + spp / 2;
  job a = base, b = base, c = base;
  a.spp = cut1;
  a.threads = 1;
  b.offset = (uint64_t)cut1;
  b.spp = cut2 - cut1;
  c.offset = (uint64_t)cut2;
  c.spp = spp - cut2;
  c.threads = 1;
  render_to(cornell, a, n[0], NULL);
  render_to(cornell, b, n[1], NULL);
  render_to(cornell, c, n[2], NULL);
  const char *parts[3] = {n[2], n[0], n[1]};
  iris_error err;
  CHECK_OK(merge_names(parts, 3, merged, &err), &err);
  char what[128];
  snprintf(what, sizeof what, "%s: samples %d+%d+%d vs one render", tag, cut1, cut2 - cut1,
           spp - cut2);
  compare(merged, full, 2, 1e-4, what);

  /* 2x2 uneven tiles, the first split in two sample ranges: windows equal
   * the full render's pixels bit for bit */
  iris_pixel_bounds w[4] = {{0, 0, 17, 10}, {17, 0, 40, 10}, {0, 10, 17, 24}, {17, 10, 40, 24}};
  for (int t = 0; t < 4; t++) {
    job j = base;
    j.bounds = w[t];
    if (t == 1) {
      render_to(cornell, j, n[3 + t], &wr);
      check_window_bits(&fr, &wr);
      iris_render_result_destroy(&wr);
    } else if (t == 0) {
      j.spp = spp / 2;
      render_to(cornell, j, n[3], NULL);
      j.offset = (uint64_t)(spp / 2);
      j.spp = spp - spp / 2;
      render_to(cornell, j, n[7], NULL);
    } else {
      render_to(cornell, j, n[3 + t], NULL);
    }
  }
  const char *tparts[5] = {n[6], n[3], n[4], n[7], n[5]};
  CHECK_OK(merge_names(tparts, 5, tiles, &err), &err);
  snprintf(what, sizeof what, "%s: 4 tiles (one split in samples) vs one render", tag);
  compare(tiles, full, 2, 1e-4, what);
  iris_render_result_destroy(&fr);
}

/* ---- refusals ----------------------------------------------------------------- */

static void expect_refusal(const char *const *names, size_t n, const char *needle) {
  iris_error err;
  char out[600];
  path_in(out, sizeof out, "refused.exr");
  iris_status st = merge_names(names, n, "refused.exr", &err);
  char buf[1400];
  iris_error_format(&err, buf, sizeof buf);
  iris_check_record(st == IRIS_ERR_INVALID && strstr(buf, needle) != NULL, __FILE__, __LINE__,
                    "refusal containing '%s': status %s, message '%s'", needle,
                    iris_status_name(st), buf);
  CHECK(!iris_path_exists(out));
  printf("refused as expected: %s\n", buf);
}

static void test_refusals(const iris_scene *cornell) {
  job h = {IRIS_METHOD_MIS, 3, 4, 2, 2, 0, {0, 0, 0, 0}};
  job h2 = h;
  h2.offset = 4;
  render_to(cornell, h, "r-a.exr", NULL);
  render_to(cornell, h2, "r-b.exr", NULL);
  job j = h2;
  j.seed = 4;
  render_to(cornell, j, "r-seed.exr", NULL);
  j = h2;
  j.method = IRIS_METHOD_NEE;
  render_to(cornell, j, "r-method.exr", NULL);
  j = h2;
  j.max_depth = 3;
  render_to(cornell, j, "r-depth.exr", NULL);
  g_light_sampler = IRIS_LIGHT_SAMPLER_DEFAULT == IRIS_LIGHT_SAMPLER_TREE ? IRIS_LIGHT_SAMPLER_POWER
                                                                          : IRIS_LIGHT_SAMPLER_TREE;
  render_to(cornell, h2, "r-lights.exr", NULL);
  g_light_sampler = IRIS_LIGHT_SAMPLER_DEFAULT;
  j = h;
  j.offset = 2;
  render_to(cornell, j, "r-overlap.exr", NULL);
  j = h;
  j.offset = 6;
  render_to(cornell, j, "r-gap.exr", NULL);
  j = h;
  j.spp = 8;
  j.bounds = (iris_pixel_bounds){0, 0, 20, 24};
  render_to(cornell, j, "r-left.exr", NULL);
  j.bounds = (iris_pixel_bounds){16, 0, 40, 24};
  render_to(cornell, j, "r-right-overlap.exr", NULL);
  j.bounds = (iris_pixel_bounds){20, 0, 40, 12};
  render_to(cornell, j, "r-right-top.exr", NULL);
  /* another scene: one material a little brighter */
  iris_scene *other = NULL;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_builtin_create("cornell-box", &other, &err), &err);
  if (other) {
    other->materials[0].color[0] *= 1.01f;
    render_to(other, h2, "r-scene.exr", NULL);
    iris_scene_destroy(other);
  }
  const char *seed[2] = {"r-a.exr", "r-seed.exr"};
  expect_refusal(seed, 2, "seed");
  const char *method[2] = {"r-a.exr", "r-method.exr"};
  expect_refusal(method, 2, "method");
  const char *lights[2] = {"r-a.exr", "r-lights.exr"};
  expect_refusal(lights, 2, "light sampler");
  const char *scene[2] = {"r-a.exr", "r-scene.exr"};
  expect_refusal(scene, 2, "scene hash");
  const char *depth[2] = {"r-a.exr", "r-depth.exr"};
  expect_refusal(depth, 2, "configuration");
  const char *overlap[2] = {"r-a.exr", "r-overlap.exr"};
  expect_refusal(overlap, 2, "overlap samples");
  const char *gap[2] = {"r-a.exr", "r-gap.exr"};
  expect_refusal(gap, 2, "samples 4..5 are missing");
  const char *twice[3] = {"r-a.exr", "r-b.exr", "r-b.exr"};
  expect_refusal(twice, 3, "overlap samples");
  const char *tiles_overlap[2] = {"r-left.exr", "r-right-overlap.exr"};
  expect_refusal(tiles_overlap, 2, "overlaps window");
  const char *tile_missing[2] = {"r-left.exr", "r-right-top.exr"};
  expect_refusal(tile_missing, 2, "pixel (20, 12)");
  const char *tile_samples[3] = {"r-left.exr", "r-right-top.exr", "r-a.exr"};
  expect_refusal(tile_samples, 3, "a part is missing or doubled");
  /* a sample run that does not start at 0 is a valid image on its own */
  const char *upper[1] = {"r-b.exr"};
  CHECK_OK(merge_names(upper, 1, "r-upper.exr", &err), &err);
}

static void test_scene_hash(const iris_scene *cornell) {
  iris_scene *again = NULL, *loaded = NULL;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_builtin_create("cornell-box", &again, &err), &err);
  uint64_t h = iris_merge_scene_hash(cornell);
  CHECK(again && iris_merge_scene_hash(again) == h);
  char json[600];
  path_in(json, sizeof json, "cornell.json");
  CHECK_OK(iris_scene_write(cornell, json, &err), &err);
  CHECK_OK(iris_scene_load(json, &loaded, &err), &err);
  if (loaded) CHECK(iris_merge_scene_hash(loaded) == h);
  if (again) {
    again->meshes[0].positions[1] = nextafterf(again->meshes[0].positions[1], 1e9f);
    CHECK(iris_merge_scene_hash(again) != h);
  }
  iris_scene_destroy(again);
  iris_scene_destroy(loaded);
}

int main(void) {
  if (iris_test_tmpdir(g_dir, sizeof g_dir, "merge") != 0) return TEST_SKIP("no temp dir");
  test_synthetic(0);
  test_synthetic(1);
  test_bad_metadata();
  iris_scene *cornell = NULL;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_builtin_create("cornell-box", &cornell, &err), &err);
  if (cornell) {
    test_scene_hash(cornell);
    test_renders(cornell, IRIS_METHOD_MIS, 16, "mis");
    /* guided: the caches are built from (scene, camera, seed, options) only,
     * so every part builds the same caches whatever its threads or samples */
    g_gp = iris_guiding_params_default();
    g_gp.photons = 20000;
    g_gp.caches = 400;
    g_gp.force = true;
    test_renders(cornell, IRIS_METHOD_GUIDED, 8, "guided");
    /* with training passes: they trace the whole frame with their own sample
     * indices, so parts of any window or sample range train the same guide
     * (an explicit budget: the automatic one follows each part's spp) */
    g_gp.train_spp = 3;
    test_renders(cornell, IRIS_METHOD_GUIDED_NEE, 8, "guided-nee trained");
    test_refusals(cornell);
    iris_scene_destroy(cornell);
  }
  int rc = TEST_SUMMARY();
  if (rc == 0) iris_test_rmtree(g_dir);
  return rc;
}
