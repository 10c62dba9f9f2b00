/* Exact merge of partitioned renders; see merge.h and docs/distributed.md. */
#include "renderer/merge.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"

/* ---- scene hash ---------------------------------------------------------- */

typedef struct hasher {
  uint64_t h;
} hasher;

static void hash_u64(hasher *s, uint64_t v) { s->h = iris_mix64(s->h ^ (v + 0x9e3779b97f4a7c15ULL)); }

static void hash_bytes(hasher *s, const void *data, size_t size) {
  const unsigned char *p = (const unsigned char *)data;
  hash_u64(s, size);
  size_t i = 0;
  for (; i + 8 <= size; i += 8) {
    uint64_t w;
    memcpy(&w, p + i, 8);
    hash_u64(s, w);
  }
  uint64_t tail = 0;
  memcpy(&tail, p + i, size - i);
  hash_u64(s, tail);
}

static void hash_str(hasher *s, const char *str) {
  if (!str) {
    hash_u64(s, 0xdeadULL);
    return;
  }
  hash_bytes(s, str, strlen(str));
}

static void hash_floats(hasher *s, const float *v, size_t n) {
  hash_u64(s, v ? 1 : 0);
  if (v) hash_bytes(s, v, n * sizeof(float));
}

uint64_t iris_merge_scene_hash(const iris_scene *scene) {
  hasher s = {0x1215c0ffeeULL};
  hash_u64(&s, scene->texture_count);
  for (size_t i = 0; i < scene->texture_count; i++) {
    const iris_texture *t = &scene->textures[i];
    hash_str(&s, t->path);
    hash_u64(&s, t->data ? 1 : 0);
    if (t->data) hash_bytes(&s, t->data, t->data_size);
    hash_str(&s, t->mime);
    hash_u64(&s, ((uint64_t)t->wrap_s << 16) | ((uint64_t)t->wrap_t << 8) | (t->nearest ? 1u : 0u));
    if (t->uv_set || t->has_transform) { /* (scenes without them hash as before) */
      float x[] = {t->offset[0], t->offset[1], t->rotation, t->scale[0], t->scale[1]};
      hash_u64(&s, ((uint64_t)t->uv_set << 8) | (t->has_transform ? 1u : 0u));
      if (t->has_transform) hash_floats(&s, x, 5);
    }
  }
  hash_u64(&s, scene->material_count);
  for (size_t i = 0; i < scene->material_count; i++) {
    const iris_material *m = &scene->materials[i];
    float f[] = {m->color[0], m->color[1], m->color[2], m->roughness, m->ior, m->metallic,
                 m->specular, m->specular_color[0], m->specular_color[1], m->specular_color[2],
                 m->transmission, m->emission[0], m->emission[1], m->emission[2]};
    hash_u64(&s, (uint64_t)m->type);
    hash_floats(&s, f, sizeof f / sizeof f[0]);
    hash_u64(&s, (uint64_t)(int64_t)m->color_texture);
    hash_u64(&s, (uint64_t)(int64_t)m->metallic_roughness_texture);
    hash_u64(&s, (uint64_t)(int64_t)m->emission_texture);
    hash_u64(&s, (m->unlit ? 4u : 0u) | (m->emission_two_sided ? 2u : 0u) | (m->double_sided ? 1u : 0u));
    if (m->alpha_mode != IRIS_ALPHA_OPAQUE || m->alpha != 1.0f) { /* (opaque scenes hash as before) */
      float a[2] = {m->alpha, m->alpha_cutoff};
      hash_u64(&s, (uint64_t)m->alpha_mode);
      hash_floats(&s, a, 2);
    }
    if (m->clearcoat > 0.0f || iris_max3(iris_v3_load(m->sheen_color)) > 0.0f) { /* (others hash as before) */
      float l[8] = {m->clearcoat, m->clearcoat_roughness, m->clearcoat_normal_scale, m->sheen_color[0],
                    m->sheen_color[1], m->sheen_color[2], m->sheen_roughness, 0};
      hash_floats(&s, l, 8);
      int32_t t[5] = {m->clearcoat_texture, m->clearcoat_roughness_texture, m->clearcoat_normal_texture,
                      m->sheen_color_texture, m->sheen_roughness_texture};
      for (int k = 0; k < 5; k++) hash_u64(&s, (uint64_t)(int64_t)t[k]);
    }
    if (m->attenuation_distance > 0.0f) { /* (others hash as before) */
      float v[4] = {m->attenuation_color[0], m->attenuation_color[1], m->attenuation_color[2],
                    m->attenuation_distance};
      hash_floats(&s, v, 4);
    }
    if (m->transmission_texture >= 0 || m->specular_texture >= 0 || m->specular_color_texture >= 0) {
      /* (scenes without them hash as before) */
      int32_t t[3] = {m->transmission_texture, m->specular_texture, m->specular_color_texture};
      for (int k = 0; k < 3; k++) hash_u64(&s, (uint64_t)(int64_t)t[k] ^ 0x7370u);
    }
    if (m->anisotropy > 0.0f) { /* (isotropic scenes hash as before) */
      float a[2] = {m->anisotropy, m->anisotropy_rotation};
      hash_floats(&s, a, 2);
      hash_u64(&s, (uint64_t)(int64_t)m->anisotropy_texture);
    }
    if (m->normal_texture >= 0) { /* (scenes without normal maps hash as before) */
      hash_u64(&s, (uint64_t)(int64_t)m->normal_texture);
      hash_floats(&s, &m->normal_scale, 1);
    }
  }
  hash_u64(&s, scene->mesh_count);
  for (size_t i = 0; i < scene->mesh_count; i++) {
    const iris_mesh *m = &scene->meshes[i];
    hash_u64(&s, ((uint64_t)m->vertex_count << 32) | m->triangle_count);
    hash_floats(&s, m->positions, 3 * (size_t)m->vertex_count);
    hash_floats(&s, m->normals, 3 * (size_t)m->vertex_count);
    hash_floats(&s, m->uvs, 2 * (size_t)m->vertex_count);
    hash_floats(&s, m->colors, 3 * (size_t)m->vertex_count);
    if (m->uvs1) hash_floats(&s, m->uvs1, 2 * (size_t)m->vertex_count);
    if (m->tangents) hash_floats(&s, m->tangents, 4 * (size_t)m->vertex_count);
    if (m->alphas) hash_floats(&s, m->alphas, (size_t)m->vertex_count);
    if (m->indices) hash_bytes(&s, m->indices, 3 * (size_t)m->triangle_count * sizeof(uint32_t));
    hash_u64(&s, (uint64_t)(int64_t)m->material);
  }
  hash_u64(&s, scene->instance_count);
  for (size_t i = 0; i < scene->instance_count; i++) {
    hash_u64(&s, scene->instances[i].mesh);
    hash_bytes(&s, &scene->instances[i].transform, sizeof(iris_mat4));
  }
  hash_u64(&s, scene->camera_count);
  for (size_t i = 0; i < scene->camera_count; i++) {
    const iris_camera *c = &scene->cameras[i];
    hash_str(&s, c->name);
    hash_bytes(&s, &c->to_world, sizeof(iris_mat4));
    float f[] = {c->yfov, c->aspect};
    hash_floats(&s, f, 2);
  }
  hash_u64(&s, scene->light_count);
  for (size_t i = 0; i < scene->light_count; i++) {
    const iris_light *l = &scene->lights[i];
    float f[] = {l->color[0],     l->color[1],     l->color[2],     l->intensity,
                 l->position[0],  l->position[1],  l->position[2],  l->direction[0],
                 l->direction[1], l->direction[2], l->range,        l->inner_cone,
                 l->outer_cone};
    hash_u64(&s, (uint64_t)l->type);
    hash_floats(&s, f, sizeof f / sizeof f[0]);
  }
  hash_u64(&s, scene->has_environment ? 1 : 0);
  if (scene->has_environment) hash_floats(&s, scene->environment, 3);
  if (scene->environment_map.path) { /* the map by its path (its texels are not read here) */
    hash_str(&s, scene->environment_map.path);
    float f[] = {scene->environment_map.strength, scene->environment_map.rotation};
    hash_floats(&s, f, 2);
  }
  return s.h;
}

