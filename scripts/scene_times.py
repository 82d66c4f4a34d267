#!/usr/bin/python3
"""Wall time of every shipped dynamic scene, for before/after comparisons of two builds.

Usage:
  scene_times.py run   --csv OUT.csv --bin LABEL=CLOTHSIM[@SCENES_DIR] [--bin ...] [--steps 100]
                       [--repeats 2] [--only NAME,NAME]
  scene_times.py table OUT.csv [--before LABEL --after LABEL]

`run` runs each dynamic scene of each SCENES_DIR (default: this checkout's scenes/) with its
binary: the first --steps steps (or the whole scene if shorter; `--steps 0`: the whole scene),
`--no-render`, no OBJ frames. The builds alternate scene by scene (A, B, A, B, ...), each
--repeats times, in separate processes, and each run appends one row to the CSV:

  label, scene, repeat, steps, wall_seconds (the whole process), step_seconds (the steps' rotate +
  assemble + solve + contact seconds from stats.csv), iterations, factorizations (totals),
  status (summary.json), peak_rss_MiB (from wait4), load_1min (at the start of the run).

A scene that fails or does not finish within --timeout seconds (default 900) gets a row with
status "failed"/"timeout" and the script goes on. SCENES_DIR lets a build run the scenes as they
were at its own commit (e.g. `git show OLD:scenes/x.json`), since the scene files change with the
defaults they rely on.

`table` prints per scene and label the median over the repeats (and, with --before/--after, the
ratio before/after of the medians) as a Markdown table.
"""
import csv
import json
import os
import statistics
import subprocess
import sys
import tempfile

from bench_cli import die, dispatch

FIELDS = ["label", "scene", "repeat", "steps", "wall_seconds", "step_seconds", "iterations", "factorizations",
          "status", "peak_rss_MiB", "load_1min"]
HERE = os.path.dirname(os.path.abspath(__file__))




def dynamic_scenes(folder):
    out = {}
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".json") or name == "scene.schema.json":
            continue
        path = os.path.join(folder, name)
        try:
            scene = json.load(open(path))
        except (OSError, ValueError) as e:
            die("%s: %s" % (path, e))
        if scene.get("analysis") == "dynamic":
            out[scene.get("name", name[:-5])] = (path, scene)
    return out


def one_run(label, binary, path, scene, steps, timeout):
    name = scene.get("name", os.path.basename(path)[:-5])
    dt, end = scene["time"]["dt"], scene["time"]["end"]
    run_end = end if steps <= 0 else min(end, steps * dt)
    row = {"label": label, "scene": name, "load_1min": round(os.getloadavg()[0], 2)}
    with tempfile.TemporaryDirectory(prefix="clothsim_scene_times_") as out:
        command = ["timeout", "%g" % timeout, binary, path, "--out", out, "--end", repr(run_end), "--no-render",
                   "--set", "output.obj=false"]
        process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        _, status, usage = os.wait4(process.pid, 0)
        if os.waitstatus_to_exitcode(status) == 124:
            row.update(status="timeout")
            return row
        row["peak_rss_MiB"] = round(usage.ru_maxrss / 1024.0, 1)
        folder = os.path.join(out, name)
        try:
            summary = json.load(open(os.path.join(folder, "summary.json")))
            with open(os.path.join(folder, "stats.csv")) as f:
                rows = list(csv.DictReader(f))
        except (OSError, ValueError):
            row.update(status="failed (exit %d)" % os.waitstatus_to_exitcode(status))
            return row
    step_ms = sum(float(r["rotate_ms"]) + float(r["assemble_ms"]) + float(r["solve_ms"]) +
                  float(r.get("contact_ms") or 0.0) for r in rows)
    row.update(steps=len(rows), wall_seconds=round(summary["wall_seconds"], 3), step_seconds=round(step_ms / 1000.0, 3),
               iterations=sum(int(r["solver_iterations"]) for r in rows),
               factorizations=sum(int(r.get("factorizations") or 0) for r in rows), status=summary["status"])
    return row


