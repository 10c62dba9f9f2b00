/* bench/export/gltf_residual: how far Cycles' rendering of an exported glTF
 * metallic-roughness material is from iris's, per material class, for the two
 * Blender mappings of exporters/blender_prelude.c: the Appendix B node tree (default)
 * and the Principled BSDF (params.gltf_principled). One image holds ten unit
 * spheres with white base colour under a uniform white sky (radiance 1) seen
 * by a distant camera (yfov 3 degrees, nearly orthographic): the disc mean is a
 * white furnace (albedo averaged over the projected sphere) and the rings of
 * equal view angle theta (sin theta = r) are a grazing-angle sweep. Pixels
 * that the sphere's silhouette cuts are left out (r < 0.985).
 * Prints a Markdown table of iris / Cycles ratios (docs/export.md).
 * Usage: gltf_residual OUT_DIR [SPP] [PIXELS_PER_SPHERE] [THREADS] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/fileio.h"
#include "core/image.h"
#include "core/log.h"
#include "exporters/blender.h"
#include "renderer/film.h"
#include "renderer/render.h"
#include "scenes/builtin.h"
#include "validate/blender_run.h"

static int fail(const iris_error *err) {
  char buf[1400];
  iris_error_format(err, buf, sizeof buf);
  fprintf(stderr, "gltf_residual: %s\n", buf);
  return 1;
}

#define COLS 5
#define ROWS 2
#define NRING 5
static const double RING_DEG[NRING + 1] = {0, 30, 60, 70, 75, 80};

typedef struct mat_case {
  const char *name;
  float metallic, roughness, transmission;
} mat_case;
static const mat_case CASES[COLS * ROWS] = {
    {"dielectric r0.1", 0, 0.1f, 0}, {"dielectric r0.3", 0, 0.3f, 0}, {"dielectric r0.6", 0, 0.6f, 0},
    {"dielectric r1.0", 0, 1.0f, 0}, {"metal r0.1", 1, 0.1f, 0},      {"metal r0.3", 1, 0.3f, 0},
    {"metal r0.6", 1, 0.6f, 0},      {"metal r1.0", 1, 1.0f, 0},      {"metallic 0.5 r0.5", 0.5f, 0.5f, 0},
    {"glass (transmission 1) r0.3", 0, 0.3f, 1},
};

static iris_scene *make_scene(void) {
  iris_scene *s = iris_scene_create();
  for (int i = 0; i < COLS * ROWS; i++) {
    iris_material m = iris_material_default(IRIS_MATERIAL_GLTF);
    m.name = iris_strdup(CASES[i].name);
    m.color[0] = m.color[1] = m.color[2] = 1.0f;
    m.metallic = CASES[i].metallic;
    m.roughness = CASES[i].roughness;
    m.transmission = CASES[i].transmission;
    m.ior = 1.5f;
    int32_t id = iris_scene_add_material(s, &m);
    int col = i % COLS, row = i / COLS;
    iris_vec3 c = iris_v3(2.5f * ((float)col - 2.0f), row == 0 ? 1.25f : -1.25f, 0.0f);
    iris_builtin_add_sphere(s, c, 1.0f, 256, id, CASES[i].name);
  }
  s->has_environment = true;
  s->environment[0] = s->environment[1] = s->environment[2] = 1.0f;
  iris_camera cam;
  memset(&cam, 0, sizeof cam);
  cam.name = iris_strdup("far");
  cam.to_world = iris_mat4_identity();
  cam.to_world.m[2][3] = 100.0f;
  cam.yfov = 2.0f * atanf(2.5f / 100.0f);
  cam.aspect = 2.5f;
  iris_scene_add_camera(s, &cam);
  return s;
}

/* Sums of the R+G+B/3 of each sphere's disc and rings. */
typedef struct stats {
  double disc[COLS * ROWS], ring[COLS * ROWS][NRING];
} stats;

static void measure(const iris_image *img, stats *st) {
  double dsum[COLS * ROWS] = {0}, dn[COLS * ROWS] = {0}, rs[COLS * ROWS][NRING] = {{0}}, rn[COLS * ROWS][NRING] = {{0}};
  int w = img->width, h = img->height;
  double half_h = 2.5, half_w = 2.5 * (double)w / h; /* world extent at z = 0 (distance 100) */
  int cr = iris_image_channel(img, "R"), cg = iris_image_channel(img, "G"), cb = iris_image_channel(img, "B");
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      double wx = ((x + 0.5) / w * 2.0 - 1.0) * half_w, wy = (1.0 - (y + 0.5) / h * 2.0) * half_h;
      int col = (int)floor((wx + 6.25) / 2.5), row = wy > 0 ? 0 : 1;
      if (col < 0 || col >= COLS) continue;
      double dx = wx - 2.5 * (col - 2), dy = wy - (row == 0 ? 1.25 : -1.25), r = sqrt(dx * dx + dy * dy);
      if (r >= 0.985) continue;
      const float *p = img->data + ((size_t)y * (size_t)w + (size_t)x) * (size_t)img->channel_count;
      double v = (p[cr] + p[cg] + p[cb]) / 3.0;
      int k = row * COLS + col;
      dsum[k] += v;
      dn[k] += 1;
      double th = asin(r) * 180.0 / 3.14159265358979323846;
      for (int b = 0; b < NRING; b++)
        if (th >= RING_DEG[b] && th < RING_DEG[b + 1]) {
          rs[k][b] += v;
          rn[k][b] += 1;
        }
    }
  for (int k = 0; k < COLS * ROWS; k++) {
    st->disc[k] = dsum[k] / fmax(dn[k], 1);
    for (int b = 0; b < NRING; b++) st->ring[k][b] = rs[k][b] / fmax(rn[k][b], 1);
  }
}

