/* core.image_oiio: EXRs written by another implementation (oiiotool, which
 * uses the OpenEXR C++ library) read correctly through iris_exr_read, for every
 * compression, half/float/uint channels, tiles, mip-maps and offset data
 * windows; and EXRs written by iris read correctly in oiiotool. The reference
 * values are oiiotool's own `--dumpdata` print-out of the same file.
 * Skips (exit 77) when oiiotool is not installed. */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "core/image.h"

static char dir[512];
static const char *oiiotool;

/* Pixel values printed by `oiiotool --dumpdata`, in oiiotool's channel order. */
typedef struct dump {
  int x0, y0, width, height, channels;
  char names[IRIS_IMAGE_MAX_CHANNELS][64];
  double *v; /* [(y * width + x) * channels + c] */
} dump;

static int run(const char *cmd) {
  int rc = system(cmd);
  if (rc != 0) fprintf(stderr, "command failed (%d): %s\n", rc, cmd);
  return rc;
}

/* Reads `--info -v` (channel names) then `--dumpdata` of path. */
static int read_dump(const char *path, dump *d) {
  memset(d, 0, sizeof *d);
  char cmd[1400], line[4096];
  snprintf(cmd, sizeof cmd, "'%s' --info -v '%s'", oiiotool, path);
  FILE *p = popen(cmd, "r");
  if (!p) return -1;
  while (fgets(line, sizeof line, p)) {
    char *cl = strstr(line, "channel list: ");
    if (!cl || d->channels) continue;
    char *s = cl + 14;
    for (char *tok = strtok(s, ",\n"); tok && d->channels < IRIS_IMAGE_MAX_CHANNELS; tok = strtok(NULL, ",\n")) {
      while (*tok == ' ') tok++;
      snprintf(d->names[d->channels++], sizeof d->names[0], "%s", tok);
    }
  }
  pclose(p);
  if (!d->channels) return -1;

  snprintf(cmd, sizeof cmd, "'%s' --dumpdata '%s'", oiiotool, path);
  p = popen(cmd, "r");
  if (!p) return -1;
  size_t cap = 0, n = 0;
  int *xy = NULL;
  double *vals = NULL;
  int minx = 1 << 30, miny = 1 << 30, maxx = -(1 << 30), maxy = -(1 << 30);
  while (fgets(line, sizeof line, p)) {
    int x, y, off = 0;
    if (sscanf(line, " Pixel (%d, %d):%n", &x, &y, &off) != 2 || off == 0) continue;
    if (n == cap) {
      cap = cap ? cap * 2 : 1024;
      xy = realloc(xy, cap * 2 * sizeof *xy);
      vals = realloc(vals, cap * (size_t)d->channels * sizeof *vals);
    }
    char *s = line + off;
    for (int c = 0; c < d->channels; c++) vals[n * (size_t)d->channels + (size_t)c] = strtod(s, &s);
    xy[2 * n] = x;
    xy[2 * n + 1] = y;
    minx = x < minx ? x : minx;
    miny = y < miny ? y : miny;
    maxx = x > maxx ? x : maxx;
    maxy = y > maxy ? y : maxy;
    n++;
  }
  pclose(p);
  if (n == 0) {
    free(xy);
    free(vals);
    return -1;
  }
  d->x0 = minx;
  d->y0 = miny;
  d->width = maxx - minx + 1;
  d->height = maxy - miny + 1;
  d->v = calloc((size_t)d->width * d->height * d->channels, sizeof *d->v);
  for (size_t i = 0; i < n; i++)
    for (int c = 0; c < d->channels; c++)
      d->v[((size_t)(xy[2 * i + 1] - miny) * d->width + (size_t)(xy[2 * i] - minx)) * d->channels + c] =
          vals[i * (size_t)d->channels + (size_t)c];
  free(xy);
  free(vals);
  return 0;
}

/* Worst absolute difference between an iris image and a dump, channel by name. */
static double compare(const iris_image *img, const dump *d, const char *what) {
  if (!iris_check_record(img->width == d->width && img->height == d->height && img->channel_count == d->channels,
                         __FILE__, __LINE__, "%s: iris reads %dx%dx%d, oiiotool %dx%dx%d", what, img->width,
                         img->height, img->channel_count, d->width, d->height, d->channels))
    return INFINITY;
  double worst = 0;
  for (int c = 0; c < d->channels; c++) {
    int ic = iris_image_channel(img, d->names[c]);
    if (!iris_check_record(ic >= 0, __FILE__, __LINE__, "%s: channel '%s' missing", what, d->names[c]))
      return INFINITY;
    for (size_t p = 0; p < (size_t)d->width * d->height; p++) {
      double a = img->data[p * img->channel_count + (size_t)ic], b = d->v[p * d->channels + (size_t)c];
      double diff = fabs(a - b) / fmax(1.0, fabs(b)); /* relative above 1 (uint channels) */
      if (!(diff <= worst)) worst = diff;
    }
  }
  return worst;
}

typedef struct exr_case {
  const char *name;
  const char *make; /* oiiotool arguments before -o */
  double tol;       /* 1e-6: lossless (dumpdata prints 9 decimals); larger: lossy codecs */
} exr_case;

#define GRAD "--pattern fill:topleft=0,0,0,1:topright=1,0.2,0,0.5:bottomleft=0,1,0.3,0:bottomright=2,1,1,1"

