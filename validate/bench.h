/* `iris bench`: speed against accuracy. Renders every scene x method x
 * wall-clock budget (setup included) x seed, measures relMSE, MAPE and the
 * mean-energy ratio against a reference (a given EXR, or a long `mis` render
 * cached by scene hash, size and settings), optionally times Blender Cycles at
 * the spp of each budget's `mis` run, and writes DIR/results.csv,
 * DIR/results.json, the tables (validate/bench_table.h), preview images and,
 * through the plot script, the convergence charts. docs/benchmarks.md. */
#ifndef IRIS_VALIDATE_BENCH_H
#define IRIS_VALIDATE_BENCH_H

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "renderer/adaptive.h"
#include "renderer/integrator.h"
#include "validate/validate.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IRIS_BENCH_MAX_SCENES 16
#define IRIS_BENCH_MAX_TIMES 16
#define IRIS_BENCH_MAX_SEEDS 64
#define IRIS_BENCH_MAX_METHODS 16
#define IRIS_BENCH_DEFAULT_REFERENCE_SPP 4096

/* What the progress callback is told before each run and after each pass. */
typedef struct iris_bench_progress {
  int run, runs;        /* 1-based number of the current run, and how many there are */
  const char *scene;
  const char *what;     /* method name, "cycles" or "reference" */
  double budget;        /* seconds (0 for spp-bound runs: reference, Cycles) */
  uint64_t seed;
  int spp_done;
  double run_fraction;  /* of the current run, in [0, 1] */
  double eta;           /* seconds left for the whole bench (estimate) */
} iris_bench_progress;

typedef struct iris_bench_params {
  const char *const *inputs;  /* files or built-in scene names (validate.h's loader) */
  int input_count;
  iris_world_override world;  /* zeroed: each scene's own world (validate.h) */
  const char *variant;        /* glTF material variant of every input (NULL: the defaults) */
  /* The timed iris runs: method k with sampler samplers[k] and emitter
   * triangle sampling light_samplings[k] (variants such as mis@independent
   * compare samplers in one run; iris_bench_method_label names them). */
  iris_method methods[IRIS_BENCH_MAX_METHODS];
  iris_sampler_kind samplers[IRIS_BENCH_MAX_METHODS];
  iris_triangle_sampling light_samplings[IRIS_BENCH_MAX_METHODS];
  /* guided methods: the training samples kept in the image or discarded
   * ("@keep" / "@discard" when not IRIS_KEEP_TRAINING_DEFAULT) */
  bool keep_training[IRIS_BENCH_MAX_METHODS];
  iris_light_sampler light_samplers[IRIS_BENCH_MAX_METHODS]; /* NEE's light choice (@power, @tree) */
  int connect; /* iris_render_params.connect for every row (--connect) */
  int light_trace; /* iris_render_params.light_trace for every row (--light-trace) */
  iris_adaptive_rule adaptive[IRIS_BENCH_MAX_METHODS]; /* @adaptive: relmse allocation, the budget
                                                           deciding; @freeze: Cycles' rule at
                                                           IRIS_BENCH_ADAPTIVE_THRESHOLD, the budget a cap */
  int method_count;
  double times[IRIS_BENCH_MAX_TIMES];  /* wall-clock budgets in seconds, setup included */
  int time_count;
  int seeds;                  /* seeds 0 .. seeds-1 (default 1) */
  const char *const *references; /* one EXR per input, or NULL: auto */
  const char *cache_dir;      /* auto references (NULL: iris_bench_default_cache_dir) */
  int reference_spp;          /* auto references (0: IRIS_BENCH_DEFAULT_REFERENCE_SPP) */
  int width, height;          /* <= 0: the reference's, else the scene's; one of them given:
                                 the other follows the scene's aspect ratio */
  int threads;                /* <= 0: all cores (iris and Blender) */
  int max_depth;              /* < 0: the scene's, else 64 */
  bool cycles;                /* also time Blender Cycles at mis's spp ("cycles" rows) */
  bool cycles_adaptive;       /* also Cycles as users run it ("cycles-adaptive" rows): adaptive
                                 sampling at cycles_threshold, each budget its time limit */
  double cycles_threshold;    /* Cycles' noise threshold (default 0.01, Blender's) */
  const char *blender;        /* NULL: $IRIS_BLENDER, else "blender" */
  double target_relmse;       /* time-to-target column; <= 0: per scene (bench_table.h) */
  const char *out_dir;
  const char *python;         /* interpreter for the plot script (NULL: /usr/bin/python3) */
  const char *plot_script;    /* bench/charts/plot_bench.py; NULL: no charts */
  bool quiet;
  volatile sig_atomic_t *cancel;
  void (*progress)(void *ctx, const iris_bench_progress *p);
  void *progress_ctx;
} iris_bench_params;

