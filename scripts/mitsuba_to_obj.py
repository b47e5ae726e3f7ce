#!/usr/bin/env python3
"""Merge a Mitsuba-style scene (an XML file naming PLY or OBJ meshes) into one OBJ with an MTL.

Many public interiors (Benedikt Bitterli's rendering resources, their minpt and Tungsten
ports) come as a scene XML listing dozens of PLY files, each with its own transform. This
program reads OBJ/MTL and glTF, so such a room is merged first:

    python3 scripts/mitsuba_to_obj.py living-room/scene.xml living.obj
    python3 scripts/real_rooms.py living.obj          # adds a ceiling panel light
    cargo run --release -- verify living.toml

What is read:

* Shapes: `<shape type="ply">`, `<shape type="obj">` (Mitsuba 0.6 / 3) and `<mesh type="ply">`
  (the minpt dialect), each with `<string name="filename">` relative to the XML's folder; and
  Mitsuba's built-in `rectangle` ([-1, 1]² at z = 0, facing +z), `disk` (the unit disk at
  z = 0, facing +z, as a 32-sided polygon) and `cube` ([-1, 1]³, facing out), through their
  transform. A rectangle is how most of these scenes write their area lights (and some walls).
* Transforms: `<transform name="toWorld">` or `name="to_world"` holding `<matrix value="16
  numbers, row major">`, `<translate x y z>`, `<scale value | x y z>`, `<rotate x y z
  angle>` (degrees); other steps (lookat) are refused by name, so a wrong placement cannot pass unnoticed.
* PLY: ascii and binary (little or big endian), any scalar vertex property types (only x, y,
  z are kept), faces as a list property named vertex_indices or vertex_index.
* Materials: a diffuse BSDF's `reflectance` / `albedo` as `<rgb value>` becomes that Kd; a
  textured, non-diffuse (mirror, conductor, dielectric, ...) or missing BSDF becomes the
  --grey Kd (default 0.5), as a radiosity solve has no textures or specular transport.
  `<ref id>` to a BSDF declared at the top level is followed.
* Shapes with an area emitter are written as their own group with `Ke` in their material,
  so the lights the scene came with are kept; environment lights are dropped with a note.

One `g` group per shape, named after its file (a second use of the same file gets `_2`,
...), so `verify` reports per object. Nothing is written over an existing file unless
--force is given.
"""

import argparse
import os
import struct
import sys
import xml.etree.ElementTree as ET

PLY_TYPES = {
    "char": "b", "int8": "b", "uchar": "B", "uint8": "B",
    "short": "h", "int16": "h", "ushort": "H", "uint16": "H",
    "int": "i", "int32": "i", "uint": "I", "uint32": "I",
    "float": "f", "float32": "f", "double": "d", "float64": "d",
}


class SceneError(Exception):
    """A problem with the input, reported as one line naming the file."""


def mat_mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def identity():
    return [[1.0 if i == j else 0.0 for j in range(4)] for i in range(4)]


def read_transform(elem, where):
    """The 4x4 row-major matrix of a shape's toWorld transform (identity when absent)."""
    m = identity()
    for t in elem.findall("transform"):
        if t.get("name") not in ("toWorld", "to_world"):
            continue
        for step in t:
            if step.tag == "matrix":
                vals = [float(x) for x in step.get("value").replace(",", " ").split()]
                if len(vals) != 16:
                    raise SceneError(f"{where}: a matrix needs 16 numbers, found {len(vals)}")
                s = [vals[4 * i:4 * i + 4] for i in range(4)]
            elif step.tag == "translate":
                s = identity()
                for i, k in enumerate("xyz"):
                    s[i][3] = float(step.get(k, 0))
            elif step.tag == "scale":
                s = identity()
                if step.get("value") is not None:
                    v = [float(step.get("value"))] * 3
                else:
                    v = [float(step.get(k, 1)) for k in "xyz"]
                for i in range(3):
                    s[i][i] = v[i]
            elif step.tag == "rotate":
                # Rodrigues' rotation about the unit axis (x, y, z) by `angle` degrees.
                import math
                ax = [float(step.get(k, 0)) for k in "xyz"]
                norm = math.sqrt(sum(a * a for a in ax))
                if norm == 0:
                    raise SceneError(f"{where}: <rotate> needs a non-zero axis")
                x, y, z = (a / norm for a in ax)
                t = math.radians(float(step.get("angle", 0)))
                c, sn, k = math.cos(t), math.sin(t), 1 - math.cos(t)
                s = identity()
                s[0][:3] = [c + x * x * k, x * y * k - z * sn, x * z * k + y * sn]
                s[1][:3] = [y * x * k + z * sn, c + y * y * k, y * z * k - x * sn]
                s[2][:3] = [z * x * k - y * sn, z * y * k + x * sn, c + z * z * k]
            else:
                raise SceneError(f"{where}: transform step <{step.tag}> is not supported")
            # Mitsuba applies the steps in the order written: later ones act on the result.
            m = mat_mul(s, m)
    return m


