/* The validation stage (validate/validate.h): scene -> iris renders ->
 * reference (file or Blender) -> metrics -> report. */
#include "validate/validate.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "core/fileio.h"
#include "core/log.h"
#include "exporters/blender.h"
#include "exporters/export.h"
#include "importers/import.h"
#include "renderer/guiding/guiding.h"
#include "renderer/render.h"
#include "scene/material_class.h"
#include "scenes/builtin.h"
#include "validate/blender_run.h"
#include "validate/json_out.h"
#include "validate/report.h"

/* Stored references: size chosen small enough for git (ZIP float EXR, well
 * under 1 MB each) and spp high enough that the reference's own noise of the
 * mean is far below the 1% tolerance (docs/validation.md, "Stored references"). */
typedef struct ref_setting {
  const char *name;
  int width, height, spp;
} ref_setting;
static const ref_setting REF_SETTINGS[] = {
    {"cornell-box", 256, 256, 2048},
    {"veach-mis", 384, 256, 1024},
    {"door", 384, 288, 1024},
};
static const char *const REF_SCENES[] = {"cornell-box", "veach-mis", "door", NULL};

const char *const *iris_validate_reference_scenes(void) { return REF_SCENES; }

bool iris_validate_reference_settings(const char *scene, int *width, int *height, int *spp) {
  for (size_t i = 0; i < sizeof REF_SETTINGS / sizeof REF_SETTINGS[0]; i++)
    if (strcmp(REF_SETTINGS[i].name, scene) == 0) {
      if (width) *width = REF_SETTINGS[i].width;
      if (height) *height = REF_SETTINGS[i].height;
      if (spp) *spp = REF_SETTINGS[i].spp;
      return true;
    }
  return false;
}

iris_validate_params iris_validate_params_default(void) {
  iris_validate_params p;
  memset(&p, 0, sizeof p);
  p.spp = IRIS_VALIDATE_DEFAULT_SPP;
  p.max_depth = -1;
  p.tolerance = IRIS_VALIDATE_DEFAULT_TOLERANCE;
  p.alpha = IRIS_METRIC_ALPHA;
  p.blender_spp = IRIS_VALIDATE_DEFAULT_BLENDER_SPP;
  p.light_sampler = IRIS_LIGHT_SAMPLER_DEFAULT;
  return p;
}

bool iris_world_override_apply(const iris_world_override *w, iris_scene *scene) {
  if (w->map) return iris_scene_set_environment_map(scene, w->map, w->strength, w->rotation);
  if (w->color) iris_scene_set_environment_color(scene, w->color);
  return true;
}

iris_status iris_validate_load_scene(const char *input, const char *camera_name, const char *variant,
                                     iris_scene **out, iris_error *err) {
  *out = NULL;
  if (iris_path_exists(input)) {
    iris_import_options opts = iris_import_options_default();
    opts.camera_name = camera_name;
    opts.variant = variant;
    return iris_import_file(input, &opts, out, err);
  }
  if (iris_builtin_exists(input) && variant)
    return iris_error_set(err, IRIS_ERR_USAGE, input, 0, NULL,
                          "no material variant \"%s\": a built-in scene has no material variants (they come "
                          "from glTF files)", variant);
  if (iris_builtin_exists(input)) return iris_builtin_create(input, out, err);
  return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL,
                        "'%s' is neither a file nor a built-in scene (cornell-box, veach-mis, door, ...)", input);
}

/* ---- reference images ---------------------------------------------------- */

static const char *meta_value(const iris_image_meta *meta, size_t n, const char *key) {
  for (size_t i = 0; i < n; i++)
    if (strcmp(meta[i].key, key) == 0) return meta[i].value;
  return NULL;
}

/* Index of channel `name`, also accepting layer-prefixed names ("x.y.R"). */
static int find_channel(const iris_image *img, const char *name) {
  int c = iris_image_channel(img, name);
  if (c >= 0) return c;
  size_t n = strlen(name);
  for (int i = 0; i < img->channel_count; i++) {
    size_t m = strlen(img->channel_names[i]);
    if (m > n + 1 && img->channel_names[i][m - n - 1] == '.' &&
        strcmp(img->channel_names[i] + m - n, name) == 0 && strncmp(img->channel_names[i], "var.", 4) != 0)
      return i;
  }
  return -1;
}

/* Repacks any EXR layout into R, G, B [, var.R, var.G, var.B] (EXR files list
 * channels alphabetically, so B often comes first). */
static iris_status repack_rgb(const iris_image *in, const char *path, iris_image *out, bool *has_var,
                              iris_error *err) {
  static const char *const names[6] = {"R", "G", "B", "var.R", "var.G", "var.B"};
  int src[6];
  for (int c = 0; c < 3; c++) src[c] = find_channel(in, names[c]);
  if (src[0] < 0 || src[1] < 0 || src[2] < 0)
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL,
                          "the reference has no R, G and B channels");
  for (int c = 3; c < 6; c++) src[c] = iris_image_channel(in, names[c]);
  *has_var = src[3] >= 0 && src[4] >= 0 && src[5] >= 0;
  int nc = *has_var ? 6 : 3;
  iris_status st = iris_image_create(out, in->width, in->height, nc, names, err);
  if (st != IRIS_OK) return st;
  size_t n = (size_t)in->width * (size_t)in->height;
  for (size_t i = 0; i < n; i++)
    for (int c = 0; c < nc; c++)
      out->data[i * (size_t)nc + (size_t)c] = in->data[i * (size_t)in->channel_count + (size_t)src[c]];
  return IRIS_OK;
}

