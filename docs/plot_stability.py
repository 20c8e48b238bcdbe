"""Draws docs/stability.png from docs/stability.csv (written by
`cargo bench -p monolayer-benches --bench stability`). Needs matplotlib."""
import csv
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import matplotlib.ticker

here = os.path.dirname(os.path.abspath(__file__))
rows = list(csv.DictReader(open(os.path.join(here, "stability.csv"))))
single = [r for r in rows if "," not in r["case"] and not r["case"].startswith("held")]

fig, axes = plt.subplots(1, 5, figsize=(20, 4))
for ax, (param, label) in zip(axes, (("gamma", "γ"), ("kappa", "κ"), ("lambda", "λ"), ("zeta", "ζ"))):
    rs = sorted((r for r in single if r["case"].startswith(param)), key=lambda r: float(r[param]))
    xs = [float(r[param]) for r in rs]
    for col, name, style in (("dt_max_euler", "Euler", "o-"), ("dt_max_heun", "Heun", "s-"),
                             ("dt_estimate", "validator's estimate", "k--")):
        ax.plot(xs, [float(r[col]) for r in rs], style, label=name)
    ax.set_xlabel(label + " (others as the paper, ζ = 0.005)")
    ax.set_ylabel("largest stable dt")
    if param in ("gamma", "kappa"):
        ax.set_xscale("log")
        ax.set_yscale("log")
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.grid(True, which="both", alpha=0.3)
axes[0].legend(fontsize=8)

ax = axes[4]
for r in rows:
    est = float(r["dt_estimate"])
    meas = min(float(r["dt_max_euler"]), float(r["dt_max_heun"]))
    held = r["case"].startswith("held")
    ax.loglog(est, meas, "^" if held else "o", color="C3" if held else "C0")
lim = [0.1, 8]
ax.loglog(lim, lim, "k-", lw=0.8, label="measured = estimate")
ax.loglog([], [], "o", color="C0", label="fitted and one-parameter cases")
ax.loglog([], [], "^", color="C3", label="held-out cases")
ax.set_xlabel("validator's estimate")
ax.set_ylabel("measured limit, min(Euler, Heun)")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=8)
fig.suptitle("Largest stable time step, 60 cells, 200 TU; every point above the diagonal is safe")
fig.tight_layout()
fig.savefig(os.path.join(here, "stability.png"), dpi=100)
print("wrote", os.path.join(here, "stability.png"))
