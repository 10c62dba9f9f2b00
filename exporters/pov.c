/* POV-Ray 3.7 exporter (exporters/pov.h, docs/export.md).
 * Geometry stays in iris's (right-handed) world coordinates: POV-Ray's
 * "left-handedness" is only the convention of its default camera vectors, so
 * the camera is written with explicit right/up/direction vectors whose
 * orientation (right x up = -direction) gives exactly iris's image; `angle`
 * then fixes the direction length from the horizontal field of view.
 * POV-Ray lighting is not physically based; the conversions below make a
 * Lambert surface under a point or parallel light come out radiometrically
 * right (no GI, no soft emitters), everything else is an approximation. */
#include "exporters/pov.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "core/log.h"

/* ---- small writers --------------------------------------------------------- */

static void put_float(FILE *fp, float v) {
  if (!isfinite(v)) v = 0.0f;
  fprintf(fp, "%.9g", (double)v);
}

static void put_vec3(FILE *fp, const float *v) {
  fputc('<', fp);
  put_float(fp, v[0]);
  fputc(',', fp);
  put_float(fp, v[1]);
  fputc(',', fp);
  put_float(fp, v[2]);
  fputc('>', fp);
}

static void put_v3(FILE *fp, iris_vec3 v) {
  float a[3] = {v.x, v.y, v.z};
  put_vec3(fp, a);
}

static void put_rgb(FILE *fp, const float *c, float scale) {
  float a[3] = {c[0] * scale, c[1] * scale, c[2] * scale};
  fputs("rgb ", fp);
  put_vec3(fp, a);
}

/* POV string literal (UTF-8, as declared in global_settings). */
static void put_string(FILE *fp, const char *s) {
  fputc('"', fp);
  for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
    if (*p == '"' || *p == '\\')
      fprintf(fp, "\\%c", *p);
    else if (*p >= 0x20)
      fputc(*p, fp);
  }
  fputc('"', fp);
}

/* A name inside a // comment: printable ASCII only. */
static void put_comment_name(FILE *fp, const char *s) {
  for (const unsigned char *p = (const unsigned char *)(s ? s : ""); *p; p++)
    fputc(*p >= 0x20 && *p < 0x7f ? *p : '?', fp);
}

/* POV-Ray's `matrix` takes the 12 numbers of a row-vector transform
 * (p' = p * M): its rows are the columns of iris's column-vector matrix. */
static void put_matrix(FILE *fp, const iris_mat4 *m) {
  fputs("matrix <", fp);
  for (int c = 0; c < 4; c++)
    for (int r = 0; r < 3; r++) {
      if (c || r) fputc(',', fp);
      put_float(fp, m->m[r][c]);
    }
  fputc('>', fp);
}

/* ---- materials ------------------------------------------------------------- */

static bool is_transmissive(const iris_material *m) {
  return m->type == IRIS_MATERIAL_GLASS || (m->type == IRIS_MATERIAL_GLTF && m->transmission > 0.0f);
}

static bool emits(const iris_material *m) {
  return m->emission[0] > 0.0f || m->emission[1] > 0.0f || m->emission[2] > 0.0f;
}

/* The finish of a material (without emission). POV-Ray's `reflection` is a
 * mirror: rough glossy surfaces get a Phong-like highlight whose size follows
 * the GGX alpha instead of blurred reflections. */
static void put_finish(FILE *fp, const iris_material *m) {
  float alpha = iris_clampf(m->roughness * m->roughness, 0.0005f, 1.0f);
  switch (m->type) {
    case IRIS_MATERIAL_DIFFUSE:
      fputs("finish { ambient 0 emission 0 diffuse 1 }", fp);
      break;
    case IRIS_MATERIAL_GLOSSY:
      fputs("finish { ambient 0 emission 0 diffuse 0 reflection { ", fp);
      put_rgb(fp, m->color, 1.0f);
      fputs(" } specular 1 roughness ", fp);
      put_float(fp, alpha);
      fputs(" }", fp);
      break;
    case IRIS_MATERIAL_GLASS:
      fputs("finish { ambient 0 emission 0 diffuse 0 reflection { 0, 1 fresnel on } conserve_energy "
            "specular 1 roughness ",
            fp);
      put_float(fp, alpha);
      fputs(" }", fp);
      break;
    case IRIS_MATERIAL_GLTF: {
      float f0 = iris_sqr((m->ior - 1.0f) / (m->ior + 1.0f)) * m->specular;
      float refl[3];
      for (int i = 0; i < 3; i++)
        refl[i] = (1.0f - m->metallic) * f0 * m->specular_color[i] + m->metallic * m->color[i];
      fputs("finish { ambient 0 emission 0 diffuse ", fp);
      put_float(fp, (1.0f - m->metallic) * (1.0f - m->transmission));
      fputs(" reflection { ", fp);
      put_rgb(fp, refl, 1.0f);
      fputs(" } specular 1 roughness ", fp);
      put_float(fp, alpha);
      fputs(m->transmission > 0.0f ? " conserve_energy }" : " }", fp);
      break;
    }
  }
}

