#!/usr/bin/python3
"""Where a render's error is (docs/benchmarks.md, "Environment light against
Cycles"): bench's relMSE per pixel, (1/3) sum_c (t - r)^2 / (r^2 + 0.01),
averaged over the test images, the top 0.1% of pixels dropped as bench does;
prints the share of the rest in the top 1% and 5% of pixels and in bands of
rows (top to bottom).

usage: bench/error_split.py REF.exr TEST.exr... [--rows A-B,C-D,...]
(Debian's /usr/bin/python3 with numpy; oiiotool converts the EXRs)
"""
import os
import subprocess
import sys
import tempfile

import numpy as np

# bench's relMSE (validate/metrics.h): per pixel (t - r)^2 / (r^2 + EPS), the
# DROP share of the pixels with the largest error left out.
EPS = 0.01
DROP = 0.001


def read_exr(path, tmp, channels="R,G,B"):
    """Channels (default R, G, B) of an EXR as float64 (through oiiotool's FITS writer), row 0 at the top."""
    out = os.path.join(tmp, "x.fits")
    subprocess.run(["oiiotool", path, "-ch", channels, "-d", "float", "-o", out], check=True)
    data = open(out, "rb").read()
    head, i, dims = {}, 0, []
    while data[i:i + 8] != b"END     ":
        key, _, val = data[i:i + 80].decode().partition("=")
        head[key.strip()] = val.split("/")[0].strip()
        i += 80
    start = (i // 2880 + 1) * 2880
    c, w, h = int(head["NAXIS1"]), int(head["NAXIS2"]), int(head["NAXIS3"])
    a = np.frombuffer(data[start:start + 4 * c * w * h], ">f4").reshape(h, w, c).astype(np.float64)
    return a[::-1]  # FITS rows run bottom-up


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--rows")]
    bands = [a for a in sys.argv[1:] if a.startswith("--rows")]
    with tempfile.TemporaryDirectory() as tmp:
        ref = read_exr(args[0], tmp)
        err = np.mean([((read_exr(p, tmp) - ref) ** 2 / (ref ** 2 + EPS)).mean(axis=2) for p in args[1:]],
                      axis=0)
    h = err.shape[0]
    flat = np.sort(err.ravel())[::-1]
    drop = int(len(flat) * DROP)
    kept = flat[drop:]
    total = kept.sum()
    print("relMSE (top 0.1%% dropped) %.5f over %d image(s)" % (kept.mean(), len(args) - 1))
    for frac in (0.01, 0.05):
        print("top %g%% of pixels: %.2f of it" % (100 * frac, flat[drop:int(len(flat) * frac)].sum() / total))
    cut = flat[drop - 1] if drop else np.inf
    kept_img = np.where(err <= cut, err, 0.0)
    spec = bands[0].split("=", 1)[1] if bands else "0-%d,%d-%d" % (h // 2, h // 2, h)
    for band in spec.split(","):
        a, b = (int(x) for x in band.split("-"))
        print("rows %d-%d: %.2f of it" % (a, b, kept_img[a:b].sum() / kept_img.sum()))


if __name__ == "__main__":
    main()
