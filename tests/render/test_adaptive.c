/* Adaptive sampling (renderer/adaptive.h, docs/rendering.md "Adaptive sampling").
 *
 * 1. No bias: on the Cornell box rendered with BSDF sampling (the small lamp
 *    is found by chance: heavy-tailed pixels, fireflies) and on env-spheres
 *    (smooth sky gradients), the mean over many seeds of the adaptive images
 *    agrees with a fixed-spp reference per image and per 8x8 block (z-tests on
 *    the seeds' spread, Bonferroni-corrected), deciding from scouts (freeze at
 *    a threshold) and from the higher-ranked neighbours' image samples (relmse
 *    under a budget: a target never reached and a fixed number of rounds).
 *    The same test on the variant that decides from the image's own samples
 *    (as Cycles' rule does) finds its bias with either rule: the test can
 *    fail (and found the bias of a two-colour checkerboard, z = -6.3).
 * 2. Determinism: the same image for 1 and 2 threads, and a window rendered
 *    alone equals the same window of the whole frame (threshold rule); relmse
 *    from the neighbours the same for 1 and 2 threads, with uneven counts and
 *    no scouts.
 * 3. The error estimate is honest: the image's estimated relMSE against its
 *    true relMSE (against a converged reference) at three target errors lies
 *    in [0.7, 1.4] with independent samples on cornell-box and veach-mis
 *    (over 3 seeds, so that one image's own luck does not decide); with Sobol
 *    samples, whose error falls faster than the variance / n the estimate
 *    assumes, it is conservative: true / estimate in [0.3, 1.4]. env-spheres
 *    is where it fails (the sun's caustic under the metal sphere: a
 *    heavy-tailed pixel makes any variance estimate optimistic; measured
 *    1.1-2.6): there the check is only that it stays below 3.5
 *    (docs/rendering.md, "Adaptive sampling").
 * 4. --target-error is reached, or the cap says so.
 * 5. iris merge weights adaptive parts by their per-pixel sample counts. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "film_stats.h"
#include "render_run.h"
#include "renderer/adaptive.h"
#include "renderer/merge.h"
#include "renderer/render.h"
#include "scenes/builtin.h"

/* The fixture's parameters (spp set by the caller), on 2 threads. */
static iris_render_params base(int w, int h, iris_method m, uint64_t seed) {
  iris_render_params p = iris_test_params(w, h, 0, m, seed);
  p.threads = 2;
  return p;
}

/* Mean pixel value per channel of a block of a film. */
static void block_mean(const iris_film *f, int x0, int y0, int x1, int y1, double out[3]) {
  double var[3];
  region(f, x0, y0, x1, y1, out, var);
}

typedef struct unbiased_case {
  const char *scene;
  iris_method method;
  int w, h;
  double threshold;
  int min_spp, cap, ref_spp;
  iris_adaptive_rule rule;
  int rounds; /* relmse: rounds past the first under a target error never reached (the neighbours decide) */
} unbiased_case;

