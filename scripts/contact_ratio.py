#!/usr/bin/env python3
"""Contact against the rest of the step over whole runs, from their stats.csv (issue 28's ratio).

Usage: scripts/contact_ratio.py RUN [RUN ...]

RUN is a run's output folder (out/<scene>, holding stats.csv) or a stats.csv itself. For each run
prints one Markdown table row: steps, contact seconds (`contact_ms`: the barrier's evaluations
and the fail-safe), rest seconds (`rotate_ms` + `assemble_ms` + `solve_ms`: rotation, assembly
and the linear solves, the barrier's extra Newton solves included), their ratio, Newton solves
per step (`contact_newton_iterations`), steps solved again with the elastic terms re-linearised
(`contact_relinearisations`), fail-safe impulses and unresolved pairs. Plain Python (no packages).
Exits 2 naming the file when a run has no stats.csv or a column is missing.
"""
import csv
import os
import sys

COLUMNS = ("contact_ms", "rotate_ms", "assemble_ms", "solve_ms", "contact_newton_iterations",
           "contact_relinearisations", "contact_impulses", "contact_unresolved")


def stats_path(run):
    return os.path.join(run, "stats.csv") if os.path.isdir(run) else run


def row_of(run):
    path = stats_path(run)
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        raise SystemExit(f"contact_ratio: {path}: {e.strerror}")
    if not rows:
        raise SystemExit(f"contact_ratio: {path}: no steps")
    missing = [c for c in COLUMNS if c not in rows[0]]
    if missing:
        raise SystemExit(f"contact_ratio: {path}: no column {', '.join(missing)} (a run without contact?)")
    total = {c: sum(float(r[c]) for r in rows) for c in COLUMNS}
    contact = total["contact_ms"] / 1000.0
    rest = (total["rotate_ms"] + total["assemble_ms"] + total["solve_ms"]) / 1000.0
    ratio = f"{contact / rest:.2f}" if rest > 0 else "–"
    name = os.path.basename(os.path.dirname(os.path.abspath(path)))
    return (f"| `{name}` | {len(rows)} | {contact:.2f} | {rest:.2f} | {ratio} | "
            f"{total['contact_newton_iterations'] / len(rows):.2f} | {int(total['contact_relinearisations'])} | "
            f"{int(total['contact_impulses'])} | {int(total['contact_unresolved'])} |")


def main(argv):
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if argv else 2
    try:
        rows = [row_of(run) for run in argv]
    except SystemExit as e:
        print(e, file=sys.stderr)
        return 2
    print("| run | steps | contact s | rest s | contact / rest | Newton solves per step | re-linearised steps | "
          "fail-safe impulses | unresolved |")
    print("|---|--:|--:|--:|--:|--:|--:|--:|--:|")
    for row in rows:
        print(row)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
