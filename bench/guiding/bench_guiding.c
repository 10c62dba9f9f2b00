/* bench_guiding SCENE METHOD (--time S | --spp N) [--ref REF.exr] [-o OUT.exr]
 *               [--photons N] [--caches N] [--cache-res R] [--refine N] [--cache-k K]
 *               [--pdf-floor F] [--alpha-max A] [--cos-min C] [--bilinear | --nearest]
 *               [--train-spp N] [--train-prior W] [--train-all-light] [--no-learn-alpha]
 *               [--keep-training | --discard-training]
 *               [--width W --height H] [--threads T] [--seed S]
 * Renders a built-in scene (or `door`) with iris_render and the guiding
 * provider, prints one line: scene method spp seconds setup relMSE. relMSE is
 * mean over pixels and channels of (x - ref)^2 / (ref^2 + 0.01). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "core/image.h"
#include "core/log.h"
#include "renderer/guiding/guiding.h"
#include "renderer/render.h"
#include "scenes/builtin.h"
#include "validate/metrics.h"

static double rel_mse(const iris_film *film, const iris_image *ref, int *ok);

/* The reference as an R,G,B image: EXR files keep channels sorted by name
 * (B, G, R, ...), and the error loops below walk R, G, B as consecutive channels. */
static bool ref_to_rgb(iris_image *ref, iris_error *err) {
  static const char *const names[3] = {"R", "G", "B"};
  int src[3];
  for (int c = 0; c < 3; ++c)
    if ((src[c] = iris_image_channel(ref, names[c])) < 0) return false;
  iris_image rgb;
  if (iris_image_create(&rgb, ref->width, ref->height, 3, names, err) != IRIS_OK) return false;
  for (size_t i = 0; i < (size_t)ref->width * (size_t)ref->height; ++i)
    for (int c = 0; c < 3; ++c) rgb.data[i * 3 + (size_t)c] = ref->data[i * (size_t)ref->channel_count + (size_t)src[c]];
  iris_image_destroy(ref);
  *ref = rgb;
  return true;
}
static const char *g_errmap = NULL; /* --errmap FILE.png: per-pixel relSE (mean of channels) */

/* CPU seconds of the whole process (all threads): on a shared, loaded machine
 * this measures the work done, where wall-clock time measures the neighbours. */
