#!/usr/bin/python3
"""Clean an assimp OBJ export of the MakeHuman test model into a closed body mesh.

Usage: make_body.py IN.obj OUT.obj [--command TEXT] [--source TEXT]

Called by scripts/make_body.sh (which runs the assimp conversion); it uses only
the Python standard library and numpy. Steps:
  1. read the triangles of IN.obj (positions only; "f a/b/c" forms and negative
     indices are accepted, a polygon with more than three corners is an error);
  2. weld vertices whose three coordinates are exactly equal (the exporter may
     split a vertex where the uv or normal differs) and drop triangles that
     become degenerate (two equal corners);
  3. split the triangles into connected components (sharing a vertex) and keep
     the largest component that is closed (no boundary edge), edge-manifold
     (every edge in exactly two triangles) and consistently oriented (every
     directed edge once); the source's small open eye parts are dropped here;
  4. drop unused vertices (kept in their original order) and, if the signed
     volume is negative, reverse every triangle so the normals face outward;
  5. write OUT.obj: a header comment, "v x y z" with 6 decimals and
     "f a b c" lines. The output depends only on the input, so a rerun on the
     same package version gives the same bytes.
"""
import argparse
import sys

import numpy as np


def read_obj(path):
    verts = []
    tris = []
    with open(path, "r", encoding="utf-8", errors="replace") as f:
        for lineno, line in enumerate(f, 1):
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                verts.append(parts[1:4])
            elif parts[0] == "f":
                idx = []
                for p in parts[1:]:
                    i = int(p.split("/")[0])
                    idx.append(i - 1 if i > 0 else len(verts) + i)
                if len(idx) != 3:
                    raise SystemExit(f"{path}:{lineno}: face with {len(idx)} corners "
                                     "(export with -tri)")
                tris.append(idx)
    if not verts or not tris:
        raise SystemExit(f"{path}: no vertices or no triangles")
    return verts, np.array(tris, dtype=np.int64)


def weld_exact(vert_text, tris):
    """Merge vertices whose coordinates are exactly equal (as parsed floats).

    Returns (positions, triangles, number merged); the first occurrence keeps its place."""
    key_to_new = {}
    remap = np.empty(len(vert_text), dtype=np.int64)
    keys = []
    for i, t in enumerate(vert_text):
        k = tuple(float(x) for x in t)
        j = key_to_new.get(k)
        if j is None:
            j = len(keys)
            key_to_new[k] = j
            keys.append(k)
        remap[i] = j
    pos = np.array(keys, dtype=np.float64)
    return pos, remap[tris], len(vert_text) - len(keys)


def components(nverts, tris):
    """Label of each triangle: the connected component (through shared vertices)."""
    parent = np.arange(nverts)

    def find(a):
        root = a
        while parent[root] != root:
            root = parent[root]
        while parent[a] != root:
            parent[a], a = root, parent[a]
        return root

    for a, b, c in tris.tolist():
        ra, rb, rc = find(a), find(b), find(c)
        parent[rb] = ra
        parent[find(rc)] = ra
    roots = np.array([find(v) for v in range(nverts)])
    return roots[tris[:, 0]]


def edge_stats(tris):
    """(boundary edges, non-manifold edges, inconsistently oriented edges, edge count)."""
    d = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    und = np.sort(d, axis=1)
    _, counts = np.unique(und, axis=0, return_counts=True)
    _, dcounts = np.unique(d, axis=0, return_counts=True)
    return (int((counts == 1).sum()), int((counts > 2).sum()),
            int((dcounts > 1).sum()), len(counts))


def signed_volume(pos, tris):
    a, b, c = pos[tris[:, 0]], pos[tris[:, 1]], pos[tris[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def fmt(x):
    s = f"{x:.6f}"
    return "0.000000" if s == "-0.000000" else s


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("inp")
    ap.add_argument("out")
    ap.add_argument("--command", default="scripts/make_body.sh",
                    help="command written into the header as the way to regenerate")
    ap.add_argument("--source", default="(unknown source)",
                    help="source description lines for the header ('|' separates lines)")
    args = ap.parse_args()

    vert_text, tris = read_obj(args.inp)
    n_in_v, n_in_t = len(vert_text), len(tris)
    pos, tris, merged = weld_exact(vert_text, tris)
    degenerate = (tris[:, 0] == tris[:, 1]) | (tris[:, 1] == tris[:, 2]) | (tris[:, 2] == tris[:, 0])
    tris = tris[~degenerate]
    log = lambda m: print(f"make_body: {m}", file=sys.stderr)
    log(f"read {n_in_v} vertices, {n_in_t} triangles; welded {merged} duplicate "
        f"positions; dropped {int(degenerate.sum())} degenerate triangles")

    label = components(len(pos), tris)
    best = None
    for lab in np.unique(label):
        t = tris[label == lab]
        b, nm, inc, _ = edge_stats(t)
        nv = len(np.unique(t))
        ok = b == 0 and nm == 0 and inc == 0
        log(f"component: {nv} vertices, {len(t)} triangles, {b} boundary edges, "
            f"{nm} non-manifold edges, {inc} badly oriented edges -> "
            f"{'closed' if ok else 'open/bad'}")
        if ok and (best is None or len(t) > len(best)):
            best = t
    if best is None:
        raise SystemExit("make_body: no closed, manifold, consistently oriented component")
    tris = best

    used = np.unique(tris)  # sorted: keeps the original vertex order
    new_index = np.full(len(pos), -1, dtype=np.int64)
    new_index[used] = np.arange(len(used))
    pos = pos[used]
    tris = new_index[tris]
    vol = signed_volume(pos, tris)
    if vol < 0:
        tris = tris[:, ::-1]
        vol = -vol
        log("signed volume was negative: reversed every triangle")
    b, nm, inc, ne = edge_stats(tris)
    assert b == 0 and nm == 0 and inc == 0
    euler = len(pos) - ne + len(tris)
    lo, hi = pos.min(axis=0), pos.max(axis=0)
    height = hi[1] - lo[1]
    log(f"kept {len(pos)} vertices, {len(tris)} triangles, Euler characteristic {euler}, "
        f"volume {vol * 1000:.3f} L, height {height:.4f} m")

    with open(args.out, "w", encoding="ascii", newline="\n") as f:
        w = f.write
        w("# Human body mesh for dressing garments (clothsim).\n")
        for line in args.source.split("|"):
            w(f"# {line}\n")
        w("# Licence: BSD-3-clause, Copyright 2006-2022 ASSIMP Development Team\n")
        w("#   (see scenes/bodies/LICENSE.human_female.txt).\n")
        w("# Units: metres. Axes: +y up, the body faces +z (its left side at +x),\n")
        w(f"#   feet at y = 0 (lowest vertex at y = {fmt(lo[1])}), centred on x = 0.\n")
        w(f"# {len(pos)} vertices, {len(tris)} triangles; one closed, edge-manifold,\n")
        w(f"#   outward-oriented component (Euler characteristic {euler}).\n")
        w(f"# Height {fmt(height)} m; bounding box min {fmt(lo[0])} {fmt(lo[1])} {fmt(lo[2])}, "
          f"max {fmt(hi[0])} {fmt(hi[1])} {fmt(hi[2])}.\n")
        w("# Kept the largest closed component (the eyes dropped), welded exact\n")
        w("#   duplicate positions, removed unused vertices; no normals or uv.\n")
        w(f"# Regenerate with: {args.command}\n")
        for x, y, z in pos:
            w(f"v {fmt(x)} {fmt(y)} {fmt(z)}\n")
        for a, b_, c in (tris + 1).tolist():
            w(f"f {a} {b_} {c}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