/* Returns the largest |z| over the image and its 8x8 blocks. */
static double seeds_against_reference(const unbiased_case *c, bool on_image, int seeds, double z_max, bool expect_pass) {
  iris_scene *s = NULL;
  iris_error err;
  if (!CHECK(iris_builtin_create(c->scene, &s, &err) == IRIS_OK)) return 0.0;
  iris_render_params rp = base(c->w, c->h, c->method, 7777);
  rp.spp = c->ref_spp;
  iris_render_result ref;
  if (!CHECK(iris_test_render(s, &rp, &ref))) {
    iris_scene_destroy(s);
    return 0.0;
  }
  const int bx = c->w / 8, by = c->h / 8, nb = 1 + bx * by;
  double *sum = calloc((size_t)nb * 3, sizeof *sum), *sum2 = calloc((size_t)nb * 3, sizeof *sum2);
  double spp_mean = 0.0;
  for (int k = 0; k < seeds; k++) {
    iris_render_params p = base(c->w, c->h, c->method, 1000 + (uint64_t)k);
    p.spp = c->cap;
    p.adaptive.rule = c->rule;
    p.adaptive.noise_threshold = c->threshold;
    p.adaptive.min_spp = c->min_spp;
    p.adaptive.decide_on_image = on_image;
    if (c->rounds > 0) {
      p.adaptive.target_error = 1e-12;
      p.adaptive.rounds = c->rounds;
    }
    iris_render_result r;
    if (!CHECK(iris_test_render(s, &p, &r))) break;
    spp_mean += r.adaptive_outcome.spp_mean / seeds;
    for (int b = 0; b < nb; b++) {
      int x0 = 0, y0 = 0, x1 = c->w, y1 = c->h;
      if (b > 0) x0 = ((b - 1) % bx) * 8, y0 = ((b - 1) / bx) * 8, x1 = x0 + 8, y1 = y0 + 8;
      double m[3];
      block_mean(&r.film, x0, y0, x1, y1, m);
      for (int ch = 0; ch < 3; ch++) {
        sum[3 * b + ch] += m[ch];
        sum2[3 * b + ch] += m[ch] * m[ch];
      }
    }
    iris_render_result_destroy(&r);
  }
  double worst = 0.0, image_z = 0.0;
  for (int b = 0; b < nb; b++) {
    int x0 = 0, y0 = 0, x1 = c->w, y1 = c->h;
    if (b > 0) x0 = ((b - 1) % bx) * 8, y0 = ((b - 1) / bx) * 8, x1 = x0 + 8, y1 = y0 + 8;
    double rm[3], rv[3];
    region(&ref.film, x0, y0, x1, y1, rm, rv);
    for (int ch = 0; ch < 3; ch++) {
      double mean = sum[3 * b + ch] / seeds;
      double var = (sum2[3 * b + ch] / seeds - mean * mean) * seeds / (seeds - 1.0) / seeds;
      double sd = sqrt((var > 0 ? var : 0) + rv[ch]);
      double z = sd > 0 ? (mean - rm[ch]) / sd : 0.0;
      if (fabs(z) > worst) worst = fabs(z);
      if (b == 0 && fabs(z) > fabs(image_z)) image_z = z;
      if (expect_pass)
        iris_check_record(fabs(z) <= z_max, __FILE__, __LINE__,
                          "%s %s: %s (%d,%d)-(%d,%d) channel %d: seeds' mean %.5f vs reference %.5f, z = %.2f",
                          c->scene, iris_method_name(c->method), b == 0 ? "image" : "block", x0, y0, x1, y1, ch,
                          mean, rm[ch], z);
    }
  }
  printf("%s %s, %s, %s: %.1f spp mean over %d seeds, image z = %+.2f, worst |z| = %.2f (limit %.2f)\n", c->scene,
         iris_method_name(c->method), iris_adaptive_rule_name(c->rule),
         on_image ? "deciding on the image's own samples" : c->rounds ? "deciding on the neighbours" : "deciding on scouts",
         spp_mean, seeds, image_z, worst, z_max);
  free(sum);
  free(sum2);
  iris_render_result_destroy(&ref);
  iris_scene_destroy(s);
  return worst;
}

/* True relMSE of a film against a reference film (eps IRIS_ADAPTIVE_EPS; the
 * reference's own expected share, from its variance, taken off). */
static double true_relmse(const iris_film *t, const iris_film *r) {
  double s = 0.0;
  int n = t->width * t->height;
  for (int y = 0; y < t->height; y++)
    for (int x = 0; x < t->width; x++) {
      iris_vec3 mt, mr, vr;
      iris_film_pixel(t, x, y, &mt, NULL);
      iris_film_pixel(r, x, y, &mr, &vr);
      float a[3] = {mt.x, mt.y, mt.z}, b[3] = {mr.x, mr.y, mr.z}, v[3] = {vr.x, vr.y, vr.z};
      for (int c = 0; c < 3; c++) s += ((a[c] - b[c]) * (a[c] - b[c]) - v[c]) / (b[c] * b[c] + IRIS_ADAPTIVE_EPS) / 3.0;
    }
  return s / n;
}

