/* Failure-stability measurements (bench/stress/suite.h). */
#include "bench/stress/suite.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "renderer/guiding/guiding.h"
#include "renderer/render.h"

iris_stress_params iris_stress_params_default(void) {
  iris_stress_params p;
  memset(&p, 0, sizeof p);
  p.spp = 16;
  p.max_depth = -1;
  return p;
}

static iris_status render_once(const iris_scene *scene, iris_method method,
                               const iris_stress_params *sp, int spp, double budget,
                               iris_render_result *res, iris_error *err) {
  iris_render_params p = iris_render_params_default();
  p.width = sp->width;
  p.height = sp->height;
  p.seed = sp->seed;
  p.threads = sp->threads;
  p.method = method;
  p.max_depth = sp->max_depth;
  p.spp = spp;
  p.time_budget = budget;
  iris_guiding_params gp = iris_guiding_params_default();
  if (iris_method_uses_guiding(method) || method == IRIS_METHOD_AUTO) {
    gp.use_nee = iris_method_uses_nee(method);
    if (sp->guide_photons > 0) gp.photons = sp->guide_photons;
    p.guide = &iris_guiding_provider;
    p.guide_options = &gp;
  }
  return iris_render(scene, &p, res, err);
}

iris_status iris_stress_render(const iris_scene *scene, iris_method method,
                               const iris_stress_params *params, iris_stress_render_out *out,
                               iris_error *err) {
  memset(out, 0, sizeof *out);
  iris_render_result res;
  iris_status st;
  if (params->seconds > 0.0) {
    /* Pilot at 1 spp: the setup time (accel, lights, guide) counts against the
     * budget, and only iris_render knows it. */
    st = render_once(scene, method, params, 1, 0.0, &res, err);
    if (st != IRIS_OK) return st;
    double setup = res.setup_seconds;
    double per_spp = res.seconds;
    iris_render_result_destroy(&res);
    double left = params->seconds - setup;
    if (left > 2.0 * per_spp)
      st = render_once(scene, method, params, 0, left, &res, err);
    else /* the setup alone fills the budget: 2 samples per pixel, the fewest
            that give a variance estimate */
      st = render_once(scene, method, params, 2, 0.0, &res, err);
  } else {
    st = render_once(scene, method, params, params->spp > 0 ? params->spp : 1, 0.0, &res, err);
  }
  if (st != IRIS_OK) return st;
  st = iris_film_to_image(&res.film, true, &out->image, err);
  out->spp = res.spp;
  out->seconds = res.setup_seconds + res.seconds;
  out->setup_seconds = res.setup_seconds;
  out->dropped = res.stats.nan_count;
  iris_render_result_destroy(&res);
  return st;
}

void iris_stress_render_out_destroy(iris_stress_render_out *out) {
  iris_image_destroy(&out->image);
  memset(out, 0, sizeof *out);
}

bool iris_stress_unbiased(const iris_stress_compare *c, double alpha) {
  if (c->nan_values || c->inf_values) return false;
  if (fabs(c->energy_z) > iris_stress_energy_zcrit(alpha)) return false;
  /* a region whose test and reference variances are both 0 is compared
   * exactly (degenerate); one that differs there fails too */
  return c->regions.z_over == 0 && c->regions.z_degenerate_fail == 0;
}

double iris_stress_energy_zcrit(double alpha) {
  /* three channel tests per comparison */
  return iris_metric_normal_two_sided_z(alpha / 3.0);
}

/* The sign of each failing region-channel of the gate (the z of
 * iris_metric_blocks, which reports only |z|). */
static void count_region_signs(const iris_image *test, const iris_image *ref, bool ref_exact,
                               int block, double z_crit, iris_stress_compare *out) {
  const int w = test->width, h = test->height;
  for (int y0 = 0; y0 < h; y0 += block)
    for (int x0 = 0; x0 < w; x0 += block)
      for (int c = 0; c < 3; c++) {
        double d = 0.0, v = 0.0;
        for (int y = y0; y < y0 + block && y < h; y++)
          for (int x = x0; x < x0 + block && x < w; x++) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            const float *t = test->data + i * (size_t)test->channel_count;
            const float *r = ref->data + i * (size_t)ref->channel_count;
            if (!isfinite(t[c]) || !isfinite(t[3 + c])) continue;
            d += (double)t[c] - r[c];
            v += t[3 + c] + (ref_exact ? 0.0 : r[3 + c]);
          }
        if (v <= 0.0) continue;
        double z = d / sqrt(v);
        if (z > z_crit) out->regions_high++;
        if (z < -z_crit) out->regions_low++;
      }
}

