#!/usr/bin/env bash
# The GPU backend on a machine with an NVIDIA GPU (issue 29): its tests, then its throughput at
# 960, 16 k, 262 k and 10⁶ cells against the memory-bandwidth roof.
#
# Such a machine has no cargo and no network: build here, carry the folder, run there.
#
#   bash docs/gpu_check.sh prepare          # here: builds into gpu-check/ (about 40 MB)
#   bash docs/gpu_check.sh run [OUTDIR]     # there, from the repository root: writes OUTDIR
#                                           # (default $OUT, else gpu-check/out)
#
# `prepare` builds the gpu crate's test executables and the `gpu_throughput` example in release
# and downloads the Vulkan loader (libvulkan1) and the GL/EGL dispatch libraries the NVIDIA
# driver's Vulkan ICD loads, as Debian packages; `run` unpacks them with dpkg -x (no install),
# points the loader at the NVIDIA ICD when it finds none of its own, and writes:
#   nvidia-smi.txt, vulkaninfo of the adapter (adapter.txt), the tests' output (tests.txt),
#   one line per size (throughput.txt) and a summary (summary.txt).
# Environment: BANDWIDTH_GB_S (default 4300, the copy bandwidth measured on an H200),
# STEPS (default 40), MARGIN (default 16), SIZES (default "960 16384 262144 1000000").
set -uo pipefail
cd "$(dirname "$0")/.."
DIR=gpu-check

prepare() {
    set -e
    mkdir -p "$DIR/bin" "$DIR/debs"
    cargo build --release -p monolayer-benches --example gpu_throughput
    cp target/release/examples/gpu_throughput "$DIR/bin/"
    cargo test --release -p gpu --no-run --message-format=json 2>/dev/null |
        python3 -c '
import json, sys, shutil
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m.get("executable") and m["target"]["kind"] == ["test"]:
        shutil.copy(m["executable"], sys.argv[1] + "/bin/" + m["target"]["name"])
        print("test executable:", m["target"]["name"])
' "$DIR"
    (cd "$DIR/debs" && apt-get download libvulkan1 libglvnd0 libegl1 libgl1 libglx0 libgles2 \
        libx11-6 libxcb1 libxau6 libxdmcp6 libxext6 libbsd0 libmd0 2>&1 | tail -1)
    du -sh "$DIR"
}

run() {
    local out="${1:-${OUT:-$DIR/out}}"
    mkdir -p "$out" "$DIR/sys"
    for d in "$DIR"/debs/*.deb; do dpkg -x "$d" "$DIR/sys"; done
    export LD_LIBRARY_PATH="$PWD/$DIR/sys/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
    if [ -z "${VK_DRIVER_FILES:-}" ]; then
        for f in /usr/share/vulkan/icd.d/nvidia*.json /etc/vulkan/icd.d/nvidia*.json \
            /usr/local/nvidia/share/vulkan/icd.d/*.json; do
            if [ -f "$f" ]; then export VK_DRIVER_FILES="$f"; break; fi
        done
    fi
    echo "VK_DRIVER_FILES=${VK_DRIVER_FILES:-}" >"$out/adapter.txt"
    nvidia-smi >"$out/nvidia-smi.txt" 2>&1 || true
    nvidia-smi --query-gpu=name,memory.total,clocks.max.memory --format=csv >>"$out/adapter.txt" 2>&1 || true
    {
        for t in "$DIR"/bin/*; do
            case "$(basename "$t")" in gpu_throughput) continue ;; esac
            echo "== $(basename "$t")"
            MONOLAYER_GPU_REQUIRED=1 timeout 300 "$t" --nocapture --test-threads 1 2>&1
            echo "exit $?"
        done
    } >"$out/tests.txt"
    : >"$out/throughput.txt"
    for n in ${SIZES:-960 16384 262144 1000000}; do
        timeout 240 "$DIR/bin/gpu_throughput" "$n" "${STEPS:-40}" "${MARGIN:-16}" "${BANDWIDTH_GB_S:-4300}" \
            >>"$out/throughput.txt" 2>&1 || echo "cells=$n failed (exit $?)" >>"$out/throughput.txt"
    done
    python3 - "$out" <<'PY' || true
import re, sys
out = sys.argv[1]
lines = []
for l in open(out + "/throughput.txt"):
    kv = dict(re.findall(r'(\w+)=("[^"]*"|\S+)', l))
    if "node_updates_per_s" not in kv:
        lines.append(l.strip())
        continue
    s = float(kv["s_per_step"])
    lines.append(
        f'{kv["cells"]:>8} cells, {kv["chunks"]} chunk(s): {float(kv["node_updates_per_s"]):.2e} node-updates/s, '
        f'{kv.get("roof_fraction", "?")} of the roof ({kv["bytes_per_node_update"]} B each); '
        f'10^4 TU: {s * 1e4 / 0.5 / 60:.1f} min at dt 0.5, {s * 1e4 / 0.2 / 60:.1f} min at dt 0.2')
tests = open(out + "/tests.txt").read()
lines.append(f'tests: {tests.count("test result: ok")} executables ok, {tests.count("FAILED")} FAILED lines')
open(out + "/summary.txt", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
}

case "${1:-}" in
prepare) prepare ;;
run) shift; run "$@" ;;
*) echo "usage: bash docs/gpu_check.sh prepare | run [OUTDIR]" >&2; exit 2 ;;
esac
