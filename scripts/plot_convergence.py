#!/usr/bin/python3
"""Draws the convergence study's plot: relative error against wall time, log-log.

Usage: plot_convergence.py RESULTS.csv OUTPUT.png

Reads the results.csv written by `clothsim study convergence` (columns documented in
docs/convergence.md) and draws one panel for the static plates and one per dynamic case, then for
each dynamic case that has the post-buckling columns two more: the relative elastic-energy error at
the end of the run against wall time (log-log; mesh series solid, time-step series dashed), and the
fold counts at the end of the run against control vertices (mesh series; circumferential median
solid, axial median dashed, the reference run's counts as grey horizontal lines), and for each
dynamic case with a tolerance series (rows of series "tolerance") two more: the solver error (the run
against its setting's tight-tolerance run) against the linear solver's tolerance, log-log, with the
discretisation error of each setting (its tight run against the reference) as a thin horizontal
line in the same colour and line style, labelled with its mesh and window; and the wall time per run (solid, left axis, log) and PCG
iterations per step (dashed, right axis) against the tolerance. Colour
= method (the same in every panel, so later baseline methods are new colours), marker and line
style = plate case (plates panel) or series and error window (dynamic panels: solid = mesh
refinement at a fixed time step, dashed = time-step refinement on the reference mesh, both with
filled markers for the first window; dotted and dash-dotted with hollow markers for later
windows; in the tolerance panels the marker gives the mesh and time step). Plates: thin grey
lines mark the relative precision of each published coefficient. Rows of the "reference" series, failed runs
(error nan) and errors of exactly 0 cannot be drawn on a log axis and are left out; the tolerance
series appears only in its own panels. Exits with status 3 when matplotlib is missing (Debian:
python3-matplotlib).
"""

import csv
import math
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
except ImportError:
    sys.stderr.write("plot_convergence.py: matplotlib is not installed (Debian: python3-matplotlib)\n")
    sys.exit(3)

PLATES = "plates"
PLATE_STYLES = {  # case -> (marker, line style)
    "plate_ss_uniform": ("o", "-"),
    "plate_clamped_uniform": ("s", "--"),
    "plate_ss_point": ("^", "-."),
    "plate_clamped_point": ("D", ":"),
}
SERIES_STYLES = {"mesh": ("o", "-"), "dt": ("s", "--")}  # first window (filled markers)
LATER_WINDOW_STYLES = {"mesh": ("o", ":"), "dt": ("s", "-.")}  # later windows (hollow markers)
SERIES_LABELS = {"mesh": "mesh series", "dt": "time-step series"}


def read_rows(path):
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    required = {"case", "method", "series", "setting", "wall_seconds", "error"}
    if rows and not required <= set(rows[0]):
        raise SystemExit(f"plot_convergence.py: {path}: missing columns {sorted(required - set(rows[0]))}")
    return rows


def drawable(row):
    try:
        error, seconds = float(row["error"]), float(row["wall_seconds"])
    except ValueError:
        return False
    return row["series"] not in ("reference", "tolerance") and math.isfinite(error) and error > 0 and seconds > 0


def panel_of(case):
    return PLATES if case.startswith("plate_") else case


def short_setting(row):
    """The part of the setting that changes along the curve: '26x19' or 'dt=0.002'."""
    parts = row["setting"].split(" ")
    return parts[-1] if row["series"] == "dt" and len(parts) > 1 else parts[0]