iris_status iris_stress_compare_images(const iris_image *test, const iris_image *ref,
                                       bool ref_exact, double alpha, int region,
                                       iris_stress_compare *out, iris_error *err) {
  memset(out, 0, sizeof *out);
  if (test->width != ref->width || test->height != ref->height || test->channel_count < 6 ||
      ref->channel_count < 6)
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL,
                          "stress: images differ in size (%dx%d vs %dx%d) or lack variance",
                          test->width, test->height, ref->width, ref->height);
  iris_metric_count_nonfinite(test, 0, 3, &out->nan_values, &out->inf_values);
  const size_t n = (size_t)test->width * (size_t)test->height;
  const int tc = test->channel_count, rc = ref->channel_count;
  double st[3] = {0, 0, 0}, sr[3] = {0, 0, 0}, vt[3] = {0, 0, 0}, vr[3] = {0, 0, 0};
  double floor_sum = 0.0;
  bool black = true;
  for (size_t i = 0; i < n; i++) {
    const float *t = test->data + i * (size_t)tc, *r = ref->data + i * (size_t)rc;
    for (int c = 0; c < 3; c++) {
      if (isfinite(t[c])) {
        if (t[c] > out->max_value) out->max_value = t[c];
        st[c] += t[c];
        vt[c] += t[3 + c];
      }
      if (t[c] != 0.0f) black = false;
      sr[c] += r[c];
      if (!ref_exact) {
        vr[c] += r[3 + c];
        floor_sum += r[3 + c] / ((double)r[c] * r[c] + IRIS_METRIC_EPS) / 3.0;
      }
    }
  }
  out->black_exact = black && out->nan_values == 0 && out->inf_values == 0;
  out->ref_relmse = floor_sum / (double)n;
  double mt[3], mr[3];
  for (int c = 0; c < 3; c++) {
    mt[c] = st[c] / (double)n;
    mr[c] = sr[c] / (double)n;
    out->energy_test += mt[c];
    out->energy_ref += mr[c];
    /* variance of a channel's image mean: pixels are independent */
    double var = (vt[c] + vr[c]) / ((double)n * (double)n);
    double z = var > 0.0 ? (mt[c] - mr[c]) / sqrt(var) : (mt[c] == mr[c] ? 0.0 : copysign(INFINITY, mt[c] - mr[c]));
    if (fabs(z) > fabs(out->energy_z)) out->energy_z = z;
  }
  out->energy_ratio = iris_metric_energy_ratio(mt, mr);
  out->relmse = iris_metric_relmse(test, 0, ref, 0, IRIS_METRIC_EPS, IRIS_METRIC_DROP);
  iris_ref_variance rv;
  rv.rv0 = ref_exact ? -1 : 3;
  rv.scale = 0.0;
  iris_status s = iris_metric_blocks(test, 0, 3, ref, 0, rv, IRIS_METRIC_BLOCK, alpha, &out->blocks, err);
  if (s == IRIS_OK)
    s = iris_metric_blocks(test, 0, 3, ref, 0, rv, region > 0 ? region : IRIS_STRESS_REGION, alpha,
                           &out->regions, err);
  if (s == IRIS_OK) count_region_signs(test, ref, ref_exact, out->regions.block, out->regions.z_crit, out);
  if (s == IRIS_OK) s = iris_metric_pixel_ztest(test, 0, 3, ref, 0, rv, alpha, NULL, &out->pixels, err);
  return s;
}

static const char *const CHANNELS[6] = {"R", "G", "B", "var.R", "var.G", "var.B"};

iris_status iris_stress_image_read(const char *path, iris_image *out, int *spp, double *seconds,
                                   iris_error *err) {
  memset(out, 0, sizeof *out);
  if (spp) *spp = 0;
  if (seconds) *seconds = 0.0;
  iris_image img;
  iris_image_meta *meta = NULL;
  size_t meta_count = 0;
  iris_status st = iris_exr_read(path, &img, &meta, &meta_count, err);
  if (st != IRIS_OK) return st;
  for (size_t k = 0; k < meta_count; k++) {
    if (spp && strcmp(meta[k].key, "iris:spp") == 0) *spp = atoi(meta[k].value);
    if (seconds && strcmp(meta[k].key, "iris:render_seconds") == 0) *seconds = atof(meta[k].value);
  }
  free(meta);
  int map[6];
  for (int c = 0; c < 6; c++) {
    map[c] = iris_image_channel(&img, CHANNELS[c]);
    if (map[c] < 0) {
      iris_image_destroy(&img);
      return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL, "no channel %s", CHANNELS[c]);
    }
  }
  st = iris_image_create(out, img.width, img.height, 6, CHANNELS, err);
  if (st == IRIS_OK) {
    size_t n = (size_t)img.width * (size_t)img.height;
    for (size_t i = 0; i < n; i++)
      for (int c = 0; c < 6; c++)
        out->data[6 * i + (size_t)c] = img.data[i * (size_t)img.channel_count + (size_t)map[c]];
  }
  iris_image_destroy(&img);
  return st;
}

iris_status iris_stress_image_write(const char *path, const iris_image *img, const char *scene,
                                    const char *method, int spp, double seconds, iris_error *err) {
  iris_image_meta meta[4];
  memset(meta, 0, sizeof meta);
  snprintf(meta[0].key, sizeof meta[0].key, "iris:scene");
  snprintf(meta[0].value, sizeof meta[0].value, "%s", scene);
  snprintf(meta[1].key, sizeof meta[1].key, "iris:method");
  snprintf(meta[1].value, sizeof meta[1].value, "%s", method);
  snprintf(meta[2].key, sizeof meta[2].key, "iris:spp");
  snprintf(meta[2].value, sizeof meta[2].value, "%d", spp);
  snprintf(meta[3].key, sizeof meta[3].key, "iris:render_seconds");
  snprintf(meta[3].value, sizeof meta[3].value, "%.3f", seconds);
  iris_status st = iris_exr_write(path, img, meta, 4, err);
  if (st != IRIS_OK) return st;
  iris_image back;
  st = iris_stress_image_read(path, &back, NULL, NULL, err);
  if (st != IRIS_OK) return st;
  size_t n = (size_t)img->width * (size_t)img->height, bad = 0, first = 0;
  if (back.width != img->width || back.height != img->height || img->channel_count != 6) {
    bad = 1;
  } else {
    for (size_t i = 0; i < 6 * n; i++)
      if (memcmp(&back.data[i], &img->data[i], sizeof(float)) != 0 && bad++ == 0) first = i;
  }
  iris_image_destroy(&back);
  if (bad)
    return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL,
                          "the EXR does not read back as written (%zu values differ from row %zu; "
                          "OpenEXR issue #2306 in the ZIP encoder)",
                          bad, first / (6 * (size_t)img->width));
  return IRIS_OK;
}
