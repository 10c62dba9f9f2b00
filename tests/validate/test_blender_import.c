/* validate.blender_import: `iris validate --blender-import` with real Blender
 * (SKIP without it) on a Khronos sample model under a uniform sky:
 *  - Box.gltf and BoxTextured.gltf rendered through Blender's own glTF importer pass (energy
 *    within the documented --blender-import tolerance), the importers agree on
 *    the geometry, and the report lists the material note (Principled BSDF);
 *  - the same scene against Blender's import of another model
 *    (BoxVertexColors) fails with exit 1 and "geometry differs".
 * argv[1]: the iris executable, argv[2]: the assets folder. */
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "check.h"
#include "core/fileio.h"

extern char **environ;

static int run(const char *const *args) {
  pid_t pid;
  if (posix_spawn(&pid, args[0], NULL, NULL, (char *const *)args, environ) != 0) return -1;
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static char *read_text(const char *path) {
  char *text = NULL;
  size_t size = 0;
  if (iris_file_read(path, 0, &text, &size, NULL) != IRIS_OK) return NULL;
  return text;
}

int main(int argc, char **argv) {
  if (argc < 3) return 2;
  char dir[512], json[700], box[900], other[900], out[700], path[800], arg[1000];
  if (iris_test_tmpdir(dir, sizeof dir, "validate-blender-import") != 0) return 1;
  snprintf(box, sizeof box, "%s/gltf/Box/glTF/Box.gltf", argv[2]);
  snprintf(other, sizeof other, "%s/gltf/BoxVertexColors/glTF/BoxVertexColors.gltf", argv[2]);
  snprintf(json, sizeof json, "%s/box.json", dir);
  const char *imp[] = {argv[1], "import", box, "-o", json, "-q", NULL};
  CHECK_EQ_INT(run(imp), 0);
  /* the scene's constant environment: a uniform white sky */
  char *text = read_text(json);
  if (!CHECK(text && text[0] == '{')) return TEST_SUMMARY();
  FILE *f = fopen(json, "w");
  fprintf(f, "{\"environment\": {\"radiance\": [1, 1, 1]},%s", text + 1);
  fclose(f);
  free(text);

  snprintf(out, sizeof out, "%s/same", dir);
  snprintf(arg, sizeof arg, "--blender-import=%s", box);
  const char *same[] = {argv[1], "validate", json, arg, "--spp", "32", "--blender-spp", "32", "--width", "48",
                        "--height", "48", "--threads", "2", "--quiet", "--out", out, NULL};
  int code = run(same);
  snprintf(path, sizeof path, "%s/cycles/batch00.log", out);
  if (code == 2 && !iris_path_exists(path)) {
    iris_test_rmtree(dir);
    return TEST_SKIP("Blender is not installed");
  }
  CHECK_EQ_INT(code, 0);
  snprintf(path, sizeof path, "%s/importers.txt", out);
  text = read_text(path);
  CHECK(text && strstr(text, "Principled BSDF") && !strstr(text, "GEOMETRY DIFFERS"));
  if (text) printf("%s", text);
  free(text);
  snprintf(path, sizeof path, "%s/summary.json", out);
  text = read_text(path);
  CHECK(text && strstr(text, "\"blender_import\"") && strstr(text, "\"geometry_differs\":\tfalse"));
  free(text);

  /* a textured model: passes too (its importer note is the Principled one) */
  {
    char tex[900], tjson[700], tout[700];
    snprintf(tex, sizeof tex, "%s/gltf/BoxTextured/glTF/BoxTextured.gltf", argv[2]);
    snprintf(tjson, sizeof tjson, "%s/textured.json", dir);
    const char *timp[] = {argv[1], "import", tex, "-o", tjson, "-q", NULL};
    CHECK_EQ_INT(run(timp), 0);
    char *t = read_text(tjson);
    if (CHECK(t && t[0] == '{')) {
      FILE *tf = fopen(tjson, "w");
      fprintf(tf, "{\"environment\": {\"radiance\": [1, 1, 1]},%s", t + 1);
      fclose(tf);
    }
    free(t);
    snprintf(tout, sizeof tout, "%s/textured", dir);
    snprintf(arg, sizeof arg, "--blender-import=%s", tex);
    const char *targs[] = {argv[1], "validate", tjson, arg, "--spp", "32", "--blender-spp", "32", "--width",
                           "48", "--height", "48", "--threads", "2", "--quiet", "--out", tout, NULL};
    CHECK_EQ_INT(run(targs), 0);
  }

  snprintf(out, sizeof out, "%s/other", dir);
  snprintf(arg, sizeof arg, "--blender-import=%s", other);
  const char *wrong[] = {argv[1], "validate", json, arg, "--spp", "32", "--blender-spp", "32", "--width", "48",
                         "--height", "48", "--threads", "2", "--quiet", "--out", out, NULL};
  CHECK_EQ_INT(run(wrong), 1);
  snprintf(path, sizeof path, "%s/importers.txt", out);
  text = read_text(path);
  CHECK(text && strstr(text, "GEOMETRY DIFFERS"));
  if (text) printf("%s", text);
  free(text);

  /* usage errors before any work: not a glTF, missing file, with --reference */
  const char *bad1[] = {argv[1], "validate", json, "--blender-import", "--out", out, "--quiet", NULL};
  CHECK_EQ_INT(run(bad1), 2);
  const char *bad2[] = {argv[1], "validate", json, "--blender-import=/nonexistent.gltf", "--out", out, "--quiet", NULL};
  CHECK_EQ_INT(run(bad2), 2);
  if (iris_check_failures == 0) iris_test_rmtree(dir);
  else printf("outputs kept in %s\n", dir);
  return TEST_SUMMARY();
}
