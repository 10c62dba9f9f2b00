/* guiding.auto_cli: what `--method auto` (the default) reports, as a user
 * sees it: the render summary line names the choice and why, --json has
 * method (resolved), method_requested and method_reason, the EXR metadata
 * (read back) has iris:method = the resolved method, iris:method_requested
 * and iris:method_reason; two sample ranges rendered with the default merge,
 * keeping those keys; an unknown method is refused with the list, exit 2. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cli_run.h"
#include "core/fileio.h"
#include "core/image.h"

static const char *meta_get(const iris_image_meta *meta, size_t n, const char *key) {
  for (size_t i = 0; i < n; i++)
    if (strcmp(meta[i].key, key) == 0) return meta[i].value;
  return NULL;
}

static void check_exr(const char *dir, const char *name, const char *method, const char *reason) {
  char path[1200];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  iris_image img;
  iris_image_meta *meta = NULL;
  size_t n = 0;
  iris_error e;
  iris_error_clear(&e);
  if (!CHECK(iris_exr_read(path, &img, &meta, &n, &e) == IRIS_OK)) return;
  const char *m = meta_get(meta, n, "iris:method"), *req = meta_get(meta, n, "iris:method_requested"),
             *why = meta_get(meta, n, "iris:method_reason");
  iris_check_record(m && !strcmp(m, method), __FILE__, __LINE__, "%s: iris:method '%s', want '%s'", name,
                    m ? m : "(none)", method);
  iris_check_record(req && !strcmp(req, "auto"), __FILE__, __LINE__, "%s: iris:method_requested '%s'", name,
                    req ? req : "(none)");
  iris_check_record(why && strstr(why, reason), __FILE__, __LINE__, "%s: iris:method_reason '%s', want '%s'", name,
                    why ? why : "(none)", reason);
  free(meta);
  iris_image_destroy(&img);
}

int main(int argc, char **argv) {
  if (argc < 2) return TEST_SKIP("usage: test IRIS");
  char dir[1024];
  if (iris_test_tmpdir(dir, sizeof dir, "auto-cli") != 0) return TEST_SKIP("no temporary folder");
  static char out[1 << 16], err[1 << 16];
  int rc;
  /* the summary line (no --method: auto) */
  rc = iris_test_run_cli(dir, argv[1], "render door --spp 1 --width 48 --height 36 --threads 2 -o door.exr", out,
                         sizeof out, err, sizeof err);
  iris_check_record(rc == 0, __FILE__, __LINE__, "render door: exit %d: %s", rc, err);
  iris_check_record(strstr(err, "spp (auto: guided-nee (") != NULL, __FILE__, __LINE__,
                    "the summary line names auto's choice: %s", err);
  check_exr(dir, "door.exr", "guided-nee", "auto: guided-nee (");
  /* --json */
  rc = iris_test_run_cli(dir, argv[1], "render veach-mis --method auto --spp 1 --width 48 --height 24 --threads 2 "
                         "-o veach.exr --json", out, sizeof out, err, sizeof err);
  iris_check_record(rc == 0, __FILE__, __LINE__, "render veach-mis --json: exit %d: %s", rc, err);
  CHECK(strstr(out, "\"method\":\t\"mis\"") != NULL);
  CHECK(strstr(out, "\"method_requested\":\t\"auto\"") != NULL);
  iris_check_record(strstr(out, "\"method_reason\":\t\"auto: mis (the scene is lit mostly directly") != NULL,
                    __FILE__, __LINE__, "--json: %s", out);
  check_exr(dir, "veach.exr", "mis", "lit mostly directly");
  /* two sample ranges with the default method merge */
  rc = iris_test_run_cli(dir, argv[1], "render door --spp 1 --width 48 --height 36 --threads 2 -o a.exr --quiet",
                         out, sizeof out, err, sizeof err);
  CHECK(rc == 0);
  rc = iris_test_run_cli(dir, argv[1], "render door --spp 1 --sample-offset 1 --width 48 --height 36 --threads 2 "
                         "-o b.exr --quiet", out, sizeof out, err, sizeof err);
  CHECK(rc == 0);
  rc = iris_test_run_cli(dir, argv[1], "merge a.exr b.exr -o ab.exr", out, sizeof out, err, sizeof err);
  iris_check_record(rc == 0, __FILE__, __LINE__, "merge of auto parts: exit %d: %s", rc, err);
  check_exr(dir, "ab.exr", "guided-nee", "auto: guided-nee (");
  /* unknown method: the list, exit 2, nothing written */
  rc = iris_test_run_cli(dir, argv[1], "render door --method fancy --spp 1 -o no.exr", out, sizeof out, err,
                         sizeof err);
  CHECK(rc == 2);
  CHECK(strstr(err, "iris: render: unknown method 'fancy' (auto, bsdf, nee, mis, guided, guided-nee)") != NULL);
  CHECK(!iris_test_file_exists(dir, "no.exr"));
  iris_test_rmtree(dir);
  return iris_check_summary("guiding.auto_cli");
}
