/* KHR_materials_variants (docs/import-gltf.md, "Material variants"), on
 * tests/importers_gltf/data/variants-quads.gltf (make_variants.py: three quads,
 * one primitive each, variants "sunset", "forest", "ocean"):
 *   import   each variant's mappings applied, the defaults otherwise, only the
 *            used materials stored, unknown names and other inputs refused
 *   reject   out-of-range indices and wrong JSON types refused in one line
 *   cli      --variant on import/info/render/export/bench/validate: refusals
 *            (exit 2, names listed, nothing written), the scene JSON round trip
 *            and the Blender script's materials
 *   blender  Cycles renders of iris's export and of Blender's own glTF import
 *            show the variant's colours (SKIP without blender) */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/image.h"
#include "core/log.h"
#include "exporters/blender.h"
#include "importers/import.h"
#include "scene/scene.h"
#include "tests/common/check.h"
#include "tests/common/cli_run.h"

#define EXPECT(cond, ...) iris_check_record(!!(cond), __FILE__, __LINE__, __VA_ARGS__)

enum { GREY, RED, GREEN, BLUE, YELLOW, UNUSED };
static const char *const NAMES[] = {"grey", "red", "green", "blue", "yellow", "unused"};
static const float COLOURS[][3] = {{0.5f, 0.5f, 0.5f}, {0.8f, 0.1f, 0.1f}, {0.1f, 0.7f, 0.2f},
                                   {0.1f, 0.2f, 0.9f}, {0.9f, 0.8f, 0.1f}, {0.3f, 0.3f, 0.3f}};
/* Per variant (none, sunset, forest, ocean): the material of the left, middle and right quad. */
static const char *const VARIANTS[] = {NULL, "sunset", "forest", "ocean"};
static const int EXPECT_QUADS[4][3] = {
    {GREY, GREY, YELLOW}, {RED, GREY, GREEN}, {GREY, GREEN, YELLOW}, {BLUE, BLUE, YELLOW}};
static const size_t EXPECT_MATERIALS[4] = {2, 3, 3, 2}; /* distinct materials in use */

static char data_file[1024];

static iris_status import(const char *path, const char *variant, iris_scene **s, char *msg, size_t size) {
  iris_import_options o = iris_import_options_default();
  o.variant = variant;
  iris_error err;
  iris_error_clear(&err);
  *s = NULL;
  iris_status st = iris_import_file(path, &o, s, &err);
  msg[0] = '\0';
  if (st != IRIS_OK) iris_error_format(&err, msg, size);
  return st;
}

/* The colour index of scene material m (by name), -1 when none matches. */
static int colour_of(const iris_scene *s, int32_t m) {
  if (m < 0 || (size_t)m >= s->material_count || !s->materials[m].name) return -1;
  for (int k = 0; k < 6; k++)
    if (strcmp(s->materials[m].name, NAMES[k]) == 0) {
      const float *c = s->materials[m].color;
      return c[0] == COLOURS[k][0] && c[1] == COLOURS[k][1] && c[2] == COLOURS[k][2] ? k : -1;
    }
  return -1;
}

/* The scene's three quads carry variant v's materials, and it records v. */
static void check_scene(const iris_scene *s, int v, const char *what) {
  EXPECT(s->mesh_count == 3, "%s: %zu meshes", what, s->mesh_count);
  for (size_t q = 0; q < 3 && q < s->mesh_count; q++) {
    int got = colour_of(s, s->meshes[q].material);
    EXPECT(got == EXPECT_QUADS[v][q], "%s: quad %zu has material %s, expected %s", what, q,
           got >= 0 ? NAMES[got] : "?", NAMES[EXPECT_QUADS[v][q]]);
  }
  EXPECT(s->material_count == EXPECT_MATERIALS[v], "%s: %zu materials stored, expected %zu", what,
         s->material_count, EXPECT_MATERIALS[v]);
  EXPECT(s->variants.count == 3 && s->variants.names && !strcmp(s->variants.names[0], "sunset") &&
             !strcmp(s->variants.names[1], "forest") && !strcmp(s->variants.names[2], "ocean"),
         "%s: variant names not recorded", what);
  EXPECT(s->variants.applied == v - 1, "%s: applied variant %d, expected %d", what, (int)s->variants.applied, v - 1);
}

