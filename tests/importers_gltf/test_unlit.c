/* KHR_materials_unlit (docs/import-gltf.md, docs/format.md "unlit"): the
 * surface shows base colour x texture x vertex colour as radiance and scatters
 * nothing. tests/importers_gltf/data/unlit-quads.gltf holds an unlit quad
 * (base colour 0.2 0.5 0.8, with metallic and an emissive factor the extension
 * says to ignore), a vertex-coloured unlit quad (0.8 0.6 0.4 x COLOR_0
 * 0.5 1 0.25) and a lit white wall behind them. Rendered with bsdf, nee and mis
 * in the dark, under a bright sky, and under the sky plus a point light, every
 * pixel of each quad is exactly its colour (no noise: nothing scatters), while
 * the wall's pixels change with the lighting. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/image.h"
#include "core/log.h"
#include "exporters/blender.h"
#include "importers/import.h"
#include "renderer/render.h"
#include "scene/scene.h"
#include "tests/common/check.h"
#include "tests/common/render_run.h"

#define EXPECT(cond, ...) iris_check_record(!!(cond), __FILE__, __LINE__, __VA_ARGS__)
#define W 40

static bool render(const iris_scene *s, iris_method m, iris_vec3 *pix) {
  iris_render_params p = iris_test_params(W, W, 16, m, 3);
  return iris_test_render_pixels(s, &p, pix);
}

/* Largest difference between the unlit quads' pixels and their colours. */
static double unlit_error(const float *const *chan, const float expect[2][3], size_t stride) {
  double worst = 0;
  for (int y = 0; y < W; y++)
    for (int x = 0; x < W; x++) {
      /* pixel centres at least 0.1 inside a quad (the filter may mix across edges) */
      const float px = -1.25f + 2.5f * ((float)x + 0.5f) / W, py = -1.25f + 2.5f * ((float)y + 0.5f) / W;
      if (fabsf(py) > 0.9f || fabsf(px) > 0.9f || fabsf(px) < 0.1f) continue;
      const float *c = expect[x >= W / 2];
      for (int k = 0; k < 3; k++) worst = fmax(worst, fabs(chan[k][((size_t)y * W + x) * stride] - c[k]));
    }
  return worst;
}

/* The same lit scene exported to Blender and rendered by Cycles 3.4: the
 * unlit quads are Emission (strength 1) over a black Diffuse, so Cycles shows
 * the same colours; SKIP (77) without blender. */
static int check_blender(iris_scene *s, const float expect[2][3]) {
  char blender[1024] = "";
  const char *path_env = getenv("PATH");
  for (const char *p = path_env; p && *p && !blender[0];) {
    size_t n = strcspn(p, ":");
    char cand[1024];
    snprintf(cand, sizeof cand, "%.*s/blender", (int)n, p);
    FILE *f = fopen(cand, "rb");
    if (f) fclose(f), snprintf(blender, sizeof blender, "%s", cand);
    p += n + (p[n] == ':');
  }
  if (!blender[0]) return TEST_SKIP("blender is not installed");
  char dir[1024], script[1100], exr[1100], cmd[4096], log[1200];
  if (!CHECK(iris_test_tmpdir(dir, sizeof dir, "unlit-blender") == 0)) return TEST_SUMMARY();
  snprintf(script, sizeof script, "%s/unlit.py", dir);
  snprintf(exr, sizeof exr, "%s/unlit.exr", dir);
  snprintf(log, sizeof log, "%s/blender.log", dir);
  iris_export_params p = iris_export_params_default();
  p.width = p.height = W, p.max_depth = 8;
  iris_error err;
  iris_error_clear(&err);
  CHECK_OK(iris_export_blender(s, script, &p, &err), &err);
  snprintf(cmd, sizeof cmd,
           "'%s' -b --factory-startup --python-exit-code 1 -P '%s' -- --output '%s' --spp 4 --threads 2 "
           "--seed 7 > '%s' 2>&1",
           blender, script, exr, log);
  if (CHECK(system(cmd) == 0)) {
    iris_image img;
    memset(&img, 0, sizeof img);
    iris_error_clear(&err);
    if (iris_exr_read(exr, &img, NULL, NULL, &err) == IRIS_OK && img.width == W && img.height == W) {
      const char *names[3] = {"R", "G", "B"};
      const float *chan[3];
      for (int k = 0; k < 3; k++) {
        int ch = iris_image_channel(&img, names[k]);
        chan[k] = ch >= 0 ? img.data + ch : img.data;
      }
      double worst = unlit_error(chan, expect, (size_t)img.channel_count);
      printf("Cycles: largest difference of the unlit pixels from the base colour %.3g\n", worst);
      /* EXR half floats hold 0.8 to 2^-11 (5e-4) */
      EXPECT(worst <= 1e-3, "Cycles: unlit pixels differ from the base colour by %g", worst);
    } else {
      CHECK_OK(IRIS_ERR_IO, &err);
    }
    iris_image_destroy(&img);
  }
  iris_test_rmtree(dir);
  return TEST_SUMMARY();
}

