/* validate.negative: `iris validate` must fail (exit 1) on a reference that is
 * 5% too bright, and refuse (exit 2, no report) a reference holding a NaN, a
 * reference of another size, a missing reference and a requested size that
 * differs from the reference's. argv[1]: the iris executable, argv[2]: the
 * stored cornell-box reference. */
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include <math.h>

#include "check.h"
#include "core/fileio.h"
#include "core/image.h"

extern char **environ;

/* Runs iris validate cornell-box --reference REF --out OUT plus extra args; returns the exit code. */
static int run_validate(const char *iris, const char *ref, const char *out, const char *extra1,
                        const char *extra2, const char *extra3, const char *extra4) {
  const char *argv[24];
  int n = 0;
  argv[n++] = iris;
  argv[n++] = "validate";
  argv[n++] = "cornell-box";
  argv[n++] = "--reference";
  argv[n++] = ref;
  argv[n++] = "--spp";
  argv[n++] = "8";
  argv[n++] = "--quiet";
  argv[n++] = "--out";
  argv[n++] = out;
  const char *extra[4] = {extra1, extra2, extra3, extra4};
  for (int i = 0; i < 4; i++)
    if (extra[i]) argv[n++] = extra[i];
  argv[n] = NULL;
  pid_t pid;
  if (posix_spawn(&pid, iris, NULL, NULL, (char *const *)argv, environ) != 0) return -1;
  int status;
  if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

static void write_variant(const iris_image *src, const iris_image_meta *meta, size_t mc,
                          const char *path, float scale, bool nan, int crop_w, int crop_h) {
  iris_error err;
  iris_error_clear(&err);
  iris_image img;
  const char *names[IRIS_IMAGE_MAX_CHANNELS];
  for (int c = 0; c < src->channel_count; c++) names[c] = src->channel_names[c];
  int w = crop_w ? crop_w : src->width, h = crop_h ? crop_h : src->height;
  CHECK_OK(iris_image_create(&img, w, h, src->channel_count, names, &err), &err);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      for (int c = 0; c < src->channel_count; c++) {
        float v = src->data[((size_t)y * (size_t)src->width + (size_t)x) * (size_t)src->channel_count + (size_t)c];
        bool colour = strncmp(src->channel_names[c], "var.", 4) != 0;
        img.data[((size_t)y * (size_t)w + (size_t)x) * (size_t)img.channel_count + (size_t)c] =
            colour ? v * scale : v * scale * scale;
      }
  if (nan) img.data[(size_t)(h / 2 * w + w / 2) * (size_t)img.channel_count] = NAN;
  CHECK_OK(iris_exr_write(path, &img, meta, mc, &err), &err);
  iris_image_destroy(&img);
}

int main(int argc, char **argv) {
  if (argc < 3) return 2;
  const char *iris = argv[1], *ref = argv[2];
  if (!iris_path_exists(ref)) return TEST_SKIP("no stored cornell-box reference");
  char dir[512];
  if (iris_test_tmpdir(dir, sizeof dir, "validate-negative") != 0) return 1;
  iris_error err;
  iris_error_clear(&err);
  iris_image src;
  iris_image_meta *meta = NULL;
  size_t mc = 0;
  CHECK_OK(iris_exr_read(ref, &src, &meta, &mc, &err), &err);
  /* keep iris's own attributes (iris:spp ...), not the EXR header's standard ones */
  size_t kept = 0;
  for (size_t i = 0; i < mc; i++)
    if (strncmp(meta[i].key, "iris:", 5) == 0) meta[kept++] = meta[i];
  mc = kept;
  char scaled[1024], nan[1024], small[1024], missing[1024], out[1024], summary[1100];
  snprintf(scaled, sizeof scaled, "%s/scaled.exr", dir);
  snprintf(nan, sizeof nan, "%s/nan.exr", dir);
  snprintf(small, sizeof small, "%s/small.exr", dir);
  snprintf(missing, sizeof missing, "%s/missing.exr", dir);
  write_variant(&src, meta, mc, scaled, 1.05f, false, 0, 0);
  write_variant(&src, meta, mc, nan, 1.0f, true, 0, 0);
  /* a crop of another aspect ratio (the square camera frames 256 x 256) */
  write_variant(&src, meta, mc, small, 1.0f, false, 256, 128);

  /* 5% too bright: the comparison is made and fails (iris is 1/1.05 = -4.8%) */
  snprintf(out, sizeof out, "%s/o-scaled", dir);
  CHECK_EQ_INT(run_validate(iris, scaled, out, NULL, NULL, NULL, NULL), 1);
  snprintf(summary, sizeof summary, "%s/summary.json", out);
  char *text = NULL;
  size_t size = 0;
  CHECK(iris_file_read(summary, 0, &text, &size, NULL) == IRIS_OK);
  CHECK(text && strstr(text, "\"energy_passed\":\tfalse") != NULL);
  free(text);
  snprintf(summary, sizeof summary, "%s/report.html", out);
  CHECK(iris_path_exists(summary));

  /* refusals: exit 2 and no report */
  const char *bad[3] = {nan, small, missing};
  for (int i = 0; i < 3; i++) {
    snprintf(out, sizeof out, "%s/o-bad%d", dir, i);
    CHECK_EQ_INT(run_validate(iris, bad[i], out, NULL, NULL, NULL, NULL), 2);
    snprintf(summary, sizeof summary, "%s/summary.json", out);
    CHECK(!iris_path_exists(summary));
  }
  snprintf(out, sizeof out, "%s/o-size", dir);
  CHECK_EQ_INT(run_validate(iris, ref, out, "--width", "128", "--height", "128"), 2);
  /* usage errors */
  CHECK_EQ_INT(run_validate(iris, ref, out, "--blender", NULL, NULL, NULL), 2);
  CHECK_EQ_INT(run_validate(iris, ref, out, "--method", "nope", NULL, NULL), 2);
  CHECK_EQ_INT(run_validate(iris, ref, out, "--tolerance", "-1", NULL, NULL), 2);

  iris_image_destroy(&src);
  free(meta);
  iris_test_rmtree(dir);
  return TEST_SUMMARY();
}