static void check_import(void) {
  char msg[1400];
  iris_scene *s;
  for (int v = 0; v < 4; v++) {
    CHECK(import(data_file, VARIANTS[v], &s, msg, sizeof msg) == IRIS_OK);
    if (!s) {
      printf("%s\n", msg);
      continue;
    }
    check_scene(s, v, VARIANTS[v] ? VARIANTS[v] : "default");
    iris_scene_destroy(s);
  }
  /* an unknown name: the names listed, no scene */
  char want[1400];
  CHECK(import(data_file, "dusk", &s, msg, sizeof msg) == IRIS_ERR_USAGE && !s);
  snprintf(want, sizeof want, "%s: no material variant \"dusk\" (variants: \"sunset\", \"forest\", \"ocean\")",
           data_file);
  CHECK_EQ_STR(msg, want);
  /* a glTF without the extension, an iris scene, an OBJ */
  char other[1100];
  snprintf(other, sizeof other, "%s/unlit-quads.gltf", IRIS_GLTF_TEST_DATA);
  CHECK(import(other, "sunset", &s, msg, sizeof msg) == IRIS_ERR_USAGE && !s);
  snprintf(want, sizeof want, "%s: no material variant \"sunset\" (the file has no KHR_materials_variants)", other);
  CHECK_EQ_STR(msg, want);
  char dir[1024];
  if (!CHECK(iris_test_tmpdir(dir, sizeof dir, "variants-import") == 0)) return;
  snprintf(other, sizeof other, "%s/tri.obj", dir);
  FILE *fp = fopen(other, "w");
  if (fp) fputs("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", fp), fclose(fp);
  CHECK(import(other, "sunset", &s, msg, sizeof msg) == IRIS_ERR_USAGE && !s);
  CHECK(strstr(msg, "glTF files only") != NULL);
  printf("OBJ: %s\n", msg);
  iris_test_rmtree(dir);
}

/* ---- rejections -------------------------------------------------------- */

typedef struct mutation {
  const char *what;
  void (*apply)(cJSON *root);
  const char *message; /* after "FILE: " */
} mutation;

static cJSON *mapping(cJSON *root, int prim, int k) {
  cJSON *p = cJSON_GetArrayItem(cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(root, "meshes"), 0),
                                                    "primitives"), prim);
  return cJSON_GetArrayItem(
      cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetObjectItem(p, "extensions"), "KHR_materials_variants"),
                          "mappings"),
      k);
}
static cJSON *root_variants(cJSON *root) {
  return cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetObjectItem(root, "extensions"), "KHR_materials_variants"),
                             "variants");
}
static void set(cJSON *o, const char *key, cJSON *v) { cJSON_ReplaceItemInObject(o, key, v); }
static void variant_7(cJSON *r) { set(mapping(r, 1, 0), "variants", cJSON_Parse("[7]")); }
static void variant_negative(cJSON *r) { set(mapping(r, 2, 0), "variants", cJSON_Parse("[0, -1]")); }
static void variant_fraction(cJSON *r) { set(mapping(r, 0, 1), "variants", cJSON_Parse("[0.5]")); }
static void variant_string(cJSON *r) { set(mapping(r, 0, 0), "variants", cJSON_Parse("[\"sunset\"]")); }
static void variants_empty(cJSON *r) { set(mapping(r, 0, 0), "variants", cJSON_Parse("[]")); }
static void material_9(cJSON *r) { set(mapping(r, 1, 1), "material", cJSON_CreateNumber(9)); }
static void material_string(cJSON *r) { set(mapping(r, 0, 0), "material", cJSON_CreateString("red")); }
static void mapped_twice(cJSON *r) { set(mapping(r, 0, 1), "variants", cJSON_Parse("[2, 0]")); }
static void mapping_not_object(cJSON *r) {
  cJSON *m = cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetArrayItem(
      cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(r, "meshes"), 0), "primitives"), 2), "extensions"),
      "KHR_materials_variants"), "mappings");
  cJSON_ReplaceItemInArray(m, 0, cJSON_CreateNumber(1));
}
static void mappings_object(cJSON *r) {
  cJSON *e = cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(
      cJSON_GetArrayItem(cJSON_GetObjectItem(r, "meshes"), 0), "primitives"), 1), "extensions"),
      "KHR_materials_variants");
  set(e, "mappings", cJSON_CreateObject());
}
static void root_not_array(cJSON *r) {
  set(cJSON_GetObjectItem(cJSON_GetObjectItem(r, "extensions"), "KHR_materials_variants"), "variants",
      cJSON_CreateNumber(3));
}
static void root_unnamed(cJSON *r) { cJSON_DeleteItemFromObject(cJSON_GetArrayItem(root_variants(r), 1), "name"); }
static void root_name_number(cJSON *r) { set(cJSON_GetArrayItem(root_variants(r), 2), "name", cJSON_CreateNumber(2)); }
/* tinygltf's own reading drops nulls and empty objects from arrays (renumbering them): refused. */
static void variant_null(cJSON *r) { set(mapping(r, 1, 1), "variants", cJSON_Parse("[null, 2]")); }
static void mapping_empty(cJSON *r) {
  cJSON_InsertItemInArray(cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetArrayItem(
      cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(r, "meshes"), 0), "primitives"), 0), "extensions"),
      "KHR_materials_variants"), "mappings"), 0, cJSON_CreateObject());
}
static void extension_empty(cJSON *r) {
  set(cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(r, "meshes"), 0),
                                                                 "primitives"), 2), "extensions"),
      "KHR_materials_variants", cJSON_CreateObject());
}
/* Without the root's variants every mapping's index is out of range. */
static void root_missing(cJSON *r) { cJSON_DeleteItemFromObject(r, "extensions"); }