int main(int argc, char **argv) {
  iris_log_set_level(IRIS_LOG_WARN);
  const bool blender = argc > 1 && strcmp(argv[1], "blender") == 0;
  char path[1024];
  snprintf(path, sizeof path, "%s/unlit-quads.gltf", IRIS_GLTF_TEST_DATA);
  iris_import_options o = iris_import_options_default();
  iris_error e;
  iris_error_clear(&e);
  iris_scene *s = NULL;
  CHECK_OK(iris_import_gltf(path, &o, &s, &e), &e);
  if (!s) return TEST_SUMMARY();
  /* The stored form: a black diffuse emitting the base colour, marked unlit. */
  for (int k = 0; k < 2; k++) {
    const iris_material *m = &s->materials[k];
    CHECK(m->unlit && m->type == IRIS_MATERIAL_DIFFUSE && m->color[0] == 0 && m->color[1] == 0 && m->color[2] == 0);
  }
  CHECK(s->materials[0].emission[0] == 0.2f && s->materials[0].emission[1] == 0.5f &&
        s->materials[0].emission[2] == 0.8f); /* emissiveFactor (1, 0, 0) ignored */
  CHECK(!s->materials[2].unlit);

  /* The file's camera, on +z: the plain quad left of x = 0, the vertex-coloured one right of it. */
  CHECK(s->camera_count == 1);
  const float expect[2][3] = {{0.2f, 0.5f, 0.8f}, {0.8f * 0.5f, 0.6f * 1.0f, 0.4f * 0.25f}};

  if (blender) { /* lit by the sky and a bulb */
    s->has_environment = true;
    s->environment[0] = s->environment[1] = s->environment[2] = 3.0f;
    iris_light l;
    memset(&l, 0, sizeof l);
    l.name = iris_strdup("bulb");
    l.type = IRIS_LIGHT_POINT;
    l.color[0] = l.color[1] = l.color[2] = 1.0f;
    l.intensity = 40.0f;
    l.position[2] = 2.0f;
    iris_scene_add_light(s, &l);
    int rc = check_blender(s, expect);
    iris_scene_destroy(s);
    return rc;
  }

  /* Lighting: none; a sky of radiance 3; the sky and a point light of 40 W/sr at z = 2. */
  static iris_vec3 pix[W * W];
  const iris_method methods[3] = {IRIS_METHOD_BSDF, IRIS_METHOD_NEE, IRIS_METHOD_MIS};
  double wall_lit[3] = {0, 0, 0};
  for (int light = 0; light < 3; light++) {
    if (light == 1) {
      s->has_environment = true;
      s->environment[0] = s->environment[1] = s->environment[2] = 3.0f;
    }
    if (light == 2) {
      iris_light l;
      memset(&l, 0, sizeof l);
      l.name = iris_strdup("bulb");
      l.type = IRIS_LIGHT_POINT;
      l.color[0] = l.color[1] = l.color[2] = 1.0f;
      l.intensity = 40.0f;
      l.position[2] = 2.0f;
      iris_scene_add_light(s, &l);
    }
    for (int k = 0; k < 3; k++) {
      if (!render(s, methods[k], pix)) continue;
      double worst = 0;
      for (int y = 0; y < W; y++)
        for (int x = 0; x < W; x++) {
          /* pixel centres at least 0.1 inside a quad (the filter may mix across edges) */
          const float px = -1.25f + 2.5f * ((float)x + 0.5f) / W, py = -1.25f + 2.5f * ((float)y + 0.5f) / W;
          if (fabsf(py) > 0.9f || fabsf(px) > 0.9f || fabsf(px) < 0.1f) continue;
          const float *c = expect[x >= W / 2];
          const iris_vec3 p = pix[y * W + x];
          worst = fmax(worst, fmax(fabs(p.x - c[0]), fmax(fabs(p.y - c[1]), fabs(p.z - c[2]))));
        }
      printf("lighting %d, %s: largest difference from the base colour %.3g\n", light, iris_method_name(methods[k]),
             worst);
      EXPECT(worst <= 1e-5, "lighting %d %s: unlit pixels differ from the base colour by %g", light,
             iris_method_name(methods[k]), worst);
      if (methods[k] == IRIS_METHOD_MIS) /* the wall, seen left and right of the quads */
        wall_lit[light] = (pix[(W / 2) * W].y + pix[(W / 2) * W + W - 1].y) / 2;
    }
  }
  printf("wall (edge pixels, luminance): dark %.4f, sky %.4f, sky + bulb %.4f\n", wall_lit[0], wall_lit[1],
         wall_lit[2]);
  CHECK(wall_lit[0] == 0.0 && wall_lit[1] > 0.1 && wall_lit[2] > wall_lit[1]);
  iris_scene_destroy(s);
  return TEST_SUMMARY();
}
