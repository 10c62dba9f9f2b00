/* stress.suite: every method on every stress scene at a small CI budget
 * (64 x 48, tens of samples per pixel), against the stored 2048-spp mis
 * references in tests/stress/ref (made by STRESS_TEST_REFS=1
 * bench/stress/run_stress.sh; when one is missing the test renders a mis
 * reference at 64x the samples instead). Asserts:
 *  - no NaN/Inf pixel and no sample dropped as NaN/Inf, for every pair;
 *  - stress-closed-box is exactly black for every method;
 *  - unbiasedness: the mean of each channel and of each 16 x 16 region
 *    agrees with the reference (z-tests on the renders' variance of the
 *    mean, Bonferroni over all tests of this file at family-wise 0.001);
 *  - the methods agree with each other: each against mis at the same budget,
 *    same tests.
 * Pairs whose estimator is too under-sampled at this budget for a variance
 * estimate to hold (docs/stability.md) are listed in UNDERSAMPLED with the
 * reason; they keep the NaN/Inf and black checks. Renders are deterministic
 * (fixed seeds), so the outcome does not change from run to run. */
#include <stdlib.h>
#include <string.h>

#include "bench/stress/suite.h"
#include "check.h"
#include "core/log.h"
#include "scenes/stress/stress.h"

#define W 64
#define H 48
#define REGION 16
#define ALPHA 1e-3

typedef struct budget {
  const char *scene;
  int spp[IRIS_METHOD_AUTO]; /* bsdf, nee, mis, guided, guided-nee (auto is one of mis and
                                guided-nee: guiding.auto) */
} budget;

static const budget BUDGETS[] = {
    /* guided 64: since the caches join the slit into one portal (docs/guiding.md, "Portals"),
     * the 32-spp guided image of this seed had 2 regions at |z| 5.2 (limit 4.95) that 64, 128,
     * 256 and 4096 spp bring to 2.2, 1.9, 3.1 and 1.7 (energy 0.95-1.01 of the reference): the
     * portal's paths through the slit to the light are rare and heavy at 32 spp */
    {"stress-gap", {64, 64, 64, 64, 32}},
    {"stress-veach-lights", {64, 64, 64, 16, 16}},
    {"stress-caustic", {64, 64, 64, 32, 32}},
    {"stress-thin-walls", {64, 64, 64, 32, 32}},
    {"stress-small-dim", {64, 64, 64, 32, 32}},
    {"stress-closed-box", {16, 16, 16, 8, 8}},
    {"stress-firefly", {64, 64, 64, 32, 32}},
    {"stress-glossy-room", {64, 256, 64, 32, 32}}, /* nee: the light in 0.3-rough walls */
};

/* Pairs that are unbiased but too under-sampled at the CI budget for the
 * z-tests to mean anything (the rare samples that carry the answer are not
 * drawn, so the sample variance is far too small); docs/stability.md shows
 * them converging in the full suite. */
typedef struct undersampled {
  const char *scene;
  iris_method method;
  const char *why;
} undersampled;

static const undersampled UNDERSAMPLED[] = {
    {"stress-gap", IRIS_METHOD_BSDF, "BSDF paths from the lit stripe must go back through the slit to hit the light"},
    {"stress-caustic", IRIS_METHOD_BSDF, "the caustic and the direct light come only from paths that hit a 10 cm light"},
    {"stress-caustic", IRIS_METHOD_GUIDED, "no light sampling: as bsdf"},
    {"stress-firefly", IRIS_METHOD_BSDF, "a 3 mm light is hit by about 1 path in 10^5"},
    /* Measured with bench/stress/seed_spread.sh (docs/stability.md, "The CI test"): single
     * 64-spp images of these are bimodal (the rare paths are in them or not),
     * while their mean over 30-40 seeds matches the reference. */
    {"stress-firefly", IRIS_METHOD_NEE, "the diffuse-glossy-light paths to the 3 mm light carry ~45% of "
     "the energy and appear about once per 64-spp image: images are ~0.49 or ~1.42 against 0.89"},
    {"stress-firefly", IRIS_METHOD_MIS, "as nee: the rare glossy-to-light paths"},
    {"stress-firefly", IRIS_METHOD_GUIDED_NEE, "as nee: the rare glossy-to-light paths"},
    {"stress-caustic", IRIS_METHOD_NEE, "the caustic under the glass comes only from paths that hit the "
     "10 cm light: most 64-spp images miss its brightest part (0.351 or 0.375 against 0.361)"},
    {"stress-caustic", IRIS_METHOD_MIS, "as nee: the caustic"},
    {"stress-caustic", IRIS_METHOD_GUIDED_NEE, "as nee: the caustic"},
    {"stress-firefly", IRIS_METHOD_GUIDED, "no light sampling: as bsdf"},
    {"stress-veach-lights", IRIS_METHOD_BSDF, "the 3 cm light seen in the rough plates"},
    {"stress-veach-lights", IRIS_METHOD_GUIDED, "no light sampling: as bsdf"},
    {"stress-veach-lights", IRIS_METHOD_NEE,
     "light samples land in the alpha-0.001 plate's lobe about once in 10^5 (the full suite: "
     "still too dark at 1875 spp, only in those regions)"},
};