static const mutation MUTATIONS[] = {
    {"variant 7", variant_7, "mesh 0 primitive 1: KHR_materials_variants mapping 0: variant 7 out of range (3 variants)"},
    {"variant -1", variant_negative,
     "mesh 0 primitive 2: KHR_materials_variants mapping 0: variant -1 out of range (3 variants)"},
    {"variant 0.5", variant_fraction,
     "mesh 0 primitive 0: KHR_materials_variants mapping 1: \"variants\" holds a value that is not an integer"},
    {"variant string", variant_string,
     "mesh 0 primitive 0: KHR_materials_variants mapping 0: \"variants\" holds a value that is not an integer"},
    {"variants empty", variants_empty,
     "mesh 0 primitive 0: KHR_materials_variants mapping 0: \"variants\" is missing or not a non-empty array"},
    {"material 9", material_9,
     "mesh 0 primitive 1: KHR_materials_variants mapping 1: material 9 does not exist (6 materials)"},
    {"material string", material_string,
     "mesh 0 primitive 0: KHR_materials_variants mapping 0: \"material\" is missing or not an integer"},
    {"mapped twice", mapped_twice, "mesh 0 primitive 0: KHR_materials_variants mapping 1: variant 0 is mapped twice"},
    {"mapping not an object", mapping_not_object,
     "mesh 0 primitive 2: KHR_materials_variants mapping 0: is not an object"},
    {"mappings an object", mappings_object,
     "mesh 0 primitive 1: KHR_materials_variants is not an object with a non-empty \"mappings\" array"},
    {"root variants a number", root_not_array,
     "KHR_materials_variants: is not an object with a non-empty \"variants\" array"},
    {"root variant unnamed", root_unnamed, "KHR_materials_variants variant 1: has no string \"name\""},
    {"root variant name a number", root_name_number, "KHR_materials_variants variant 2: has no string \"name\""},
    {"variant null", variant_null,
     "mesh 0 primitive 1: KHR_materials_variants mapping 1: \"variants\" holds a value that is not an integer"},
    {"empty mapping", mapping_empty,
     "mesh 0 primitive 0: KHR_materials_variants mapping 0: \"material\" is missing or not an integer"},
    {"empty extension", extension_empty,
     "mesh 0 primitive 2: KHR_materials_variants is not an object with a non-empty \"mappings\" array"},
    {"no root variants", root_missing,
     "mesh 0 primitive 0: KHR_materials_variants mapping 0: variant 0 out of range (0 variants)"},
};