/* ---- part metadata --------------------------------------------------------- */

static const char *meta_get(const iris_image_meta *meta, size_t n, const char *key) {
  for (size_t i = 0; i < n; i++)
    if (strcmp(meta[i].key, key) == 0) return meta[i].value;
  return NULL;
}

/* Parses exactly `count` comma-separated non-negative integers. */
static bool parse_ints(const char *text, long long *out, int count) {
  const char *p = text;
  for (int i = 0; i < count; i++) {
    if (*p < '0' || *p > '9') return false;
    char *end = NULL;
    errno = 0;
    long long v = strtoll(p, &end, 10);
    if (errno || end == p || v < 0 || v > (1LL << 40)) return false;
    out[i] = v;
    p = end;
    if (i + 1 < count) {
      if (*p != ',') return false;
      p++;
    }
  }
  return *p == 0;
}

/* Copies a metadata value; false when it does not fit (such values are never
 * written by iris, so the part is refused rather than compared truncated). */
static bool copy_str(char *dst, size_t size, const char *src) {
  size_t n = src ? strlen(src) : 0;
  if (n >= size) return false;
  if (n) memcpy(dst, src, n);
  dst[n] = 0;
  return true;
}

iris_status iris_merge_part_info_parse(const iris_image *img, const iris_image_meta *meta,
                                       size_t meta_count, const char *path,
                                       iris_merge_part_info *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  for (int c = 0; c < 3; c++) {
    static const char *const rgb[3] = {"R", "G", "B"};
    if (iris_image_channel(img, rgb[c]) < 0)
      return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL, "has no %s channel", rgb[c]);
  }
  out->has_counts = iris_image_channel(img, "spp") >= 0;
  out->has_variance = iris_image_channel(img, "var.R") >= 0 &&
                      iris_image_channel(img, "var.G") >= 0 &&
                      iris_image_channel(img, "var.B") >= 0;
  const char *method = meta_get(meta, meta_count, "iris:method");
  const char *seed = meta_get(meta, meta_count, "iris:seed");
  const char *spp = meta_get(meta, meta_count, "iris:spp");
  const char *hash = meta_get(meta, meta_count, "iris:scene_hash");
  if (!method || !seed || !spp)
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL,
                          "is not an iris render (no iris:method, iris:seed or iris:spp metadata)");
  if (!hash)
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL,
                          "has no iris:scene_hash (rendered by an iris without partitioned "
                          "renders); re-render it to merge it");
  if (!copy_str(out->method, sizeof out->method, method) ||
      !copy_str(out->seed, sizeof out->seed, seed) ||
      !copy_str(out->scene_hash, sizeof out->scene_hash, hash) ||
      !copy_str(out->config_hash, sizeof out->config_hash,
                meta_get(meta, meta_count, "iris:config_hash")))
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL,
                          "iris:method, iris:seed or a hash is too long to be iris's");
  /* parts written before samplers existed used independent numbers */
  const char *sampler = meta_get(meta, meta_count, "iris:sampler");
  if (!copy_str(out->sampler, sizeof out->sampler, sampler ? sampler : "independent"))
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, "iris:sampler", "is too long to be iris's");
  /* parts written before the light tree existed chose lights by power */
  const char *light_sampler = meta_get(meta, meta_count, "iris:light_sampler");
  if (!copy_str(out->light_sampler, sizeof out->light_sampler, light_sampler ? light_sampler : "power"))
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, "iris:light_sampler", "is too long to be iris's");
  long long v[4];
  if (!parse_ints(spp, v, 1) || v[0] < 1)
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, "iris:spp", "'%s' is not a sample count", spp);
  out->spp = v[0];
  const char *train = meta_get(meta, meta_count, "iris:train_spp");
  if (train) {
    if (!parse_ints(train, v, 1))
      return iris_error_set(err, IRIS_ERR_INVALID, path, 0, "iris:train_spp", "'%s' is not a sample count", train);
    out->train_spp = v[0];
  }
  const char *off = meta_get(meta, meta_count, "iris:sample_offset");
  if (off) {
    if (!parse_ints(off, v, 1))
      return iris_error_set(err, IRIS_ERR_INVALID, path, 0, "iris:sample_offset",
                            "'%s' is not a sample index", off);
    out->sample_offset = v[0];
  }
  const char *full = meta_get(meta, meta_count, "iris:full_size");
  if (full) {
    if (!parse_ints(full, v, 2) || v[0] < 1 || v[1] < 1 || v[0] > 65536 || v[1] > 65536)
      return iris_error_set(err, IRIS_ERR_INVALID, path, 0, "iris:full_size",
                            "'%s' is not W,H", full);
    out->full_width = (int)v[0];
    out->full_height = (int)v[1];
    if ((uint64_t)v[0] * (uint64_t)v[1] > (1ull << 28)) /* iris_film_create's limit */
      return iris_error_set(err, IRIS_ERR_INVALID, path, 0, "iris:full_size",
                            "frame %s is larger than any iris film", full);
  } else {
    out->full_width = img->width;
    out->full_height = img->height;
  }
  const char *win = meta_get(meta, meta_count, "iris:window");
  if (win) {
    if (!parse_ints(win, v, 4))
      return iris_error_set(err, IRIS_ERR_INVALID, path, 0, "iris:window",
                            "'%s' is not x0,y0,x1,y1", win);
    if (v[0] >= v[2] || v[1] >= v[3] || v[2] > out->full_width || v[3] > out->full_height)
      return iris_error_set(err, IRIS_ERR_INVALID, path, 0, "iris:window",
                            "window %s is empty or outside the %dx%d frame", win,
                            out->full_width, out->full_height);
    out->x0 = (int)v[0];
    out->y0 = (int)v[1];
    out->x1 = (int)v[2];
    out->y1 = (int)v[3];
  } else {
    out->x1 = out->full_width;
    out->y1 = out->full_height;
  }
  if (img->width != out->x1 - out->x0 || img->height != out->y1 - out->y0)
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL,
                          "image is %dx%d but its window %d,%d,%d,%d is %dx%d", img->width,
                          img->height, out->x0, out->y0, out->x1, out->y1, out->x1 - out->x0,
                          out->y1 - out->y0);
  return IRIS_OK;
}

