/* The failure-stability scenes: small scenes built so that one sampling
 * method or another fails (starves, fireflies, leaks, NaNs), each with the
 * sentence saying what it breaks. They are built-in scenes (`stress-*`) and
 * the suite bench/stress/run_stress.sh measures every method on them
 * (docs/stability.md). */
#ifndef IRIS_SCENES_STRESS_STRESS_H
#define IRIS_SCENES_STRESS_STRESS_H

#include <stdbool.h>
#include <stddef.h>

#include "core/error.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct iris_stress_info {
  const char *name;   /* built-in name, "stress-..." */
  const char *breaks; /* one sentence: what the scene breaks and why */
  bool black;         /* the exact answer is a black image (closed box, light outside) */
} iris_stress_info;

/* The stress scenes, in the order of docs/stability.md. */
const iris_stress_info *iris_stress_scenes(size_t *count);
/* The entry called `name`, or NULL. */
const iris_stress_info *iris_stress_find(const char *name);

/* Appends the named stress scene (materials, geometry, lights, camera, render
 * size) to an empty scene. IRIS_ERR_USAGE for an unknown name. */
iris_status iris_stress_build(const char *name, iris_scene *scene);
/* Creates and validates the named stress scene (what iris_builtin_create does
 * for a `stress-*` name). */
iris_status iris_stress_create(const char *name, iris_scene **out, iris_error *err);

#ifdef __cplusplus
}
#endif
#endif
