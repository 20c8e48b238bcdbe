#!/usr/bin/env bash
# Are two builds' outputs identical to the byte? The check behind every "bit-identical" speed-up
# of issue 14: short runs of 240 cells on 200² (10 TU of relaxation, then 20 TU at zeta = 0.005,
# frames and checkpoints every 10 TU, series every 5), with both pressure forms, in f32 and f64,
# on 2 threads, by each build; then `diff -r` of the two output folders (frames, checkpoints,
# series.csv, run.json; not the lock file, which holds the pid and the time).
#
# Usage, from the repository root:
#   bash docs/same_outputs.sh OTHER_COMMIT          # builds OTHER_COMMIT in a worktree, compares with this tree
#   bash docs/same_outputs.sh BINARY_A BINARY_B     # compares two monolayer binaries
# Exits 1 if any output differs.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -eq 1 ]; then
    tree=$(mktemp -d /tmp/monolayer-other.XXXXXX)
    git worktree add -q --detach "$tree" "$1"
    trap 'git worktree remove --force "$tree"' EXIT
    (cd "$tree" && CARGO_TARGET_DIR="${OTHER_TARGET:-/tmp/monolayer-other-target}" cargo build --release -q -p monolayer-cli)
    cargo build --release -q -p monolayer-cli
    a="${OTHER_TARGET:-/tmp/monolayer-other-target}/release/monolayer"
    b=target/release/monolayer
else
    a=$1
    b=$2
fi
out=$(mktemp -d /tmp/monolayer-same.XXXXXX)
status=0
for pressure in paper interaction; do
    for precision in f32 f64; do
        for side in a b; do
            bin=$a
            [ $side = b ] && bin=$b
            "$bin" run scenes/large.toml --out "$out/$side" --overwrite -q --threads 2 \
                --set cells.count=240 --set domain.lx=200 --set domain.ly=200 \
                --set "model.pressure=\"$pressure\"" --set "integrator.precision=\"$precision\"" \
                --set run.relax_time=10 --set run.time=20 --set run.output_every=10 \
                --set run.series_every=5 --set run.checkpoint_every=10
        done
        n=$(diff -rq -x .lock "$out/a" "$out/b" | wc -l || true)
        echo "$pressure, $precision: $n differing files"
        if [ "$n" -ne 0 ]; then
            diff -rq -x .lock "$out/a" "$out/b" | head -5 || true
            status=1
        fi
    done
done
rm -rf "$out"
exit $status
