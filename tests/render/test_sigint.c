/* SIGINT during `iris render` finishes the current pass and leaves a valid
 * EXR holding the samples done so far (iris:interrupted = true), exit 130.
 * Also: conflicting flags are rejected before any work (exit 2, no file). */
#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "core/fileio.h"
#include "core/image.h"

static int run_and_interrupt(const char *iris, const char *out, int sig, double after) {
  pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    execl(iris, iris, "render", "cornell-box", "--spp", "1000000", "--width", "64", "--height",
          "64", "--threads", "2", "--quiet", "-o", out, (char *)NULL);
    _exit(127);
  }
  struct timespec ts = {(time_t)after, (long)((after - (double)(time_t)after) * 1e9)};
  nanosleep(&ts, NULL);
  kill(pid, sig);
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
}

static void check_exr(const char *out) {
  iris_image img;
  iris_image_meta *meta = NULL;
  size_t nmeta = 0;
  iris_error err;
  iris_error_clear(&err);
  if (!CHECK(iris_exr_read(out, &img, &meta, &nmeta, &err) == IRIS_OK)) {
    fprintf(stderr, "%s\n", err.message);
    return;
  }
  CHECK_EQ_INT(img.width, 64);
  CHECK_EQ_INT(img.height, 64);
  const char *interrupted = NULL, *spp = NULL;
  for (size_t i = 0; i < nmeta; i++) {
    if (strcmp(meta[i].key, "iris:interrupted") == 0) interrupted = meta[i].value;
    if (strcmp(meta[i].key, "iris:spp") == 0) spp = meta[i].value;
  }
  CHECK(interrupted && strcmp(interrupted, "true") == 0);
  CHECK(spp && atoi(spp) > 0 && atoi(spp) < 1000000);
  double sum = 0.0;
  bool finite = true;
  for (size_t i = 0; i < (size_t)img.width * img.height * (size_t)img.channel_count; i++) {
    finite = finite && isfinite(img.data[i]);
    sum += img.data[i];
  }
  CHECK(finite);
  CHECK(sum > 0.0); /* the samples done are in the image */
  iris_image_destroy(&img);
  free(meta);
}

int main(int argc, char **argv) {
  if (argc < 2) return TEST_SKIP("usage: test_render_sigint PATH_TO_IRIS");
  const char *iris = argv[1];
  char dir[512], out[600];
  if (iris_test_tmpdir(dir, sizeof dir, "sigint") != 0) return TEST_SKIP("no temporary folder");
  snprintf(out, sizeof out, "%s/out.exr", dir);

  CHECK_EQ_INT(run_and_interrupt(iris, out, SIGINT, 1.5), 130);
  check_exr(out);
  remove(out);
  CHECK_EQ_INT(run_and_interrupt(iris, out, SIGTERM, 1.5), 143);
  check_exr(out);
  remove(out);

  /* --spp with --time: usage error before any work, no output file */
  char cmd[1400];
  snprintf(cmd, sizeof cmd, "'%s' render cornell-box --spp 4 --time 1 -o '%s' 2>/dev/null", iris, out);
  int st = system(cmd);
  CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 2);
  CHECK(!iris_path_exists(out));
  snprintf(cmd, sizeof cmd, "'%s' render no-such-scene -o '%s' 2>/dev/null", iris, out);
  st = system(cmd);
  CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 2);
  CHECK(!iris_path_exists(out));
  iris_test_rmtree(dir);
  return iris_check_summary("render.sigint");
}
