#!/usr/bin/env python3
"""Write a triangulated disc as an OBJ file (a mesh for Loop subdivision).

Usage: make_disc_mesh.py [--radius R] [--rings N] [--uv] OUT.obj

The disc lies in the x-z plane at y = 0, centred at the origin, with its
triangles oriented so that the normal is +y. Ring k (k = 1..N) has 6*k vertices
evenly spaced on the circle of radius R*k/N (vertex j at angle 2*pi*j/(6k),
x = r cos(theta), z = -r sin(theta)); the centre is one vertex. Consecutive
rings are joined as in a hexagonal lattice (6 sectors of 2k-1 triangles), so
every interior vertex has valence 6 and every boundary vertex valence 4, except
the 6 boundary "corner" vertices of the sectors (valence 3).
Counts: 1 + 3N(N+1) vertices, 6N^2 triangles. The output is deterministic
(fixed formatting, no randomness). With --uv every vertex also gets texture
coordinates u = (x/R + 1)/2, v = (1 - z/R)/2 (a planar map: +u along +x, +v
along -z), written as "vt" lines and "f a/a b/b c/c" faces, so that a woven
material's grain can be measured from them (docs/materials.md, Grain: warp = +u).

Example: make_disc_mesh.py --radius 0.15 --rings 20 scenes/meshes/cusick_disc_r015.obj
"""
import argparse
import math
import sys


def disc(radius, rings):
    verts = [(0.0, 0.0, 0.0)]
    start = [0]  # index of the first vertex of ring k
    for k in range(1, rings + 1):
        start.append(len(verts))
        r = radius * k / rings
        n = 6 * k
        for j in range(n):
            t = 2.0 * math.pi * j / n
            verts.append((r * math.cos(t), 0.0, -r * math.sin(t)))

    def ring(k, j):
        if k == 0:
            return 0
        return start[k] + (j % (6 * k))

    tris = []
    for k in range(1, rings + 1):
        for s in range(6):
            for i in range(k):  # triangles with an edge on ring k
                tris.append((ring(k, s * k + i), ring(k, s * k + i + 1),
                             ring(k - 1, s * (k - 1) + i)))
            for i in range(k - 1):  # triangles with an edge on ring k-1
                tris.append((ring(k - 1, s * (k - 1) + i), ring(k, s * k + i + 1),
                             ring(k - 1, s * (k - 1) + i + 1)))
    # orient every triangle so that its normal points to +y
    out = []
    for a, b, c in tris:
        pa, pb, pc = verts[a], verts[b], verts[c]
        ux, uz = pb[0] - pa[0], pb[2] - pa[2]
        vx, vz = pc[0] - pa[0], pc[2] - pa[2]
        ny = uz * vx - ux * vz  # y component of (pb-pa) x (pc-pa)
        out.append((a, b, c) if ny > 0 else (a, c, b))
    return verts, out


def main(argv=None):
    ap = argparse.ArgumentParser(
        description="Write a triangulated disc (x-z plane, y = 0, normal +y) as OBJ: "
                    "concentric rings with 6k vertices on ring k, mostly valence-6 vertices.",
        usage="%(prog)s [--radius R] [--rings N] [--uv] OUT.obj")
    ap.add_argument("out", help="output OBJ path ('-' for stdout)")
    ap.add_argument("--radius", type=float, default=0.15, help="disc radius [m] (default 0.15)")
    ap.add_argument("--rings", type=int, default=20,
                    help="number of rings N (default 20: 1261 vertices, 2400 triangles)")
    ap.add_argument("--uv", action="store_true",
                    help="also write texture coordinates (planar: +u along +x, +v along -z)")
    a = ap.parse_args(argv)
    if not (a.radius > 0 and math.isfinite(a.radius)):
        ap.error("--radius must be a finite number > 0")
    if a.rings < 1:
        ap.error("--rings must be >= 1")
    verts, tris = disc(a.radius, a.rings)
    lines = ["# disc: radius %g m, %d rings, %d vertices, %d triangles; x-z plane, normal +y"
             % (a.radius, a.rings, len(verts), len(tris)),
             "# written by scripts/make_disc_mesh.py --radius %g --rings %d" % (a.radius, a.rings)]
    def fmt(c):
        s = "%.9f" % c
        return "0.000000000" if s == "-0.000000000" else s
    for x, y, z in verts:
        lines.append("v %s %s %s" % (fmt(x), fmt(y), fmt(z)))
    if a.uv:
        for x, y, z in verts:
            lines.append("vt %s %s" % (fmt((x / a.radius + 1) / 2), fmt((1 - z / a.radius) / 2)))
    for t in tris:
        if a.uv:
            lines.append("f %d/%d %d/%d %d/%d" % (t[0] + 1, t[0] + 1, t[1] + 1, t[1] + 1, t[2] + 1, t[2] + 1))
        else:
            lines.append("f %d %d %d" % (t[0] + 1, t[1] + 1, t[2] + 1))
    text = "\n".join(lines) + "\n"
    if a.out == "-":
        sys.stdout.write(text)
    else:
        with open(a.out, "w", newline="\n") as f:
            f.write(text)
    print("wrote %s: %d vertices, %d triangles" % (a.out, len(verts), len(tris)), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
