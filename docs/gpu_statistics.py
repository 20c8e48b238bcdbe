#!/usr/bin/env python3
"""The verdict of docs/gpu_statistics.sh: do long active runs on the GPU backend agree with the
CPU backend statistically?

    python3 docs/gpu_statistics.py OUTDIR SEEDS SKIP   # reads OUTDIR/{cpu,gpu}-SEED/series.csv
    python3 docs/gpu_statistics.py --self-test         # the rule on synthetic data (CI runs it)

The statistic of a run: the time average after its relaxation and SKIP TU more of v_rms,
area_mean and s_rms. The rule, per quantity, from the difference of the seed means
Δ = m_gpu − m_cpu and its standard error se = √(s_cpu²/n + s_gpu²/n) (s the sample standard
deviations over the n seeds of each):
  - DIFFER when |Δ| > 3 se (Welch's t beyond 3: about 2 % by chance with 5 seeds a side);
  - AGREE when |Δ| + 2.3 se ≤ 5 % of the CPU's mean (the 95 % bound on the difference,
    t at 8 degrees of freedom, inside an equivalence margin of 5 %);
  - NOT ESTABLISHED otherwise (the seeds are too few, or the runs too short, to decide).
The verdict: the backends differ when one quantity differs, agree when all three agree, and
it is not established otherwise.
"""
import csv
import math
import random
import sys

NAMES = ["v_rms", "area_mean", "s_rms"]
# The equivalence margin, relative to the CPU's mean, and the two thresholds in standard errors.
MARGIN = 0.05
T_DIFFER = 3.0
T_BOUND = 2.3


def mean_sd(v):
    m = sum(v) / len(v)
    return m, math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1))


def compare(cpu, gpu):
    """One quantity's seed values on each backend -> (outcome, line), the outcome "agree",
    "differ" or "not established"."""
    (mc, sc), (mg, sg) = mean_sd(cpu), mean_sd(gpu)
    delta = mg - mc
    se = math.sqrt(sc**2 / len(cpu) + sg**2 / len(gpu))
    if abs(delta) > T_DIFFER * se:
        outcome = "differ"
    elif abs(delta) + T_BOUND * se <= MARGIN * abs(mc):
        outcome = "agree"
    else:
        outcome = "not established"
    return outcome, (
        f"cpu {mc:.5g} ± {sc:.2g}, gpu {mg:.5g} ± {sg:.2g} (mean ± sd over {len(cpu)} seeds); "
        f"Δ = {delta:.2g} ({delta / mc:+.2%}), se {se:.2g}: {outcome.upper()}"
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
    """Each outcome on synthetic seeds, 5 a side, 200 draws each:
    - the same distribution with a small spread (sd 1 % of the mean): agree in most draws;
    - a shift of 8 % with that spread (outside the margin; Δ/se ≈ 13): differ in all but a few;
    - the same distribution with a large spread (sd 10 %: 2.3 se alone passes the margin):
      not established in most, and never differ in more than a few."""
    rng = random.Random(29)
    draws = lambda mu, sd: [rng.gauss(mu, sd) for _ in range(5)]
    def count(mu_gpu, sd):
        tally = {"agree": 0, "differ": 0, "not established": 0}
        for _ in range(200):
            tally[compare(draws(100.0, sd), draws(mu_gpu, sd))[0]] += 1
        return tally
    same, shifted, noisy = count(100.0, 1.0), count(108.0, 1.0), count(100.0, 10.0)
    assert same["agree"] >= 180 and same["differ"] <= 10, f"same distribution: {same}"
    assert shifted["differ"] >= 190 and shifted["agree"] == 0, f"an 8 % shift: {shifted}"
    assert noisy["not established"] >= 180 and noisy["differ"] <= 10, f"a large spread: {noisy}"
    for outcomes, want in [(["agree"] * 3, "agree"), (["agree", "differ", "agree"], "differ"),
                           (["agree", "not established", "agree"], "not established")]:
        assert verdict(outcomes)[0] == want, (outcomes, want)
    print(f"gpu_statistics self-test: same distribution {same}; an 8 % shift {shifted}; "
          f"a 10 % spread {noisy}")


if __name__ == "__main__":
    if sys.argv[1:] == ["--self-test"]:
        self_test()
    else:
        main(sys.argv[1], int(sys.argv[2]), float(sys.argv[3]))
