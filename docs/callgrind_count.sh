#!/usr/bin/env bash
# Instructions per node-update, issue 14's method (docs/performance.md): callgrind counts the
# timed steps of the `cost_per_cell` example on an x86-64-v3 build (valgrind cannot run
# AVX-512 code) at 2 and 6 steps; the difference, divided by 4 steps x N cells x patch nodes x
# 2 evaluations, is the cost of one node-update, free of set-up. libc's memset is left out
# (valgrind counts a `rep stos` once per byte, and whether LLVM calls memset to zero the
# lattice stripes changes from build to build); memcpy is counted.
#
# Usage, from the repository root:
#   bash docs/callgrind_count.sh [N L PRECISION RELAX_STEPS MARGIN]    (default 240 200 f32 250 12)
# Keeps /tmp/cg_count_{2,6}.out for docs/callgrind_blocks.py, with NODE_UPDATES as printed.
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-240}; l=${2:-200}; prec=${3:-f32}; relax=${4:-250}; margin=${5:-12}
target=${V3_TARGET:-/tmp/v3}
RUSTFLAGS="-C target-cpu=x86-64-v3" CARGO_TARGET_DIR="$target" \
    cargo build --release -q -p monolayer-benches --example cost_per_cell
bin="$target/release/examples/cost_per_cell"
for s in 2 6; do
    valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*time_steps*' --dump-instr=yes \
        --callgrind-out-file=/tmp/cg_count_$s.out "$bin" "$n" "$l" "$s" 1 "$prec" "$relax" "$margin" >/dev/null 2>&1
done
total() { grep -m1 "^summary:\|^totals:" "$1" | awk '{print $2}'; }
memset() { callgrind_annotate --inclusive=no "$1" 2>/dev/null | awk '/__memset/ && !n {gsub(",", "", $1); n = $1} END {print n + 0}'; }
side=$((2 * margin + 1))
updates=$((4 * n * side * side * 2))
ir=$(($(total /tmp/cg_count_6.out) - $(total /tmp/cg_count_2.out)))
ms=$(($(memset /tmp/cg_count_6.out) - $(memset /tmp/cg_count_2.out)))
echo "$n cells, ${l}², $prec, $relax relaxation steps, margin $margin: $(echo "scale=2; ($ir - $ms) / $updates" | bc) instructions per node-update ($(echo "scale=2; $ms / $updates" | bc) more in memset); NODE_UPDATES=$updates, binary $bin"
