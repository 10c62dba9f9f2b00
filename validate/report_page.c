/* The report page (validate/report_page.h). */
#include "validate/report_page.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "core/fileio.h"

#define MAX_SECTIONS 64
#define MAX_IMAGE_BYTES (64u << 20)

typedef struct page {
  FILE *fp;
  const char *dir;      /* the report's root */
  bool link;
  int images;
  int missing;
} page;

static void esc(FILE *fp, const char *s) {
  for (; s && *s; s++) {
    switch (*s) {
    case '<': fputs("&lt;", fp); break;
    case '>': fputs("&gt;", fp); break;
    case '&': fputs("&amp;", fp); break;
    case '"': fputs("&quot;", fp); break;
    default: fputc(*s, fp);
    }
  }
}

static const char B64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

static void put_base64(FILE *fp, const unsigned char *d, size_t n) {
  char out[4];
  for (size_t i = 0; i < n; i += 3) {
    unsigned v = (unsigned)d[i] << 16;
    if (i + 1 < n) v |= (unsigned)d[i + 1] << 8;
    if (i + 2 < n) v |= d[i + 2];
    out[0] = B64[(v >> 18) & 63];
    out[1] = B64[(v >> 12) & 63];
    out[2] = i + 1 < n ? B64[(v >> 6) & 63] : '=';
    out[3] = i + 2 < n ? B64[v & 63] : '=';
    fwrite(out, 1, 4, fp);
  }
}

/* A PNG or SVG file as <img>, relative to the report root: `rel` is the
 * path under DIR. Missing files become a visible note, never a broken image. */
static void put_img(page *pg, const char *rel, const char *alt, const char *cls) {
  char path[2200];
  iris_path_join(pg->dir, rel, path, sizeof path);
  char ext[16];
  iris_path_ext(rel, ext, sizeof ext);
  const char *mime = strcmp(ext, "svg") == 0 ? "image/svg+xml" : "image/png";
  if (!iris_path_exists(path)) {
    fprintf(pg->fp, "<div class=missing>missing: ");
    esc(pg->fp, rel);
    fprintf(pg->fp, "</div>");
    pg->missing++;
    return;
  }
  fprintf(pg->fp, "<img class=\"%s\" alt=\"", cls);
  esc(pg->fp, alt);
  fprintf(pg->fp, "\" src=\"");
  char *data = NULL;
  size_t size = 0;
  if (!pg->link && iris_file_read(path, MAX_IMAGE_BYTES, &data, &size, NULL) == IRIS_OK) {
    fprintf(pg->fp, "data:%s;base64,", mime);
    put_base64(pg->fp, (const unsigned char *)data, size);
    free(data);
  } else {
    esc(pg->fp, rel);
  }
  fprintf(pg->fp, "\">");
  pg->images++;
}

static void put_figure(page *pg, const char *rel, const char *caption, const char *cls) {
  fprintf(pg->fp, "<figure>");
  put_img(pg, rel, caption, cls);
  fprintf(pg->fp, "<figcaption>");
  esc(pg->fp, caption);
  fprintf(pg->fp, "</figcaption></figure>\n");
}

static iris_status read_json(const char *path, cJSON **out, iris_error *err) {
  char *text = NULL;
  size_t size = 0;
  iris_status st = iris_file_read(path, 64u << 20, &text, &size, err);
  if (st != IRIS_OK) return st;
  *out = cJSON_Parse(text);
  free(text);
  if (!*out || !cJSON_IsObject(*out)) {
    cJSON_Delete(*out);
    *out = NULL;
    return iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL, "not a JSON object");
  }
  return IRIS_OK;
}

static const char *jstr(const cJSON *o, const char *k) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, k);
  return cJSON_IsString(v) ? v->valuestring : "";
}

static double jnum(const cJSON *o, const char *k) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, k);
  return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

static void join_rel(const char *sub, const char *name, char *out, size_t size) {
  /* both parts are short (folder names under 200, file names from JSON) */
  size_t a = strlen(sub), b = strlen(name);
  if (a + b + 2 > size) {
    out[0] = 0;
    return;
  }
  memcpy(out, sub, a);
  if (a) out[a++] = '/';
  memcpy(out + a, name, b + 1);
}

