/* Report outputs of `iris validate` (validate/report.h). */
#include "validate/report.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "core/fileio.h"
#include "validate/json_out.h"
#include "validate/metrics.h"

float iris_report_exposure(const double ref_mean[3]) {
  double e = (ref_mean[0] + ref_mean[1] + ref_mean[2]) / 3.0;
  if (!(e > 0.0)) return 0.0f;
  double ev = log2(0.18 / e);
  return (float)(ev < -10 ? -10 : ev > 10 ? 10 : ev);
}

void iris_report_png_name(const char *method, const char *kind, char *buf, size_t size) {
  if (kind && kind[0])
    snprintf(buf, size, "%s-%s.png", method, kind);
  else
    snprintf(buf, size, "%s.png", method);
}

void iris_report_relative_difference(const iris_image *test, const iris_image *ref, float *out) {
  size_t n = (size_t)ref->width * (size_t)ref->height;
  for (size_t i = 0; i < n; i++) {
    const float *t = test->data + i * (size_t)test->channel_count;
    const float *r = ref->data + i * (size_t)ref->channel_count;
    double et = (double)t[0] + t[1] + t[2], er = (double)r[0] + r[1] + r[2];
    out[i] = (float)((et - er) / (er + 3.0 * IRIS_METRIC_EPS));
  }
}

iris_status iris_report_write_false_colour(const char *path, const float *values, int width,
                                           int height, float range, iris_error *err) {
  static const char *const names[3] = {"R", "G", "B"};
  iris_image img;
  iris_status st = iris_image_create(&img, width, height, 3, names, err);
  if (st != IRIS_OK) return st;
  size_t n = (size_t)width * (size_t)height;
  for (size_t i = 0; i < n; i++) {
    float v = values[i];
    float t = isfinite(v) ? v / range : (v > 0 ? 1.0f : -1.0f);
    if (isnan(v)) t = 0.0f;
    t = t < -1 ? -1 : t > 1 ? 1 : t;
    /* white at 0, towards red (iris brighter) or blue (iris darker); the PNG
     * writer applies the sRGB curve, so hand it linear values */
    float a = fabsf(t);
    float rgb[3];
    if (t >= 0) {
      rgb[0] = 1.0f; rgb[1] = 1.0f - 0.85f * a; rgb[2] = 1.0f - 0.85f * a;
    } else {
      rgb[0] = 1.0f - 0.85f * a; rgb[1] = 1.0f - 0.6f * a; rgb[2] = 1.0f;
    }
    if (isnan(v)) { rgb[0] = 0.0f; rgb[1] = 1.0f; rgb[2] = 0.0f; } /* NaN: green */
    for (int c = 0; c < 3; c++) img.data[3 * i + (size_t)c] = iris_srgb_to_linear(rgb[c]);
  }
  st = iris_png_write(path, &img, 0, 0.0f, err);
  iris_image_destroy(&img);
  return st;
}

/* ---- summary.json ---------------------------------------------------- */

static cJSON *triple(const double v[3]) {
  cJSON *a = cJSON_CreateArray();
  for (int c = 0; c < 3; c++) cJSON_AddItemToArray(a, cJSON_CreateNumber(isfinite(v[c]) ? v[c] : -1));
  return a;
}

