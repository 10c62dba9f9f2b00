#!/usr/bin/python3
"""slurm.driver_local: tools/slurm/iris-slurm without a cluster. `render
--dry-run` with 3x2 tiles x 2 sample partitions writes the array and merge job
scripts; running them here (SLURM_ARRAY_TASK_ID = 0..11, then the merge) must
give the single-process render. A guided-nee render gets a training job
(--guide-out) that the array waits for (afterok) and whose guide every task
reads (--guide-in): trained, rendered as 2 tiles x 2 partitions and merged here,
it must also give the single-process render. Also: the driver's usage errors
exit 2.

usage: driver_local.py WORKDIR IRIS IRIS_SLURM EXR_CLOSE
"""
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import checks  # noqa: E402
from checks import check  # noqa: E402


def main():
    workdir, iris, driver, exr_close = (os.path.abspath(p) for p in sys.argv[1:5])
    shutil.rmtree(workdir, ignore_errors=True)
    os.makedirs(workdir)
    checks.verbose = True

    scene = ["cornell-box", "--seed", "5", "--max-depth", "3"]
    merged = os.path.join(workdir, "merged.exr")
    job = os.path.join(workdir, "job")
    r = subprocess.run([driver, "render", "--dry-run", "--workdir", job, "--iris", iris,
                        "-o", merged, "--spp", "6", "--parts", "2", "--tiles", "3x2",
                        "--width", "29", "--height", "17", "--"] + scene,
                       capture_output=True, text=True)
    print(r.stdout + r.stderr)
    check(r.returncode == 0 and "would run: sbatch" in r.stdout, "dry run writes scripts")
    env = dict(os.environ)
    for t in range(12):
        env["SLURM_ARRAY_TASK_ID"] = str(t)
        r = subprocess.run(["sh", os.path.join(job, "render-array.sh")], env=env,
                           capture_output=True, text=True)
        check(r.returncode == 0, f"array task {t}: {r.stderr.strip()}")
    env["SLURM_ARRAY_TASK_ID"] = "12"
    r = subprocess.run(["sh", os.path.join(job, "render-array.sh")], env=env,
                       capture_output=True, text=True)
    check(r.returncode == 2, "a task id beyond the array is refused")
    r = subprocess.run(["sh", os.path.join(job, "render-final.sh")], capture_output=True, text=True)
    print(r.stdout + r.stderr)
    check(r.returncode == 0 and "12 parts (6 windows)" in r.stderr, "merge job merges 12 parts")
    single = os.path.join(workdir, "single.exr")
    subprocess.run([iris, "render"] + scene + ["--spp", "6", "--width", "29", "--height", "17",
                   "--variance", "--quiet", "-o", single], check=True)
    r = subprocess.run([exr_close, merged, single], capture_output=True, text=True)
    print(r.stdout + r.stderr)
    check(r.returncode == 0, "tiles x partitions merge to the single render")

    # Guided: training job, then the array reading its guide, then the merge.
    gscene = ["door", "--method", "guided-nee", "--seed", "3", "--max-depth", "6"]
    gjob = os.path.join(workdir, "gjob")
    gmerged = os.path.join(workdir, "gmerged.exr")
    r = subprocess.run([driver, "render", "--dry-run", "--workdir", gjob, "--iris", iris,
                        "-o", gmerged, "--spp", "6", "--parts", "2", "--tiles", "2x1",
                        "--width", "32", "--height", "24", "--"] + gscene,
                       capture_output=True, text=True)
    print(r.stdout + r.stderr)
    sbatch_lines = [ln for ln in r.stdout.splitlines() if ln.startswith("would run: sbatch")]
    check(r.returncode == 0 and len(sbatch_lines) == 3 and "render-train.sh" in sbatch_lines[0]
          and "--dependency=afterok:" in sbatch_lines[1] and "render-array.sh" in sbatch_lines[1],
          "guided: training job, then the array depends on it")
    guide = os.path.join(gjob, "guide.bin")
    with open(os.path.join(gjob, "render-array.sh")) as f:
        check(f.read().count("--guide-in " + guide) == 4, "every task reads the guide")
    r = subprocess.run(["sh", os.path.join(gjob, "render-train.sh")], capture_output=True, text=True)
    check(r.returncode == 0 and os.path.exists(guide) and not os.path.exists(gmerged),
          f"training job writes the guide and no image: {r.stderr.strip()}")
    for t in range(4):
        env["SLURM_ARRAY_TASK_ID"] = str(t)
        r = subprocess.run(["sh", os.path.join(gjob, "render-array.sh")], env=env,
                           capture_output=True, text=True)
        check(r.returncode == 0, f"guided array task {t}: {r.stderr.strip()}")
    r = subprocess.run(["sh", os.path.join(gjob, "render-final.sh")], capture_output=True, text=True)
    check(r.returncode == 0, f"guided merge: {r.stderr.strip()}")
    gsingle = os.path.join(workdir, "gsingle.exr")
    subprocess.run([iris, "render"] + gscene + ["--spp", "6", "--width", "32", "--height", "24",
                   "--variance", "--quiet", "-o", gsingle], check=True)
    r = subprocess.run([exr_close, gmerged, gsingle], capture_output=True, text=True)
    print(r.stdout + r.stderr)
    check(r.returncode == 0, "guided: trained guide + tiles x partitions merge to the single render")

    def usage(args, needle):
        r = subprocess.run([driver] + args, capture_output=True, text=True)
        check(r.returncode == 2 and needle in r.stderr, f"iris-slurm {' '.join(args)} -> {needle}")

    base = ["render", "--dry-run", "--workdir", job, "--iris", iris, "-o", merged]
    usage(base + ["--spp", "4", "--tiles", "2x2", "--"] + scene, "needs --width and --height")
    usage(base + ["--spp", "4", "--parts", "5", "--"] + scene, "parts <= --spp")
    usage(base + ["--spp", "4", "--", "cornell-box", "--time", "3"], "--time")
    usage(base + ["--spp", "4", "--", "cornell-box", "--sample-offset=3"], "--sample-offset")
    usage(base + ["--spp", "4", "--", "door", "--method", "guided", "--guide-out", "g"], "--guide-out")
    usage(["sweep", "--dry-run", "--workdir", job, "--template", "echo {x}"], "no --set gives it")
    if not checks.failures:
        shutil.rmtree(workdir, ignore_errors=True)
    return checks.summary("slurm.driver_local")


if __name__ == "__main__":
    sys.exit(main())