static void put_legend(FILE *fp, const char *what, const char *lo, const char *hi) {
  fprintf(fp, "<div class=legend><span>%s</span><span class=bar></span><span>%s</span> %s</div>\n", lo,
          hi, what);
}

/* ---- bench section ------------------------------------------------------- */

static void bench_section(page *pg, const char *sub, const cJSON *o) {
  FILE *fp = pg->fp;
  char rel[1400], path[2200];
  fprintf(fp, "<section><h2>Benchmark");
  if (sub[0]) {
    fprintf(fp, ": ");
    esc(fp, sub);
  }
  fprintf(fp, "</h2>\n<p class=meta>");
  const cJSON *mach = cJSON_GetObjectItemCaseSensitive(o, "machine");
  const cJSON *par = cJSON_GetObjectItemCaseSensitive(o, "params");
  fprintf(fp, "iris ");
  esc(fp, jstr(o, "iris_version"));
  fprintf(fp, ", ");
  esc(fp, jstr(o, "date"));
  if (mach) {
    fprintf(fp, "; %g CPUs", jnum(mach, "cpus"));
    const cJSON *lb = cJSON_GetObjectItemCaseSensitive(mach, "load_average_before");
    const cJSON *la = cJSON_GetObjectItemCaseSensitive(mach, "load_average_after");
    if (cJSON_IsArray(lb) && cJSON_IsArray(la) && cJSON_GetArraySize(lb) > 0 && cJSON_GetArraySize(la) > 0)
      fprintf(fp, ", load average %.1f before and %.1f after the runs",
              cJSON_GetArrayItem(lb, 0)->valuedouble, cJSON_GetArrayItem(la, 0)->valuedouble);
  }
  if (par) {
    fprintf(fp, "; %g seed(s), %g thread(s); budgets in wall-clock seconds with setup included",
            jnum(par, "seeds"), jnum(par, "threads"));
    const char *cv = jstr(par, "cycles_version");
    if (cv[0]) {
      fprintf(fp, "; Cycles ");
      esc(fp, cv);
      fprintf(fp, " at the spp of each budget's mis run (render time, start-up excluded)");
    }
  }
  if (cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(o, "interrupted")))
    fprintf(fp, "; <b class=bad>interrupted</b>: partial results");
  fprintf(fp, ".</p>\n");

  /* the charts */
  const cJSON *outs = cJSON_GetObjectItemCaseSensitive(o, "outputs");
  const cJSON *scenes = cJSON_GetObjectItemCaseSensitive(o, "scenes");
  if (outs && cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(outs, "charts"))) {
    fprintf(fp, "<h3>Convergence</h3>\n<div class=charts>");
    const cJSON *sc;
    cJSON_ArrayForEach(sc, scenes) {
      char cap[300];
      snprintf(cap, sizeof cap, "%s: relMSE against seconds (log-log); band: min/max over seeds",
               jstr(sc, "name"));
      join_rel(sub, jstr(sc, "chart_svg"), rel, sizeof rel);
      put_figure(pg, rel, cap, "chart");
    }
    fprintf(fp, "</div>\n");
  } else {
    fprintf(fp, "<p>No charts (the chart script did not run).</p>\n");
  }

  /* the tables, as iris bench wrote them */
  join_rel(sub, "table.html", rel, sizeof rel);
  iris_path_join(pg->dir, rel, path, sizeof path);
  char *text = NULL;
  size_t size = 0;
  if (iris_file_read(path, 16u << 20, &text, &size, NULL) == IRIS_OK) {
    const char *a = strstr(text, "<!-- iris-bench-tables -->");
    const char *b = a ? strstr(a, "<!-- /iris-bench-tables -->") : NULL;
    if (a && b) {
      fprintf(fp, "<h3>Tables</h3>\n");
      fwrite(a, 1, (size_t)(b - a), fp);
    }
    free(text);
  }

  /* images of the largest budget, seed 0 */
  const cJSON *sc;
  cJSON_ArrayForEach(sc, scenes) {
    fprintf(fp, "<h3>");
    esc(fp, jstr(sc, "name"));
    fprintf(fp, " at the largest budget (seed 0)</h3>\n<p class=meta>");
    fprintf(fp, "%gx%g; reference: ", jnum(sc, "width"), jnum(sc, "height"));
    const cJSON *ref = cJSON_GetObjectItemCaseSensitive(sc, "reference");
    esc(fp, jstr(ref, "description"));
    fprintf(fp, ". Difference images: (E<sub>method</sub> - E<sub>ref</sub>) / (E<sub>ref</sub> + 0.03) per "
                "pixel, E = R+G+B.</p>\n");
    put_legend(fp, "relative difference (blue: below the reference)", "-0.5", "+0.5");
    fprintf(fp, "<div class=grid>\n");
    const cJSON *im;
    cJSON_ArrayForEach(im, cJSON_GetObjectItemCaseSensitive(sc, "images")) {
      fprintf(fp, "<div class=pair>");
      join_rel(sub, jstr(im, "image"), rel, sizeof rel);
      put_figure(pg, rel, jstr(im, "what"), "render");
      const char *diff = jstr(im, "diff");
      if (diff[0]) {
        char cap[96];
        snprintf(cap, sizeof cap, "%s - reference", jstr(im, "what"));
        join_rel(sub, diff, rel, sizeof rel);
        put_figure(pg, rel, cap, "render");
      }
      const char *spp = jstr(im, "spp");
      if (spp[0]) { /* adaptive: where the samples went */
        char cap[96];
        snprintf(cap, sizeof cap, "%s samples per pixel (log2 of count / mean, blue -3 .. red +3)", jstr(im, "what"));
        join_rel(sub, spp, rel, sizeof rel);
        put_figure(pg, rel, cap, "render");
      }
      fprintf(fp, "</div>\n");
    }
    fprintf(fp, "</div>\n");
  }
  fprintf(fp, "</section>\n");
}

