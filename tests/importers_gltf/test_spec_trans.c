/* KHR_materials_transmission.transmissionTexture and KHR_materials_specular's
 * specularTexture / specularColorTexture (docs/import-gltf.md, docs/format.md):
 * a glTF written here reads one 2x2 RGBA PNG whose channels all differ,
 *   row 0: P = (60, 90, 160, 220), Q = (200, 130, 70, 110); row 1: Z = (0, 50, 100, 150),
 * through three placements: transmission with texCoord 1 (uvs1 at Q's texel
 * centre), specular with texCoord 0 and a KHR_texture_transform offset of
 * (0.5, 0) (uvs at P's centre, moved onto Q), specular colour with texCoord 0
 * (P). The uvs are constant over the quad, so every point reads texel centres
 * exactly. `shade` checks what iris_integrator_shade hands the BSDF:
 * transmission = 0.9 x Q.R / 255, specular = 0.8 x Q.A / 255 (both linear),
 * specular colour = (4, 3, 6) x sRGB-decoded P.RGB, and that a point whose
 * transmission texel is 0 (Z) has no transmission lobe and is shaded
 * two-sided there. `blender` renders the quad in front of an emitter under a
 * sky in iris and, through the Blender export, in Cycles 3.4 and compares
 * them (SKIP 77 without blender); the export script must hold the wiring. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <stb_image_write.h>

#include "core/image.h"
#include "core/log.h"
#include "exporters/blender.h"
#include "exporters/pov.h"
#include "importers/import.h"
#include "renderer/integrator.h"
#include "renderer/render.h"
#include "renderer/texture.h"
#include "scene/scene.h"
#include "tests/common/check.h"
#include "tests/common/render_run.h"

#define EXPECT(cond, ...) iris_check_record(!!(cond), __FILE__, __LINE__, __VA_ARGS__)
#define W 24

static const unsigned char P[4] = {60, 90, 160, 220}, Q[4] = {200, 130, 70, 110}, Z[4] = {0, 50, 100, 150};

/* The quad (z = 0, 2x2, facing +z) with both uv sets, and a 40x40 emitter at z = -1. */
static bool write_files(const char *dir) {
  char path[1200];
  unsigned char img[16];
  memcpy(img, P, 4), memcpy(img + 4, Q, 4), memcpy(img + 8, Z, 4), memcpy(img + 12, Z, 4);
  snprintf(path, sizeof path, "%s/channels.png", dir);
  if (!stbi_write_png(path, 2, 2, 4, img, 8)) return false;
  float buf[4 * 3 + 4 * 3 + 4 * 2 + 4 * 2 + 4 * 3 + 4 * 3];
  float *pos = buf, *nrm = buf + 12, *uv0 = buf + 24, *uv1 = buf + 32, *epos = buf + 40, *enrm = buf + 52;
  const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (int v = 0; v < 4; v++) {
    pos[3 * v] = corners[v][0], pos[3 * v + 1] = corners[v][1], pos[3 * v + 2] = 0;
    epos[3 * v] = 20 * corners[v][0], epos[3 * v + 1] = 20 * corners[v][1], epos[3 * v + 2] = -1;
    nrm[3 * v] = nrm[3 * v + 1] = 0, nrm[3 * v + 2] = 1;
    enrm[3 * v] = enrm[3 * v + 1] = 0, enrm[3 * v + 2] = 1;
    uv0[2 * v] = 0.25f, uv0[2 * v + 1] = 0.25f; /* P's texel centre */
    uv1[2 * v] = 0.75f, uv1[2 * v + 1] = 0.25f; /* Q's */
  }
  const unsigned short idx[6] = {0, 1, 2, 0, 2, 3};
  snprintf(path, sizeof path, "%s/quad.bin", dir);
  FILE *f = fopen(path, "wb");
  if (!f) return false;
  bool ok = fwrite(buf, sizeof buf, 1, f) == 1 && fwrite(idx, sizeof idx, 1, f) == 1;
  ok = fclose(f) == 0 && ok;
  snprintf(path, sizeof path, "%s/quad.gltf", dir);
  f = fopen(path, "w");
  if (!f) return false;
  if (!ok) {
    fclose(f);
    return false;
  }
  fprintf(f,
          "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_materials_transmission\","
          "\"KHR_materials_specular\",\"KHR_texture_transform\",\"KHR_materials_emissive_strength\"],"
          "\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2]}],"
          "\"nodes\":[{\"mesh\":0},{\"mesh\":1},{\"camera\":0,\"translation\":[0,0,3]}],"
          "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.4,\"znear\":0.01,\"aspectRatio\":1}}],"
          "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2,"
          "\"TEXCOORD_1\":3},\"indices\":6,\"material\":0}]},"
          "{\"primitives\":[{\"attributes\":{\"POSITION\":4,\"NORMAL\":5},\"indices\":6,\"material\":1}]}],"
          "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.8,0.7,0.6,1],\"metallicFactor\":0,"
          "\"roughnessFactor\":0},\"extensions\":{"
          "\"KHR_materials_transmission\":{\"transmissionFactor\":0.9,\"transmissionTexture\":{\"index\":0,"
          "\"texCoord\":1}},"
          "\"KHR_materials_specular\":{\"specularFactor\":0.8,\"specularTexture\":{\"index\":0,\"extensions\":"
          "{\"KHR_texture_transform\":{\"offset\":[0.5,0]}}},\"specularColorFactor\":[4,3,6],"
          "\"specularColorTexture\":{\"index\":0}}}},"
          "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1]},\"emissiveFactor\":[1,1,1],"
          "\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":6}}}],"
          "\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"channels.png\"}],"
          "\"buffers\":[{\"uri\":\"quad.bin\",\"byteLength\":%zu}],"
          "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu},"
          "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":12}],"
          "\"accessors\":[",
          sizeof buf + sizeof idx, sizeof buf, sizeof buf);
  const struct {
    int offset;
    const char *type;
  } acc[6] = {{0, "VEC3"}, {48, "VEC3"}, {96, "VEC2"}, {128, "VEC2"}, {160, "VEC3"}, {208, "VEC3"}};
  for (int k = 0; k < 6; k++) {
    fprintf(f, "{\"bufferView\":0,\"byteOffset\":%d,\"componentType\":5126,\"count\":4,\"type\":\"%s\"", acc[k].offset,
            acc[k].type);
    if (k == 0) fputs(",\"min\":[-1,-1,0],\"max\":[1,1,0]", f);
    if (k == 4) fputs(",\"min\":[-20,-20,-1],\"max\":[20,20,-1]", f);
    fputs("},", f);
  }
  fputs("{\"bufferView\":1,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}]}\n", f);
  return fclose(f) == 0;
}

