/* render.env_cli: the environment flags as a user runs them.
 *  - bad maps (missing, a folder, empty, not an image, NaN / Inf / negative
 *    texels) and bad --env-* values: exit 2, one line naming the file or the
 *    flag, no output file, for render, import and export;
 *  - a map that is not 2:1 warns and renders;
 *  - the light-less warning appears exactly when nothing emits (glTF without
 *    lights; built-ins with lights or a sky; --env / --env-color), for render
 *    and info;
 *  - `import --env` writes environment.map into the scene (path, strength,
 *    rotation) and rendering that scene gives the image the flags give.
 * Usage: test_render_env_cli IRIS_BINARY ASSETS_DIR */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "cli_run.h"
#include "core/image.h"
#include "exr_map.h"

static const char *iris_bin, *assets;
static char dir[512];
static char out_text[1 << 16], err_text[1 << 16];

static int run(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static char last_args[4096];
static int run(const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(last_args, sizeof last_args, fmt, ap);
  va_end(ap);
  return iris_test_run_cli(dir, iris_bin, last_args, out_text, sizeof out_text, err_text, sizeof err_text);
}

static int lines(const char *s) {
  int n = 0;
  for (; *s; s++) n += *s == '\n';
  return n;
}

static int count(const char *hay, const char *needle) {
  int n = 0;
  for (const char *p = strstr(hay, needle); p; p = strstr(p + 1, needle)) n++;
  return n;
}

/* 0.5 + 0.01 (i % 7) for channel value i, with `bad` (unless 0) in G of texel (2, 1). */
static void map_texel(void *ctx, int x, int y, int w, int h, float p[3]) {
  (void)h;
  float bad = *(const float *)ctx;
  for (int k = 0; k < 3; k++) p[k] = 0.5f + 0.01f * (float)((3 * (y * w + x) + k) % 7);
  if (bad != 0.0f && x == 2 && y == 1) p[1] = bad;
}

static void write_map(const char *name, int w, int h, float bad) {
  char path[1024];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  iris_test_write_exr_map(path, w, h, map_texel, &bad);
}

static void write_text(const char *name, const char *text) {
  char path[1024];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *fp = fopen(path, "wb");
  CHECK(fp != NULL);
  if (fp) {
    fputs(text, fp);
    fclose(fp);
  }
}

/* exit 2, one stderr line starting "iris: " and naming `needle` (plus the
 * "Try --help" hint of usage errors), no output file */
#define EXPECT_BAD(needle, ...)                                                                      \
  do {                                                                                               \
    int rc_ = run(__VA_ARGS__);                                                                      \
    iris_check_record(rc_ == 2, __FILE__, __LINE__, "iris %s: exit %d, expected 2; stderr: %s",      \
                      last_args, rc_, err_text);                                                     \
    iris_check_record(strncmp(err_text, "iris: ", 6) == 0 && strstr(err_text, needle) &&            \
                          (lines(err_text) == 1 ||                                                   \
                           (lines(err_text) == 2 && strstr(err_text, "Try 'iris"))),                 \
                      __FILE__, __LINE__, "iris %s: stderr should be one line naming '%s': %s",      \
                      last_args, needle, err_text);                                                  \
    iris_check_record(!iris_test_file_exists(dir, "o.exr") && !iris_test_file_exists(dir, "o.json") && \
                          !iris_test_file_exists(dir, "o.py"),                                       \
                      __FILE__, __LINE__, "iris %s: left an output file", last_args);                \
  } while (0)

static double exr_mean(const char *name) {
  char path[1024];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  iris_image img;
  iris_error err;
  iris_error_clear(&err);
  if (iris_exr_read(path, &img, NULL, NULL, &err) != IRIS_OK) return -1.0;
  double m = 0.0;
  for (int i = 0; i < img.width * img.height; i++) m += img.data[(size_t)i * (size_t)img.channel_count];
  m /= (double)img.width * img.height;
  iris_image_destroy(&img);
  return m;
}

static bool same_exr(const char *a, const char *b) {
  char pa[1024], pb[1024];
  snprintf(pa, sizeof pa, "%s/%s", dir, a);
  snprintf(pb, sizeof pb, "%s/%s", dir, b);
  iris_image ia, ib;
  iris_error err;
  iris_error_clear(&err);
  if (iris_exr_read(pa, &ia, NULL, NULL, &err) != IRIS_OK) return false;
  if (iris_exr_read(pb, &ib, NULL, NULL, &err) != IRIS_OK) {
    iris_image_destroy(&ia);
    return false;
  }
  bool same = ia.width == ib.width && ia.height == ib.height && ia.channel_count == ib.channel_count &&
              memcmp(ia.data, ib.data, sizeof(float) * (size_t)ia.width * (size_t)ia.height *
                                           (size_t)ia.channel_count) == 0;
  iris_image_destroy(&ia);
  iris_image_destroy(&ib);
  return same;
}

int main(int argc, char **argv) {
  if (argc < 3) return TEST_SKIP("usage: test_render_env_cli IRIS ASSETS");
  iris_bin = argv[1];
  assets = argv[2];
  if (iris_test_tmpdir(dir, sizeof dir, "env-cli") != 0) return TEST_SKIP("no temporary folder");
  char box[1024], hdr[1024];
  snprintf(box, sizeof box, "%s/gltf/Box/glTF/Box.gltf", assets);
  snprintf(hdr, sizeof hdr, "%s/env/immenstadter_horn_1k.hdr", assets);
  write_map("good.exr", 16, 8, 0.0f);
  write_map("square.exr", 8, 8, 0.0f);
  write_map("nan.exr", 16, 8, NAN);
  write_map("inf.exr", 16, 8, INFINITY);
  write_map("neg.exr", 16, 8, -1.0f);
  write_text("empty.hdr", "");
  write_text("text.hdr", "this is not an image\n");
  char folder[1024];
  snprintf(folder, sizeof folder, "%s/folder.exr", dir);
  mkdir(folder, 0755);

  static const char *const bad_maps[][2] = {
      {"missing.hdr", "missing.hdr"}, {"folder.exr", "not a regular file"}, {"empty.hdr", "empty"},
      {"text.hdr", "not an OpenEXR or Radiance HDR"}, {"nan.exr", "NaN"}, {"inf.exr", "infinite"},
      {"neg.exr", "negative"}};
  for (size_t i = 0; i < sizeof bad_maps / sizeof bad_maps[0]; i++) {
    const char *m = bad_maps[i][0];
    EXPECT_BAD(m, "render '%s' --env %s -o o.exr --spp 1 --width 8 --height 8", box, m);
    EXPECT_BAD(bad_maps[i][1], "render '%s' --env %s -o o.exr --spp 1 --width 8 --height 8", box, m);
    EXPECT_BAD(m, "import '%s' --env %s -o o.json", box, m);
    EXPECT_BAD(m, "export '%s' --env %s --to blender -o o.py", box, m);
  }
  /* bad flag values */
  EXPECT_BAD("--env-rotation", "render '%s' --env good.exr --env-rotation abc -o o.exr", box);
  EXPECT_BAD("--env-rotation", "render '%s' --env good.exr --env-rotation 1e9 -o o.exr", box);
  EXPECT_BAD("--env-rotation", "import '%s' --env good.exr --env-rotation nan -o o.json", box);
  EXPECT_BAD("--env-strength", "render '%s' --env good.exr --env-strength -1 -o o.exr", box);
  EXPECT_BAD("--env-color", "render '%s' --env-color 1,2 -o o.exr", box);
  EXPECT_BAD("--env-color", "render '%s' --env-color 1,nan,2 -o o.exr", box);
  EXPECT_BAD("--env-color", "render '%s' --env-color -1,0,0 -o o.exr", box);
  EXPECT_BAD("--env-color", "export '%s' --env-color 1,1,1,1 --to blender -o o.py", box);
  EXPECT_BAD("--env-color", "render '%s' --env good.exr --env-color 1,1,1 -o o.exr", box);
  EXPECT_BAD("--env-strength", "render '%s' --env-strength 2 -o o.exr", box);
  EXPECT_BAD("--env", "render '%s' --env -o o.exr", box);

  /* not 2:1: a warning, and the render is written */
  int rc = run("render '%s' --env square.exr -o sq.exr --spp 1 --width 8 --height 8", box);
  CHECK(rc == 0);
  iris_check_record(strstr(err_text, "not 2:1") != NULL, __FILE__, __LINE__, "no 2:1 warning: %s", err_text);
  CHECK(iris_test_file_exists(dir, "sq.exr"));

  /* the light-less warning, exactly once, exactly when nothing emits */
  const char *warn = "the scene has no light";
  rc = run("render '%s' -o l0.exr --spp 1 --width 8 --height 8", box);
  CHECK(rc == 0);
  iris_check_record(count(err_text, warn) == 1, __FILE__, __LINE__, "glTF without lights: %s", err_text);
  CHECK(strstr(err_text, "--env FILE") && strstr(err_text, "--env-color R,G,B"));
  CHECK(exr_mean("l0.exr") == 0.0);
  rc = run("info '%s'", box);
  CHECK(rc == 0 && count(err_text, warn) == 1);
  static const char *const lit[] = {"cornell-box", "veach-mis", "door", "furnace-diffuse", "inside-sphere"};
  for (size_t i = 0; i < sizeof lit / sizeof lit[0]; i++) {
    rc = run("render %s -o l1.exr --spp 1 --width 8 --height 8", lit[i]);
    iris_check_record(rc == 0 && count(err_text, warn) == 0, __FILE__, __LINE__, "%s warned: %s", lit[i], err_text);
  }
  rc = run("render '%s' --env-color 0.5,0.5,0.5 -o l2.exr --spp 1 --width 8 --height 8", box);
  CHECK(rc == 0 && count(err_text, warn) == 0 && exr_mean("l2.exr") > 0.0);
  rc = run("render '%s' --env-color 0,0,0 -o l3.exr --spp 1 --width 8 --height 8", box);
  CHECK(rc == 0 && count(err_text, warn) == 1);
  rc = run("render '%s' --env '%s' -o l4.exr --spp 1 --width 8 --height 8", box, hdr);
  CHECK(rc == 0 && count(err_text, warn) == 0 && exr_mean("l4.exr") > 0.0);
  rc = run("render '%s' --env '%s' --env-strength 0 -o l5.exr --spp 1 --width 8 --height 8", box, hdr);
  CHECK(rc == 0 && count(err_text, warn) == 1);

  /* import --env writes environment.map; the scene renders as the flags do */
  rc = run("import '%s' --env '%s' --env-strength 2 --env-rotation 45 -o lit.json -q", box, hdr);
  CHECK(rc == 0);
  rc = run("info --json lit.json");
  CHECK(rc == 0 && strstr(out_text, "\"environment_map\"") && strstr(out_text, "immenstadter_horn_1k.hdr") &&
        strstr(out_text, "\"rotation\":\t45") && strstr(out_text, "\"strength\":\t2"));
  rc = run("render lit.json -o a.exr --spp 4 --width 16 --height 16 --quiet");
  CHECK(rc == 0);
  rc = run("render '%s' --env '%s' --env-strength 2 --env-rotation 45 -o b.exr --spp 4 --width 16 "
           "--height 16 --quiet", box, hdr);
  CHECK(rc == 0);
  CHECK(same_exr("a.exr", "b.exr"));
  /* the flags override the scene's world */
  rc = run("render lit.json --env-color 0,0,0 -o c.exr --spp 1 --width 8 --height 8");
  CHECK(rc == 0 && count(err_text, warn) == 1 && exr_mean("c.exr") == 0.0);

  iris_test_rmtree(dir);
  return TEST_SUMMARY();
}
