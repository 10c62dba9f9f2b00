/* The shared chi-square harness for every direction sampler in iris (BSDFs,
 * lights, guiding caches): histogram of samples over a (cos theta, phi) grid
 * against the pdf integrated over each cell (adaptive Gauss-Legendre),
 * pooling of cells with expected count < 5, p-value from the regularised
 * incomplete gamma function, significance corrected for the number of tests
 * (Sidak). Samplers may fail (mass they lose must be missing from the pdf). */
#ifndef IRIS_TESTS_CHI2_H
#define IRIS_TESTS_CHI2_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum chi2_mode {
  CHI2_SPHERE = 0,    /* cos theta in [-1, 1] */
  CHI2_HEMISPHERE = 1 /* cos theta in [0, 1]; samples below count as outside */
} chi2_mode;

typedef struct chi2_domain {
  chi2_mode mode;
  int theta_res;  /* cells in cos theta (0: 32 for the hemisphere, 64 for the sphere) */
  int phi_res;    /* cells in phi (0: 2 * 32) */
  uint64_t seed;  /* random stream of the samples */
} chi2_domain;

/* Draws one direction (unit, any frame the pdf uses) from three uniform
 * numbers in [0,1) (exactly representable as float). Returns false when the
 * sampler produces nothing (the lost mass). */
typedef bool (*chi2_sample_fn)(void *ctx, const double u[3], double dir[3]);
/* Solid-angle density of the sampler at a unit direction. Also used as the
 * generic integrand of chi2_integrate. */
typedef double (*chi2_pdf_fn)(void *ctx, const double dir[3]);

typedef struct chi2_result {
  bool passed;
  double p_value;
  double significance; /* per-test level after the Sidak correction */
  double chi2;
  int dof;
  double pdf_integral;  /* quadrature of the pdf over the domain */
  size_t lost;          /* samples that failed or fell outside the domain */
  char message[256];    /* why it failed, or a summary */
} chi2_result;

/* Runs the test with n_samples samples; `alpha_total` is the family-wise
 * significance shared by `n_tests` tests (e.g. 0.01 over all tests of a file). */
chi2_result chi2_run(const chi2_domain *domain, chi2_sample_fn sample, chi2_pdf_fn pdf, void *ctx,
                     size_t n_samples, double alpha_total, int n_tests);

/* Integrates fn over the domain's directions by adaptive quadrature. When
 * `hint` is given, n_hint directions drawn from it mark the cells whose
 * quadrature is refined (so narrow lobes are not missed). */
double chi2_integrate(const chi2_domain *domain, chi2_pdf_fn fn, void *ctx, chi2_sample_fn hint,
                      void *hint_ctx, size_t n_hint);

/* Pearson's test of a discrete sampler: hits[i] of n_samples draws chose
 * outcome i (i < n) of probability pmf[i], the other n_samples - got chose
 * nothing (probability 1 - sum pmf); cells of expected count < 5 are pooled.
 * Returns the p-value, with the statistic and degrees of freedom in *chi and
 * *dof (a pooled cell with draws but no probability: chi = INFINITY). */
double chi2_discrete(const double *pmf, const size_t *hits, size_t n, size_t n_samples, size_t got, double *chi,
                     int *dof);

/* Regularised upper incomplete gamma Q(a, x) = Gamma(a, x) / Gamma(a). */
double chi2_gamma_q(double a, double x);

/* Checks the harness itself: a uniform-sphere sampler passes against its own
 * pdf, fails against 1.1 x the pdf and against a slightly wrong shape.
 * Returns true when all three behave; writes a summary into msg. */
bool chi2_self_test(char *msg, size_t msg_size);

/* A small deterministic generator for tests: uniform double in [0,1) with 24 bits. */
double chi2_uniform(uint64_t *state);

#ifdef __cplusplus
}
#endif
#endif
