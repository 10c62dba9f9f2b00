/* Blender 3.4 exporter (exporters/blender.h, docs/export.md): writes this
 * scene's data tables after the fixed Python prelude (blender_prelude.c: the
 * functions that build a scene from plain data tables and set the
 * fair-comparison Cycles settings) and a call to main(); the script for
 * Blender's own glTF importer is in blender_import.c. Mesh arrays are stored
 * once, little-endian, in a sidecar file (or a base64 blob in the script) and
 * read with numpy + foreach_set, the fast path for large meshes. */
#define _DEFAULT_SOURCE /* realpath */
#include "exporters/blender.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "core/log.h"
#include "exporters/blender_script.h"

/* ---- small writers --------------------------------------------------------- */

/* Python float literal: shortest round-trip form of a finite float. */
static void put_float(FILE *fp, float v) {
  if (!isfinite(v)) v = 0.0f; /* unreachable after validation; keeps the script valid */
  char buf[32];
  snprintf(buf, sizeof buf, "%.9g", (double)v);
  /* "1e+10" and "3" are valid Python floats/ints; make integers floats. */
  if (!strpbrk(buf, ".eEn")) strcat(buf, ".0");
  fputs(buf, fp);
}

void iris_blender_put_vec3(FILE *fp, const float *v) {
  fputc('(', fp);
  for (int i = 0; i < 3; i++) {
    if (i) fputs(", ", fp);
    put_float(fp, v[i]);
  }
  fputc(')', fp);
}

/* A Python bytes literal holding the exact bytes of s (NULL -> b""). Names are
 * decoded with errors="replace" by the prelude's text(); paths with os.fsdecode. */
void iris_blender_put_world(FILE *fp, const iris_scene *scene) {
  if (scene->has_environment && scene->environment_map.path) {
    char map[4096];
    char *abs = realpath(scene->environment_map.path, NULL);
    snprintf(map, sizeof map, "%s", abs ? abs : scene->environment_map.path);
    free(abs);
    fputs("WORLD = dict(map=", fp);
    iris_blender_put_bytes(fp, map);
    fputs(", strength=", fp);
    put_float(fp, scene->environment_map.strength);
    fputs(", rotation=", fp);
    put_float(fp, scene->environment_map.rotation);
    fputs(")\n", fp);
  } else if (scene->has_environment) {
    fputs("WORLD = dict(color=", fp);
    iris_blender_put_vec3(fp, scene->environment);
    fputs(")\n", fp);
  } else {
    fputs("WORLD = None\n", fp);
  }
}

void iris_blender_put_bytes(FILE *fp, const char *s) {
  fputs("b\"", fp);
  for (const unsigned char *p = (const unsigned char *)(s ? s : ""); *p; p++) {
    if (*p == '"' || *p == '\\')
      fprintf(fp, "\\%c", *p);
    else if (*p < 0x20 || *p >= 0x7f)
      fprintf(fp, "\\x%02x", *p);
    else
      fputc(*p, fp);
  }
  fputc('"', fp);
}

static void put_matrix(FILE *fp, const iris_mat4 *m) {
  fputc('(', fp);
  for (int r = 0; r < 4; r++) {
    fputs(r ? ", (" : "(", fp);
    for (int c = 0; c < 4; c++) {
      if (c) fputs(", ", fp);
      put_float(fp, m->m[r][c]);
    }
    fputc(')', fp);
  }
  fputc(')', fp);
}

/* ---- mesh blob layout ------------------------------------------------------ */

typedef struct mesh_layout {
  int64_t pos, nrm, uv, col, idx; /* byte offsets, -1 when absent */
  int64_t uv1, alpha;
} mesh_layout;

static uint64_t align16(uint64_t v) { return (v + 15u) & ~(uint64_t)15u; }