/* 3: the estimate against the truth, 4: target reached or capped. */
static void calibration(void) {
  static const struct {
    const char *scene;
    int w, h, ref_spp;
    double targets[3];
  } cases[3] = {{"cornell-box", 32, 32, 8192, {3e-3, 1e-3, 5e-4}},
                {"veach-mis", 36, 24, 8192, {2e-2, 1e-2, 5e-3}},
                {"env-spheres", 36, 24, 8192, {1.5e-3, 1e-3, 5e-4}}};
  for (int c = 0; c < 3; c++) {
    iris_scene *s = NULL;
    iris_error err;
    if (!CHECK(iris_builtin_create(cases[c].scene, &s, &err) == IRIS_OK)) continue;
    iris_render_params rp = base(cases[c].w, cases[c].h, IRIS_METHOD_MIS, 4242);
    rp.spp = cases[c].ref_spp;
    iris_render_result ref;
    if (!CHECK(iris_test_render(s, &rp, &ref))) {
      iris_scene_destroy(s);
      continue;
    }
    for (int t = 0; t < 6; t++) {
      const iris_sampler_kind kind = t < 3 ? IRIS_SAMPLER_INDEPENDENT : IRIS_SAMPLER_SOBOL;
      double est = 0.0, tru = 0.0;
      const int seeds = 3;
      for (int k = 0; k < seeds; k++) {
        iris_render_params p = base(cases[c].w, cases[c].h, IRIS_METHOD_MIS, 50 + (uint64_t)k);
        p.sampler = kind;
        p.spp = 8192;
        p.adaptive.rule = IRIS_ADAPTIVE_RELMSE;
        p.adaptive.target_error = cases[c].targets[t % 3];
        iris_render_result r;
        if (!CHECK(iris_test_render(s, &p, &r))) break;
        CHECK(r.adaptive_outcome.reached_target || r.adaptive_outcome.capped);
        CHECK(!(r.adaptive_outcome.reached_target && r.adaptive_outcome.capped));
        if (r.adaptive_outcome.reached_target) CHECK(r.adaptive_outcome.error_estimate <= cases[c].targets[t % 3]);
        est += r.adaptive_outcome.error_estimate / seeds;
        tru += true_relmse(&r.film, &ref.film) / seeds;
        iris_render_result_destroy(&r);
      }
      double ratio = tru / est;
      const double lo = kind == IRIS_SAMPLER_SOBOL ? 0.3 : 0.7;
      const double hi = c == 2 ? 3.5 : 1.4; /* env-spheres: fireflies (see the top) */
      printf("%s %s: target %.3g: estimated relMSE %.4g, true %.4g, true/estimate %.2f\n", cases[c].scene,
             iris_sampler_kind_name(kind), cases[c].targets[t % 3], est, tru, ratio);
      iris_check_record(ratio >= lo && ratio <= hi, __FILE__, __LINE__,
                        "%s %s target %.3g: true/estimated relMSE %.2f outside [%.1f, %.1f]", cases[c].scene,
                        iris_sampler_kind_name(kind), cases[c].targets[t % 3], ratio, lo, hi);
    }
    iris_render_result_destroy(&ref);
    iris_scene_destroy(s);
  }
}

