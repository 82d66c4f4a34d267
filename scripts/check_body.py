#!/usr/bin/python3
"""Check that an OBJ body mesh is a closed, manifold, outward-oriented triangle mesh.

Usage: check_body.py [--measure] [BODY.obj]      (default: scenes/bodies/human_female.obj)

Prints vertex/triangle/edge counts, connected components, boundary edges,
non-manifold edges, non-manifold vertices (a vertex whose triangles do not form
one closed fan; on an open mesh the boundary vertices count too), badly
oriented edges (a directed edge used twice), degenerate triangles, unused
vertices, the Euler characteristic (and genus when closed and
connected), signed volume, area, bounding box, height and edge lengths.

Exit status 0 when the mesh is closed and manifold and consistently oriented
with positive signed volume (outward normals); 1 otherwise (the reasons are
printed); 2 when the file cannot be read.

--measure adds body measurements computed from planar cross-sections (the
method is described in docs/body.md). They assume the conventions of
scenes/bodies/human_female.obj: metres, +y up, the body faces +z, arms out
towards +-x (A-pose); the numbers are printed for the +x side (the body's left)
and the script reports whether the mesh is mirror-symmetric in x.
Needs only python3 and numpy.
"""
import argparse
import os
import sys

import numpy as np


# ---------------------------------------------------------------- reading

def read_obj(path):
    verts, tris = [], []
    with open(path, "r", encoding="utf-8", errors="replace") as f:
        for lineno, line in enumerate(f, 1):
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                verts.append([float(x) for x in p[1:4]])
            elif p[0] == "f":
                idx = []
                for q in p[1:]:
                    i = int(q.split("/")[0])
                    idx.append(i - 1 if i > 0 else len(verts) + i)
                if len(idx) != 3:
                    raise ValueError(f"{path}:{lineno}: face with {len(idx)} corners")
                tris.append(idx)
    V = np.array(verts, dtype=np.float64).reshape(-1, 3)
    F = np.array(tris, dtype=np.int64).reshape(-1, 3)
    if len(F) and (F.min() < 0 or F.max() >= len(V)):
        raise ValueError(f"{path}: face index out of range")
    return V, F


# ---------------------------------------------------------------- topology checks

def component_count(nv, F):
    parent = list(range(nv))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for a, b, c in F.tolist():
        ra, rb, rc = find(a), find(b), find(c)
        parent[rb] = ra
        parent[find(rc)] = ra
    used = np.unique(F)
    return len({find(int(v)) for v in used})


def nonmanifold_vertices(nv, F):
    """Vertices whose incident triangles do not form a single closed fan."""
    # For vertex v in triangle (v, a, b) (in cyclic order) the link has the
    # directed edge a -> b. A closed-fan vertex has a link that is one cycle:
    # each neighbour appears once as a start and once as an end, and following
    # the edges from any start returns after visiting all of them.
    links = [dict() for _ in range(nv)]
    bad = set()
    for a, b, c in F.tolist():
        for v, p, q in ((a, b, c), (b, c, a), (c, a, b)):
            if p in links[v]:
                bad.add(v)
            links[v][p] = q
    for v in range(nv):
        L = links[v]
        if not L or v in bad:
            continue
        if set(L.keys()) != set(L.values()):
            bad.add(v)
            continue
        start = next(iter(L))
        cur, steps = L[start], 1
        while cur != start and steps <= len(L):
            cur = L[cur]
            steps += 1
        if steps != len(L):
            bad.add(v)
    return len(bad)


