#!/usr/bin/env python3
"""A small study driven from Python: how far a cantilevered strip of each fabric sags.

A 0.2 m x 0.04 m strip is clamped along one short edge and released under gravity; for each
material preset the script steps the simulation for 1 s with heavy damping and records the tip's
sag, the kinetic and the elastic energy, then writes a CSV (and prints it as a table) beside the
preset's bending length c = (B / (rho_A g))^(1/3), the quantity the cantilever test measures
(with --quick the strips are still falling at the end: a test of the script, not a result).

    PYTHONPATH=build/release/python /usr/bin/python3 python/examples/bending_study.py [--quick] [--out FILE.csv]

Cell by cell it reads like a notebook: build a scene as a dict, vary one key, step, read arrays.
"""
import argparse
import csv
import sys

import numpy as np

import clothsim

# Cell 1: the scene, a Python dict in the scene format (scenes/README.md).
def strip_scene(preset, divisions):
    return {
        "name": "strip_" + preset,
        "analysis": "dynamic",
        "mesh": {"primitive": "grid", "size": [0.2, 0.04], "divisions": divisions},
        "material": {"preset": preset},
        "boundary": [{"select": {"box": [[-1, -1, -1], [-0.0999, 1, 1]]}, "fix": ["x", "y", "z"], "rotation": "clamped"}],
        "loads": {"gravity": [0, 0, -9.81]},
        "damping": {"mass": 8.0, "stiffness": 0.001},
        "time": {"dt": 0.01, "end": 1.0, "output_fps": 10},
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="two presets, a coarse strip, 0.2 s")
    parser.add_argument("--out", default="bending_study.csv", help="CSV file to write")
    args = parser.parse_args()

    presets = ["cotton", "black_denim"] if args.quick else ["cotton", "black_denim", "gray_interlock", "wool_tropical_ortho"]
    divisions = [10, 2] if args.quick else [20, 4]
    rows = []
    for preset in presets:
        # Cell 2: load, step, read.
        sim = clothsim.Simulation(strip_scene(preset, divisions), set=["time.end=0.2"] if args.quick else [])
        x0 = sim.positions
        sim.run()
        x = sim.positions
        tip = x0[:, 0] > 0.0999  # the free short edge
        sag = float(x0[tip, 2].mean() - x[tip, 2].mean())
        e = sim.energies()
        rows.append({"preset": preset, "tip_sag_m": sag, "kinetic_J": e["kinetic"], "elastic_J": e["elastic"]})

    # Cell 3: the bending rigidity each preset used (from its scene), and the table.
    for r in rows:
        p = clothsim.presets()[r["preset"]]
        r["bending_rigidity"] = p["bending_rigidity"]
        r["bending_length_m"] = (p["bending_rigidity"] / (p["areal_density"] * 9.81)) ** (1 / 3)
    with open(args.out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["preset", "bending_rigidity", "bending_length_m", "tip_sag_m", "kinetic_J", "elastic_J"])
        w.writeheader()
        w.writerows(rows)
    print(f"{'preset':24s} {'B [N m]':>10s} {'c [mm]':>8s} {'tip sag [mm]':>13s}")
    for r in rows:
        print(f"{r['preset']:24s} {r['bending_rigidity']:10.3g} {1000 * r['bending_length_m']:8.1f} "
              f"{1000 * r['tip_sag_m']:13.2f}")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
