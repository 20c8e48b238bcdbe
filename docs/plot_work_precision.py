"""Draws docs/work_precision.png from docs/work_precision.csv (written by
`cargo bench -p monolayer-benches --bench work_precision`). Needs matplotlib."""
import csv
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

here = os.path.dirname(os.path.abspath(__file__))
rows = list(csv.DictReader(open(os.path.join(here, "work_precision.csv"))))

plt.rcParams["axes.prop_cycle"] = plt.cycler(color=plt.get_cmap("tab20").colors)
fig, axes = plt.subplots(1, 2, figsize=(13, 5.5))
groups = {}
for r in rows:
    if r.get("adaptive_tolerance"):
        key = ("full domain" if r["margin"] == "0" else "margin " + r["margin"]) + ", adaptive"
    elif r.get("precision") == "f32":
        key = ("full domain" if r["margin"] == "0" else "margin " + r["margin"]) + ", Heun, f32"
    elif r["config"].startswith("margin") and r["dt"] == "0.05":
        key = "patch margin (Heun, dt 0.05)"
    elif r["config"].startswith("full"):
        key = {"0": "full domain, Euler", "1": "full domain, Heun", "2": "full domain, Heun npc 2"}[r["npc"]]
    else:
        key = "margin " + r["margin"] + (", Euler" if r["npc"] == "0" else ", Heun")
    groups.setdefault(key, []).append(r)
for ax, col, label in ((axes[0], "centre_error", "largest centre-of-mass error (nodes)"),
                       (axes[1], "phi_error", "largest |Δφ|")):
    for key, rs in groups.items():
        rs = sorted(rs, key=lambda r: float(r["wall_s"]))
        xs = [float(r["wall_s"]) for r in rs]
        ys = [max(float(r[col]), 1e-16) for r in rs]
        style = "s--" if key.endswith("f32") else "^:" if key.endswith("adaptive") else "o-"
        ax.loglog(xs, ys, style, label=key, lw=2 if key.endswith("adaptive") else 1.5)
        for r, x, y in zip(rs, xs, ys):
            if key.startswith("patch"):
                tag = "m" + r["margin"]
            elif key.endswith("adaptive"):
                tag = "tol " + r["adaptive_tolerance"]
            else:
                tag = "dt " + r["dt"]
            ax.annotate(tag, (x, y), fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_xlabel("wall time for 20 TU, 60 cells, 2 threads (s)")
    ax.set_ylabel(label)
    ax.grid(True, which="both", alpha=0.3)
axes[0].legend(fontsize=7, ncol=2)
fig.suptitle("Work against precision; reference: full domain, Heun, dt 0.01, f64")
fig.tight_layout()
fig.savefig(os.path.join(here, "work_precision.png"), dpi=110)
print("wrote", os.path.join(here, "work_precision.png"))
