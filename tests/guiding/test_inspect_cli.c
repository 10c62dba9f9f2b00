/* guiding.inspect_cli: `iris render --dump-caches DIR --aov caches` as a user
 * runs it. The dumps and marks are produced by the inspection module through
 * the guide's inspection hook (guiding.h: iris_guiding_params.inspect), so
 * this fails when the hook is not wired: DIR/caches.txt lists 12 pixels, a
 * pdf and a photon-count PNG per listed cache exist, and OUT-caches.png is
 * written next to the EXR; on the door some listed caches show their portal,
 * in the door's plane (x = 0). Without a guided method both flags are
 * refused. */
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "cli_run.h"
#include "core/fileio.h"

int main(int argc, char **argv) {
  if (argc < 2) return TEST_SKIP("usage: test IRIS");
  char dir[1024];
  if (iris_test_tmpdir(dir, sizeof dir, "inspect-cli") != 0) return TEST_SKIP("no temporary folder");
  static char out[1 << 16], err[1 << 16];
  char cmd[2048];
  char sub[1100];
  snprintf(sub, sizeof sub, "%s/dumps", dir);
  iris_error e;
  iris_error_clear(&e);
  if (!CHECK(iris_mkdir_p(sub, &e) == IRIS_OK)) return iris_check_summary("guiding.inspect_cli");
  int rc;
  snprintf(cmd, sizeof cmd, "render cornell-box --method guided-nee --force-guiding --spp 1 --width 64 "
                            "--height 48 --photons 20000 --dump-caches dumps --aov caches -o img.exr --quiet");
  rc = iris_test_run_cli(dir, argv[1], cmd, out, sizeof out, err, sizeof err);
  iris_check_record(rc == 0, __FILE__, __LINE__, "render with inspection: exit %d: %s", rc, err);
  CHECK(iris_test_file_exists(dir, "img.exr"));
  CHECK(iris_test_file_exists(dir, "img-caches.png"));
  char path[1200];
  snprintf(path, sizeof path, "%s/dumps/caches.txt", dir);
  FILE *f = fopen(path, "r");
  int lines = 0, pngs = 0, listed = 0;
  if (CHECK(f != NULL)) {
    char line[512];
    while (fgets(line, sizeof line, f)) {
      int px, py;
      char cache[32];
      if (line[0] == '#' || sscanf(line, "%d %d %31s", &px, &py, cache) != 3) continue;
      lines++;
      if (strcmp(cache, "none") == 0) continue; /* no cache serves that pixel */
      char name[128];
      snprintf(name, sizeof name, "dumps/cache_px%04d_py%04d_pdf.png", px, py);
      pngs += iris_test_file_exists(dir, name);
      snprintf(name, sizeof name, "dumps/cache_px%04d_py%04d_photons.png", px, py);
      pngs += iris_test_file_exists(dir, name);
      listed += 2;
    }
    fclose(f);
  }
  iris_check_record(lines == 12 && listed > 0 && pngs == listed, __FILE__, __LINE__,
                    "caches.txt: %d pixel lines (want 12), %d of %d PNGs found", lines, pngs, listed);
  /* the door: the portals of the caches that have one */
  snprintf(sub, sizeof sub, "%s/door-dumps", dir);
  if (CHECK(iris_mkdir_p(sub, &e) == IRIS_OK)) {
    rc = iris_test_run_cli(dir, argv[1], "render door --method guided-nee --spp 1 --height 72 --dump-caches door-dumps "
                           "-o door.exr --quiet", out, sizeof out, err, sizeof err);
    iris_check_record(rc == 0, __FILE__, __LINE__, "door with inspection: exit %d: %s", rc, err);
    snprintf(path, sizeof path, "%s/door-dumps/caches.txt", dir);
    f = fopen(path, "r");
    int portals = 0, none = 0, bad = 0;
    if (CHECK(f != NULL)) {
      char line[512];
      while (fgets(line, sizeof line, f)) {
        if (line[0] == '#') continue;
        float v[22];
        char src[16], map[16], last[32];
        int n = sscanf(line, "%f %f %f %f %f %f %f %f %f %f %15s %15s %f %f %f %f %f %f %f %f %f %f", &v[0], &v[1],
                       &v[2], &v[3], &v[4], &v[5], &v[6], &v[7], &v[8], &v[9], src, map, &v[12], &v[13], &v[14],
                       &v[15], &v[16], &v[17], &v[18], &v[19], &v[20], &v[21]);
        if (n == 22) portals++, bad += !(v[12] > -0.01f && v[12] < 0.01f && v[21] > 0.0f && v[21] <= 1.0f);
        else if (n == 12 && sscanf(line, "%*s %*s %*s %*s %*s %*s %*s %*s %*s %*s %*s %*s %31s", last) == 1 &&
                 strcmp(last, "none") == 0)
          none++;
      }
      fclose(f);
    }
    iris_check_record(portals > 0 && bad == 0 && portals + none == 12, __FILE__, __LINE__,
                      "door caches.txt: %d portals (%d off the door's plane), %d none, want 12 lines", portals, bad,
                      none);
  }
  /* refused without a guided method, nothing written */
  rc = iris_test_run_cli(dir, argv[1], "render cornell-box --method mis --spp 1 --dump-caches dumps -o no.exr",
                         out, sizeof out, err, sizeof err);
  CHECK(rc == 2);
  CHECK(!iris_test_file_exists(dir, "no.exr"));
  iris_test_rmtree(dir);
  return iris_check_summary("guiding.inspect_cli");
}