/* spp of a reference: the EXR's iris:spp, else "spp" in the <stem>.json next to it. */
static int reference_spp(const char *path, const iris_image_meta *meta, size_t meta_count,
                         char *desc, size_t desc_size) {
  const char *v = meta_value(meta, meta_count, "iris:spp");
  int spp = v ? atoi(v) : 0;
  const char *renderer = meta_value(meta, meta_count, "iris:renderer");
  char json_path[1400], dir[1024], stem[256];
  iris_path_dir(path, dir, sizeof dir);
  iris_path_stem(path, stem, sizeof stem);
  snprintf(json_path, sizeof json_path, "%s/%s.json", dir, stem);
  char *text = NULL;
  size_t size = 0;
  if (spp <= 0 && iris_file_read(json_path, 1u << 20, &text, &size, NULL) == IRIS_OK) {
    cJSON *o = cJSON_Parse(text);
    const cJSON *s = cJSON_GetObjectItemCaseSensitive(o, "spp");
    if (cJSON_IsNumber(s) && s->valuedouble >= 1) spp = (int)s->valuedouble;
    cJSON_Delete(o);
    free(text);
  }
  char name[64];
  snprintf(name, sizeof name, "%.63s", renderer ? renderer : "unknown renderer");
  if (spp > 0)
    snprintf(desc, desc_size, "%s, %d spp", name, spp);
  else
    snprintf(desc, desc_size, "%s, spp unknown", name);
  return spp;
}

/* Reads, repacks and checks a reference image: it must exist, be readable and
 * hold only finite values. */
static iris_status load_reference(const char *path, iris_image *ref, iris_validate_reference *info,
                                  iris_error *err) {
  iris_image raw;
  iris_image_meta *meta = NULL;
  size_t meta_count = 0;
  memset(&raw, 0, sizeof raw);
  if (!iris_path_exists(path))
    return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "reference image does not exist");
  iris_status st = iris_exr_read(path, &raw, &meta, &meta_count, err);
  if (st != IRIS_OK) return st;
  st = repack_rgb(&raw, path, ref, &info->has_variance, err);
  iris_image_destroy(&raw);
  if (st != IRIS_OK) {
    free(meta);
    return st;
  }
  snprintf(info->path, sizeof info->path, "%s", path);
  info->spp = reference_spp(path, meta, meta_count, info->description, sizeof info->description);
  const char *secs = meta_value(meta, meta_count, "iris:render_seconds");
  info->seconds = secs ? atof(secs) : 0.0;
  free(meta);
  info->width = ref->width;
  info->height = ref->height;
  iris_metric_count_nonfinite(ref, 0, ref->channel_count, &info->nan_count, &info->inf_count);
  if (info->nan_count || info->inf_count) {
    iris_image_destroy(ref);
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL,
                          "the reference holds %llu NaN and %llu Inf values; it cannot be a reference",
                          (unsigned long long)info->nan_count, (unsigned long long)info->inf_count);
  }
  iris_metric_channel_means(ref, 0, info->mean);
  if (info->has_variance) iris_metric_mean_standard_error(ref, 3, info->mean_se);
  return IRIS_OK;
}

/* Cycles in `batches` independent runs (seeds seed*batches + k) of
 * ceil(spp / batches) samples each, in `work_dir`: the mean of the batch
 * images is the reference and, with two or more batches, the variance of that
 * mean is estimated from their spread, sum_k (x_k - mean)^2 / (K (K - 1)),
 * and stored as var.R/G/B. Cycles has no variance pass, and its per-sample
 * variance differs from iris's (it samples lights differently), so it cannot
 * be derived from iris's variance. */
typedef struct cycles_job {
  const iris_scene *scene;
  const char *work_dir;
  const char *camera_name;
  int width, height, max_depth;
  int spp, batches;
  uint64_t seed;
  int threads;
  const char *blender;
  bool quiet;
  const char *import_path;    /* Blender imports this glTF itself (NULL: iris's export) */
  const char *inventory_path; /* with import_path: what the importer created (batch 0) */
} cycles_job;

typedef struct cycles_run {
  int spp;                /* total samples per pixel (batches x per batch) */
  int batches;
  double render_seconds;  /* sum over the batches */
  double wall_seconds;
  iris_blender_run_info first; /* version, command of batch 0 */
} cycles_run;

