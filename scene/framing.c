/* Camera choice, film size and automatic framing; see framing.h. */
#include "scene/framing.h"

#include <math.h>
#include <string.h>

int32_t iris_scene_find_camera(const iris_scene *scene, const char *name) {
  for (size_t i = 0; i < scene->camera_count; i++)
    if (scene->cameras[i].name && strcmp(scene->cameras[i].name, name) == 0) return (int32_t)i;
  return -1;
}

void iris_framing_resolve_size(const iris_scene *scene, const iris_camera *camera, int width,
                               int height, int *out_width, int *out_height) {
  float aspect = 1.0f;
  if (camera && camera->aspect > 0.0f)
    aspect = camera->aspect;
  else if (scene->render.width > 0 && scene->render.height > 0)
    aspect = (float)scene->render.width / (float)scene->render.height;
  if (width <= 0 && height <= 0 && scene->render.width > 0 && scene->render.height > 0) {
    width = scene->render.width;
    height = scene->render.height;
  }
  if (width <= 0 && height <= 0) height = IRIS_FRAMING_DEFAULT_HEIGHT;
  if (width <= 0) width = (int)lroundf((float)height * aspect);
  if (height <= 0) height = (int)lroundf((float)width / aspect);
  *out_width = width < 1 ? 1 : width;
  *out_height = height < 1 ? 1 : height;
}

iris_vec3 iris_framing_auto_origin(const iris_scene *scene, float aspect) {
  iris_vec3 lo, hi;
  if (!iris_scene_bounds(scene, &lo, &hi)) {
    lo = iris_v3(-1, -1, -1);
    hi = iris_v3(1, 1, 1);
  }
  iris_vec3 c = iris_scale(iris_add(lo, hi), 0.5f);
  float r = 0.5f * iris_length(iris_sub(hi, lo));
  if (!(r > 0.0f)) r = 1.0f;
  float half_y = 0.5f * IRIS_FRAMING_AUTO_YFOV;
  float half_x = atanf(tanf(half_y) * aspect);
  float dist = r / sinf(fminf(half_y, half_x));
  return iris_add(c, iris_v3(0, 0, dist));
}