/* ---- accumulation ---------------------------------------------------------- */

void iris_merge_init(iris_merge *m) {
  memset(m, 0, sizeof *m);
  m->all_variance = true;
}

void iris_merge_destroy(iris_merge *m) {
  if (!m) return;
  free(m->parts);
  free(m->meta);
  free(m->n);
  free(m->mean);
  free(m->m2);
  memset(m, 0, sizeof *m);
}

static iris_status mismatch(iris_error *err, const char *path, const char *what, const char *a,
                            const char *b, const char *first) {
  return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL,
                        "rendered with %s %s, but %s has %s; parts of one image must share it",
                        what, b, first, a);
}

iris_status iris_merge_add(iris_merge *m, const char *path, const iris_image *img,
                           const iris_image_meta *meta, size_t meta_count, iris_error *err) {
  iris_merge_part part;
  memset(&part, 0, sizeof part);
  if (!copy_str(part.path, sizeof part.path, path))
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "part path too long");
  iris_status st = iris_merge_part_info_parse(img, meta, meta_count, path, &part.info, err);
  if (st != IRIS_OK) return st;
  const iris_merge_part_info *in = &part.info;
  if (m->part_count == 0) {
    size_t n = (size_t)in->full_width * (size_t)in->full_height;
    m->n = calloc(n, sizeof(double));
    m->mean = calloc(3 * n, sizeof(double));
    m->m2 = calloc(3 * n, sizeof(double));
    m->meta = meta_count ? malloc(meta_count * sizeof *meta) : NULL;
    if (!m->n || !m->mean || !m->m2 || (meta_count && !m->meta))
      return iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "out of memory for a %dx%d merge",
                            in->full_width, in->full_height);
    if (meta_count) memcpy(m->meta, meta, meta_count * sizeof *meta);
    m->meta_count = meta_count;
    m->width = in->full_width;
    m->height = in->full_height;
  } else {
    const iris_merge_part *f = &m->parts[0];
    const iris_merge_part_info *fi = &f->info;
    if (strcmp(in->scene_hash, fi->scene_hash) != 0)
      return mismatch(err, path, "scene hash", fi->scene_hash, in->scene_hash, f->path);
    if (strcmp(in->seed, fi->seed) != 0) return mismatch(err, path, "seed", fi->seed, in->seed, f->path);
    if (strcmp(in->method, fi->method) != 0)
      return mismatch(err, path, "method", fi->method, in->method, f->path);
    if (strcmp(in->sampler, fi->sampler) != 0)
      return mismatch(err, path, "sampler", fi->sampler, in->sampler, f->path);
    if (strcmp(in->light_sampler, fi->light_sampler) != 0)
      return mismatch(err, path, "light sampler", fi->light_sampler, in->light_sampler, f->path);
    if (in->full_width != fi->full_width || in->full_height != fi->full_height) {
      char a[32], b[32];
      snprintf(a, sizeof a, "%dx%d", fi->full_width, fi->full_height);
      snprintf(b, sizeof b, "%dx%d", in->full_width, in->full_height);
      return mismatch(err, path, "frame size", a, b, f->path);
    }
    if (strcmp(in->config_hash, fi->config_hash) != 0)
      return mismatch(err, path, "render configuration (camera, depths, guiding options) hash",
                      fi->config_hash, in->config_hash, f->path);
  }
  /* Training samples are the guide-training process's own: only a part that
   * starts at sample 0 can hold them, and every such part the same number. */
  if (in->train_spp > 0 && in->sample_offset > 0)
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, "iris:train_spp",
                          "%" PRId64 " training samples in a part starting at sample %" PRId64
                          " (only the part at sample 0 may hold them)", in->train_spp, in->sample_offset);
  if (in->sample_offset == 0) {
    bool first0 = true;
    for (size_t i = 0; i < m->part_count; i++) first0 = first0 && m->parts[i].info.sample_offset != 0;
    if (first0) m->train_spp = in->train_spp;
    else if (in->train_spp != m->train_spp)
      return iris_error_set(err, IRIS_ERR_INVALID, path, 0, "iris:train_spp",
                            "%" PRId64 " training samples where the other parts at sample 0 hold %" PRId64,
                            in->train_spp, m->train_spp);
  }
  if (m->part_count == m->part_capacity) {
    size_t cap = m->part_capacity ? 2 * m->part_capacity : 16;
    iris_merge_part *p = realloc(m->parts, cap * sizeof *p);
    if (!p) return iris_error_set(err, IRIS_ERR_NOMEM, path, 0, NULL, "out of memory");
    m->parts = p;
    m->part_capacity = cap;
  }
  m->parts[m->part_count++] = part;
  if (!in->has_variance) m->all_variance = false;
  const char *secs = meta_get(meta, meta_count, "iris:render_seconds");
  if (secs) m->render_seconds += strtod(secs, NULL);
  const char *nans = meta_get(meta, meta_count, "iris:nan_count");
  if (nans) m->nan_count += strtoull(nans, NULL, 10);

  /* Chan, Golub and LeVeque's pairwise update: with the part's count nb, mean
   * mb and variance of the mean vb, its sum of squared deviations is
   * M2b = vb * nb * (nb - 1) (film.c stores s^2 / n with s^2 = M2 / (n - 1)),
   * and n = na + nb, mean += (mb - ma) nb / n, M2 = M2a + M2b + (mb - ma)^2 na nb / n. */
  int cm[3], cv[3];
  static const char *const names[6] = {"R", "G", "B", "var.R", "var.G", "var.B"};
  for (int c = 0; c < 3; c++) {
    cm[c] = iris_image_channel(img, names[c]);
    cv[c] = in->has_variance ? iris_image_channel(img, names[3 + c]) : -1;
  }
  const double uniform_nb = (double)(in->spp + in->train_spp); /* the film's count per pixel */
  const int cn = in->has_counts ? iris_image_channel(img, "spp") : -1; /* adaptive: per pixel */
  if (cn >= 0) m->any_counts = true;
  const int cc = img->channel_count;
  for (int y = in->y0; y < in->y1; y++)
    for (int x = in->x0; x < in->x1; x++) {
      const float *px = img->data + ((size_t)(y - in->y0) * (size_t)img->width + (size_t)(x - in->x0)) * (size_t)cc;
      size_t i = (size_t)y * (size_t)m->width + (size_t)x;
      const double nb = cn >= 0 ? (double)px[cn] : uniform_nb;
      if (!(nb >= 0.0 && nb <= 4294967295.0 && nb == floor(nb)))
        return iris_error_set(err, IRIS_ERR_INVALID, path, 0, "spp", "pixel (%d, %d): %g is not a sample count", x,
                              y, (double)px[cn]);
      if (nb == 0.0) continue;
      double na = m->n[i], n = na + nb;
      for (int c = 0; c < 3; c++) {
        double mb = px[cm[c]];
        double m2b = cv[c] >= 0 ? (double)px[cv[c]] * nb * (nb - 1.0) : 0.0;
        double delta = mb - m->mean[3 * i + c];
        m->mean[3 * i + c] += delta * (nb / n);
        m->m2[3 * i + c] += m2b + delta * delta * (na * nb / n);
      }
      m->n[i] = n;
    }
  return IRIS_OK;
}