/* KHR_texture_transform as a pigment transform. In POV-Ray's uv space (u, w),
 * w = 1 - v, the image is read at A (u, w) with
 *   A = [[a, -b, b + c], [-d, e, 1 - e - f]]
 * for iris's u' = a u + b v + c, v' = d u + e v + f; a transformed pigment is
 * evaluated at the inverse transform of the point, so the pigment gets A^-1. */
static void put_uv_transform(FILE *fp, const iris_texture *t) {
  double c = cos((double)t->rotation), s = sin((double)t->rotation);
  double a = c * t->scale[0], b = s * t->scale[1], cc = t->offset[0];
  double d = -s * t->scale[0], e = c * t->scale[1], f = t->offset[1];
  double m00 = a, m01 = -b, m02 = b + cc, m10 = -d, m11 = e, m12 = 1.0 - e - f;
  double det = m00 * m11 - m01 * m10;
  if (!(fabs(det) > 1e-30)) return;
  double i00 = m11 / det, i01 = -m01 / det, i10 = -m10 / det, i11 = m00 / det;
  double i02 = -(i00 * m02 + i01 * m12), i12 = -(i10 * m02 + i11 * m12);
  /* POV-Ray: p' = p M with row vectors: x' = x M00 + y M10 + M30 */
  fprintf(fp, " matrix <%.9g, %.9g, 0, %.9g, %.9g, 0, 0, 0, 1, %.9g, %.9g, 0>", i00, i10, i01, i11, i02, i12);
}

/* Pigment of a material: its colour (or its colour texture, uv-mapped) times
 * an optional vertex colour; glass and transmissive glTF filter their colour. */
static void put_pigment(FILE *fp, const iris_scene *scene, const iris_material *m, const char *pov_path,
                        const float *vertex_color) {
  float c[3] = {m->color[0], m->color[1], m->color[2]};
  if (vertex_color)
    for (int i = 0; i < 3; i++) c[i] *= vertex_color[i];
  float filter = m->type == IRIS_MATERIAL_GLASS ? 1.0f
                 : m->type == IRIS_MATERIAL_GLTF ? m->transmission
                                                 : 0.0f;
  if (m->color_texture >= 0 && !vertex_color) {
    const iris_texture *t = &scene->textures[m->color_texture];
    char path[2048];
    iris_export_texture_file(scene, (size_t)m->color_texture, pov_path, true, path, sizeof path);
    const char *kind = strcmp(t->mime, "image/jpeg") == 0 ? "jpeg" : "png";
    fprintf(fp, "pigment { uv_mapping image_map { %s ", kind);
    put_string(fp, path);
    fprintf(fp, " gamma srgb%s%s }", t->nearest ? "" : " interpolate 2",
            t->wrap_s == IRIS_WRAP_CLAMP && t->wrap_t == IRIS_WRAP_CLAMP ? " once" : "");
    if (t->has_transform) put_uv_transform(fp, t);
    fputs(" }", fp);
    return;
  }
  if (filter > 0.0f) {
    fputs("pigment { rgbf <", fp);
    for (int i = 0; i < 3; i++) {
      put_float(fp, c[i]);
      fputc(',', fp);
    }
    put_float(fp, filter);
    fputs("> }", fp);
  } else {
    fputs("pigment { ", fp);
    put_rgb(fp, c, 1.0f);
    fputs(" }", fp);
  }
}

/* The texture of a material; emitters show exactly their radiance (POV-Ray
 * multiplies `emission` by the pigment) and no BSDF. */
