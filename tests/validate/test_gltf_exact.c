/* validate.gltf_exact: glTF scenes whose materials Cycles can reproduce exactly,
 * written as real .gltf files, imported by iris, exported to Blender (the
 * Appendix B node tree of exporters/blender_prelude.c) and rendered by real Blender
 * (SKIP without it), through iris_validate_run: every channel's mean within 1%
 * of iris and the 8x8 block z-test passing.
 *   room:  a Lambert-only room (specularFactor 0: imported as `diffuse`)
 *   metal: metallic 1 GGX spheres, roughness 0.08-0.5, on a metal floor under
 *          a uniform sky (the residual of the N.V Fresnel and Cycles' separable
 *          G is measured in docs/export.md; it is inside 1% here)
 *   glass: a smooth glTF glass sphere, a smooth coated plastic and a mirror on a
 *          Lambert floor under the sky (all exact: mirrors have V.H = N.V)
 * argv[1] (optional): "print" to print the ratios only, without checks. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/fileio.h"
#include "core/log.h"
#include "gltf_writer.h"
#include "importers/import.h"
#include "validate/validate.h"

#define LAMBERT(name, r, g, b)                                                              \
  "{\"name\":\"" name "\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[" #r "," #g "," #b \
  ",1],\"metallicFactor\":0,\"roughnessFactor\":1},\"extensions\":{\"KHR_materials_specular\":{" \
  "\"specularFactor\":0}}}"
#define METAL(name, r, g, b, rough)                                                         \
  "{\"name\":\"" name "\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[" #r "," #g "," #b \
  ",1],\"metallicFactor\":1,\"roughnessFactor\":" #rough "}}"

static bool blender_missing = false;

/* Imports gltf, adds a constant sky when env != NULL, writes an iris scene and
 * validates it against Blender. Returns the result's `passed`. */
static bool run(const char *dir, const char *name, const char *gltf, const float *env, int w, int h,
                int expect_diffuse) {
  char json[700], out[700];
  iris_error err;
  iris_scene *scene = NULL;
  if (iris_import_file(gltf, NULL, &scene, &err) != IRIS_OK) {
    CHECK(!"import failed");
    fprintf(stderr, "%s\n", err.message);
    return false;
  }
  int diffuse = 0;
  for (size_t i = 0; i < scene->material_count; i++) diffuse += scene->materials[i].type == IRIS_MATERIAL_DIFFUSE;
  CHECK_EQ_INT(diffuse, expect_diffuse);
  if (env) {
    scene->has_environment = true;
    memcpy(scene->environment, env, sizeof scene->environment);
  }
  snprintf(json, sizeof json, "%s/%s.json", dir, name);
  snprintf(out, sizeof out, "%s/out-%s", dir, name);
  CHECK(iris_scene_write(scene, json, &err) == IRIS_OK);
  iris_scene_destroy(scene);
  iris_validate_params p = iris_validate_params_default();
  p.input = json;
  p.source = IRIS_REFERENCE_BLENDER;
  p.spp = 128;
  p.blender_spp = 128;
  p.width = w;
  p.height = h;
  p.threads = 2;
  p.seed = 5;
  p.out_dir = out;
  p.quiet = true;
  iris_validate_result r;
  iris_status st = iris_validate_run(&p, &r, &err);
  if (st != IRIS_OK) {
    if (st == IRIS_ERR_USAGE) blender_missing = true;
    fprintf(stderr, "%s: %s\n", name, err.message);
    if (!blender_missing) CHECK(!"validate failed to run");
    return false;
  }
  const iris_validate_method *m = &r.methods[0];
  printf("%s: iris/Cycles %.4f %.4f %.4f (+- %.4f %.4f %.4f), energy %.4f, block max |z| %.2f (crit %.2f, %llu over), %s\n",
         name, m->channel_ratio[0], m->channel_ratio[1], m->channel_ratio[2], m->ratio_se[0],
         m->ratio_se[1], m->ratio_se[2], m->energy_ratio, m->blocks.max_abs_z, m->blocks.z_crit,
         (unsigned long long)m->blocks.z_over,
         r.passed ? "passed" : "FAILED");
  for (int c = 0; c < 3; c++) CHECK(fabs(m->channel_ratio[c] - 1.0) <= 0.01);
  CHECK(m->blocks.passed);
  CHECK(r.passed);
  return r.passed;
}