/* ---- validate section ------------------------------------------------------- */

static void validate_section(page *pg, const char *sub, const cJSON *o) {
  FILE *fp = pg->fp;
  char rel[1400];
  bool passed = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(o, "passed"));
  fprintf(fp, "<section><h2>Validation: ");
  esc(fp, jstr(o, "scene"));
  if (sub[0]) {
    fprintf(fp, " <small>(");
    esc(fp, sub);
    fprintf(fp, ")</small>");
  }
  fprintf(fp, " %s</h2>\n<p class=meta>%gx%g, max depth %g; reference: ",
          passed ? "<b class=ok>pass</b>" : "<b class=bad>FAIL</b>", jnum(o, "width"),
          jnum(o, "height"), jnum(o, "max_depth"));
  const cJSON *ref = cJSON_GetObjectItemCaseSensitive(o, "reference");
  esc(fp, jstr(ref, "description"));
  fprintf(fp, "; energy tolerance %g.</p>\n", jnum(o, "tolerance"));
  fprintf(fp, "<table><tr><th>method</th><th>spp</th><th>seconds</th><th>energy ratio</th>"
              "<th>relMSE</th><th>MAPE</th><th>block max |z| / crit</th><th>pixel max |z| / crit</th>"
              "<th>NaN/Inf</th><th>result</th></tr>\n");
  const cJSON *m;
  const cJSON *methods = cJSON_GetObjectItemCaseSensitive(o, "methods");
  cJSON_ArrayForEach(m, methods) {
    const cJSON *b = cJSON_GetObjectItemCaseSensitive(m, "blocks");
    const cJSON *z = cJSON_GetObjectItemCaseSensitive(m, "pixels");
    fprintf(fp, "<tr><td>");
    esc(fp, jstr(m, "method"));
    fprintf(fp, "</td><td>%g</td><td>%.2f</td><td>%.4f</td><td>%.4g</td><td>%.4g</td>"
                "<td>%.2f / %.2f</td><td>%.2f / %.2f</td><td>%g / %g</td><td>%s</td></tr>\n",
            jnum(m, "spp"), jnum(m, "seconds"), jnum(m, "energy_ratio"), jnum(m, "relmse"),
            jnum(m, "mape"), jnum(b, "max_abs_z"), jnum(b, "z_crit"), jnum(z, "max_abs_z"),
            jnum(z, "z_crit"), jnum(m, "nan_count"), jnum(m, "inf_count"),
            cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(m, "passed")) ? "<b class=ok>pass</b>"
                                                                        : "<b class=bad>FAIL</b>");
  }
  fprintf(fp, "</table>\n");
  put_legend(fp, "relative difference (blue: iris below the reference)", "-0.5", "+0.5");
  put_legend(fp, "z score per pixel", "-5", "+5");
  fprintf(fp, "<div class=grid>\n<div class=pair>");
  join_rel(sub, "cycles.png", rel, sizeof rel);
  put_figure(pg, rel, "reference", "render");
  fprintf(fp, "</div>\n");
  cJSON_ArrayForEach(m, methods) {
    const char *name = jstr(m, "method");
    char file[200], cap[200];
    fprintf(fp, "<div class=pair>");
    static const char *const kinds[3][2] = {{"", ""}, {"-diff", " - reference"}, {"-z", " z score"}};
    for (int k = 0; k < 3; k++) {
      snprintf(file, sizeof file, "%s%s.png", name, kinds[k][0]);
      snprintf(cap, sizeof cap, "%s%s", name, kinds[k][1]);
      join_rel(sub, file, rel, sizeof rel);
      put_figure(pg, rel, cap, "render");
    }
    fprintf(fp, "</div>\n");
  }
  fprintf(fp, "</div></section>\n");
}