static double cpu_seconds(void) {
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
         (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
}

/* The guiding provider, timed in CPU seconds. */
static double g_guide_cpu = 0.0;
static iris_status timed_build(const iris_guide_setup *setup, iris_direction_sampler *out,
                               void **state, iris_error *err) {
  double t0 = cpu_seconds();
  iris_status st = iris_guiding_provider.build(setup, out, state, err);
  g_guide_cpu = cpu_seconds() - t0;
  if (st == IRIS_OK && *state) { /* the skip decision's inputs (docs/guiding.md, "--method auto") */
    const iris_guiding_stats *gs = &((const iris_guiding *)*state)->stats;
    printf("decision: %s; pilot %llu paths share %.3f (%.3f s); full %llu paths share %.3f\n",
           gs->skipped ? "skip" : "guide", (unsigned long long)gs->pilot_paths, gs->pilot_share, gs->pilot_seconds,
           (unsigned long long)gs->photon_paths, gs->indirect_share);
  }
  return st;
}
static void timed_destroy(void *state) { iris_guiding_provider.destroy(state); }
static bool timed_decision(const void *state, char *why, size_t size, bool *forced) {
  return iris_guiding_provider.decision(state, why, size, forced);
}
static iris_status timed_build_lights(const iris_guide_setup *setup, void **state, iris_error *err) {
  double t0 = cpu_seconds();
  iris_status st = iris_guiding_provider.build_lights(setup, state, err);
  g_guide_cpu += cpu_seconds() - t0;
  return st;
}
static iris_light_learned timed_light_select(const void *state) { return iris_guiding_provider.light_select(state); }
static const iris_guide_provider timed_provider = {timed_build, timed_destroy, timed_decision, timed_build_lights,
                                                   timed_light_select};

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: bench_guiding SCENE METHOD (--time S | --spp N) [options]\n");
    return 2;
  }
  const char *scene_name = argv[1], *ref_path = NULL, *out_path = NULL;
  iris_render_params p = iris_render_params_default();
  iris_guiding_params gp = iris_guiding_params_default();
  if (!iris_method_parse(argv[2], &p.method)) {
    fprintf(stderr, "unknown method %s\n", argv[2]);
    return 2;
  }
  for (int i = 3; i < argc; ++i) {
    const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : "0";
    if (!strcmp(a, "--time")) p.time_budget = atof(v), ++i;
    else if (!strcmp(a, "--spp")) p.spp = atoi(v), ++i;
    else if (!strcmp(a, "--ref")) ref_path = v, ++i;
    else if (!strcmp(a, "-o")) out_path = v, ++i;
    else if (!strcmp(a, "--photons")) gp.photons = atoll(v), ++i;
    else if (!strcmp(a, "--caches")) gp.caches = atoll(v), ++i;
    else if (!strcmp(a, "--cache-res")) gp.cache_res = atoi(v), ++i;
    else if (!strcmp(a, "--refine")) gp.refine = atoi(v), ++i;
    else if (!strcmp(a, "--cache-k")) gp.cache_k = atoi(v), ++i;
    else if (!strcmp(a, "--pdf-floor")) gp.pdf_floor = (float)atof(v), ++i;
    else if (!strcmp(a, "--alpha-max")) gp.alpha_max = (float)atof(v), ++i;
    else if (!strcmp(a, "--cos-min")) gp.cos_min = (float)atof(v), ++i;
    else if (!strcmp(a, "--errmap")) g_errmap = v, ++i;
    else if (!strcmp(a, "--bilinear")) gp.splat = IRIS_SPLAT_BILINEAR;
    else if (!strcmp(a, "--nearest")) gp.splat = IRIS_SPLAT_NEAREST;
    else if (!strcmp(a, "--no-adjoint-rr")) gp.adjoint_rr = false;
    else if (!strcmp(a, "--photon-lights-area")) gp.photon_lights = IRIS_EMIT_BY_AREA;
    else if (!strcmp(a, "--force")) gp.force = true;
    else if (!strcmp(a, "--pilot")) gp.pilot_paths = atoll(v), ++i; /* 0: decide on the full pass */
    else if (!strcmp(a, "--direct-photons")) gp.direct_photons = atoi(v), ++i;
    else if (!strcmp(a, "--train-spp")) gp.train_spp = atoi(v), ++i;
    else if (!strcmp(a, "--sky-regions")) gp.sky_regions = atoi(v), ++i;
    else if (!strcmp(a, "--sky-probes")) gp.sky_probes = atoi(v), ++i;
    else if (!strcmp(a, "--sky-beta")) gp.sky_beta = (float)atof(v), ++i;
    else if (!strcmp(a, "--train-prior")) gp.train_prior = (float)atof(v), ++i;
    else if (!strcmp(a, "--train-all-light")) gp.train_all_light = true;
    else if (!strcmp(a, "--no-learn-alpha")) gp.learn_alpha = false;
    else if (!strcmp(a, "--keep-training")) p.keep_training = true;
    else if (!strcmp(a, "--discard-training")) p.keep_training = false;
    else if (!strcmp(a, "--width")) p.width = atoi(v), ++i;
    else if (!strcmp(a, "--height")) p.height = atoi(v), ++i;
    else if (!strcmp(a, "--threads")) p.threads = atoi(v), ++i;
    else if (!strcmp(a, "--seed")) p.seed = strtoull(v, NULL, 10), ++i;
    else if (!strcmp(a, "--max-depth")) p.max_depth = atoi(v), ++i;
    else if (!strcmp(a, "--rr-depth")) p.rr_depth = atoi(v), ++i;
    else {
      fprintf(stderr, "unknown option %s\n", a);
      return 2;
    }
  }
  iris_log_set_level(IRIS_LOG_INFO);
  iris_error err;
  iris_error_clear(&err);
  iris_scene *scene = NULL;
  iris_status st;
  st = iris_builtin_create(scene_name, &scene, &err); /* door-shielded is a built-in too */
  if (st != IRIS_OK) {
    char b[1400];
    iris_error_format(&err, b, sizeof b);
    fprintf(stderr, "iris: %s\n", b);
    return 2;
  }
  p.guide = &timed_provider;
  p.guide_options = &gp;
  iris_render_result res;
  double c0 = cpu_seconds();
  st = iris_render(scene, &p, &res, &err);
  double cpu_total = cpu_seconds() - c0;
  if (st != IRIS_OK) {
    char b[1400];
    iris_error_format(&err, b, sizeof b);
    fprintf(stderr, "iris: %s\n", b);
    return 1;
  }
  double rmse = -1.0, rmse_drop = -1.0;
  if (ref_path) {
    iris_image ref;
    if (iris_exr_read(ref_path, &ref, NULL, NULL, &err) == IRIS_OK && ref_to_rgb(&ref, &err)) {
      int ok = 0;
      rmse = rel_mse(&res.film, &ref, &ok);
      if (!ok) rmse = -2.0;
      iris_image img;
      if (ok && iris_film_to_image(&res.film, false, &img, &err) == IRIS_OK) {
        rmse_drop = iris_metric_relmse(&img, iris_image_channel(&img, "R"), &ref,
                                       iris_image_channel(&ref, "R"), IRIS_METRIC_EPS, IRIS_METRIC_DROP);
        iris_image_destroy(&img);
      }
      iris_image_destroy(&ref);
    }
  }
  if (out_path && iris_render_write_exr(&res, out_path, scene_name, false, &err) != IRIS_OK) {
    fprintf(stderr, "cannot write %s\n", out_path);
  }
  /* render_cpu: the passes (total minus guide build; accel/lights set-up is
   * tiny and the same for every method). */
  double samples = (double)res.spp * (double)res.film.width * (double)res.film.height;
  printf("%s %s spp=%d render_s=%.2f setup_s=%.2f guide_cpu=%.3f render_cpu=%.3f "
         "ksamples_per_cpu_s=%.1f rays_per_path=%.2f shadow_per_path=%.2f relMSE=%.6g relMSE_drop=%.6g\n",
         scene_name, argv[2], res.spp, res.seconds, res.setup_seconds, g_guide_cpu,
         cpu_total - g_guide_cpu, samples / (cpu_total - g_guide_cpu) * 1e-3,
         (double)(res.stats.rays + res.stats.shadow_rays) / (double)(res.stats.paths ? res.stats.paths : 1),
         (double)res.stats.shadow_rays / (double)(res.stats.paths ? res.stats.paths : 1), rmse, rmse_drop);
  iris_render_result_destroy(&res);
  iris_scene_destroy(scene);
  return 0;
}

