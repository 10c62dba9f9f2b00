/* Chi-square goodness-of-fit harness (see chi2.h). Follows the structure of
 * pbrt-v4's bsdfs_test.cpp and Mitsuba's chi2.py: equal-solid-angle grid in
 * (cos theta, phi), pdf integrated per cell, low-count cells pooled. */
#include "chi2.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CHI2_PI 3.14159265358979323846
#define CHI2_MIN_EXPECTED 5.0

double chi2_uniform(uint64_t *state) {
  /* splitmix64 */
  uint64_t z = (*state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return (double)(z >> 40) * 0x1p-24;
}

/* ---- grid ---------------------------------------------------------------- */

typedef struct grid {
  int nt, np;
  double zmin, zmax;
} grid;

static grid grid_of(const chi2_domain *d) {
  grid g;
  g.zmin = d->mode == CHI2_HEMISPHERE ? 0.0 : -1.0;
  g.zmax = 1.0;
  g.nt = d->theta_res > 0 ? d->theta_res : (d->mode == CHI2_HEMISPHERE ? 32 : 64);
  g.np = d->phi_res > 0 ? d->phi_res : 64;
  return g;
}

/* Cell index of a direction, -1 when outside the domain or not finite. */
static long grid_cell(const grid *g, const double dir[3]) {
  double x = dir[0], y = dir[1], z = dir[2];
  if (!isfinite(x) || !isfinite(y) || !isfinite(z)) return -1;
  double len = sqrt(x * x + y * y + z * z);
  if (!(fabs(len - 1.0) < 1e-3)) return -1;
  z /= len;
  if (z < g->zmin) return -1;
  double t = (z - g->zmin) / (g->zmax - g->zmin);
  int it = (int)(t * g->nt);
  if (it >= g->nt) it = g->nt - 1;
  if (it < 0) it = 0;
  double phi = atan2(y, x);
  if (phi < 0.0) phi += 2.0 * CHI2_PI;
  int ip = (int)(phi / (2.0 * CHI2_PI) * g->np);
  if (ip >= g->np) ip = g->np - 1;
  if (ip < 0) ip = 0;
  return (long)it * g->np + ip;
}

/* ---- adaptive Gauss-Legendre over a (z, phi) rectangle --------------------- */

/* 3-point Gauss-Legendre per axis: exact for polynomials of degree 5. */
static const double gl_x[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
static const double gl_w[3] = {0.5555555555555556, 0.8888888888888888, 0.5555555555555556};

/* Cells are bounded in z = cos(theta) but integrated in theta (d(omega) =
 * sin(theta) dtheta dphi), which resolves lobes centred on the poles. */
static double rect_gauss(chi2_pdf_fn fn, void *ctx, double t0, double t1, double p0, double p1) {
  double tc = 0.5 * (t0 + t1), th = 0.5 * (t1 - t0);
  double pc = 0.5 * (p0 + p1), ph = 0.5 * (p1 - p0);
  double sum = 0.0;
  for (int i = 0; i < 3; ++i) {
    double t = tc + th * gl_x[i];
    double st = sin(t), z = cos(t);
    for (int j = 0; j < 3; ++j) {
      double phi = pc + ph * gl_x[j];
      double dir[3] = {st * cos(phi), st * sin(phi), z};
      double v = fn(ctx, dir);
      if (isfinite(v)) sum += gl_w[i] * gl_w[j] * v * st;
      else sum = NAN;
    }
  }
  return sum * th * ph;
}

static double rect_adaptive(chi2_pdf_fn fn, void *ctx, double z0, double z1, double p0, double p1,
                            double whole, int depth, int min_depth, int max_depth) {
  double zm = 0.5 * (z0 + z1), pm = 0.5 * (p0 + p1);
  double q[4] = {rect_gauss(fn, ctx, z0, zm, p0, pm), rect_gauss(fn, ctx, zm, z1, p0, pm),
                 rect_gauss(fn, ctx, z0, zm, pm, p1), rect_gauss(fn, ctx, zm, z1, pm, p1)};
  double halves = q[0] + q[1] + q[2] + q[3];
  double area = (z1 - z0) * (p1 - p0);
  if (depth >= max_depth ||
      (depth >= min_depth && fabs(halves - whole) <= 1e-4 * fabs(halves) + 1e-8 * area))
    return halves;
  return rect_adaptive(fn, ctx, z0, zm, p0, pm, q[0], depth + 1, min_depth, max_depth) +
         rect_adaptive(fn, ctx, zm, z1, p0, pm, q[1], depth + 1, min_depth, max_depth) +
         rect_adaptive(fn, ctx, z0, zm, pm, p1, q[2], depth + 1, min_depth, max_depth) +
         rect_adaptive(fn, ctx, zm, z1, pm, p1, q[3], depth + 1, min_depth, max_depth);
}

static double cell_integral(const grid *g, chi2_pdf_fn fn, void *ctx, int it, int ip,
                            int min_depth, int max_depth) {
  double dz = (g->zmax - g->zmin) / g->nt, dp = 2.0 * CHI2_PI / g->np;
  double z0 = g->zmin + it * dz, z1 = (it + 1 == g->nt) ? g->zmax : z0 + dz;
  double p0 = ip * dp, p1 = (ip + 1 == g->np) ? 2.0 * CHI2_PI : p0 + dp;
  double t0 = acos(fmin(1.0, z1)), t1 = acos(fmax(-1.0, z0));
  double whole = rect_gauss(fn, ctx, t0, t1, p0, p1);
  return rect_adaptive(fn, ctx, t0, t1, p0, p1, whole, 0, min_depth, max_depth);
}

/* ---- incomplete gamma (series for x < a + 1, continued fraction otherwise) */

double chi2_gamma_q(double a, double x) {
  if (!(a > 0.0) || !(x >= 0.0)) return NAN;
  if (x == 0.0) return 1.0;
  double lg = lgamma(a);
  if (x < a + 1.0) {
    double ap = a, del = 1.0 / a, sum = del;
    for (int n = 0; n < 100000; ++n) {
      ap += 1.0;
      del *= x / ap;
      sum += del;
      if (fabs(del) < fabs(sum) * 1e-15) break;
    }
    double p = sum * exp(-x + a * log(x) - lg);
    return fmax(0.0, 1.0 - p);
  }
  /* Lentz's method for the continued fraction of Gamma(a, x). */
  double b = x + 1.0 - a, c = 1.0 / 1e-300, d = 1.0 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (fabs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (fabs(c) < 1e-300) c = 1e-300;
    d = 1.0 / d;
    double del = d * c;
    h *= del;
    if (fabs(del - 1.0) < 1e-15) break;
  }
  return exp(-x + a * log(x) - lg) * h;
}

/* ---- the test ------------------------------------------------------------ */

typedef struct bin {
  double expected;
  double observed;
} bin;

static int compare_bins(const void *a, const void *b) {
  double ea = ((const bin *)a)->expected, eb = ((const bin *)b)->expected;
  return (ea > eb) - (ea < eb);
}

chi2_result chi2_run(const chi2_domain *domain, chi2_sample_fn sample, chi2_pdf_fn pdf, void *ctx,
                     size_t n_samples, double alpha_total, int n_tests) {
  chi2_result r;
  memset(&r, 0, sizeof(r));
  grid g = grid_of(domain);
  size_t ncell = (size_t)g.nt * (size_t)g.np;
  bin *bins = calloc(ncell + 1, sizeof(bin));
  if (!bins) {
    snprintf(r.message, sizeof(r.message), "out of memory");
    return r;
  }
  uint64_t state = domain->seed ^ 0x5eed5eed5eedULL;
  for (size_t i = 0; i < n_samples; ++i) {
    double u[3] = {chi2_uniform(&state), chi2_uniform(&state), chi2_uniform(&state)};
    double dir[3] = {0.0, 0.0, 0.0};
    long c = sample(ctx, u, dir) ? grid_cell(&g, dir) : -1;
    if (c < 0) r.lost++;
    else bins[c].observed += 1.0;
  }
  /* Expected counts. Cells whose plain quadrature disagrees badly with what
   * was observed are integrated again with forced refinement, so a lobe
   * narrower than the quadrature points is not mistaken for a sampler bug. */
  double total = 0.0;
  for (int it = 0; it < g.nt; ++it) {
    for (int ip = 0; ip < g.np; ++ip) {
      bin *b = &bins[(size_t)it * g.np + ip];
      /* Cells holding a large share of the samples hold (part of) a narrow
       * lobe: refine them before trusting the error estimate. */
      double share = b->observed / (double)n_samples;
      double e = cell_integral(&g, pdf, ctx, it, ip, share > 0.02 ? 6 : (share > 0.002 ? 4 : 1), 9);
      double ne = e * (double)n_samples;
      static const int min_d[2] = {5, 7}, max_d[2] = {9, 11};
      for (int k = 0; k < 2 && (fabs(b->observed - ne) > 4.0 * sqrt(ne) + 4.0 ||
                                  (ne == 0.0 && b->observed > 0.0)); ++k) {
        e = cell_integral(&g, pdf, ctx, it, ip, min_d[k], max_d[k]);
        ne = e * (double)n_samples;
      }
      if (!isfinite(e) || e < 0.0) {
        snprintf(r.message, sizeof(r.message), "pdf is negative or not finite in cell (%d, %d)",
                 it, ip);
        free(bins);
        r.pdf_integral = NAN;
        return r;
      }
      b->expected = e * (double)n_samples;
      total += e;
      if (getenv("CHI2_DEBUG") && fabs(b->observed - b->expected) > atof(getenv("CHI2_DEBUG")) * sqrt(b->expected) + 1.0)
        fprintf(stderr, "chi2: cell (%d, %d) observed %g expected %g\n", it, ip, b->observed,
                b->expected);
    }
  }
  r.pdf_integral = total;
  /* The lost bin: samples that failed must match the mass the pdf lacks. */
  bins[ncell].observed = (double)r.lost;
  bins[ncell].expected = fmax(0.0, 1.0 - total) * (double)n_samples;
  size_t nb = ncell + 1;

  for (size_t i = 0; i < ncell; ++i) { /* the lost bin is only pooled */
    if (bins[i].expected == 0.0 && bins[i].observed > 0.0) {
      snprintf(r.message, sizeof(r.message),
               "%g samples in cell %zu where the pdf integrates to 0", bins[i].observed, i);
      free(bins);
      return r;
    }
  }
  qsort(bins, nb, sizeof(bin), compare_bins);
  double chsq = 0.0, pool_e = 0.0, pool_o = 0.0;
  int dof = 0;
  for (size_t i = 0; i < nb; ++i) {
    if (bins[i].expected == 0.0) continue;
    if (bins[i].expected < CHI2_MIN_EXPECTED) {
      pool_e += bins[i].expected;
      pool_o += bins[i].observed;
      if (pool_e >= CHI2_MIN_EXPECTED) {
        chsq += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        dof++;
        pool_e = pool_o = 0.0;
      }
      continue;
    }
    double diff = bins[i].observed - bins[i].expected;
    chsq += diff * diff / bins[i].expected;
    dof++;
  }
  if (pool_e > 0.0) {
    /* The remainder of the pool (expected < 5) still counts as one bin. */
    chsq += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
    dof++;
  }
  dof -= 1; /* counts sum to n_samples */
  free(bins);
  r.chi2 = chsq;
  r.dof = dof;
  if (n_tests < 1) n_tests = 1;
  r.significance = 1.0 - pow(1.0 - alpha_total, 1.0 / (double)n_tests);
  if (dof < 1) {
    /* Everything in one bin: the test is only as strong as the lost-mass check. */
    r.p_value = 1.0;
    r.passed = true;
    snprintf(r.message, sizeof(r.message), "single bin (no degrees of freedom)");
    return r;
  }
  r.p_value = chi2_gamma_q(0.5 * dof, 0.5 * chsq);
  r.passed = r.p_value >= r.significance;
  snprintf(r.message, sizeof(r.message), "chi2 %.1f dof %d p %.3g (level %.3g), pdf mass %.5f, lost %zu",
           chsq, dof, r.p_value, r.significance, total, r.lost);
  return r;
}

double chi2_integrate(const chi2_domain *domain, chi2_pdf_fn fn, void *ctx, chi2_sample_fn hint,
                      void *hint_ctx, size_t n_hint) {
  grid g = grid_of(domain);
  size_t ncell = (size_t)g.nt * (size_t)g.np;
  size_t *hits = calloc(ncell, sizeof(size_t));
  if (!hits) return NAN;
  if (hint) {
    uint64_t state = domain->seed ^ 0x1717ULL;
    for (size_t i = 0; i < n_hint; ++i) {
      double u[3] = {chi2_uniform(&state), chi2_uniform(&state), chi2_uniform(&state)};
      double dir[3];
      long c = hint(hint_ctx, u, dir) ? grid_cell(&g, dir) : -1;
      if (c >= 0) hits[c]++;
    }
  }
  /* Cells holding a large share of the hint samples hold a narrow lobe:
   * refine them further before trusting the error estimate. */
  double sum = 0.0;
  for (int it = 0; it < g.nt; ++it) {
    for (int ip = 0; ip < g.np; ++ip) {
      double share = n_hint ? (double)hits[(size_t)it * g.np + ip] / (double)n_hint : 0.0;
      int min_depth = share > 0.02 ? 6 : (share > 0.002 ? 4 : 1);
      sum += cell_integral(&g, fn, ctx, it, ip, min_depth, 8);
    }
  }
  free(hits);
  return sum;
}

/* ---- self test ----------------------------------------------------------- */

typedef struct self_ctx {
  double scale;
  double bias; /* pdf shape error: (1 + bias z) / 4pi */
} self_ctx;

static bool self_sample(void *ctx, const double u[3], double dir[3]) {
  (void)ctx;
  double z = 1.0 - 2.0 * u[0];
  double r = sqrt(fmax(0.0, 1.0 - z * z));
  double phi = 2.0 * CHI2_PI * u[1];
  dir[0] = r * cos(phi);
  dir[1] = r * sin(phi);
  dir[2] = z;
  return true;
}

static double self_pdf(void *ctx, const double dir[3]) {
  const self_ctx *c = ctx;
  return c->scale * (1.0 + c->bias * dir[2]) / (4.0 * CHI2_PI);
}

bool chi2_self_test(char *msg, size_t msg_size) {
  chi2_domain d = {CHI2_SPHERE, 16, 32, 7};
  self_ctx good = {1.0, 0.0}, scaled = {1.1, 0.0}, shape = {1.0, 0.1};
  chi2_result a = chi2_run(&d, self_sample, self_pdf, &good, 200000, 0.01, 3);
  chi2_result b = chi2_run(&d, self_sample, self_pdf, &scaled, 200000, 0.01, 3);
  chi2_result c = chi2_run(&d, self_sample, self_pdf, &shape, 200000, 0.01, 3);
  bool ok = a.passed && !b.passed && !c.passed && fabs(a.pdf_integral - 1.0) < 1e-6;
  snprintf(msg, msg_size, "correct: %s (%s); pdf x1.1: %s (%s); shape 1+0.1z: %s (%s)",
           a.passed ? "pass" : "FAIL", a.message, b.passed ? "PASS" : "fail", b.message,
           c.passed ? "PASS" : "fail", c.message);
  return ok;
}

double chi2_discrete(const double *pmf, const size_t *hits, size_t n, size_t n_samples, size_t got, double *chi_out,
                     int *dof_out) {
  double sum = 0.0;
  for (size_t i = 0; i < n; i++) sum += pmf[i];
  double chi = 0.0, pool_e = 0.0, pool_o = 0.0;
  int cells = 0;
  double e_none = (1.0 - fmin(sum, 1.0)) * (double)n_samples, o_none = (double)(n_samples - got);
  if (e_none >= 5.0) {
    chi += (o_none - e_none) * (o_none - e_none) / e_none;
    cells++;
  } else {
    pool_e += e_none;
    pool_o += o_none;
  }
  for (size_t i = 0; i < n; i++) {
    double e = pmf[i] * (double)n_samples;
    if (e < 5.0) {
      pool_e += e;
      pool_o += (double)hits[i];
      continue;
    }
    chi += ((double)hits[i] - e) * ((double)hits[i] - e) / e;
    cells++;
  }
  if (pool_e > 0.0) {
    chi += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
    cells++;
  } else if (pool_o > 0.0) {
    chi = INFINITY;
  }
  int dof = cells - 1;
  *chi_out = chi;
  *dof_out = dof;
  return dof > 0 ? chi2_gamma_q(0.5 * dof, 0.5 * chi) : (chi == 0.0 || cells == 1 ? 1.0 : 0.0);
}