def mesh_facts(V, F):
    facts = {}
    facts["vertices"] = len(V)
    facts["triangles"] = len(F)
    d = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    und, counts = np.unique(np.sort(d, axis=1), axis=0, return_counts=True)
    _, dcounts = np.unique(d, axis=0, return_counts=True)
    facts["edges"] = len(und)
    facts["boundary_edges"] = int((counts == 1).sum())
    facts["nonmanifold_edges"] = int((counts > 2).sum())
    facts["badly_oriented_edges"] = int((dcounts > 1).sum())
    facts["degenerate_triangles"] = int(((F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2])
                                         | (F[:, 2] == F[:, 0])).sum())
    used = np.zeros(len(V), bool)
    used[F.ravel()] = True
    facts["unused_vertices"] = int((~used).sum())
    facts["duplicate_positions"] = len(V) - len(np.unique(V, axis=0))
    facts["nonmanifold_vertices"] = nonmanifold_vertices(len(V), F)
    facts["components"] = component_count(len(V), F)
    facts["euler_characteristic"] = int(used.sum()) - len(und) + len(F)
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    cr = np.cross(b - a, c - a)
    facts["zero_area_triangles"] = int((np.linalg.norm(cr, axis=1) == 0).sum())
    facts["signed_volume_L"] = float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0) * 1000
    facts["area_m2"] = float(np.linalg.norm(cr, axis=1).sum() / 2)
    lo, hi = V[used].min(axis=0), V[used].max(axis=0)
    facts["bbox_min"], facts["bbox_max"] = lo, hi
    facts["height_m"] = float(hi[1] - lo[1])
    el = np.linalg.norm(V[und[:, 0]] - V[und[:, 1]], axis=1)
    facts["edge_min_mm"] = float(el.min() * 1000)
    facts["edge_median_mm"] = float(np.median(el) * 1000)
    facts["edge_max_mm"] = float(el.max() * 1000)
    closed = facts["boundary_edges"] == 0 and facts["nonmanifold_edges"] == 0
    if closed and facts["components"] == 1:
        facts["genus"] = (2 - facts["euler_characteristic"]) // 2
    return facts


def failures(f):
    out = []
    for key in ("boundary_edges", "nonmanifold_edges", "nonmanifold_vertices",
                "badly_oriented_edges", "degenerate_triangles"):
        if f[key]:
            out.append(f"{key} = {f[key]}")
    if f["triangles"] == 0:
        out.append("no triangles")
    elif f["signed_volume_L"] <= 0:
        out.append(f"signed volume {f['signed_volume_L']:.3f} L <= 0 (normals face inward)")
    return out


# ---------------------------------------------------------------- cross-sections

def section(V, F, n, c):
    """Closed polylines where the plane n.x = c cuts the mesh (list of (k,3) arrays)."""
    n = np.asarray(n, float)
    d = V @ n - c
    above = d >= 0
    s = above[F]
    cut = F[s.any(axis=1) & ~s.all(axis=1)]
    adj, pts = {}, {}
    for t in cut.tolist():
        keys = []
        for i in range(3):
            a, b = t[i], t[(i + 1) % 3]
            if above[a] != above[b]:
                k = (a, b) if a < b else (b, a)
                if k not in pts:
                    w = d[a] / (d[a] - d[b])
                    pts[k] = V[a] + w * (V[b] - V[a])
                keys.append(k)
        adj.setdefault(keys[0], []).append(keys[1])
        adj.setdefault(keys[1], []).append(keys[0])
    loops, seen = [], set()
    for k0 in adj:
        if k0 in seen:
            continue
        loop, prev, cur = [k0], None, k0
        seen.add(k0)
        while True:
            nxt = adj[cur][0] if adj[cur][0] != prev else adj[cur][1]
            if nxt == k0 or nxt in seen:
                break
            loop.append(nxt)
            seen.add(nxt)
            prev, cur = cur, nxt
        loops.append(np.array([pts[k] for k in loop]))
    return loops


def hsection(V, F, y):
    return section(V, F, (0, 1, 0), y + 1.234e-6)  # offset: never exactly on a vertex


def perimeter(P):
    return float(np.linalg.norm(P - np.roll(P, -1, axis=0), axis=1).sum())


def area_centroid(P, n):
    n = np.asarray(n, float) / np.linalg.norm(n)
    c0 = P.mean(axis=0)
    a, b = P - c0, np.roll(P, -1, axis=0) - c0
    ar = 0.5 * (np.cross(a, b) @ n)
    A = ar.sum()
    return abs(float(A)), c0 + (ar[:, None] * (a + b) / 3).sum(axis=0) / A


def hull_perimeter_xz(P):
    """Perimeter of the convex hull of the section in x-z (a tape measure's length)."""
    pts = sorted(set(map(tuple, np.round(P[:, [0, 2]], 9))))

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    H = np.array(lower[:-1] + upper[:-1])
    return float(np.linalg.norm(H - np.roll(H, -1, axis=0), axis=1).sum())


