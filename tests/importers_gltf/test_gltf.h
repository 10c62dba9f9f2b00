/* Shared by test_gltf.c and test_gltf_extensions.c (one executable,
 * test_importers_gltf): the failure count and EXPECT, the import helpers and
 * the synthetic document's payload, and the checks each file offers main. */
#ifndef IRIS_TESTS_IMPORTERS_GLTF_TEST_GLTF_H
#define IRIS_TESTS_IMPORTERS_GLTF_TEST_GLTF_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "importers/import.h"

extern int failures;
#define EXPECT(cond, ...)                                            \
  do {                                                               \
    if (!(cond)) {                                                   \
      fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond); \
      fprintf(stderr, __VA_ARGS__);                                  \
      fprintf(stderr, "\n");                                         \
      failures++;                                                    \
    }                                                                \
  } while (0)

/* Import options of every test here: normals computed. */
iris_import_options options(void);
/* Imports a file that must load (an EXPECT otherwise); NULL on failure. */
iris_scene *import_ok(const char *path);
/* Binary payload of the synthetic files: 5 positions (60 bytes) then 6 u8 indices. */
extern const float quad_pos[15];
extern const uint8_t strip_idx[6];
/* Base64 of n bytes into out (4 (n + 2) / 3 + 1 chars). */
void base64(const uint8_t *in, size_t n, char *out);
/* A glTF document over the synthetic payload with `rest` as its last members (malloc'd). */
char *make_gltf(const char *rest);
/* Imports a JSON text; msg gets the error record. */
iris_status import_text(const char *json, const iris_import_options *o, iris_scene **s, char *msg,
                        size_t size);

/* ---- test_gltf_extensions.c ------------------------------------------------- */
void check_gpu_instancing(void);
void check_generated_vs_supplied(const char *rel, double max_median_deg, double min_within_1deg,
                                 double min_sign_agree);
void check_mirrored_uvs(void);
void check_anisotropy(void);

#endif