def run(args):
    out_csv, builds, steps, repeats, only, timeout = None, [], 100, 2, None, 900.0
    i = 0
    while i < len(args):
        a = args[i]
        if i + 1 >= len(args):
            die(a + " needs a value")
        v = args[i + 1]
        if a == "--csv": out_csv = v
        elif a == "--bin":
            if "=" not in v:
                die("--bin: expected LABEL=CLOTHSIM[@SCENES_DIR], got '%s'" % v)
            label, rest = v.split("=", 1)
            binary, _, folder = rest.partition("@")
            builds.append((label, binary, folder or os.path.join(HERE, "..", "scenes")))
        elif a == "--steps": steps = int(v)
        elif a == "--repeats": repeats = int(v)
        elif a == "--only": only = set(v.split(","))
        elif a == "--timeout": timeout = float(v)
        else: die("unknown option " + a)
        i += 2
    if not out_csv or not builds:
        die("run needs --csv and at least one --bin")
    scenes = [dynamic_scenes(folder) for _, _, folder in builds]
    names = sorted(set().union(*[set(s) for s in scenes]))
    if only:
        unknown = only - set(names)
        if unknown:
            die("--only: no dynamic scene named " + ", ".join(sorted(unknown)))
        names = [n for n in names if n in only]
    new = not os.path.exists(out_csv)
    with open(out_csv, "a", newline="") as f:
        writer = csv.DictWriter(f, FIELDS)
        if new:
            writer.writeheader()
        for name in names:
            for repeat in range(repeats):
                for (label, binary, _), found in zip(builds, scenes):
                    if name not in found:
                        continue
                    row = one_run(label, binary, found[name][0], found[name][1], steps, timeout)
                    row["repeat"] = repeat
                    writer.writerow(row)
                    f.flush()
                    sys.stderr.write("scene_times.py: %s %s repeat %d: %s s (%s)\n" %
                                     (label, name, repeat, row.get("wall_seconds", "-"), row.get("status")))


def table(args):
    if not args:
        die("table needs a CSV")
    path, before, after = args[0], None, None
    rest = args[1:]
    while rest:
        if rest[0] == "--before" and len(rest) > 1: before = rest[1]
        elif rest[0] == "--after" and len(rest) > 1: after = rest[1]
        else: die("unknown option " + rest[0])
        rest = rest[2:]
    groups = {}
    for r in csv.DictReader(open(path)):
        groups.setdefault(r["scene"], {}).setdefault(r["label"], []).append(r)
    labels = sorted({label for g in groups.values() for label in g})
    if before or after:
        labels = [before, after]
    header = "| scene | steps |" + "".join(" %s: wall s (iterations, factorisations) |" % l for l in labels)
    if before and after:
        header += " before / after |"
    print(header)
    print("|---|--:|" + "--:|" * (len(labels) + (1 if before and after else 0)))
    for scene in sorted(groups):
        cells, medians, steps = [], {}, ""
        for label in labels:
            rows = [r for r in groups[scene].get(label, []) if r["status"] == "completed"]
            if not rows:
                bad = groups[scene].get(label, [])
                cells.append(bad[0]["status"] if bad else "—")
                continue
            steps = rows[0]["steps"]
            medians[label] = statistics.median(float(r["wall_seconds"]) for r in rows)
            cells.append("%.2f (%d, %d)" % (medians[label], statistics.median(int(r["iterations"]) for r in rows),
                                            statistics.median(int(r["factorizations"]) for r in rows)))
        line = "| `%s` | %s | %s |" % (scene, steps, " | ".join(cells))
        if before and after:
            line += " %s |" % ("%.2f" % (medians[before] / medians[after]) if before in medians and after in medians else "—")
        print(line)


def main():
    return dispatch(__doc__, {"run": run, "table": table})


if __name__ == "__main__":
    sys.exit(main())
