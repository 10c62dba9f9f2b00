/* Cost of iris_polygon_triangulate per corner on polygon families, with and
 * without the work budget; the measurement behind
 * IRIS_TRIANGULATE_STEPS_PER_CORNER (docs/performance.md, "Triangulation").
 * Usage: iris_bench_triangulate [FILE.obj|FILE.ply ...]
 * Synthetic families (simple polygons: convex, star, comb; degenerate: corners
 * drawn from a few points, collinear) are printed first, then for each file
 * the import's triangulation counters (iris_import_stats). Not a test. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/log.h"
#include "importers/import.h"
#include "importers/triangulate.h"

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static double uniform(void) {
  rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
  return (double)(rng >> 11) / 9007199254740992.0;
}

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

enum family { CONVEX, STAR, COMB, REPEATED, COLLINEAR, FAMILY_COUNT };
static const char *family_name[] = {"convex", "star", "comb", "repeated", "collinear"};
static const int family_simple[] = {1, 1, 1, 0, 0};

/* Corner i of the polygon at (x, y, 0) in pos[3 * i]. */
static void make(enum family f, uint32_t n, float *pos) {
  const double pi = 3.14159265358979323846;
  for (uint32_t i = 0; i < n; i++) {
    double x = 0, y = 0;
    switch (f) {
      case CONVEX: x = cos(2 * pi * i / n), y = sin(2 * pi * i / n); break;
      case STAR: {
        const double a = 2 * pi * (i + 0.3 * uniform()) / n, r = 0.2 + uniform();
        x = r * cos(a), y = r * sin(a);
        break;
      }
      case COMB: {
        /* (0,0) -> (T,0) -> zigzag back along the top: teeth up at (j, 2),
         * notches down at (j - 0.5, 1): about n / 2 reflex corners. */
        const uint32_t teeth = (n - 2) / 2;
        if (i == 0) x = 0, y = 0;
        else if (i == 1) x = teeth, y = 0;
        else {
          const uint32_t k = i - 2, j = teeth - k / 2;
          x = (k % 2 == 0) ? j : j - 0.5, y = (k % 2 == 0) ? 2 : 1;
        }
        break;
      }
      case REPEATED: {
        /* Like the fuzz finding: corners drawn from n / 3 points. */
        static double px[1 << 16], py[1 << 16];
        const uint32_t m = n / 3 > 1 ? n / 3 : 1;
        if (i == 0)
          for (uint32_t k = 0; k < m; k++) px[k] = uniform(), py[k] = uniform();
        const uint32_t k = (uint32_t)(uniform() * m);
        x = px[k], y = py[k];
        break;
      }
      case COLLINEAR: x = i, y = (i % 97 == 0) ? 1 : 0; break;
      default: break;
    }
    pos[3 * i] = (float)x, pos[3 * i + 1] = (float)y, pos[3 * i + 2] = 0;
  }
}

/* Sum of |triangle areas| against the polygon's area (1 when the polygon is
 * covered exactly once, as ear clipping of a simple polygon does). */
static double coverage(const float *pos, uint32_t n, const uint32_t *tris) {
  double poly = 0, sum = 0;
  for (uint32_t i = 0; i < n; i++) {
    const float *a = pos + 3 * i, *b = pos + 3 * ((i + 1) % n);
    poly += (double)a[0] * b[1] - (double)b[0] * a[1];
  }
  for (uint32_t t = 0; t < n - 2; t++) {
    const float *a = pos + 3 * tris[3 * t], *b = pos + 3 * tris[3 * t + 1], *c = pos + 3 * tris[3 * t + 2];
    sum += fabs(((double)b[0] - a[0]) * ((double)c[1] - a[1]) - ((double)b[1] - a[1]) * ((double)c[0] - a[0]));
  }
  return sum / fabs(poly);
}