static iris_status render_cycles(const cycles_job *job, iris_image *out, cycles_run *run,
                                 iris_error *err) {
  memset(run, 0, sizeof *run);
  int batches = job->batches < 1 ? 1 : job->batches;
  if (batches > job->spp) batches = job->spp;
  int per = (job->spp + batches - 1) / batches;
  char script[1200], exr[1200], log[1200];
  snprintf(script, sizeof script, "%s/scene.py", job->work_dir);
  iris_export_params ep = iris_export_params_default();
  ep.camera_name = job->camera_name;
  ep.width = job->width;
  ep.height = job->height;
  ep.spp = per;
  ep.max_depth = job->max_depth;
  ep.seed = job->seed;
  ep.has_seed = true;
  iris_status st = job->import_path
                       ? iris_export_blender_import(job->scene, job->import_path, script, &ep, err)
                       : iris_export_blender(job->scene, script, &ep, err);
  if (st != IRIS_OK) return st;
  int threads = job->threads > 0 ? job->threads : (int)sysconf(_SC_NPROCESSORS_ONLN);
  static const char *const names[6] = {"R", "G", "B", "var.R", "var.G", "var.B"};
  int nc = batches >= 2 ? 6 : 3;
  st = iris_image_create(out, job->width, job->height, nc, names, err);
  if (st != IRIS_OK) return st;
  size_t n = (size_t)job->width * (size_t)job->height;
  /* running sums of x and x^2 in double */
  double *acc = calloc(6 * n, sizeof *acc);
  if (!acc) {
    iris_image_destroy(out);
    return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory");
  }
  for (int k = 0; k < batches && st == IRIS_OK; k++) {
    snprintf(exr, sizeof exr, "%s/batch%02d.exr", job->work_dir, k);
    snprintf(log, sizeof log, "%s/batch%02d.log", job->work_dir, k);
    char a_spp[32], a_threads[32], a_seed[32], a_w[32], a_h[32], a_b[32];
    snprintf(a_spp, sizeof a_spp, "%d", per);
    snprintf(a_threads, sizeof a_threads, "%d", threads);
    snprintf(a_seed, sizeof a_seed, "%llu",
             (unsigned long long)((job->seed * (uint64_t)batches + (uint64_t)k) & 0x7fffffff));
    snprintf(a_w, sizeof a_w, "%d", job->width);
    snprintf(a_h, sizeof a_h, "%d", job->height);
    snprintf(a_b, sizeof a_b, "%d", job->max_depth);
    const char *args[] = {"--output", exr, "--spp", a_spp, "--threads", a_threads, "--seed", a_seed,
                          "--width", a_w, "--height", a_h, "--max-bounces", a_b,
                          k == 0 && job->inventory_path ? "--inventory" : NULL, job->inventory_path, NULL};
    if (!job->quiet)
      iris_infof("cycles: batch %d/%d, %d spp, %dx%d, %d threads", k + 1, batches, per, job->width,
                 job->height, threads);
    iris_blender_run_info info;
    st = iris_blender_run(job->blender, script, args, log, &info, err);
    if (st != IRIS_OK) break;
    if (k == 0) run->first = info;
    run->render_seconds += info.render_seconds;
    run->wall_seconds += info.wall_seconds;
    iris_image img;
    iris_validate_reference ri;
    memset(&ri, 0, sizeof ri);
    st = load_reference(exr, &img, &ri, err);
    if (st != IRIS_OK) break;
    if (img.width != job->width || img.height != job->height) {
      st = iris_error_set(err, IRIS_ERR_INTERNAL, exr, 0, NULL, "Blender wrote %dx%d instead of %dx%d",
                          img.width, img.height, job->width, job->height);
      iris_image_destroy(&img);
      break;
    }
    for (size_t i = 0; i < n; i++)
      for (int c = 0; c < 3; c++) {
        double x = img.data[i * (size_t)img.channel_count + (size_t)c];
        acc[6 * i + (size_t)c] += x;
        acc[6 * i + 3 + (size_t)c] += x * x;
      }
    iris_image_destroy(&img);
  }
  if (st == IRIS_OK) {
    double K = (double)batches;
    for (size_t i = 0; i < n; i++)
      for (int c = 0; c < 3; c++) {
        double m = acc[6 * i + (size_t)c] / K;
        out->data[i * (size_t)nc + (size_t)c] = (float)m;
        if (nc == 6) {
          double ss = acc[6 * i + 3 + (size_t)c] - K * m * m;
          out->data[i * (size_t)nc + 3 + (size_t)c] = (float)(ss > 0.0 ? ss / (K * (K - 1.0)) : 0.0);
        }
      }
    run->spp = per * batches;
    run->batches = batches;
  } else {
    iris_image_destroy(out);
  }
  free(acc);
  return st;
}

static iris_status run_blender_reference(const iris_scene *scene, const iris_validate_params *p,
                                         int width, int height, int max_depth, iris_image *ref,
                                         iris_validate_reference *info, iris_error *err) {
  char dir[900];
  snprintf(dir, sizeof dir, "%.880s/cycles", p->out_dir);
  iris_status st = iris_mkdir_p(dir, err);
  if (st != IRIS_OK) return st;
  char inventory[1000];
  snprintf(inventory, sizeof inventory, "%s/import.json", dir);
  cycles_job job = {scene, dir, p->camera_name, width, height, max_depth, p->blender_spp,
                    IRIS_VALIDATE_BLENDER_BATCHES, p->seed, p->threads, p->blender, p->quiet,
                    p->blender_import, p->blender_import ? inventory : NULL};
  cycles_run run;
  st = render_cycles(&job, ref, &run, err);
  if (st != IRIS_OK) return st;
  snprintf(info->path, sizeof info->path, "%s/scene.py", dir);
  info->width = ref->width;
  info->height = ref->height;
  info->has_variance = ref->channel_count == 6;
  info->spp = run.spp;
  info->seconds = run.render_seconds;
  iris_metric_count_nonfinite(ref, 0, ref->channel_count, &info->nan_count, &info->inf_count);
  iris_metric_channel_means(ref, 0, info->mean);
  if (info->has_variance) iris_metric_mean_standard_error(ref, 3, info->mean_se);
  snprintf(info->description, sizeof info->description,
           "Cycles %s, %d spp in %d batches (rendered here%s)",
           run.first.version[0] ? run.first.version : "?", run.spp, run.batches,
           p->blender_import ? " from Blender's own glTF import" : "");
  return IRIS_OK;
}

