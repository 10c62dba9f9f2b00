/* Pinhole camera set-up and primary rays; see camera.h. */
#include "renderer/camera.h"

#include <stdio.h>
#include <string.h>

iris_status iris_pinhole_setup(const iris_scene *scene, const char *name, int width, int height,
                               iris_pinhole *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  const iris_camera *cam = NULL;
  if (name && *name) {
    int32_t index = iris_scene_find_camera(scene, name);
    if (index >= 0) cam = &scene->cameras[index];
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

  iris_framing_resolve_size(scene, cam, width, height, &out->width, &out->height);
  out->aspect = (float)out->width / (float)out->height;

  if (cam) {
    out->yfov = cam->yfov;
    out->origin = iris_mat4_point(&cam->to_world, iris_v3(0, 0, 0));
    out->right = iris_normalize(iris_mat4_vector(&cam->to_world, iris_v3(1, 0, 0)));
    out->up = iris_normalize(iris_mat4_vector(&cam->to_world, iris_v3(0, 1, 0)));
    out->forward = iris_normalize(iris_mat4_vector(&cam->to_world, iris_v3(0, 0, -1)));
    snprintf(out->name, sizeof out->name, "%s", cam->name ? cam->name : "camera 0");
  } else {
    out->yfov = IRIS_FRAMING_AUTO_YFOV;
    out->origin = iris_framing_auto_origin(scene, out->aspect);
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
