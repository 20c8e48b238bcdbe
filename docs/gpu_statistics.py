#!/usr/bin/env python3
"""The verdict of docs/gpu_statistics.sh: do long active runs on the GPU backend agree with the
CPU backend statistically?

    python3 docs/gpu_statistics.py OUTDIR SEEDS SKIP   # reads OUTDIR/{cpu,gpu}-SEED/series.csv
    python3 docs/gpu_statistics.py --self-test         # the rule on synthetic data (CI runs it)

The statistic of a run: the time average after its relaxation and SKIP TU more of v_rms,
area_mean and s_rms. Seed s starts both backends from the same state, so the comparison is
paired: per quantity, the differences d_s = gpu_s − cpu_s over the n seeds, their mean d̄ and
its standard error se = sd(d)/√n. (A scene that is not chaotic over the run keeps each pair
within round-off, and se is tiny; a chaotic one decorrelates them, and se is about the seed
spread. The pairing is valid either way.) The rule:
  - DIFFER when |d̄| > 4 se and |d̄| > 1e-6 of the CPU's mean (beyond chance: t at 4
    degrees of freedom exceeds 4 in 1.6 % of draws; and beyond f32 round-off);
  - AGREE when |d̄| + 2.8 se ≤ 5 % of the CPU's mean (the 95 % bound on the difference, t at 4
    degrees of freedom, inside an equivalence margin of 5 %);
  - NOT ESTABLISHED otherwise (too few seeds, or runs too short, to decide).
The verdict: the backends differ when one quantity differs, agree when all three agree, and
it is not established otherwise.
"""
import csv
import math
import random
import sys

NAMES = ["v_rms", "area_mean", "s_rms"]
# The equivalence margin and the floor of a difference (relative to the CPU's mean), and the
# two thresholds in standard errors (t at n − 1 = 4 degrees of freedom).
MARGIN = 0.05
FLOOR = 1e-6
T_DIFFER = 4.0
T_BOUND = 2.8


def mean_sd(v):
    m = sum(v) / len(v)
    return m, math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1))


def compare(cpu, gpu):
    """One quantity's values on each backend, seed by seed (paired) -> (outcome, line), the
    outcome "agree", "differ" or "not established"."""
    (mc, sc), (mg, sg) = mean_sd(cpu), mean_sd(gpu)
    d, sd = mean_sd([g - c for c, g in zip(cpu, gpu)])
    se = sd / math.sqrt(len(cpu))
    if abs(d) > T_DIFFER * se and abs(d) > FLOOR * abs(mc):
        outcome = "differ"
    elif abs(d) + T_BOUND * se <= MARGIN * abs(mc):
        outcome = "agree"
    else:
        outcome = "not established"
    return outcome, (
        f"cpu {mc:.5g} ± {sc:.2g}, gpu {mg:.5g} ± {sg:.2g} (mean ± sd over {len(cpu)} seeds); "
        f"paired difference {d:.2g} ({d / mc:+.2%}) ± se {se:.2g}: {outcome.upper()}"
    )


def verdict(outcomes):
    if "differ" in outcomes:
        return "differ", "verdict: the backends differ beyond the seed spread in at least one quantity"
    if all(o == "agree" for o in outcomes):
        return "agree", f"verdict: the backends agree (each quantity within {MARGIN:.0%}, at 95 %)"
    return "not established", "verdict: not established (no difference found, none excluded at the margin)"


def run_average(path, skip):
    """The time averages of a run's series.csv over t ≥ relax + skip, `relax` its scene's
    `run.relax_time` (from the run's own scene.toml: the activity and the terms start there)."""
    import os
    import tomllib
    with open(os.path.join(os.path.dirname(path), "scene.toml"), "rb") as f:
        relax = float(tomllib.load(f).get("run", {}).get("relax_time", 0.0))
    with open(path) as f:
        r = list(csv.DictReader(f))
    use = [x for x in r if float(x["time"]) >= relax + skip]
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
    lines, outcomes = [], []
    for k in NAMES:
        outcome, line = compare(stats[("cpu", k)], stats[("gpu", k)])
        outcomes.append(outcome)
        lines.append(f"{k}: {line}")
    lines.append(verdict(outcomes)[1])
    open(f"{out}/verdict.txt", "w").write("\n".join(lines) + "\n")
    print("\n".join(lines))


def self_test():
    """Each outcome on synthetic seeds, 5 pairs, 200 draws each. A seed's value is drawn
    around 100 with the seed spread (sd 10), and the GPU's is the CPU's plus its own part:
    - pairs within round-off (a scene that is not chaotic: 1e-8): agree in all;
    - decorrelated pairs of the same distribution with a small spread (sd 1, the GPU's its own
      draw): agree in most, differ in few;
    - a shift of 8 % (outside the margin) on decorrelated pairs of sd 1: differ in all;
    - decorrelated pairs of a large spread (sd 10 each): not established in most."""
    rng = random.Random(29)
    def count(shift, own, sd, paired):
        tally = {"agree": 0, "differ": 0, "not established": 0}
        for _ in range(200):
            cpu = [rng.gauss(100.0, sd) for _ in range(5)]
            if paired:
                gpu = [c + shift + rng.gauss(0.0, own) for c in cpu]
            else:
                gpu = [rng.gauss(100.0 + shift, sd) for _ in range(5)]
            tally[compare(cpu, gpu)[0]] += 1
        return tally
    close = count(0.0, 1e-8, 10.0, True)
    same = count(0.0, 0.0, 1.0, False)
    shifted = count(8.0, 0.0, 1.0, False)
    noisy = count(0.0, 0.0, 10.0, False)
    assert close["agree"] == 200, f"pairs within round-off: {close}"
    assert same["agree"] >= 170 and same["differ"] <= 10, f"same distribution: {same}"
    assert shifted["differ"] == 200, f"an 8 % shift: {shifted}"
    assert noisy["not established"] >= 180 and noisy["differ"] <= 10, f"a large spread: {noisy}"
    for outcomes, want in [(["agree"] * 3, "agree"), (["agree", "differ", "agree"], "differ"),
                           (["agree", "not established", "agree"], "not established")]:
        assert verdict(outcomes)[0] == want, (outcomes, want)
    print(f"gpu_statistics self-test: pairs within round-off {close}; same distribution {same}; "
          f"an 8 % shift {shifted}; a 10 % spread {noisy}")


if __name__ == "__main__":
    if sys.argv[1:] == ["--self-test"]:
        self_test()
    else:
        main(sys.argv[1], int(sys.argv[2]), float(sys.argv[3]))