/* 2: threads and windows. */
static void determinism(void) {
  iris_scene *s = NULL;
  iris_error err;
  if (!CHECK(iris_builtin_create("cornell-box", &s, &err) == IRIS_OK)) return;
  iris_render_result r[3];
  for (int k = 0; k < 3; k++) {
    iris_render_params p = base(40, 32, IRIS_METHOD_MIS, 9);
    p.spp = 1024;
    p.adaptive.rule = IRIS_ADAPTIVE_FREEZE;
    p.adaptive.noise_threshold = 0.02;
    p.threads = k == 1 ? 1 : 2;
    if (k == 2) p.bounds = (iris_pixel_bounds){13, 5, 29, 21};
    if (!CHECK(iris_test_render(s, &p, &r[k]))) {
      iris_scene_destroy(s);
      return;
    }
  }
  const iris_film *a = &r[0].film, *b = &r[1].film, *w = &r[2].film;
  size_t n = (size_t)a->width * (size_t)a->height;
  CHECK(memcmp(a->sum, b->sum, 3 * n * sizeof *a->sum) == 0);
  CHECK(memcmp(a->count, b->count, n * sizeof *a->count) == 0);
  int differ = 0;
  for (int y = 0; y < w->height; y++)
    for (int x = 0; x < w->width; x++) {
      size_t i = (size_t)y * (size_t)w->width + (size_t)x, j = (size_t)(y + 5) * (size_t)a->width + (size_t)(x + 13);
      differ += w->count[i] != a->count[j] || w->sum[3 * i] != a->sum[3 * j];
    }
  iris_check_record(differ == 0, __FILE__, __LINE__, "%d pixels of the window differ from the whole frame's", differ);
  printf("determinism: %.1f spp mean, 1 and 2 threads and a window alike\n", r[0].adaptive_outcome.spp_mean);
  for (int k = 0; k < 3; k++) iris_render_result_destroy(&r[k]);
  /* relmse deciding from the neighbours: the same for 1 and 2 threads, uneven
   * counts, and no scouts */
  for (int k = 0; k < 2; k++) {
    iris_render_params p = base(40, 32, IRIS_METHOD_MIS, 9);
    p.spp = 4096;
    p.adaptive.rule = IRIS_ADAPTIVE_RELMSE;
    p.adaptive.target_error = 1e-12;
    p.adaptive.rounds = 4;
    p.threads = k + 1;
    if (!CHECK(iris_test_render(s, &p, &r[k]))) {
      if (k) iris_render_result_destroy(&r[0]);
      iris_scene_destroy(s);
      return;
    }
  }
  CHECK(memcmp(r[0].film.sum, r[1].film.sum, 3 * n * sizeof *r[0].film.sum) == 0);
  CHECK(memcmp(r[0].film.count, r[1].film.count, n * sizeof *r[0].film.count) == 0);
  const iris_adaptive_outcome *o = &r[0].adaptive_outcome;
  CHECK(o->scout_paths == 0 && o->scout_spp_mean == 0.0);
  CHECK(o->rounds == 5 && o->spp_min < o->spp_max);
  printf("determinism, relmse from the neighbours: %.1f spp mean (%d..%d), 1 and 2 threads alike\n", o->spp_mean,
         o->spp_min, o->spp_max);
  for (int k = 0; k < 2; k++) iris_render_result_destroy(&r[k]);
  iris_scene_destroy(s);
}

/* 5: two adaptive parts (sample offsets 0 and the cap) merge into the
 * count-weighted mean, with the summed counts in the "spp" channel. */
