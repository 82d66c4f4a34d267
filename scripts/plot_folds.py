#!/usr/bin/python3
"""Fold counts against resolution: scripts/plot_folds.py RESULTS.csv OUT.png

One panel per case (twist, compress) and count (circumferential: median over 9 heights of the
r(theta) peaks; axial: median over 16 half-planes of the r(s) peaks). x: control vertices (log
scale); one colour per method; each seed's run is a small marker (spread a little sideways so
that equal counts stay visible), the line joins the mean over the seeds at each mesh. The theory
band of the row (circumferential_theory_lo/hi, axial_theory_lo/hi) is shaded grey; panels without
one say so. Only rows with status "ok" are drawn; failed or unstable runs are marked with an x on
the lower edge of the panel.
Written by `clothsim study folds` (app/study_folds.cpp); needs Debian's python3-matplotlib.
"""
import csv
import math
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    sys.exit(3)

COLOURS = {"loop_kl": "#1f77b4", "linear_fe": "#d62728", "mass_spring": "#2ca02c"}
OTHER_COLOURS = ["#9467bd", "#8c564b", "#e377c2", "#7f7f7f"]
CASE_TITLES = {"twist": "twisted sleeve (90°)", "compress": "compressed sleeve (6 cm)"}
COUNT_TITLES = {"circumferential": "circumferential folds (r(θ) peaks)", "axial": "folds along the axis (r(s) peaks)"}


def number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return float("nan")


def main():
    if len(sys.argv) != 3:
        print("usage: plot_folds.py RESULTS.csv OUT.png", file=sys.stderr)
        return 2
    with open(sys.argv[1], newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        print("plot_folds.py: no runs in " + sys.argv[1], file=sys.stderr)
        return 1

    cases = []
    methods = []
    for r in rows:
        if r["case"] not in cases:
            cases.append(r["case"])
        if r["method"] not in methods:
            methods.append(r["method"])
    colour = {}
    for i, m in enumerate(methods):
        colour[m] = COLOURS.get(m, OTHER_COLOURS[i % len(OTHER_COLOURS)])
    seeds = sorted({int(r["seed"]) for r in rows})
    offset = {s: (k - (len(seeds) - 1) / 2.0) * 0.025 for k, s in enumerate(seeds)}  # in log10 units
    moffset = {m: (k - (len(methods) - 1) / 2.0) * 0.012 for k, m in enumerate(methods)}

    counts = ["circumferential", "axial"]
    fig, axes = plt.subplots(len(cases), 2, figsize=(10.5, 3.6 * len(cases)), squeeze=False)
    for ci, case in enumerate(cases):
        case_rows = [r for r in rows if r["case"] == case]
        for ki, count in enumerate(counts):
            ax = axes[ci][ki]
            lo = number(case_rows[0][count + "_theory_lo"])
            hi = number(case_rows[0][count + "_theory_hi"])
            if math.isfinite(lo) and math.isfinite(hi):
                ax.axhspan(lo, hi, color="0.85", zorder=0, label=f"theory {lo:.1f}–{hi:.1f}")
            else:
                ax.text(0.98, 0.95, "no theory band", transform=ax.transAxes, ha="right", va="top",
                        fontsize=8, color="0.4")
            top = hi if math.isfinite(hi) else 0.0
            for m in methods:
                mrows = [r for r in case_rows if r["method"] == m]
                by_vertices = {}
                for r in mrows:
                    v = int(r["vertices"])
                    value = number(r[count + "_median"])
                    x = v * 10 ** (offset[int(r["seed"])] + moffset[m])
                    if r["status"] != "ok" or not math.isfinite(value):
                        ax.plot([x], [0], marker="x", color=colour[m], ms=7, mew=1.5, clip_on=False, zorder=4)
                        continue
                    by_vertices.setdefault(v, []).append(value)
                    ax.plot([x], [value], marker="o", ls="", ms=4.5, color=colour[m], alpha=0.75, zorder=3)
                    top = max(top, value)
                xs = sorted(by_vertices)
                means = [sum(by_vertices[v]) / len(by_vertices[v]) for v in xs]
                ax.plot([v * 10 ** moffset[m] for v in xs], means, "-", color=colour[m], lw=1.4, label=m, zorder=2)
            ax.set_xscale("log")
            ax.set_ylim(bottom=0, top=1.15 * top + 1)
            vs = sorted({int(r["vertices"]) for r in case_rows})
            ax.set_xticks(vs)
            ax.set_xticklabels([str(v) for v in vs], fontsize=8)
            ax.minorticks_off()
            ax.set_xlabel("control vertices")
            ax.set_ylabel("folds (median)")
            ax.set_title(f"{CASE_TITLES.get(case, case)}: {COUNT_TITLES[count]}", fontsize=9)
            ax.grid(True, axis="y", color="0.9", lw=0.6)
            ax.legend(fontsize=7, loc="upper left")
    first = rows[0]
    fig.suptitle(
        f"Fold counts at the end of the runs ({first['preset']}, t_eff = {number(first['t_eff']) * 1e3:.3g} mm, "
        f"imperfection {number(first['amplitude']) * 1e3:.3g} mm, seeds {', '.join(str(s) for s in seeds)}: dots)",
        fontsize=10)
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=90)
    return 0


if __name__ == "__main__":
    sys.exit(main())