def torso_loop(V, F, y):
    """The horizontal section loop around the body's midline (x = 0) at height y."""
    c = [P for P in hsection(V, F, y) if P[:, 0].min() < 0 < P[:, 0].max()]
    return max(c, key=perimeter) if c else None


def fit_line(C):
    m = C.mean(axis=0)
    return m, np.linalg.svd(C - m)[2][0]


def loop_distance(A, B):
    return float(np.linalg.norm(A[:, None, :] - B[None, :, :], axis=2).min())


def bisect(pred, lo, hi, tol=1e-4):
    """Largest y in [lo, hi] with pred(y) true, given pred(lo) and not pred(hi)."""
    while hi - lo > tol:
        m = 0.5 * (lo + hi)
        if pred(m):
            lo = m
        else:
            hi = m
    return lo


def refine_axis(V, F, m, u, span, sign_axis=0, iters=3):
    """Fit a limb axis through centroids of sections perpendicular to it."""
    for _ in range(iters):
        C = []
        for s in np.arange(-span, span + 1e-9, 0.01):
            p = m + s * u
            best = None
            for P in section(V, F, u, float(p @ u)):
                A, c = area_centroid(P, u)
                if best is None or np.linalg.norm(c - p) < best[0]:
                    best = (np.linalg.norm(c - p), c)
            C.append(best[1])
        m, u = fit_line(np.array(C))
        if u[sign_axis] < 0:
            u = -u
    return m, u


def axis_section(V, F, m, u, s):
    p = m + s * u
    best = None
    for P in section(V, F, u, float(p @ u)):
        A, c = area_centroid(P, u)
        dist = np.linalg.norm(c - p)
        if best is None or dist < best[0]:
            best = (dist, c, perimeter(P))
    return best


def closest_points(m1, u1, m2, u2):
    w = m1 - m2
    a, b, c, d, e = u1 @ u1, u1 @ u2, u2 @ u2, u1 @ w, u2 @ w
    den = a * c - b * b
    s, t = (b * e - c * d) / den, (a * e - b * d) / den
    return m1 + s * u1, m2 + t * u2


def deg(x):
    return float(np.degrees(x))


