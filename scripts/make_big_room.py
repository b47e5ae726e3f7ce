#!/usr/bin/env python3
"""Writes a furnished room of about N triangles as OBJ + MTL, for `radiosity bench --big`.

The room (6 x 2.8 x 5 m, two ceiling lights, a table, shelves, a sofa of boxes) is a handful
of quads; the triangle count comes from curved objects standing in it: copies of a model
(any triangulated OBJ, e.g. a scanned bunny) or, without one, a torus knot. Each copy is
subdivided with curved PN edges (Vlachos et al. 2001: edge midpoints on the cubic through
both ends along their vertex normals) until the room holds about N triangles, so the facets
are not coplanar and every one is its own surface, as in a real scan. Large outputs are not
meant to be committed: write them under target/ or /tmp.

  python3 scripts/make_big_room.py --triangles 120000 -o /tmp/big/room.obj
  python3 scripts/make_big_room.py --triangles 1000000 --model bunny.obj -o /tmp/big/room1m.obj

Needs numpy. Deterministic: the same arguments write the same file.
"""

import argparse
import math
import sys
from pathlib import Path

import numpy as np

# (name, Kd, Ke): reflectances of painted plaster, wood, fabric; lights by exitance.
MATERIALS = [
    ("wall", (0.70, 0.68, 0.64), None),
    ("floor", (0.45, 0.33, 0.22), None),
    ("ceiling", (0.80, 0.80, 0.80), None),
    ("wood", (0.50, 0.36, 0.22), None),
    ("fabric", (0.25, 0.35, 0.55), None),
    ("model", (0.65, 0.62, 0.58), None),
    ("lamp", (0.80, 0.80, 0.80), (40.0, 38.0, 34.0)),
]

ROOM = (6.0, 2.8, 5.0)  # x, y (up), z