static uint64_t layout_meshes(const iris_scene *scene, mesh_layout *lay) {
  uint64_t off = 0;
  for (size_t i = 0; i < scene->mesh_count; i++) {
    const iris_mesh *m = &scene->meshes[i];
    uint64_t nv = m->vertex_count, nt = m->triangle_count;
    lay[i].pos = (int64_t)off;
    off = align16(off + 12u * nv);
    lay[i].nrm = m->normals ? (int64_t)off : -1;
    if (m->normals) off = align16(off + 12u * nv);
    lay[i].uv = m->uvs ? (int64_t)off : -1;
    if (m->uvs) off = align16(off + 8u * nv);
    lay[i].col = m->colors ? (int64_t)off : -1;
    if (m->colors) off = align16(off + 12u * nv);
    lay[i].uv1 = m->uvs1 ? (int64_t)off : -1;
    if (m->uvs1) off = align16(off + 8u * nv);
    lay[i].alpha = m->alphas ? (int64_t)off : -1;
    if (m->alphas) off = align16(off + 4u * nv);
    lay[i].idx = (int64_t)off;
    off = align16(off + 12u * nt);
  }
  return off;
}

/* Byte sink for the blob: raw into the sidecar, or base64 into the script. */
typedef struct blob_sink {
  FILE *fp;
  bool base64;
  uint64_t written;
  unsigned char carry[3];
  int carry_count;
} blob_sink;

static const char B64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

static void b64_group(FILE *fp, const unsigned char *in, int n) {
  char out[4];
  uint32_t v = (uint32_t)in[0] << 16 | (uint32_t)(n > 1 ? in[1] : 0) << 8 | (uint32_t)(n > 2 ? in[2] : 0);
  out[0] = B64[(v >> 18) & 63];
  out[1] = B64[(v >> 12) & 63];
  out[2] = n > 1 ? B64[(v >> 6) & 63] : '=';
  out[3] = n > 2 ? B64[v & 63] : '=';
  fwrite(out, 1, 4, fp);
}

static void sink_write(blob_sink *s, const void *data, size_t size) {
  const unsigned char *p = data;
  s->written += size;
  if (!s->base64) {
    fwrite(p, 1, size, s->fp);
    return;
  }
  while (size > 0 && s->carry_count > 0 && s->carry_count < 3) {
    s->carry[s->carry_count++] = *p++;
    size--;
    if (s->carry_count == 3) {
      b64_group(s->fp, s->carry, 3);
      s->carry_count = 0;
    }
  }
  for (; size >= 3; size -= 3, p += 3) b64_group(s->fp, p, 3);
  for (; size > 0; size--) s->carry[s->carry_count++] = *p++;
}

static void sink_finish(blob_sink *s) {
  if (s->base64 && s->carry_count > 0) b64_group(s->fp, s->carry, s->carry_count);
  s->carry_count = 0;
}

static void sink_pad(blob_sink *s, uint64_t to) {
  static const unsigned char zeros[16] = {0};
  while (s->written < to) {
    uint64_t n = to - s->written;
    sink_write(s, zeros, n > 16 ? 16 : (size_t)n);
  }
}

static bool host_is_little_endian(void) {
  const uint32_t one = 1;
  unsigned char b;
  memcpy(&b, &one, 1);
  return b == 1;
}

/* 32-bit words written little-endian whatever the host. */
static void sink_words(blob_sink *s, const void *words, size_t count) {
  if (host_is_little_endian()) {
    sink_write(s, words, count * 4);
    return;
  }
  const unsigned char *p = words;
  for (size_t i = 0; i < count; i++, p += 4) {
    unsigned char w[4] = {p[3], p[2], p[1], p[0]};
    sink_write(s, w, 4);
  }
}