static const char *undersampled_why(const char *scene, iris_method m) {
  for (size_t i = 0; i < sizeof UNDERSAMPLED / sizeof UNDERSAMPLED[0]; i++)
    if (strcmp(UNDERSAMPLED[i].scene, scene) == 0 && UNDERSAMPLED[i].method == m) return UNDERSAMPLED[i].why;
  return NULL;
}

static bool render(const iris_scene *s, iris_method m, int spp, uint64_t seed, iris_stress_render_out *out) {
  iris_stress_params p = iris_stress_params_default();
  p.width = W;
  p.height = H;
  p.spp = spp;
  p.seed = seed;
  p.guide_photons = 100000; /* the CI budget; the full suite lets the guide choose */
  iris_error err;
  iris_error_clear(&err);
  iris_status st = iris_stress_render(s, m, &p, out, &err);
  CHECK_OK(st, &err);
  return st == IRIS_OK;
}

static void check_gate(const char *scene, iris_method m, const char *against,
                       const iris_stress_compare *c, double alpha) {
  bool ok = iris_stress_unbiased(c, alpha);
  iris_check_record(ok, __FILE__, __LINE__,
                    "%s %s vs %s: energy %.5g vs %.5g (z %+.2f, limit %.2f), regions max |z| %.2f "
                    "(limit %.2f, %llu over, %llu degenerate differing)",
                    scene, iris_method_name(m), against, c->energy_test, c->energy_ref, c->energy_z,
                    iris_stress_energy_zcrit(alpha), c->regions.max_abs_z, c->regions.z_crit,
                    (unsigned long long)c->regions.z_over,
                    (unsigned long long)c->regions.z_degenerate_fail);
}

