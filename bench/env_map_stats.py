#!/usr/bin/python3
"""Where an equirectangular Radiance .hdr map's light is (docs/benchmarks.md,
"Environment light against Cycles"): the share of luminance x sin(theta) (power
over the sphere) in the upper half and in the texels above a few thresholds.

usage: bench/env_map_stats.py MAP.hdr   (Debian's /usr/bin/python3 with numpy)
"""
import re
import sys

import numpy as np


def read_hdr(path):
    data = open(path, "rb").read()
    head_end = data.index(b"\n\n")
    line_end = data.index(b"\n", head_end + 2)
    m = re.match(rb"-Y (\d+) \+X (\d+)", data[head_end + 2:line_end])
    h, w = int(m.group(1)), int(m.group(2))
    p = line_end + 1
    out = np.zeros((h, w, 4), np.uint8)
    for y in range(h):  # new-style run-length scanlines only
        if data[p] != 2 or data[p + 1] != 2:
            sys.exit("%s: only run-length encoded scanlines are read here" % path)
        p += 4
        for c in range(4):
            x = 0
            while x < w:
                n = data[p]
                p += 1
                if n > 128:
                    out[y, x:x + n - 128, c] = data[p]
                    p += 1
                    x += n - 128
                else:
                    out[y, x:x + n, c] = np.frombuffer(data[p:p + n], np.uint8)
                    p += n
                    x += n
    e = out[..., 3].astype(np.int32)
    scale = np.where(e > 0, np.ldexp(1.0, e - 136), 0.0)
    return out[..., :3] * scale[..., None]


def main():
    rgb = read_hdr(sys.argv[1])
    h, w, _ = rgb.shape
    lum = rgb @ np.array([0.2126, 0.7152, 0.0722])
    power = lum * np.sin((np.arange(h) + 0.5) / h * np.pi)[:, None]
    total = power.sum()
    print("%s: %dx%d, largest texel luminance %.1f" % (sys.argv[1], w, h, lum.max()))
    print("upper half: %.3f of the power" % (power[: h // 2].sum() / total))
    for t in (1000, 100, 20):
        print("texels above %g: %d, %.3f of the power" % (t, (lum > t).sum(), power[lum > t].sum() / total))


if __name__ == "__main__":
    main()
