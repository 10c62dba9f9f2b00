/* Ctrl-C in every phase of `iris render` (issue 24): loading the scene, the
 * BVH build, texture decoding, the light tables, photons, irradiance caches,
 * the guide's training, before the first image pass and during the image
 * passes. Each run is set up so that the phase, left alone, would last far
 * longer than the allowed stop time (a 1.3M-triangle OBJ, a billion photons,
 * caches with 2,000 photons each, 50,000 spp of training), and the signal is
 * raised by the test hook of core/cancel.h at the moment the phase starts; the
 * hook writes that moment (CLOCK_MONOTONIC) to a file, so the test times the
 * stop from the signal, whatever the set-up before it cost.
 *
 * Each run must exit within STOP_SECONDS of the signal with 130 (SIGINT) or
 * 143 (SIGTERM), print one line naming the phase and saying that nothing was
 * written, and leave no file behind (not even a temporary one) — except an
 * interrupt during the image passes, which writes a valid EXR holding the
 * passes done, marked iris:interrupted=true. */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "cli_run.h"
#include "core/fileio.h"
#include "core/image.h"

#define STOP_SECONDS 2.0

static double now_monotonic(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Files in `dir` other than `keep` (NULL: none kept). */
static int stray_files(const char *dir, const char *keep) {
  DIR *d = opendir(dir);
  if (!d) return -1;
  int n = 0;
  struct dirent *e;
  while ((e = readdir(d)) != NULL) {
    if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
    if (keep && strcmp(e->d_name, keep) == 0) continue;
    fprintf(stderr, "  stray file: %s\n", e->d_name);
    n++;
  }
  closedir(d);
  return n;
}

/* A flat grid of n x n quads (2 n^2 triangles) under a quad lamp. */
static bool write_big_obj(const char *path, int n) {
  FILE *f = fopen(path, "w");
  if (!f) return false;
  fprintf(f, "mtllib big.mtl\n");
  for (int y = 0; y <= n; y++)
    for (int x = 0; x <= n; x++) fprintf(f, "v %.5f 0 %.5f\n", (double)x / n - 0.5, (double)y / n - 0.5);
  fprintf(f, "usemtl grey\n");
  for (int y = 0; y < n; y++)
    for (int x = 0; x < n; x++) {
      int a = y * (n + 1) + x + 1, b = a + 1, c = a + n + 2, d = a + n + 1;
      fprintf(f, "f %d %d %d %d\n", a, b, c, d);
    }
  bool ok = fclose(f) == 0;
  char mtl[1024];
  snprintf(mtl, sizeof mtl, "%.*s/big.mtl", (int)(strrchr(path, '/') - path), path);
  f = fopen(mtl, "w");
  if (!f) return false;
  fprintf(f, "newmtl grey\nKd 0.5 0.5 0.5\n");
  return fclose(f) == 0 && ok;
}

typedef struct phase_case {
  const char *key;      /* core/cancel.h hook name */
  const char *words;    /* what the message must say: "interrupted while <words>" */
  const char *args;     /* after `iris render`, before -o */
  bool term;            /* SIGTERM instead of SIGINT */
  bool writes_image;    /* the image passes: an EXR marked interrupted */
} phase_case;

static void run_case(const char *iris, const char *dir, const phase_case *pc) {
  char out_dir[1100], stamp[1200], cmd[4096], err[8192], out[2048];
  snprintf(out_dir, sizeof out_dir, "%s/out-%s", dir, pc->key);
  char mk[1200];
  snprintf(mk, sizeof mk, "mkdir -p '%s'", out_dir);
  if (system(mk) != 0) {
    CHECK(false);
    return;
  }
  snprintf(stamp, sizeof stamp, "%s/stamp-%s", dir, pc->key);
  remove(stamp);
  snprintf(cmd, sizeof cmd,
           "IRIS_TEST_INTERRUPT_IN=%s IRIS_TEST_INTERRUPT_SIGNAL=%s IRIS_TEST_INTERRUPT_STAMP='%s' '%s' render %s "
           "--threads 2 --quiet -o '%s/image.exr'",
           pc->key, pc->term ? "TERM" : "INT", stamp, iris, pc->args, out_dir);
  int rc = iris_test_run_cli(dir, "env", cmd, out, sizeof out, err, sizeof err);
  double end = now_monotonic();
  double raised = -1.0;
  FILE *f = fopen(stamp, "r");
  if (f) {
    if (fscanf(f, "%lf", &raised) != 1) raised = -1.0;
    fclose(f);
  }
  printf("%-10s exit %d, stopped %.2f s after the signal; stderr: %s", pc->key, rc,
         raised > 0.0 ? end - raised : -1.0, err);
  if (!CHECK(raised > 0.0)) fprintf(stderr, "  the hook for phase '%s' never fired\n", pc->key);
  CHECK(raised > 0.0 && end - raised < STOP_SECONDS);
  CHECK_EQ_INT(rc, pc->term ? 143 : 130);
  if (pc->writes_image) {
    CHECK_EQ_INT(stray_files(out_dir, "image.exr"), 0);
    char exr[1200];
    snprintf(exr, sizeof exr, "%s/image.exr", out_dir);
    iris_image img;
    iris_image_meta *meta = NULL;
    size_t nmeta = 0;
    iris_error e;
    iris_error_clear(&e);
    if (CHECK(iris_exr_read(exr, &img, &meta, &nmeta, &e) == IRIS_OK)) {
      const char *interrupted = NULL;
      for (size_t i = 0; i < nmeta; i++)
        if (strcmp(meta[i].key, "iris:interrupted") == 0) interrupted = meta[i].value;
      CHECK(interrupted && strcmp(interrupted, "true") == 0);
      iris_image_destroy(&img);
      free(meta);
    }
    CHECK(strstr(err, "nothing was written") == NULL);
  } else {
    CHECK_EQ_INT(stray_files(out_dir, NULL), 0);
    /* one line: "iris: [FILE: ]interrupted while <words>; nothing was written" */
    char want[200];
    snprintf(want, sizeof want, "interrupted while %s", pc->words);
    if (!CHECK(strstr(err, want) && strstr(err, "; nothing was written\n")))
      fprintf(stderr, "  expected '%s' in stderr\n", want);
    int lines = 0;
    for (const char *p = err; *p; p++) lines += *p == '\n';
    CHECK_EQ_INT(lines, 1);
  }
}

int main(int argc, char **argv) {
  if (argc < 3) return TEST_SKIP("usage: test_render_interrupt_phases PATH_TO_IRIS ASSETS_DIR");
  const char *iris = argv[1], *assets = argv[2];
  char dir[512], obj[700], textured[1200];
  if (iris_test_tmpdir(dir, sizeof dir, "interrupt") != 0) return TEST_SKIP("no temporary folder");
  snprintf(obj, sizeof obj, "%s/big.obj", dir);
  /* 1.3M triangles, 40 MB: seconds to load and to build, more with sanitizers */
  if (!CHECK(write_big_obj(obj, 800))) return iris_check_summary("render.interrupt_phases");
  snprintf(textured, sizeof textured, "'%s/gltf/BoxTextured/glTF/BoxTextured.gltf' --method mis --spp 4", assets);
  char big[900];
  snprintf(big, sizeof big, "'%s' --method mis --spp 4 --width 32 --height 32", obj);
  const phase_case cases[] = {
      {"loading", "loading the scene", big, false, false},
      {"bvh", "building the BVH", big, true, false},
      {"textures", "decoding textures", textured, false, false},
      {"lights", "building the light tables", "door --method guided-nee --spp 64 --width 64 --height 48", false,
       false},
      {"photons", "tracing photons",
       "door --method guided-nee --spp 64 --width 64 --height 48 --photons 1000000000", false, false},
      {"caches", "building the irradiance caches",
       "door --method guided-nee --spp 64 --width 64 --height 48 --photons 200000 --caches 200000 --cache-k 2000",
       false, false},
      {"training", "training the guide", "door --method guided-nee --spp 1000000 --width 64 --height 48", true,
       false},
      {"first-pass", "rendering the first image pass",
       "cornell-box --method mis --spp 1000000 --width 64 --height 64", false, false},
      {"image", "", "cornell-box --method mis --spp 1000000 --width 64 --height 64", true, true},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) run_case(iris, dir, &cases[i]);
  iris_test_rmtree(dir);
  return iris_check_summary("render.interrupt_phases");
}