def draw_reference_precision(ax, rows):
    """Thin grey lines at the relative precision of each plate's published coefficient, for the
    coefficients whose precision comes near the smallest plotted error."""
    precision, smallest = {}, {}
    for row in rows:
        if not row["case"].startswith("plate_"):
            continue
        try:
            value = float(row.get("reference_precision") or 0)
        except ValueError:
            continue
        if value > 0:
            precision[row["case"]] = value
        if drawable(row):
            smallest[row["case"]] = min(smallest.get(row["case"], math.inf), float(row["error"]))
    precision = {case: value for case, value in precision.items() if value >= smallest.get(case, math.inf) / 3}
    for case, value in precision.items():
        _, style = PLATE_STYLES.get(case, ("v", "-"))
        ax.axhline(value, color="0.6", linewidth=0.8, linestyle=style, zorder=0)
        ax.annotate(f"precision of the {case.removeprefix('plate_')} coefficient", (0.995, value),
                    xycoords=("axes fraction", "data"), ha="right", va="bottom", fontsize=6.5, color="0.45")


def number(row, column):
    """The row's value in `column` as a float, or None when absent, empty or not finite."""
    try:
        value = float(row.get(column) or "")
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def end_state_rows(rows, case):
    """One row per run of a dynamic case (the end-of-run columns repeat in every window's rows):
    the rows of the case's last window, in file order."""
    windows = [r.get("window", "") for r in rows if r["case"] == case]
    last = windows[-1] if windows else ""
    return [r for r in rows if r["case"] == case and r.get("window", "") == last]


def has_end_state(rows, case):
    return any(number(r, "elastic_energy") is not None for r in end_state_rows(rows, case))


def draw_energy_panel(ax, rows, case, colour):
    """Relative elastic-energy error at the end of the run against wall time."""
    curves = {}
    for r in end_state_rows(rows, case):
        error, seconds = number(r, "energy_error"), number(r, "wall_seconds")
        if r["series"] in ("reference", "tolerance") or error is None or error <= 0 or seconds is None or seconds <= 0:
            continue
        curves.setdefault((r["method"], r["series"]), []).append((seconds, error, short_setting(r)))
    for (method, series), points in curves.items():
        marker, style = SERIES_STYLES.get(series, ("v", "-"))
        ax.plot([p[0] for p in points], [p[1] for p in points], linestyle=style, marker=marker,
                color=colour[method], markersize=5)
        if series == "mesh":
            for xi, yi, label in points:
                ax.annotate(label, (xi, yi), textcoords="offset points", xytext=(4, 4), fontsize=6.5, color="0.35")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time per run [s]")
    ax.set_ylabel("|E - E_ref| / |E_ref|  [-]")
    ends = [number(r, "steps") * number(r, "dt") for r in end_state_rows(rows, case)
            if number(r, "steps") is not None and number(r, "dt") is not None]
    end = f" (t = {ends[0]:g} s)" if ends else ""
    ax.set_title(f"{case}: elastic energy at the end of the run{end} vs. reference", fontsize=10)
    ax.grid(True, which="major", alpha=0.4)
    ax.grid(True, which="minor", alpha=0.12)
    handles = [plt.Line2D([], [], color="0.3", linestyle=SERIES_STYLES[s][1], marker=SERIES_STYLES[s][0],
                          label=SERIES_LABELS[s]) for s in ("mesh", "dt")]
    ax.legend(handles=handles, fontsize=7, loc="best")
    if not curves:
        ax.text(0.5, 0.5, "no drawable rows", transform=ax.transAxes, ha="center")