iris_bench_params iris_bench_params_default(void);

/* Name of run variant k in results, tables and charts: the method's name,
 * followed by "@independent", "@area" and/or the light sampler ("@power" or
 * "@tree", joined with "+") when it does not use the defaults (sobol,
 * solid-angle, IRIS_LIGHT_SAMPLER_DEFAULT): "mis", "mis@independent",
 * "mis@area", "mis@independent+area", "mis@power". iris_bench_method_parse
 * reads it back. */
const char *iris_bench_method_label(const iris_bench_params *p, int k, char *buf, size_t size);
/* Whether a label asks for the training samples to be kept ("@keep"),
 * discarded ("@discard"), else IRIS_KEEP_TRAINING_DEFAULT. */
bool iris_bench_method_keeps_training(const char *label);
/* The adaptive rule a label asks for: "@adaptive" relmse, "@freeze" Cycles' rule, else off. */
iris_adaptive_rule iris_bench_method_adaptive(const char *label);
/* The noise threshold of @freeze rows: Blender's default. */
#define IRIS_BENCH_ADAPTIVE_THRESHOLD 0.01
bool iris_bench_method_parse(const char *label, iris_method *m, iris_sampler_kind *sampler, iris_light_sampler *light_sampler,
                             iris_triangle_sampling *light);

/* One render: a line of results.csv. method is a method name or "cycles". */
typedef struct iris_bench_row {
  char scene[128];
  char method[64];
  char resolved[32];     /* the method the paths used: auto's choice, else = method */
  char method_reason[240]; /* auto: "auto: guided-nee (75% of the photons indirect)"; else "" */
  uint64_t seed;
  double budget_s;       /* the budget; Cycles: the budget of the mis run whose spp it used */
  double seconds;        /* wall-clock of setup + passes; Cycles: render time, start-up excluded */
  double setup_seconds;  /* of which setup (accel, lights, guide); Cycles: scene build */
  int spp;
  double relmse, mape, energy_ratio;
  double relmse_full;    /* relMSE over every pixel: what relmse's dropped 0.1% (fireflies) adds */
  uint64_t nonfinite;    /* NaN/Inf pixel values in the image */
} iris_bench_row;

typedef struct iris_bench_scene {
  char name[128];        /* label in the results (file stem or built-in name, made unique) */
  char input[1024];
  int width, height;
  char reference[1024];  /* the EXR used */
  char reference_description[256];
  int reference_spp;
  double reference_relmse; /* the reference's own expected relMSE, from its variance channels
                              (contained in every measured relMSE); < 0 unknown */
  double target_relmse;  /* used for the time-to-target column */
  char images[IRIS_BENCH_MAX_METHODS + 3][64]; /* preview PNG names in DIR/images: reference, methods,
                                                  cycles, cycles-adaptive */
  int image_count;
} iris_bench_scene;

typedef struct iris_bench_result {
  iris_bench_row *rows;
  size_t row_count, row_capacity;
  iris_bench_scene scenes[IRIS_BENCH_MAX_SCENES];
  int scene_count;
  bool cycles_done, cycles_adaptive_done;
  char cycles_version[64];
  bool charts;             /* the plot script ran */
  bool interrupted;
  double load_before[3], load_after[3]; /* /proc/loadavg around the runs (-1: unknown) */
  int cpus;
} iris_bench_result;

/* $XDG_CACHE_HOME/iris/bench, else $HOME/.cache/iris/bench, else /tmp/iris-bench-cache. */
void iris_bench_default_cache_dir(char *buf, size_t size);

/* Runs the whole bench and writes its outputs into params->out_dir. Bad
 * inputs, references of the wrong size and unusable budgets fail before any
 * rendering (IRIS_ERR_USAGE / IO / INVALID). Interrupted: the rows done so far
 * are written and IRIS_ERR_INTERRUPTED is returned. */
iris_status iris_bench_run(const iris_bench_params *params, iris_bench_result *result,
                           iris_error *err);
void iris_bench_result_destroy(iris_bench_result *result);

/* DIR/results.csv: header scene,method,seed,budget_s,seconds,spp,relmse,mape,energy_ratio,resolved,
 * relmse_net,relmse_full. */
iris_status iris_bench_write_csv(const char *path, const iris_bench_result *res, iris_error *err);
/* DIR/results.json: machine, parameters, scenes (reference, images), rows, tables and charts. */
iris_status iris_bench_write_json(const char *path, const iris_bench_params *params,
                                  const iris_bench_result *res, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