/* ---- rendering and comparing ------------------------------------------- */

static void describe_ref_variance(const iris_validate_reference *ref, int spp, iris_ref_variance *rv,
                                  double *test_floor, char *buf, size_t size) {
  *test_floor = 0.0;
  if (ref->has_variance) {
    rv->rv0 = 3;
    rv->scale = 0.0;
    if (ref->spp > 0) {
      *test_floor = (double)ref->spp / (double)spp;
      snprintf(buf, size, "the reference's own var.R/G/B channels; iris's variance at least "
                          "theirs x %d/%d spp", ref->spp, spp);
    } else {
      snprintf(buf, size, "the reference's own var.R/G/B channels");
    }
  } else if (ref->spp > 0) {
    rv->rv0 = -1;
    rv->scale = (double)spp / (double)ref->spp;
    snprintf(buf, size,
             "estimated as iris's variance x %d/%d spp (same per-sample variance assumed)", spp,
             ref->spp);
  } else {
    rv->rv0 = -1;
    rv->scale = 0.0;
    snprintf(buf, size, "unknown spp: the reference is treated as exact (z-tests are stricter)");
  }
}

static iris_status compare_method(const iris_image *img, const iris_image *ref,
                                  const iris_validate_params *p, const iris_validate_reference *rinfo,
                                  iris_validate_method *m, float *zimg, iris_error *err) {
  iris_metric_channel_means(img, 0, m->mean);
  iris_metric_mean_standard_error(img, 3, m->mean_se);
  double ref_sum = rinfo->mean[0] + rinfo->mean[1] + rinfo->mean[2];
  m->energy_passed = true;
  for (int c = 0; c < 3; c++) {
    m->channel_ratio[c] = rinfo->mean[c] > 0 ? m->mean[c] / rinfo->mean[c] : (m->mean[c] > 0 ? INFINITY : 1.0);
    /* first-order error propagation of a ratio of independent means */
    double rt = m->mean[c] > 0 ? m->mean_se[c] / m->mean[c] : 0.0;
    double rr = rinfo->mean[c] > 0 ? rinfo->mean_se[c] / rinfo->mean[c] : 0.0;
    m->ratio_se[c] = isfinite(m->channel_ratio[c]) ? m->channel_ratio[c] * sqrt(rt * rt + rr * rr) : 0.0;
    /* A channel carrying under 0.1% of the energy cannot be held to a relative tolerance. */
    if (rinfo->mean[c] > 1e-3 * ref_sum && !(fabs(m->channel_ratio[c] - 1.0) <= p->tolerance))
      m->energy_passed = false;
  }
  m->energy_ratio = iris_metric_energy_ratio(m->mean, rinfo->mean);
  if (!(fabs(m->energy_ratio - 1.0) <= p->tolerance)) m->energy_passed = false;
  iris_metric_count_nonfinite(img, 0, img->channel_count, &m->nan_count, &m->inf_count);
  m->relmse = iris_metric_relmse(img, 0, ref, 0, IRIS_METRIC_EPS, IRIS_METRIC_DROP);
  m->mape = iris_metric_mape(img, 0, ref, 0, IRIS_METRIC_EPS, IRIS_METRIC_DROP);
  iris_ref_variance rv = {-1, 0.0, false};
  double floor;
  describe_ref_variance(rinfo, m->spp, &rv, &floor, m->ref_variance, sizeof m->ref_variance);
  /* The block test that gates: with correlated (sobol) samples the variance
   * channels over-estimate iris's error, so the tiles' variance comes from
   * the spread of their pixel differences instead (metrics.h). */
  iris_ref_variance brv = rv;
  brv.spread = p->sampler == IRIS_SAMPLER_SOBOL;
  if (brv.spread) {
    size_t len = strlen(m->ref_variance);
    snprintf(m->ref_variance + len, sizeof m->ref_variance - len,
             "; block test: tile variance from the spread of the pixel differences (sobol sampler)");
  }
  iris_status st = iris_metric_blocks_floored(img, 0, 3, ref, 0, brv, floor, IRIS_METRIC_BLOCK, p->alpha,
                                              &m->blocks, err);
  if (st == IRIS_OK)
    st = iris_metric_pixel_ztest_floored(img, 0, 3, ref, 0, rv, floor, p->alpha, zimg, &m->pixels, err);
  if (st != IRIS_OK) return st;
  m->z_passed = m->blocks.passed && (!p->pixel_test_gates || m->pixels.passed);
  /* Through Blender's own importer the materials are Principled BSDFs, not
   * iris's: the per-block z-test would only measure that known difference
   * (docs/validation.md), so it is reported and the energy decides. */
  bool z_gates = !(p->source == IRIS_REFERENCE_BLENDER && p->blender_import);
  m->passed = m->energy_passed && (m->z_passed || !z_gates) && m->nan_count == 0 && m->inf_count == 0;
  return IRIS_OK;
}

