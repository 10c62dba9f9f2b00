/* Cache marks and cache dumps; renderer/guiding/inspect.h. */
#include "renderer/guiding/inspect.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "core/image.h"

#define DUMP_COLS 4
#define DUMP_ROWS 3
#define DUMP_SCALE 8 /* PNG pixels per texel */

void iris_guiding_marks_destroy(iris_guiding_marks *m) {
  if (!m) return;
  free(m->kind);
  memset(m, 0, sizeof *m);
}

/* Film position of world point p, false when behind the camera or off the film. */
static bool project(const iris_pinhole *cam, iris_vec3 p, int *px, int *py) {
  iris_vec3 d = iris_sub(p, cam->origin);
  float z = iris_dot(d, cam->forward);
  if (!(z > 1e-6f)) return false;
  float x = iris_dot(d, cam->right) / (z * cam->tan_half_yfov * cam->aspect);
  float y = iris_dot(d, cam->up) / (z * cam->tan_half_yfov);
  float fx = (x + 1.0f) * 0.5f * (float)cam->width, fy = (1.0f - y) * 0.5f * (float)cam->height;
  if (!(fx >= 0.0f && fx < (float)cam->width && fy >= 0.0f && fy < (float)cam->height)) return false;
  *px = (int)fx;
  *py = (int)fy;
  return true;
}

iris_status iris_guiding_mark_caches(const iris_guiding *g, const iris_guide_setup *s,
                                     iris_guiding_marks *out, iris_error *err) {
  const iris_pinhole *cam = s->camera;
  iris_guiding_marks_destroy(out);
  out->kind = calloc((size_t)cam->width * (size_t)cam->height, 1);
  if (!out->kind) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory");
  out->width = cam->width;
  out->height = cam->height;
  for (size_t i = 0; i < g->cache_count; ++i) {
    const iris_cache *c = &g->caches[i];
    int px, py;
    if (!project(cam, c->p, &px, &py)) continue;
    if (!c->from_camera) { /* visible from the camera? */
      iris_vec3 d = iris_sub(c->p, cam->origin);
      float len = iris_length(d);
      iris_ray r = {cam->origin, 0.0f, iris_scale(d, 1.0f / len), len * (1.0f - 1e-3f)};
      if (iris_accel_occluded(s->accel, &r)) continue;
    }
    uint8_t *k = &out->kind[(size_t)py * (size_t)cam->width + (size_t)px];
    if (*k != 1) *k = c->from_camera ? 1 : 2;
  }
  return IRIS_OK;
}

/* First non-delta hit of the camera ray through pixel centre (px, py). */
static bool first_diffuse_hit(const iris_guide_setup *s, int px, int py, iris_shading_point *sp) {
  iris_ray ray = iris_pinhole_ray(s->camera, (float)px + 0.5f, (float)py + 0.5f);
  iris_sampler rng = iris_sampler_start(s->seed, (uint64_t)py * (uint64_t)s->camera->width + (uint64_t)px, 0x64756d70ULL);
  for (int depth = 0; depth <= 8; ++depth) {
    iris_sampler_set_bounce(&rng, depth);
    iris_hit hit;
    if (!iris_accel_intersect(s->accel, &ray, &hit)) return false;
    iris_interaction si;
    iris_accel_interaction(s->accel, ray.d, &hit, &si);
    iris_integrator_shade(s->integrator, &si, iris_normalize(iris_neg(ray.d)), depth, sp);
    if (!sp->delta) return true;
    iris_direction_sample ds;
    if (!iris_integrator_sample_bsdf(sp, &rng, &ds)) return false;
    ray = iris_spawn_ray(&sp->si, ds.wi);
  }
  return false;
}

/* Writes values[texel] (scaled so the largest is white) as a grey PNG. */
static iris_status write_map_png(const iris_octmap *map, const float *values, const char *path,
                                 iris_error *err) {
  float mx = 0.0f;
  for (uint32_t t = 0; t < map->texel_count; ++t) mx = fmaxf(mx, values[t]);
  static const char *const names[3] = {"R", "G", "B"};
  iris_image img;
  iris_status st = iris_image_create(&img, map->width * DUMP_SCALE, map->height * DUMP_SCALE, 3, names, err);
  if (st != IRIS_OK) return st;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      uint32_t t = (uint32_t)((y / DUMP_SCALE) * map->width + x / DUMP_SCALE);
      float v = mx > 0.0f ? values[t] / mx : 0.0f;
      float *px = &img.data[((size_t)y * (size_t)img.width + (size_t)x) * 3];
      px[0] = px[1] = px[2] = v;
      if (map->sphere && x / DUMP_SCALE == map->res && y % 2 == 0) px[0] = 1.0f; /* the equator seam */
    }
  st = iris_png_write(path, &img, 0, 0.0f, err);
  iris_image_destroy(&img);
  return st;
}

