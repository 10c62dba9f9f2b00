/* guiding.guide_file_cli: `iris render --guide-out G` then `--guide-in G` as a
 * user runs them. The render that reads the guide has the bit-identical
 * pixels of the render that wrote it (and so does a guide written without an
 * image, the Slurm training job's form). A guide file of another scene, cut
 * short, with a flipped byte, of another version, or made with other settings
 * (cache res, seed, sampler, max depth, frame size, method) is refused: exit
 * 2, exactly one stderr line `iris: FILE: ...`, no output EXR. Usage errors:
 * --guide-in with mis, --guide-in with --guide-out, a missing guide file. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cli_run.h"
#include "core/fileio.h"
#include "core/image.h"

#define BASE "render door --method guided-nee --spp 4 --height 48"

static char out[1 << 16], err[1 << 16];

static int lines(const char *s) {
  int n = 0;
  for (; *s; ++s) n += *s == '\n';
  return n;
}

/* Same size, channels and float bits. */
static bool same_pixels(const char *dir, const char *a, const char *b) {
  char pa[1200], pb[1200];
  snprintf(pa, sizeof pa, "%s/%s", dir, a);
  snprintf(pb, sizeof pb, "%s/%s", dir, b);
  iris_image x, y;
  iris_error e;
  memset(&x, 0, sizeof x);
  memset(&y, 0, sizeof y);
  bool ok = iris_exr_read(pa, &x, NULL, NULL, &e) == IRIS_OK && iris_exr_read(pb, &y, NULL, NULL, &e) == IRIS_OK &&
            x.width == y.width && x.height == y.height && x.channel_count == y.channel_count &&
            memcmp(x.data, y.data, sizeof(float) * (size_t)x.width * (size_t)x.height * (size_t)x.channel_count) == 0;
  iris_image_destroy(&x);
  iris_image_destroy(&y);
  return ok;
}

/* `BASE args -o X.exr` must be refused because of guide file `file`. */
static void refused(const char *dir, const char *bin, const char *args, const char *file, const char *why) {
  char cmd[2048], prefix[256];
  snprintf(cmd, sizeof cmd, "%s %s -o X.exr", BASE, args);
  int rc = iris_test_run_cli(dir, bin, cmd, out, sizeof out, err, sizeof err);
  snprintf(prefix, sizeof prefix, "iris: %s: ", file);
  bool ok = rc == 2 && lines(err) == 1 && strncmp(err, prefix, strlen(prefix)) == 0 &&
            !iris_test_file_exists(dir, "X.exr");
  iris_check_record(ok, __FILE__, __LINE__, "%s (%s): exit %d, stderr: %s", why, args, rc, err);
}

static bool write_bytes(const char *dir, const char *name, const unsigned char *d, size_t n) {
  char path[1200];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "wb");
  if (!f) return false;
  bool ok = fwrite(d, 1, n, f) == n;
  return fclose(f) == 0 && ok;
}