static iris_status write_render_pngs(const char *dir, const char *name, const iris_image *img,
                                     const iris_image *ref, const float *zimg, float exposure,
                                     iris_error *err) {
  char file[128], path[1300];
  iris_report_png_name(name, "", file, sizeof file);
  iris_path_join(dir, file, path, sizeof path);
  iris_status st = iris_png_write(path, img, 0, exposure, err);
  if (st != IRIS_OK || !ref) return st;
  size_t n = (size_t)img->width * (size_t)img->height;
  float *diff = malloc(n * sizeof *diff);
  if (!diff) return iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory");
  iris_report_relative_difference(img, ref, diff);
  iris_report_png_name(name, "diff", file, sizeof file);
  iris_path_join(dir, file, path, sizeof path);
  st = iris_report_write_false_colour(path, diff, img->width, img->height, 0.5f, err);
  free(diff);
  if (st != IRIS_OK) return st;
  iris_report_png_name(name, "z", file, sizeof file);
  iris_path_join(dir, file, path, sizeof path);
  return iris_report_write_false_colour(path, zimg, img->width, img->height, 5.0f, err);
}

/* |iris / Cycles - 1| of the white-furnace disc mean per roughness 0.1, 0.3,
 * 0.6, 1.0, measured by bench/export/gltf_residual (docs/export.md, "Measured
 * residual per material class"): dielectrics (metallic < 0.5) and metals. */
static const double FURNACE_RESIDUAL[2][4] = {{0.0004, 0.0037, 0.0145, 0.0129},
                                              {0.0018, 0.0007, 0.0057, 0.0727}};
static const double FURNACE_ROUGHNESS[4] = {0.1, 0.3, 0.6, 1.0};

static double expected_residual(const iris_material *m) {
  const double *t = FURNACE_RESIDUAL[m->metallic >= 0.5f ? 1 : 0];
  double r = m->metallic_roughness_texture >= 0 ? 1.0 : m->roughness; /* textured: the worst case */
  if (r <= FURNACE_ROUGHNESS[0]) return t[0] * r / FURNACE_ROUGHNESS[0];
  for (int k = 1; k < 4; k++)
    if (r <= FURNACE_ROUGHNESS[k]) {
      double f = (r - FURNACE_ROUGHNESS[k - 1]) / (FURNACE_ROUGHNESS[k] - FURNACE_ROUGHNESS[k - 1]);
      return t[k - 1] + f * (t[k] - t[k - 1]);
    }
  return t[3];
}

/* Whether Cycles renders every material of the exported scene exactly
 * (docs/export.md, "glTF materials"): rough gltf lobes are approximate. */
static void describe_export_exactness(const iris_scene *scene, iris_validate_result *res) {
  int rough = 0;
  double worst = 0.0;
  char names[200] = "";
  size_t len = 0;
  for (size_t i = 0; i < scene->material_count; i++) {
    const iris_material *m = &scene->materials[i];
    if (m->type != IRIS_MATERIAL_GLTF || iris_material_gltf_smooth(m)) continue;
    if (iris_material_gltf_class(m) == IRIS_GLTF_LAMBERT) continue; /* exact: diffuse weight 1, no lobe */
    worst = fmax(worst, expected_residual(m));
    if (rough++ < 4 && len < sizeof names)
      len += (size_t)snprintf(names + len, sizeof names - len, "%s'%s' (%s)", rough > 1 ? ", " : "",
                              m->name ? m->name : "", iris_gltf_class_name(iris_material_gltf_class(m)));
  }
  res->export_exact = rough == 0;
  res->export_residual = worst;
  if (res->export_exact)
    snprintf(res->export_note, sizeof res->export_note, "every material is exact in Cycles");
  else
    snprintf(res->export_note, sizeof res->export_note,
             "%d rough glTF material(s) %s%s are approximate in Cycles (Fresnel at N.V, separable G): "
             "white-furnace residual up to %.2f%% (docs/export.md), more at grazing angles",
             rough, names, rough > 4 ? ", ..." : "", 100.0 * worst);
}

/* DIR/importers.txt: one line per disagreement of iris's and Blender's glTF import. */
static iris_status write_import_notes(const char *dir, const iris_validate_result *res, iris_error *err) {
  char path[1300];
  iris_path_join(dir, "importers.txt", path, sizeof path);
  iris_atomic_file af;
  iris_status st = iris_atomic_open(&af, path, err);
  if (st != IRIS_OK) return st;
  const iris_import_diff *d = &res->import_diff;
  fprintf(af.fp, "# iris's glTF import vs Blender's of %s: %d note(s)%s\n", res->import_file, d->total,
          d->geometry_differs ? ", GEOMETRY DIFFERS" : "");
  for (int i = 0; i < d->note_count; i++) fprintf(af.fp, "%s: %s\n", d->notes[i].topic, d->notes[i].text);
  if (d->total > d->note_count) fprintf(af.fp, "... %d more\n", d->total - d->note_count);
  return iris_atomic_commit(&af, err);
}