/* CHECK_OK as an expression: true when the call succeeded. */
static bool ok_call(iris_status st, iris_error *err) {
  CHECK_OK(st, err);
  return st == IRIS_OK;
}

static float srgb8(unsigned char c) { return iris_srgb_to_linear((float)c / 255.0f); }

static void shade_at(const iris_scene *s, const iris_textures *tex, const float uv[2], const float uv1[2],
                     iris_vec3 wo, iris_shading_point *sp) {
  iris_integrator it = iris_integrator_default(s, NULL, NULL, tex);
  iris_interaction si;
  memset(&si, 0, sizeof si);
  si.ng = si.ns = iris_v3(0, 0, 1);
  memcpy(si.uv, uv, sizeof si.uv);
  memcpy(si.uv1, uv1, sizeof si.uv1);
  si.color = iris_v3(1, 1, 1);
  si.material = 0;
  si.front = wo.z > 0;
  iris_integrator_shade(&it, &si, wo, 0, sp);
}

/* The scene format keeps the three fields (written, read back equal) and
 * rejects an index past the textures on load. */
static void check_format(const iris_scene *s, const char *dir) {
  char json[1200];
  snprintf(json, sizeof json, "%s/scene.json", dir);
  iris_error err;
  iris_error_clear(&err);
  iris_scene *back = NULL;
  if (!ok_call(iris_scene_write(s, json, &err), &err) || !ok_call(iris_scene_load(json, &back, &err), &err)) return;
  const iris_material *a = &s->materials[0], *b = &back->materials[0];
  CHECK(a->transmission_texture == b->transmission_texture && a->specular_texture == b->specular_texture &&
        a->specular_color_texture == b->specular_color_texture);
  back->materials[0].specular_texture = (int32_t)back->texture_count;
  iris_error_clear(&err);
  CHECK(iris_scene_validate(back, json, &err) != IRIS_OK && strstr(err.message, "specular_texture"));
  iris_scene_destroy(back);
}

