/* race_check SCENE [--spp N] [--width W --height H] [--threads T] [--seed S]
 *
 * How well `--method auto`'s race (renderer/method_race.h) predicts what it
 * decides: renders SCENE with auto (1 spp, for the race's numbers), then mis
 * and guided-nee with N samples per pixel each (independent sampler, training
 * samples left out), and measures each method's relative variance of one
 * sample (the race's statistic: mean over pixels of (1/3) sum_c var_c /
 * (m_c^2 + 0.01), m the two long renders' mean over the pixel's 8
 * neighbours) and its image-pass time per sample. Prints one line:
 *   scene choice race_speedup race_relvar_ratio true_relvar_ratio
 *   trimmed_relvar_ratio model_cost_ratio true_time_ratio true_speedup agrees
 * (ratios are mis over guided-nee for variance, guided-nee over mis for cost;
 * speedup > 1: guided-nee is the better at equal time). docs/guiding.md,
 * "--method auto", has the table and the command. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "renderer/guiding/guiding.h"
#include "renderer/render.h"
#include "scenes/builtin.h"

static bool render(const iris_scene *s, iris_method m, int w, int h, int spp, int threads, uint64_t seed,
                   iris_render_result *r) {
  static iris_guiding_params gp;
  gp = iris_guiding_params_default();
  iris_render_params p = iris_render_params_default();
  p.width = w;
  p.height = h;
  p.spp = spp;
  p.method = m;
  p.seed = seed;
  p.threads = threads;
  p.sampler = IRIS_SAMPLER_INDEPENDENT;
  p.keep_training = false;
  p.guide = &iris_guiding_provider;
  p.guide_options = &gp;
  iris_error err;
  iris_error_clear(&err);
  if (iris_render(s, &p, r, &err) != IRIS_OK) {
    fprintf(stderr, "race_check: %s\n", err.message);
    return false;
  }
  return true;
}

/* The race's statistic over the whole film, with denominators from `both`;
 * with `trim`, after dropping the 0.1% largest pixel terms, as iris bench's
 * relMSE drops the 0.1% largest errors. */
static double relvar(const iris_film *f, const double *both, bool trim) {
  const int w = f->width, h = f->height;
  double *terms = malloc((size_t)w * (size_t)h * sizeof *terms);
  if (!terms) return NAN;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      double ref[3];
      iris_race_neighbour_mean(both, w, h, x, y, ref);
      iris_vec3 mean, var;
      iris_film_pixel(f, x, y, &mean, &var);
      const double n = f->count[(size_t)y * (size_t)w + (size_t)x];
      const double v[3] = {var.x * n, var.y * n, var.z * n}; /* one sample's variance */
      terms[(size_t)y * (size_t)w + (size_t)x] = iris_race_term(v, ref);
    }
  const size_t n = (size_t)w * (size_t)h;
  double mean;
  if (trim) {
    mean = iris_race_trimmed_mean(terms, n, NULL);
  } else {
    mean = 0.0;
    for (size_t i = 0; i < n; i++) mean += terms[i] / (double)n;
  }
  free(terms);
  return mean;
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: race_check SCENE [--spp N] [--width W --height H] [--threads T] [--seed S]\n");
    return 2;
  }
  int spp = 256, w = 128, h = 96, threads = 2;
  uint64_t seed = 1;
  for (int i = 2; i + 1 < argc; i += 2) {
    if (!strcmp(argv[i], "--spp")) spp = atoi(argv[i + 1]);
    else if (!strcmp(argv[i], "--width")) w = atoi(argv[i + 1]);
    else if (!strcmp(argv[i], "--height")) h = atoi(argv[i + 1]);
    else if (!strcmp(argv[i], "--threads")) threads = atoi(argv[i + 1]);
    else if (!strcmp(argv[i], "--seed")) seed = strtoull(argv[i + 1], NULL, 10);
    else {
      fprintf(stderr, "race_check: unknown option %s\n", argv[i]);
      return 2;
    }
  }
  iris_scene *s = NULL;
  iris_error err;
  iris_error_clear(&err);
  if (iris_builtin_create(argv[1], &s, &err) != IRIS_OK) {
    fprintf(stderr, "race_check: %s\n", err.message);
    return 2;
  }
  iris_render_result a, m, g;
  if (!render(s, IRIS_METHOD_AUTO, w, h, 1, threads, seed, &a)) return 1;
  if (!render(s, IRIS_METHOD_MIS, w, h, spp, threads, seed + 1, &m)) return 1;
  if (!render(s, IRIS_METHOD_GUIDED_NEE, w, h, spp, threads, seed + 2, &g)) return 1;
  const size_t n = (size_t)w * (size_t)h;
  double *both = malloc(3 * n * sizeof *both);
  if (!both) return 1;
  for (size_t i = 0; i < n; i++)
    for (int c = 0; c < 3; c++)
      both[3 * i + (size_t)c] = 0.5 * (m.film.sum[3 * i + (size_t)c] / m.film.count[i] +
                                       g.film.sum[3 * i + (size_t)c] / g.film.count[i]);
  const double rv_m = relvar(&m.film, both, false), rv_g = relvar(&g.film, both, false);
  const double tr_m = relvar(&m.film, both, true), tr_g = relvar(&g.film, both, true);
  const double samples = (double)spp * (double)n;
  const double t_m = m.seconds / samples, t_g = g.seconds / samples;
  const double true_speedup = (rv_m * t_m) / (rv_g * t_g);
  if (!a.raced) {
    printf("%s %s (no race: %s) - - %.3f %.3f - %.3f %.3f -\n", argv[1], iris_method_name(a.method), a.method_reason,
           rv_m / rv_g, tr_m / tr_g, t_g / t_m, true_speedup);
  } else {
    const iris_race_outcome *o = &a.race;
    const bool agrees = (a.method == IRIS_METHOD_GUIDED_NEE) == (true_speedup > 1.0);
    printf("%s %s %.3f %.3f %.3f %.3f %.3f %.3f %.3f %s\n", argv[1], iris_method_name(a.method), o->speedup,
           o->relvar[0] / o->relvar[1], rv_m / rv_g, tr_m / tr_g, o->cost[1] / o->cost[0], t_g / t_m, true_speedup,
           agrees ? "yes" : "NO");
  }
  free(both);
  iris_render_result_destroy(&a);
  iris_render_result_destroy(&m);
  iris_render_result_destroy(&g);
  iris_scene_destroy(s);
  return 0;
}