iris_status iris_report_write_summary(const char *path, const iris_validate_params *params,
                                      const iris_validate_result *res, iris_error *err) {
  cJSON *o = cJSON_CreateObject();
  cJSON_AddStringToObject(o, "scene", res->scene);
  cJSON_AddNumberToObject(o, "width", res->width);
  cJSON_AddNumberToObject(o, "height", res->height);
  cJSON_AddNumberToObject(o, "max_depth", res->max_depth);
  cJSON_AddNumberToObject(o, "seed", (double)params->seed);
  iris_json_add_number(o, "tolerance", params->tolerance);
  iris_json_add_number(o, "alpha", params->alpha);
  cJSON_AddBoolToObject(o, "pixel_test_gates", params->pixel_test_gates);
  cJSON_AddBoolToObject(o, "passed", res->passed);
  cJSON *r = cJSON_AddObjectToObject(o, "reference");
  cJSON_AddStringToObject(r, "path", res->reference.path);
  cJSON_AddStringToObject(r, "description", res->reference.description);
  cJSON_AddStringToObject(r, "source", params->source == IRIS_REFERENCE_BLENDER ? "blender" : "file");
  cJSON_AddNumberToObject(r, "spp", res->reference.spp);
  cJSON_AddItemToObject(r, "mean", triple(res->reference.mean));
  cJSON_AddItemToObject(r, "mean_standard_error", triple(res->reference.mean_se));
  cJSON_AddNumberToObject(r, "nan_count", (double)res->reference.nan_count);
  cJSON_AddNumberToObject(r, "inf_count", (double)res->reference.inf_count);
  cJSON_AddBoolToObject(r, "has_variance", res->reference.has_variance);
  iris_json_add_number(r, "seconds", res->reference.seconds);
  if (params->source == IRIS_REFERENCE_BLENDER && !res->blender_import) {
    cJSON_AddBoolToObject(r, "export_exact", res->export_exact);
    cJSON_AddStringToObject(r, "export_note", res->export_note);
    iris_json_add_number(r, "export_expected_residual", res->export_residual);
  }
  if (res->blender_import) {
    cJSON *bi = cJSON_AddObjectToObject(o, "blender_import");
    const iris_import_diff *d = &res->import_diff;
    cJSON_AddStringToObject(bi, "file", res->import_file);
    cJSON_AddBoolToObject(bi, "geometry_differs", d->geometry_differs);
    cJSON_AddNumberToObject(bi, "iris_triangles", (double)d->iris_triangles);
    cJSON_AddNumberToObject(bi, "blender_triangles", (double)d->blender_triangles);
    cJSON_AddNumberToObject(bi, "note_count", d->total);
    cJSON *notes = cJSON_AddArrayToObject(bi, "notes");
    for (int i = 0; i < d->note_count; i++) {
      cJSON *n = cJSON_CreateObject();
      cJSON_AddStringToObject(n, "topic", d->notes[i].topic);
      cJSON_AddStringToObject(n, "text", d->notes[i].text);
      cJSON_AddItemToArray(notes, n);
    }
  }
  cJSON *ms = cJSON_AddArrayToObject(o, "methods");
  for (int k = 0; k < res->method_count; k++) {
    const iris_validate_method *m = &res->methods[k];
    cJSON *j = cJSON_CreateObject();
    cJSON_AddStringToObject(j, "method", iris_method_name(m->method));
    cJSON_AddStringToObject(j, "resolved", iris_method_name(m->resolved));
    if (m->method_reason[0]) cJSON_AddStringToObject(j, "method_reason", m->method_reason);
    cJSON_AddNumberToObject(j, "spp", m->spp);
    iris_json_add_number(j, "seconds", m->seconds);
    cJSON_AddItemToObject(j, "mean", triple(m->mean));
    cJSON_AddItemToObject(j, "mean_standard_error", triple(m->mean_se));
    cJSON_AddItemToObject(j, "channel_ratio", triple(m->channel_ratio));
    cJSON_AddItemToObject(j, "channel_ratio_standard_error", triple(m->ratio_se));
    iris_json_add_number(j, "energy_ratio", m->energy_ratio);
    cJSON_AddNumberToObject(j, "nan_count", (double)m->nan_count);
    cJSON_AddNumberToObject(j, "inf_count", (double)m->inf_count);
    cJSON_AddNumberToObject(j, "dropped_nonfinite_samples", (double)m->dropped_samples);
    iris_json_add_number(j, "relmse", m->relmse);
    iris_json_add_number(j, "mape", m->mape);
    cJSON_AddStringToObject(j, "reference_variance", m->ref_variance);
    cJSON *b = cJSON_AddObjectToObject(j, "blocks");
    cJSON_AddNumberToObject(b, "block", m->blocks.block);
    cJSON_AddNumberToObject(b, "tiles", (double)m->blocks.tiles_x * m->blocks.tiles_y);
    cJSON_AddNumberToObject(b, "compared", m->blocks.compared);
    iris_json_add_number(b, "max_rel_dev", m->blocks.signed_max_rel_dev);
    cJSON *at = cJSON_AddArrayToObject(b, "max_at_pixel");
    cJSON_AddItemToArray(at, cJSON_CreateNumber(m->blocks.max_tile_x * m->blocks.block));
    cJSON_AddItemToArray(at, cJSON_CreateNumber(m->blocks.max_tile_y * m->blocks.block));
    iris_json_add_number(b, "rms_rel_dev", m->blocks.rms_rel_dev);
    cJSON_AddNumberToObject(b, "z_tests", (double)m->blocks.z_tests);
    iris_json_add_number(b, "max_abs_z", m->blocks.max_abs_z);
    iris_json_add_number(b, "z_crit", m->blocks.z_crit);
    cJSON_AddNumberToObject(b, "z_over", (double)m->blocks.z_over);
    cJSON_AddNumberToObject(b, "zero_variance_mismatches", (double)m->blocks.z_degenerate_fail);
    cJSON_AddBoolToObject(b, "passed", m->blocks.passed);
    cJSON *z = cJSON_AddObjectToObject(j, "pixels");
    cJSON_AddNumberToObject(z, "tests", (double)m->pixels.tests);
    iris_json_add_number(z, "max_abs_z", m->pixels.max_abs_z);
    cJSON *zat = cJSON_AddArrayToObject(z, "max_at");
    cJSON_AddItemToArray(zat, cJSON_CreateNumber(m->pixels.max_x));
    cJSON_AddItemToArray(zat, cJSON_CreateNumber(m->pixels.max_y));
    cJSON_AddItemToArray(zat, cJSON_CreateNumber(m->pixels.max_c));
    iris_json_add_number(z, "z_crit", m->pixels.z_crit);
    cJSON_AddNumberToObject(z, "over_crit", (double)m->pixels.over_crit);
    iris_json_add_number(z, "count_threshold", m->pixels.count_threshold);
    cJSON_AddNumberToObject(z, "over_count", (double)m->pixels.over_count);
    iris_json_add_number(z, "expected_over", m->pixels.expected_over);
    iris_json_add_number(z, "allowed_over", m->pixels.allowed_over);
    cJSON_AddNumberToObject(z, "zero_variance", (double)m->pixels.degenerate);
    cJSON_AddNumberToObject(z, "zero_variance_mismatches", (double)m->pixels.degenerate_fail);
    cJSON_AddBoolToObject(z, "bonferroni_passed", m->pixels.bonferroni_passed);
    cJSON_AddBoolToObject(z, "count_passed", m->pixels.count_passed);
    cJSON_AddBoolToObject(z, "passed", m->pixels.passed);
    cJSON_AddBoolToObject(j, "energy_passed", m->energy_passed);
    cJSON_AddBoolToObject(j, "z_passed", m->z_passed);
    cJSON_AddBoolToObject(j, "passed", m->passed);
    cJSON_AddItemToArray(ms, j);
  }
  return iris_json_write_file(o, path, err);
}

