#!/usr/bin/env python3
"""The verdict of docs/gpu_statistics.sh: do long active runs on the GPU backend agree with the
CPU backend statistically?

    python3 docs/gpu_statistics.py OUTDIR SEEDS SKIP   # reads OUTDIR/{cpu,gpu}-SEED/series.csv
    python3 docs/gpu_statistics.py --self-test         # the rule on synthetic data (CI runs it)

The statistic of a run: the time average over its active phase after SKIP TU of v_rms,
area_mean and s_rms. The rule, per quantity: the backends agree when the difference of their
seed means is within the seed spread (the larger of the two sample standard deviations over
seeds), and differ otherwise; the verdict is "agree" only when all three agree.
"""
import csv
import math
import random
import sys

NAMES = ["v_rms", "area_mean", "s_rms"]


def mean_sd(v):
    m = sum(v) / len(v)
    return m, math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1))


def compare(cpu, gpu):
    """One quantity's seed values on each backend -> (agree, line)."""
    (mc, sc), (mg, sg) = mean_sd(cpu), mean_sd(gpu)
    spread = max(sc, sg)
    ok = abs(mg - mc) <= spread
    return ok, (
        f"cpu {mc:.5g} ± {sc:.2g}, gpu {mg:.5g} ± {sg:.2g} (mean ± sd over {len(cpu)} seeds); "
        f"|Δ| = {abs(mg - mc):.2g} {'≤' if ok else '>'} spread {spread:.2g}: {'agree' if ok else 'DIFFER'}"
    )


def run_average(path, skip):
    with open(path) as f:
        r = list(csv.DictReader(f))
    active = [x for x in r if float(x["zeta"]) > 0]
    start = min(float(x["time"]) for x in active)
    use = [x for x in active if float(x["time"]) >= start + skip]
    return len(use), {n: sum(float(x[n]) for x in use) / len(use) for n in NAMES}


def main(out, seeds, skip):
    rows, stats = [], {}
    for backend in ["cpu", "gpu"]:
        for seed in range(1, seeds + 1):
            n, avg = run_average(f"{out}/{backend}-{seed}/series.csv", skip)
            rows.append({"backend": backend, "seed": seed, "rows": n, **avg})
            for k in NAMES:
                stats.setdefault((backend, k), []).append(avg[k])
    with open(f"{out}/runs.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["backend", "seed", "rows"] + NAMES)
        w.writeheader()
        w.writerows(rows)
    lines, agree = [], True
    for k in NAMES:
        ok, line = compare(stats[("cpu", k)], stats[("gpu", k)])
        agree &= ok
        lines.append(f"{k}: {line}")
    lines.append(
        "verdict: the backends agree within the seed spread"
        if agree
        else "verdict: the backends differ beyond the seed spread in at least one quantity"
    )
    open(f"{out}/verdict.txt", "w").write("\n".join(lines) + "\n")
    print("\n".join(lines))


def self_test():
    """Both outcomes on synthetic seeds: the same distribution agrees, a shift of 3 sd differs."""
    rng = random.Random(29)
    draws = lambda mu: [rng.gauss(mu, 1.0) for _ in range(5)]
    same = sum(compare(draws(10.0), draws(10.0))[0] for _ in range(200))
    shifted = sum(compare(draws(10.0), draws(13.0))[0] for _ in range(200))
    # Same distribution: |Δ| ~ N(0, sqrt(2/5)) against a spread near 1, agree in most draws
    # (about 90 %); a shift of 3 sd: agree in almost none.
    assert same >= 160, f"same distribution agreed in {same} of 200"
    assert shifted <= 10, f"a 3-sd shift agreed in {shifted} of 200"
    print(f"gpu_statistics self-test: same distribution agrees in {same}/200, a 3-sd shift in {shifted}/200")


if __name__ == "__main__":
    if sys.argv[1:] == ["--self-test"]:
        self_test()
    else:
        main(sys.argv[1], int(sys.argv[2]), float(sys.argv[3]))
