/* bench_sampler: CPU cost of the samplers' numbers, as the path tracer draws
 * them per bounce (docs/rendering.md, "Dimension layout": three 1D decisions
 * and two 2D pairs), for sobol and independent, single-threaded.
 * Usage: bench_sampler [SAMPLES]   (default 4M samples x 5 bounces)
 * Prints ns per bounce and per decision for each sampler and their ratio. */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "core/rng.h"
#include "renderer/integrator.h"

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double run(iris_sampler_kind k, long samples, float *sink) {
  double t0 = now();
  float acc = 0.0f;
  for (long i = 0; i < samples; i++) {
    iris_sampler s = iris_sampler_start_kind(k, 1, (uint64_t)(i & 4095), (uint64_t)(i >> 12));
    for (int b = 0; b < 5; b++) {
      iris_sampler_set_bounce(&s, b);
      float u0, u1;
      acc += iris_sampler_slot(&s, IRIS_SLOT_LIGHT_CHOICE);
      acc += iris_sampler_slot(&s, IRIS_SLOT_LOBE);
      iris_sampler_slot2(&s, IRIS_SLOT_LIGHT_POS, &u0, &u1);
      acc += u0 + u1;
      iris_sampler_slot2(&s, IRIS_SLOT_DIRECTION, &u0, &u1);
      acc += u0 + u1;
      acc += iris_sampler_slot(&s, IRIS_SLOT_RR);
    }
  }
  *sink += acc;
  return (now() - t0) / ((double)samples * 5.0) * 1e9;
}

int main(int argc, char **argv) {
  long samples = argc > 1 ? atol(argv[1]) : 4000000L;
  if (samples < 1) samples = 1;
  float sink = 0.0f;
  double best[2] = {1e30, 1e30};
  for (int rep = 0; rep < 3; rep++) /* best of three: the least disturbed run */
    for (int k = 0; k < 2; k++) {
      double ns = run((iris_sampler_kind)k, samples, &sink);
      if (ns < best[k]) best[k] = ns;
    }
  printf("sobol:       %.1f ns per bounce (%.1f ns per decision)\n", best[0], best[0] / 5.0);
  printf("independent: %.1f ns per bounce (%.1f ns per decision)\n", best[1], best[1] / 5.0);
  printf("sobol / independent: %.2f (checksum %g)\n", best[0] / best[1], (double)sink);
  return 0;
}
