/* Command-line options declared once, as data: a table row per flag (long
 * name, value type, range, help line, the field it fills), grouped so that the
 * commands taking the same flags share the rows (environment, render,
 * guiding), parsed by one getopt_long loop, with --help made from the same
 * rows (docs/cli.md). A command binds each group it takes to the struct the
 * group's rows fill, adds its own group, and reads what was given from the
 * struct and the per-row "seen" bits. */
#ifndef IRIS_TOOLS_OPTIONS_H
#define IRIS_TOOLS_OPTIONS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "scene/scene.h"

typedef enum iris_opt_type {
  IRIS_OPT_FLAG = 0, /* bool, no value */
  IRIS_OPT_INT,      /* int in [lo, hi] */
  IRIS_OPT_I64,      /* int64_t in [lo, hi] */
  IRIS_OPT_U64,      /* uint64_t (any) */
  IRIS_OPT_FLOAT,    /* float in [lo, hi] */
  IRIS_OPT_DOUBLE,   /* double in [lo, hi] */
  IRIS_OPT_STRING,   /* const char * (argv's own string), non-empty */
  IRIS_OPT_RGB,      /* float[3] "R,G,B", each finite in [lo, hi] */
  IRIS_OPT_CHOICE    /* int: index of the value in `choices` (NULL-terminated) */
} iris_opt_type;

typedef struct iris_option {
  const char *name;   /* long name without "--" */
  char short_name;    /* 0: none */
  iris_opt_type type;
  const char *arg;    /* value name in --help ("N", "FILE") */
  double lo, hi;      /* range of numbers */
  size_t offset;      /* of the field in the group's struct */
  const char *help;   /* one line (may contain '\n' + indentation for more) */
  const char *const *choices;
} iris_option;

#define IRIS_OPTIONS_MAX_ROWS 64
typedef struct iris_option_group {
  const char *title;  /* --help section heading */
  const iris_option *rows;
  size_t count;
} iris_option_group;

/* A group bound to the struct its rows fill; `seen` gets bit i for row i
 * given; `rows` (0 = all) selects the rows this command takes
 * (iris_options_rows), so that commands share a group's declarations without
 * taking flags that mean nothing to them. */
typedef struct iris_option_binding {
  const iris_option_group *group;
  void *target;
  uint64_t seen;
  uint64_t rows;
} iris_option_binding;

/* The mask of the rows named in a comma-separated list ("spp,seed,width"). */
uint64_t iris_options_rows(const iris_option_group *g, const char *names);

/* Parses argv[1..] against the bindings with getopt_long (GNU long options,
 * "--name=value" or "--name value", options and operands in any order).
 * Operands are stored in operands[0..*operand_count) (at most max_operands).
 * Returns 0 when done, 2 after printing a usage error (unknown option,
 * missing or bad value, a string option given twice (a repeated number
 * or flag overrides), too many operands) and -1
 * when --help or -h was given (the caller prints iris_options_help). */
int iris_options_parse(const char *cmd, int argc, char **argv, iris_option_binding *bindings,
                       size_t binding_count, const char **operands, int max_operands,
                       int *operand_count);
/* For a command that keeps its own getopt_long loop: writes the binding's
 * (selected) rows as struct option entries with val = base + row (returns
 * how many), and takes such a value c (with optarg) into the binding; *rc
 * gets 0 or 2. */
struct option;
size_t iris_options_getopt_rows(const iris_option_binding *b, int base, struct option *out);
bool iris_options_getopt_take(const char *cmd, iris_option_binding *b, int base, int c,
                              const char *arg, int *rc);
/* For a command with a hand-rolled loop: when argv[*i] (already split into
 * `name` and `val` by iris_cli_split_option) is one of the group's flags,
 * takes it (and its value, advancing *i) and returns true; *rc gets 0 or 2. */
bool iris_options_take(const char *cmd, iris_option_binding *b, const char *name, const char *val,
                       int argc, char **argv, int *i, int *rc);
/* Prints the groups' rows as --help sections. */
void iris_options_help(const iris_option_binding *bindings, size_t binding_count);
/* True when row `name` of the binding was given. */
bool iris_options_seen(const iris_option_binding *b, const char *name);

/* ---- shared groups ------------------------------------------------------ */

/* Environment: --env FILE, --env-strength S, --env-rotation DEG, --env-color R,G,B. */
typedef struct iris_env_options {
  const char *map;
  float strength;    /* default 1 */
  float rotation;    /* degrees, default 0 */
  float color[3];
  bool has_color;
} iris_env_options;
extern const iris_option_group IRIS_ENV_OPTIONS;
iris_env_options iris_env_options_default(void);
/* Checks the bound group (conflicts; the map file itself when check_map) and
 * applies it to the scene: the map or colour replaces the scene's world.
 * Returns 0, or the exit code after printing the error. */
int iris_env_options_check(const char *cmd, const iris_option_binding *b, bool check_map);
int iris_env_options_apply(const char *cmd, const iris_option_binding *b, iris_scene *scene);

/* Render: the sampling and frame flags of render, bench and validate. */
typedef struct iris_render_options {
  int spp;
  double time;
  uint64_t seed;
  const char *method;
  int sampler;        /* iris_sampler_kind */
  int light_sampling; /* iris_triangle_sampling */
  int light_sampler;  /* iris_light_sampler; commands set IRIS_LIGHT_SAMPLER_DEFAULT before parsing */
  int connect;        /* iris_render_params.connect (0: auto) */
  int light_trace;    /* iris_render_params.light_trace (0: auto) */
  int max_depth;
  int threads;
  int width, height;
  const char *camera;
} iris_render_options;
extern const iris_option_group IRIS_RENDER_OPTIONS;

/* glTF input: --variant NAME, the KHR_materials_variants variant the glTF
 * importer applies (iris_import_options.variant), for every command that
 * imports a file (import, info, render, export, validate, bench). */
typedef struct iris_gltf_input_options {
  const char *variant;
} iris_gltf_input_options;
extern const iris_option_group IRIS_GLTF_INPUT_OPTIONS;

/* Guiding (--method guided | guided-nee): fills iris_guiding_params directly. */
extern const iris_option_group IRIS_GUIDING_OPTIONS;

/* "iris: FILE: warning: the scene has no light ..." when nothing in the scene
 * emits (iris_scene_has_emitter); `what` names the scene. */
void iris_warn_if_lightless(const iris_scene *scene, const char *what);

#endif