iris_status iris_validate_run(const iris_validate_params *params, iris_validate_result *res,
                              iris_error *err) {
  iris_validate_params p = *params;
  memset(res, 0, sizeof *res);
  if (p.method_count <= 0) { /* the scene's method, else auto */
    p.methods[0] = IRIS_METHOD_COUNT;
    p.method_count = 1;
  }
  if (p.spp <= 0) p.spp = IRIS_VALIDATE_DEFAULT_SPP;
  if (p.blender_spp <= 0) p.blender_spp = IRIS_VALIDATE_DEFAULT_BLENDER_SPP;
  if (!p.out_dir) return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "no output folder");
  if (p.source == IRIS_REFERENCE_FILE && !p.reference_path)
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL, "no reference image");

  iris_image ref;
  memset(&ref, 0, sizeof ref);
  iris_status st = IRIS_OK;
  /* A given reference is read (and checked) before any rendering. */
  if (p.source == IRIS_REFERENCE_FILE) {
    st = load_reference(p.reference_path, &ref, &res->reference, err);
    if (st != IRIS_OK) return st;
    if ((p.width > 0 && p.width != ref.width) || (p.height > 0 && p.height != ref.height)) {
      iris_error_set(err, IRIS_ERR_INVALID, p.reference_path, 0, NULL,
                     "image sizes differ: %dx%d requested against a %dx%d reference",
                     p.width > 0 ? p.width : ref.width, p.height > 0 ? p.height : ref.height,
                     ref.width, ref.height);
      iris_image_destroy(&ref);
      return IRIS_ERR_INVALID;
    }
  }
  iris_scene *scene = NULL;
  st = iris_validate_load_scene(p.input, p.camera_name, p.variant, &scene, err);
  if (st == IRIS_OK && !iris_world_override_apply(&p.world, scene))
    st = iris_error_set(err, IRIS_ERR_NOMEM, p.input, 0, NULL, "out of memory");
  if (st == IRIS_OK) iris_scene_warn_if_lightless(scene, p.input);
  if (st == IRIS_OK) st = iris_mkdir_p(p.out_dir, err);
  if (st != IRIS_OK) goto done;
  snprintf(res->scene, sizeof res->scene, "%s", p.input);
  res->max_depth = p.max_depth >= 0 ? p.max_depth
                   : scene->render.max_depth >= 0 ? scene->render.max_depth
                                                  : IRIS_DEFAULT_MAX_DEPTH;
  if (p.source == IRIS_REFERENCE_FILE) {
    res->width = ref.width;
    res->height = ref.height;
    /* A reference of the scene at another resolution is fine; one with
     * another aspect ratio is of another framing (or a crop): refused. */
    iris_export_params ep = iris_export_params_default();
    ep.camera_name = p.camera_name;
    iris_export_view view;
    st = iris_export_resolve_view(scene, &ep, p.input, &view, err);
    if (st != IRIS_OK) goto done;
    double skew = fabs((double)ref.width * view.height - (double)ref.height * view.width);
    if (skew > (double)(view.width > view.height ? view.width : view.height)) {
      st = iris_error_set(err, IRIS_ERR_INVALID, p.reference_path, 0, NULL,
                          "image sizes differ: the reference is %dx%d but the camera frames %dx%d "
                          "(another aspect ratio)", ref.width, ref.height, view.width, view.height);
      goto done;
    }
  } else {
    iris_export_params ep = iris_export_params_default();
    ep.camera_name = p.camera_name;
    ep.width = p.width;
    ep.height = p.height;
    iris_export_view view;
    st = iris_export_resolve_view(scene, &ep, p.input, &view, err);
    if (st != IRIS_OK) goto done;
    res->width = view.width;
    res->height = view.height;
    st = run_blender_reference(scene, &p, res->width, res->height, res->max_depth, &ref,
                               &res->reference, err);
    if (st != IRIS_OK) goto done;
    if (ref.width != res->width || ref.height != res->height) {
      st = iris_error_set(err, IRIS_ERR_INVALID, res->reference.path, 0, NULL,
                          "image sizes differ: Blender wrote %dx%d, %dx%d were asked for",
                          ref.width, ref.height, res->width, res->height);
      goto done;
    }
  }
  if (p.source == IRIS_REFERENCE_BLENDER && !p.blender_import) describe_export_exactness(scene, res);
  if (p.source == IRIS_REFERENCE_BLENDER && p.blender_import) {
    char inventory[1000];
    snprintf(inventory, sizeof inventory, "%.880s/cycles/import.json", p.out_dir);
    res->blender_import = true;
    snprintf(res->import_file, sizeof res->import_file, "%s", p.blender_import);
    st = iris_import_compare(scene, inventory, &res->import_diff, err);
    if (st == IRIS_OK) st = write_import_notes(p.out_dir, res, err);
    if (st != IRIS_OK) goto done;
  }
  float exposure = iris_report_exposure(res->reference.mean);
  st = write_render_pngs(p.out_dir, "cycles", &ref, NULL, NULL, exposure, err);
  if (st != IRIS_OK) goto done;

  iris_guiding_params gp = iris_guiding_params_default();
  res->passed = true;
  for (int k = 0; k < p.method_count; k++) {
    iris_validate_method *m = &res->methods[res->method_count];
    iris_render_params rp = iris_render_params_default();
    rp.width = res->width;
    rp.height = res->height;
    rp.spp = p.spp;
    rp.sampler = p.sampler;
    rp.light_sampler = p.light_sampler;
    rp.connect = p.connect;
    rp.light_trace = p.light_trace;
    rp.seed = p.seed;
    rp.threads = p.threads;
    rp.method = p.methods[k];
    rp.max_depth = res->max_depth;
    rp.camera_name = p.camera_name;
    rp.cancel = p.cancel;
    if (iris_method_uses_guiding(rp.method) || rp.method == IRIS_METHOD_AUTO || rp.method == IRIS_METHOD_COUNT ||
        rp.light_sampler == IRIS_LIGHT_SAMPLER_LEARNED) {
      rp.guide = &iris_guiding_provider;
      rp.guide_options = &gp;
    }
    if (!p.quiet) iris_infof("validate: rendering %s with %s, %d spp, %dx%d", p.input,
                             rp.method == IRIS_METHOD_COUNT ? "the default method" : iris_method_name(rp.method),
                             rp.spp, rp.width, rp.height);
    iris_render_result rr;
    st = iris_render(scene, &rp, &rr, err);
    if (st != IRIS_OK) goto done;
    if (rr.interrupted) {
      iris_render_result_destroy(&rr);
      st = iris_error_set(err, IRIS_ERR_INTERRUPTED, NULL, 0, NULL, "interrupted");
      goto done;
    }
    m->method = rr.method_requested;
    m->resolved = rr.method;
    snprintf(m->method_reason, sizeof m->method_reason, "%s", rr.method_reason);
    if (!p.quiet && rr.method_reason[0]) iris_infof("validate: %s", rr.method_reason);
    m->spp = rr.spp;
    m->seconds = rr.seconds + rr.setup_seconds;
    m->dropped_samples = rr.stats.nan_count;
    iris_image img;
    st = iris_film_to_image(&rr.film, true, &img, err);
    if (st == IRIS_OK) {
      char name[64], path[1300];
      snprintf(name, sizeof name, "%s.exr", iris_method_name(m->method));
      iris_path_join(p.out_dir, name, path, sizeof path);
      st = iris_render_write_exr(&rr, path, p.input, true, err);
    }
    iris_render_result_destroy(&rr);
    if (st != IRIS_OK) goto done;
    float *zimg = malloc((size_t)img.width * (size_t)img.height * sizeof *zimg);
    if (!zimg) st = iris_error_set(err, IRIS_ERR_NOMEM, NULL, 0, NULL, "out of memory");
    if (st == IRIS_OK) st = compare_method(&img, &ref, &p, &res->reference, m, zimg, err);
    if (st == IRIS_OK)
      st = write_render_pngs(p.out_dir, iris_method_name(m->method), &img, &ref, zimg, exposure, err);
    free(zimg);
    iris_image_destroy(&img);
    if (st != IRIS_OK) goto done;
    res->method_count++;
    if (!m->passed) res->passed = false;
  }
  /* Importers that disagree on the geometry render different scenes. */
  if (res->blender_import && res->import_diff.geometry_differs) res->passed = false;
  {
    char path[1300];
    iris_path_join(p.out_dir, "summary.json", path, sizeof path);
    st = iris_report_write_summary(path, &p, res, err);
    if (st == IRIS_OK) st = iris_report_write_html(p.out_dir, &p, res, err);
  }