static const exr_case cases[] = {
    {"piz_half_checker", "--pattern checker:width=2:height=2:color1=0,0,0:color2=1,1,1 9x5 3 -d half --compression piz", 1e-6},
    {"zip_half_tiled", GRAD " 37x21 4 -d half --tile 16 16 --compression zip", 1e-6},
    {"zips_float", GRAD " 19x7 4 -d float --compression zips", 1e-6},
    {"rle_float_origin", GRAD " 13x9 3 --origin +5+3 -d float --compression rle", 1e-6},
    {"none_half", GRAD " 8x8 4 -d half --compression none", 1e-6},
    {"piz_float_blender_names",
     GRAD " 33x17 4 --chnames ViewLayer.Combined.R,ViewLayer.Combined.G,ViewLayer.Combined.B,ViewLayer.Combined.A"
          " -d float --compression piz", 1e-6},
    {"pxr24_half", GRAD " 21x11 3 -d half --compression pxr24", 1e-6},
    {"pxr24_float", GRAD " 21x11 3 -d float --compression pxr24", 1e-4},
    {"b44_half", GRAD " 23x13 3 -d half --compression b44", 1e-2},
    {"b44a_half", GRAD " 23x13 3 -d half --compression b44a", 1e-2},
    {"dwaa_half", GRAD " 40x35 3 -d half --compression dwaa", 1e-2},
    {"dwab_float", GRAD " 300x40 4 -d float --compression dwab", 1e-2},
    {"uint_zip", "--pattern constant:color=0.25,0.5,1.0 6x3 3 -d uint32 --compression zip", 1e-6},
    {"mipmap_tiled", GRAD " 20x12 3 -d half -otex", 1e-6},
};

static void test_read_foreign(void) {
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    char path[700], cmd[2400];
    snprintf(path, sizeof path, "%s/%s.exr", dir, cases[i].name);
    /* "-otex" (tiled, mip-mapped texture output) replaces "-o" and must come last. */
    char make[600];
    snprintf(make, sizeof make, "%s", cases[i].make);
    char *otex = strstr(make, " -otex");
    if (otex) *otex = '\0';
    snprintf(cmd, sizeof cmd, "'%s' %s --attrib iris:note 'case %s' %s '%s'", oiiotool, make, cases[i].name,
             otex ? "-otex" : "-o", path);
    if (!iris_check_record(run(cmd) == 0, __FILE__, __LINE__, "oiiotool failed for %s", cases[i].name)) continue;
    dump d;
    if (!iris_check_record(read_dump(path, &d) == 0, __FILE__, __LINE__, "cannot dump %s", cases[i].name))
      continue;
    iris_image img;
    iris_image_meta *meta = NULL;
    size_t mn = 0;
    iris_error err;
    iris_error_clear(&err);
    CHECK_OK(iris_exr_read(path, &img, &meta, &mn, &err), &err);
    if (img.data) {
      double worst = compare(&img, &d, cases[i].name);
      iris_check_record(worst <= cases[i].tol, __FILE__, __LINE__, "%s: worst difference %.3g > %.3g",
                        cases[i].name, worst, cases[i].tol);
      printf("%-24s %dx%dx%d  worst diff vs oiiotool %.3g\n", cases[i].name, img.width, img.height,
             img.channel_count, worst);
      char want[128];
      snprintf(want, sizeof want, "case %s", cases[i].name);
      const char *note = NULL;
      for (size_t k = 0; k < mn; k++)
        if (strcmp(meta[k].key, "iris:note") == 0) note = meta[k].value;
      CHECK_EQ_STR(note, want);
    }
    free(meta);
    iris_image_destroy(&img);
    free(d.v);
  }
}

static void test_write_for_foreign(int nc) {
  const char *names[] = {"R", "G", "B", "A", "var.R"};
  iris_image img;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_image_create(&img, 29, 18, nc, names, &err), &err);
  if (!img.data) return;
  for (int y = 0; y < 18; y++)
    for (int x = 0; x < 29; x++)
      for (int c = 0; c < nc; c++) img.data[(y * 29 + x) * nc + c] = (float)(x * 0.5 - y * 0.25 + c * 10) / 7.0f;
  iris_image_meta meta = {"iris:renderer", "iris test"};
  char path[700], cmd[1600], line[2048];
  snprintf(path, sizeof path, "%s/by_iris_%d.exr", dir, nc);
  CHECK_OK(iris_exr_write(path, &img, &meta, 1, &err), &err);
  dump d;
  if (iris_check_record(read_dump(path, &d) == 0, __FILE__, __LINE__, "oiiotool cannot read iris's EXR")) {
    double worst = compare(&img, &d, "written by iris");
    iris_check_record(worst <= 1e-6, __FILE__, __LINE__, "iris EXR in oiiotool: worst difference %.3g", worst);
    free(d.v);
  }
  snprintf(cmd, sizeof cmd, "'%s' --info -v '%s'", oiiotool, path);
  FILE *p = popen(cmd, "r");
  int found_meta = 0, zip = 0;
  while (p && fgets(line, sizeof line, p)) {
    found_meta |= strstr(line, "iris:renderer: \"iris test\"") != NULL;
    zip |= strstr(line, "compression: \"zip\"") != NULL;
  }
  if (p) pclose(p);
  CHECK(found_meta);
  CHECK(zip);
  iris_image_destroy(&img);
}

int main(int argc, char **argv) {
  oiiotool = argc > 1 ? argv[1] : "";
  if (access(oiiotool, X_OK) != 0) oiiotool = "/usr/bin/oiiotool";
  if (access(oiiotool, X_OK) != 0) return TEST_SKIP("oiiotool (Debian openimageio-tools) is not installed");
  if (iris_test_tmpdir(dir, sizeof dir, "oiio") != 0) {
    fprintf(stderr, "cannot create a temporary directory\n");
    return 1;
  }
  test_read_foreign();
  for (int nc = 3; nc <= 5; nc++) test_write_for_foreign(nc);
  iris_test_rmtree(dir);
  return TEST_SUMMARY();
}
