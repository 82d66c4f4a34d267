#!/usr/bin/python3
"""Is a scene's linear-solver tolerance sound? Its solver error against its time-step error.

Usage:
  tolerance_check.py run   --csv OUT.csv [--bin CLOTHSIM] [--window SECONDS] [--only NAME,NAME]
                           [--tolerance T] [--timeout SECONDS] [SCENE.json ...]
  tolerance_check.py table OUT.csv

`run` checks each SCENE (default: every dynamic scene of this checkout's scenes/) over its first
--window simulated seconds (default 0.2, or the whole scene if shorter), with runs of CLOTHSIM
(default build/release/clothsim) that differ only in the solver tolerance, the step and the mesh:

  own     the scene as it is (its solver.tolerance, or the default 1e-5; --tolerance T: T instead)
  1e-8    solver.tolerance = 1e-8   (a baseline: is the window resolved?)
  tight   solver.tolerance = 1e-11  (the reference for the solver error)
  half    tight, with time.dt halved (for the time step's error)
  fine    tight, with the mesh refined once (for the mesh's error): a primitive only -- a cylinder
          with twice the segments and 2 rings - 1 rings, a grid with twice the divisions, which
          keeps every vertex of the scene's mesh at its rest position; an OBJ mesh has no fine run

Each run writes OBJ frames of the limit surface at the control vertices (output.obj_level 0),
about 40 in the window, at times that are whole multiples of the step (so the halved step lands
on them too); frames are compared by their time, the fine run at the vertices nearest to the
scene's in the first frame. With u the displacement from the first frame, a run's error against
another over [0, t] is RMS |u - u_other| / RMS |u_other| over the frames after the first up to t:

  solver error     own against tight
  baseline error   1e-8 against tight
  step error       tight against half: the change from halving the step
  mesh error       tight against fine: the change from halving the mesh size
  ratio            solver error / max(step error, mesh error)

The larger of the step and mesh errors estimates the discretisation error from below (each is the
change from one refinement, about half of its part of the error or less, and the two parts add);
so the check errs on the safe side, the more so for an OBJ mesh, whose mesh error is not measured.
All are taken over the **resolved window** [0, t*]: the longest one whose baseline error stays
within 1000 x 1e-8 at every frame (rule 1 of docs/convergence.md, "Solver tolerance": beyond it
perturbations of any size grow -- a bifurcation, a contact decision -- and the norm measures that
growth, not the solver). The verdict (rule 2):

  pass        ratio <= 0.1 over [0, t*]
  FAIL        ratio > 0.1: the tolerance is not shown to be tight enough for this scene
  unresolved  not even the first frame's window is resolved

One CSV row per scene: scene, window_s, dt, tolerance, resolved_to_s (t*), frames (up to t*),
solver_error, baseline_error, step_error, mesh_error, ratio, verdict, the PCG iterations per step
of own and tight, and each run's wall seconds. A run that fails or times out (--timeout, default 3600 s) gives the verdict
"failed: <run>" and the script goes on. Exit status 0 when every row passes (or is unresolved),
1 when a row fails, 2 on bad arguments.

`table` prints the CSV as a Markdown table.
"""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from bench_cli import die, dispatch

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
FIELDS = ["scene", "window_s", "dt", "tolerance", "resolved_to_s", "frames", "solver_error", "baseline_error", "step_error", "mesh_error",
          "ratio", "verdict", "iterations_own", "iterations_tight", "seconds_own", "seconds_1e-8", "seconds_tight",
          "seconds_half", "seconds_fine"]
DEFAULT_TOLERANCE = 1e-5  # LinearSolverSettings' default (scenes/README.md, solver.tolerance)
BASELINE_TOLERANCE = 1e-8
TIGHT_TOLERANCE = 1e-11
RESOLVED_FACTOR = 1000.0  # docs/convergence.md, rule 1
PASS_RATIO = 0.1          # docs/convergence.md, rule 2


def read_frames(folder):
    """{time: array of vertex positions} from the OBJ frames of a run."""
    frames = {}
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".obj"):
            continue
        t = None
        points = []
        with open(os.path.join(folder, name)) as f:
            for line in f:
                if line.startswith("# clothsim:") and " t = " in line:
                    t = float(line.split(" t = ")[1].split()[0])
                elif line.startswith("v "):
                    points.append([float(x) for x in line.split()[1:4]])
        if t is None:
            die("%s: no time in the header" % os.path.join(folder, name))
        frames[t] = np.array(points)
    return frames


def prefix_errors(run, other):
    """[(t, error over the frames after the first up to t)] for each frame time t of `other` that
    `run` has too: error = RMS |u - u_other| / RMS |u_other|, u from the first frame."""
    times = sorted(other)
    t0 = times[0]

    def at(frames, t):
        s = min(frames, key=lambda s: abs(s - t))
        return frames[s] if abs(s - t) <= 1e-9 * max(1.0, abs(t)) else None

    if at(run, t0) is None:
        return []
    out, difference, size = [], 0.0, 0.0
    for t in times[1:]:
        x = at(run, t)
        if x is None:
            continue
        u = x - at(run, t0)
        v = other[t] - other[t0]
        difference += float(np.sum((u - v) ** 2))
        size += float(np.sum(v ** 2))
        out.append((t, math.sqrt(difference / size) if size > 0 else math.nan))
    return out


