/* merge.cli: `iris render --sample-offset/--pixel-bounds` and `iris merge` as a
 * user runs them: two halves and four tiles merge to the one-process render
 * (to float rounding), the merged EXR's metadata, exit 2 with a one-line
 * `iris: FILE: message` for parts that do not belong together and for bad
 * usage, and no output file on any failure.
 * Usage: test_merge_cli IRIS_BINARY */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cli_run.h"
#include "core/fileio.h"
#include "core/image.h"

static const char *iris_bin;
static char dir[512];
static char out_text[1 << 16], err_text[1 << 16];

/* Runs `iris ARGS` in the test folder; returns the exit code and fills
 * out_text/err_text. */
static int run(const char *args) {
  return iris_test_run_cli(dir, iris_bin, args, out_text, sizeof out_text, err_text, sizeof err_text);
}

static bool exists(const char *name) { return iris_test_file_exists(dir, name); }

#define EXPECT_RUN(args, code, needle)                                                           \
  do {                                                                                           \
    int rc_ = run(args);                                                                         \
    iris_check_record(rc_ == (code), __FILE__, __LINE__,                                         \
                      "iris %s: exit %d, expected %d; stderr: %s", args, rc_, code, err_text);   \
    iris_check_record(strstr(err_text, needle) || strstr(out_text, needle), __FILE__, __LINE__, \
                      "iris %s: output lacks '%s'; stderr: %s", args, needle, err_text);         \
  } while (0)

/* Means within 2 float steps, same size/channels. */
static void expect_close(const char *a, const char *b) {
  char pa[800], pb[800];
  snprintf(pa, sizeof pa, "%s/%s", dir, a);
  snprintf(pb, sizeof pb, "%s/%s", dir, b);
  iris_image ia, ib;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_exr_read(pa, &ia, NULL, NULL, &err), &err);
  CHECK_OK(iris_exr_read(pb, &ib, NULL, NULL, &err), &err);
  if (!CHECK(ia.width == ib.width && ia.height == ib.height && ia.channel_count == ib.channel_count))
    return;
  double worst = 0.0;
  size_t n = (size_t)ia.width * (size_t)ia.height * (size_t)ia.channel_count;
  for (size_t i = 0; i < n; i++) {
    if (i % (size_t)ia.channel_count >= 3) continue;
    double s = fmax(fabs(ia.data[i]), fabs(ib.data[i]));
    if (s > 0) worst = fmax(worst, fabs((double)ia.data[i] - ib.data[i]) / (s * FLT_EPSILON));
  }
  iris_check_record(worst <= 2.0, __FILE__, __LINE__, "%s vs %s: worst %.2f float steps", a, b,
                    worst);
  iris_image_destroy(&ia);
  iris_image_destroy(&ib);
}

static const char *meta_value(const char *name, const char *key, char *buf, size_t size) {
  char p[800];
  snprintf(p, sizeof p, "%s/%s", dir, name);
  iris_image img;
  iris_image_meta *meta = NULL;
  size_t mc = 0;
  iris_error err;
  iris_error_clear(&err);
  buf[0] = 0;
  if (iris_exr_read(p, &img, &meta, &mc, &err) != IRIS_OK) return buf;
  for (size_t i = 0; i < mc; i++)
    if (strcmp(meta[i].key, key) == 0) snprintf(buf, size, "%s", meta[i].value);
  free(meta);
  iris_image_destroy(&img);
  return buf;
}

#define R "render cornell-box --width 30 --height 20 --seed 11 --max-depth 3 --variance --quiet "

