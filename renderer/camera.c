/* Pinhole camera set-up and primary rays; see camera.h. */
#include "renderer/camera.h"

#include <stdio.h>
#include <string.h>

static void resolve_resolution(const iris_scene *scene, float aspect, int width, int height,
                               int *w, int *h) {
  if (width <= 0 && height <= 0 && scene->render.width > 0 && scene->render.height > 0) {
    width = scene->render.width;
    height = scene->render.height;
  }
  if (width <= 0 && height <= 0) height = IRIS_CAMERA_DEFAULT_HEIGHT;
  if (width <= 0) width = (int)lroundf((float)height * aspect);
  if (height <= 0) height = (int)lroundf((float)width / aspect);
  *w = width < 1 ? 1 : width;
  *h = height < 1 ? 1 : height;
}

iris_status iris_pinhole_setup(const iris_scene *scene, const char *name, int width, int height,
                               iris_pinhole *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  const iris_camera *cam = NULL;
  if (name && *name) {
    for (size_t i = 0; i < scene->camera_count; i++)
      if (scene->cameras[i].name && strcmp(scene->cameras[i].name, name) == 0) cam = &scene->cameras[i];
    if (!cam) {
      char list[256] = "";
      for (size_t i = 0; i < scene->camera_count && strlen(list) < 200; i++) {
        strncat(list, i ? ", " : "", sizeof list - strlen(list) - 1);
        strncat(list, scene->cameras[i].name ? scene->cameras[i].name : "(unnamed)",
                sizeof list - strlen(list) - 1);
      }
      return iris_error_set(err, IRIS_ERR_USAGE, scene->source_path, 0, NULL,
                            "no camera named '%s' (cameras: %s)", name,
                            scene->camera_count ? list : "none");
    }
  } else if (scene->camera_count > 0) {
    cam = &scene->cameras[0];
  }

  float aspect = 1.0f;
  if (cam && cam->aspect > 0.0f)
    aspect = cam->aspect;
  else if (scene->render.width > 0 && scene->render.height > 0)
    aspect = (float)scene->render.width / (float)scene->render.height;
  resolve_resolution(scene, aspect, width, height, &out->width, &out->height);
  out->aspect = (float)out->width / (float)out->height;

  if (cam) {
    out->yfov = cam->yfov;
    out->origin = iris_mat4_point(&cam->to_world, iris_v3(0, 0, 0));
    out->right = iris_normalize(iris_mat4_vector(&cam->to_world, iris_v3(1, 0, 0)));
    out->up = iris_normalize(iris_mat4_vector(&cam->to_world, iris_v3(0, 1, 0)));
    out->forward = iris_normalize(iris_mat4_vector(&cam->to_world, iris_v3(0, 0, -1)));
    snprintf(out->name, sizeof out->name, "%s", cam->name ? cam->name : "camera 0");
  } else {
    /* Frame the bounding sphere from +z, looking down -z, with a 40 degree fov. */
    iris_vec3 lo, hi;
    if (!iris_scene_bounds(scene, &lo, &hi)) {
      lo = iris_v3(-1, -1, -1);
      hi = iris_v3(1, 1, 1);
    }
    iris_vec3 c = iris_scale(iris_add(lo, hi), 0.5f);
    float r = 0.5f * iris_length(iris_sub(hi, lo));
    if (!(r > 0.0f)) r = 1.0f;
    out->yfov = IRIS_CAMERA_AUTO_YFOV;
    float half_y = 0.5f * out->yfov;
    float half_x = atanf(tanf(half_y) * out->aspect);
    float half = fminf(half_y, half_x);
    float dist = r / sinf(half);
    out->origin = iris_add(c, iris_v3(0, 0, dist));
    out->right = iris_v3(1, 0, 0);
    out->up = iris_v3(0, 1, 0);
    out->forward = iris_v3(0, 0, -1);
    out->automatic = true;
    snprintf(out->name, sizeof out->name, "auto");
  }
  if (!(out->yfov > 0.0f && out->yfov < IRIS_PI) || !iris_isfinite3(out->origin) ||
      !iris_isfinite3(out->forward))
    return iris_error_set(err, IRIS_ERR_INVALID, scene->source_path, 0, "camera",
                          "unusable camera (field of view %g rad)", (double)out->yfov);
  out->tan_half_yfov = tanf(0.5f * out->yfov);
  return IRIS_OK;
}

iris_ray iris_pinhole_ray(const iris_pinhole *cam, float fx, float fy) {
  float x = (2.0f * fx / (float)cam->width - 1.0f) * cam->tan_half_yfov * cam->aspect;
  float y = (1.0f - 2.0f * fy / (float)cam->height) * cam->tan_half_yfov;
  iris_ray r;
  r.o = cam->origin;
  r.d = iris_normalize(iris_add(cam->forward, iris_add(iris_scale(cam->right, x), iris_scale(cam->up, y))));
  r.tmin = 0.0f;
  r.tmax = INFINITY;
  return r;
}