static void write_blob(blob_sink *s, const iris_scene *scene, const mesh_layout *lay) {
  for (size_t i = 0; i < scene->mesh_count; i++) {
    const iris_mesh *m = &scene->meshes[i];
    size_t nv = m->vertex_count, nt = m->triangle_count;
    sink_pad(s, (uint64_t)lay[i].pos);
    sink_words(s, m->positions, 3 * nv);
    if (m->normals) {
      sink_pad(s, (uint64_t)lay[i].nrm);
      sink_words(s, m->normals, 3 * nv);
    }
    if (m->uvs) {
      sink_pad(s, (uint64_t)lay[i].uv);
      sink_words(s, m->uvs, 2 * nv);
    }
    if (m->colors) {
      sink_pad(s, (uint64_t)lay[i].col);
      sink_words(s, m->colors, 3 * nv);
    }
    if (m->uvs1) {
      sink_pad(s, (uint64_t)lay[i].uv1);
      sink_words(s, m->uvs1, 2 * nv);
    }
    if (m->alphas) {
      sink_pad(s, (uint64_t)lay[i].alpha);
      sink_words(s, m->alphas, nv);
    }
    sink_pad(s, (uint64_t)lay[i].idx);
    sink_words(s, m->indices, 3 * nt);
  }
  sink_pad(s, align16(s->written));
  sink_finish(s);
}

/* ---- materials ------------------------------------------------------------- */

/* A Blender material is one iris material with or without vertex colours
 * multiplied in (vertex colours are a mesh attribute in iris). */
typedef struct material_variant {
  int32_t material; /* -1 = iris's default material */
  bool vertex_colors;
  bool vertex_alpha; /* the mesh has alphas (read by MASK/BLEND materials) */
} material_variant;

static const char *wrap_name(iris_wrap w) {
  switch (w) {
    case IRIS_WRAP_CLAMP: return "CLAMP";
    case IRIS_WRAP_MIRROR: return "MIRROR";
    default: return "REPEAT";
  }
}

static const char *material_type_name(iris_material_type t) {
  switch (t) {
    case IRIS_MATERIAL_GLOSSY: return "glossy";
    case IRIS_MATERIAL_GLASS: return "glass";
    case IRIS_MATERIAL_GLTF: return "gltf";
    default: return "diffuse";
  }
}

/* Principled BSDF (v1) "Specular" gives a dielectric F0 of 0.08 * Specular;
 * glTF's is ((ior-1)/(ior+1))^2 * specular * specularColor (KHR_materials_specular,
 * colour approximated by its maximum). */
static float principled_specular(const iris_material *m) {
  float f0 = iris_sqr((m->ior - 1.0f) / (m->ior + 1.0f));
  float col = fmaxf(m->specular_color[0], fmaxf(m->specular_color[1], m->specular_color[2]));
  return f0 / 0.08f * m->specular * col;
}

