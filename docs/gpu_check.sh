#!/usr/bin/env bash
# The GPU backend on a machine with a GPU (issues 29 and 40), in one short lease: build here,
# carry the folder, run there within a fixed budget, read the results back.
#
#   bash docs/gpu_check.sh prepare          # here: builds into gpu-check/ (portable binaries,
#                                           # Debian packages of the Vulkan loader, vulkaninfo)
#   bash docs/gpu_check.sh run [OUTDIR]     # there, from the repository root; OUTDIR defaults
#                                           # to $OUT, else gpu-check/out
#   bash docs/gpu_check.sh verify OUTDIR    # anywhere: exits 1 unless every check is there
#                                           # and passed (CI runs all three on lavapipe)
#
# The device host has no cargo and no network, and may have another processor: `prepare`
# builds for the portable x86-64-v2 level (GPU_CHECK_CPU; Rust never fuses a multiply and an
# add, so the results are the same bits as a native build), into its own target directory
# (GPU_CHECK_TARGET, default target/gpu-check). GPU_CHECK_BUILD=workspace takes the
# workspace's own release test build instead, as it is (CI). The scenes are compiled into the
# binary.
#
# `run` stops every command by an overall budget (BUDGET_S, default 540 s: a device command
# may run 10 minutes) and writes each result the moment it has it:
#   results.txt   one `check=… key=value` line per measurement, as it ends
#   summary.txt   rewritten after each: throughput against the measured copy bandwidth,
#                 agreement, determinism, the tests
#   host.txt, vulkaninfo.txt, loader.txt (the Vulkan loader's own diagnosis when wgpu looked
#   for an adapter), tests.txt, log.txt (each command, its limit, its exit status and time)
# In the order of their value, so that a cut leaves the most important ones:
#   the adapter; the copy bandwidth; agreement with the CPU (AGREE_CELLS, default 960, after
#   AGREE_STEPS, default 100); determinism (the state hashed after DET_STEPS, default 100, at
#   DET_CELLS, default 10⁴, twice); the minimal model's throughput at SIZES (default 10⁴ 10⁵
#   10⁶); the shared-patch variant of the kernels against the plain ones (agreement at
#   DET_CELLS after DET_STEPS, and the minimal model's throughput at SIZES); the gpu crate's
#   tests; each extension's throughput at SIZES (or its refusal).
set -uo pipefail
cd "$(dirname "$0")/.."
DIR=$(realpath -m "${GPU_CHECK_DIR:-gpu-check}")
PARTS="polarity populations walls adhesion division"