def apply(m, p):
    return tuple(m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + m[i][3] for i in range(3))


def read_ply(path):
    """Vertex positions and faces (lists of vertex indices) of a PLY file."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise SceneError(f"{path}: not a PLY file (no 'ply' magic or no end_header)")
    body = data.index(b"\n", end) + 1
    header = data[:body].decode("ascii", "replace").splitlines()
    fmt = None
    elements = []  # (name, count, [(prop name, type) or (name, ('list', count type, item type))])
    for line in header:
        p = line.split()
        if not p:
            continue
        if p[0] == "format":
            fmt = p[1]
        elif p[0] == "element":
            elements.append((p[1], int(p[2]), []))
        elif p[0] == "property":
            if not elements:
                raise SceneError(f"{path}: a property before any element")
            if p[1] == "list":
                elements[-1][2].append((p[4], ("list", p[2], p[3])))
            else:
                elements[-1][2].append((p[2], p[1]))
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise SceneError(f"{path}: PLY format {fmt!r} is not supported")
    verts, faces = [], []
    if fmt == "ascii":
        tokens = data[body:].split()
        pos = 0

        def take(_ty):
            nonlocal pos
            pos += 1
            return float(tokens[pos - 1])
    else:
        order = "<" if fmt == "binary_little_endian" else ">"
        pos = body

        def take(ty):
            nonlocal pos
            code = PLY_TYPES.get(ty)
            if code is None:
                raise SceneError(f"{path}: PLY property type {ty!r} is not supported")
            size = struct.calcsize(code)
            if pos + size > len(data):
                raise SceneError(f"{path}: the file ends inside its data")
            (v,) = struct.unpack_from(order + code, data, pos)
            pos += size
            return v
    for name, count, props in elements:
        for _ in range(count):
            rec = {}
            for pname, ty in props:
                if isinstance(ty, tuple):
                    n = int(take(ty[1]))
                    rec[pname] = [int(take(ty[2])) for _ in range(n)]
                else:
                    rec[pname] = take(ty)
            if name == "vertex":
                verts.append((rec["x"], rec["y"], rec["z"]))
            elif name == "face":
                idx = rec.get("vertex_indices", rec.get("vertex_index"))
                if idx is None:
                    raise SceneError(f"{path}: faces have no vertex_indices list")
                faces.append(idx)
    return verts, faces


def read_obj(path):
    """Vertex positions and faces of an OBJ file (materials and groups ignored)."""
    verts, faces = [], []
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                verts.append(tuple(float(x) for x in p[1:4]))
            elif p[0] == "f":
                idx = []
                for c in p[1:]:
                    i = int(c.split("/")[0])
                    idx.append(i - 1 if i > 0 else len(verts) + i)
                faces.append(idx)
    return verts, faces


def builtin_shape(kind, m):
    """Corners and faces of Mitsuba's built-in `rectangle`, `disk` and `cube` in local
    coordinates, wound so that the cross product of the *transformed* corners faces the way
    Mitsuba's transformed normal does (a transform that mirrors turns the winding over)."""
    if kind == "rectangle":
        verts = [(-1.0, -1.0, 0.0), (1.0, -1.0, 0.0), (1.0, 1.0, 0.0), (-1.0, 1.0, 0.0)]
        faces = [[0, 1, 2, 3]]
    elif kind == "disk":
        import math
        verts = [(math.cos(2 * math.pi * k / 32), math.sin(2 * math.pi * k / 32), 0.0) for k in range(32)]
        faces = [list(range(32))]
    else:  # cube: one quad per side, counter-clockwise seen from outside
        verts = [(x, y, z) for z in (-1.0, 1.0) for y in (-1.0, 1.0) for x in (-1.0, 1.0)]
        faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    det = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
           - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
           + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
    if det < 0:
        faces = [f[::-1] for f in faces]
    return verts, faces


