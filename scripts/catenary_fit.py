#!/usr/bin/python3
"""Sag and shape of the hanging fold of `sleeve_catenary`:
scripts/catenary_fit.py RUN_DIR [--frame N]

Reads RUN_DIR/frames/mesh_0000.obj (the rest shape) and mesh_N.obj (default: the last frame),
written with "output": {"obj": true} (obj_level 0: one point per control vertex). The fold's crest
is the sleeve's top line: the vertices highest at rest (the generator through both hooks). Reports
  - the hooks' span and the line's length at rest (the chain),
  - the sag: the hooks' mean height minus the line's lowest point [mm],
  - the sag of an inextensible chain of that length over that span (a catenary:
    a sinh(span / 2a) = length / 2, sag = a (cosh(span / 2a) - 1)),
  - a least-squares catenary y = y0 + a (cosh((x - x0) / a) - 1) through the line's lower half
    (the points below the middle of the sag) and the RMS distance of those points from it, with
    the same for a parabola (to tell the two shapes apart).
Needs numpy (python3-numpy, installed with python3-matplotlib).
"""
import argparse
import glob
import math
import os
import sys

import numpy as np


def read_points(path):
    pts = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.startswith("v "):
                pts.append([float(t) for t in line.split()[1:4]])
    if not pts:
        sys.exit(f"{path}: no vertices")
    return np.array(pts)


def chain_sag(span, length):
    """Sag of an inextensible chain of `length` hanging over `span` (length > span)."""
    half_s, half_l = span / 2.0, length / 2.0
    lo, hi = 1e-9, 600.0  # bisection on x = half_s / a: sinh(x)/x = half_l/half_s is increasing in x
    ratio = half_l / half_s
    for _ in range(200):
        mid = math.sqrt(lo * hi)
        if math.sinh(mid) / mid < ratio:
            lo = mid
        else:
            hi = mid
    x = math.sqrt(lo * hi)
    a = half_s / x
    return a * (math.cosh(x) - 1.0), a


def fit(xs, ys, model):
    """Least squares over the shape parameter by golden search; the rest is linear."""
    def residual(a):
        basis = model(xs, a)
        A = np.column_stack([np.ones_like(xs), basis])
        coef, *_ = np.linalg.lstsq(A, ys, rcond=None)
        r = ys - A @ coef
        return float(np.sqrt(np.mean(r * r))), coef
    best = None
    for a in np.geomspace(1e-3, 1.0, 400):
        rms, coef = residual(a)
        if best is None or rms < best[0]:
            best = (rms, a, coef)
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir")
    parser.add_argument("--frame", type=int, default=None)
    args = parser.parse_args()
    frames = sorted(glob.glob(os.path.join(args.run_dir, "frames", "mesh_*.obj")))
    if len(frames) < 2:
        sys.exit(f"{args.run_dir}/frames: needs mesh_0000.obj and a later frame (\"output\": {{\"obj\": true}})")
    rest = read_points(frames[0])
    last = frames[-1] if args.frame is None else os.path.join(args.run_dir, "frames", f"mesh_{args.frame:04d}.obj")
    now = read_points(last)
    top = np.where(rest[:, 1] > rest[:, 1].max() - 1e-6)[0]
    line_rest = rest[top][np.argsort(rest[top][:, 0])]
    line = now[top][np.argsort(rest[top][:, 0])]
    length = float(np.sum(np.linalg.norm(np.diff(line_rest, axis=0), axis=1)))
    span = float(np.linalg.norm(line[-1] - line[0]))
    hooks_y = 0.5 * (line[0, 1] + line[-1, 1])
    sag = hooks_y - float(line[:, 1].min())
    chain, a_chain = chain_sag(span, length)
    lower = line[line[:, 1] < hooks_y - 0.5 * sag]
    xs = lower[:, 0] - float(line[np.argmin(line[:, 1]), 0])
    ys = lower[:, 1]
    cat = fit(xs, ys, lambda x, a: a * (np.cosh(x / a) - 1.0))
    par = fit(xs, ys, lambda x, a: x * x / (2.0 * a))
    print(f"frame {os.path.basename(last)}: {len(top)} points on the crest line")
    print(f"span between the hooks {span * 1000:.1f} mm, crest length at rest {length * 1000:.1f} mm")
    print(f"sag {sag * 1000:.1f} mm; inextensible chain of that length and span: {chain * 1000:.1f} mm (a = {a_chain * 1000:.1f} mm)")
    print(f"lower half ({len(lower)} points): catenary a = {cat[1] * 1000:.1f} mm, RMS {cat[0] * 1000:.2f} mm; "
          f"parabola RMS {par[0] * 1000:.2f} mm")
    return 0


if __name__ == "__main__":
    sys.exit(main())