static void put_material(FILE *fp, const iris_scene *scene, material_variant v, bool principled) {
  iris_material def = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  const iris_material *m = v.material >= 0 ? &scene->materials[v.material] : &def;
  fputs("    dict(name=", fp);
  iris_blender_put_bytes(fp, v.material >= 0 ? (m->name ? m->name : "material") : "iris-default");
  fprintf(fp, ", type=\"%s\", color=", material_type_name(m->type));
  iris_blender_put_vec3(fp, m->color);
  fprintf(fp, ", color_tex=%d, roughness=", (int)m->color_texture);
  put_float(fp, m->roughness);
  fputs(", ior=", fp);
  put_float(fp, m->ior);
  fputs(", metallic=", fp);
  put_float(fp, m->metallic);
  fprintf(fp, ", mr_tex=%d, principled_specular=", (int)m->metallic_roughness_texture);
  put_float(fp, principled_specular(m));
  fputs(", transmission=", fp);
  put_float(fp, m->transmission);
  /* glTF dielectric F0 per channel, as renderer/bsdf.c: min(((ior-1)/(ior+1))^2 s, 1). */
  float f0 = iris_sqr((m->ior - 1.0f) / (m->ior + 1.0f)), f0c[3];
  for (int k = 0; k < 3; k++) f0c[k] = fminf(f0 * m->specular_color[k], 1.0f);
  fputs(", specular=", fp);
  put_float(fp, m->specular);
  fputs(", f0=", fp);
  iris_blender_put_vec3(fp, f0c);
  fputs(", f0_ior=", fp);
  put_float(fp, f0);
  fputs(", specular_color=", fp);
  iris_blender_put_vec3(fp, m->specular_color);
  fprintf(fp, ", trans_tex=%d, spec_tex=%d, spec_color_tex=%d", (int)m->transmission_texture,
          (int)m->specular_texture, (int)m->specular_color_texture);
  fprintf(fp, ", principled=%s", principled ? "True" : "False");
  fputs(", emission=", fp);
  iris_blender_put_vec3(fp, m->emission);
  fprintf(fp, ", emission_tex=%d, emission_two_sided=%s, unlit=%s, vertex_colors=%s",
          (int)m->emission_texture, m->emission_two_sided ? "True" : "False", m->unlit ? "True" : "False",
          v.vertex_colors ? "True" : "False");
  static const char *const ALPHA[] = {"opaque", "mask", "blend"};
  fprintf(fp, ", normal_tex=%d, normal_scale=", (int)m->normal_texture);
  put_float(fp, m->normal_scale);
  fprintf(fp, ", alpha_mode=\"%s\", vertex_alpha=%s, alpha=", ALPHA[m->alpha_mode <= IRIS_ALPHA_BLEND ? m->alpha_mode : 0],
          v.vertex_alpha ? "True" : "False");
  put_float(fp, m->alpha);
  fputs(", alpha_cutoff=", fp);
  put_float(fp, m->alpha_cutoff);
  fputs(", clearcoat=", fp);
  put_float(fp, m->clearcoat);
  fputs(", clearcoat_roughness=", fp);
  put_float(fp, m->clearcoat_roughness);
  fprintf(fp, ", cc_tex=%d, ccr_tex=%d, ccn_tex=%d, ccn_scale=", (int)m->clearcoat_texture,
          (int)m->clearcoat_roughness_texture, (int)m->clearcoat_normal_texture);
  put_float(fp, m->clearcoat_normal_scale);
  fputs(", sheen=", fp);
  iris_blender_put_vec3(fp, m->sheen_color);
  fputs(", aniso=", fp);
  put_float(fp, m->type == IRIS_MATERIAL_GLTF ? m->anisotropy : 0.0f);
  fputs(", aniso_rot=", fp);
  put_float(fp, m->anisotropy_rotation);
  fprintf(fp, ", aniso_tex=%d", (int)m->anisotropy_texture);
  fputs(", attenuation=", fp);
  if (m->attenuation_distance > 0.0f) {
    fputs("(", fp);
    for (int k = 0; k < 3; k++) put_float(fp, m->attenuation_color[k]), fputs(", ", fp);
    put_float(fp, m->attenuation_distance);
    fputs(")", fp);
  } else {
    fputs("None", fp);
  }
  fputs("),\n", fp);
}

/* ---- textures -------------------------------------------------------------- */

static void put_texture(FILE *fp, const iris_scene *scene, size_t index, const char *script_path) {
  const iris_texture *t = &scene->textures[index];
  char path[2048];
  iris_export_texture_file(scene, index, script_path, false, path, sizeof path);
  fputs("    dict(path=", fp);
  iris_blender_put_bytes(fp, path);
  fprintf(fp, ", wrap_s=\"%s\", wrap_t=\"%s\", nearest=%s, uv_map=\"%s\", xf=", wrap_name(t->wrap_s),
          wrap_name(t->wrap_t), t->nearest ? "True" : "False", t->uv_set ? "UV1" : "UVMap");
  if (t->has_transform) {
    const float v[5] = {t->offset[0], t->offset[1], t->rotation, t->scale[0], t->scale[1]};
    fputc('(', fp);
    for (int k = 0; k < 5; k++) {
      if (k) fputs(", ", fp);
      put_float(fp, v[k]);
    }
    fputc(')', fp);
  } else {
    fputs("None", fp);
  }
  fputs("),\n", fp);
}

