#!/usr/bin/env bash
# The GPU tests with no Vulkan adapter visible must pass by skipping, as they do on a machine
# without a Vulkan driver (the README's promise; `.ci/run` installs lavapipe, so the main test
# command never sees that case). Runs the test executables `cargo test --release --no-run`
# built, with the Vulkan loader pointed at no driver, and checks that each GPU test said it
# skipped.
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t exes < <(cargo test --release --locked --no-run --message-format=json 2>/dev/null | python3 -c '
import json, sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") != "compiler-artifact" or not m.get("executable"):
        continue
    pkg = m["package_id"]
    name = m["target"]["name"]
    if ("/crates/gpu#" in pkg and name in ("agreement", "equations")) or ("/crates/cli#" in pkg and name == "integration"):
        print(name + " " + m["executable"])
')
[ "${#exes[@]}" -eq 3 ] || { echo "expected the gpu tests' 2 executables and the CLI's: ${exes[*]}"; exit 1; }
log=$(mktemp)
for e in "${exes[@]}"; do
    name=${e%% *}
    exe=${e#* }
    filter=()
    [ "$name" = integration ] && filter=(gpu::)
    (cd "crates/$([ "$name" = integration ] && echo cli || echo gpu)" &&
        env -u MONOLAYER_GPU_REQUIRED VK_ICD_FILENAMES=/nonexistent.json VK_DRIVER_FILES=/nonexistent.json \
            XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}" "$exe" "${filter[@]}" --test-threads 1 --nocapture) >>"$log" 2>&1 ||
        { cat "$log"; echo "FAILED without an adapter: $name"; exit 1; }
done
skips=$(grep -c "skipped: .*no Vulkan adapter" "$log" || true)
passed=$(grep -Eo "test result: ok\. [0-9]+ passed" "$log" | awk '{s += $4} END {print s}')
echo "GPU tests without an adapter: $passed passed, $skips of them said they skipped"
[ "$skips" -ge 3 ] || { cat "$log"; echo "the GPU tests did not skip"; exit 1; }
