#!/usr/bin/env bash
# Long active runs on the GPU backend against the CPU backend, statistically (issue 29): the
# paper's scene for SEEDS seeds (default 5) on each backend, each time-averaged over its
# active phase after a transient, then compared seed spread against seed spread.
#
#   bash docs/gpu_statistics.sh [OUTDIR]         # default out/gpu-statistics
#
# Environment: SEEDS (5), TIME (active time, 500 TU), SKIP (transient left out, 100 TU).
# The statistic of each run is the time average over t ∈ [relax + SKIP, relax + TIME] of
# v_rms, area_mean and s_rms (series.csv); the rule, per quantity: the backends agree when the
# difference of their seed means is within the seed spread (the larger of the two sample
# standard deviations over seeds), and differ otherwise. Writes runs.csv (one row per run)
# and verdict.txt. On lavapipe (the CPU Vulkan driver) a GPU run of 700 TU takes about 2 min.
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-out/gpu-statistics}"
seeds="${SEEDS:-5}"
time_="${TIME:-500}"
skip="${SKIP:-100}"
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
cargo build --release --quiet -p monolayer-cli --features gpu
mkdir -p "$out"
for backend in cpu gpu; do
    for seed in $(seq 1 "$seeds"); do
        dir="$out/$backend-$seed"
        target/release/monolayer run scenes/paper.toml --out "$dir" --overwrite --quiet \
            --set "integrator.backend=$backend" --set "run.seed=$seed" --set "run.time=$time_" \
            --set run.output_every="$time_" --set run.series_every=1
    done
done
python3 - "$out" "$seeds" "$skip" <<'PY'
import csv, math, sys
out, seeds, skip = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
names = ["v_rms", "area_mean", "s_rms"]
rows, stats = [], {}
for backend in ["cpu", "gpu"]:
    for seed in range(1, seeds + 1):
        with open(f"{out}/{backend}-{seed}/series.csv") as f:
            r = list(csv.DictReader(f))
        relax = min(float(x["time"]) for x in r if float(x["zeta"]) > 0)
        use = [x for x in r if float(x["zeta"]) > 0 and float(x["time"]) >= relax + skip]
        avg = {n: sum(float(x[n]) for x in use) / len(use) for n in names}
        rows.append({"backend": backend, "seed": seed, "rows": len(use), **avg})
        for n in names:
            stats.setdefault((backend, n), []).append(avg[n])
with open(f"{out}/runs.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=["backend", "seed", "rows"] + names)
    w.writeheader()
    w.writerows(rows)
def ms(v):
    m = sum(v) / len(v)
    return m, math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1))
lines, agree = [], True
for n in names:
    (mc, sc), (mg, sg) = ms(stats[("cpu", n)]), ms(stats[("gpu", n)])
    spread = max(sc, sg)
    ok = abs(mg - mc) <= spread
    agree &= ok
    lines.append(f"{n}: cpu {mc:.5g} ± {sc:.2g}, gpu {mg:.5g} ± {sg:.2g} (mean ± sd over {seeds} seeds); "
                 f"|Δ| = {abs(mg - mc):.2g} {'≤' if ok else '>'} spread {spread:.2g}: {'agree' if ok else 'DIFFER'}")
lines.append("verdict: the backends agree within the seed spread" if agree
             else "verdict: the backends differ beyond the seed spread in at least one quantity")
open(f"{out}/verdict.txt", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
