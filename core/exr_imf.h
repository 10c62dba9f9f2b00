/* Internal to core/image.c: pixel reading through the OpenEXR C++ library,
 * for the DWAA/DWAB compressions that OpenEXRCore 3.1 cannot decompress
 * ("DWA/A decompression not yet implemented in C"). C interface, C++ inside. */
#ifndef IRIS_CORE_EXR_IMF_H
#define IRIS_CORE_EXR_IMF_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Reads all pixels of part 0 of `path` as float into `data` (interleaved,
 * channel k = names[k], row 0 = top of the data window). The caller has read
 * the header already: width/height must match the data window. Returns 0, or
 * -1 with a one-line message in `msg`. Never throws. */
int iris_exr_imf_read_pixels(const char *path, int width, int height, int channel_count,
                             const char *const *names, float *data, char *msg, size_t msg_size);

#ifdef __cplusplus
}
#endif
#endif
