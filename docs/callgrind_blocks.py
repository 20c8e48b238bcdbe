#!/usr/bin/env python3
"""Instructions per node-update by function and by basic block, from two callgrind runs.

Issue 14's method (docs/performance.md): run callgrind with --dump-instr=yes on an
x86-64-v3 build of the `cost_per_cell` example at two step counts; the difference is the
cost of the extra steps, free of set-up. This script prints that difference per function of
the binary, and the heaviest straight-line blocks of instructions with their execution count
per node-update: a block run 1/8 as often as nodes are updated is a chunk of LANES = 8 nodes,
1/25 is once per patch column (margin 12), and so on, which tells kernel work from overhead.

    python3 docs/callgrind_blocks.py CG_SHORT CG_LONG NODE_UPDATES BINARY [MIN_WEIGHT] [--asm]

NODE_UPDATES = (extra steps) x cells x patch nodes x 2 evaluations per step.
Counts only instructions in BINARY (libc's memset and memcpy are left out: valgrind counts
a `rep stos` once per byte).
"""
import collections
import re
import subprocess
import sys


def parse(path, binary_name):
    """Ir per instruction address of the object `binary_name` in a callgrind file."""
    cost = collections.Counter()
    addr, skip, names, current = 0, False, {}, ""
    for line in open(path):
        if line.startswith(("ob=", "cob=")):
            m = re.match(r"c?ob=\((\d+)\)\s*(.*)", line.strip())
            if m.group(2):
                names[m.group(1)] = m.group(2)
            if line.startswith("ob="):
                current = names[m.group(1)]
            continue
        if line.startswith("calls="):
            skip = True  # the next cost line is the call's inclusive cost
            continue
        if line[:1] and line[0] in "0123456789+-*":
            parts = line.split()
            a = parts[0]
            if a.startswith("0x"):
                addr = int(a, 16)
            elif a[0] in "+-":
                step = int(a[1:], 16) if a[1:].startswith("0x") else int(a[1:])
                addr += step if a[0] == "+" else -step
            if skip:
                skip = False
                continue
            if len(parts) > 2 and binary_name in current:
                cost[addr] += int(parts[2])
        else:
            skip = False
    return cost


def main():
    short, long_, units, binary = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4]
    min_weight = float(sys.argv[5]) if len(sys.argv) > 5 and sys.argv[5] != "--asm" else 1.0
    show_asm = "--asm" in sys.argv
    name = binary.rsplit("/", 1)[-1]
    a, b = parse(short, name), parse(long_, name)
    diff = {k: v - a.get(k, 0) for k, v in b.items() if v - a.get(k, 0) > 0}
    dis, order, fn = {}, [], ""
    objdump = subprocess.run(["objdump", "-d", "-C", "--no-show-raw-insn", binary],
                             capture_output=True, text=True).stdout
    for line in objdump.splitlines():
        m = re.match(r"\s*([0-9a-f]+):\s+(.*)$", line)
        if m:
            ad = int(m.group(1), 16)
            dis[ad] = (fn, m.group(2))
            order.append(ad)
        else:
            m = re.match(r"[0-9a-f]+ <(.*)>:", line)
            if m:
                fn = m.group(1)[:100]
    per_fn = collections.Counter()
    for ad, v in diff.items():
        per_fn[dis.get(ad, ("?", ""))[0]] += v
    print(f"instructions per node-update in {name}: {sum(diff.values()) / units:.1f}")
    for f, v in per_fn.most_common(8):
        print(f"{v / units:7.2f}  {f}")
    # Blocks: consecutive instructions with one execution count.
    blocks, cur = [], None
    for ad in order:
        f, ins = dis[ad]
        c = diff.get(ad, 0)
        if cur and cur["fn"] == f and cur["c"] == c:
            cur["ins"].append((ad, ins))
        else:
            if cur:
                blocks.append(cur)
            cur = {"fn": f, "c": c, "ins": [(ad, ins)]}
    if cur:
        blocks.append(cur)
    print("\nblocks (weight = instructions per node-update; runs = executions per node-update)")
    for blk in sorted(blocks, key=lambda blk: -blk["c"] * len(blk["ins"])):
        w = blk["c"] * len(blk["ins"]) / units
        if w < min_weight:
            break
        print(f"{w:6.2f}  {len(blk['ins']):4d} instructions x {blk['c'] / units:.4f} runs  "
              f"{blk['fn'][:60]}  @{blk['ins'][0][0]:x}")
        if show_asm:
            for ad, ins in blk["ins"]:
                print(f"          {ad:x}: {ins}")


if __name__ == "__main__":
    main()