/* ---- report.html ------------------------------------------------------- */

static const char B64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/* Writes the PNG `name` of `dir` as a data URI (falls back to the relative name). */
static void put_image(FILE *fp, const char *dir, const char *name, const char *alt) {
  char path[1300];
  iris_path_join(dir, name, path, sizeof path);
  char *data = NULL;
  size_t size = 0;
  fprintf(fp, "<img alt=\"%s\" title=\"%s\" src=\"", alt, alt);
  if (iris_file_read(path, 256u << 20, &data, &size, NULL) == IRIS_OK) {
    fputs("data:image/png;base64,", fp);
    const unsigned char *d = (const unsigned char *)data;
    for (size_t i = 0; i < size; i += 3) {
      unsigned v = (unsigned)d[i] << 16 | (i + 1 < size ? (unsigned)d[i + 1] << 8 : 0) |
                   (i + 2 < size ? d[i + 2] : 0);
      fputc(B64[v >> 18 & 63], fp);
      fputc(B64[v >> 12 & 63], fp);
      fputc(i + 1 < size ? B64[v >> 6 & 63] : '=', fp);
      fputc(i + 2 < size ? B64[v & 63] : '=', fp);
    }
    free(data);
  } else {
    fputs(name, fp);
  }
  fputs("\">", fp);
}

static void html_escape(FILE *fp, const char *s) {
  for (; *s; s++) {
    if (*s == '<') fputs("&lt;", fp);
    else if (*s == '>') fputs("&gt;", fp);
    else if (*s == '&') fputs("&amp;", fp);
    else if (*s == '"') fputs("&quot;", fp);
    else fputc(*s, fp);
  }
}