done:
  iris_scene_destroy(scene);
  iris_image_destroy(&ref);
  return st;
}

/* ---- stored references ------------------------------------------------- */

static void remove_work_dir(const char *dir, int batches) {
  char path[1300];
  static const char *const files[] = {"scene.py", "scene.meshes.bin", NULL};
  for (int i = 0; files[i]; i++) {
    iris_path_join(dir, files[i], path, sizeof path);
    remove(path);
  }
  for (int k = 0; k < batches; k++) {
    snprintf(path, sizeof path, "%s/batch%02d.exr", dir, k);
    remove(path);
    snprintf(path, sizeof path, "%s/batch%02d.log", dir, k);
    remove(path);
  }
  rmdir(dir);
}

iris_status iris_validate_refresh(const iris_refresh_params *params, iris_error *err) {
  int width, height, spp;
  if (!iris_validate_reference_settings(params->scene, &width, &height, &spp))
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL,
                          "'%s' has no stored reference (cornell-box, veach-mis, door)", params->scene);
  if (params->spp > 0) spp = params->spp;
  iris_scene *scene = NULL;
  iris_status st = iris_validate_load_scene(params->scene, NULL, NULL, &scene, err);
  if (st != IRIS_OK) return st;
  st = iris_mkdir_p(params->dir, err);
  if (st != IRIS_OK) {
    iris_scene_destroy(scene);
    return st;
  }
  char tmp[] = "/tmp/iris-refresh-XXXXXX";
  if (!mkdtemp(tmp)) {
    iris_scene_destroy(scene);
    return iris_error_set(err, IRIS_ERR_IO, "/tmp", 0, NULL, "cannot create a temporary folder");
  }
  int max_depth = scene->render.max_depth >= 0 ? scene->render.max_depth : IRIS_DEFAULT_MAX_DEPTH;
  int threads = params->threads > 0 ? params->threads : (int)sysconf(_SC_NPROCESSORS_ONLN);
  cycles_job job = {scene, tmp, NULL, width, height, max_depth, spp, IRIS_VALIDATE_REFRESH_BATCHES,
                    params->seed, threads, params->blender, params->quiet, NULL, NULL};
  if (!params->quiet)
    iris_infof("refresh: %s with Cycles, %d spp in %d batches, %dx%d, %d threads", params->scene,
               spp, IRIS_VALIDATE_REFRESH_BATCHES, width, height, threads);
  iris_image ref;
  memset(&ref, 0, sizeof ref);
  cycles_run run;
  st = render_cycles(&job, &ref, &run, err);
  iris_scene_destroy(scene);
  double mean[3] = {0, 0, 0};
  if (st == IRIS_OK) iris_metric_channel_means(&ref, 0, mean);
  /* Standard error of the image mean from the per-pixel variances (pixels independent). */
  double mean_se[3] = {0, 0, 0};
  if (st == IRIS_OK && ref.channel_count == 6) {
    size_t n = (size_t)ref.width * (size_t)ref.height;
    for (int c = 0; c < 3; c++) {
      double v = 0.0;
      for (size_t i = 0; i < n; i++) v += ref.data[6 * i + 3 + (size_t)c];
      mean_se[c] = sqrt(v) / (double)n;
    }
  }
  char out_exr[1300], out_json[1300], name[300];
  snprintf(name, sizeof name, "%s.exr", params->scene);
  iris_path_join(params->dir, name, out_exr, sizeof out_exr);
  snprintf(name, sizeof name, "%s.json", params->scene);
  iris_path_join(params->dir, name, out_json, sizeof out_json);
  time_t now = time(NULL);
  char date[64];
  strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", gmtime(&now));
  const char *version = run.first.version[0] ? run.first.version : "?";
  if (st == IRIS_OK) {
    iris_image_meta meta[10];
    size_t mc = 0;
#define META(k, ...)                                                   \
  do {                                                                 \
    snprintf(meta[mc].key, sizeof meta[mc].key, "%s", k);              \
    snprintf(meta[mc].value, sizeof meta[mc].value, __VA_ARGS__);      \
    mc++;                                                              \
  } while (0)
    META("iris:scene", "%s", params->scene);
    META("iris:renderer", "Cycles %s", version);
    META("iris:spp", "%d", run.spp);
    META("iris:batches", "%d", run.batches);
    META("iris:seed", "%llu", (unsigned long long)params->seed);
    META("iris:max_bounces", "%d", max_depth);
    META("iris:render_seconds", "%.3f", run.render_seconds);
    META("iris:date", "%s", date);
    META("iris:source", "iris validate --refresh (iris %s)", IRIS_VERSION_STRING);
#undef META
    st = iris_exr_write(out_exr, &ref, meta, mc, err);
  }
  if (st == IRIS_OK) {
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "scene", params->scene);
    char exr_name[300];
    snprintf(exr_name, sizeof exr_name, "%s.exr", params->scene);
    cJSON_AddStringToObject(o, "file", exr_name);
    cJSON_AddStringToObject(o, "channels", "R G B var.R var.G var.B (variance of each pixel's mean, from the batches)");
    cJSON_AddStringToObject(o, "renderer", "Cycles");
    cJSON_AddStringToObject(o, "blender_version", version);
    cJSON_AddNumberToObject(o, "width", width);
    cJSON_AddNumberToObject(o, "height", height);
    cJSON_AddNumberToObject(o, "spp", run.spp);
    cJSON_AddNumberToObject(o, "batches", run.batches);
    cJSON_AddNumberToObject(o, "spp_per_batch", run.spp / run.batches);
    cJSON_AddStringToObject(o, "batch_seeds", "seed * batches + k, k = 0 .. batches - 1");
    cJSON_AddNumberToObject(o, "seed", (double)params->seed);
    cJSON_AddNumberToObject(o, "threads", threads);
    cJSON_AddNumberToObject(o, "max_bounces", max_depth);
    cJSON *set = cJSON_AddObjectToObject(o, "settings");
    cJSON_AddStringToObject(set, "device", "CPU");
    cJSON_AddStringToObject(set, "pixel_filter", "BOX (1 pixel)");
    cJSON_AddBoolToObject(set, "adaptive_sampling", false);
    cJSON_AddBoolToObject(set, "denoising", false);
    cJSON_AddNumberToObject(set, "sample_clamp_direct", 0);
    cJSON_AddNumberToObject(set, "sample_clamp_indirect", 0);
    cJSON_AddNumberToObject(set, "light_sampling_threshold", 0);
    cJSON_AddNumberToObject(set, "blur_glossy", 0);
    cJSON_AddBoolToObject(set, "caustics_reflective", true);
    cJSON_AddBoolToObject(set, "caustics_refractive", true);
    cJSON_AddNumberToObject(set, "min_light_bounces", 0);
    cJSON_AddStringToObject(set, "exr", "float32, ZIP (batches combined and written by iris)");
    cJSON_AddNumberToObject(o, "render_seconds", run.render_seconds);
    cJSON_AddNumberToObject(o, "wall_seconds", run.wall_seconds);
    cJSON_AddStringToObject(o, "command_batch0", run.first.command);
    cJSON_AddStringToObject(o, "script", "iris export <scene> --to blender (exporters/blender.c), in a temporary folder");
    cJSON_AddStringToObject(o, "date", date);
    cJSON_AddStringToObject(o, "iris_version", IRIS_VERSION_STRING);
    cJSON *jm = cJSON_AddArrayToObject(o, "mean");
    cJSON *js = cJSON_AddArrayToObject(o, "mean_standard_error");
    for (int c = 0; c < 3; c++) {
      cJSON_AddItemToArray(jm, cJSON_CreateNumber(mean[c]));
      cJSON_AddItemToArray(js, cJSON_CreateNumber(mean_se[c]));
    }
    st = iris_json_write_file(o, out_json, err);
    if (st != IRIS_OK) remove(out_exr);
  }
  iris_image_destroy(&ref);
  if (st == IRIS_OK && !params->quiet)
    iris_infof("refresh: wrote %s (%.1f s in Cycles %s; mean %.5g %.5g %.5g +- %.2g %.2g %.2g)", out_exr,
               run.render_seconds, version, mean[0], mean[1], mean[2], mean_se[0], mean_se[1], mean_se[2]);
  if (st != IRIS_ERR_INTERNAL)
    remove_work_dir(tmp, IRIS_VALIDATE_REFRESH_BATCHES);
  else
    iris_warnf("refresh: Blender's files are kept in %s", tmp);
  return st;
}