static void put_texture(FILE *fp, const iris_scene *scene, int32_t index, const char *pov_path,
                        bool coverage, const float *vertex_color) {
  if (coverage) {
    fputs("texture { pigment { rgb 1 } finish { ambient 0 diffuse 0 emission 1 } }", fp);
    return;
  }
  iris_material def = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  const iris_material *m = index >= 0 ? &scene->materials[index] : &def;
  if (emits(m)) {
    fputs("texture { pigment { ", fp);
    put_rgb(fp, m->emission, 1.0f);
    fputs(" } finish { ambient 0 diffuse 0 emission 1 } }", fp);
    return;
  }
  fputs("texture { ", fp);
  put_pigment(fp, scene, m, pov_path, vertex_color);
  fputc(' ', fp);
  if (m->color_texture >= 0 && !vertex_color && m->type == IRIS_MATERIAL_DIFFUSE) {
    /* POV-Ray cannot multiply an image by a colour: scale the diffuse weight. */
    fprintf(fp, "finish { ambient 0 emission 0 diffuse ");
    put_float(fp, iris_avg3(iris_v3_load(m->color)));
    fputs(" }", fp);
  } else {
    put_finish(fp, m);
  }
  fputs(" }", fp);
}

/* ---- meshes ---------------------------------------------------------------- */

static bool degenerate(const uint32_t *i) { return i[0] == i[1] || i[1] == i[2] || i[0] == i[2]; }

/* Triangles POV-Ray gets (it rejects a mesh2 without any). */
static size_t usable_triangles(const iris_mesh *m) {
  size_t nt = 0;
  for (size_t t = 0; t < m->triangle_count; t++) nt += !degenerate(m->indices + 3 * t);
  return nt;
}

static void put_mesh(FILE *fp, const iris_scene *scene, size_t index, const char *pov_path,
                     bool coverage) {
  const iris_mesh *m = &scene->meshes[index];
  size_t nv = m->vertex_count, nt = usable_triangles(m);
  if (nt == 0) {
    fprintf(fp, "// mesh %zu has no non-degenerate triangles: skipped\n", index);
    return;
  }
  fprintf(fp, "// mesh %zu: ", index);
  put_comment_name(fp, m->name);
  fprintf(fp, "\n#declare IrisMesh%zu = mesh2 {\n  vertex_vectors { %zu", index, nv);
  for (size_t v = 0; v < nv; v++) {
    fputs(v % 4 ? ", " : ",\n    ", fp);
    put_vec3(fp, m->positions + 3 * v);
  }
  fputs("\n  }\n", fp);
  if (m->normals) {
    fprintf(fp, "  normal_vectors { %zu", nv);
    for (size_t v = 0; v < nv; v++) {
      fputs(v % 4 ? ", " : ",\n    ", fp);
      put_vec3(fp, m->normals + 3 * v);
    }
    fputs("\n  }\n", fp);
  }
  /* POV-Ray meshes have one uv set: the one the colour texture reads. */
  const float *uvs = m->uvs;
  if (m->uvs1 && m->material >= 0 && scene->materials[m->material].color_texture >= 0 &&
      scene->textures[scene->materials[m->material].color_texture].uv_set == 1)
    uvs = m->uvs1;
  if (uvs) {
    /* iris (glTF) v runs down from the image's top; POV-Ray's image_map has v up. */
    fprintf(fp, "  uv_vectors { %zu", nv);
    for (size_t v = 0; v < nv; v++) {
      fputs(v % 6 ? ", <" : ",\n    <", fp);
      put_float(fp, uvs[2 * v]);
      fputc(',', fp);
      put_float(fp, 1.0f - uvs[2 * v + 1]);
      fputc('>', fp);
    }
    fputs("\n  }\n", fp);
  }
  /* Vertex colours: one texture per vertex, interpolated over each triangle. */
  iris_material def = iris_material_default(IRIS_MATERIAL_DIFFUSE);
  const iris_material *mat = m->material >= 0 ? &scene->materials[m->material] : &def;
  bool per_vertex = m->colors && !coverage && !emits(mat);
  if (per_vertex) {
    fprintf(fp, "  texture_list { %zu", nv);
    for (size_t v = 0; v < nv; v++) {
      fputs(",\n    ", fp);
      put_texture(fp, scene, m->material, pov_path, false, m->colors + 3 * v);
    }
    fputs("\n  }\n", fp);
  }
  fprintf(fp, "  face_indices { %zu", nt);
  size_t k = 0;
  for (size_t t = 0; t < m->triangle_count; t++) {
    const uint32_t *i = m->indices + 3 * t;
    if (degenerate(i)) continue;
    fputs(k++ % 4 ? ", " : ",\n    ", fp);
    fprintf(fp, "<%u,%u,%u>", i[0], i[1], i[2]);
    if (per_vertex) fprintf(fp, ",%u,%u,%u", i[0], i[1], i[2]);
  }
  fputs("\n  }\n", fp);
  if (!coverage && is_transmissive(mat)) fputs("  inside_vector <0,0,1>\n", fp);
  fputs("}\n", fp);
}