/* ---- coverage checks -------------------------------------------------------- */

static int cmp_parts(const void *a, const void *b) {
  const iris_merge_part_info *p = &((const iris_merge_part *)a)->info;
  const iris_merge_part_info *q = &((const iris_merge_part *)b)->info;
  int k[4] = {p->y0 - q->y0, p->x0 - q->x0, p->y1 - q->y1, p->x1 - q->x1};
  for (int i = 0; i < 4; i++)
    if (k[i]) return k[i] < 0 ? -1 : 1;
  if (p->sample_offset != q->sample_offset) return p->sample_offset < q->sample_offset ? -1 : 1;
  return 0;
}

static bool same_window(const iris_merge_part_info *a, const iris_merge_part_info *b) {
  return a->x0 == b->x0 && a->y0 == b->y0 && a->x1 == b->x1 && a->y1 == b->y1;
}

typedef struct window_run {
  const iris_merge_part *first;
  int64_t begin, end;
} window_run;

static iris_status check_coverage(iris_merge *m, int64_t *begin, int64_t *end, iris_error *err) {
  qsort(m->parts, m->part_count, sizeof *m->parts, cmp_parts);
  window_run *runs = calloc(m->part_count, sizeof *runs);
  if (!runs) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory");
  size_t nr = 0;
  iris_status st = IRIS_OK;
  for (size_t i = 0; i < m->part_count && st == IRIS_OK; i++) {
    const iris_merge_part *p = &m->parts[i];
    int64_t b = p->info.sample_offset, e = b + p->info.spp;
    if (nr > 0 && same_window(&runs[nr - 1].first->info, &p->info)) {
      const iris_merge_part *prev = &m->parts[i - 1];
      window_run *r = &runs[nr - 1];
      if (b < r->end)
        st = iris_error_set(err, IRIS_ERR_INVALID, p->path, 0, NULL,
                            "samples %" PRId64 "..%" PRId64 " overlap samples %" PRId64
                            "..%" PRId64 " of %s (same window %d,%d,%d,%d)",
                            b, e - 1, prev->info.sample_offset,
                            prev->info.sample_offset + prev->info.spp - 1, prev->path, p->info.x0,
                            p->info.y0, p->info.x1, p->info.y1);
      else if (b > r->end)
        st = iris_error_set(err, IRIS_ERR_INVALID, p->path, 0, NULL,
                            "samples %" PRId64 "..%" PRId64 " are missing between %s (ends at "
                            "%" PRId64 ") and this part (starts at %" PRId64 "), window %d,%d,%d,%d",
                            r->end, b - 1, prev->path, r->end - 1, b, p->info.x0, p->info.y0,
                            p->info.x1, p->info.y1);
      r->end = e;
    } else {
      runs[nr].first = p;
      runs[nr].begin = b;
      runs[nr].end = e;
      nr++;
    }
  }
  /* Every window the same sample run. */
  for (size_t i = 1; i < nr && st == IRIS_OK; i++)
    if (runs[i].begin != runs[0].begin || runs[i].end != runs[0].end) {
      const iris_merge_part_info *a = &runs[0].first->info, *b = &runs[i].first->info;
      st = iris_error_set(err, IRIS_ERR_INVALID, runs[i].first->path, 0, NULL,
                          "window %d,%d,%d,%d has samples %" PRId64 "..%" PRId64
                          " but window %d,%d,%d,%d (%s) has %" PRId64 "..%" PRId64
                          "; a part is missing or doubled",
                          b->x0, b->y0, b->x1, b->y1, runs[i].begin, runs[i].end - 1, a->x0,
                          a->y0, a->x1, a->y1, runs[0].first->path, runs[0].begin, runs[0].end - 1);
    }
  /* Windows pairwise disjoint, then their areas must add up to the frame. */
  uint64_t area = 0;
  for (size_t i = 0; i < nr && st == IRIS_OK; i++) {
    const iris_merge_part_info *a = &runs[i].first->info;
    area += (uint64_t)(a->x1 - a->x0) * (uint64_t)(a->y1 - a->y0);
    for (size_t j = i + 1; j < nr && st == IRIS_OK; j++) {
      const iris_merge_part_info *b = &runs[j].first->info;
      if (b->y0 >= a->y1) break; /* sorted by y0: no later window reaches a */
      if (a->x0 < b->x1 && b->x0 < a->x1 && a->y0 < b->y1 && b->y0 < a->y1)
        st = iris_error_set(err, IRIS_ERR_INVALID, runs[j].first->path, 0, NULL,
                            "window %d,%d,%d,%d overlaps window %d,%d,%d,%d of %s", b->x0, b->y0,
                            b->x1, b->y1, a->x0, a->y0, a->x1, a->y1, runs[i].first->path);
    }
  }
  if (st == IRIS_OK && area != (uint64_t)m->width * (uint64_t)m->height) {
    size_t i = 0, n = (size_t)m->width * (size_t)m->height;
    while (i < n && m->n[i] > 0) i++;
    st = iris_error_set(err, IRIS_ERR_INVALID, NULL, 0, NULL,
                        "the parts leave pixel (%d, %d) of the %dx%d frame uncovered; a tile is "
                        "missing", (int)(i % (size_t)m->width), (int)(i / (size_t)m->width),
                        m->width, m->height);
  }
  if (st == IRIS_OK) {
    m->window_count = nr;
    *begin = runs[0].begin;
    *end = runs[0].end;
  }
  free(runs);
  return st;
}

