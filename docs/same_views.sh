#!/usr/bin/env bash
# Are two binaries' outputs the same to the byte, beyond the runs that docs/same_outputs.sh
# compares: the analysis tables, the pictures and the ParaView files too, on three scenes that
# exercise the parts (the paper's model; polarity and two populations of their own ζ; dividing
# and extruded cells). The check behind issue 48's refactors.
#
# Usage, from the repository root:
#   bash docs/same_views.sh BINARY_A BINARY_B [OUT_DIR]
# Prints the files that differ (the lock files aside) and exits 1 if any does.
set -euo pipefail
cd "$(dirname "$0")/.."
a=$1
b=$2
out=${3:-$(mktemp -d /tmp/monolayer-views.XXXXXX)}
rm -rf "$out"
mkdir -p "$out"
cat > "$out/mix.toml" <<'T'
[domain]
lx = 80
ly = 80
[cells]
count = 16
radius = 7.0
[[population]]
name = "a"
count = 10
zeta = 0.01
[[population]]
name = "b"
count = 6
zeta = -0.005
[polarity]
alpha = 0.04
rotational_diffusion = 1e-3
align = "velocity"
align_rate = 1.0
[run]
relax_time = 10.0
time = 30.0
output_every = 5.0
series_every = 1.0
T
for side in a b; do
    bin=$a
    [ "$side" = b ] && bin=$b
    d="$out/$side"
    "$bin" run scenes/paper.toml --out "$d/paper" --quiet --threads 2 \
        --set run.relax_time=20 --set run.time=60 --set run.output_every=10
    "$bin" run "$out/mix.toml" --out "$d/mix" --quiet --threads 2
    "$bin" run scenes/proliferation.toml --out "$d/prolif" --quiet --threads 2 \
        --set domain.lx=100 --set domain.ly=100 --set cells.count=60 \
        --set division.cycle_time=40 --set division.cycle_spread=20 --set division.growth_time=10 \
        --set division.extrusion=0.15 --set run.relax_time=20 --set run.time=150 \
        --set run.output_every=10 --set run.checkpoint_every=50
    for r in paper mix prolif; do
        "$bin" analyze "$d/$r" -q
        "$bin" export vtk "$d/$r" -q
        "$bin" render "$d/$r" --out "$d/$r/png" --polarity --director --defects --colour population -q
    done
done
if diff -r -q -x .lock "$out/a" "$out/b"; then
    echo "the same: runs, analyses, pictures and ParaView files ($out)"
else
    exit 1
fi