/* ---- lights ---------------------------------------------------------------- */

/* POV-Ray's light fading is 2 / (1 + (d / fade_distance)^2); with a tiny
 * fade_distance eps and the colour scaled by 1 / (2 eps^2) it is 1 / (eps^2 + d^2),
 * i.e. the inverse-square law. Its diffuse term is pigment x light x cos with
 * no 1/pi, so the colour also carries 1/pi: a Lambert surface under a point
 * light of intensity I then shows rho / pi * I cos / d^2, as in iris. */
typedef struct fade {
  float eps, scale;
} fade;

static void put_point_light(FILE *fp, iris_vec3 p, const float *intensity, fade f, const char *extra) {
  fputs("light_source { ", fp);
  put_v3(fp, p);
  fputs(", ", fp);
  put_rgb(fp, intensity, IRIS_INV_PI * f.scale);
  fputs(" fade_distance ", fp);
  put_float(fp, f.eps);
  fprintf(fp, " fade_power 2%s }\n", extra ? extra : "");
}

static void put_light(FILE *fp, const iris_light *l, fade f, float far) {
  float c[3] = {l->color[0] * l->intensity, l->color[1] * l->intensity, l->color[2] * l->intensity};
  iris_vec3 p = iris_v3_load(l->position), d = iris_normalize(iris_v3_load(l->direction));
  fputs("// light ", fp);
  put_comment_name(fp, l->name);
  fputc('\n', fp);
  if (l->type == IRIS_LIGHT_DIRECTIONAL) {
    /* Irradiance E on a surface facing it: colour E / pi, no fading. */
    fputs("light_source { ", fp);
    put_v3(fp, iris_scale(d, -far));
    fputs(", ", fp);
    put_rgb(fp, c, IRIS_INV_PI);
    fputs(" parallel point_at <0,0,0> }\n", fp);
    return;
  }
  if (l->type == IRIS_LIGHT_SPOT) {
    char extra[256];
    float outer = iris_clampf(l->outer_cone, 1e-4f, 0.5f * IRIS_PI);
    float inner = iris_clampf(l->inner_cone, 0.0f, outer);
    iris_vec3 at = iris_add(p, d);
    snprintf(extra, sizeof extra,
             " spotlight point_at <%.9g,%.9g,%.9g> radius %.9g falloff %.9g tightness 0", (double)at.x,
             (double)at.y, (double)at.z, (double)(inner * 180.0f / IRIS_PI),
             (double)(outer * 180.0f / IRIS_PI));
    put_point_light(fp, p, c, f, extra);
    return;
  }
  put_point_light(fp, p, c, f, NULL);
}

/* An emissive mesh instance becomes a light at its area-weighted centre: when
 * it is planar, an area spotlight over its bounding rectangle with a cosine
 * falloff per emitting side (below), else an isotropic point light of
 * intensity L * A / 2. The emissive object itself casts no shadow. */