/* ---- lights and camera ----------------------------------------------------- */

static void put_light(FILE *fp, const iris_light *l, size_t index) {
  static const char *const TYPES[] = {"POINT", "SPOT", "SUN"};
  char name[32];
  snprintf(name, sizeof name, "light.%zu", index);
  /* Cycles 3.4 (measured, docs/export.md): a point or spot light of power P W
   * has radiant intensity P/(4 pi) W/sr; a sun of strength S gives irradiance
   * S W/m^2 on a surface facing it. */
  float strength = l->type == IRIS_LIGHT_DIRECTIONAL ? l->intensity : 4.0f * IRIS_PI * l->intensity;
  float outer = iris_clampf(l->outer_cone, 1e-4f, 0.5f * IRIS_PI);
  float inner = iris_clampf(l->inner_cone, 0.0f, outer);
  if (l->range > 0.0f)
    iris_warnf("light '%s': range %g ignored (Cycles lights have no range)", l->name ? l->name : name,
               (double)l->range);
  fputs("    dict(name=", fp);
  iris_blender_put_bytes(fp, l->name ? l->name : name);
  fprintf(fp, ", type=\"%s\", color=", TYPES[l->type <= IRIS_LIGHT_DIRECTIONAL ? l->type : 0]);
  iris_blender_put_vec3(fp, l->color);
  fputs(", strength=", fp);
  put_float(fp, strength);
  fputs(", position=", fp);
  iris_blender_put_vec3(fp, l->position);
  fputs(", direction=", fp);
  iris_blender_put_vec3(fp, l->direction);
  fputs(", cos_inner=", fp);
  put_float(fp, cosf(inner));
  fputs(", cos_outer=", fp);
  put_float(fp, cosf(outer));
  fputs("),\n", fp);
}

void iris_blender_put_camera(FILE *fp, const iris_scene *scene, const iris_export_view *view) {
  /* Cycles starts camera rays at clip_start: keep it far below any feature
   * size. clip_end must reach past everything. */
  iris_vec3 lo, hi, eye = iris_v3(view->to_world.m[0][3], view->to_world.m[1][3], view->to_world.m[2][3]);
  float far = 1.0f, diag = 1.0f;
  if (iris_scene_bounds(scene, &lo, &hi)) {
    diag = fmaxf(iris_length(iris_sub(hi, lo)), 1e-6f);
    iris_vec3 c = iris_scale(iris_add(lo, hi), 0.5f);
    far = iris_length(iris_sub(c, eye)) + diag;
  }
  fputs("CAMERA = dict(name=", fp);
  iris_blender_put_bytes(fp, view->camera >= 0 && scene->cameras[view->camera].name ? scene->cameras[view->camera].name
                                                                       : "camera");
  fputs(", yfov=", fp);
  put_float(fp, view->yfov);
  fputs(", clip_start=", fp);
  put_float(fp, fmaxf(1e-6f, 1e-7f * diag));
  fputs(", clip_end=", fp);
  put_float(fp, 2.0f * far + 1.0f);
  fputs(",\n              matrix=", fp);
  put_matrix(fp, &view->to_world);
  fputs(")\n", fp);
}

/* ---- the script ------------------------------------------------------------ */

void iris_blender_sidecar_path(const char *script_path, char *out, size_t size) {
  char dir[1024], stem[256], name[300];
  iris_path_dir(script_path, dir, sizeof dir);
  iris_path_stem(script_path, stem, sizeof stem);
  snprintf(name, sizeof name, "%s.meshes.bin", stem);
  iris_path_join(dir, name, out, size);
}