static char *read_text(const char *path) {
  FILE *fp = fopen(path, "rb");
  if (!fp) return NULL;
  fseek(fp, 0, SEEK_END);
  long n = ftell(fp);
  fseek(fp, 0, SEEK_SET);
  char *t = n >= 0 ? malloc((size_t)n + 1) : NULL;
  if (t) t[fread(t, 1, (size_t)n, fp)] = '\0';
  fclose(fp);
  return t;
}

static void check_reject(void) {
  char dir[1024], path[1100], msg[1400], want[1400];
  if (!CHECK(iris_test_tmpdir(dir, sizeof dir, "variants-reject") == 0)) return;
  snprintf(path, sizeof path, "%s/bad.gltf", dir);
  char *text = read_text(data_file);
  if (!CHECK(text != NULL)) return;
  for (size_t i = 0; i < sizeof MUTATIONS / sizeof MUTATIONS[0]; i++) {
    const mutation *m = &MUTATIONS[i];
    cJSON *root = cJSON_Parse(text);
    m->apply(root);
    char *out = cJSON_Print(root);
    FILE *fp = fopen(path, "w");
    if (fp) fputs(out, fp), fclose(fp);
    free(out);
    cJSON_Delete(root);
    snprintf(want, sizeof want, "%s: %s", path, m->message);
    /* refused whether or not a variant is chosen: the file is checked before the choice */
    for (int v = 0; v < 2; v++) {
      iris_scene *s = NULL;
      iris_status st = import(path, v ? "ocean" : NULL, &s, msg, sizeof msg);
      EXPECT(st == IRIS_ERR_INVALID && !s, "%s: status %s", m->what, iris_status_name(st));
      EXPECT(strcmp(msg, want) == 0 && !strchr(msg, '\n'), "%s: message\n  %s\nexpected\n  %s", m->what, msg, want);
      iris_scene_destroy(s);
    }
    printf("%-28s %s\n", m->what, msg + strlen(path) + 2);
  }
  free(text);
  iris_test_rmtree(dir);
}

/* ---- the iris command ---------------------------------------------------- */

static const char *iris_bin;
static char out_text[1 << 16], err_text[1 << 14];