/* ---- the page ------------------------------------------------------------------ */

typedef struct found {
  char sub[256];  /* "" for DIR itself */
  bool bench;     /* results.json, else summary.json */
} found;

static int cmp_found(const void *a, const void *b) {
  return strcmp(((const found *)a)->sub, ((const found *)b)->sub);
}

static void probe(const char *dir, const char *sub, found *list, int *n) {
  static const char *const files[2] = {"results.json", "summary.json"};
  for (int k = 0; k < 2 && *n < MAX_SECTIONS; k++) {
    char rel[600], path[1700];
    join_rel(sub, files[k], rel, sizeof rel);
    iris_path_join(dir, rel, path, sizeof path);
    if (iris_path_exists(path)) {
      snprintf(list[*n].sub, sizeof list[*n].sub, "%s", sub);
      list[*n].bench = k == 0;
      (*n)++;
    }
  }
}

static const char CSS[] =
    "body{font-family:sans-serif;margin:1.5em;max-width:1400px;color:#222}"
    "h1{font-size:1.5em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:2em}"
    ".meta{color:#555;font-size:.9em}"
    "table{border-collapse:collapse;margin:.5em 0 1.5em}caption{text-align:left;font-weight:bold;padding:.3em 0}"
    "td,th{border:1px solid #bbb;padding:.25em .6em;text-align:right;font-size:.9em}"
    "td:first-child,th:first-child{text-align:left}"
    ".ok{color:#1a7f37}.bad{color:#c62828}"
    ".grid{display:flex;flex-wrap:wrap;gap:1em}.pair{display:flex;gap:.3em}"
    ".charts{display:flex;flex-wrap:wrap;gap:1em}"
    "figure{margin:0}figcaption{font-size:.8em;color:#444;text-align:center}"
    "img.render{width:256px;image-rendering:pixelated;display:block}"
    "img.chart{width:520px;display:block;background:#fff}"
    ".missing{width:256px;padding:1em;border:1px dashed #c62828;color:#c62828;font-size:.8em}"
    ".legend{font-size:.8em;color:#444;margin:.3em 0;display:flex;align-items:center;gap:.4em}"
    ".legend .bar{display:inline-block;width:160px;height:10px;"
    "background:linear-gradient(to right,#2c3e9e,#ffffff,#b2182b);border:1px solid #999}";

