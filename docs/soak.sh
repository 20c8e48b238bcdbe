#!/usr/bin/env bash
# Soak run of issue 4: 1000 cells at the paper's density (408² lattice), 100 TU relaxation,
# then 10^4 TU at zeta = 0.005 with the default integrator (margin 16, dt 0.5, Heun, f32), on
# 2 threads. Prints the wall time, the peak memory, the mean cell area over three windows
# (a drift would show there) and the range of phi over the whole run.
# Usage: bash docs/soak.sh [OUT_DIR] [--set key=value ...]   (about 5 minutes on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-/tmp/monolayer-soak}
shift || true
cargo build --release -q
/usr/bin/time -f "wall %e s, peak RSS %M KB" target/release/monolayer run scenes/large.toml \
    --out "$out" --overwrite -q --threads 2 \
    --set cells.count=1000 --set domain.lx=408 --set domain.ly=408 \
    --set integrator.margin=16 --set integrator.dt=0.5 \
    --set run.relax_time=100 --set run.time=10000 \
    --set run.output_every=2500 --set run.series_every=10 "$@"
python3 - "$out" <<'PY'
import csv, statistics as st, sys
rows = list(csv.DictReader(open(sys.argv[1] + "/series.csv")))
active = [r for r in rows if float(r["time"]) >= 1000]
thirds = [active[i * len(active) // 3:(i + 1) * len(active) // 3] for i in range(3)]
for w in thirds:
    print(f"t {float(w[0]['time']):7.0f}-{float(w[-1]['time']):7.0f}: mean area {st.mean(float(r['area_mean']) for r in w):.3f}, "
          f"v_rms {st.mean(float(r['v_rms']) for r in w):.4f}")
print(f"phi range over the run: [{min(float(r['phi_min']) for r in rows):.3g}, {max(float(r['phi_max']) for r in rows):.3g}]")
PY