static bool mesh_has_degenerate(const iris_mesh *m) {
  for (size_t t = 0; t < m->triangle_count; t++) {
    const uint32_t *i = m->indices + 3 * t;
    if (i[0] == i[1] || i[1] == i[2] || i[0] == i[2]) return true;
  }
  return false;
}

static iris_status write_script(FILE *fp, const iris_scene *scene, const char *script_path,
                                const iris_export_params *params, const iris_export_view *view,
                                const mesh_layout *lay, uint64_t blob_size, int32_t *mesh_variant,
                                const material_variant *variants, size_t variant_count) {
  char stem[256], sidecar[1300];
  iris_path_stem(script_path, stem, sizeof stem);
  iris_blender_sidecar_path(script_path, sidecar, sizeof sidecar);
  char sidecar_name[300];
  snprintf(sidecar_name, sizeof sidecar_name, "%s.meshes.bin", stem);

  fprintf(fp,
          "# Blender 3.4 scene written by iris %s from ",
          IRIS_VERSION_STRING);
  iris_blender_put_bytes(fp, scene->source_path ? scene->source_path : "(memory)");
  if (scene->variants.count && scene->variants.applied >= 0) { /* its materials are the scene's */
    fputs("\n# with the glTF material variant ", fp);
    iris_blender_put_bytes(fp, scene->variants.names[scene->variants.applied]);
    fputs(" (KHR_materials_variants) applied", fp);
  }
  fputs("\n# Builds the scene from an empty file and renders it with Cycles using the\n"
        "# fair-comparison settings of iris's docs/export.md. Usage:\n"
        "#   blender -b --factory-startup --python-exit-code 1 -P THIS.py -- --output OUT.exr\n"
        "#           [--spp N] [--threads T] [--seed S] [--width W --height H] [--max-bounces B]\n"
        "#           [--adaptive-threshold T [--adaptive-min-samples N]] [--time-limit SECONDS]\n",
        fp);
  iris_blender_put_prelude(fp);

  fputs("\n\n# ---- this scene ----------------------------------------------------------\n\n", fp);
  fprintf(fp, "SETTINGS = dict(width=%d, height=%d, spp=%d, max_depth=%d, seed=%llu)\n", view->width,
          view->height, view->spp, view->max_depth, (unsigned long long)(view->seed & 0x7fffffffu));
  iris_blender_put_world(fp, scene);

  fputs("TEXTURES = [\n", fp);
  for (size_t i = 0; i < scene->texture_count; i++) put_texture(fp, scene, i, script_path);
  fputs("]\nMATERIALS = [\n", fp);
  for (size_t i = 0; i < variant_count; i++) put_material(fp, scene, variants[i], params->gltf_principled);
  fputs("]\nMESHES = [\n", fp);
  for (size_t i = 0; i < scene->mesh_count; i++) {
    const iris_mesh *m = &scene->meshes[i];
    char name[32];
    snprintf(name, sizeof name, "mesh.%zu", i);
    fputs("    dict(name=", fp);
    iris_blender_put_bytes(fp, m->name ? m->name : name);
    fprintf(fp,
            ", nv=%u, nt=%u, pos=%lld, nrm=%lld, uv=%lld, col=%lld, idx=%lld, material=%d, "
            "validate=%s, uv1=%lld, alpha=%lld),\n",
            m->vertex_count, m->triangle_count, (long long)lay[i].pos, (long long)lay[i].nrm,
            (long long)lay[i].uv, (long long)lay[i].col, (long long)lay[i].idx, (int)mesh_variant[i],
            mesh_has_degenerate(m) ? "True" : "False", (long long)lay[i].uv1, (long long)lay[i].alpha);
  }
  fputs("]\nINSTANCES = [\n", fp);
  for (size_t i = 0; i < scene->instance_count; i++) {
    fprintf(fp, "    (%u, ", scene->instances[i].mesh);
    put_matrix(fp, &scene->instances[i].transform);
    fputs("),\n", fp);
  }
  fputs("]\nLIGHTS = [\n", fp);
  for (size_t i = 0; i < scene->light_count; i++) put_light(fp, &scene->lights[i], i);
  fputs("]\n", fp);
  iris_blender_put_camera(fp, scene, view);

  fprintf(fp, "BLOB_SIZE = %llu\n", (unsigned long long)blob_size);
  if (params->embed_meshes) {
    fputs("SIDECAR = None\nBLOB = b\"", fp);
    blob_sink sink = {fp, true, 0, {0}, 0};
    write_blob(&sink, scene, lay);
    fputs("\"\n", fp);
  } else {
    fputs("SIDECAR = ", fp);
    iris_blender_put_bytes(fp, sidecar_name);
    fputs("\nBLOB = None\n", fp);
  }
  fputs("\nmain()\n", fp);
  return IRIS_OK;
}

