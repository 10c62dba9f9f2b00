/* Mesh processing through OpenMesh, behind a C interface (meshproc.cpp is the
 * only C++ here): polygon triangulation, angle-weighted vertex normals,
 * degenerate-face removal and optional welding. */
#ifndef IRIS_IMPORTERS_MESHPROC_H
#define IRIS_IMPORTERS_MESHPROC_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Filled by the importers (to be designed by the importer implementation). */

#ifdef __cplusplus
}
#endif
#endif