prepare() {
    set -e
    local target=${GPU_CHECK_TARGET:-target/gpu-check}
    local flags="-C target-cpu=${GPU_CHECK_CPU:-x86-64-v2}"
    rm -rf "$DIR/bin"
    mkdir -p "$DIR/bin" "$DIR/debs"
    # The example and the gpu crate's test executables, picked from cargo's own list.
    local pick='
import json, shutil, sys
found = 0
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") != "compiler-artifact" or not m.get("executable"):
        continue
    if not m["manifest_path"].endswith("crates/gpu/Cargo.toml"):
        continue
    kind, name = m["target"]["kind"], m["target"]["name"]
    if kind == ["example"] and name == "gpu_check":
        shutil.copy(m["executable"], sys.argv[1] + "/bin/gpu_check"); found += 1
    elif kind == ["test"]:
        shutil.copy(m["executable"], sys.argv[1] + "/bin/test-" + name); found += 1
sys.exit(0 if found >= 2 else "gpu_check: the example or the tests were not built")
'
    if [ "${GPU_CHECK_BUILD:-portable}" = workspace ]; then
        # CI: the workspace's own release test build (this machine's flags), which builds the
        # examples too and is already there; nothing is compiled again.
        cargo test --release --locked --no-run --message-format=json 2>/dev/null | python3 -c "$pick" "$DIR"
        flags="(the workspace's)"
    else
        RUSTFLAGS="$flags" CARGO_TARGET_DIR="$target" cargo build --release --locked -q -p gpu --example gpu_check
        RUSTFLAGS="$flags" CARGO_TARGET_DIR="$target" cargo test --release --locked -q -p gpu --no-run \
            --message-format=json 2>/dev/null | python3 -c "$pick" "$DIR"
        # `cargo build` names no example in `cargo test`'s list: copied here.
        cp "$target/release/examples/gpu_check" "$DIR/bin/"
    fi
    ls "$DIR"/bin/gpu_check "$DIR"/bin/test-* >/dev/null
    # The Vulkan loader, vulkaninfo and what the NVIDIA driver's ICD loads, as packages that
    # `run` unpacks without installing (GPU_CHECK_DEBS=0 skips the download).
    if [ "${GPU_CHECK_DEBS:-1}" != 0 ]; then
        (cd "$DIR/debs" && apt-get download libvulkan1 vulkan-tools libwayland-client0 libffi8 \
            libglvnd0 libegl1 libgl1 libglx0 libgles2 libx11-6 libxcb1 libxau6 libxdmcp6 libxext6 \
            libbsd0 libmd0 >/dev/null 2>&1) || echo "warning: some packages were not downloaded" >&2
    fi
    {
        echo "commit $(git rev-parse HEAD 2>/dev/null || echo unknown)"
        echo "built $(date -u +%FT%TZ) on $(uname -m), RUSTFLAGS=$flags"
        rustc --version
    } >"$DIR/build.txt"
    du -sh "$DIR"
}