iris_status iris_merge_finish(iris_merge *m, iris_image *out, iris_image_meta **meta_out,
                              size_t *meta_count_out, iris_error *err) {
  memset(out, 0, sizeof *out);
  *meta_out = NULL;
  *meta_count_out = 0;
  if (m->part_count == 0)
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "no parts to merge");
  int64_t begin = 0, end = 0;
  iris_status st = check_coverage(m, &begin, &end, err);
  if (st != IRIS_OK) return st;
  static const char *const with_var[7] = {"R", "G", "B", "var.R", "var.G", "var.B", "spp"};
  static const char *const without_var[4] = {"R", "G", "B", "spp"};
  const bool var = m->all_variance;
  const int cc = (var ? 6 : 3) + (m->any_counts ? 1 : 0);
  st = iris_image_create(out, m->width, m->height, cc, var ? with_var : without_var, err);
  if (st != IRIS_OK) return st;
  size_t n = (size_t)m->width * (size_t)m->height;
  for (size_t i = 0; i < n; i++) {
    float *px = out->data + i * (size_t)cc;
    double k = m->n[i];
    for (int c = 0; c < 3; c++) {
      px[c] = (float)m->mean[3 * i + c];
      if (var) px[3 + c] = k > 1.0 ? (float)(m->m2[3 * i + c] / (k - 1.0) / k) : 0.0f;
    }
    if (m->any_counts) px[cc - 1] = (float)k;
  }

  /* Metadata: the first part's iris:* keys (not the EXR's own, such as type
   * and name, which the writer sets), with the merged sample range, window
   * and totals; per-process keys (threads) are dropped. */
  static const char *const replaced[] = {"iris:spp",          "iris:sample_offset", "iris:window",
                                         "iris:full_size",    "iris:render_seconds",
                                         "iris:nan_count",    "iris:threads",
                                         "iris:interrupted",  "iris:merged_parts", "iris:train_spp"};
  const size_t nrep = sizeof replaced / sizeof replaced[0];
  iris_image_meta *meta = calloc(m->meta_count + nrep, sizeof *meta);
  if (!meta) {
    iris_image_destroy(out);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory");
  }
  size_t k = 0;
  for (size_t i = 0; i < m->meta_count; i++) {
    bool skip = strncmp(m->meta[i].key, "iris:", 5) != 0;
    for (size_t r = 0; r < nrep; r++) skip = skip || strcmp(m->meta[i].key, replaced[r]) == 0;
    if (!skip) meta[k++] = m->meta[i];
  }