int main(void) {
  iris_log_set_level(IRIS_LOG_WARN);
  char dir[512], path[700];
  if (iris_test_tmpdir(dir, sizeof dir, "gltf-exact") != 0) return 1;

  /* room: five coloured Lambert walls, a Lambert block and a one-sided emitter
   * panel (split 6 x 6 so that Cycles keeps area sampling, docs/export.md). */
  {
    gltf_writer w = {0};
    int white = gw_material(&w, LAMBERT("white", 0.7, 0.7, 0.7));
    int red = gw_material(&w, LAMBERT("red", 0.7, 0.15, 0.1));
    int green = gw_material(&w, LAMBERT("green", 0.1, 0.6, 0.15));
    int light = gw_material(&w,
        "{\"name\":\"light\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],\"metallicFactor\":0},"
        "\"emissiveFactor\":[1,0.9,0.8],\"extensions\":{\"KHR_materials_emissive_strength\":{"
        "\"emissiveStrength\":12},\"KHR_materials_specular\":{\"specularFactor\":0}}}");
    struct { float p[3], u[3], v[3]; int mat; } walls[] = {
        {{-1, -1, -1}, {0, 0, 2}, {2, 0, 0}, white},  /* floor */
        {{-1, 1, -1}, {2, 0, 0}, {0, 0, 2}, white},   /* ceiling */
        {{-1, -1, -1}, {2, 0, 0}, {0, 2, 0}, white},  /* back */
        {{-1, -1, 1}, {0, 2, 0}, {2, 0, 0}, white},   /* front, behind the camera */
        {{-1, -1, -1}, {0, 2, 0}, {0, 0, 2}, red},    /* left */
        {{1, -1, -1}, {0, 0, 2}, {0, 2, 0}, green},   /* right */
    };
    for (size_t i = 0; i < sizeof walls / sizeof *walls; i++)
      gw_quad(&w, gw_mesh_begin(&w, walls[i].mat), walls[i].p, walls[i].u, walls[i].v, 1);
    float lo[3] = {-0.6f, -1.0f, -0.6f}, hi[3] = {-0.1f, -0.3f, -0.1f};
    gw_box(&w, gw_mesh_begin(&w, white), lo, hi, false, 1);
    float lp[3] = {-0.3f, 0.98f, -0.3f}, lu[3] = {0.6f, 0, 0}, lv[3] = {0, 0, 0.6f};
    gw_quad(&w, gw_mesh_begin(&w, light), lp, lu, lv, 6);
    float cp[3] = {0, 0, 0.95f}, q[4] = {0, 0, 0, 1};
    gw_camera(&w, cp, q, 1.2f, 1.0f);
    snprintf(path, sizeof path, "%s/room.gltf", dir);
    CHECK(gw_write(&w, path) == 0);
    run(dir, "room", path, NULL, 64, 64, 4);
  }
  if (blender_missing) {
    iris_test_rmtree(dir);
    return TEST_SKIP("Blender is not installed");
  }

  /* metal: four metallic-1 spheres (roughness 0.08, 0.2, 0.35, 0.5) on a metal floor. */
  const float sky[3] = {1.0f, 0.9f, 0.8f};
  float pitch = -0.3588f; /* atan(1.2 / 3.2) down */
  float cam_q[4] = {sinf(pitch / 2), 0, 0, cosf(pitch / 2)}, cam_p[3] = {0, 1.6f, 3.2f};
  {
    gltf_writer w = {0};
    const char *mats[4] = {METAL("gold", 1.0, 0.77, 0.34, 0.08), METAL("copper", 0.95, 0.64, 0.54, 0.2),
                           METAL("silver", 0.97, 0.96, 0.91, 0.35), METAL("aluminium", 0.91, 0.92, 0.92, 0.5)};
    for (int i = 0; i < 4; i++) {
      float c[3] = {-1.5f + (float)i, 0.5f, 0.0f};
      gw_sphere(&w, gw_mesh_begin(&w, gw_material(&w, mats[i])), c, 0.45f, 24, 48);
    }
    float fp[3] = {-3, 0, -3}, fu[3] = {0, 0, 6}, fv[3] = {6, 0, 0};
    gw_quad(&w, gw_mesh_begin(&w, gw_material(&w, METAL("floor", 0.9, 0.9, 0.9, 0.3))), fp, fu, fv, 1);
    gw_camera(&w, cam_p, cam_q, 0.7f, 1.5f);
    snprintf(path, sizeof path, "%s/metal.gltf", dir);
    CHECK(gw_write(&w, path) == 0);
    run(dir, "metal", path, sky, 96, 64, 0);
  }

  /* glass: smooth glTF glass, a smooth coated red plastic, a smooth mirror on Lambert. */
  {
    gltf_writer w = {0};
    int glass = gw_material(&w,
        "{\"name\":\"glass\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,1],\"metallicFactor\":0,"
        "\"roughnessFactor\":0},\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
        "\"KHR_materials_ior\":{\"ior\":1.5}}}");
    int plastic = gw_material(&w,
        "{\"name\":\"plastic\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.8,0.1,0.05,1],"
        "\"metallicFactor\":0,\"roughnessFactor\":0}}");
    int mirror = gw_material(&w, METAL("mirror", 0.95, 0.93, 0.88, 0.0));
    int floor = gw_material(&w, LAMBERT("floor", 0.8, 0.8, 0.8));
    float c0[3] = {-1.0f, 0.5f, 0.0f}, c1[3] = {0.0f, 0.5f, 0.0f}, c2[3] = {1.0f, 0.5f, 0.0f};
    gw_sphere(&w, gw_mesh_begin(&w, glass), c0, 0.45f, 32, 64);
    gw_sphere(&w, gw_mesh_begin(&w, plastic), c1, 0.45f, 24, 48);
    gw_sphere(&w, gw_mesh_begin(&w, mirror), c2, 0.45f, 24, 48);
    float fp[3] = {-3, 0, -3}, fu[3] = {0, 0, 6}, fv[3] = {6, 0, 0};
    gw_quad(&w, gw_mesh_begin(&w, floor), fp, fu, fv, 1);
    gw_camera(&w, cam_p, cam_q, 0.7f, 1.5f);
    snprintf(path, sizeof path, "%s/glass.gltf", dir);
    CHECK(gw_write(&w, path) == 0);
    run(dir, "glass", path, sky, 96, 64, 1);
  }
  if (iris_check_failures == 0) iris_test_rmtree(dir);
  else printf("outputs kept in %s\n", dir);
  return TEST_SUMMARY();
}