static int cycles(const iris_scene *s, const char *dir, bool principled, int spp, int w, int h,
                  const char *threads, iris_image *img) {
  char script[1200], exr[1200], log[1200], a_spp[32], a_w[32], a_h[32];
  snprintf(script, sizeof script, "%s/%s.py", dir, principled ? "principled" : "nodes");
  snprintf(exr, sizeof exr, "%s/%s.exr", dir, principled ? "principled" : "nodes");
  snprintf(log, sizeof log, "%s/%s.log", dir, principled ? "principled" : "nodes");
  iris_export_params ep = iris_export_params_default();
  ep.width = w, ep.height = h, ep.spp = spp, ep.gltf_principled = principled;
  iris_error err;
  if (iris_export_blender(s, script, &ep, &err) != IRIS_OK) return fail(&err);
  snprintf(a_spp, sizeof a_spp, "%d", spp);
  snprintf(a_w, sizeof a_w, "%d", w);
  snprintf(a_h, sizeof a_h, "%d", h);
  const char *args[] = {"--output", exr, "--spp", a_spp, "--threads", threads, "--seed", "1",
                        "--width", a_w, "--height", a_h, NULL};
  iris_blender_run_info info;
  if (iris_blender_run(NULL, script, args, log, &info, &err) != IRIS_OK) return fail(&err);
  if (iris_exr_read(exr, img, NULL, NULL, &err) != IRIS_OK) return fail(&err);
  return 0;
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: gltf_residual OUT_DIR [SPP] [PIXELS_PER_SPHERE] [THREADS]\n");
    return 2;
  }
  const char *dir = argv[1];
  int spp = argc > 2 ? atoi(argv[2]) : 256, px = argc > 3 ? atoi(argv[3]) : 128;
  const char *threads = argc > 4 ? argv[4] : "2";
  iris_log_set_level(IRIS_LOG_WARN);
  iris_error err;
  if (iris_mkdir_p(dir, &err) != IRIS_OK) return fail(&err);
  iris_scene *s = make_scene();
  int w = COLS * px, h = ROWS * px;
  iris_render_params rp = iris_render_params_default();
  rp.width = w, rp.height = h, rp.spp = spp, rp.seed = 1, rp.threads = atoi(threads);
  iris_render_result rr;
  if (iris_render(s, &rp, &rr, &err) != IRIS_OK) return fail(&err);
  iris_image ii, in, ip;
  if (iris_film_to_image(&rr.film, false, &ii, &err) != IRIS_OK) return fail(&err);
  iris_render_result_destroy(&rr);
  if (cycles(s, dir, false, spp, w, h, threads, &in) || cycles(s, dir, true, spp, w, h, threads, &ip)) return 1;
  stats si, sn, sp;
  measure(&ii, &si);
  measure(&in, &sn);
  measure(&ip, &sp);
  printf("| material (white base, sky 1) | Cycles mapping | iris albedo (disc) | iris / Cycles: disc |");
  for (int b = 0; b < NRING; b++) printf(" %g-%g deg |", RING_DEG[b], RING_DEG[b + 1]);
  printf("\n|---|---|---|---|");
  for (int b = 0; b < NRING; b++) printf("---|");
  printf("\n");
  for (int k = 0; k < COLS * ROWS; k++)
    for (int v = 0; v < 2; v++) {
      const stats *c = v ? &sp : &sn;
      printf("| %s | %s | %.4f | %.4f |", v ? "" : CASES[k].name, v ? "Principled BSDF" : "node tree",
             si.disc[k], si.disc[k] / c->disc[k]);
      for (int b = 0; b < NRING; b++) printf(" %.4f |", si.ring[k][b] / c->ring[k][b]);
      printf("\n");
    }
  iris_image_destroy(&ii);
  iris_image_destroy(&in);
  iris_image_destroy(&ip);
  iris_scene_destroy(s);
  return 0;
}