def draw_fold_panel(ax, rows, case, colour):
    """Fold counts at the end of the run against control vertices (mesh series), with the
    reference run's counts as horizontal lines."""
    styles = {"folds_circumferential": ("o", "-", "circumferential (median over heights)"),
              "folds_axial": ("^", "--", "axial (median over meridians)")}
    drawn = False
    for r in end_state_rows(rows, case):
        if r["series"] == "reference":
            for column, (_, style, _) in styles.items():
                value = number(r, column)
                if value is not None:
                    ax.axhline(value, color="0.55", linestyle=style, linewidth=1.2, zorder=0)
                    above = column == "folds_circumferential"  # the axial label goes below its line
                    ax.annotate(f"reference {column.split('_')[1]}: {value:g}", (0.99, value),
                                xycoords=("axes fraction", "data"), ha="right", va="bottom" if above else "top",
                                fontsize=6.5, color="0.4")
            break
    curves = {}
    for r in end_state_rows(rows, case):
        if r["series"] != "mesh":
            continue
        vertices = number(r, "vertices")
        for column in styles:
            value = number(r, column)
            if vertices is not None and vertices > 0 and value is not None:
                curves.setdefault((r["method"], column), []).append((vertices, value))
    for (method, column), points in curves.items():
        marker, style, _ = styles[column]
        ax.plot([p[0] for p in points], [p[1] for p in points], linestyle=style, marker=marker, color=colour[method],
                markersize=5)
        drawn = True
    ax.set_xscale("log")
    ax.yaxis.set_major_locator(matplotlib.ticker.MaxNLocator(integer=True))
    ax.set_ylim(bottom=-0.5)
    ax.set_xlabel("control vertices (mesh series)")
    ax.set_ylabel("folds at the end of the run")
    ax.set_title(f"{case}: fold count of the drawn surface (count_sleeve_folds)", fontsize=10)
    ax.grid(True, alpha=0.4)
    handles = [plt.Line2D([], [], color="0.3", linestyle=style, marker=marker, label=label)
               for marker, style, label in styles.values()]
    handles.append(plt.Line2D([], [], color="0.55", label="reference run"))
    ax.legend(handles=handles, fontsize=7, loc="best")
    if not drawn:
        ax.text(0.5, 0.5, "no drawable rows", transform=ax.transAxes, ha="center")


TOLERANCE_MARKERS = ["o", "s", "^", "D", "v"]  # by mesh and time step, in file order


def tolerance_rows(rows, case):
    """The case's rows of the tolerance series that have a tolerance."""
    return [r for r in rows if r["case"] == case and r["series"] == "tolerance" and number(r, "tolerance")]


def has_tolerance_series(rows, case):
    return bool(tolerance_rows(rows, case))


def base_setting(row):
    """The setting without its tolerance: '26x19 dt=0.001'."""
    return row["setting"].split(" tol=")[0]


def tolerance_settings(rows, case):
    """(method, mesh and time step) -> marker, in file order."""
    bases, markers = [], {}
    for r in tolerance_rows(rows, case):
        base = base_setting(r)
        if base not in bases:
            bases.append(base)
        markers.setdefault((r["method"], base), TOLERANCE_MARKERS[bases.index(base) % len(TOLERANCE_MARKERS)])
    return markers