iris_status iris_export_blender(const iris_scene *scene, const char *script_path,
                                const iris_export_params *params, iris_error *err) {
  const char *file = scene->source_path ? scene->source_path : script_path;
  iris_status st = iris_scene_validate(scene, file, err);
  if (st != IRIS_OK) return st;
  iris_export_view view;
  st = iris_export_resolve_view(scene, params, file, &view, err);
  if (st != IRIS_OK) return st;

  size_t nm = scene->mesh_count;
  mesh_layout *lay = calloc(nm ? nm : 1, sizeof *lay);
  int32_t *mesh_variant = calloc(nm ? nm : 1, sizeof *mesh_variant);
  material_variant *variants = calloc(nm ? nm : 1, sizeof *variants);
  if (!lay || !mesh_variant || !variants) {
    st = iris_error_set(err, IRIS_ERR_NOMEM, script_path, 0, NULL, "out of memory");
    goto done;
  }
  /* Variants in order of first use, so equal scenes give equal scripts. */
  size_t variant_count = 0;
  for (size_t i = 0; i < nm; i++) {
    material_variant v = {scene->meshes[i].material, scene->meshes[i].colors != NULL,
                          scene->meshes[i].alphas != NULL};
    size_t k = 0;
    while (k < variant_count && !(variants[k].material == v.material && variants[k].vertex_colors == v.vertex_colors &&
                                    variants[k].vertex_alpha == v.vertex_alpha)) k++;
    if (k == variant_count) variants[variant_count++] = v;
    mesh_variant[i] = (int32_t)k;
  }
  uint64_t blob_size = layout_meshes(scene, lay);

  st = iris_export_write_textures(scene, script_path, err);
  if (st != IRIS_OK) goto done;
  if (!params->embed_meshes) {
    char sidecar[1300];
    iris_blender_sidecar_path(script_path, sidecar, sizeof sidecar);
    iris_atomic_file af;
    st = iris_atomic_open(&af, sidecar, err);
    if (st != IRIS_OK) goto done;
    blob_sink sink = {af.fp, false, 0, {0}, 0};
    write_blob(&sink, scene, lay);
    if (ferror(af.fp)) {
      iris_atomic_abort(&af);
      st = iris_error_set(err, IRIS_ERR_IO, sidecar, 0, NULL, "write failed: %s", strerror(errno));
      goto done;
    }
    st = iris_atomic_commit(&af, err);
    if (st != IRIS_OK) goto done;
  }

  iris_atomic_file af;
  st = iris_atomic_open(&af, script_path, err);
  if (st != IRIS_OK) goto done;
  st = write_script(af.fp, scene, script_path, params, &view, lay, blob_size, mesh_variant, variants,
                    variant_count);
  if (st == IRIS_OK && ferror(af.fp))
    st = iris_error_set(err, IRIS_ERR_IO, script_path, 0, NULL, "write failed: %s", strerror(errno));
  if (st != IRIS_OK)
    iris_atomic_abort(&af);
  else
    st = iris_atomic_commit(&af, err);

done:
  free(lay);
  free(mesh_variant);
  free(variants);
  return st;
}