/* POV-Ray cannot drive filter or reflection by a texture: one warning per kind
 * (stderr captured), naming the number of materials. */
static void check_pov(const iris_scene *s, const char *dir) {
  char pov[1200], log[1200];
  snprintf(pov, sizeof pov, "%s/quad.pov", dir);
  snprintf(log, sizeof log, "%s/pov.log", dir);
  fflush(stderr);
  int saved = dup(2);
  FILE *f = fopen(log, "w");
  if (!CHECK(saved >= 0 && f)) return;
  dup2(fileno(f), 2);
  iris_export_params p = iris_export_params_default();
  iris_error err;
  iris_error_clear(&err);
  iris_status st = iris_export_pov(s, pov, &p, &err);
  fflush(stderr);
  dup2(saved, 2);
  close(saved);
  fclose(f);
  ok_call(st, &err);
  static char text[1 << 16];
  f = fopen(log, "r");
  size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
  if (f) fclose(f);
  text[n] = 0;
  const char *t = strstr(text, "1 material(s) with a transmission texture");
  const char *sp = strstr(text, "1 material(s) with a specular or specular colour texture");
  EXPECT(t && !strstr(t + 20, "with a transmission texture") && sp && !strstr(sp + 20, "with a specular or"),
         "POV-Ray export: expected one warning per kind, got: %s", text);
}

static int check_shade(const iris_scene *s) {
  const iris_material *m = &s->materials[0];
  if (!CHECK(m->type == IRIS_MATERIAL_GLTF && m->transmission_texture >= 0 && m->specular_texture >= 0 &&
             m->specular_color_texture >= 0))
    return TEST_SUMMARY();
  /* one scene texture per placement of the one image */
  const iris_texture *tt = &s->textures[m->transmission_texture], *ts = &s->textures[m->specular_texture],
                     *tc = &s->textures[m->specular_color_texture];
  CHECK(tt->uv_set == 1 && !tt->has_transform);
  CHECK(ts->uv_set == 0 && ts->has_transform && ts->offset[0] == 0.5f && ts->offset[1] == 0.0f);
  CHECK(tc->uv_set == 0 && !tc->has_transform);
  CHECK(m->transmission_texture != m->specular_texture && m->specular_texture != m->specular_color_texture);

  iris_textures tex;
  iris_error err;
  iris_error_clear(&err);
  if (!ok_call(iris_textures_load(s, &tex, &err), &err)) return TEST_SUMMARY();
  const float uv[2] = {0.25f, 0.25f}, uv1[2] = {0.75f, 0.25f};
  iris_shading_point sp;
  shade_at(s, &tex, uv, uv1, iris_v3(0.3f, 0.0f, 0.95f), &sp);
  const float t_exp = 0.9f * Q[0] / 255.0f, s_exp = 0.8f * Q[3] / 255.0f;
  const float c_exp[3] = {4.0f * srgb8(P[0]), 3.0f * srgb8(P[1]), 6.0f * srgb8(P[2])};
  printf("transmission %.5f (expected %.5f), specular %.5f (%.5f), specular colour %.5f %.5f %.5f (%.5f %.5f %.5f)\n",
         sp.bsdf.transmission, t_exp, sp.bsdf.specular, s_exp, sp.bsdf.specular_color.x, sp.bsdf.specular_color.y,
         sp.bsdf.specular_color.z, c_exp[0], c_exp[1], c_exp[2]);
  EXPECT(fabsf(sp.bsdf.transmission - t_exp) < 1e-4f, "transmission %g, expected 0.9 x R of Q = %g",
         sp.bsdf.transmission, t_exp);
  EXPECT(fabsf(sp.bsdf.specular - s_exp) < 1e-4f, "specular %g, expected 0.8 x A of Q = %g", sp.bsdf.specular, s_exp);
  const float got[3] = {sp.bsdf.specular_color.x, sp.bsdf.specular_color.y, sp.bsdf.specular_color.z};
  for (int k = 0; k < 3; k++)
    EXPECT(fabsf(got[k] - c_exp[k]) < 1e-3f * c_exp[k], "specular colour[%d] %g, expected factor x sRGB-decoded P = %g",
           k, got[k], c_exp[k]);
  CHECK(sp.lobes & IRIS_LOBE_TRANSMISSION);

  /* Where the transmission texel is 0 (Z, row 1 of uvs1) the point does not
   * transmit: no transmission lobe, and seen from below it is shaded
   * two-sided (normals turned to wo's side), as an opaque material. */
  const float uv1_z[2] = {0.75f, 0.75f};
  shade_at(s, &tex, uv, uv1_z, iris_v3(0.0f, 0.3f, -0.95f), &sp);
  CHECK(sp.bsdf.transmission == 0.0f);
  CHECK(!(sp.lobes & IRIS_LOBE_TRANSMISSION));
  CHECK(sp.si.ng.z < 0.0f && sp.wo_local.z > 0.0f);
  /* ... and where it is not 0, seen from below keeps the outward normal (inside). */
  shade_at(s, &tex, uv, uv1, iris_v3(0.0f, 0.3f, -0.95f), &sp);
  CHECK((sp.lobes & IRIS_LOBE_TRANSMISSION) && sp.si.ng.z > 0.0f && sp.wo_local.z < 0.0f);

  /* The specular pair packed in one image with one placement (one scene texture,
   * read once): A still linear, RGB still sRGB-decoded. */
  iris_material *mm = &((iris_scene *)s)->materials[0];
  const int32_t keep = mm->specular_texture;
  mm->specular_texture = mm->specular_color_texture;
  shade_at(s, &tex, uv, uv1, iris_v3(0.3f, 0.0f, 0.95f), &sp);
  mm->specular_texture = keep;
  EXPECT(fabsf(sp.bsdf.specular - 0.8f * P[3] / 255.0f) < 1e-4f, "packed: specular %g, expected 0.8 x A of P = %g",
         sp.bsdf.specular, 0.8f * P[3] / 255.0f);
  EXPECT(fabsf(sp.bsdf.specular_color.z - c_exp[2]) < 1e-3f * c_exp[2], "packed: specular colour %g, expected %g",
         sp.bsdf.specular_color.z, c_exp[2]);
  iris_textures_destroy(&tex);
  return TEST_SUMMARY();
}