int main(int argc, char **argv) {
  if (argc < 2) return TEST_SKIP("usage: test IRIS");
  char dir[1024];
  if (iris_test_tmpdir(dir, sizeof dir, "guide-file-cli") != 0) return TEST_SKIP("no temporary folder");
  const char *bin = argv[1];
  int rc = iris_test_run_cli(dir, bin, BASE " --guide-out G -o A.exr --quiet", out, sizeof out, err, sizeof err);
  iris_check_record(rc == 0 && iris_test_file_exists(dir, "G"), __FILE__, __LINE__, "--guide-out: exit %d: %s", rc, err);
  rc = iris_test_run_cli(dir, bin, BASE " --guide-in G -o B.exr", out, sizeof out, err, sizeof err);
  iris_check_record(rc == 0 && strstr(err, "(read from G)"), __FILE__, __LINE__, "--guide-in: exit %d: %s", rc, err);
  iris_check_record(same_pixels(dir, "A.exr", "B.exr"), __FILE__, __LINE__,
                    "the render with --guide-in differs from the render that wrote the guide");
  /* the guide alone (no image), then read: the same image again */
  rc = iris_test_run_cli(dir, bin, BASE " --guide-out G2", out, sizeof out, err, sizeof err);
  iris_check_record(rc == 0 && iris_test_file_exists(dir, "G2") && iris_test_count_entries(dir, ".exr") == 2,
                    __FILE__, __LINE__, "guide only: exit %d: %s", rc, err);
  rc = iris_test_run_cli(dir, bin, BASE " --guide-in G2 -o C.exr --quiet", out, sizeof out, err, sizeof err);
  CHECK(rc == 0);
  CHECK(same_pixels(dir, "A.exr", "C.exr"));
  /* --method auto: its guide is a file too, a trained one on the door and a
   * declined one (the choice and its reason) on cornell-box; read back, each
   * gives the same choice and image, and a guide of guided-nee is not auto's */
  /* the render that trains keeps its 3 training spp in its image unless told
   * not to; a render from the guide file has none (docs/guiding.md) */
  rc = iris_test_run_cli(dir, bin,
                         "render door --spp 8 --height 48 --train-spp 3 --discard-training --guide-out GA -o AA.exr --quiet",
                         out, sizeof out, err, sizeof err);
  CHECK(rc == 0);
  rc = iris_test_run_cli(dir, bin, "render door --spp 8 --height 48 --train-spp 3 --guide-in GA -o AB.exr", out,
                         sizeof out, err, sizeof err);
  iris_check_record(rc == 0 && strstr(err, "auto: guided-nee") && same_pixels(dir, "AA.exr", "AB.exr"), __FILE__,
                    __LINE__, "auto on door through a guide file: exit %d: %s", rc, err);
  /* under a sky the reading render probes the map again from the caches read
   * (docs/guiding.md, "Sky visibility"): the same tables, the same image */
  rc = iris_test_run_cli(dir, bin,
                         "render sky-room --method guided-nee --spp 8 --height 32 --train-spp 3 --discard-training "
                         "--guide-out GS -o SA.exr --quiet",
                         out, sizeof out, err, sizeof err);
  CHECK(rc == 0);
  rc = iris_test_run_cli(dir, bin, "render sky-room --method guided-nee --spp 8 --height 32 --train-spp 3 --guide-in GS -o SB.exr",
                         out, sizeof out, err, sizeof err);
  iris_check_record(rc == 0 && strstr(err, "sky seen from the caches") && same_pixels(dir, "SA.exr", "SB.exr"),
                    __FILE__, __LINE__, "sky-room through a guide file: exit %d: %s", rc, err);
  rc = iris_test_run_cli(dir, bin,
                         "render sky-room --method guided-nee --spp 8 --height 32 --train-spp 3 --guide-in GS "
                         "--sky-beta 0.5 -o X.exr",
                         out, sizeof out, err, sizeof err);
  CHECK(rc == 2 && lines(err) == 1 && !iris_test_file_exists(dir, "X.exr")); /* other sky settings */
  rc = iris_test_run_cli(dir, bin, "render cornell-box --spp 4 --height 32 --guide-out GC -o CA.exr --quiet", out,
                         sizeof out, err, sizeof err);
  CHECK(rc == 0 && iris_test_file_exists(dir, "GC"));
  rc = iris_test_run_cli(dir, bin, "render cornell-box --spp 4 --height 32 --guide-in GC -o CB.exr", out, sizeof out,
                         err, sizeof err);
  iris_check_record(rc == 0 && strstr(err, "auto: mis (what the camera sees is lit mostly directly") &&
                        same_pixels(dir, "CA.exr", "CB.exr"),
                    __FILE__, __LINE__, "auto on cornell-box through a declined guide file: exit %d: %s", rc, err);
  rc = iris_test_run_cli(dir, bin, "render door --method mis --spp 1 --height 48 --guide-out GM -o X.exr", out,
                         sizeof out, err, sizeof err);
  CHECK(rc == 2 && !iris_test_file_exists(dir, "GM") && !iris_test_file_exists(dir, "X.exr"));
  rc = iris_test_run_cli(dir, bin, "render door --method auto --spp 8 --height 48 --guide-in G -o X.exr", out,
                         sizeof out, err, sizeof err);
  CHECK(rc == 2 && lines(err) == 1 && !iris_test_file_exists(dir, "X.exr")); /* guided-nee's guide, auto asks */
  /* a guide of another scene */
  rc = iris_test_run_cli(dir, bin, "render cornell-box --method guided-nee --spp 1 --height 48 --guide-in G -o X.exr",
                         out, sizeof out, err, sizeof err);
  iris_check_record(rc == 2 && lines(err) == 1 && strstr(err, "iris: G: ") == err && strstr(err, "another scene") &&
                        !iris_test_file_exists(dir, "X.exr"),
                    __FILE__, __LINE__, "cornell-box with door's guide: exit %d: %s", rc, err);
  /* other settings */
  refused(dir, bin, "--guide-in G --cache-res 6", "G", "another cache res");
  refused(dir, bin, "--guide-in G --seed 1", "G", "another seed");
  refused(dir, bin, "--guide-in G --sampler independent", "G", "another sampler");
  refused(dir, bin, "--guide-in G --max-depth 5", "G", "another max depth");
  refused(dir, bin, "--guide-in G --width 60", "G", "another frame size");
  refused(dir, bin, "--guide-in G --alpha-max 0.6", "G", "another alpha max");
  rc = iris_test_run_cli(dir, bin, "render door --method guided --spp 4 --height 48 --guide-in G -o X.exr", out,
                         sizeof out, err, sizeof err);
  CHECK(rc == 2 && lines(err) == 1 && !iris_test_file_exists(dir, "X.exr")); /* guided vs guided-nee */
  /* damaged files */
  char path[1200];
  snprintf(path, sizeof path, "%s/G", dir);
  char *data = NULL;
  size_t n = 0;
  iris_error e;
  if (CHECK(iris_file_read(path, 0, &data, &n, &e) == IRIS_OK && n > 1000)) {
    unsigned char *d = (unsigned char *)data;
    size_t cuts[] = {0, 7, 20, 47, 48, 200, n / 2, n - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; ++i) {
      CHECK(write_bytes(dir, "T", d, cuts[i]));
      char why[64];
      snprintf(why, sizeof why, "truncated to %zu bytes", cuts[i]);
      refused(dir, bin, "--guide-in T", "T", why);
    }
    size_t flips[] = {3, 20, 44, n / 3, n - 1};
    for (size_t i = 0; i < sizeof flips / sizeof flips[0]; ++i) {
      d[flips[i]] ^= 0x01;
      CHECK(write_bytes(dir, "F", d, n));
      d[flips[i]] ^= 0x01;
      char why[64];
      snprintf(why, sizeof why, "byte %zu flipped", flips[i]);
      refused(dir, bin, "--guide-in F", "F", why);
    }
    d[8]++; /* the next version, which this iris does not read */
    CHECK(write_bytes(dir, "V", d, n));
    char version[32];
    snprintf(version, sizeof version, "version %u", (unsigned)d[8]);
    refused(dir, bin, "--guide-in V", "V", version);
    free(data);
  }
  /* usage errors, nothing written */
  rc = iris_test_run_cli(dir, bin, "render door --method mis --spp 1 --height 48 --guide-in G -o X.exr", out,
                         sizeof out, err, sizeof err);
  CHECK(rc == 2 && strstr(err, "--guide-in needs --method auto, guided or guided-nee") && !iris_test_file_exists(dir, "X.exr"));
  rc = iris_test_run_cli(dir, bin, BASE " --guide-in G --guide-out H -o X.exr", out, sizeof out, err, sizeof err);
  CHECK(rc == 2 && !iris_test_file_exists(dir, "X.exr") && !iris_test_file_exists(dir, "H"));
  refused(dir, bin, "--guide-in missing.guide", "missing.guide", "missing file");
  CHECK(iris_test_count_entries(dir, ".tmp") == 0);
  iris_test_rmtree(dir);
  return iris_check_summary("guiding.guide_file_cli");
}