def refined_mesh(mesh):
    """--set overrides for the scene's primitive mesh refined once (h halved), or None (an OBJ mesh)."""
    if mesh.get("primitive") == "cylinder":  # closed or a panel: twice the segments, a ring between rings
        return [("mesh.segments", str(2 * int(mesh["segments"]))), ("mesh.rings", str(2 * int(mesh["rings"]) - 1))]
    if mesh.get("primitive") == "grid":
        m, n = mesh["divisions"]
        return [("mesh.divisions", "[%d,%d]" % (2 * int(m), 2 * int(n)))]
    return None


def restricted(fine, coarse):
    """The fine run's frames at the vertices nearest (in the first frame) to the coarse run's: a
    refined primitive keeps every vertex of the coarse one at the same rest position."""
    t0 = min(coarse)
    a, b = coarse[t0], fine[min(fine)]
    nearest = np.empty(len(a), dtype=int)
    for start in range(0, len(a), 256):
        d = ((a[start:start + 256, None, :] - b[None, :, :]) ** 2).sum(axis=2)
        nearest[start:start + 256] = d.argmin(axis=1)
    return {t: x[nearest] for t, x in fine.items()}


def one_run(binary, path, name, window, dt, fps, settings, timeout):
    """Runs the scene with the --set overrides; returns (frames, iterations per step, seconds) or None."""
    with tempfile.TemporaryDirectory(prefix="clothsim_tolerance_") as out:
        command = ["timeout", "%g" % timeout, binary, path, "--out", out, "--end", repr(window), "--no-render",
                   "--set", "output.obj=true", "--set", "output.obj_level=0", "--set", "time.output_fps=%r" % fps,
                   "--set", "time.dt=%r" % dt]
        for key, value in settings:
            command += ["--set", "%s=%s" % (key, value)]
        start = time.monotonic()
        result = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        seconds = time.monotonic() - start
        if result.returncode != 0:
            sys.stderr.write("%s: %s\n" % (name, result.stderr.strip().splitlines()[-1] if result.stderr.strip()
                                           else "exit %d" % result.returncode))
            return None
        folder = os.path.join(out, name)
        frames = read_frames(os.path.join(folder, "frames"))
        with open(os.path.join(folder, "stats.csv")) as f:
            rows = list(csv.DictReader(f))
        iterations = sum(float(r["solver_iterations"]) for r in rows) / max(1, len(rows))
        return frames, iterations, seconds


def check(binary, path, scene, window_request, timeout, tolerance_override):
    name = scene.get("name", os.path.basename(path)[:-5])
    timing = scene.get("time", {})
    dt, end = float(timing.get("dt", 0.001)), float(timing.get("end", 1.0))  # scenes/README.md, "time"
    window = min(end, window_request)
    tolerance = tolerance_override or float(scene.get("solver", {}).get("tolerance", DEFAULT_TOLERANCE))
    # Frames every `every` steps (about 40 in the window): whole multiples of dt and of dt / 2.
    every = max(1, int(round(window / (40.0 * dt))))
    fps = 1.0 / (every * dt)
    row = {"scene": name, "window_s": window, "dt": dt, "tolerance": tolerance}
    runs = {}
    own = [("solver.tolerance", repr(tolerance))] if tolerance_override else []
    tight = [("solver.tolerance", repr(TIGHT_TOLERANCE))]
    plan = [("own", dt, own), ("1e-8", dt, [("solver.tolerance", repr(BASELINE_TOLERANCE))]), ("tight", dt, tight),
            ("half", dt / 2, tight)]
    refined = refined_mesh(scene.get("mesh", {}))
    if refined is not None:
        plan.append(("fine", dt, tight + refined))
    for label, step, settings in plan:
        result = one_run(binary, path, name, window, step, fps, settings, timeout)
        if result is None:
            row["verdict"] = "failed: " + label
            return row
        runs[label] = result
        row["seconds_" + label] = round(result[2], 2)
    solver = dict(prefix_errors(runs["own"][0], runs["tight"][0]))
    baseline = dict(prefix_errors(runs["1e-8"][0], runs["tight"][0]))
    step = dict(prefix_errors(runs["tight"][0], runs["half"][0]))
    mesh = dict(prefix_errors(runs["tight"][0], restricted(runs["fine"][0], runs["tight"][0]))) if "fine" in runs else {}
    times = sorted(t for t in solver if t in baseline and t in step and (not mesh or t in mesh))
    # The discretisation error's estimate: the larger of the step's and the mesh's parts.
    discretisation = {t: max(step[t], mesh.get(t, 0.0)) for t in times}
    times = [t for t in times if not math.isnan(discretisation[t]) and discretisation[t] > 0]
    if not times:
        row["verdict"] = "failed: no frames to compare"
        return row
    # The longest window [0, t] whose baseline error is within the rule's bound.
    resolved = [t for t in times if all(baseline[s] <= RESOLVED_FACTOR * BASELINE_TOLERANCE for s in times if s <= t)]
    t = resolved[-1] if resolved else times[-1]
    ratio = solver[t] / discretisation[t]
    row.update(resolved_to_s="%.6g" % t if resolved else "", frames=sum(1 for s in times if s <= t),
               solver_error="%.2e" % solver[t], baseline_error="%.2e" % baseline[t], step_error="%.2e" % step[t],
               mesh_error="%.2e" % mesh[t] if mesh else "", ratio="%.3g" % ratio,
               iterations_own=round(runs["own"][1], 2), iterations_tight=round(runs["tight"][1], 2))
    if not resolved:
        row["verdict"] = "unresolved"
    else:
        row["verdict"] = "pass" if ratio <= PASS_RATIO else "FAIL"
    return row