def bsdf_colour(bsdf, grey):
    """Kd for a BSDF element: its diffuse reflectance when it is a plain colour, else grey."""
    if bsdf is None:
        return grey, "no BSDF"
    kind = bsdf.get("type")
    if kind in ("twosided",):
        inner = bsdf.find("bsdf")
        return bsdf_colour(inner, grey)
    if kind != "diffuse":
        return grey, f"{kind} BSDF"
    for c in bsdf:
        if c.get("name") in ("reflectance", "albedo"):
            if c.tag in ("rgb", "spectrum") and c.get("value"):
                vals = [float(x) for x in c.get("value").replace(",", " ").split()]
                if len(vals) == 1:
                    vals *= 3
                return tuple(vals[:3]), None
            if c.tag == "float":
                v = float(c.get("value"))
                return (v, v, v), None
            return grey, "textured"
    return grey, "diffuse with no reflectance"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene", help="the scene XML")
    ap.add_argument("obj", help="the OBJ to write (its MTL goes beside it)")
    ap.add_argument("--grey", type=float, default=0.5,
                    help="Kd for textured, non-diffuse or unspecified materials (default 0.5)")
    ap.add_argument("--force", action="store_true", help="overwrite existing output files")
    ap.add_argument("--skip-missing", action="store_true",
                    help="leave out shapes whose mesh file is missing (noted), instead of stopping")
    args = ap.parse_args()
    if not 0.0 <= args.grey < 1.0:
        sys.exit(f"--grey {args.grey}: a reflectance must be in [0, 1)")
    mtl_path = os.path.splitext(args.obj)[0] + ".mtl"
    for out in (args.obj, mtl_path):
        if os.path.exists(out) and not args.force:
            sys.exit(f"{out}: exists; give --force to replace it")
    try:
        root = ET.parse(args.scene).getroot()
    except (OSError, ET.ParseError) as e:
        sys.exit(f"{args.scene}: {e}")
    base = os.path.dirname(os.path.abspath(args.scene))
    named = {b.get("id"): b for b in root.findall("bsdf") if b.get("id")}
    materials = {}  # Kd/Ke key -> material name
    grey = (args.grey,) * 3
    notes = {}
    lines, mtl_lines = [], []
    used_names = {}
    voff, ntri = 1, 0
    try:
        for shape in root:
            if shape.tag == "emitter" or (shape.tag == "light"):
                notes.setdefault(f"a {shape.get('type')} light dropped (no geometry)", 0)
                notes[f"a {shape.get('type')} light dropped (no geometry)"] += 1
                continue
            if shape.tag not in ("shape", "mesh"):
                continue
            kind = shape.get("type")
            fn_elem = shape.find("string[@name='filename']")
            if kind in ("rectangle", "disk", "cube"):
                fn = f"{shape.get('id') or kind}.{kind}"
                path = f"{args.scene}: {kind}"
                m = read_transform(shape, f"{args.scene}: shape {kind}")
                verts, faces = builtin_shape(kind, m)
            elif kind not in ("ply", "obj") or fn_elem is None:
                notes.setdefault(f"a {kind} shape skipped", 0)
                notes[f"a {kind} shape skipped"] += 1
                continue
            else:
                fn = fn_elem.get("value")
                path = os.path.join(base, fn)
                if args.skip_missing and not os.path.exists(path):
                    notes[f"shape left out, its file is missing: {fn}"] = 1
                    continue
                verts, faces = (read_ply if kind == "ply" else read_obj)(path)
                m = read_transform(shape, f"{args.scene}: shape {fn}")
            bsdf = shape.find("bsdf")
            ref = shape.find("ref")
            if bsdf is None and ref is not None:
                bsdf = named.get(ref.get("id"))
            kd, why = bsdf_colour(bsdf, grey)
            if why:
                notes[f"{why}: Kd {args.grey}"] = notes.get(f"{why}: Kd {args.grey}", 0) + 1
            ke = None
            em = shape.find("emitter")
            if em is not None and em.get("type") == "area":
                rad = em.find("*[@name='radiance']")
                if rad is not None and rad.get("value"):
                    vals = [float(x) for x in rad.get("value").replace(",", " ").split()]
                    ke = tuple((vals * 3)[:3] if len(vals) == 1 else vals[:3])
            key = (kd, ke)
            if key not in materials:
                mname = f"m{len(materials)}"
                materials[key] = mname
                mtl_lines.append(f"newmtl {mname}")
                mtl_lines.append("Kd {:.6g} {:.6g} {:.6g}".format(*kd))
                if ke:
                    mtl_lines.append("Ke {:.6g} {:.6g} {:.6g}".format(*ke))
                mtl_lines.append("")
            name = os.path.splitext(os.path.basename(fn))[0]
            used_names[name] = used_names.get(name, 0) + 1
            if used_names[name] > 1:
                name = f"{name}_{used_names[name]}"
            lines.append(f"g {name}")
            lines.append(f"usemtl {materials[key]}")
            for v in verts:
                lines.append("v {:.6f} {:.6f} {:.6f}".format(*apply(m, v)))
            for face in faces:
                if any(i < 0 or i >= len(verts) for i in face):
                    raise SceneError(f"{path}: a face refers to a vertex that does not exist")
                lines.append("f " + " ".join(str(voff + i) for i in face))
                ntri += max(0, len(face) - 2)
            voff += len(verts)
    except (OSError, SceneError) as e:
        sys.exit(str(e))
    with open(mtl_path, "w") as f:
        f.write("\n".join(mtl_lines))
    with open(args.obj, "w") as f:
        f.write(f"mtllib {os.path.basename(mtl_path)}\n")
        f.write("\n".join(lines) + "\n")
    print(f"{args.obj}: {sum(used_names.values())} shapes, {voff - 1} vertices, "
          f"{ntri} triangles, {len(materials)} materials ({mtl_path})")
    for note, n in sorted(notes.items()):
        print(f"  {n} x {note}")


if __name__ == "__main__":
    main()