static void put_emitter_light(FILE *fp, const iris_scene *scene, const iris_instance *inst, fade f) {
  const iris_mesh *m = &scene->meshes[inst->mesh];
  const iris_material *mat = &scene->materials[m->material];
  double area = 0;
  iris_vec3 centre = iris_v3(0, 0, 0), nsum = iris_v3(0, 0, 0), edge = iris_v3(0, 0, 0);
  float best = 0;
  for (uint32_t t = 0; t < m->triangle_count; t++) {
    const uint32_t *ix = m->indices + 3 * (size_t)t;
    iris_vec3 v[3];
    for (int k = 0; k < 3; k++) v[k] = iris_mat4_point(&inst->transform, iris_v3_load(m->positions + 3 * (size_t)ix[k]));
    iris_vec3 n2 = iris_cross(iris_sub(v[1], v[0]), iris_sub(v[2], v[0]));
    float a = 0.5f * iris_length(n2);
    if (!(a > 0.0f)) continue;
    area += a;
    nsum = iris_add(nsum, iris_scale(n2, 0.5f));
    centre = iris_add(centre, iris_scale(iris_add(iris_add(v[0], v[1]), v[2]), a / 3.0f));
    if (a > best) {
      best = a;
      edge = iris_sub(v[1], v[0]);
    }
  }
  if (!(area > 0.0)) return;
  centre = iris_scale(centre, (float)(1.0 / area));
  float c[3];
  for (int i = 0; i < 3; i++) c[i] = mat->emission[i] * (float)area * 0.5f;
  fputs("// emitter: mesh ", fp);
  put_comment_name(fp, m->name);
  fputc('\n', fp);
  float planarity = iris_length(nsum) / (float)area;
  if (planarity < 0.999f) {
    put_point_light(fp, centre, c, f, NULL);
    return;
  }
  /* Bounding rectangle in the emitter's plane. */
  iris_vec3 n = iris_normalize(nsum);
  iris_vec3 u = iris_normalize(iris_sub(edge, iris_scale(n, iris_dot(edge, n))));
  iris_vec3 w = iris_cross(n, u);
  float lo_u = INFINITY, hi_u = -INFINITY, lo_w = INFINITY, hi_w = -INFINITY;
  for (uint32_t v = 0; v < m->vertex_count; v++) {
    iris_vec3 p = iris_sub(iris_mat4_point(&inst->transform, iris_v3_load(m->positions + 3 * (size_t)v)), centre);
    float pu = iris_dot(p, u), pw = iris_dot(p, w);
    lo_u = fminf(lo_u, pu), hi_u = fmaxf(hi_u, pu);
    lo_w = fminf(lo_w, pw), hi_w = fmaxf(hi_w, pw);
  }
  iris_vec3 mid = iris_add(centre, iris_add(iris_scale(u, 0.5f * (lo_u + hi_u)), iris_scale(w, 0.5f * (lo_w + hi_w))));
  iris_vec3 au = iris_scale(u, hi_u - lo_u), aw = iris_scale(w, hi_w - lo_w);
  /* A planar Lambertian emitter of radiance L and area A has radiant intensity
   * L A cos(theta) on the side(s) it emits from: a spotlight along the normal
   * with POV-Ray's cos^tightness falloff (tightness 1, radius = falloff = 90
   * degrees: no cone edge), spread over the rectangle as an area light. */
  for (int side = 0; side < (mat->emission_two_sided ? 2 : 1); side++) {
    iris_vec3 at = iris_add(mid, side ? iris_scale(n, -1.0f) : n);
    char extra[640];
    snprintf(extra, sizeof extra,
             " spotlight point_at <%.9g,%.9g,%.9g> radius 90 falloff 90 tightness 1"
             " area_light <%.9g,%.9g,%.9g>, <%.9g,%.9g,%.9g>, 5, 5 adaptive 1 area_illumination on",
             (double)at.x, (double)at.y, (double)at.z, (double)au.x, (double)au.y, (double)au.z,
             (double)aw.x, (double)aw.y, (double)aw.z);
    float cs[3] = {2.0f * c[0], 2.0f * c[1], 2.0f * c[2]}; /* L A on the axis */
    put_point_light(fp, mid, cs, f, extra);
  }
}

/* ---- the scene ------------------------------------------------------------- */

static void put_camera(FILE *fp, const iris_export_view *view) {
  float aspect = (float)view->width / (float)view->height;
  float hfov = 2.0f * atanf(tanf(0.5f * view->yfov) * aspect);
  /* Right-handed camera in iris's world: right = +x, up = +y, looking along -z. */
  fprintf(fp,
          "camera {\n  perspective\n  location <0,0,0>\n  direction <0,0,-1>\n  right <%.9g,0,0>\n"
          "  up <0,1,0>\n  angle %.9g\n  ",
          (double)aspect, (double)(hfov * 180.0f / IRIS_PI));
  put_matrix(fp, &view->to_world);
  fputs("\n}\n", fp);
}

/* POV-Ray 3.7 radiosity: diffuse interreflection gathered by hemisphere
 * sampling and cached (docs/export.md). Its indirect term is the mean radiance
 * over the cosine-weighted hemisphere, i.e. E/pi, times pigment x diffuse: the
 * Lambert radiance, so `brightness 1` is the physical setting and
 * `gray_threshold 0` keeps colour bleeding. recursion_limit is how many
 * diffuse bounces are gathered (capped by --max-depth). */
