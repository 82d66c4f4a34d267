#!/usr/bin/python3
"""How different two sleeve shapes are, whatever their meshes:
scripts/shape_difference.py A.obj B.obj [--bins 72x40]

Reads the vertices of two OBJ frames of a sleeve around the y axis (drawn surfaces, refined, e.g.
"output": {"obj": true, "obj_level": 1}), maps each to its outer-radius map r(theta, y): for every
cell of a grid of `bins` angles x heights over the common height range, the largest distance from
the y axis of the vertices in that cell, and prints the RMS and the largest difference of the two
maps over the cells both reach [mm], and the RMS radius change of each from the rest radius.
Needs numpy (python3-numpy, installed with python3-matplotlib).
"""
import argparse
import sys

import numpy as np


def read_points(path):
    pts = [[float(t) for t in line.split()[1:4]] for line in open(path, encoding="utf-8") if line.startswith("v ")]
    if not pts:
        sys.exit(f"{path}: no vertices")
    return np.array(pts)


def radius_map(points, n_theta, n_y, y_lo, y_hi):
    theta = np.mod(np.arctan2(points[:, 2], points[:, 0]), 2 * np.pi)
    r = np.hypot(points[:, 0], points[:, 2])
    i = np.minimum((theta / (2 * np.pi) * n_theta).astype(int), n_theta - 1)
    j = np.floor((points[:, 1] - y_lo) / (y_hi - y_lo) * n_y).astype(int)
    inside = (j >= 0) & (j < n_y)
    out = np.full((n_theta, n_y), np.nan)
    for a, b, v in zip(i[inside], j[inside], r[inside]):
        if np.isnan(out[a, b]) or v > out[a, b]:
            out[a, b] = v
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("a")
    parser.add_argument("b")
    parser.add_argument("--bins", default="72x40")
    parser.add_argument("--radius", type=float, default=0.05, help="rest radius [m]")
    args = parser.parse_args()
    n_theta, n_y = (int(v) for v in args.bins.split("x"))
    pa, pb = read_points(args.a), read_points(args.b)
    y_lo = max(pa[:, 1].min(), pb[:, 1].min())
    y_hi = min(pa[:, 1].max(), pb[:, 1].max())
    ma = radius_map(pa, n_theta, n_y, y_lo, y_hi)
    mb = radius_map(pb, n_theta, n_y, y_lo, y_hi)
    both = ~np.isnan(ma) & ~np.isnan(mb)
    d = (ma - mb)[both]
    print(f"cells {both.sum()} of {n_theta * n_y} (heights {y_lo * 1000:.1f} to {y_hi * 1000:.1f} mm)")
    print(f"RMS difference {np.sqrt(np.mean(d * d)) * 1000:.2f} mm, largest {np.abs(d).max() * 1000:.2f} mm")
    for name, m in (("A", ma), ("B", mb)):
        dev = m[both] - args.radius
        print(f"{name}: RMS radius change from rest {np.sqrt(np.mean(dev * dev)) * 1000:.2f} mm")
    return 0


if __name__ == "__main__":
    sys.exit(main())
