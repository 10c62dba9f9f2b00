/* Outputs of `iris validate`: PNGs (tone-mapped renders, false-colour
 * difference and z images), DIR/summary.json and a self-contained
 * DIR/report.html (images embedded as data URIs). */
#ifndef IRIS_VALIDATE_REPORT_H
#define IRIS_VALIDATE_REPORT_H

#include "core/error.h"
#include "core/image.h"
#include "validate/validate.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Exposure (EV) that maps the reference's mean energy to mid-grey 0.18,
 * clamped to [-10, 10]; one exposure for every image of a report. */
float iris_report_exposure(const double ref_mean[3]);

/* Signed values in [-range, range] as a diverging blue-white-red PNG
 * (blue: iris below the reference). */
iris_status iris_report_write_false_colour(const char *path, const float *values, int width,
                                           int height, float range, iris_error *err);

/* Per-pixel relative difference of the energy (R+G+B): (E_t - E_r) / (E_r + 3 eps). */
void iris_report_relative_difference(const iris_image *test, const iris_image *ref, float *out);

/* Standard file names in DIR: "cycles.png", "<method>.png", "<method>-diff.png",
 * "<method>-z.png". */
void iris_report_png_name(const char *method, const char *kind, char *buf, size_t size);

iris_status iris_report_write_summary(const char *path, const iris_validate_params *params,
                                      const iris_validate_result *res, iris_error *err);
iris_status iris_report_write_html(const char *dir, const iris_validate_params *params,
                                   const iris_validate_result *res, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