iris_status iris_report_page_write(const iris_report_page_params *params,
                                   iris_report_page_result *result, iris_error *err) {
  memset(result, 0, sizeof *result);
  const char *dir = params->dir;
  struct stat sb;
  if (!dir || stat(dir, &sb) != 0 || !S_ISDIR(sb.st_mode))
    return iris_error_set(err, IRIS_ERR_IO, dir ? dir : "", 0, NULL, "not a folder");
  found list[MAX_SECTIONS];
  int n = 0;
  probe(dir, "", list, &n);
  DIR *d = opendir(dir);
  if (d) {
    int first_sub = n;
    struct dirent *e;
    while ((e = readdir(d)) && n < MAX_SECTIONS) {
      if (e->d_name[0] == '.' || strlen(e->d_name) >= 200) continue;
      char path[1400];
      iris_path_join(dir, e->d_name, path, sizeof path);
      if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode)) probe(dir, e->d_name, list, &n);
    }
    closedir(d);
    qsort(list + first_sub, (size_t)(n - first_sub), sizeof list[0], cmp_found);
  }
  if (n == 0)
    return iris_error_set(err, IRIS_ERR_INVALID, dir, 0, NULL,
                          "no iris bench (results.json) or iris validate (summary.json) output here "
                          "or in a subfolder");
  /* parse everything before writing anything */
  cJSON *docs[MAX_SECTIONS];
  iris_status st = IRIS_OK;
  int parsed = 0;
  for (int i = 0; i < n && st == IRIS_OK; i++) {
    char rel[600], path[1700];
    join_rel(list[i].sub, list[i].bench ? "results.json" : "summary.json", rel, sizeof rel);
    iris_path_join(dir, rel, path, sizeof path);
    st = read_json(path, &docs[i], err);
    if (st == IRIS_OK) parsed++;
    if (st == IRIS_OK && list[i].bench && strcmp(jstr(docs[i], "kind"), "iris-bench") != 0)
      st = iris_error_set(err, IRIS_ERR_INVALID, path, 0, NULL, "not an iris bench results.json");
  }
  if (st == IRIS_OK) {
    if (params->output)
      snprintf(result->output, sizeof result->output, "%s", params->output);
    else
      iris_path_join(dir, "index.html", result->output, sizeof result->output);
    if (params->link_images) {
      char odir[1024];
      iris_path_dir(result->output, odir, sizeof odir);
      struct stat so, sd;
      if (stat(odir, &so) != 0 || stat(dir, &sd) != 0 || so.st_dev != sd.st_dev || so.st_ino != sd.st_ino)
        st = iris_error_set(err, IRIS_ERR_USAGE, result->output, 0, NULL,
                            "with linked images the page must be written into %s", dir);
    }
  }
  iris_atomic_file f;
  if (st == IRIS_OK) st = iris_atomic_open(&f, result->output, err);
  if (st == IRIS_OK) {
    page pg = {f.fp, dir, params->link_images, 0, 0};
    char title[1200];
    if (params->title)
      snprintf(title, sizeof title, "%s", params->title);
    else
      snprintf(title, sizeof title, "iris report: %s", dir);
    fprintf(f.fp, "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
                  "<meta name=\"viewport\" content=\"width=device-width\">\n<link rel=\"icon\" href=\"data:,\">\n<title>");
    esc(f.fp, title);
    fprintf(f.fp, "</title>\n<style>%s</style></head>\n<body>\n<h1>", CSS);
    esc(f.fp, title);
    time_t now = time(NULL);
    char date[64];
    strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", gmtime(&now));
    fprintf(f.fp, "</h1>\n<p class=meta>Written by iris report %s on %s. Self-contained: no network "
                  "access, no scripts.</p>\n", IRIS_VERSION_STRING, date);
    for (int i = 0; i < n; i++) {
      if (list[i].bench) {
        bench_section(&pg, list[i].sub, docs[i]);
        result->bench_sections++;
      } else {
        validate_section(&pg, list[i].sub, docs[i]);
        result->validate_sections++;
      }
    }
    fprintf(f.fp, "</body></html>\n");
    result->images = pg.images;
    if (ferror(f.fp)) {
      iris_atomic_abort(&f);
      st = iris_error_set(err, IRIS_ERR_IO, result->output, 0, NULL, "write failed");
    } else {
      st = iris_atomic_commit(&f, err);
    }
  }
  for (int i = 0; i < parsed; i++) cJSON_Delete(docs[i]);
  return st;
}