def box(lo, hi):
    """The six outward quads of an axis-aligned box, counter-clockwise from outside."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 4, 7, 3), (1, 2, 6, 5), (0, 1, 5, 4), (3, 7, 6, 2)]
    return [[v[i] for i in q] for q in quads]


def room_quads():
    """Walls, floor and ceiling facing in, furniture as boxes, lights under the ceiling."""
    w, h, d = ROOM
    out = {
        "floor": [[(0, 0, 0), (0, 0, d), (w, 0, d), (w, 0, 0)]],
        "ceiling": [[(0, h, 0), (w, h, 0), (w, h, d), (0, h, d)]],
        "wall": [
            [(0, 0, 0), (w, 0, 0), (w, h, 0), (0, h, 0)],
            [(0, 0, d), (0, h, d), (w, h, d), (w, 0, d)],
            [(0, 0, 0), (0, h, 0), (0, h, d), (0, 0, d)],
            [(w, 0, 0), (w, 0, d), (w, h, d), (w, h, 0)],
        ],
        "wood": [],
        "fabric": [],
        "lamp": [],
    }
    # Table: top and four legs.
    out["wood"] += box((2.0, 0.72, 1.8), (4.0, 0.77, 3.0))
    for x, z in [(2.05, 1.85), (3.9, 1.85), (2.05, 2.9), (3.9, 2.9)]:
        out["wood"] += box((x, 0.0, z), (x + 0.05, 0.72, z + 0.05))
    # Shelves against the back wall.
    for y in (0.4, 0.9, 1.4, 1.9):
        out["wood"] += box((0.5, y, 0.02), (2.3, y + 0.03, 0.42))
    out["wood"] += box((0.48, 0.0, 0.02), (0.5, 1.95, 0.42)) + box((2.3, 0.0, 0.02), (2.32, 1.95, 0.42))
    # Sofa: seat, back, arms.
    out["fabric"] += box((1.0, 0.0, 4.0), (3.2, 0.42, 4.8)) + box((1.0, 0.42, 4.6), (3.2, 0.9, 4.8))
    out["fabric"] += box((0.8, 0.0, 4.0), (1.0, 0.62, 4.8)) + box((3.2, 0.0, 4.0), (3.4, 0.62, 4.8))
    # Two lights just under the ceiling, facing down.
    for x0, z0 in [(1.5, 1.2), (4.0, 3.3)]:
        y = h - 0.01
        out["lamp"].append([(x0, y, z0), (x0 + 0.5, y, z0), (x0 + 0.5, y, z0 + 0.5), (x0, y, z0 + 0.5)])
    return out


def torus_knot(segments=96, sides=12, p=2, q=3):
    """A (p, q) torus knot tube: the model when none is given."""
    t = np.linspace(0, 2 * math.pi, segments, endpoint=False)
    r = 2 + np.cos(q * t)
    c = np.stack([r * np.cos(p * t), -np.sin(q * t), r * np.sin(p * t)], axis=1)
    tang = np.roll(c, -1, axis=0) - np.roll(c, 1, axis=0)
    tang /= np.linalg.norm(tang, axis=1, keepdims=True)
    ref = np.array([0.0, 1.0, 0.0])
    n1 = np.cross(tang, ref)
    n1 /= np.linalg.norm(n1, axis=1, keepdims=True)
    n2 = np.cross(tang, n1)
    a = np.linspace(0, 2 * math.pi, sides, endpoint=False)
    verts = (c[:, None, :] + 0.45 * (np.cos(a)[None, :, None] * n1[:, None, :] + np.sin(a)[None, :, None] * n2[:, None, :]))
    verts = verts.reshape(-1, 3)
    faces = []
    for i in range(segments):
        for j in range(sides):
            a0, a1 = i * sides + j, i * sides + (j + 1) % sides
            b0, b1 = ((i + 1) % segments) * sides + j, ((i + 1) % segments) * sides + (j + 1) % sides
            faces += [(a0, b1, b0), (a0, a1, b1)]  # wound outwards (positive volume)
    return verts, np.array(faces)


def read_obj(path):
    """Vertices and triangles (polygons fanned) of an OBJ; everything else is ignored."""
    verts, faces = [], []
    for line in Path(path).read_text(errors="replace").splitlines():
        f = line.split()
        if not f:
            continue
        if f[0] == "v":
            verts.append([float(x) for x in f[1:4]])
        elif f[0] == "f":
            idx = [int(x.split("/")[0]) for x in f[1:]]
            idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
            faces += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]
    if not faces:
        sys.exit(f"{path}: no faces")
    return np.array(verts), np.array(faces)


def vertex_normals(v, f):
    n = np.zeros_like(v)
    fn = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    for k in range(3):
        np.add.at(n, f[:, k], fn)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.where(length > 0, length, 1)


def subdivide(v, f):
    """One curved 1-to-4 split: each edge's midpoint on the PN cubic of its ends."""
    n = vertex_normals(v, f)
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    key = np.sort(edges, axis=1)
    uniq, inverse = np.unique(key, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    p0, p1, n0, n1 = v[uniq[:, 0]], v[uniq[:, 1]], n[uniq[:, 0]], n[uniq[:, 1]]
    d = p1 - p0
    b1 = p0 + (d - np.sum(d * n0, axis=1, keepdims=True) * n0) / 3
    b2 = p1 + (-d + np.sum(d * n1, axis=1, keepdims=True) * n1) / 3
    mid = (p0 + 3 * b1 + 3 * b2 + p1) / 8
    m = len(f)
    e01, e12, e20 = (len(v) + inverse[k * m:(k + 1) * m] for k in range(3))
    a, b, c = f[:, 0], f[:, 1], f[:, 2]
    nf = np.concatenate([
        np.stack([a, e01, e20], 1), np.stack([e01, b, e12], 1),
        np.stack([e20, e12, c], 1), np.stack([e01, e12, e20], 1)])
    return np.concatenate([v, mid]), nf


def placed(v, centre, height):
    """The model scaled to `height`, standing on y = centre.y with its middle at centre."""
    lo, hi = v.min(0), v.max(0)
    s = height / (hi[1] - lo[1])
    mid = (lo + hi) / 2
    out = (v - mid) * s
    out[:, 1] += centre[1] + height / 2
    out[:, 0] += centre[0]
    out[:, 2] += centre[2]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--triangles", type=int, default=120_000, help="about how many in all")
    ap.add_argument("--model", help="a triangulated OBJ to place (default: a torus knot)")
    ap.add_argument("--copies", type=int, default=6, help="how many copies of the model")
    ap.add_argument("-o", "--output", required=True, help="the OBJ to write (an MTL beside it)")
    a = ap.parse_args()

    v, f = read_obj(a.model) if a.model else torus_knot()
    per_copy = a.triangles / a.copies
    while len(f) * 4 <= per_copy * 1.5:
        v, f = subdivide(v, f)
    # Places: on the table, on the shelves, on the floor.
    spots = [((2.6, 0.77, 2.4), 0.45), ((3.4, 0.77, 2.4), 0.45), ((1.0, 0.93, 0.22), 0.4),
             ((1.8, 1.43, 0.22), 0.4), ((5.0, 0.0, 1.0), 0.9), ((5.0, 0.0, 4.0), 0.9),
             ((1.4, 0.43, 0.22), 0.3), ((1.0, 1.93, 0.22), 0.5)]
    if a.copies > len(spots):
        sys.exit(f"--copies: at most {len(spots)}")

    out = Path(a.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    mtl = out.with_suffix(".mtl")
    with mtl.open("w") as m:
        for name, kd, ke in MATERIALS:
            m.write(f"newmtl {name}\nKd {kd[0]} {kd[1]} {kd[2]}\n")
            if ke:
                m.write(f"Ke {ke[0]} {ke[1]} {ke[2]}\n")
    lines = [f"# furnished room written by scripts/make_big_room.py\nmtllib {mtl.name}\n"]
    base, total = 1, 0
    for name, quads in room_quads().items():
        lines.append(f"o {name}\nusemtl {name}\n")
        for q in quads:
            lines.extend(f"v {x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in q)
            lines.append(f"f {base} {base + 1} {base + 2} {base + 3}\n")
            base += 4
            total += 2
    for k, (centre, height) in enumerate(spots[:a.copies]):
        pv = placed(v, centre, height)
        lines.append(f"o model_{k}\nusemtl model\n")
        lines.extend(f"v {x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in pv)
        lines.extend(f"f {i + base} {j + base} {l + base}\n" for i, j, l in f)
        base += len(pv)
        total += len(f)
    out.write_text("".join(lines))
    print(f"{out}: {total} triangles ({a.copies} copies of {len(f)})")


if __name__ == "__main__":
    main()