int main(int argc, char **argv) {
  const char *ref_dir = argc > 1 ? argv[1] : NULL;
  iris_log_set_level(IRIS_LOG_WARN);
  size_t n_scenes;
  const iris_stress_info *scenes = iris_stress_scenes(&n_scenes);
  CHECK_EQ_INT(n_scenes, sizeof BUDGETS / sizeof BUDGETS[0]);
  /* two gate comparisons (vs reference, vs mis) per checked pair */
  int comparisons = 0;
  for (size_t k = 0; k < n_scenes; k++)
    for (int m = 0; m < IRIS_METHOD_AUTO; m++)
      if (!scenes[k].black && !undersampled_why(scenes[k].name, (iris_method)m))
        comparisons += m == IRIS_METHOD_MIS ? 1 : 2;
  const double alpha = ALPHA / comparisons;
  printf("%d comparisons, each at alpha %.3g (energy |z| <= %.2f)\n", comparisons, alpha,
         iris_stress_energy_zcrit(alpha));

  for (size_t k = 0; k < n_scenes; k++) {
    const iris_stress_info *info = &scenes[k];
    const budget *b = &BUDGETS[k];
    CHECK_EQ_STR(b->scene, info->name);
    iris_scene *scene = NULL;
    iris_error err;
    iris_error_clear(&err);
    iris_status st = iris_stress_create(info->name, &scene, &err);
    CHECK_OK(st, &err);
    if (st != IRIS_OK) continue;

    iris_stress_render_out r[IRIS_METHOD_AUTO];
    memset(r, 0, sizeof r);
    bool have[IRIS_METHOD_AUTO] = {false};
    for (int m = 0; m < IRIS_METHOD_AUTO; m++) {
      have[m] = render(scene, (iris_method)m, b->spp[m], 1, &r[m]);
      if (!have[m]) continue;
      uint64_t nan = 0, inf = 0;
      iris_metric_count_nonfinite(&r[m].image, 0, 6, &nan, &inf);
      iris_check_record(nan == 0 && inf == 0 && r[m].dropped == 0, __FILE__, __LINE__,
                        "%s %s: %llu NaN and %llu Inf values, %llu samples dropped as NaN/Inf",
                        info->name, iris_method_name((iris_method)m), (unsigned long long)nan,
                        (unsigned long long)inf, (unsigned long long)r[m].dropped);
      if (info->black) {
        size_t n = (size_t)W * H * 6, lit = 0;
        for (size_t i = 0; i < n; i++) lit += r[m].image.data[i] != 0.0f;
        iris_check_record(lit == 0, __FILE__, __LINE__, "%s %s: %zu values are not exactly 0",
                          info->name, iris_method_name((iris_method)m), lit);
      }
    }
    if (!info->black) {
      /* the reference: stored, or mis at 64x the samples */
      iris_image ref;
      memset(&ref, 0, sizeof ref);
      bool have_ref = false;
      if (ref_dir) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s.exr", ref_dir, info->name);
        int ref_spp = 0;
        have_ref = iris_stress_image_read(path, &ref, &ref_spp, NULL, &err) == IRIS_OK;
        if (have_ref && (ref.width != W || ref.height != H)) {
          printf("%s: %s is %dx%d, not %dx%d; ignored\n", info->name, path, ref.width, ref.height, W, H);
          iris_image_destroy(&ref);
          have_ref = false;
        }
        if (have_ref) printf("%s: stored reference %s (%d spp)\n", info->name, path, ref_spp);
      }
      if (!have_ref) {
        iris_stress_render_out big;
        printf("%s: no stored reference; rendering mis at %d spp\n", info->name, 64 * b->spp[IRIS_METHOD_MIS]);
        if (render(scene, IRIS_METHOD_MIS, 64 * b->spp[IRIS_METHOD_MIS], 99, &big)) {
          ref = big.image;
          have_ref = true;
        }
      }
      for (int m = 0; have_ref && m < IRIS_METHOD_AUTO; m++) {
        if (!have[m]) continue;
        const char *why = undersampled_why(info->name, (iris_method)m);
        iris_stress_compare c;
        st = iris_stress_compare_images(&r[m].image, &ref, false, alpha, REGION, &c, &err);
        CHECK_OK(st, &err);
        printf("  %-20s %-10s %4d spp  relMSE %-9.4g energy %.5g / %.5g  z %+6.2f  regions max |z| %5.2f "
               "(%d low, %d high)%s%s\n",
               info->name, iris_method_name((iris_method)m), r[m].spp, c.relmse, c.energy_test,
               c.energy_ref, c.energy_z, c.regions.max_abs_z, c.regions_low, c.regions_high,
               why ? "  (not gated: " : "",
               why ? "under-sampled)" : "");
        if (st != IRIS_OK || why) continue;
        check_gate(info->name, (iris_method)m, "reference", &c, alpha);
        if (m != IRIS_METHOD_MIS && have[IRIS_METHOD_MIS]) {
          st = iris_stress_compare_images(&r[m].image, &r[IRIS_METHOD_MIS].image, false, alpha,
                                          REGION, &c, &err);
          CHECK_OK(st, &err);
          if (st == IRIS_OK) check_gate(info->name, (iris_method)m, "mis", &c, alpha);
        }
      }
      iris_image_destroy(&ref);
    }
    for (int m = 0; m < IRIS_METHOD_AUTO; m++) iris_stress_render_out_destroy(&r[m]);
    iris_scene_destroy(scene);
  }
  return TEST_SUMMARY();
}