/* Mean radiance of the image (the quad fills it). */
static bool render_mean(const iris_scene *s, double mean[3]) {
  iris_render_params p = iris_test_params(W, W, 64, IRIS_METHOD_COUNT, 5); /* the scene's method */
  p.max_depth = 8;
  return CHECK(iris_test_render_mean(s, &p, mean, NULL));
}

static bool find_blender(char *out, size_t size) {
  out[0] = 0;
  for (const char *p = getenv("PATH"); p && *p && !out[0];) {
    size_t n = strcspn(p, ":");
    char cand[1024];
    snprintf(cand, sizeof cand, "%.*s/blender", (int)n, p);
    FILE *f = fopen(cand, "rb");
    if (f) fclose(f), snprintf(out, size, "%s", cand);
    p += n + (p[n] == ':');
  }
  return out[0] != 0;
}

static int check_blender(iris_scene *s, const char *dir) {
  char script[1200], exr[1200], cmd[4096], log[1200], blender[1024];
  snprintf(script, sizeof script, "%s/quad.py", dir);
  snprintf(exr, sizeof exr, "%s/quad.exr", dir);
  snprintf(log, sizeof log, "%s/blender.log", dir);
  s->has_environment = true;
  s->environment[0] = s->environment[1] = s->environment[2] = 1.5f;
  iris_export_params p = iris_export_params_default();
  p.width = p.height = W, p.max_depth = 8;
  iris_error err;
  iris_error_clear(&err);
  if (!ok_call(iris_export_blender(s, script, &p, &err), &err)) return TEST_SUMMARY();
  /* the wiring: each texture in the material's dict, read through its channel */
  FILE *f = fopen(script, "r");
  static char text[1 << 20];
  size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
  if (f) fclose(f);
  text[n] = 0;
  char want[64];
  snprintf(want, sizeof want, "trans_tex=%d, spec_tex=%d, spec_color_tex=%d", (int)s->materials[0].transmission_texture,
           (int)s->materials[0].specular_texture, (int)s->materials[0].specular_color_texture);
  EXPECT(strstr(text, want) != NULL, "the export script lacks '%s'", want);
  EXPECT(strstr(text, "texture_node(nt, m[\"trans_tex\"], \"Non-Color\").outputs[\"Color\"]") &&
             strstr(text, "sep.outputs[\"Red\"], T)") &&
             strstr(text, "texture_node(nt, m[\"spec_tex\"], \"Non-Color\").outputs[\"Alpha\"]") &&
             strstr(text, "texture_node(nt, m[\"spec_color_tex\"], \"sRGB\")"),
         "the export script does not read transmission R, specular A (linear) and specular colour (sRGB)");

  double iris_mean[3], plain[3];
  if (!render_mean(s, iris_mean)) return TEST_SUMMARY();
  /* the same scene without each texture in turn: the comparison must be able to tell */
  const char *which[3] = {"transmission", "specular", "specular colour"};
  for (int t = 0; t < 3; t++) {
    iris_material keep = s->materials[0];
    int32_t *field[3] = {&s->materials[0].transmission_texture, &s->materials[0].specular_texture,
                         &s->materials[0].specular_color_texture};
    *field[t] = -1;
    bool ok = render_mean(s, plain);
    s->materials[0] = keep;
    if (!ok) return TEST_SUMMARY();
    double change = 0;
    for (int k = 0; k < 3; k++) change = fmax(change, fabs(plain[k] / iris_mean[k] - 1));
    printf("iris: %.4f %.4f %.4f; without the %s texture %.4f %.4f %.4f (%.1f%%)\n", iris_mean[0], iris_mean[1],
           iris_mean[2], which[t], plain[0], plain[1], plain[2], 100 * change);
    EXPECT(change > 0.03, "the %s texture changes the image by only %.2f%%", which[t], 100 * change);
  }

  if (!find_blender(blender, sizeof blender)) return TEST_SKIP("blender is not installed");
  snprintf(cmd, sizeof cmd,
           "'%s' -b --factory-startup --python-exit-code 1 -P '%s' -- --output '%s' --spp 64 --threads 2 "
           "--seed 7 > '%s' 2>&1",
           blender, script, exr, log);
  if (!CHECK(system(cmd) == 0)) return TEST_SUMMARY();
  iris_image img;
  memset(&img, 0, sizeof img);
  iris_error_clear(&err);
  if (ok_call(iris_exr_read(exr, &img, NULL, NULL, &err), &err) && CHECK(img.width == W && img.height == W)) {
    const char *names[3] = {"R", "G", "B"};
    for (int k = 0; k < 3; k++) {
      int ch = iris_image_channel(&img, names[k]);
      double mean = 0;
      for (size_t i = 0; i < (size_t)W * W; i++) mean += img.data[i * (size_t)img.channel_count + (size_t)ch];
      mean /= W * W;
      printf("channel %s: iris %.4f, Cycles %.4f, iris / Cycles %.4f\n", names[k], iris_mean[k], mean,
             iris_mean[k] / mean);
      /* smooth lobes: the export's node tree is exact (docs/export.md); 1% allows the noise */
      EXPECT(fabs(iris_mean[k] / mean - 1) < 0.01, "channel %s: iris %g, Cycles %g", names[k], iris_mean[k], mean);
    }
  }
  iris_image_destroy(&img);
  return TEST_SUMMARY();
}

int main(int argc, char **argv) {
  iris_log_set_level(IRIS_LOG_WARN);
  const bool blender = argc > 1 && strcmp(argv[1], "blender") == 0;
  char dir[1024], path[1200];
  if (!CHECK(iris_test_tmpdir(dir, sizeof dir, "spec-trans") == 0)) return TEST_SUMMARY();
  if (!CHECK(write_files(dir))) return TEST_SUMMARY();
  snprintf(path, sizeof path, "%s/quad.gltf", dir);
  iris_import_options opts = iris_import_options_default();
  iris_error e;
  iris_error_clear(&e);
  iris_scene *s = NULL;
  int rc;
  if (!ok_call(iris_import_file(path, &opts, &s, &e), &e) || !s) {
    rc = TEST_SUMMARY();
  } else {
    if (!blender) check_format(s, dir), check_pov(s, dir);
    rc = blender ? check_blender(s, dir) : check_shade(s);
    iris_scene_destroy(s);
  }
  iris_test_rmtree(dir);
  return rc;
}
