#!/usr/bin/python3
"""Heat map of the stability study: scripts/plot_stability.py RESULTS.csv OUT.png

One row per case, one column per criterion. Each cell's colour says how close the figure comes to
its pass limit (figure / limit on a log scale: green far below, yellow within a factor of 10,
red near or at the limit); the text is the figure itself. The limits come from the CSV
(energy_rise_limit, strain_limit, tolerance, iteration_limit). The last columns give the run's
outcome, the verdict with the base's solver settings (for cases that need more) and the verdict;
a * after a case name marks solver settings beyond the base (table.md).
Written by `clothsim study stability` (app/study_stability.cpp); needs Debian's python3-matplotlib.
"""
import csv
import math
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LinearSegmentedColormap
except ImportError:
    sys.exit(3)

FLOOR = 1e-4  # ratios below this get the greenest colour


def number(text):
    try:
        return float(text)
    except ValueError:
        return float("nan")


def short(value, kind):
    if math.isnan(value):
        return "NaN"
    if kind == "int":
        return str(int(value))
    if value == 0:
        return "0"
    return f"{value:.1e}".replace("e-0", "e-").replace("e+0", "e")


def base_solver_text(verdict):
    """'fail: energy rise 0.988 > 0.01' -> 'fail: rise 0.99'; 'fail: strain 2.26 > 1' -> 'fail: strain 2.3'."""
    if not verdict.startswith("fail"):
        return "pass"
    reason = verdict[len("fail: "):]
    for prefix, label in (("energy rise ", "rise "), ("strain ", "strain ")):
        if reason.startswith(prefix):
            figure = number(reason[len(prefix):].split(" ")[0])
            if not math.isnan(figure):
                return f"fail: {label}{figure:.2g}"
    return "fail"


def main():
    if len(sys.argv) != 3:
        print("usage: plot_stability.py RESULTS.csv OUT.png", file=sys.stderr)
        return 2
    with open(sys.argv[1], newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        print("plot_stability.py: no cases in " + sys.argv[1], file=sys.stderr)
        return 1

    # (title, value column, limit column, text kind)
    metrics = [
        ("energy rise", "energy_rise", "energy_rise_limit", "float"),
        ("max strain", "max_strain", "strain_limit", "float"),
        ("residual", "residual", "tolerance", "float"),
        ("max iterations", "max_iterations", "iteration_limit", "int"),
    ]
    cmap = LinearSegmentedColormap.from_list(
        "closeness", [(0.0, "#1a9850"), (0.5, "#a6d96a"), (0.75, "#fee08b"), (0.9, "#fdae61"), (1.0, "#d73027")]
    )
    n = len(rows)
    columns = len(metrics) + 3
    fig_height = 1.3 + 0.3 * n
    fig, ax = plt.subplots(figsize=(10.4, fig_height), dpi=100)
    ax.set_xlim(0, columns)
    ax.set_ylim(n, 0)
    ax.set_axis_off()

    def cell(col, row, colour, text, bold=False, text_colour="black"):
        ax.add_patch(plt.Rectangle((col, row), 1, 1, facecolor=colour, edgecolor="white", linewidth=1.5))
        ax.text(col + 0.5, row + 0.5, text, ha="center", va="center", fontsize=9,
                fontweight="bold" if bold else "normal", color=text_colour)

    previous_group = None
    for i, r in enumerate(rows):
        for j, (_, key, limit_key, kind) in enumerate(metrics):
            value, limit = number(r[key]), number(r[limit_key])
            if math.isnan(value) or math.isinf(value):
                ratio = float("inf")
            elif limit > 0:
                ratio = value / limit
            else:
                ratio = 0.0
            if key == "residual":  # PCG stops just below its tolerance: only over or not matters
                over = ratio > 1.01
                position = 1.0 if over else 0.0
            else:
                over = ratio > 1
                position = 1.0 if ratio >= 1 else (math.log10(max(ratio, FLOOR)) - math.log10(FLOOR)) / -math.log10(FLOOR)
            cell(j, i, cmap(min(position, 1.0)), short(value, kind) + (" !" if over else ""), bold=over,
                 text_colour="white" if position > 0.95 else "black")
        finished = r["finished"] == "true"
        nan = r["nan"] == "true"
        run_text = "NaN" if nan else ("finished" if finished else "stopped " + r["steps"] + "/" + r["planned_steps"])
        cell(len(metrics), i, "#1a9850" if finished and not nan else "#d73027", run_text,
             text_colour="white")
        plain = r.get("without_remedy", "")
        if plain:
            cell(len(metrics) + 1, i, "#f4a582" if plain.startswith("fail") else "#a6d96a", base_solver_text(plain))
        else:
            cell(len(metrics) + 1, i, "#f0f0f0", "–", text_colour="#888888")
        passed = r["verdict"] == "pass"
        cell(len(metrics) + 2, i, "#1a9850" if passed else "#d73027", "pass" if passed else "FAIL", bold=not passed,
             text_colour="white")
        name = r["case"] + (" *" if r.get("remedy") else "")
        ax.text(-0.08, i + 0.5, name, ha="right", va="center", fontsize=9,
                color="black" if passed else "#b2182b", fontweight="normal" if passed else "bold")
        if previous_group is not None and r.get("group") != previous_group:
            ax.plot([-3.2, columns], [i, i], color="#555555", linewidth=0.8, clip_on=False)
        previous_group = r.get("group")

    headers = [m[0] for m in metrics] + ["run", "base solver", "verdict"]
    for j, h in enumerate(headers):
        ax.text(j + 0.5, -0.35, h, ha="center", va="bottom", fontsize=10, fontweight="bold")
    limits = rows[0]
    passed = sum(1 for r in rows if r["verdict"] == "pass")
    ax.set_title(f"Stability study: {passed} of {n} cases pass", fontsize=12, pad=26)
    note = (f"Colour: figure / pass limit on a log scale (green <= 1e-4 of the limit, yellow ~ 0.1, red near or over it; "
            f"'!' = over the limit). Limits: energy rise {limits['energy_rise_limit']} of the energy scale, strain "
            f"{limits['strain_limit']}, iterations: the solver's limit; residual: green when within the solver "
            f"tolerance.\n* solver settings beyond the base (see table.md); 'base solver': the verdict of the same case "
            f"with the base's solver settings. Energy rise: rise of kinetic + elastic energy not explained by the "
            f"work of loads and supports, / energy scale.")
    fig.text(0.5, 0.005, note, ha="center", va="bottom", fontsize=8, wrap=True)
    fig.subplots_adjust(left=0.27, right=0.99, top=1 - 0.75 / fig_height, bottom=0.55 / fig_height)
    fig.savefig(sys.argv[2], metadata={"Software": None})
    return 0


if __name__ == "__main__":
    sys.exit(main())