int main(int argc, char **argv) {
  if (argc != 2) return TEST_SKIP("usage: test_merge_cli IRIS_BINARY");
  iris_bin = argv[1];
  if (iris_test_tmpdir(dir, sizeof dir, "merge-cli") != 0) return TEST_SKIP("no temp dir");

  EXPECT_RUN(R "--spp 10 -o full.exr", 0, "");
  EXPECT_RUN(R "--spp 6 -o a.exr", 0, "");
  EXPECT_RUN(R "--spp 4 --sample-offset 6 -o b.exr", 0, "");
  EXPECT_RUN("merge a.exr b.exr -o m.exr", 0, "2 parts (1 windows)");
  expect_close("m.exr", "full.exr");
  char v[1024];
  CHECK_EQ_STR(meta_value("m.exr", "iris:spp", v, sizeof v), "10");
  CHECK_EQ_STR(meta_value("m.exr", "iris:sample_offset", v, sizeof v), "0");
  CHECK_EQ_STR(meta_value("m.exr", "iris:merged_parts", v, sizeof v), "2");
  CHECK_EQ_STR(meta_value("b.exr", "iris:sample_offset", v, sizeof v), "6");
  CHECK_EQ_STR(meta_value("b.exr", "iris:window", v, sizeof v), "0,0,30,20");
  CHECK_EQ_STR(meta_value("b.exr", "iris:full_size", v, sizeof v), "30,20");
  CHECK_EQ_STR(meta_value("b.exr", "iris:seed", v, sizeof v), "11");

  /* four tiles (windows) */
  EXPECT_RUN(R "--spp 10 --pixel-bounds 0,0,13,7 -o t0.exr", 0, "");
  EXPECT_RUN(R "--spp 10 --pixel-bounds 13,0,30,7 -o t1.exr", 0, "");
  EXPECT_RUN(R "--spp 10 --pixel-bounds 0,7,13,20 -o t2.exr", 0, "");
  EXPECT_RUN(R "--spp 10 --pixel-bounds 13,7,30,20 --json -o t3.exr", 0, "\"pixel_bounds\"");
  CHECK_EQ_STR(meta_value("t3.exr", "iris:window", v, sizeof v), "13,7,30,20");
  EXPECT_RUN("merge t3.exr t1.exr t0.exr t2.exr -o tiles.exr --json", 0, "\"windows\":\t4");
  expect_close("tiles.exr", "full.exr");

  /* guided-nee keeping its training samples (the default; 3 spp, the same guide in every
   * part): the part at sample 0 holds them, the later part does not, and the
   * merge equals the single render that kept them */
#define G "render door --width 24 --height 16 --threads 2 --quiet --method guided-nee --photons 20000 " \
          "--train-spp 3 "
  EXPECT_RUN(G "--spp 6 -o gfull.exr", 0, "");
  EXPECT_RUN(G "--spp 4 -o g0.exr", 0, "");
  EXPECT_RUN(G "--spp 2 --sample-offset 4 -o g1.exr", 0, "");
  CHECK_EQ_STR(meta_value("gfull.exr", "iris:train_spp", v, sizeof v), "3");
  CHECK_EQ_STR(meta_value("g0.exr", "iris:train_spp", v, sizeof v), "3");
  CHECK_EQ_STR(meta_value("g1.exr", "iris:train_spp", v, sizeof v), "0");
  EXPECT_RUN("merge g1.exr g0.exr -o gm.exr", 0, "2 parts (1 windows)");
  expect_close("gm.exr", "gfull.exr");
  CHECK_EQ_STR(meta_value("gm.exr", "iris:train_spp", v, sizeof v), "3");
  CHECK_EQ_STR(meta_value("gm.exr", "iris:spp", v, sizeof v), "6");
  EXPECT_RUN(G "--spp 4 --discard-training -o gd.exr", 0, "");
  CHECK_EQ_STR(meta_value("gd.exr", "iris:train_spp", v, sizeof v), "0");
#undef G
  /* the same under a sky through a window, where guided-nee also samples the
   * map from what its caches see (docs/guiding.md, "Sky visibility") */
#define S "render sky-room --width 24 --height 16 --threads 2 --quiet --method guided-nee --photons 20000 " \
          "--train-spp 3 "
  EXPECT_RUN(S "--spp 6 -o sfull.exr", 0, "");
  EXPECT_RUN(S "--spp 4 --threads 1 -o s0.exr", 0, "");
  EXPECT_RUN(S "--spp 2 --sample-offset 4 -o s1.exr", 0, "");
  EXPECT_RUN("merge s1.exr s0.exr -o sm.exr", 0, "2 parts (1 windows)");
  expect_close("sm.exr", "sfull.exr");
#undef S

  /* refusals: exit 2, one line naming the part, no output */
  EXPECT_RUN(R "--spp 4 --sample-offset 6 --seed 12 -o seed.exr", 0, "");
  EXPECT_RUN("merge a.exr seed.exr -o x.exr", 2, "iris: seed.exr: rendered with seed 12, but a.exr has 11");
  CHECK(!exists("x.exr"));
  EXPECT_RUN(R "--spp 4 --sample-offset 5 -o early.exr", 0, "");
  EXPECT_RUN("merge a.exr early.exr -o x.exr", 2, "overlap samples 0..5 of a.exr");
  CHECK(!exists("x.exr"));
  EXPECT_RUN("merge b.exr t0.exr t1.exr t2.exr t3.exr -o x.exr", 2, "a part is missing or doubled");
  EXPECT_RUN("merge t0.exr t1.exr t2.exr -o x.exr", 2, "pixel (13, 7)");
  CHECK(!exists("x.exr"));
  EXPECT_RUN(R "--spp 4 --sample-offset 6 --method nee -o nee.exr", 0, "");
  EXPECT_RUN("merge a.exr nee.exr -o x.exr", 2, "method nee");
  EXPECT_RUN("merge a.exr missing.exr -o x.exr", 2, "missing.exr");
  CHECK(!exists("x.exr"));

  /* usage */
  EXPECT_RUN("merge a.exr b.exr", 2, "no output");
  EXPECT_RUN("merge -o x.exr", 2, "no parts");
  EXPECT_RUN("merge a.exr b.exr -o x.png", 2, "must end in .exr");
  EXPECT_RUN("merge a.exr a.exr -o x.exr", 2, "given twice");
  EXPECT_RUN("merge a.exr --bogus -o x.exr", 2, "unknown option '--bogus'");
  EXPECT_RUN("merge a.exr -o nodir/x.exr", 2, "does not exist");
  EXPECT_RUN("merge --help", 0, "Usage: iris merge");
  EXPECT_RUN(R "--spp 2 --pixel-bounds 0,0,31,20 -o x.exr", 2, "outside the 30x20 frame");
  EXPECT_RUN(R "--spp 2 --pixel-bounds 5,0,5,20 -o x.exr", 2, "--pixel-bounds");
  EXPECT_RUN(R "--spp 2 --pixel-bounds 1,2,3 -o x.exr", 2, "--pixel-bounds");
  EXPECT_RUN(R "--spp 2 --pixel-bounds -1,0,3,4 -o x.exr", 2, "--pixel-bounds");
  EXPECT_RUN(R "--spp 2 --sample-offset -3 -o x.exr", 2, "--sample-offset");
  CHECK(!exists("x.exr"));

  int rc = TEST_SUMMARY();
  if (rc == 0) iris_test_rmtree(dir);
  return rc;
}