static int run(const char *dir, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int run(const char *dir, const char *fmt, ...) {
  char args[3000];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(args, sizeof args, fmt, ap);
  va_end(ap);
  return iris_test_run_cli(dir, iris_bin, args, out_text, sizeof out_text, err_text, sizeof err_text);
}

/* The MATERIALS list of an exported Blender script: the colour indices in order (-1: unknown). */
static int script_materials(const char *path, int *out, int cap) {
  char *t = read_text(path);
  if (!t) return -1;
  int n = 0;
  const char *p = strstr(t, "\nMATERIALS = [\n"), *end = p ? strstr(p, "\n]\n") : NULL;
  for (const char *q = p; q && end && (q = strstr(q + 1, "dict(name=b\"")) && q < end && n < cap;) {
    int k = -1;
    for (int c = 0; c < 6 && k < 0; c++) {
      char key[160];
      /* name and colour as the script writes them (9 significant digits) */
      snprintf(key, sizeof key, "dict(name=b\"%s\", type=\"diffuse\", color=(%.9g, %.9g, %.9g)", NAMES[c],
               (double)COLOURS[c][0], (double)COLOURS[c][1], (double)COLOURS[c][2]);
      if (strncmp(q, key, strlen(key)) == 0) k = c;
    }
    out[n++] = k;
  }
  free(t);
  return n;
}

static void check_cli(void) {
  char dir[1024], want[1400];
  if (!CHECK(iris_test_tmpdir(dir, sizeof dir, "variants-cli") == 0)) return;
  const char *f = data_file;
  snprintf(want, sizeof want, "iris: %s: no material variant \"dusk\" (variants: \"sunset\", \"forest\", \"ocean\")\n",
           f);
  /* An unknown name: exit 2, one line naming the variants, nothing written, on every command. */
  struct {
    const char *args, *output;
  } refuse[] = {
      {"import '%s' --variant dusk -o refused.json", "refused.json"},
      {"info '%s' --variant dusk", NULL},
      {"render '%s' --variant dusk --spp 1 --width 8 --height 4 -o refused.exr", "refused.exr"},
      {"export '%s' --variant dusk --to blender -o refused.py", "refused.py"},
      {"bench '%s' --variant dusk --times 1 --reference auto --reference-spp 1 --cache refused-cache --no-charts "
       "--out refused",
       "refused"},
      {"validate '%s' --variant dusk --out refused --reference ref.exr", "refused"},
  };
  /* validate checks its reference before the scene: a good one */
  CHECK_EQ_INT(run(dir, "render '%s' --spp 1 --width 8 --height 4 --env-color 1,1,1 -o ref.exr -q", f), 0);
  for (size_t i = 0; i < sizeof refuse / sizeof refuse[0]; i++) {
    char args[2000];
    snprintf(args, sizeof args, refuse[i].args, f);
    int rc = run(dir, "%s", args);
    EXPECT(rc == 2 && strcmp(err_text, want) == 0, "iris %s: exit %d, stderr\n%s", args, rc, err_text);
    if (refuse[i].output)
      EXPECT(!iris_test_file_exists(dir, refuse[i].output), "iris %s wrote %s", args, refuse[i].output);
    EXPECT(iris_test_count_entries(dir, "refused") == 0, "iris %s left files", args);
  }
  /* A built-in scene and an iris scene refuse --variant. */
  int rc = run(dir, "render cornell-box --variant sunset --spp 1 -o refused.exr");
  EXPECT(rc == 2 && strstr(err_text, "cornell-box: no material variant \"sunset\": a built-in scene"), "%d %s", rc,
         err_text);

  /* import --variant forest: the scene JSON records it and holds its materials */
  rc = run(dir, "import '%s' --variant forest -o forest.json -q", f);
  CHECK_EQ_INT(rc, 0);
  char path[1200];
  snprintf(path, sizeof path, "%s/forest.json", dir);
  char *text = read_text(path);
  cJSON *j = text ? cJSON_Parse(text) : NULL;
  cJSON *mv = cJSON_GetObjectItem(j, "material_variants");
  CHECK(cJSON_IsArray(cJSON_GetObjectItem(mv, "names")) && cJSON_GetArraySize(cJSON_GetObjectItem(mv, "names")) == 3);
  CHECK_EQ_STR(cJSON_GetStringValue(cJSON_GetObjectItem(mv, "applied")), "forest");
  cJSON_Delete(j);
  free(text);
  iris_scene *s = NULL;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_scene_load(path, &s, &err), &err);
  if (s) check_scene(s, 2, "forest.json");
  iris_scene_destroy(s);
  /* ... and without --variant: the names, nothing applied */
  rc = run(dir, "import '%s' -o plain.json -q", f);
  CHECK_EQ_INT(rc, 0);
  snprintf(path, sizeof path, "%s/plain.json", dir);
  s = NULL;
  CHECK_OK(iris_scene_load(path, &s, &err), &err);
  if (s) check_scene(s, 0, "plain.json");
  iris_scene_destroy(s);
  /* the scene keeps its variant: --variant on it is refused */
  rc = run(dir, "import forest.json --variant ocean -o again.json");
  EXPECT(rc == 2 && strstr(err_text, "an iris scene keeps the variant it was imported with") &&
             !iris_test_file_exists(dir, "again.json"),
         "%d %s", rc, err_text);

  /* info: the names, and which one is applied (text, JSON, and from the scene JSON) */
  rc = run(dir, "info -q '%s'", f);
  EXPECT(rc == 0 && strstr(out_text, "variants     3: \"sunset\", \"forest\", \"ocean\"; none applied"), "%s",
         out_text);
  rc = run(dir, "info -q '%s' --variant ocean", f);
  EXPECT(rc == 0 && strstr(out_text, "\"forest\", \"ocean\" (applied)\n"), "%s", out_text);
  rc = run(dir, "info -q forest.json --json");
  j = cJSON_Parse(out_text);
  CHECK_EQ_STR(cJSON_GetStringValue(cJSON_GetObjectItem(cJSON_GetObjectItem(j, "material_variants"), "applied")),
               "forest");
  cJSON_Delete(j);

  /* The Blender script carries the applied variant's materials, from the glTF and from the scene JSON. */
  struct {
    const char *input, *variant, *script;
    int v;
  } exports[] = {{f, "ocean", "ocean.py", 3}, {f, NULL, "plain.py", 0}, {"forest.json", NULL, "forest.py", 2}};
  for (size_t i = 0; i < 3; i++) {
    rc = run(dir, "export '%s' %s%s --to blender -o %s -q", exports[i].input, exports[i].variant ? "--variant " : "",
             exports[i].variant ? exports[i].variant : "", exports[i].script);
    CHECK_EQ_INT(rc, 0);
    snprintf(path, sizeof path, "%s/%s", dir, exports[i].script);
    int got[8], n = script_materials(path, got, 8), v = exports[i].v;
    EXPECT(n == (int)EXPECT_MATERIALS[v], "%s: %d materials in the script", exports[i].script, n);
    for (int q = 0; q < 3; q++) { /* every quad's material is in the script, nothing else */
      bool found = false;
      for (int k = 0; k < n; k++) found |= got[k] == EXPECT_QUADS[v][q];
      EXPECT(found, "%s: no %s material in the script", exports[i].script, NAMES[EXPECT_QUADS[v][q]]);
    }
    for (int k = 0; k < n; k++) EXPECT(got[k] >= 0, "%s: material %d is not one of the file's", exports[i].script, k);
  }
  iris_test_rmtree(dir);
}