static void put_radiosity(FILE *fp, iris_pov_radiosity q, int max_depth) {
  static const struct {
    int count, nearest, recursion;
    double error_bound, pretrace_end, minimum_reuse;
  } LEVELS[] = {{0, 0, 0, 0, 0, 0},
                {60, 5, 3, 1.0, 0.04, 0.015},
                {300, 10, 6, 0.5, 0.01, 0.01},
                {1000, 20, 10, 0.25, 0.005, 0.005}};
  int rec = LEVELS[q].recursion < max_depth ? LEVELS[q].recursion : max_depth;
  fprintf(fp,
          "  radiosity { pretrace_start 0.08 pretrace_end %g count %d nearest_count %d error_bound %g\n"
          "              recursion_limit %d low_error_factor 0.5 gray_threshold 0 minimum_reuse %g\n"
          "              brightness 1 adc_bailout 0.005 normal on media off always_sample off }\n",
          LEVELS[q].pretrace_end, LEVELS[q].count, LEVELS[q].nearest, LEVELS[q].error_bound, rec,
          LEVELS[q].minimum_reuse);
}

static iris_status write_pov(FILE *fp, const iris_scene *scene, const char *pov_path,
                             const iris_export_params *params, const iris_export_view *view) {
  bool coverage = params->coverage;
  bool radiosity = !coverage && params->pov_radiosity != IRIS_POV_RADIOSITY_OFF && view->max_depth > 0 &&
                   params->pov_radiosity <= IRIS_POV_RADIOSITY_HIGH;
  iris_vec3 lo = iris_v3(-1, -1, -1), hi = iris_v3(1, 1, 1);
  iris_scene_bounds(scene, &lo, &hi);
  float diag = fmaxf(iris_length(iris_sub(hi, lo)), 1e-6f);
  fade f;
  f.eps = fmaxf(1e-4f * diag, 1e-6f);
  f.scale = 1.0f / (2.0f * f.eps * f.eps);

  fprintf(fp, "// POV-Ray 3.7 scene written by iris %s from ", IRIS_VERSION_STRING);
  put_comment_name(fp, scene->source_path ? scene->source_path : "(memory)");
  fprintf(fp,
          "%s\n// Render: povray +I<this> +O<out>.png +FN +W%d +H%d -D -V\n"
          "// (+WT1 makes a radiosity image reproducible: its cache depends on the thread timing)\n"
          "// Approximations of iris's materials and lights: docs/export.md.\n"
          "#version 3.7;\n"
          "global_settings { assumed_gamma 1.0 charset utf8 ambient_light rgb 0 max_trace_level %d\n",
          coverage ? " (coverage mode: every object white on black)" : "", view->width, view->height,
          view->max_depth + 1 < 1 ? 1 : (view->max_depth + 1 > 256 ? 256 : view->max_depth + 1));
  if (radiosity) put_radiosity(fp, params->pov_radiosity, view->max_depth);
  fputs("}\n", fp);
  if (scene->has_environment && scene->environment_map.path && !coverage) {
    /* An approximation (docs/export.md): the map is seen directly and, with
     * radiosity, lights the scene; its strength is ignored. POV-Ray's
     * spherical map wraps u once around +Y; the x mirror and the half turn
     * were chosen by eye against iris's render of env-objects. */
    char ext[16];
    iris_path_ext(scene->environment_map.path, ext, sizeof ext);
    fprintf(fp, "background { rgb 0 }\nsky_sphere { pigment { image_map { %s ",
            strcmp(ext, "exr") == 0 ? "exr" : "hdr");
    put_string(fp, scene->environment_map.path);
    fprintf(fp, " gamma 1.0 map_type 1 interpolate 2 } scale <-1, 1, 1> rotate y * %g } }\n",
            (double)(180.0f + scene->environment_map.rotation));
  } else if (scene->has_environment && !coverage) {
    fputs("background { ", fp);
    put_rgb(fp, scene->environment, 1.0f);
    fputs(" }\n", fp);
  } else {
    fputs("background { rgb 0 }\n", fp);
  }
  put_camera(fp, view);

  for (size_t i = 0; i < scene->mesh_count; i++) put_mesh(fp, scene, i, pov_path, coverage);

  for (size_t i = 0; i < scene->instance_count; i++) {
    const iris_instance *inst = &scene->instances[i];
    const iris_mesh *m = &scene->meshes[inst->mesh];
    if (usable_triangles(m) == 0) continue;
    iris_material def = iris_material_default(IRIS_MATERIAL_DIFFUSE);
    const iris_material *mat = m->material >= 0 ? &scene->materials[m->material] : &def;
    fprintf(fp, "object { IrisMesh%u ", inst->mesh);
    put_matrix(fp, &inst->transform);
    fputs("\n  ", fp);
    put_texture(fp, scene, m->material, pov_path, coverage, NULL);
    if (!coverage && is_transmissive(mat)) {
      fputs("\n  interior { ior ", fp);
      put_float(fp, mat->ior);
      fputs(" }", fp);
    }
    if (!coverage && emits(mat)) fputs("\n  no_shadow", fp);
    /* An emitter already lights the scene through its light source (below);
     * radiosity rays must not gather its emission a second time. */
    if (radiosity && emits(mat)) fputs(" no_radiosity", fp);
    fputs("\n}\n", fp);
  }

  if (!coverage) {
    float far = 10.0f * diag;
    for (size_t i = 0; i < scene->light_count; i++) put_light(fp, &scene->lights[i], f, far);
    for (size_t i = 0; i < scene->instance_count; i++) {
      const iris_mesh *m = &scene->meshes[scene->instances[i].mesh];
      if (m->material >= 0 && emits(&scene->materials[m->material]))
        put_emitter_light(fp, scene, &scene->instances[i], f);
    }
  }
  return IRIS_OK;
}

