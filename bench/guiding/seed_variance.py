#!/usr/bin/python3
"""relMSE over many seeds, with and without bench's dropped pixels
(docs/guiding.md, "Glints", *Fireflies the metric drops*).

For each set of renders (a glob, one image per seed) prints the mean and the
median over the seeds of
  - the full relMSE: mean over all pixels of (1/3) sum_c (t - r)^2 / (r^2 + 0.01);
  - bench's relMSE: the same after dropping the 0.1% of pixels with the
    largest error (validate/metrics.h, IRIS_METRIC_DROP);
and the seeds' own variance per pixel over r^2 + 0.01 (no reference needed).
A set written GLOB:MINUS is compared with REF minus the mean of the images
MINUS matches (a render that leaves a part of the light out, against the
reference without that part's mean); GLOB:self against the set's own mean
(a render of that part alone).

usage: bench/guiding/seed_variance.py REF.exr GLOB[:MINUS|:self]...
(Debian's /usr/bin/python3 with numpy; oiiotool reads the EXRs)
"""
import glob
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from error_split import DROP, EPS, read_exr  # noqa: E402



def kept_mean(err):
    s = np.sort(err.ravel())
    return s[: len(s) - int(len(s) * DROP)].mean()


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    with tempfile.TemporaryDirectory() as tmp:
        ref = read_exr(sys.argv[1], tmp)
        den = ref ** 2 + EPS
        for arg in sys.argv[2:]:
            pattern, _, minus = arg.partition(":")
            files = sorted(glob.glob(pattern))
            if len(files) < 2:
                sys.exit("%s: fewer than two images" % pattern)
            imgs = np.array([read_exr(f, tmp) for f in files])
            r = ref
            if minus == "self":
                r = imgs.mean(axis=0)
            elif minus:
                mf = sorted(glob.glob(minus))
                if not mf:
                    sys.exit("%s: no images" % minus)
                r = ref - np.mean([read_exr(f, tmp) for f in mf], axis=0)
            err = [(((x - r) ** 2) / den).mean(axis=2) for x in imgs]
            full = [e.mean() for e in err]
            kept = [kept_mean(e) for e in err]
            var = ((imgs - imgs.mean(axis=0)) ** 2).sum(axis=0) / (len(files) - 1)
            print("%-24s %2d seeds  full relMSE mean %.5f median %.5f | bench's (0.1%% dropped) mean %.5f "
                  "median %.5f | seeds' variance %.5f" % (os.path.basename(pattern) + (":" + os.path.basename(minus) if minus else ""), len(files),
                                                          np.mean(full), np.median(full), np.mean(kept),
                                                          np.median(kept), (var / den).mean()))


if __name__ == "__main__":
    main()
