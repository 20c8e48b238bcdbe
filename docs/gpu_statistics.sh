#!/usr/bin/env bash
# Long active runs on the GPU backend against the CPU backend, statistically (issues 29 and
# 40): each scene of SCENES for SEEDS seeds on each backend, each run time-averaged over its
# active phase after a transient, then compared seed spread against seed spread by
# docs/gpu_statistics.py (three outcomes: agree, differ, not established; its docstring has
# the rule, and `--self-test` tests each outcome on synthetic data).
#
#   bash docs/gpu_statistics.sh [OUTDIR]         # default out/gpu-statistics
#
# Environment:
#   SCENES  shipped scenes (default: paper.toml; every scene the GPU runs:
#           "paper.toml polar.toml disc.toml wound.toml extensile_contractile.toml mixture.toml
#            channel.toml doublet.toml walker.toml single.toml")
#   SEEDS   seeds per backend (5)
#   TIME    active time in TU (500), SKIP the transient left out (100), RELAX the relaxation
#           (the scene's when unset)
#   GPU_SET extra `--set` overrides for the GPU's runs only, to show that the verdict can
#           fail (`GPU_SET="polarity.alpha=0.05"` on polar.toml: a GPU run of other physics)
# Writes OUTDIR/SCENE/{cpu,gpu}-SEED/ (the runs), OUTDIR/SCENE/runs.csv and verdict.txt, and
# OUTDIR/summary.txt (one verdict line per scene). On lavapipe (the CPU Vulkan driver) a GPU run
# of the paper's scene for 700 TU takes about 2 min.
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-out/gpu-statistics}"
scenes="${SCENES:-paper.toml}"
seeds="${SEEDS:-5}"
time_="${TIME:-500}"
skip="${SKIP:-100}"
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
cargo build --release --quiet -p monolayer-cli --features gpu
mkdir -p "$out"
: >"$out/summary.txt"
for scene in $scenes; do
    name="${scene%.toml}"
    for backend in cpu gpu; do
        extra=()
        if [ "$backend" = gpu ]; then
            for s in ${GPU_SET:-}; do extra+=(--set "$s"); done
        fi
        if [ -n "${RELAX:-}" ]; then extra+=(--set "run.relax_time=$RELAX"); fi
        for seed in $(seq 1 "$seeds"); do
            target/release/monolayer run "scenes/$scene" --out "$out/$name/$backend-$seed" \
                --overwrite --quiet --set "integrator.backend=$backend" --set "run.seed=$seed" \
                --set "run.time=$time_" --set run.output_every="$time_" --set run.series_every=1 \
                "${extra[@]}"
        done
    done
    python3 docs/gpu_statistics.py "$out/$name" "$seeds" "$skip"
    echo "$scene: $(tail -1 "$out/$name/verdict.txt")" | tee -a "$out/summary.txt"
done
