#!/usr/bin/env python3
"""A garment drop, clothsim against Blender's cloth on the same mesh (issue 44's benchmark).

Usage: bench/garment_drop.py [--bin build/release/clothsim] [--checker build/release/tools/check_intersections]
                             [--scene scenes/tshirt_drop.json] [--edge-length L] [--dt 0.005,0.002]
                             [--end 1.0] [--rounds 3] [--blender blender] [--quality Q] [--no-blender]
                             [--no-self] [--set KEY=VALUE ...] [--work DIR] [--csv OUT.csv]

For each dt and round, alternating, it runs
  - clothsim on the scene (`--no-render`, OBJ frames at the collision surface's level 2), and
  - Blender's cloth (bench/blender_cloth_drop.py under `blender -b`) on clothsim's start mesh
    (frame 0 at obj_level 0: the limit points of the control vertices joined by the control
    triangles, the same vertex count), at the same dt (frame rate and steps per frame chosen to
    give it), with the same thickness, areal density, ball and ground;
and prints per run: wall seconds of the simulation alone (clothsim: the sum of stats.csv's step_ms;
Blender: its frame loop), seconds per simulated second, ms per step, Newton solves per contact
step (clothsim), and the crossing count of the last frame by tools/check_intersections (the exact
checker, on the cloth against itself; clothsim's frame at level 2, Blender's as it is). The
medians over the rounds follow as a Markdown table. `--quality Q` also runs Blender at its own
step for Q steps per frame at 24 fps-like rates (its default quality is 5), independent of --dt.
Plain Python (no packages). Exits 2 with a message when a program is missing or a run fails.
"""
import argparse
import csv
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def fail(message):
    print("garment_drop: " + message, file=sys.stderr)
    sys.exit(2)


def crossings(checker, obj):
    """Pairs of triangles that intersect in OBJ (tools/check_intersections, the cloth against itself)."""
    r = subprocess.run([checker, obj], capture_output=True, text=True)
    if r.returncode == 0:
        return 0
    if r.returncode != 1:
        fail(f"{checker} {obj}: exit {r.returncode}: {r.stderr.strip()}")
    m = re.search(r"(\d+) (?:intersecting|crossing)", r.stdout + r.stderr)
    return int(m.group(1)) if m else -1