iris_status iris_guiding_dump_caches(const iris_guiding *g, const iris_guide_setup *s,
                                     const iris_photon_map *photons, const iris_kdtree *photon_tree,
                                     const char *dir, iris_error *err) {
  if (!iris_path_exists(dir))
    return iris_error_set(err, IRIS_ERR_USAGE, dir, 0, NULL, "the --dump-caches folder does not exist");
  uint32_t k = (uint32_t)g->params.cache_k;
  float *values = malloc(sizeof(float) * g->sphere.texel_count);
  uint32_t *ids = malloc(sizeof(uint32_t) * k);
  float *d2 = malloc(sizeof(float) * k);
  size_t text_cap = 8192, text_len = 0;
  char *text = malloc(text_cap);
  iris_status st = IRIS_OK;
  if (!values || !ids || !d2 || !text)
    st = iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, "guiding", "out of memory");
  if (st == IRIS_OK)
    text_len = (size_t)snprintf(text, text_cap, "# pixel_x pixel_y cache x y z nx ny nz photons_used source map portal"
                                   " (none, or centre x y z, half-axes ux uy uz vx vy vz, weight)\n");
  for (int j = 0; st == IRIS_OK && j < DUMP_ROWS; ++j)
    for (int i = 0; st == IRIS_OK && i < DUMP_COLS; ++i) {
      int px = (int)((i + 0.5) * s->camera->width / DUMP_COLS);
      int py = (int)((j + 0.5) * s->camera->height / DUMP_ROWS);
      iris_shading_point sp;
      uint32_t pick[IRIS_GUIDING_PICK_K];
      int m = first_diffuse_hit(s, px, py, &sp) ? iris_guiding_pick(g, sp.si.p, sp.frame.n, pick) : 0;
      if (m == 0) {
        if (text_len + 128 < text_cap)
          text_len += (size_t)snprintf(text + text_len, text_cap - text_len, "%d %d none\n", px, py);
        continue;
      }
      const iris_cache *c = &g->caches[pick[0]];
      const iris_octmap *map = c->sphere ? &g->sphere : &g->hemi;
      char path[1200];
      /* pdf as texel probability (what sampling picks), not density. */
      for (uint32_t t = 0; t < map->texel_count; ++t)
        values[t] = g->pdf[c->table + t] * 2.0f / ((float)map->res * (float)map->res);
      snprintf(path, sizeof path, "%s/cache_px%04d_py%04d_pdf.png", dir, px, py);
      st = write_map_png(map, values, path, err);
      if (st != IRIS_OK) break;
      memset(values, 0, sizeof(float) * map->texel_count);
      uint32_t n = photons ? iris_kdtree_knn(photon_tree, c->p, k, INFINITY, ids, d2) : 0;
      for (uint32_t q = 0; q < n; ++q) {
        const iris_photon *ph = &photons->photons[ids[q]];
        if (iris_dot(ph->n, c->frame.n) < IRIS_GUIDING_PHOTON_NORMAL_COS) continue;
        iris_cache_splat(map, values, iris_frame_to_local(&c->frame, ph->wi), 1.0f, IRIS_SPLAT_NEAREST);
      }
      snprintf(path, sizeof path, "%s/cache_px%04d_py%04d_photons.png", dir, px, py);
      st = write_map_png(map, values, path, err);
      if (st == IRIS_OK && text_len + 512 < text_cap) {
        text_len += (size_t)snprintf(text + text_len, text_cap - text_len,
                                     "%d %d %u %.4f %.4f %.4f %.3f %.3f %.3f %u %s %s", px, py, pick[0],
                                     (double)c->p.x, (double)c->p.y, (double)c->p.z, (double)c->frame.n.x,
                                     (double)c->frame.n.y, (double)c->frame.n.z, c->photons,
                                     c->from_camera ? "camera" : "photon", c->sphere ? "sphere" : "hemisphere");
        const iris_portal *pt = &c->portal;
        text_len += c->portal_weight > 0.0f
                        ? (size_t)snprintf(text + text_len, text_cap - text_len,
                                           " %.4f %.4f %.4f %.4f %.4f %.4f %.4f %.4f %.4f %.3f\n", (double)pt->o.x,
                                           (double)pt->o.y, (double)pt->o.z, (double)pt->u.x, (double)pt->u.y,
                                           (double)pt->u.z, (double)pt->v.x, (double)pt->v.y, (double)pt->v.z,
                                           (double)c->portal_weight)
                        : (size_t)snprintf(text + text_len, text_cap - text_len, " none\n");
      }
    }
  if (st == IRIS_OK) {
    char path[1200];
    snprintf(path, sizeof path, "%s/caches.txt", dir);
    st = iris_file_write_atomic(path, text, text_len, err);
  }
  free(values);
  free(ids);
  free(d2);
  free(text);
  return st;
}

iris_status iris_guiding_inspect(const iris_guiding *g, const iris_guide_setup *setup,
                                 const iris_guiding_params *params, const iris_photon_map *photons,
                                 const iris_kdtree *photon_tree, iris_error *err) {
  iris_status st = IRIS_OK;
  if (params->dump_dir) st = iris_guiding_dump_caches(g, setup, photons, photon_tree, params->dump_dir, err);
  if (st == IRIS_OK && params->marks) st = iris_guiding_mark_caches(g, setup, params->marks, err);
  return st;
}