def draw_tolerance_error_panel(ax, rows, case, colour):
    """Solver error against tolerance, log-log; the discretisation error of each setting as a thin
    horizontal line."""
    markers = tolerance_settings(rows, case)
    windows = []
    for r in tolerance_rows(rows, case):
        if r["window"] not in windows:
            windows.append(r["window"])
    curves, levels = {}, {}
    for r in tolerance_rows(rows, case):
        key = (r["method"], base_setting(r), r["window"])
        error = number(r, "solver_error")
        if error is not None and error > 0:
            curves.setdefault(key, []).append((number(r, "tolerance"), error))
        level = number(r, "discretization_error")
        if level is not None and level > 0:
            levels[key] = level
    for (method, base, window), points in curves.items():
        first = window == windows[0]
        points.sort()
        ax.plot([p[0] for p in points], [p[1] for p in points], linestyle="-" if first else ":",
                marker=markers[(method, base)], color=colour[method], markersize=5,
                markerfacecolor=colour[method] if first else "white")
    for (method, base, window), level in levels.items():
        ax.axhline(level, color=colour[method], linestyle="-" if window == windows[0] else ":", linewidth=0.9,
                   alpha=0.55, zorder=0)
        ax.annotate(f"{base.split(' ')[0]} {window}", (0.01, level), xycoords=("axes fraction", "data"), ha="left",
                    va="bottom", fontsize=6, color=colour[method], alpha=0.8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("linear solver tolerance (relative residual) [-]")
    ax.set_ylabel("solver error vs. the tight run [-]")
    ax.set_title(f"{case}: solver error against tolerance (thin lines: discretisation error)", fontsize=10)
    ax.grid(True, which="major", alpha=0.4)
    ax.grid(True, which="minor", alpha=0.12)
    handles = [plt.Line2D([], [], color=colour[method], linestyle="", marker=m, label=f"{method} · {base}")
               for (method, base), m in markers.items()]
    handles += [plt.Line2D([], [], color="0.3", linestyle="-" if w == windows[0] else ":",
                           markerfacecolor="0.3" if w == windows[0] else "white", marker="o", label=f"window {w}")
                for w in windows]
    handles.append(plt.Line2D([], [], color="0.3", linewidth=0.9, alpha=0.55,
                              label="discretisation error (tight run vs. reference)"))
    ax.legend(handles=handles, fontsize=6.5, loc="best")
    if not curves:
        ax.text(0.5, 0.5, "no drawable rows", transform=ax.transAxes, ha="center")


def draw_tolerance_cost_panel(ax, rows, case, colour):
    """Wall time per run (solid, left axis) and PCG iterations per step (dashed, right axis)
    against tolerance, one point per run (the first window's rows)."""
    markers = tolerance_settings(rows, case)
    first = next((r["window"] for r in tolerance_rows(rows, case)), "")
    curves = {}
    for r in tolerance_rows(rows, case):
        if r["window"] != first:
            continue
        seconds, iterations, steps = number(r, "wall_seconds"), number(r, "solver_iterations"), number(r, "steps")
        if seconds is None or seconds <= 0 or not steps:
            continue
        curves.setdefault((r["method"], base_setting(r)), []).append((number(r, "tolerance"), seconds, iterations / steps))
    right = ax.twinx()
    for (method, base), points in curves.items():
        points.sort()
        x = [p[0] for p in points]
        ax.plot(x, [p[1] for p in points], linestyle="-", marker=markers[(method, base)], color=colour[method],
                markersize=5)
        right.plot(x, [p[2] for p in points], linestyle="--", marker=markers[(method, base)], color=colour[method],
                   markersize=4, markerfacecolor="white")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("linear solver tolerance (relative residual) [-]")
    ax.set_ylabel("wall time per run [s] (solid)")
    right.set_ylabel("PCG iterations per step (dashed)")
    right.set_ylim(bottom=0)
    ax.set_title(f"{case}: cost against tolerance", fontsize=10)
    ax.grid(True, which="major", alpha=0.4)
    handles = [plt.Line2D([], [], color=colour[method], linestyle="", marker=m, label=f"{method} · {base}")
               for (method, base), m in markers.items()]
    ax.legend(handles=handles, fontsize=6.5, loc="best")
    if not curves:
        ax.text(0.5, 0.5, "no drawable rows", transform=ax.transAxes, ha="center")


EXTRA_PANELS = {"energy": draw_energy_panel, "folds": draw_fold_panel,
                "tolerance_error": draw_tolerance_error_panel, "tolerance_cost": draw_tolerance_cost_panel}


def main(argv):
    if len(argv) != 3:
        sys.stderr.write("usage: plot_convergence.py RESULTS.csv OUTPUT.png\n")
        return 2
    rows = read_rows(argv[1])
    methods, panels = [], []
    for row in rows:
        if row["method"] not in methods:
            methods.append(row["method"])
        if panel_of(row["case"]) not in panels:
            panels.append(panel_of(row["case"]))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    colour = {m: colours[i % len(colours)] for i, m in enumerate(methods)}

    # The post-buckling panels (energy and folds) and the tolerance panels (solver error, cost) for
    # every dynamic case that has them, in pairs.
    extra = []
    for case in panels:
        if case == PLATES:
            continue
        if has_end_state(rows, case):
            extra += [("energy", case), ("folds", case)]
        if has_tolerance_series(rows, case):
            extra += [("tolerance_error", case), ("tolerance_cost", case)]
    columns = 2 if len(panels) + len(extra) > 1 else 1
    first_extra = math.ceil(len(panels) / columns) * columns  # the pairs start on a new row
    grid_rows = max(1, math.ceil((first_extra + len(extra)) / columns)) if extra else max(1, math.ceil(len(panels) / columns))
    fig, axes = plt.subplots(grid_rows, columns, figsize=(16, 5.4 * grid_rows + 0.8), dpi=100, squeeze=False)
    for ax in axes.flat[len(panels):]:
        ax.set_visible(False)
    for ax, (kind, case) in zip(axes.flat[first_extra:], extra):
        ax.set_visible(True)
        EXTRA_PANELS[kind](ax, rows, case, colour)

    shared_legend = {}  # dynamic panels: label -> handle (same styles in every panel)
    for ax, panel in zip(axes.flat, panels):
        curves = {}  # (case, method, series, window) -> rows, in file order
        windows = []
        for row in rows:
            if panel_of(row["case"]) == panel and drawable(row):
                window = row.get("window", "")
                curves.setdefault((row["case"], row["method"], row["series"], window), []).append(row)
                if window not in windows:
                    windows.append(window)
        reference = next((r["reference"] for r in rows if panel_of(r["case"]) == panel and r.get("reference")), "")
        for (case, method, series, window), points in curves.items():
            filled = True
            if panel == PLATES:
                marker, style = PLATE_STYLES.get(case, ("v", "-"))
                label = f"{case.removeprefix('plate_')} · {method}"
            else:
                filled = window == windows[0]
                marker, style = (SERIES_STYLES if filled else LATER_WINDOW_STYLES).get(series, ("v", "-"))
                label = f"{method} · {SERIES_LABELS.get(series, series)}" + (f" · {window}" if window else "")
            x = [float(r["wall_seconds"]) for r in points]
            y = [float(r["error"]) for r in points]
            (line,) = ax.plot(x, y, linestyle=style, marker=marker, color=colour[method], label=label,
                              markersize=5, markerfacecolor=colour[method] if filled else "white")
            if panel != PLATES:
                shared_legend.setdefault(label, line)
            # Label the points of the first method's curves with their resolution / time step.
            if method == methods[0] and filled:
                below = series == "dt"  # keeps the labels of a point shared by two series apart
                for r, xi, yi in zip(points, x, y):
                    ax.annotate(short_setting(r), (xi, yi), textcoords="offset points",
                                xytext=(4, -10 if below else 4), fontsize=7, color="0.35")
        if panel == PLATES:
            draw_reference_precision(ax, rows)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time per run [s]")
        ax.set_ylabel("relative error [-]")
        if panel == PLATES:
            ax.set_title("Static square plates: centre deflection vs. analytic (Timoshenko)")
        else:
            title = f"{panel}: RMS surface displacement vs. reference"
            ax.set_title(title + (f"\nreference = {reference}" if reference else ""), fontsize=10.5)
        ax.grid(True, which="major", alpha=0.4)
        ax.grid(True, which="minor", alpha=0.12)
        if not curves:
            ax.text(0.5, 0.5, "no drawable rows", transform=ax.transAxes, ha="center")
        elif panel == PLATES:
            ax.legend(fontsize=7, loc="upper right", ncol=2)
    bottom = 0.0
    if shared_legend:
        fig.legend(list(shared_legend.values()), list(shared_legend.keys()), loc="lower center",
                   ncol=min(4, len(shared_legend)), fontsize=8.5, frameon=False,
                   title="dynamic cases (colour = method; line = series and error window)", title_fontsize=9)
        bottom = 0.022 * (1.5 + math.ceil(len(shared_legend) / 4))
    fig.suptitle("clothsim convergence study: error against run time (lower left is better)", fontsize=13)
    fig.tight_layout(rect=(0, bottom, 1, 0.97))
    fig.savefig(argv[2], dpi=100, metadata={"Software": None})
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
