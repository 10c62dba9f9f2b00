#!/usr/bin/python3
"""render.adaptive_cli: `iris render` with adaptive sampling from the command line.

Checks: bad values of --noise-threshold, --target-error and --min-spp (negative,
NaN, 0, out of range) and contradictory flags are refused with one line naming
the flag, exit 2 and no output file; --target-error reports the estimate it
reached and why it stopped (target reached, or the --spp/--time cap: never
both silently); a threshold render's --json says adaptive, with the per-pixel
spp range spread (some pixels stop at the minimum, some go further); --time
alone renders adaptively (relmse, no scouts), --adaptive off uniformly.

usage: test_adaptive_cli.py WORKDIR IRIS
"""
import json
import os
import shutil
import subprocess
import sys

failures = 0


def check(ok, what):
    global failures
    if not ok:
        failures += 1
        print("FAIL:", what)
    return ok


def run(iris, *args):
    return subprocess.run([iris, "render", *args], capture_output=True, text=True, timeout=300)


def main():
    work, iris = sys.argv[1], sys.argv[2]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    out = os.path.join(work, "out.exr")
    bad = [("--target-error", "-1"), ("--target-error", "nan"), ("--target-error", "0"),
           ("--noise-threshold", "0"), ("--noise-threshold", "-0.01"), ("--noise-threshold", "inf"),
           ("--min-spp", "0"), ("--adaptive", "sometimes")]
    for flag, value in bad:
        p = run(iris, "cornell-box", "--height", "16", "-o", out, flag, value)
        lines = [l for l in p.stderr.splitlines() if l.startswith("iris:")]
        check(p.returncode == 2, f"{flag} {value}: exit {p.returncode}")
        check(len(lines) == 1 and flag in lines[0], f"{flag} {value}: stderr {p.stderr.strip()!r}")
        check(not os.path.exists(out), f"{flag} {value}: wrote {out}")
    for args, why in [(["--adaptive", "freeze", "--target-error", "0.01"], "--noise-threshold"),
                      (["--adaptive", "off", "--noise-threshold", "0.01"], "adaptive"),
                      (["--noise-threshold", "0.01", "--spp", "16", "--min-spp", "32"], "--min-spp"),
                      (["--spp", "16", "--time", "1"], "--time"),
                      (["--spp", "16", "--time-total"], "--time")]:
        p = run(iris, "cornell-box", "--height", "16", "-o", out, *args)
        check(p.returncode == 2 and why in p.stderr, f"{args}: exit {p.returncode}, {p.stderr.strip()!r}")
        check(not os.path.exists(out), f"{args}: wrote {out}")

    # a reachable target: reached, with the estimate at most the target
    p = run(iris, "cornell-box", "--height", "24", "--method", "mis", "--target-error", "0.01", "--json", "-o", out)
    if check(p.returncode == 0, f"target run: exit {p.returncode} {p.stderr[-300:]}"):
        a = json.loads(p.stdout).get("adaptive", {})
        check(a.get("stop") == "target", f"target run stopped by {a.get('stop')}")
        check(0 < a.get("error_estimate", 1) <= 0.01, f"target run estimate {a.get('error_estimate')}")
    # an unreachable target under a small --spp cap: the cap says so
    p = run(iris, "cornell-box", "--height", "24", "--method", "mis", "--target-error", "1e-9", "--spp", "32",
            "--json", "-o", out)
    if check(p.returncode == 0, f"capped run: exit {p.returncode}"):
        a = json.loads(p.stdout).get("adaptive", {})
        check(a.get("stop") == "cap", f"capped run stopped by {a.get('stop')}")
        check(a.get("error_estimate", 0) > 1e-9, f"capped run claims {a.get('error_estimate')}")
    p = run(iris, "cornell-box", "--height", "24", "--method", "mis", "--target-error", "1e-9", "-o", out)
    check(p.returncode == 0 and "before the target" in p.stderr, f"capped run's summary: {p.stderr[-300:]!r}")
    # a threshold render: counts spread between the minimum and more
    p = run(iris, "cornell-box", "--height", "24", "--method", "mis", "--noise-threshold", "0.02", "--json",
            "-o", out)
    if check(p.returncode == 0, f"threshold run: exit {p.returncode}"):
        a = json.loads(p.stdout).get("adaptive", {})
        check(a.get("rule") == "relmse" and a.get("stop") in ("threshold", "cap"), f"threshold run {a}")
        check(a.get("spp_min", 0) >= 40 and a.get("spp_max", 0) > a.get("spp_min", 0),
              f"threshold run spp range {a.get('spp_min')}..{a.get('spp_max')}")
    # under --time without --spp adaptive sampling is the default (relmse, the
    # neighbours deciding: no scouts, counts spread); --adaptive off keeps every
    # pixel the same samples, and --spp keeps --time's meaning (refused together)
    p = run(iris, "env-spheres", "--height", "24", "--method", "mis", "--time", "1", "--json", "-o", out)
    if check(p.returncode == 0, f"--time run: exit {p.returncode} {p.stderr[-300:]}"):
        a = json.loads(p.stdout).get("adaptive", {})
        check(a.get("rule") == "relmse" and a.get("scout_spp_mean") == 0, f"--time run: {a}")
        check(0 < a.get("spp_min", 0) < a.get("spp_max", 0), f"--time run spp range {a.get('spp_min')}..{a.get('spp_max')}")
    p = run(iris, "env-spheres", "--height", "24", "--method", "mis", "--time", "1", "-o", out)
    check(p.returncode == 0 and "the --time budget spent" in p.stderr, f"--time run's summary: {p.stderr[-300:]!r}")
    p = run(iris, "env-spheres", "--height", "24", "--method", "mis", "--time", "1", "--adaptive", "off", "--json",
            "-o", out)
    if check(p.returncode == 0, f"--time --adaptive off run: exit {p.returncode}"):
        check("adaptive" not in json.loads(p.stdout), "--time --adaptive off rendered adaptively")
    print("render.adaptive_cli:", "ok" if failures == 0 else f"{failures} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