static int compare_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double rel_mse(const iris_film *film, const iris_image *ref, int *ok) {
  iris_image img;
  iris_error err;
  *ok = 0;
  if (iris_film_to_image(film, false, &img, &err) != IRIS_OK) return -1.0;
  if (img.width != ref->width || img.height != ref->height) {
    iris_image_destroy(&img);
    return -1.0;
  }
  int cr = iris_image_channel(ref, "R"), ci = iris_image_channel(&img, "R");
  double sum = 0.0, mean_img = 0.0, mean_ref = 0.0, maxerr = 0.0;
  size_t n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c) {
        double v = img.data[((size_t)y * img.width + x) * img.channel_count + ci + c];
        double r = ref->data[((size_t)y * ref->width + x) * ref->channel_count + cr + c];
        double e = (v - r) * (v - r) / (r * r + 0.01);
        sum += e;
        maxerr = e > maxerr ? e : maxerr;
        mean_img += v;
        mean_ref += r;
        ++n;
      }
  iris_image_destroy(&img);
  /* How much of the relMSE the worst 1% of the pixel channels carry (fireflies). */
  double *e = malloc(sizeof(double) * n);
  if (e) {
    size_t at = 0;
    for (int y = 0; y < ref->height; ++y)
      for (int x = 0; x < ref->width; ++x) {
        iris_vec3 m, var;
        iris_film_pixel(film, x, y, &m, &var);
        float v3[3] = {m.x, m.y, m.z};
        for (int c = 0; c < 3; ++c) {
          double r = ref->data[((size_t)y * ref->width + x) * ref->channel_count + cr + c];
          e[at++] = (v3[c] - r) * (v3[c] - r) / (r * r + 0.01);
        }
      }
    if (g_errmap) {
      static const char *const names[3] = {"R", "G", "B"};
      iris_image em;
      iris_error err;
      if (iris_image_create(&em, ref->width, ref->height, 3, names, &err) == IRIS_OK) {
        for (size_t i = 0; i < n / 3; ++i) {
          float v = (float)((e[3 * i] + e[3 * i + 1] + e[3 * i + 2]) / 3.0);
          em.data[3 * i] = em.data[3 * i + 1] = em.data[3 * i + 2] = v;
        }
        iris_png_write(g_errmap, &em, 0, 0.0f, &err);
        iris_image_destroy(&em);
      }
    }
    qsort(e, n, sizeof(double), compare_double);
    double top = 0.0;
    for (size_t i = n - n / 100; i < n; ++i) top += e[i];
    printf("worst 1%% of pixel channels carry %.1f%% of the relMSE; median relSE %.4g\n",
           sum > 0 ? 100.0 * top / sum : 0.0, e[n / 2]);
    free(e);
  }
  printf("mean image %.6g reference %.6g (ratio %.4f), worst pixel relSE %.4g\n", mean_img / (double)n,
         mean_ref / (double)n, mean_img / mean_ref, maxerr);
  *ok = 1;
  return sum / (double)n;
}
