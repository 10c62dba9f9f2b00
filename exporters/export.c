/* Export parameters resolved against a scene (exporters/export.h). */
#include "exporters/export.h"

#include <math.h>
#include <stdio.h>
#include <limits.h>
#include <string.h>
#include <unistd.h>

#include "core/fileio.h"
#include "core/log.h"
#include "scene/framing.h"

iris_export_params iris_export_params_default(void) {
  iris_export_params p;
  memset(&p, 0, sizeof p);
  p.max_depth = -1;
  p.pov_radiosity = IRIS_POV_RADIOSITY_MEDIUM;
  return p;
}

/* Unit-length columns; false when a column is degenerate or not finite. */
static bool normalize_camera(const iris_mat4 *in, iris_mat4 *out) {
  *out = *in;
  if (!iris_mat4_is_finite(in)) return false;
  for (int c = 0; c < 3; c++) {
    iris_vec3 v = iris_v3(in->m[0][c], in->m[1][c], in->m[2][c]);
    float len = iris_length(v);
    if (!(len > 1e-12f)) return false;
    for (int r = 0; r < 3; r++) out->m[r][c] = in->m[r][c] / len;
  }
  out->m[3][0] = out->m[3][1] = out->m[3][2] = 0.0f;
  out->m[3][3] = 1.0f;
  return true;
}

iris_status iris_export_resolve_view(const iris_scene *scene, const iris_export_params *params,
                                     const char *file, iris_export_view *view, iris_error *err) {
  memset(view, 0, sizeof *view);
  view->camera = -1;
  if (params->camera_name && *params->camera_name) {
    view->camera = iris_scene_find_camera(scene, params->camera_name);
    if (view->camera < 0)
      return iris_error_set(err, IRIS_ERR_USAGE, file, 0, NULL, "no camera named '%s' (%zu cameras)",
                            params->camera_name, scene->camera_count);
  } else if (scene->camera_count > 0) {
    view->camera = 0;
  }

  /* The same choices as renderer/camera.c (iris_pinhole_setup), so that an
   * export frames exactly what `iris render` frames; tests/exporters checks. */
  const iris_camera *cam = view->camera >= 0 ? &scene->cameras[view->camera] : NULL;
  iris_framing_resolve_size(scene, cam, params->width, params->height, &view->width, &view->height);

  if (cam) {
    char element[64];
    snprintf(element, sizeof element, "cameras[%d]", view->camera);
    if (!normalize_camera(&cam->to_world, &view->to_world))
      return iris_error_set(err, IRIS_ERR_INVALID, file, 0, element, "degenerate camera matrix");
    if (!(cam->yfov > 0.0f && cam->yfov < IRIS_PI))
      return iris_error_set(err, IRIS_ERR_INVALID, file, 0, element,
                            "vertical field of view %g is not in (0, pi)", (double)cam->yfov);
    view->yfov = cam->yfov;
  } else {
    /* No camera: the automatic one, looking along -Z with +Y up. */
    view->yfov = IRIS_EXPORT_FRAMING_YFOV;
    iris_vec3 o = iris_framing_auto_origin(scene, (float)view->width / (float)view->height);
    view->to_world = iris_mat4_identity();
    view->to_world.m[0][3] = o.x;
    view->to_world.m[1][3] = o.y;
    view->to_world.m[2][3] = o.z;
  }

  view->spp = params->spp > 0 ? params->spp
                              : (scene->render.spp > 0 ? scene->render.spp : IRIS_EXPORT_DEFAULT_SPP);
  view->max_depth = params->max_depth >= 0
                        ? params->max_depth
                        : (scene->render.max_depth >= 0 ? scene->render.max_depth : IRIS_EXPORT_DEFAULT_DEPTH);
  view->seed = params->has_seed ? params->seed : (scene->render.has_seed ? scene->render.seed : 0);
  return IRIS_OK;
}

float iris_export_triangle_area(const iris_mesh *m, uint32_t t, const iris_mat4 *x) {
  const uint32_t *ix = m->indices + 3 * (size_t)t;
  iris_vec3 a = iris_mat4_point(x, iris_v3_load(m->positions + 3 * (size_t)ix[0]));
  iris_vec3 b = iris_mat4_point(x, iris_v3_load(m->positions + 3 * (size_t)ix[1]));
  iris_vec3 c = iris_mat4_point(x, iris_v3_load(m->positions + 3 * (size_t)ix[2]));
  return 0.5f * iris_length(iris_cross(iris_sub(b, a), iris_sub(c, a)));
}

bool iris_export_material_emits(const iris_scene *scene, int32_t material) {
  if (material < 0 || (size_t)material >= scene->material_count) return false;
  const float *e = scene->materials[material].emission;
  return e[0] > 0.0f || e[1] > 0.0f || e[2] > 0.0f;
}

static const char *texture_ext(const iris_texture *t) {
  return strcmp(t->mime, "image/jpeg") == 0 ? "jpg" : "png";
}

/* "<dir>/<stem>.textures" for an exported file. */
static void textures_dir(const char *out_path, char *out, size_t size) {
  char dir[1024], stem[256], name[300];
  iris_path_dir(out_path, dir, sizeof dir);
  iris_path_stem(out_path, stem, sizeof stem);
  snprintf(name, sizeof name, "%s.textures", stem);
  iris_path_join(dir, name, out, size);
}

/* Absolute form of a path (relative ones are taken from the working folder). */
static void absolute_path(const char *path, char *out, size_t size) {
  char cwd[PATH_MAX];
  if (path[0] != '/' && getcwd(cwd, sizeof cwd))
    iris_path_join(cwd, path, out, size);
  else
    snprintf(out, size, "%s", path);
}

iris_status iris_export_write_textures(const iris_scene *scene, const char *out_path, iris_error *err) {
  char tdir[1400], path[1600], name[32];
  textures_dir(out_path, tdir, sizeof tdir);
  bool made = false;
  for (size_t i = 0; i < scene->texture_count; i++) {
    const iris_texture *t = &scene->textures[i];
    if (t->path) continue;
    if (!made) {
      iris_status st = iris_mkdir_p(tdir, err);
      if (st != IRIS_OK) return st;
      made = true;
    }
    snprintf(name, sizeof name, "%zu.%s", i, texture_ext(t));
    iris_path_join(tdir, name, path, sizeof path);
    iris_status st = iris_file_write_atomic(path, t->data, t->data_size, err);
    if (st != IRIS_OK) return st;
  }
  return IRIS_OK;
}

bool iris_export_texture_file(const iris_scene *scene, size_t i, const char *out_path, bool absolute,
                              char *buf, size_t size) {
  const iris_texture *t = &scene->textures[i];
  if (t->path) {
    absolute_path(t->path, buf, size);
    if (!iris_path_exists(buf)) {
      iris_warnf("texture '%s' not found (the export refers to it anyway)", buf);
      return false;
    }
    return true;
  }
  char stem[256], rel[400], tdir[1400];
  if (absolute) {
    textures_dir(out_path, tdir, sizeof tdir);
    snprintf(rel, sizeof rel, "%zu.%s", i, texture_ext(t));
    char joined[1800];
    iris_path_join(tdir, rel, joined, sizeof joined);
    absolute_path(joined, buf, size);
  } else {
    iris_path_stem(out_path, stem, sizeof stem);
    snprintf(buf, size, "%s.textures/%zu.%s", stem, i, texture_ext(t));
  }
  return true;
}