def run_clothsim(a, dt, work, label):
    name = f"drop_{label}"
    cmd = [a.bin, a.scene, "--no-render", "--out", work, "--set", f"name={name}", "--set", f"time.dt={dt}",
           "--set", f"time.end={a.end}", "--set", "output.obj=true", "--set", "output.obj_level=2"]
    if a.edge_length:
        cmd += ["--set", f"mesh.pattern.edge_length={a.edge_length}"]
    if a.no_self:
        cmd += ["--set", "collision.self=false"]
    for s in a.set or []:
        cmd += ["--set", s]
    start = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if r.returncode != 0:
        fail("clothsim failed: " + " ".join(cmd) + "\n" + r.stderr[-2000:])
    run_dir = os.path.join(work, name)
    with open(os.path.join(run_dir, "stats.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    steps = len(rows)
    step_seconds = sum(float(x["step_ms"]) for x in rows) / 1000.0
    contact = [x for x in rows if int(x["contact_newton_iterations"]) > 0 and int(x["contact_active_pairs"]) > 0]
    newton = statistics.mean(int(x["contact_newton_iterations"]) for x in contact) if contact else 0.0
    frames = sorted(f for f in os.listdir(os.path.join(run_dir, "frames")) if f.startswith("mesh_"))
    last = os.path.join(run_dir, "frames", frames[-1])
    worst = max(crossings(a.checker, os.path.join(run_dir, "frames", f)) for f in frames)
    summary = json.load(open(os.path.join(run_dir, "summary.json")))
    return {"who": "clothsim", "dt": dt, "seconds": step_seconds, "wall": wall, "steps": steps,
            "per_simulated_second": step_seconds / a.end, "ms_per_step": 1000.0 * step_seconds / steps,
            "newton_per_contact_step": newton, "crossings_last": crossings(a.checker, last), "crossings_worst_frame": worst,
            "failsafe_impulses": summary["contact"]["impulses"], "vertices": None}


def start_mesh(a, work):
    """clothsim's start mesh at obj_level 0 (one step's run writes frame 0)."""
    name = "drop_start"
    cmd = [a.bin, a.scene, "--no-render", "--out", work, "--set", f"name={name}", "--frames", "1",
           "--set", "output.obj=true", "--set", "output.obj_level=0"]
    if a.edge_length:
        cmd += ["--set", f"mesh.pattern.edge_length={a.edge_length}"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        fail("clothsim failed: " + " ".join(cmd) + "\n" + r.stderr[-2000:])
    return os.path.join(work, name, "frames", "mesh_0000.obj")


def run_blender(a, mesh, dt, scene, work, label, quality=None):
    out = os.path.join(work, f"blender_{label}.obj")
    ball = next(o for o in scene["obstacles"] if o.get("primitive") == "sphere")
    cmd = [a.blender, "-b", "--factory-startup", "--python", os.path.join(HERE, "blender_cloth_drop.py"), "--", mesh, out,
           str(dt), str(a.end), str(scene["collision"]["thickness"]), str(a.density), "0" if a.no_self else "1",
           str(ball["radius"]), str(ball["center"][1])]
    if quality:
        cmd.append(str(quality))
    r = subprocess.run(cmd, capture_output=True, text=True)
    line = next((l for l in r.stdout.splitlines() if l.startswith("{\"seconds\"")), None)
    if r.returncode != 0 or line is None:
        fail("blender failed: " + " ".join(cmd) + "\n" + r.stdout[-2000:] + r.stderr[-2000:])
    j = json.loads(line)
    return {"who": f"blender (quality {j['quality']})", "dt": 1.0 / (j["fps"] * j["quality"]), "seconds": j["seconds"],
            "wall": j["seconds"], "steps": j["steps"], "per_simulated_second": j["seconds"] / a.end,
            "ms_per_step": 1000.0 * j["seconds"] / j["steps"], "newton_per_contact_step": None,
            "crossings_last": crossings(a.checker, out), "crossings_worst_frame": None, "failsafe_impulses": None,
            "vertices": j["vertices"]}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--bin", default=os.path.join(ROOT, "build/release/clothsim"))
    p.add_argument("--checker", default=os.path.join(ROOT, "build/release/tools/check_intersections"))
    p.add_argument("--scene", default=os.path.join(ROOT, "scenes/tshirt_drop.json"))
    p.add_argument("--edge-length", type=float, default=None, help="mesh.pattern.edge_length [m] (default: the scene's)")
    p.add_argument("--dt", default="0.005", help="comma-separated steps [s]")
    p.add_argument("--end", type=float, default=1.0, help="simulated time [s]")
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--blender", default="blender")
    p.add_argument("--quality", type=int, default=None, help="also Blender at this quality (its own step)")
    p.add_argument("--no-blender", action="store_true")
    p.add_argument("--no-self", action="store_true", help="self-collision off in both")
    p.add_argument("--set", action="append", help="further clothsim scene overrides")
    p.add_argument("--work", default=None, help="folder for the runs (default: a new one under /tmp)")
    p.add_argument("--csv", default=None, help="write every run's row here")
    a = p.parse_args()
    for prog in (a.bin, a.checker):
        if not os.path.exists(prog):
            fail(f"{prog}: not found (build with cmake --build --preset release)")
    if not a.no_blender and shutil.which(a.blender) is None:
        fail(f"{a.blender}: not found (apt-get install blender, or --no-blender)")
    scene = json.load(open(a.scene))
    from_preset = {"gray_interlock": 0.187}
    a.density = scene.get("material", {}).get("density_area") or from_preset.get(scene.get("material", {}).get("preset"))
    if a.density is None:
        fail("the scene's areal density is not known to this script (gray_interlock only)")
    work = a.work or os.path.join("/tmp", f"garment_drop_{os.getpid()}")
    os.makedirs(work, exist_ok=True)
    mesh = None if a.no_blender else start_mesh(a, work)
    rows = []
    for dt in [float(x) for x in a.dt.split(",")]:
        for k in range(a.rounds):
            rows.append(run_clothsim(a, dt, work, f"{dt}_{k}"))
            print(json.dumps(rows[-1]), flush=True)
            if not a.no_blender:
                rows.append(run_blender(a, mesh, dt, scene, work, f"{dt}_{k}"))
                print(json.dumps(rows[-1]), flush=True)
                if a.quality:
                    rows.append(run_blender(a, mesh, 1.0 / (24 * a.quality), scene, work, f"q{a.quality}_{k}", a.quality))
                    print(json.dumps(rows[-1]), flush=True)
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
            w.writeheader()
            w.writerows(rows)
    print("\n| run | dt [ms] | s per simulated s | ms per step | Newton per contact step | crossings (last frame) |")
    print("|---|--:|--:|--:|--:|--:|")
    groups = {}
    for r in rows:
        groups.setdefault((r["who"], r["dt"]), []).append(r)
    for (who, dt), rs in groups.items():
        med = lambda key: statistics.median(r[key] for r in rs)
        newton = f"{med('newton_per_contact_step'):.2f}" if rs[0]["newton_per_contact_step"] is not None else "–"
        print(f"| {who} | {1000 * dt:.3g} | {med('per_simulated_second'):.3g} | {med('ms_per_step'):.3g} | {newton} | "
              f"{max(r['crossings_last'] for r in rs)} |")


if __name__ == "__main__":
    main()
