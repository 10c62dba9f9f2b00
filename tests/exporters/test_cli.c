/* exporters.cli: `iris export` as a user runs it. Bad usage and bad input exit
 * 2 with one "iris: ..." line and leave no output file; good inputs (built-in
 * scenes, real glTF assets with textures and instancing) give a script / scene
 * and sidecars; when blender is installed, a real asset's script renders.
 * argv[1] = the iris executable, argv[2] = the shared assets folder. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "core/fileio.h"
#include "core/image.h"
#include "fixture.h"

static const char *g_iris, *g_assets;
static char g_dir[1024];

/* Runs `iris export ARGS` in g_dir; returns the exit status, output in *log. */
static int run(const char *args, char **log) {
  char cmd[4096], path[1200];
  snprintf(path, sizeof path, "%s/log.txt", g_dir);
  snprintf(cmd, sizeof cmd, "cd '%s' && '%s' export %s", g_dir, g_iris, args);
  int rc = fixture_run(cmd, path);
  char *text = fixture_read_text(path);
  if (log)
    *log = text;
  else
    free(text);
  return rc;
}

/* Exit 2, a single "iris: " line, and no file at all left in g_dir but the log. */
static void expect_usage_error(const char *args, const char *needle) {
  char *log = NULL;
  int rc = run(args, &log);
  if (!iris_check_record(rc == 2, __FILE__, __LINE__, "iris export %s: exit %d, want 2: %s", args, rc,
                         log ? log : ""))
    goto done;
  CHECK(log && strncmp(log, "iris: ", 6) == 0);
  if (needle)
    iris_check_record(log && strstr(log, needle) != NULL, __FILE__, __LINE__, "'%s' not in: %s", needle,
                      log ? log : "");
  /* Nothing written: only log.txt remains. */
  int entries = iris_test_count_entries(g_dir, "");
  iris_check_record(entries == 1, __FILE__, __LINE__, "iris export %s left %d entries", args, entries);
done:
  free(log);
}

static bool exists(const char *name) {
  char path[1400];
  snprintf(path, sizeof path, "%s/%s", g_dir, name);
  return iris_path_exists(path);
}

static void clean(void) {
  iris_test_rmtree(g_dir);
  iris_mkdir_p(g_dir, NULL);
}