iris_status iris_export_pov(const iris_scene *scene, const char *pov_path,
                            const iris_export_params *params, iris_error *err) {
  const char *file = scene->source_path ? scene->source_path : pov_path;
  iris_status st = iris_scene_validate(scene, file, err);
  if (st != IRIS_OK) return st;
  iris_export_view view;
  st = iris_export_resolve_view(scene, params, file, &view, err);
  if (st != IRIS_OK) return st;
  for (size_t i = 0; i < scene->light_count; i++)
    if (scene->lights[i].range > 0.0f)
      iris_warnf("light '%s': range ignored by the POV-Ray export",
                 scene->lights[i].name ? scene->lights[i].name : "(unnamed)");
  { /* POV-Ray's finish has no anisotropic highlight: one warning for all such materials */
    size_t n = 0;
    const char *first = NULL;
    for (size_t i = 0; i < scene->material_count; i++)
      if (scene->materials[i].type == IRIS_MATERIAL_GLTF && scene->materials[i].anisotropy > 0.0f) {
        if (!first) first = scene->materials[i].name ? scene->materials[i].name : "(unnamed)";
        n++;
      }
    if (n)
      iris_warnf("%zu anisotropic material(s) (first '%s'): KHR_materials_anisotropy is exported isotropic "
                 "to POV-Ray", n, first);
  }
  if (!params->coverage) {
    /* POV-Ray's filter and reflection are one value per finish: the glTF
     * transmission and specular textures cannot drive them (docs/export.md). */
    size_t trans_tex = 0, spec_tex = 0;
    for (size_t i = 0; i < scene->material_count; i++) {
      const iris_material *m = &scene->materials[i];
      if (m->type != IRIS_MATERIAL_GLTF) continue;
      trans_tex += m->transmission_texture >= 0 && m->transmission > 0.0f;
      spec_tex += m->specular_texture >= 0 || m->specular_color_texture >= 0;
    }
    if (trans_tex)
      iris_warnf("%s: %zu material(s) with a transmission texture: the POV-Ray export uses the transmission "
                 "factor alone",
                 pov_path, trans_tex);
    if (spec_tex)
      iris_warnf("%s: %zu material(s) with a specular or specular colour texture: the POV-Ray export uses "
                 "the specular factors alone",
                 pov_path, spec_tex);
    st = iris_export_write_textures(scene, pov_path, err);
    if (st != IRIS_OK) return st;
  }
  iris_atomic_file af;
  st = iris_atomic_open(&af, pov_path, err);
  if (st != IRIS_OK) return st;
  st = write_pov(af.fp, scene, pov_path, params, &view);
  if (st == IRIS_OK && ferror(af.fp))
    st = iris_error_set(err, IRIS_ERR_IO, pov_path, 0, NULL, "write failed: %s", strerror(errno));
  if (st != IRIS_OK) {
    iris_atomic_abort(&af);
    return st;
  }
  return iris_atomic_commit(&af, err);
}
