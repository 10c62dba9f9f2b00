/* `iris report DIR [-o OUT.html]`: one self-contained HTML page from the
 * outputs of iris bench and iris validate in DIR and its subfolders
 * (validate/report_page.h). docs/cli.md ("report"). */
#include <stdio.h>
#include <string.h>

#include "core/log.h"
#include "tools/cli.h"
#include "validate/report_page.h"

static const char *CMD = "report";

static void print_help(void) {
  printf(
      "Usage: iris report DIR [-o OUT.html] [options]\n"
      "\n"
      "Writes one self-contained HTML page (images embedded as data URIs, inline\n"
      "styles, no scripts, no network) from the iris bench (results.json) and iris\n"
      "validate (summary.json) outputs in DIR and its immediate subfolders: the\n"
      "convergence charts, the tables, side-by-side renders and false-colour\n"
      "difference images.\n"
      "\n"
      "  -o, --output FILE   the page (default DIR/index.html)\n"
      "      --title TEXT    page title (default \"iris report: DIR\")\n"
      "      --link-images   refer to the image files instead of embedding them\n"
      "                      (smaller page; it must then be written into DIR)\n"
      "      --quiet         no messages\n"
      "\n"
      "Exit status: 0 done, 2 bad usage or no usable output in DIR, 1 other failure.\n");
}

int iris_cmd_report(int argc, char **argv) {
  iris_report_page_params p;
  memset(&p, 0, sizeof p);
  bool quiet = false;
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i];
    if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
      print_help();
      return IRIS_EXIT_OK;
    } else if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0 || strcmp(a, "--title") == 0) {
      if (i + 1 >= argc) return iris_cli_usage_error(CMD, "option %s needs a value", a);
      if (strcmp(a, "--title") == 0)
        p.title = argv[++i];
      else
        p.output = argv[++i];
    } else if (strcmp(a, "--link-images") == 0) {
      p.link_images = true;
    } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
      quiet = true;
    } else if (a[0] == '-' && a[1] != 0) {
      return iris_cli_usage_error(CMD, "unknown option '%s'", a);
    } else {
      if (p.dir) return iris_cli_usage_error(CMD, "more than one folder ('%s' and '%s')", p.dir, a);
      p.dir = a;
    }
  }
  if (!p.dir) return iris_cli_usage_error(CMD, "no folder given");
  if (quiet) iris_log_set_level(IRIS_LOG_QUIET);
  iris_error err;
  iris_error_clear(&err);
  iris_report_page_result res;
  iris_status st = iris_report_page_write(&p, &res, &err);
  if (st != IRIS_OK) return iris_cli_report(&err);
  iris_infof("report: wrote %s (%d bench and %d validate section(s), %d images)", res.output,
             res.bench_sections, res.validate_sections, res.images);
  return IRIS_EXIT_OK;
}