int main(int argc, char **argv) {
  if (argc < 3) return TEST_SKIP("usage: test_exporters_cli IRIS ASSETS");
  /* Commands run inside the temporary folder: make the executable's path absolute. */
  static char iris_abs[2048];
  char cwd[1024];
  if (argv[1][0] != '/' && getcwd(cwd, sizeof cwd))
    snprintf(iris_abs, sizeof iris_abs, "%s/%s", cwd, argv[1]);
  else
    snprintf(iris_abs, sizeof iris_abs, "%s", argv[1]);
  g_iris = iris_abs;
  g_assets = argv[2];
  if (iris_test_tmpdir(g_dir, sizeof g_dir, "export-cli") != 0) return TEST_SKIP("no temporary folder");
  char args[2048];

  expect_usage_error("", "no input");
  expect_usage_error("cornell-box -o x.py", "--to");
  expect_usage_error("cornell-box --to fbx -o x.fbx", "fbx");
  expect_usage_error("cornell-box --to blender", "--output");
  expect_usage_error("cornell-box --to blender -o x.pov", ".py");
  expect_usage_error("cornell-box --to pov -o x.py", ".pov");
  expect_usage_error("cornell-box --to pov -o x.pov --embed", "--embed");
  expect_usage_error("cornell-box --to blender -o x.py --pov-coverage", "--pov-coverage");
  expect_usage_error("cornell-box --to pov -o x.pov --spp 4", "--spp");
  expect_usage_error("cornell-box --to pov -o x.pov --pov-radiosity ultra", "ultra");
  expect_usage_error("cornell-box --to blender -o x.py --pov-radiosity low", "--pov-radiosity");
  expect_usage_error("cornell-box --to pov -o x.pov --pov-coverage --pov-radiosity high", "conflict");
  expect_usage_error("cornell-box --to blender -o x.py --spp 0", "--spp");
  expect_usage_error("cornell-box --to blender -o x.py --width -3", "--width");
  expect_usage_error("cornell-box --to blender -o x.py --seed abc", "--seed");
  expect_usage_error("cornell-box --to blender -o no/such/folder/x.py", "folder");
  expect_usage_error("no-such-scene --to blender -o x.py", "no-such-scene");
  expect_usage_error("cornell-box --to blender -o x.py --camera nosuch", "nosuch");
  expect_usage_error("cornell-box --to blender -o x.py --bogus", "--bogus");
  snprintf(args, sizeof args, "'%s/basisu-required.gltf' --to blender -o x.py", IRIS_GLTF_TEST_DATA);
  expect_usage_error(args, "basisu-required.gltf");
  snprintf(args, sizeof args, "'%s/bad/gltf/assimp/IndexOutOfRange/IndexOutOfRange.gltf' --to pov -o x.pov",
           g_assets);
  expect_usage_error(args, "IndexOutOfRange.gltf");

  /* Good exports. */
  CHECK_EQ_INT(run("cornell-box --to blender -o cb.py -q", NULL), 0);
  CHECK(exists("cb.py") && exists("cb.meshes.bin"));
  CHECK_EQ_INT(run("cornell-box --to blender -o emb.py --embed -q", NULL), 0);
  CHECK(exists("emb.py") && !exists("emb.meshes.bin"));
  CHECK_EQ_INT(run("veach-mis --to pov -o vm.pov -q", NULL), 0);
  CHECK(exists("vm.pov"));
  /* A real glTF: several primitives and materials, a JPEG texture, a shared wheel mesh. */
  snprintf(args, sizeof args,
           "'%s/gltf/CesiumMilkTruck/glTF/CesiumMilkTruck.gltf' --to blender -o truck.py --width 48 "
           "--height 32 --spp 4 --max-depth 3 -q",
           g_assets);
  CHECK_EQ_INT(run(args, NULL), 0);
  CHECK(exists("truck.py") && exists("truck.meshes.bin"));
  char *script = NULL;
  {
    char path[1400];
    snprintf(path, sizeof path, "%s/truck.py", g_dir);
    script = fixture_read_text(path);
    CHECK(script && strstr(script, "CesiumMilkTruck.jpg") != NULL); /* absolute texture path */
    CHECK(script && strstr(script, "SETTINGS = dict(width=48, height=32, spp=4, max_depth=3, seed=0)"));
    free(script);
  }
  /* A glTF with its image embedded as a data URI: written next to the output. */
  snprintf(args, sizeof args, "'%s/gltf/Box/glTF-Embedded/Box.gltf' --to pov -o box.pov -q", g_assets);
  CHECK_EQ_INT(run(args, NULL), 0);
  CHECK(exists("box.pov"));

  char blender[1024];
  if (fixture_find_tool("blender", blender, sizeof blender)) {
    char cmd[4096], log[1200], exr[1200];
    snprintf(exr, sizeof exr, "%s/truck.exr", g_dir);
    snprintf(log, sizeof log, "%s/truck.log", g_dir);
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' -b --factory-startup --python-exit-code 1 -P truck.py -- --output truck.exr --threads 2",
             g_dir, blender);
    int rc = fixture_run(cmd, log);
    char *out = fixture_read_text(log);
    if (!CHECK(rc == 0)) fprintf(stderr, "%s\n", out ? out : "");
    CHECK(out && strstr(out, "IRIS_BLENDER build_seconds=") && strstr(out, "spp=4") && strstr(out, "width=48 height=32"));
    free(out);
    iris_image img = {0};
    iris_error err;
    iris_error_clear(&err);
    if (rc == 0) {
      CHECK_OK(iris_exr_read(exr, &img, NULL, NULL, &err), &err);
      CHECK_EQ_INT(img.width, 48);
      CHECK_EQ_INT(img.height, 32);
      size_t bad = 0;
      for (size_t i = 0; i < (size_t)img.width * img.height * img.channel_count; i++) bad += !isfinite(img.data[i]);
      CHECK_EQ_INT(bad, 0);
      iris_image_destroy(&img);
    }
  } else {
    printf("blender not installed: the truck script is not rendered\n");
  }
  clean();

  if (iris_check_failures == 0)
    iris_test_rmtree(g_dir);
  else
    printf("files kept in %s\n", g_dir);
  return TEST_SUMMARY();
}