static void merge_parts(void) {
  iris_scene *s = NULL;
  iris_error err;
  char dir[512], a[600], b[600], out[600];
  if (!CHECK(iris_builtin_create("cornell-box", &s, &err) == IRIS_OK)) return;
  if (!CHECK(iris_test_tmpdir(dir, sizeof dir, "adaptive-merge") == 0)) return;
  snprintf(a, sizeof a, "%s/a.exr", dir);
  snprintf(b, sizeof b, "%s/b.exr", dir);
  snprintf(out, sizeof out, "%s/m.exr", dir);
  iris_render_result r[2];
  bool ok = true;
  for (int k = 0; k < 2 && ok; k++) {
    iris_render_params p = base(16, 16, IRIS_METHOD_MIS, 3);
    p.spp = 256;
    p.sample_offset = (uint64_t)k * 256;
    p.adaptive.rule = IRIS_ADAPTIVE_FREEZE;
    p.adaptive.noise_threshold = 0.03;
    p.adaptive.min_spp = 8;
    ok = CHECK(iris_test_render(s, &p, &r[k])) &&
         CHECK(iris_render_write_exr(&r[k], k ? b : a, "cornell-box", true, &err) == IRIS_OK);
  }
  const char *paths[2] = {a, b};
  iris_image m;
  iris_image_meta *meta = NULL;
  size_t mc = 0;
  if (ok && CHECK(iris_merge_files(paths, 2, out, NULL, &err) == IRIS_OK) &&
      CHECK(iris_exr_read(out, &m, &meta, &mc, &err) == IRIS_OK)) {
    int cs = iris_image_channel(&m, "spp"), cr = iris_image_channel(&m, "R");
    CHECK(cs >= 0 && cr >= 0);
    int bad = 0, spread = 0;
    for (int y = 0; y < 16 && cs >= 0 && cr >= 0; y++)
      for (int x = 0; x < 16; x++) {
        size_t i = (size_t)y * 16 + (size_t)x;
        double n0 = r[0].film.count[i], n1 = r[1].film.count[i];
        spread += n0 != r[0].film.count[0];
        double want = (r[0].film.sum[3 * i] / n0 * n0 + r[1].film.sum[3 * i] / n1 * n1) / (n0 + n1);
        const float *px = m.data + i * (size_t)m.channel_count;
        bad += px[cs] != (float)(n0 + n1) || fabs(px[cr] - want) > 1e-5 * (fabs(want) + 1e-3);
      }
    iris_check_record(bad == 0, __FILE__, __LINE__, "%d merged pixels are not the count-weighted mean", bad);
    iris_check_record(spread > 0, __FILE__, __LINE__, "the parts were not adaptive (all pixels %u samples)",
                      r[0].film.count[0]);
    iris_image_destroy(&m);
    free(meta);
  }
  for (int k = 0; k < 2 && ok; k++) iris_render_result_destroy(&r[k]);
  iris_test_rmtree(dir);
  iris_scene_destroy(s);
}

int main(void) {
  merge_parts();
  determinism();
  calibration();
  static const unbiased_case cases[4] = {
      {"cornell-box", IRIS_METHOD_BSDF, 24, 24, 0.1, 4, 512, 8192, IRIS_ADAPTIVE_FREEZE, 0},
      {"env-spheres", IRIS_METHOD_MIS, 24, 16, 0.02, 8, 256, 4096, IRIS_ADAPTIVE_FREEZE, 0},
      /* relmse under a budget: 16 spp, then 4 rounds of half the samples so
       * far (~81 spp), allotted from the neighbours' image samples */
      {"cornell-box", IRIS_METHOD_BSDF, 24, 24, 0.0, 16, 4096, 8192, IRIS_ADAPTIVE_RELMSE, 4},
      {"env-spheres", IRIS_METHOD_MIS, 24, 16, 0.0, 16, 4096, 4096, IRIS_ADAPTIVE_RELMSE, 4},
  };
  const int seeds = 32;
  int n_tests = 0;
  for (int c = 0; c < 4; c++) n_tests += 3 * (1 + (cases[c].w / 8) * (cases[c].h / 8));
  double z_max = z_for_alpha(1e-3 / n_tests);
  for (int c = 0; c < 4; c++) seeds_against_reference(&cases[c], false, seeds, z_max, true);
  /* the test can fail: deciding on the image's own samples is biased, with
   * either rule */
  for (int c = 0; c < 4; c += 2) {
    double biased = seeds_against_reference(&cases[c], true, seeds, z_max, false);
    iris_check_record(biased > z_max, __FILE__, __LINE__,
                      "%s, deciding on the image's own samples: worst |z| %.2f, not above %.2f (no power)",
                      iris_adaptive_rule_name(cases[c].rule), biased, z_max);
  }
  return iris_check_summary("render.adaptive");
}