run() {
    local out="${1:-${OUT:-$DIR/out}}"
    local budget=${BUDGET_S:-540} start
    start=$(date +%s)
    mkdir -p "$out" "$DIR/sys"
    : >"$out/results.txt"
    : >"$out/log.txt"
    : >"$out/tests.txt"
    cp "$DIR/build.txt" "$out/" 2>/dev/null || true
    left() { echo $((budget - ($(date +%s) - start))); }
    # `step LIMIT FILE CMD...`: CMD's stdout appended to FILE, under the smaller of LIMIT and
    # what the budget has left (less 15 s for the summary); skipped when under 10 s are left.
    step() {
        local limit=$1 file=$2 t0 rc
        shift 2
        local t=$(($(left) - 15))
        [ "$t" -gt "$limit" ] && t=$limit
        if [ "$t" -lt 10 ]; then
            echo "skipped (budget): $*" | tee -a "$out/log.txt" >>"$out/results.txt"
            return 0
        fi
        t0=$(date +%s)
        timeout -k 5 "$t" "$@" >>"$file" 2>>"$out/log.txt"
        rc=$?
        echo "[$(($(date +%s) - start)) s] exit $rc after $(($(date +%s) - t0)) s (limit $t s): $*" >>"$out/log.txt"
        if [ "$rc" = 124 ] || [ "$rc" = 137 ]; then
            echo "timed out after $t s: $*" >>"$file"
        fi
        summary "$out"
    }
    for d in "$DIR"/debs/*.deb; do [ -f "$d" ] && dpkg -x "$d" "$DIR/sys"; done
    export LD_LIBRARY_PATH="$DIR/sys/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    export PATH="$DIR/sys/usr/bin:$PATH"
    export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
    if [ -z "${VK_DRIVER_FILES:-}${VK_ICD_FILENAMES:-}" ]; then
        for f in /usr/share/vulkan/icd.d/nvidia*.json /etc/vulkan/icd.d/nvidia*.json \
            /usr/local/nvidia/share/vulkan/icd.d/*.json; do
            if [ -f "$f" ]; then export VK_DRIVER_FILES="$f"; break; fi
        done
    fi
    {
        echo "VK_DRIVER_FILES=${VK_DRIVER_FILES:-} VK_ICD_FILENAMES=${VK_ICD_FILENAMES:-}"
        uname -a
        grep -m1 "model name" /proc/cpuinfo
        nproc
        nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.memory --format=csv 2>&1
        nvidia-smi 2>&1
    } >"$out/host.txt" 2>&1
    timeout 30 vulkaninfo --summary >"$out/vulkaninfo.txt" 2>&1 || echo "vulkaninfo: exit $?" >>"$out/vulkaninfo.txt"
    local bin="$DIR/bin/gpu_check" r="$out/results.txt"
    # The loader's own account of the drivers it found, once, beside the adapter wgpu chose.
    VK_LOADER_DEBUG=error,warn,info timeout -k 5 60 "$bin" adapter >>"$r" 2>"$out/loader.txt"
    echo "[$(($(date +%s) - start)) s] exit $? : $bin adapter" >>"$out/log.txt"
    step 60 "$r" "$bin" bandwidth "${BANDWIDTH_MIB:-1024}"
    step 120 "$r" "$bin" agree "${AGREE_CELLS:-960}" "${AGREE_STEPS:-100}"
    step 120 "$r" "$bin" determinism "${DET_CELLS:-10000}" "${DET_STEPS:-100}"
    local sizes=${SIZES:-10000 100000 1000000}
    for n in $sizes; do step 150 "$r" "$bin" throughput "$n" minimal "${STEPS:-20}"; done
    # The faster variant against the plain kernels, which only a device can time.
    step 120 "$r" "$bin" variants "${DET_CELLS:-10000}" "${DET_STEPS:-100}"
    for n in $sizes; do
        step 150 "$r" "$bin" throughput "$n" minimal "${STEPS:-20}" shared-patch
    done
    for t in "$DIR"/bin/test-*; do
        echo "== $(basename "$t")" >>"$out/tests.txt"
        MONOLAYER_GPU_REQUIRED=1 step 120 "$out/tests.txt" "$t" --test-threads 1
        echo "== exit of $(basename "$t"): see log.txt" >>"$out/tests.txt"
    done
    for p in $PARTS; do
        for n in $sizes; do step 150 "$r" "$bin" throughput "$n" "$p" "${STEPS:-20}"; done
    done
    echo "[$(($(date +%s) - start)) s of $budget] done" >>"$out/log.txt"
    summary "$out"
    cat "$out/summary.txt"
}

# The summary of OUTDIR's results so far (rewritten after every command).
summary() {
    python3 - "$1" <<'PY' || true
import re, sys
out = sys.argv[1]
rows = [{**dict(re.findall(r'(\w+)=("[^"]*"|\S+)', l)), "line": l.strip()} for l in open(out + "/results.txt")]
bw = next((float(r["copy_gb_s"]) for r in rows if r.get("check") == "bandwidth"), None)
lines = []
for r in rows:
    c = r.get("check")
    if c == "adapter":
        lines.append(f'adapter: {r["adapter"]}')
    elif c == "bandwidth":
        lines.append(f'copy bandwidth: {bw:.1f} GB/s (read + write)')
    elif c == "throughput" and "node_updates_per_s" in r:
        rate, b = float(r["node_updates_per_s"]), float(r["bytes_per_node_update"])
        roof = f', {rate * b / (bw * 1e9):.2f} of the copy roof' if bw else ""
        s = float(r["s_per_step"])
        lines.append(f'{r["part"]:>11} {r.get("variant", "plain"):>12} {int(r["cells"]):>8} cells, {r["chunks"]} chunk(s): {rate:.2e} node-updates/s, '
                     f'{b} B each{roof}; {s * 1e3:.2f} ms a step, 10^4 TU at dt 0.2 in {s * 5e4 / 60:.1f} min')
    elif c == "throughput":
        lines.append(f'{r["part"]:>11} {int(r["cells"]):>8} cells: refused ({r.get("refused", "?")})')
    elif c == "agree":
        lines.append(f'agreement with the CPU, {r["cells"]} cells, {r["steps"]} steps: max |dphi| {r["max_dphi"]} '
                     f'(bound {r["bound_phi"]}), centres {r["max_dcentre"]} (bound {r["bound_centre"]}): {r["agree"]}')
    elif c == "variants":
        lines.append(f'shared-patch against plain, {r["cells"]} cells, {r["steps"]} steps: max |dphi| {r["max_dphi"]} '
                     f'(bound {r["bound_phi"]}), the same bits: {r["identical"]}; agree: {r["agree"]}')
    elif c == "determinism":
        lines.append(f'determinism, {r["cells"]} cells, {r["steps"]} steps: {r["hash_1"]} {r["hash_2"]}: {r["identical"]}')
    else:
        lines.append(r["line"])
tests = open(out + "/tests.txt").read()
lines.append(f'tests: {tests.count("test result: ok")} executables ok, {tests.count("test result: FAILED")} failed, '
             f'{tests.count("timed out")} timed out')
open(out + "/summary.txt", "w").write("\n".join(lines) + "\n")
PY
}

# Exits 1 unless OUTDIR has every check, each passed: vulkaninfo's summary and the loader's
# diagnosis, the adapter, a bandwidth, agreement and
# determinism `yes`, a throughput line (or a refusal, for an extension) at every size of
# SIZES for every part, and every test executable ok.
verify() {
    python3 - "$1" "${SIZES:-10000 100000 1000000}" "$PARTS" <<'PY'
import re, sys
out, sizes, parts = sys.argv[1], sys.argv[2].split(), ["minimal"] + sys.argv[3].split()
rows = [dict(re.findall(r'(\w+)=("[^"]*"|\S+)', l)) for l in open(out + "/results.txt")]
bad = []
def one(check, **kv):
    rs = [r for r in rows if r.get("check") == check and all(r.get(k) == v for k, v in kv.items())]
    if not rs:
        bad.append(f"no {check} {kv}")
    return rs[0] if rs else {}
one("adapter")
one("bandwidth")
if one("agree").get("agree", "yes") != "yes":
    bad.append("the GPU does not agree with the CPU")
if one("determinism").get("identical", "yes") != "yes":
    bad.append("two runs differ")
if one("variants").get("agree", "yes") != "yes":
    bad.append("the shared-patch variant does not agree with the plain kernels")
for p in parts:
    for n in sizes:
        r = one("throughput", part=p, cells=n, variant="plain")
        if r and "node_updates_per_s" not in r and (p == "minimal" or "refused" not in r):
            bad.append(f"throughput {p} {n}: {r}")
for n in sizes:
    # The variant may be refused (a device with too little workgroup memory), not fail.
    r = one("throughput", part="minimal", cells=n, variant="shared-patch")
    if r and "node_updates_per_s" not in r and "refused" not in r:
        bad.append(f"throughput minimal shared-patch {n}: {r}")
tests = open(out + "/tests.txt").read()
if "test result: ok" not in tests or "FAILED" in tests or "timed out" in tests:
    bad.append("the tests did not all pass (tests.txt)")
if "Vulkan Instance Version" not in open(out + "/vulkaninfo.txt").read():
    bad.append("vulkaninfo --summary did not run (vulkaninfo.txt)")
if "Loader" not in open(out + "/loader.txt").read():
    bad.append("the loader's diagnosis is missing (loader.txt)")
if "error=" in open(out + "/results.txt").read():
    bad.append("a command failed (results.txt)")
print("\n".join(bad) if bad else f"gpu_check: every check is there and passed ({out})")
sys.exit(1 if bad else 0)
PY
}

case "${1:-}" in
prepare) prepare ;;
run) shift; run "$@" ;;
verify) shift; verify "${1:?verify OUTDIR}" ;;
*) echo "usage: bash docs/gpu_check.sh prepare | run [OUTDIR] | verify OUTDIR" >&2; exit 2 ;;
esac
