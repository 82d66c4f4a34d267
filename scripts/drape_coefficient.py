#!/usr/bin/env python3
"""Drape coefficient and node count of a draped disc (Cusick drape test, ISO 9073-9 / BS 5058).

Usage: drape_coefficient.py [--cell H] [--support-radius R0] [--specimen-radius R1]
                            [--prominence P] [--smooth W] [--angles N] FRAME.obj

Reads an OBJ frame of the cloth (v and f lines; best the refined limit surface written
with "output": {"obj": true, "obj_level": 2}), projects it vertically onto the x-z plane
(its shadow from above, gravity along -y) and prints

  A_shadow   area of the union of the projected triangles and the support disc (radius
             R0 about the y axis), by rasterising them on a
             square grid of cell H (default 0.5 mm): a cell counts if its centre lies
             in some projected triangle. The error is of the order of the cells cut by
             the outline; the script prints the bound (boundary cells) x H^2 / 2 and
             the area on a grid of cell 2H as a check.
  DC         = (A_shadow - A_support) / (A_specimen - A_support),
             A_support = pi R0^2 (R0 = 0.09 m), A_specimen = pi R1^2 (R1 = 0.15 m).
  nodes      folds: the outline radius r(theta) of the shadow (largest distance from
             the centre of the occupied cells in each of N = 720 angular bins, about
             the shadow's centroid), smoothed by a circular moving average over W
             bins (default 5 = 2.5 deg), and its local maxima with a topographic
             prominence of at least P (default 5 mm) counted.

Only the Python 3 standard library is used. Exit code 0 on success, 2 on bad usage.
"""
import argparse
import math
import sys


def read_obj(path):
    verts, tris = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                p = line.split()
                verts.append((float(p[1]), float(p[2]), float(p[3])))
            elif line.startswith("f "):
                idx = [int(t.split("/")[0]) for t in line.split()[1:]]
                idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
                for k in range(1, len(idx) - 1):  # fan-triangulate polygons
                    tris.append((idx[0], idx[k], idx[k + 1]))
    if not verts or not tris:
        raise ValueError("%s: no vertices or faces" % path)
    return verts, tris


def rasterise(pts, tris, h, x0, z0, nx, nz):
    """Occupancy grid (bytearray, row-major in z): cell (i, j) has centre
    (x0 + (i + 0.5) h, z0 + (j + 0.5) h); it is set if the centre is inside
    (or on the edge of) a projected triangle."""
    grid = bytearray(nx * nz)
    for a, b, c in tris:
        ax, az = pts[a]
        bx, bz = pts[b]
        cx, cz = pts[c]
        det = (bx - ax) * (cz - az) - (bz - az) * (cx - ax)
        if det == 0.0:
            continue
        i0 = max(0, int(math.floor((min(ax, bx, cx) - x0) / h - 0.5)))
        i1 = min(nx - 1, int(math.ceil((max(ax, bx, cx) - x0) / h - 0.5)))
        j0 = max(0, int(math.floor((min(az, bz, cz) - z0) / h - 0.5)))
        j1 = min(nz - 1, int(math.ceil((max(az, bz, cz) - z0) / h - 0.5)))
        eps = -1e-12 * abs(det)
        inv = 1.0 / det
        for j in range(j0, j1 + 1):
            pz = z0 + (j + 0.5) * h
            row = j * nx
            for i in range(i0, i1 + 1):
                if grid[row + i]:
                    continue
                px = x0 + (i + 0.5) * h
                # barycentric coordinates (sign-normalised by det)
                l1 = ((px - ax) * (cz - az) - (pz - az) * (cx - ax)) * inv
                l2 = ((bx - ax) * (pz - az) - (bz - az) * (px - ax)) * inv
                if l1 >= -1e-12 and l2 >= -1e-12 and l1 + l2 <= 1 + 1e-12:
                    grid[row + i] = 1
    return grid


def shadow(pts, tris, h, r0):
    """The projected triangles and the support disc (radius r0 about the y axis: opaque and under
    the specimen, so always in the shadow; a clamped specimen's mesh may leave its middle out)."""
    xs = [p[0] for p in pts] + [-r0, r0]
    zs = [p[1] for p in pts] + [-r0, r0]
    x0, z0 = min(xs) - 2 * h, min(zs) - 2 * h
    nx = int(math.ceil((max(xs) - x0) / h)) + 2
    nz = int(math.ceil((max(zs) - z0) / h)) + 2
    grid = rasterise(pts, tris, h, x0, z0, nx, nz)
    for j in range(max(0, int((-r0 - z0) / h) - 1), min(nz, int((r0 - z0) / h) + 2)):
        pz = z0 + (j + 0.5) * h
        for i in range(max(0, int((-r0 - x0) / h) - 1), min(nx, int((r0 - x0) / h) + 2)):
            px = x0 + (i + 0.5) * h
            if px * px + pz * pz <= r0 * r0:
                grid[j * nx + i] = 1
    return grid, x0, z0, nx, nz


def boundary_cells(grid, nx, nz):
    n = 0
    for j in range(1, nz - 1):
        r = j * nx
        for i in range(1, nx - 1):
            k = r + i
            if grid[k] and not (grid[k - 1] and grid[k + 1] and grid[k - nx] and grid[k + nx]):
                n += 1
    return n


