#!/bin/sh
# Equal-time comparison of mis / guided / guided-nee (docs/guiding.md, docs/performance.md).
#   bench/guiding/run.sh BUILD_DIR [OUT_DIR]
# Needs BUILD_DIR/bench/guiding/bench_guiding (cmake --build BUILD_DIR --target bench_guiding).
# For each scene: a long mis reference (kept in OUT_DIR, reused), then one
# render per method at a fixed spp on ONE thread, timed in CPU seconds of the
# process (robust on a shared machine; wall-clock budgets measure the
# neighbours). The error is relMSE_drop (eps = 0.01, the worst 0.1% of pixel
# channels dropped, as `iris bench` measures). Efficiency = relMSE_drop *
# (render_cpu + guide_cpu): relMSE at equal time up to a constant, lower is
# better. relMSE at equal time T, preprocessing included, is
#   relMSE_T = relMSE_drop * render_cpu / (T - guide_cpu)
# (variance ~ 1/samples for these unbiased estimators), T = BUDGET CPU seconds
# (default 16: an 8-second render on 2 cores). Errors and CPU times are means
# over SEEDS (heavy-tailed errors: one run is not enough). Environment: SCENES,
# HEIGHT (96), REF_SPP (2048; door-shielded 8192), MIS_SPP (64), GUIDED_SPP (24),
# BUDGET (16), SEEDS ("1 2 3"), EXTRA (extra bench_guiding options for the guided runs).
set -eu
BUILD=${1:?usage: run.sh BUILD_DIR [OUT_DIR]}
OUT=${2:-bench-guiding-out}
BIN="$BUILD/bench/guiding/bench_guiding"
SCENES=${SCENES:-"door door-shielded cornell-box veach-mis"}
SEEDS=${SEEDS:-"1 2 3"}
HEIGHT=${HEIGHT:-96}
REF_SPP=${REF_SPP:-2048}
MIS_SPP=${MIS_SPP:-64}
GUIDED_SPP=${GUIDED_SPP:-24}
EXTRA=${EXTRA:-}
BUDGET=${BUDGET:-16}
mkdir -p "$OUT"
RESULTS="$OUT/results.txt"
: > "$RESULTS"
for scene in $SCENES; do
  ref="$OUT/ref_$scene.exr"
  if [ ! -f "$ref" ]; then
    rs=$REF_SPP; [ "$scene" = door-shielded ] && rs=$((REF_SPP * 4))
    echo "reference $scene ($rs spp)..." >&2
    "$BIN" "$scene" mis --spp "$rs" --height "$HEIGHT" --seed 99 -o "$ref" >/dev/null
  fi
  for m in mis guided guided-nee; do
    spp=$GUIDED_SPP; opts=$EXTRA
    [ "$m" = mis ] && { spp=$MIS_SPP; opts=; }
    for seed in $SEEDS; do
      # shellcheck disable=SC2086
      line=$("$BIN" "$scene" "$m" --spp "$spp" --height "$HEIGHT" --threads 1 --seed "$seed" --ref "$ref" $opts 2>"$OUT/$scene-$m.log" | tail -1)
      grep "^iris: guiding" "$OUT/$scene-$m.log" >&2 || true
      echo "$line" | tee -a "$RESULTS" >&2
    done
  done
done
/usr/bin/python3 - "$RESULTS" "$BUDGET" <<'PY'
import sys
rows = {}
for line in open(sys.argv[1]):
    f = line.split()
    kv = dict(x.split("=", 1) for x in f[2:])
    rows.setdefault(f[0], {}).setdefault(f[1], []).append({k: float(v) for k, v in kv.items()})
# mean over seeds
rows = {s: {m: {k: sum(r[k] for r in rs) / len(rs) for k in rs[0]} for m, rs in ms.items()}
        for s, ms in rows.items()}
print("| scene | method | spp run | ksamples/CPU s | preprocessing CPU s (% of T) | relMSE_drop x CPU s | relMSE_drop at equal time T | vs mis |")
print("|---|---|---|---|---|---|---|---|")
for scene, ms in rows.items():
    T = float(sys.argv[2])
    base = None
    for m in ("mis", "guided", "guided-nee"):
        r = ms.get(m)
        if not r: continue
        left = T - r["guide_cpu"]
        eq = r["relMSE_drop"] * r["render_cpu"] / left if left > 0 else float("inf")
        eff = r["relMSE_drop"] * (r["render_cpu"] + r["guide_cpu"])
        if m == "mis": base = eq
        print(f"| {scene} | {m} | {int(r['spp'])} | {r['ksamples_per_cpu_s']:.0f} | "
              f"{r['guide_cpu']:.2f} ({100*r['guide_cpu']/T:.0f}%) | {eff:.4g} | {eq:.4g} | {eq/base:.2f}x |")
    print(f"|  | (T = {T:.2f} CPU s) | | | | | | |")
PY
