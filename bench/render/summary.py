"""Prints the markdown table of bench/render/run.sh's results."""
import json, os, re, sys

out = sys.argv[1]
print(open(os.path.join(out, "machine.txt")).read().strip().replace("\n", "; "))
print()
print("| scene | size, spp | iris mis 2 thr: s, Msamples/s, Mrays/s (rays, shadow rays per path) | raw Embree 2 thr Mrays/s (rays, shadow per path) | iris/raw 2 thr | iris/raw 1 thr | 1→2 threads | Cycles 2 thr: s, Msamples/s | iris vs Cycles |")
print("|---|---|---|---|---|---|---|---|---|")
for name in ["cornell-box", "veach-mis", "bunny-box"]:
    try:
        t1 = json.load(open(os.path.join(out, name + ".iris.t1.json")))
        t2 = json.load(open(os.path.join(out, name + ".iris.t2.json")))
        raw = json.load(open(os.path.join(out, name + ".raw.json")))
        raw1 = json.load(open(os.path.join(out, name + ".raw.t1.json")))
    except (OSError, ValueError):
        continue
    cyc = "n/a"
    speed = "n/a"
    try:
        line = open(os.path.join(out, name + ".cycles.txt")).read()
        m = re.search(r"render_seconds=([0-9.]+)", line)
        if m:
            cs = float(m.group(1))
            cyc = "%.2f s, %.2f" % (cs, t2["samples"] / cs / 1e6)
            speed = "%.2fx faster" % (cs / t2["seconds"])
    except OSError:
        pass
    print("| %s | %dx%d, %d | %.2f s, %.2f, %.2f (%.2f, %.2f) | %.2f (%.2f, %.2f) | %.2f | %.2f | %.2fx | %s | %s |" % (
        name, t2["width"], t2["height"], t2["spp"], t2["seconds"], t2["samples_per_second"] / 1e6,
        t2["rays_per_second"] / 1e6, t2["rays"] / t2["samples"], t2["shadow_rays"] / t2["samples"],
        raw["rays_per_second"] / 1e6, raw.get("rays_per_path", 0), raw.get("shadow_per_path", 0),
        t2["rays_per_second"] / raw["rays_per_second"], t1["rays_per_second"] / raw1["rays_per_second"],
        t1["seconds"] / t2["seconds"], cyc, speed))
