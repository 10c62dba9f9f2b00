/* `iris report DIR`: one self-contained HTML page (no network: images are
 * embedded as data URIs, styles inline, no scripts) from the outputs of `iris
 * bench` (results.json, table.html, charts/, images/) and `iris validate`
 * (summary.json and its PNGs) found in DIR and its immediate subfolders:
 * side-by-side images, false-colour difference images, convergence charts
 * and the tables. docs/benchmarks.md ("iris report"). */
#ifndef IRIS_VALIDATE_REPORT_PAGE_H
#define IRIS_VALIDATE_REPORT_PAGE_H

#include <stdbool.h>

#include "core/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct iris_report_page_params {
  const char *dir;
  const char *output;  /* NULL: DIR/index.html */
  const char *title;   /* NULL: "iris report: DIR" */
  bool link_images;    /* refer to the PNG/SVG files by relative path instead of embedding */
} iris_report_page_params;

typedef struct iris_report_page_result {
  int bench_sections, validate_sections;
  int images;          /* <img> elements written */
  char output[1024];
} iris_report_page_result;

/* Fails with IRIS_ERR_IO when DIR does not exist, IRIS_ERR_INVALID when it
 * holds no bench or validate output or a JSON file is malformed. */
iris_status iris_report_page_write(const iris_report_page_params *params,
                                   iris_report_page_result *result, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