def outline(grid, x0, z0, nx, nz, h, nang):
    occ = [(i, j) for j in range(nz) for i in range(nx) if grid[j * nx + i]]
    cx = sum(x0 + (i + 0.5) * h for i, _ in occ) / len(occ)
    cz = sum(z0 + (j + 0.5) * h for _, j in occ) / len(occ)
    r = [0.0] * nang
    for i, j in occ:
        dx = x0 + (i + 0.5) * h - cx
        dz = z0 + (j + 0.5) * h - cz
        rad = math.hypot(dx, dz) + 0.5 * h
        k = int((math.atan2(dz, dx) + math.pi) / (2 * math.pi) * nang) % nang
        if rad > r[k]:
            r[k] = rad
    return r, (cx, cz)


def smooth(r, w):
    n = len(r)
    if w <= 1:
        return list(r)
    half = w // 2
    return [sum(r[(k + d) % n] for d in range(-half, w - half)) / w for k in range(n)]


def count_nodes(r, prominence):
    """Local maxima of a circular sequence with topographic prominence >= prominence."""
    n = len(r)
    peaks = []
    k = 0
    for k in range(n):
        if r[k] > r[k - 1] and r[k] >= r[(k + 1) % n]:
            peaks.append(k)
    gmax = max(r)
    result = []
    for p in peaks:
        v = r[p]
        mins = []
        for step in (1, -1):
            m = v
            found = False
            for d in range(1, n):
                q = (p + step * d) % n
                if r[q] > v or (r[q] == v and q < p):
                    found = True
                    break
                m = min(m, r[q])
            mins.append(m if found else None)
        if mins[0] is None and mins[1] is None:  # the highest peak
            prom = v - min(r)
        else:
            prom = v - max(m for m in mins if m is not None)
        if prom >= prominence:
            result.append((p, v, prom))
    return result


def main(argv=None):
    ap = argparse.ArgumentParser(
        usage="%(prog)s [--cell H] [--support-radius R0] [--specimen-radius R1] "
              "[--prominence P] [--smooth W] [--angles N] FRAME.obj",
        description="Drape coefficient DC = (A_shadow - A_support)/(A_specimen - A_support) and "
                    "number of nodes (folds) of a draped disc, from an OBJ frame (y up). The shadow "
                    "is the vertical projection onto the x-z plane, rasterised on a grid of cell H; "
                    "nodes are the local maxima, with prominence >= P, of the smoothed outline "
                    "radius r(theta) sampled in N angular bins about the shadow's centroid.")
    ap.add_argument("obj", help="OBJ frame of the cloth, e.g. frames/mesh_0075.obj written with obj_level 2")
    ap.add_argument("--cell", type=float, default=0.0005, help="raster cell H [m] (default 0.0005)")
    ap.add_argument("--support-radius", type=float, default=0.09, help="R0 [m] (default 0.09)")
    ap.add_argument("--specimen-radius", type=float, default=0.15, help="R1 [m] (default 0.15)")
    ap.add_argument("--prominence", type=float, default=0.005, help="P [m] (default 0.005)")
    ap.add_argument("--smooth", type=int, default=5, help="moving-average width W in bins (default 5)")
    ap.add_argument("--angles", type=int, default=720, help="angular bins N (default 720)")
    ap.add_argument("--no-check", action="store_true", help="skip the area on the 2H grid")
    a = ap.parse_args(argv)
    if a.cell <= 0 or a.support_radius <= 0 or a.specimen_radius <= a.support_radius \
            or a.prominence < 0 or a.smooth < 1 or a.angles < 8:
        ap.error("need --cell > 0, 0 < R0 < R1, --prominence >= 0, --smooth >= 1, --angles >= 8")
    try:
        verts, tris = read_obj(a.obj)
    except (OSError, ValueError) as e:
        print("drape_coefficient: error: %s" % e, file=sys.stderr)
        return 1
    pts = [(v[0], v[2]) for v in verts]
    h = a.cell
    grid, x0, z0, nx, nz = shadow(pts, tris, h, a.support_radius)
    area = sum(grid) * h * h
    nb = boundary_cells(grid, nx, nz)
    err = 0.5 * nb * h * h
    a_sup = math.pi * a.support_radius ** 2
    a_spec = math.pi * a.specimen_radius ** 2
    dc = (area - a_sup) / (a_spec - a_sup)
    r, c = outline(grid, x0, z0, nx, nz, h, a.angles)
    rs = smooth(r, a.smooth)
    nodes = count_nodes(rs, a.prominence)
    print("file            %s" % a.obj)
    print("triangles       %d" % len(tris))
    print("cell            %.4g m (grid %d x %d)" % (h, nx, nz))
    print("A_shadow        %.6f m^2  (+- %.6f m^2 resolution bound: %d boundary cells x H^2/2)"
          % (area, err, nb))
    if not a.no_check:
        g2, _, _, _, _ = shadow(pts, tris, 2 * h, a.support_radius)
        a2 = sum(g2) * 4 * h * h
        print("A_shadow (2H)   %.6f m^2  (DC %.4f)" % (a2, (a2 - a_sup) / (a_spec - a_sup)))
    print("A_support       %.6f m^2, A_specimen %.6f m^2" % (a_sup, a_spec))
    print("DC              %.4f  (+- %.4f)" % (dc, err / (a_spec - a_sup)))
    print("outline radius  min %.4f m, max %.4f m, centroid (%.4f, %.4f) m"
          % (min(rs), max(rs), c[0], c[1]))
    print("nodes           %d  (prominence >= %g m; peaks at %s deg)"
          % (len(nodes), a.prominence,
             ", ".join("%.0f" % ((p + 0.5) * 360.0 / a.angles - 180.0) for p, _, _ in nodes)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