#define META(name, ...)                                                \
  do {                                                                 \
    snprintf(meta[k].key, sizeof meta[k].key, "%s", name);             \
    snprintf(meta[k].value, sizeof meta[k].value, __VA_ARGS__);        \
    k++;                                                               \
  } while (0)
  META("iris:spp", "%" PRId64, end - begin);
  META("iris:sample_offset", "%" PRId64, begin);
  META("iris:window", "0,0,%d,%d", m->width, m->height);
  META("iris:full_size", "%d,%d", m->width, m->height);
  META("iris:render_seconds", "%.3f", m->render_seconds);
  META("iris:nan_count", "%" PRIu64, m->nan_count);
  META("iris:interrupted", "false");
  META("iris:merged_parts", "%zu", m->part_count);
  META("iris:train_spp", "%" PRId64, m->train_spp);
#undef META
  *meta_out = meta;
  *meta_count_out = k;
  return IRIS_OK;
}

iris_status iris_merge_files(const char *const *paths, size_t count, const char *out_path,
                             iris_merge_summary *summary, iris_error *err) {
  iris_merge m;
  iris_merge_init(&m);
  iris_status st = IRIS_OK;
  for (size_t i = 0; i < count && st == IRIS_OK; i++) {
    iris_image img;
    iris_image_meta *meta = NULL;
    size_t mc = 0;
    st = iris_exr_read(paths[i], &img, &meta, &mc, err);
    if (st != IRIS_OK) break;
    st = iris_merge_add(&m, paths[i], &img, meta, mc, err);
    iris_image_destroy(&img);
    free(meta);
  }
  iris_image out;
  iris_image_meta *meta = NULL;
  size_t mc = 0;
  memset(&out, 0, sizeof out);
  if (st == IRIS_OK) st = iris_merge_finish(&m, &out, &meta, &mc, err);
  if (st == IRIS_OK) {
    if (summary) {
      memset(summary, 0, sizeof *summary);
      summary->width = out.width;
      summary->height = out.height;
      summary->parts = m.part_count;
      summary->variance = m.all_variance;
      for (size_t i = 0; i < mc; i++) {
        if (strcmp(meta[i].key, "iris:spp") == 0) summary->spp = strtoll(meta[i].value, NULL, 10);
        if (strcmp(meta[i].key, "iris:sample_offset") == 0)
          summary->sample_offset = strtoll(meta[i].value, NULL, 10);
      }
      summary->windows = m.window_count;
    }
    st = iris_exr_write(out_path, &out, meta, mc, err);
  }
  iris_image_destroy(&out);
  free(meta);
  iris_merge_destroy(&m);
  return st;
}
