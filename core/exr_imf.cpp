// Thin shim: OpenEXR C++ (Imf) pixel reading behind a C function; see exr_imf.h.
#include "core/exr_imf.h"

#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>

#include <cstdio>
#include <exception>

extern "C" int iris_exr_imf_read_pixels(const char *path, int width, int height, int channel_count,
                                        const char *const *names, float *data, char *msg,
                                        size_t msg_size) {
  try {
    Imf::InputFile file(path);
    const Imath::Box2i dw = file.header().dataWindow();
    if (dw.max.x - dw.min.x + 1 != width || dw.max.y - dw.min.y + 1 != height) {
      std::snprintf(msg, msg_size, "data window changed between reads");
      return -1;
    }
    const size_t xstride = sizeof(float) * static_cast<size_t>(channel_count);
    const size_t ystride = xstride * static_cast<size_t>(width);
    Imf::FrameBuffer fb;
    for (int c = 0; c < channel_count; c++)
      fb.insert(names[c], Imf::Slice::Make(Imf::FLOAT, data + c, dw, xstride, ystride));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return 0;
  } catch (const std::exception &e) {
    std::snprintf(msg, msg_size, "%s", e.what());
  } catch (...) {
    std::snprintf(msg, msg_size, "unknown OpenEXR error");
  }
  return -1;
}