def dynamic_scenes(paths, strict):
    """(path, scene) of the dynamic scenes among `paths`; with `strict` any other is an error."""
    out = []
    for path in paths:
        try:
            scene = json.load(open(path))
        except (OSError, ValueError) as e:
            die("%s: %s" % (path, e))
        if scene.get("analysis") == "dynamic":
            out.append((path, scene))
        elif strict:
            die("%s: not a dynamic scene" % path)
    return out


def run(args):
    binary, csv_path, window, only, timeout, paths = os.path.join(ROOT, "build/release/clothsim"), None, 0.2, None, 3600.0, []
    tolerance = None
    i = 0
    while i < len(args):
        arg = args[i]
        if arg in ("--bin", "--csv", "--window", "--only", "--timeout", "--tolerance"):
            if i + 1 >= len(args):
                die(arg + " needs a value")
            value = args[i + 1]
            i += 2
            if arg == "--bin":
                binary = value
            elif arg == "--csv":
                csv_path = value
            elif arg == "--only":
                only = set(value.split(","))
            else:
                try:
                    number = float(value)
                except ValueError:
                    die("%s %s: not a number" % (arg, value))
                if not number > 0:
                    die("%s %s: must be > 0" % (arg, value))
                if arg == "--window":
                    window = number
                elif arg == "--tolerance":
                    tolerance = number
                else:
                    timeout = number
        elif arg.startswith("--"):
            die("unknown option " + arg)
        else:
            paths.append(arg)
            i += 1
    if csv_path is None:
        die("--csv OUT.csv is required")
    if not os.access(binary, os.X_OK):
        die("%s: not an executable (build it: cmake --build --preset release)" % binary)
    strict = bool(paths)
    if not paths:
        folder = os.path.join(ROOT, "scenes")
        paths = [os.path.join(folder, n) for n in sorted(os.listdir(folder)) if n.endswith(".json") and n != "scene.schema.json"]
    scenes = dynamic_scenes(paths, strict)
    if only is not None:
        names = {s.get("name", os.path.basename(p)[:-5]) for p, s in scenes}
        unknown = only - names
        if unknown:
            die("--only: no dynamic scene named " + ", ".join(sorted(unknown)))
        scenes = [(p, s) for p, s in scenes if s.get("name", os.path.basename(p)[:-5]) in only]
    failed = False
    # Rows are written as they come (a temporary file renamed at the end: the CSV is whole or absent).
    partial = csv_path + ".partial"
    with open(partial, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=FIELDS)
        writer.writeheader()
        for path, scene in scenes:
            row = check(binary, path, scene, window, timeout, tolerance)
            writer.writerow(row)
            f.flush()
            print("%s: %s (solver error %s, step error %s, mesh error %s, ratio %s)" % (
                row["scene"], row["verdict"], row.get("solver_error", "-"), row.get("step_error", "-"),
                row.get("mesh_error") or "-", row.get("ratio", "-")), flush=True)
            failed = failed or row["verdict"] == "FAIL" or row["verdict"].startswith("failed")
    os.replace(partial, csv_path)
    sys.exit(1 if failed else 0)


def table(args):
    if len(args) != 1:
        die("table needs exactly one CSV file")
    try:
        rows = list(csv.DictReader(open(args[0])))
    except OSError as e:
        die("%s: %s" % (args[0], e))
    print("| scene | window [s] | dt [s] | tolerance | resolved to [s] | solver error | 1e-8 error | step error | mesh error "
          "| ratio | verdict | PCG it./step own / tight |")
    print("|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|---|--:|")
    for r in rows:
        print("| `%s` | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s / %s |" % (
            r["scene"], r["window_s"], r["dt"], r["tolerance"], r["resolved_to_s"], r["solver_error"], r["baseline_error"],
            r["step_error"], r["mesh_error"] or "–",
            r["ratio"], r["verdict"], r["iterations_own"], r["iterations_tight"]))


if __name__ == "__main__":
    sys.exit(dispatch(__doc__, {"run": run, "table": table}))
