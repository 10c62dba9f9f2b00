/* EXT_meshopt_compression buffer views through libmeshoptimizer (a C API). */
#include "importers/meshopt.h"

#include <string.h>

#include <meshoptimizer.h>

bool iris_meshopt_parse_mode(const char *s, iris_meshopt_mode *out) {
  if (!strcmp(s, "ATTRIBUTES")) *out = IRIS_MESHOPT_ATTRIBUTES;
  else if (!strcmp(s, "TRIANGLES")) *out = IRIS_MESHOPT_TRIANGLES;
  else if (!strcmp(s, "INDICES")) *out = IRIS_MESHOPT_INDICES;
  else return false;
  return true;
}

bool iris_meshopt_parse_filter(const char *s, iris_meshopt_filter *out) {
  if (!strcmp(s, "NONE")) *out = IRIS_MESHOPT_NONE;
  else if (!strcmp(s, "OCTAHEDRAL")) *out = IRIS_MESHOPT_OCTAHEDRAL;
  else if (!strcmp(s, "QUATERNION")) *out = IRIS_MESHOPT_QUATERNION;
  else if (!strcmp(s, "EXPONENTIAL")) *out = IRIS_MESHOPT_EXPONENTIAL;
  else return false;
  return true;
}

/* The rules of the extension's specification (and the library's asserts). */
const char *iris_meshopt_check(size_t count, size_t stride, iris_meshopt_mode mode, iris_meshopt_filter filter) {
  if (count == 0) return "count is 0";
  switch (mode) {
    case IRIS_MESHOPT_ATTRIBUTES:
      if (stride < 4 || stride > 256 || stride % 4) return "ATTRIBUTES needs a byteStride that is a multiple of 4 in [4, 256]";
      break;
    case IRIS_MESHOPT_TRIANGLES:
      if (count % 3) return "TRIANGLES needs a count that is a multiple of 3";
      /* fall through */
    case IRIS_MESHOPT_INDICES:
      if (stride != 2 && stride != 4) return "index modes need byteStride 2 or 4";
      if (filter != IRIS_MESHOPT_NONE) return "a filter is only allowed in ATTRIBUTES mode";
      break;
  }
  if (filter == IRIS_MESHOPT_OCTAHEDRAL && stride != 4 && stride != 8) return "OCTAHEDRAL needs byteStride 4 or 8";
  if (filter == IRIS_MESHOPT_QUATERNION && stride != 8) return "QUATERNION needs byteStride 8";
  return NULL;
}

bool iris_meshopt_decode(const uint8_t *src, size_t size, size_t count, size_t stride, iris_meshopt_mode mode,
                         iris_meshopt_filter filter, void *dst) {
  int rc;
  switch (mode) {
    case IRIS_MESHOPT_ATTRIBUTES: rc = meshopt_decodeVertexBuffer(dst, count, stride, src, size); break;
    case IRIS_MESHOPT_TRIANGLES: rc = meshopt_decodeIndexBuffer(dst, count, stride, src, size); break;
    default: rc = meshopt_decodeIndexSequence(dst, count, stride, src, size); break;
  }
  if (rc != 0) return false;
  switch (filter) {
    case IRIS_MESHOPT_OCTAHEDRAL: meshopt_decodeFilterOct(dst, count, stride); break;
    case IRIS_MESHOPT_QUATERNION: meshopt_decodeFilterQuat(dst, count, stride); break;
    case IRIS_MESHOPT_EXPONENTIAL: meshopt_decodeFilterExp(dst, count, stride); break;
    default: break;
  }
  return true;
}