static const char *verdict(bool ok) { return ok ? "<b class=ok>pass</b>" : "<b class=bad>FAIL</b>"; }

iris_status iris_report_write_html(const char *dir, const iris_validate_params *params,
                                   const iris_validate_result *res, iris_error *err) {
  char path[1300];
  iris_path_join(dir, "report.html", path, sizeof path);
  iris_atomic_file f;
  iris_status st = iris_atomic_open(&f, path, err);
  if (st != IRIS_OK) return st;
  FILE *fp = f.fp;
  fprintf(fp, "<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8><title>iris validate: ");
  html_escape(fp, res->scene);
  fprintf(fp, "</title>\n<style>body{font-family:sans-serif;margin:1.5em;max-width:1400px}"
              "table{border-collapse:collapse;margin:0.8em 0}td,th{border:1px solid #bbb;padding:3px 8px;"
              "text-align:right}th{background:#eee}td.l{text-align:left}.ok{color:#080}.bad{color:#c00}"
              "figure{display:inline-block;margin:0 8px 8px 0}figcaption{font-size:90%%}"
              "img{image-rendering:pixelated;border:1px solid #888}</style></head><body>\n");
  fprintf(fp, "<h1>iris validate: ");
  html_escape(fp, res->scene);
  fprintf(fp, " &mdash; %s</h1>\n", verdict(res->passed));
  fprintf(fp, "<p>%dx%d pixels, %d bounces (Cycles' count), energy tolerance %.3g%%, z-test "
              "family-wise &alpha; = %g. Reference: ", res->width, res->height, res->max_depth,
          100.0 * params->tolerance, params->alpha);
  html_escape(fp, res->reference.description);
  fprintf(fp, " (<code>");
  html_escape(fp, res->reference.path);
  fprintf(fp, "</code>), mean RGB %.6g %.6g %.6g, %llu NaN, %llu Inf.</p>\n", res->reference.mean[0],
          res->reference.mean[1], res->reference.mean[2], (unsigned long long)res->reference.nan_count,
          (unsigned long long)res->reference.inf_count);
  if (params->source == IRIS_REFERENCE_BLENDER && !res->blender_import) {
    fprintf(fp, "<p>Materials: ");
    html_escape(fp, res->export_note);
    fprintf(fp, ".</p>\n");
  }
  if (res->blender_import) {
    const iris_import_diff *d = &res->import_diff;
    fprintf(fp, "<h2>iris's glTF import vs Blender's</h2><p>");
    html_escape(fp, res->import_file);
    fprintf(fp, ": %d note(s)%s. Blender's importer renders Principled BSDFs, so the block z-test is "
                "reported, not gating (docs/validation.md).</p>\n<table><tr><th>topic</th><th>note</th></tr>\n",
            d->total, d->geometry_differs ? ", <b>the geometry differs</b> (the run fails)" : "");
    for (int i = 0; i < d->note_count; i++) {
      fprintf(fp, "<tr><td class=l>%s</td><td class=l>", d->notes[i].topic);
      html_escape(fp, d->notes[i].text);
      fprintf(fp, "</td></tr>\n");
    }
    fprintf(fp, "</table>\n");
  }

  fprintf(fp, "<h2>Summary</h2><table><tr><th>method</th><th>spp</th><th>seconds</th>"
              "<th>ratio R</th><th>ratio G</th><th>ratio B</th><th>energy ratio</th><th>energy</th>"
              "<th>relMSE</th><th>MAPE</th><th>max block dev</th><th>block |z| max / crit</th>"
              "<th>pixel |z| max / crit</th><th>|z|&gt;3 count / allowed</th><th>NaN/Inf</th>"
              "<th>z-test</th><th>result</th></tr>\n");
  for (int k = 0; k < res->method_count; k++) {
    const iris_validate_method *m = &res->methods[k];
    fprintf(fp, "<tr><td class=l>%s</td><td>%d</td><td>%.2f</td><td>%.5f&plusmn;%.5f</td><td>%.5f&plusmn;%.5f</td><td>%.5f&plusmn;%.5f</td>"
                "<td>%.5f</td><td>%s</td><td>%.4g</td><td>%.4g</td><td>%+.2f%%</td><td>%.2f / %.2f</td>"
                "<td>%.2f / %.2f</td><td>%llu / %.0f</td><td>%llu</td><td>%s</td><td>%s</td></tr>\n",
            iris_method_name(m->method), m->spp, m->seconds, m->channel_ratio[0], m->ratio_se[0],
            m->channel_ratio[1], m->ratio_se[1], m->channel_ratio[2], m->ratio_se[2], m->energy_ratio, verdict(m->energy_passed), m->relmse, m->mape,
            100.0 * m->blocks.signed_max_rel_dev, m->blocks.max_abs_z, m->blocks.z_crit,
            m->pixels.max_abs_z, m->pixels.z_crit, (unsigned long long)m->pixels.over_count,
            m->pixels.allowed_over, (unsigned long long)(m->nan_count + m->inf_count),
            verdict(m->z_passed), verdict(m->passed));
  }
  fprintf(fp, "</table>\n<p>Energy: per-channel mean of iris over the reference; pass when every "
              "channel and the sum are within the tolerance. Blocks: %dx%d tiles, the largest "
              "relative deviation of tile energy (tiles above %g of the mean tile energy) and a "
              "per-tile, per-channel z-test with Bonferroni correction. Pixels: per-pixel z with "
              "Bonferroni (no |z| above crit) and a count test (number of |z|&gt;3 within its "
              "binomial expectation)%s. Formulas: docs/validation.md.</p>\n",
          IRIS_METRIC_BLOCK, IRIS_METRIC_BLOCK, IRIS_METRIC_BLOCK_FLOOR,
          params->pixel_test_gates ? ", which gates (--strict-pixels)"
                                   : ", reported only: at low spp the skew of path-tracing samples "
                                     "makes it reject unbiased renders; the block z-test gates");

  for (int k = 0; k < res->method_count; k++) {
    const iris_validate_method *m = &res->methods[k];
    const char *name = iris_method_name(m->method);
    char file[128], alt[160];
    fprintf(fp, "<h2>%s</h2><p>Reference variance in the z-tests: ", name);
    html_escape(fp, m->ref_variance);
    fprintf(fp, ". Largest pixel |z| %.2f at (%d, %d) channel %c; %llu zero-variance values, %llu of "
                "them differing. Block z: %llu tests, %llu over %.2f.</p>\n",
            m->pixels.max_abs_z, m->pixels.max_x, m->pixels.max_y, "RGB"[m->pixels.max_c],
            (unsigned long long)m->pixels.degenerate, (unsigned long long)m->pixels.degenerate_fail,
            (unsigned long long)m->blocks.z_tests, (unsigned long long)m->blocks.z_over, m->blocks.z_crit);
    fprintf(fp, "<figure>");
    iris_report_png_name(name, "", file, sizeof file);
    snprintf(alt, sizeof alt, "iris %s", name);
    put_image(fp, dir, file, alt);
    fprintf(fp, "<figcaption>iris, %s, %d spp</figcaption></figure>\n<figure>", name, m->spp);
    put_image(fp, dir, "cycles.png", "Cycles reference");
    fprintf(fp, "<figcaption>Cycles reference</figcaption></figure>\n<figure>");
    iris_report_png_name(name, "diff", file, sizeof file);
    snprintf(alt, sizeof alt, "relative difference %s", name);
    put_image(fp, dir, file, alt);
    fprintf(fp, "<figcaption>(E<sub>iris</sub> &minus; E<sub>ref</sub>) / (E<sub>ref</sub> + 0.03): "
                "blue &minus;0.5 &hellip; white 0 &hellip; red +0.5</figcaption></figure>\n<figure>");
    iris_report_png_name(name, "z", file, sizeof file);
    snprintf(alt, sizeof alt, "z-score %s", name);
    put_image(fp, dir, file, alt);
    fprintf(fp, "<figcaption>per-pixel z (largest channel): blue &minus;5 &hellip; red +5</figcaption>"
                "</figure>\n");
  }
  fprintf(fp, "<p>Written by <code>iris validate</code> (iris %s). Machine-readable: "
              "<code>summary.json</code>.</p></body></html>\n", IRIS_VERSION_STRING);
  if (ferror(fp)) {
    iris_atomic_abort(&f);
    return iris_error_set(err, IRIS_ERR_IO, path, 0, NULL, "write failed");
  }
  return iris_atomic_commit(&f, err);
}
