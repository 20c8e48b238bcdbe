#!/usr/bin/env bash
# Long active runs of the work-precision study: time averages of v_rms, S_rms and the mean
# area over the last 500 TU of the paper scene (200 TU relaxation, 1000 TU at zeta = 0.005,
# paper pressure), five seeds per configuration (f64 storage unless marked f32), against the
# full-domain reference.
# Usage: bash docs/long_runs.sh [OUT_DIR]   (about 8 minutes on 2 cores; writes docs/long_runs.csv)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-/tmp/monolayer-long-runs}
cargo build --release -q
bin=target/release/monolayer
configs=("full-dt0.1:0:0.1" "m12-dt0.2:12:0.2" "m16-dt0.5:16:0.5" "m16-dt1:16:1.0" "m25-dt0.2:25:0.2" "m16-dt0.5-f32:16:0.5:f32")
for c in "${configs[@]}"; do
    IFS=: read -r name margin dt precision <<<"$c"
    for seed in 1 2 3 4 5; do
        "$bin" run scenes/paper.toml --out "$out/$name-$seed" --overwrite -q \
            --set integrator.margin="$margin" --set integrator.dt="$dt" --set run.seed="$seed" \
            --set integrator.precision="${precision:-f64}" \
            --set run.output_every=1200 --set run.series_every=1
    done
done
python3 - "$out" <<'PY'
import csv, statistics as st, sys
out = sys.argv[1]
rows = ["config,quantity,mean,std"]
for name in ["full-dt0.1", "m12-dt0.2", "m16-dt0.5", "m16-dt1", "m25-dt0.2", "m16-dt0.5-f32"]:
    per_seed = []
    for seed in range(1, 6):
        r = [x for x in csv.DictReader(open(f"{out}/{name}-{seed}/series.csv")) if float(x["time"]) >= 700]
        per_seed.append([st.mean(float(x[k]) for x in r) for k in ("v_rms", "s_rms", "area_mean")])
    for i, q in enumerate(("v_rms", "s_rms", "area_mean")):
        xs = [p[i] for p in per_seed]
        rows.append(f"{name},{q},{st.mean(xs):.5g},{st.stdev(xs):.3g}")
open("docs/long_runs.csv", "w").write("\n".join(rows) + "\n")
print("\n".join(rows))
PY