static void run(enum family f, uint32_t n, uint32_t budget, float *pos, uint32_t *corners, uint32_t *tris) {
  const uint64_t saved = rng;
  make(f, n, pos);
  rng = saved;
  for (uint32_t i = 0; i < n; i++) corners[i] = i;
  /* Repeat small polygons so that the CPU time is measurable; each repetition
   * is a file of its own (a fresh triangulator, so a fresh file budget). */
  const int reps = n < 4096 ? (int)(65536 / n) : 1;
  iris_triangulate_stats st = {0, 0, 0, 0};
  double dt = 0;
  for (int r = 0; r < reps; r++) {
    iris_polygon_triangulator *t = iris_polygon_triangulator_create();
    iris_polygon_triangulator_set_budget(t, budget, budget == UINT32_MAX ? UINT32_MAX : IRIS_TRIANGULATE_FILE_STEPS_PER_CORNER);
    const double t0 = now();
    iris_polygon_triangulate(t, pos, corners, n, tris);
    dt += now() - t0;
    const iris_triangulate_stats s = iris_polygon_triangulator_stats(t);
    st.steps += s.steps, st.fallbacks += s.fallbacks;
    iris_polygon_triangulator_destroy(t);
  }
  dt /= reps;
  const double steps = (double)st.steps / reps;
  printf("| %s | %u | %s | %.0f | %.1f | %.1f | %s | %.4f |\n", family_name[f], n,
         budget == UINT32_MAX ? "none" : "default", steps / n, 1e9 * dt / n,
         steps > 0 ? 1e9 * dt / steps : 0.0, st.fallbacks ? "yes" : "no",
         family_simple[f] ? coverage(pos, n, tris) : NAN);
}

int main(int argc, char **argv) {
  iris_log_set_level(IRIS_LOG_QUIET);
  enum { NMAX = 65536 };
  float *pos = malloc(3 * sizeof(float) * NMAX);
  uint32_t *corners = malloc(sizeof(uint32_t) * NMAX), *tris = malloc(3 * sizeof(uint32_t) * NMAX);
  if (!pos || !corners || !tris) return 1;
  printf("budget: %u steps per corner + %u per polygon, %u per corner + %u per file (one polygon here)\n\n",
         IRIS_TRIANGULATE_STEPS_PER_CORNER, IRIS_TRIANGULATE_STEPS_BASE, IRIS_TRIANGULATE_FILE_STEPS_PER_CORNER,
         IRIS_TRIANGULATE_FILE_STEPS_BASE);
  printf("| family | corners | budget | steps/corner | CPU ns/corner | ns/step | fanned | area covered |\n");
  printf("|---|---:|---|---:|---:|---:|---|---:|\n");
  for (int f = 0; f < FAMILY_COUNT; f++)
    for (uint32_t n = 16; n <= NMAX; n *= 4) {
      /* Without a budget the degenerate families are cubic: stop early. */
      if (family_simple[f] ? n <= 16384 : n <= 1024) run((enum family)f, n, UINT32_MAX, pos, corners, tris);
      run((enum family)f, n, IRIS_TRIANGULATE_STEPS_PER_CORNER, pos, corners, tris);
    }
  if (argc > 1) {
    printf("\n| file | polygons | corners | steps/corner | fanned polygons | import CPU s |\n|---|---:|---:|---:|---:|---:|\n");
  }
  for (int a = 1; a < argc; a++) {
    iris_import_stats stats;
    memset(&stats, 0, sizeof stats);
    iris_import_options opts = iris_import_options_default();
    opts.stats = &stats;
    iris_scene *s = NULL;
    iris_error err;
    iris_error_clear(&err);
    const double t0 = now();
    const iris_status st = iris_import_file(argv[a], &opts, &s, &err);
    const double dt = now() - t0;
    if (st != IRIS_OK) {
      fprintf(stderr, "%s: import failed: %s\n", argv[a], err.message);
      continue;
    }
    const char *base = strrchr(argv[a], '/');
    printf("| %s | %llu | %llu | %.1f | %llu | %.3f |\n", base ? base + 1 : argv[a],
           (unsigned long long)stats.polygons, (unsigned long long)stats.polygon_corners,
           stats.polygon_corners ? (double)stats.triangulation_steps / stats.polygon_corners : 0.0,
           (unsigned long long)stats.triangulation_fallbacks, dt);
    iris_scene_destroy(s);
  }
  free(pos), free(corners), free(tris);
  return 0;
}