/* ---- Blender ---------------------------------------------------------------- */

#define BW 120
#define BH 60

/* Mean colour of quad q's interior (camera at z = 5, yfov 0.5, 2:1). */
static void quad_mean(const iris_image *img, int q, double out[3]) {
  const double half_h = 5.0 * tan(0.25), half_w = 2.0 * half_h, cx = -1.2 + 1.2 * q;
  const char *names[3] = {"R", "G", "B"};
  double sum[3] = {0, 0, 0};
  int n = 0;
  for (int y = 0; y < BH; y++)
    for (int x = 0; x < BW; x++) {
      double wx = -half_w + 2 * half_w * (x + 0.5) / BW, wy = half_h - 2 * half_h * (y + 0.5) / BH;
      if (fabs(wx - cx) > 0.35 || fabs(wy) > 0.35) continue;
      for (int k = 0; k < 3; k++) {
        int ch = iris_image_channel(img, names[k]);
        sum[k] += img->data[((size_t)y * BW + x) * (size_t)img->channel_count + (size_t)(ch < 0 ? 0 : ch)];
      }
      n++;
    }
  for (int k = 0; k < 3; k++) out[k] = n ? sum[k] / n : 0;
}

/* The palette colour nearest in chromaticity and brightness to c. */
static int nearest_colour(const double c[3]) {
  int best = -1;
  double bd = 1e30;
  for (int k = 0; k < 5; k++) {
    double d = 0;
    for (int i = 0; i < 3; i++) d += (c[i] - COLOURS[k][i]) * (c[i] - COLOURS[k][i]);
    if (d < bd) bd = d, best = k;
  }
  return best;
}

static bool render_blender(const char *blender, const char *dir, const char *script, iris_image *img) {
  char cmd[4096], exr[1100];
  snprintf(exr, sizeof exr, "%s/%s.exr", dir, script);
  snprintf(cmd, sizeof cmd,
           "'%s' -b --factory-startup --python-exit-code 1 -P '%s/%s' -- --output '%s' --spp 16 --threads 2 "
           "--seed 5 > '%s/%s.log' 2>&1",
           blender, dir, script, exr, dir, script);
  if (!EXPECT(system(cmd) == 0, "blender failed on %s (log %s/%s.log)", script, dir, script)) return false;
  iris_error err;
  iris_error_clear(&err);
  memset(img, 0, sizeof *img);
  if (iris_exr_read(exr, img, NULL, NULL, &err) != IRIS_OK || img->width != BW || img->height != BH) {
    CHECK_OK(IRIS_ERR_IO, &err);
    return false;
  }
  return true;
}