def measure(V, F):
    """Body measurements (see docs/body.md for the method). Returns (label, text) rows."""
    rows = []
    out = lambda k, v: rows.append((k, v))
    fmtp = lambda p: "(" + ", ".join(f"{x:+.3f}" for x in p) + ")"
    ymin, ymax = V[:, 1].min(), V[:, 1].max()
    H = ymax - ymin
    mirror = V * np.array([-1.0, 1.0, 1.0])
    same = (np.array_equal(np.unique(np.round(V, 6), axis=0), np.unique(np.round(mirror, 6), axis=0)))
    out("mirror symmetric in x", "yes (every vertex has an exact mirror image)" if same else "no")

    # Armpit: highest y at which the +x arm is still a separate section loop.
    def arm_separate(y):
        return any(P[:, 0].min() > 0.01 for P in hsection(V, F, y))
    y_ap = bisect(arm_separate, ymin + 0.70 * H, ymin + 0.82 * H)
    L = hsection(V, F, y_ap)
    T = max((P for P in L if P[:, 0].min() < 0 < P[:, 0].max()), key=perimeter)
    A = min((P for P in L if P[:, 0].min() > 0.01), key=lambda P: P[:, 0].min())
    dd = np.linalg.norm(T[:, None, :] - A[None, :, :], axis=2)
    i, j = np.unravel_index(dd.argmin(), dd.shape)
    armpit = 0.5 * (T[i] + A[j])
    out("armpit apex", fmtp(armpit))

    # Upper-arm axis: start from centroids of x = const sections, then refine with
    # sections perpendicular to the axis.
    C = []
    for x in np.arange(armpit[0] + 0.05, armpit[0] + 0.1301, 0.01):
        P = max(section(V, F, (1, 0, 0), x + 1.234e-6), key=lambda P: P[:, 1].mean())
        C.append(area_centroid(P, (1, 0, 0))[1])
    m1, u1 = fit_line(np.array(C))
    u1 = u1 if u1[0] > 0 else -u1
    m1, u1 = refine_axis(V, F, m1, u1, 0.05)
    # Elbow: the perpendicular sections' centroids leave the upper-arm axis there.
    s_dev = None
    for s in np.arange(0.0, 0.3, 0.005):
        if axis_section(V, F, m1, u1, s)[0] > 0.005:
            s_dev = s
            break
    p_dev = m1 + s_dev * u1
    C = []
    for x in np.arange(p_dev[0] + 0.03, p_dev[0] + 0.0801, 0.01):
        P = max(section(V, F, (1, 0, 0), x + 1.234e-6), key=lambda P: P[:, 1].mean())
        C.append(area_centroid(P, (1, 0, 0))[1])
    m2, u2 = fit_line(np.array(C))
    u2 = u2 if u2[0] > 0 else -u2
    m2, u2 = refine_axis(V, F, m2, u2, 0.04)
    q1, q2 = closest_points(m1, u1, m2, u2)
    elbow = 0.5 * (q1 + q2)
    # Wrist: narrowest perpendicular forearm section before the hand widens.
    t0 = float((elbow - m2) @ u2)
    best, t = None, t0 + 0.10
    while t < t0 + 0.45:
        per = axis_section(V, F, m2, u2, t)[2]
        if best is None or per < best[0]:
            best = (per, t)
        elif per > 1.25 * best[0]:
            break
        t += 0.005
    wrist = m2 + best[1] * u2
    # Acromion: corner of the top outline (highest point of x = const sections)
    # where the gentle shoulder slope meets the steeper top of the arm.
    def top(x):
        return max(P[:, 1].max() for P in section(V, F, (1, 0, 0), x + 1.234e-6))
    xa = np.arange(armpit[0] - 0.065, armpit[0] + 0.0051, 0.01)
    xb = np.arange(armpit[0] + 0.065, armpit[0] + 0.1251, 0.01)
    pa = np.polyfit(xa, [top(x) for x in xa], 1)
    pb = np.polyfit(xb, [top(x) for x in xb], 1)
    x_ac = (pb[1] - pa[1]) / (pa[0] - pb[0])
    y_ac = np.polyval(pa, x_ac)
    shoulder = m1 + ((x_ac - m1[0]) / u1[0]) * u1
    out("acromion (shoulder corner)", fmtp((x_ac, y_ac, shoulder[2])))
    out("shoulder joint centre", fmtp(shoulder) + "  (upper-arm axis below the acromion)")
    out("elbow joint centre", fmtp(elbow) + f"  (axes {np.linalg.norm(q1 - q2) * 1000:.1f} mm apart)")
    out("wrist (narrowest forearm section)", fmtp(wrist) + f"  perimeter {best[0]:.3f} m")
    out("upper arm from vertical", f"{deg(np.arccos(-u1[1])):.1f} deg (in the x-y plane "
        f"{deg(np.arctan2(u1[0], -u1[1])):.1f} deg, forward {deg(np.arcsin(u1[2])):.1f} deg)")
    out("forearm from vertical", f"{deg(np.arccos(-u2[1])):.1f} deg (forward "
        f"{deg(np.arcsin(u2[2])):.1f} deg); elbow bend {deg(np.arccos(u1 @ u2)):.1f} deg")
    out("shoulder-elbow / elbow-wrist", f"{np.linalg.norm(elbow - shoulder):.3f} m / "
        f"{np.linalg.norm(wrist - elbow):.3f} m")

    # Crotch: highest y at which the legs are two separate loops (hands excluded).
    def legs_apart(y):
        return len([P for P in hsection(V, F, y) if abs(P[:, 0].mean()) < 0.3]) >= 2
    y_cr = bisect(legs_apart, ymin + 0.35 * H, ymin + 0.55 * H)
    out("crotch height", f"{y_cr:.3f} m")
    rows_leg = []
    for y in np.arange(ymin + 0.04, y_cr - 0.005, 0.01):
        P = min((P for P in hsection(V, F, y) if P[:, 0].min() >= 0), key=lambda P: P[:, 0].mean())
        rows_leg.append((y, area_centroid(P, (0, 1, 0))[1], perimeter(P)))
    Y = np.array([r[0] for r in rows_leg])
    Cl = np.array([r[1] for r in rows_leg])
    Pl = np.array([r[2] for r in rows_leg])
    knee_band = (Y >= ymin + 0.22 * H) & (Y <= ymin + 0.33 * H)
    k = np.argmin(np.where(knee_band, Pl, np.inf))
    out("knee (narrowest leg section, 0.22H-0.33H)", fmtp(Cl[k]) + f"  perimeter {Pl[k]:.3f} m")
    ank = (Y >= ymin + 0.04 * H) & (Y <= ymin + 0.10 * H)
    k = np.argmin(np.where(ank, Pl, np.inf))
    out("ankle (narrowest leg section, 0.04H-0.10H)", fmtp(Cl[k]) + f"  perimeter {Pl[k]:.3f} m")
    thigh = (Y >= ymin + 0.33 * H) & (Y <= y_cr - 0.03)
    mt, ut = fit_line(Cl[thigh])
    ut = ut if ut[1] > 0 else -ut
    shank = (Y >= ymin + 0.09 * H) & (Y <= ymin + 0.23 * H)
    ms, us = fit_line(Cl[shank])
    us = us if us[1] > 0 else -us
    y_hip = ymin + 0.53 * H
    hip = mt + ((y_hip - mt[1]) / ut[1]) * ut
    out("hip joint centre", fmtp(hip) + "  (thigh axis at 0.53 H)")
    out("thigh / shank axis from vertical", f"{deg(np.arccos(ut[1])):.1f} / {deg(np.arccos(us[1])):.1f} deg")

    # Girths: horizontal torso section (its own perimeter, and the convex hull = tape).
    ys = np.arange(y_ap - 0.15, y_ap - 0.02, 0.005)
    y_bust = ys[np.argmax([torso_loop(V, F, y)[:, 2].max() for y in ys])]
    ys = np.arange(y_cr + 0.15, y_ap - 0.15, 0.005)
    y_waist = ys[np.argmin([perimeter(torso_loop(V, F, y)) for y in ys])]
    ys = np.arange(y_cr + 0.02, y_waist, 0.005)
    y_hipg = ys[np.argmin([torso_loop(V, F, y)[:, 2].min() for y in ys])]
    for name, y in (("bust (most forward point)", y_bust), ("waist (smallest)", y_waist),
                    ("hip (most backward point)", y_hipg)):
        P = torso_loop(V, F, y)
        out(f"girth {name}", f"y = {y:.3f} m: section {perimeter(P):.3f} m, "
            f"tape (convex hull) {hull_perimeter_xz(P):.3f} m")

    # Clearances.
    for dy in (0.02, 0.05, 0.10):
        L = hsection(V, F, y_ap - dy)
        T = max((P for P in L if P[:, 0].min() < 0 < P[:, 0].max()), key=perimeter)
        A = min((P for P in L if P[:, 0].min() > 0.01), key=lambda P: P[:, 0].min())
        out(f"arm-torso gap {dy * 100:.0f} cm below armpit", f"{loop_distance(T, A) * 100:.1f} cm")
    for dy in (0.02, 0.05):
        L = [P for P in hsection(V, F, y_cr - dy) if abs(P[:, 0].mean()) < 0.3]
        R = min((P for P in L if P[:, 0].min() >= 0), key=lambda P: P[:, 0].mean())
        Lf = max((P for P in L if P[:, 0].max() <= 0), key=lambda P: P[:, 0].mean())
        out(f"thigh-thigh gap {dy * 100:.0f} cm below crotch", f"{loop_distance(R, Lf) * 100:.1f} cm")
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("obj", nargs="?",
                    default=os.path.join(here, "..", "scenes", "bodies", "human_female.obj"))
    ap.add_argument("--measure", action="store_true", help="also print body measurements")
    args = ap.parse_args()
    try:
        V, F = read_obj(args.obj)
    except (OSError, ValueError) as e:
        print(f"check_body: {e}", file=sys.stderr)
        return 2
    f = mesh_facts(V, F)
    for k, v in f.items():
        if isinstance(v, float):
            v = f"{v:.4f}"
        elif isinstance(v, np.ndarray):
            v = " ".join(f"{x:+.4f}" for x in v)
        print(f"{k}: {v}")
    print(f"outward_oriented: {'yes' if f['signed_volume_L'] > 0 else 'no'}")
    bad = failures(f)
    if not bad and args.measure:
        for k, v in measure(V, F):
            print(f"{k}: {v}")
    if bad:
        print("check_body: FAIL: " + "; ".join(bad))
        return 1
    print("check_body: OK (closed, manifold, consistently oriented, outward)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
