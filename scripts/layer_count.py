#!/usr/bin/env python3
"""Layers of cloth over the ground in an OBJ frame (for `sheet_fall`: did it fold over itself?).

Usage: scripts/layer_count.py FRAME.obj [--up y] [--cell 0.005]

Casts a vertical ray (along the `--up` axis, default y) through the centre of every cell of a
square grid (side `--cell` metres) over the surface's footprint and counts the triangles it
crosses: the number of layers of cloth at that place. Prints the footprint area (cells with at
least one layer) and the share of it covered by 1, 2, 3 and more layers. Plain Python (no
packages): triangles are binned by the grid cells their footprint covers.
"""
import argparse
import collections
import math
import sys


def read_obj(path):
    vertices, triangles = [], []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                vertices.append(tuple(float(c) for c in parts[1:4]))
            elif parts[0] == "f":
                idx = [int(p.split("/")[0]) for p in parts[1:]]
                idx = [i - 1 if i > 0 else len(vertices) + i for i in idx]
                for k in range(1, len(idx) - 1):
                    triangles.append((idx[0], idx[k], idx[k + 1]))
    if not vertices or not triangles:
        raise ValueError(f"{path}: no vertices or no faces")
    return vertices, triangles


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("obj")
    parser.add_argument("--up", choices="xyz", default="y")
    parser.add_argument("--cell", type=float, default=0.005, help="grid spacing [m]")
    args = parser.parse_args()
    try:
        vertices, triangles = read_obj(args.obj)
    except (OSError, ValueError) as e:
        sys.exit(f"layer_count: {e}")
    up = "xyz".index(args.up)
    a, b = [k for k in range(3) if k != up]
    pts = [(v[a], v[b]) for v in vertices]
    lo_a = min(p[0] for p in pts)
    lo_b = min(p[1] for p in pts)
    cell = args.cell
    bins = collections.defaultdict(list)
    for t, (i, j, k) in enumerate(triangles):
        xs = [pts[i][0], pts[j][0], pts[k][0]]
        ys = [pts[i][1], pts[j][1], pts[k][1]]
        for gx in range(math.floor((min(xs) - lo_a) / cell - 0.5), math.floor((max(xs) - lo_a) / cell - 0.5) + 2):
            for gy in range(math.floor((min(ys) - lo_b) / cell - 0.5), math.floor((max(ys) - lo_b) / cell - 0.5) + 2):
                bins[(gx, gy)].append(t)
    counts = collections.Counter()
    for (gx, gy), tris in sorted(bins.items()):
        # (nudged off the cell centre by an irrational fraction so no ray runs exactly through an
        # edge or vertex the grid is aligned with, where a shared edge would count twice or never)
        px, py = lo_a + (gx + 0.5 + 1e-4 * math.sqrt(2)) * cell, lo_b + (gy + 0.5 + 1e-4 * math.sqrt(3)) * cell
        layers = 0
        for t in tris:
            (x0, y0), (x1, y1), (x2, y2) = (pts[i] for i in triangles[t])
            d = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
            if d == 0:
                continue
            s = ((px - x0) * (y2 - y0) - (x2 - x0) * (py - y0)) / d
            u = ((x1 - x0) * (py - y0) - (px - x0) * (y1 - y0)) / d
            if s >= 0 and u >= 0 and s + u <= 1:
                layers += 1
        if layers:
            counts[min(layers, 3)] += 1
    total = sum(counts.values())
    if total == 0:
        sys.exit("layer_count: the surface has no footprint")
    area = total * cell * cell
    shares = {k: counts[k] / total for k in (1, 2, 3)}
    print(f"footprint {area:.4f} m2; 1 layer {100 * shares[1]:.1f} %, 2 layers {100 * shares[2]:.1f} %, "
          f"3 or more {100 * shares[3]:.1f} %")


if __name__ == "__main__":
    main()