static int check_blender(void) {
  char blender[1024] = "";
  for (const char *p = getenv("PATH"); p && *p && !blender[0];) {
    size_t n = strcspn(p, ":");
    char cand[1024];
    snprintf(cand, sizeof cand, "%.*s/blender", (int)n, p);
    FILE *fp = fopen(cand, "rb");
    if (fp) fclose(fp), snprintf(blender, sizeof blender, "%s", cand);
    p += n + (p[n] == ':');
  }
  if (!blender[0]) return TEST_SKIP("blender is not installed");
  char dir[1024], path[1200], msg[1400];
  if (!CHECK(iris_test_tmpdir(dir, sizeof dir, "variants-blender") == 0)) return TEST_SUMMARY();
  iris_export_params p = iris_export_params_default();
  p.width = BW, p.height = BH, p.max_depth = 8;
  const float sky[3] = {1, 1, 1};
  /* iris's export (Cycles' Diffuse BSDF: exactly the colour under a white sky) with "sunset",
   * and Blender's own import of the file made to show "ocean" and "forest". */
  struct {
    int v;
    bool own_import;
    const char *script;
  } runs[] = {{1, false, "export-sunset.py"}, {3, true, "import-ocean.py"}, {2, true, "import-forest.py"}};
  for (size_t r = 0; r < 3; r++) {
    iris_scene *s = NULL;
    if (!CHECK(import(data_file, VARIANTS[runs[r].v], &s, msg, sizeof msg) == IRIS_OK)) continue;
    iris_scene_set_environment_color(s, sky);
    snprintf(path, sizeof path, "%s/%s", dir, runs[r].script);
    iris_error err;
    iris_error_clear(&err);
    CHECK_OK(runs[r].own_import ? iris_export_blender_import(s, data_file, path, &p, &err)
                                : iris_export_blender(s, path, &p, &err),
             &err);
    iris_scene_destroy(s);
    iris_image img;
    if (!render_blender(blender, dir, runs[r].script, &img)) continue;
    for (int q = 0; q < 3; q++) {
      double c[3];
      quad_mean(&img, q, c);
      int want = EXPECT_QUADS[runs[r].v][q], got = nearest_colour(c);
      double worst = 0;
      for (int k = 0; k < 3; k++) worst = fmax(worst, fabs(c[k] - COLOURS[want][k]));
      printf("%s quad %d: %.4f %.4f %.4f (%s; expected %s, largest difference %.4f)\n", runs[r].script, q, c[0], c[1],
             c[2], NAMES[got], NAMES[want], worst);
      EXPECT(got == want, "%s: quad %d looks %s, expected %s", runs[r].script, q, NAMES[got], NAMES[want]);
      /* Cycles' Diffuse BSDF under a white sky shows the albedo (16 spp noise); Blender's own
       * import is a Principled BSDF (docs/validation.md), only its colour is compared. */
      if (!runs[r].own_import) EXPECT(worst < 0.03, "%s: quad %d differs by %g", runs[r].script, q, worst);
    }
    iris_image_destroy(&img);
  }
  iris_test_rmtree(dir);
  return TEST_SUMMARY();
}

int main(int argc, char **argv) {
  iris_log_set_level(IRIS_LOG_QUIET);
  snprintf(data_file, sizeof data_file, "%s/variants-quads.gltf", IRIS_GLTF_TEST_DATA);
  const char *part = argc > 1 ? argv[1] : "import";
  if (strcmp(part, "import") == 0) {
    check_import();
  } else if (strcmp(part, "reject") == 0) {
    check_reject();
  } else if (strcmp(part, "cli") == 0 && argc > 2) {
    iris_bin = argv[2];
    check_cli();
  } else if (strcmp(part, "blender") == 0) {
    return check_blender();
  } else {
    fprintf(stderr, "usage: %s import | reject | cli IRIS | blender\n", argv[0]);
    return 2;
  }
  return TEST_SUMMARY();
}
