#!/usr/bin/env python3
"""Scene files that light public rooms for `radiosity bench --real` (and any other command).

Most public interiors come without a lamp the renderer can use: their light is a sky or an
environment map seen through the windows, which a closed radiosity solve does not have. For
each OBJ given, this writes a scene TOML that places the model (`type = "mesh"`) and adds
one ceiling panel light (`type = "polygon"`, 1.0 x 0.5 m, facing down), so the room solves
as it is:

    python3 scripts/real_rooms.py ~/models/living_room/living_room.obj ~/models/sibenik/sibenik.obj
    python3 scripts/real_rooms.py --out-dir /tmp/scenes ~/models/*/*.obj
    cargo run --release -- bench --real /tmp/scenes/sibenik.toml --real-reference-seconds 120

Each TOML goes next to its model (or into --out-dir), named after it (`sibenik.obj` ->
`sibenik.toml`), and refers to the model by a path relative to itself (absolute when the
model is not under the TOML's folder). An existing TOML is
left alone unless --force is given. The script prints what it wrote and where it put the
lamp.

Where the models come from (the download is your step: this script reads only local files,
and the machine it was written on could not reach these sites, so none of them was fetched
or checked from here):

* Morgan McGuire's Computer Graphics Archive, https://casual-effects.com/data/ : conference,
  breakfast_room, living_room, fireplace_room, dining-room (not the same as Bitterli's),
  sibenik, sponza. Each is a zip holding an OBJ with its MTL; unzip it and pass the OBJ.
* Benedikt Bitterli's rendering resources, https://benedikt-bitterli.me/resources/ : the
  rooms (living-room, dining-room, classroom, ...) are Mitsuba or Tungsten scenes of several
  OBJ files, each with its own transform; they must be merged into one OBJ first (apply
  each shape's toWorld matrix, one `g` group per shape, `usemtl` per BSDF, Kd from the
  BSDF's reflectance). `scripts/mitsuba_to_obj.py scene.xml room.obj` does that merge
  (also for the minpt ports of these rooms, github.com/guijiangheng/minpt-scenes). Pass the
  merged OBJ.

Each model keeps its own licence (most are CC BY 3.0: credit the author); read the one that
comes with the download.

How the lamp is placed (the ceiling is found from the OBJ's faces alone, y up, as OBJ has it):

1. The room's centre is the median x and z of the face centroids, not the middle of the
   bounding box: a model with an outdoor ground plane (Bitterli's classroom has one 220 units
   wide) or a long nave has its bounding box far from where its faces are, while the median
   stays inside the part of the model that has the detail, the room.
2. Vertical rays are cast upward on a 5 x 5 grid around that centre (spacing 0.25 m). Each
   ray's hits are sorted by height; a face counts as a ceiling when it is horizontal (its
   normal within about 18 degrees of vertical), faces down, and the face the ray hit just
   below it faces up and is at least 0.25 m lower: then the lamp hangs in air, not inside
   a slab or between a fixture and the ceiling. Per ray the highest such face is its
   ceiling (hanging lamps and shelves below the ceiling are passed over).
3. The ceiling is the median of the rays' ceilings; the lamp is centred on the ray nearest
   the centre that found it, 1 cm below it, its long side along x.
4. A fitting hanging from the ceiling over the lamp's footprint (a recessed light, a shallow
   fixture: every triangle of it within 10 cm under the ceiling) puts the lamp 1 cm under
   the fitting's bottom instead, so that the panel does not cut through it.
5. With no ceiling above the centre (an atrium open to the sky, such as Sponza's), the lamp
   goes 1 cm below the highest point of the model above the centre, with a warning.

Scene units are guessed from the room's height (floor to ceiling): over 60 units it is taken
for centimetres, over 6000 for millimetres, else metres; --units-per-metre overrides it.
The lamp's size, its offset and the grid follow the units, and its emission (100 W/m^2 of
white, given per unit^2) too, so a room emits the same power whatever its units.
--ceiling Y and --at X Z override steps 1-3 for a room where they guess wrong: look at what
the script prints.

The rule assumes faces wound consistently (a ceiling's front facing into the room), as in the
Bitterli conversions and McGuire's rooms; a room whose roof lies above a ceiling with air in
between (an attic) would get its lamp in the attic: give --ceiling there.
"""

import argparse
import os
import statistics
import sys

#: Lamp size, metres: a common office panel.
LAMP_SIZE_M = (1.0, 0.5)
#: Gap between the lamp and the ceiling, metres: close enough to read as a ceiling panel,
#: far enough that the solver and the path tracer see two surfaces.
LAMP_DROP_M = 0.01
#: Emitted radiosity, W/m^2 (a white panel of about 50 W).
LAMP_EMISSION_W_M2 = 100.0
#: Least air below a ceiling, metres: thinner gaps are slabs and fixtures.
MIN_AIR_M = 0.25
#: Ray grid around the centre: GRID x GRID rays, GRID_STEP_M apart.
GRID = 5
GRID_STEP_M = 0.25
#: |n_y| above this counts as horizontal (about 18 degrees).
HORIZONTAL = 0.95
#: Fittings hanging at most this far under the ceiling (metres) over the lamp's footprint
#: lower the lamp to LAMP_DROP_M under their bottom, so that it does not cut through them.
FITTING_M = 0.1


def load_obj(path):
    """Vertex positions and faces (lists of 0-based vertex indices) of an OBJ."""
    vertices, faces = [], []
    with open(path, encoding="utf-8", errors="replace") as f:
        for number, line in enumerate(f, 1):
            if line.startswith("v "):
                p = line.split()
                vertices.append((float(p[1]), float(p[2]), float(p[3])))
            elif line.startswith("f "):
                face = []
                for token in line.split()[1:]:
                    i = int(token.split("/")[0])
                    # Negative indices count back from the last vertex read so far.
                    face.append(i - 1 if i > 0 else len(vertices) + i)
                if len(face) >= 3:
                    faces.append(face)
    if not faces:
        raise ValueError(f"{path}: no faces")
    return vertices, faces


def triangles(vertices, faces):
    """Every face fanned into triangles: (a, b, c, n_y of the unit normal)."""
    out = []
    for face in faces:
        a = vertices[face[0]]
        for k in range(1, len(face) - 1):
            b, c = vertices[face[k]], vertices[face[k + 1]]
            e1 = (b[0] - a[0], b[1] - a[1], b[2] - a[2])
            e2 = (c[0] - a[0], c[1] - a[1], c[2] - a[2])
            n = (
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            )
            length = (n[0] ** 2 + n[1] ** 2 + n[2] ** 2) ** 0.5
            if length > 0.0:
                out.append((a, b, c, n[1] / length))
    return out


def hits_above(tris, x, z):
    """(height, n_y) of every triangle a vertical line at (x, z) crosses, lowest first."""
    hits = []
    for a, b, c, ny in tris:
        # Quick reject on the triangle's xz bounds before the barycentric test.
        if x < min(a[0], b[0], c[0]) or x > max(a[0], b[0], c[0]):
            continue
        if z < min(a[2], b[2], c[2]) or z > max(a[2], b[2], c[2]):
            continue
        d = (b[0] - a[0]) * (c[2] - a[2]) - (c[0] - a[0]) * (b[2] - a[2])
        if d == 0.0:
            continue  # seen edge-on from above: a wall
        u = ((x - a[0]) * (c[2] - a[2]) - (c[0] - a[0]) * (z - a[2])) / d
        w = ((b[0] - a[0]) * (z - a[2]) - (x - a[0]) * (b[2] - a[2])) / d
        if u < 0.0 or w < 0.0 or u + w > 1.0:
            continue
        hits.append((a[1] + u * (b[1] - a[1]) + w * (c[1] - a[1]), ny))
    hits.sort()
    return hits


def ceiling_of(hits, min_air):
    """The highest downward-facing horizontal hit with at least `min_air` of air below it (the
    hit under it faces up), or None."""
    best = None
    for below, here in zip(hits, hits[1:]):
        if here[1] < -HORIZONTAL and below[1] > 0.0 and here[0] - below[0] >= min_air:
            best = here[0]
    return best


def guess_units_per_metre(height):
    """Scene units per metre from a room's floor-to-ceiling height in scene units."""
    if height > 6000.0:
        return 1000.0
    if height > 60.0:
        return 100.0
    return 1.0


def place_lamp(vertices, faces, args):
    """(centre x, lamp y, centre z, units per metre, notes) for the model."""
    tris = triangles(vertices, faces)
    notes = []
    if args.at:
        cx, cz = args.at
    else:
        centroids = [
            (sum(vertices[i][0] for i in f) / len(f), sum(vertices[i][2] for i in f) / len(f))
            for f in faces
        ]
        cx = statistics.median(c[0] for c in centroids)
        cz = statistics.median(c[1] for c in centroids)
    centre_hits = hits_above(tris, cx, cz)
    floor = centre_hits[0][0] if centre_hits else min(v[1] for v in vertices)
    top = max(v[1] for v in vertices)
    # The units decide the grid and the least air, so they come from a first look at the
    # centre ray alone (or the model's height when that ray finds no ceiling).
    unit = args.units_per_metre
    if unit is None:
        first = ceiling_of(centre_hits, 0.0)
        unit = guess_units_per_metre((first if first is not None else top) - floor)
    if args.ceiling is not None:
        return cx, args.ceiling - LAMP_DROP_M * unit, cz, unit, ["ceiling given: y = %g" % args.ceiling]
    found = []
    half = (GRID - 1) / 2
    for i in range(GRID):
        for j in range(GRID):
            x = cx + (i - half) * GRID_STEP_M * unit
            z = cz + (j - half) * GRID_STEP_M * unit
            y = ceiling_of(hits_above(tris, x, z), MIN_AIR_M * unit)
            if y is not None:
                found.append(((x - cx) ** 2 + (z - cz) ** 2, x, z, y))
    if not found:
        notes.append(
            "warning: no ceiling above the centre (open to the sky?): lamp under the model's top, y = %g" % top
        )
        return cx, top - LAMP_DROP_M * unit, cz, unit, notes
    ceiling = statistics.median_low([f[3] for f in found])
    _, x, z, _ = min(f for f in found if f[3] == ceiling)
    notes.append(
        "ceiling y = %g (%d of %d rays found one; floor y = %g, model top y = %g)"
        % (ceiling, len(found), GRID * GRID, floor, top)
    )
    return x, clear_of_fittings(tris, x, z, ceiling, unit, notes), z, unit, notes


def clear_of_fittings(tris, x, z, ceiling, unit, notes):
    """The lamp's height: LAMP_DROP_M under the ceiling, or under the lowest fitting hanging
    from it over the lamp's footprint (a triangle wholly within FITTING_M under the ceiling
    whose xz bounds overlap the footprint): a panel laid through a recessed light or a
    shallow fixture would light its inside from a fraction of a millimetre."""
    half_x, half_z = LAMP_SIZE_M[0] * unit / 2, LAMP_SIZE_M[1] * unit / 2
    y = ceiling - LAMP_DROP_M * unit
    lowest = ceiling
    for a, b, c, _ in tris:
        ys = (a[1], b[1], c[1])
        if max(ys) > ceiling or min(ys) < ceiling - FITTING_M * unit:
            continue
        if max(a[0], b[0], c[0]) < x - half_x or min(a[0], b[0], c[0]) > x + half_x:
            continue
        if max(a[2], b[2], c[2]) < z - half_z or min(a[2], b[2], c[2]) > z + half_z:
            continue
        if min(ys) < y + LAMP_DROP_M * unit / 2:
            lowest = min(lowest, min(ys))
    if lowest < ceiling:
        y = lowest - LAMP_DROP_M * unit
        notes.append("a fitting hangs to y = %g over the lamp's footprint: lamp lowered under it" % lowest)
    return y


def fmt(x):
    """A coordinate for the TOML: short, exact enough (1e-6 of a unit)."""
    return ("%.6f" % x).rstrip("0").rstrip(".")


def scene_toml(name, model_ref, x, y, z, unit):
    """The scene file's text."""
    hx, hz = LAMP_SIZE_M[0] * unit / 2, LAMP_SIZE_M[1] * unit / 2
    # Counter-clockwise seen from below, so the lamp's front (the lit side) faces down.
    corners = [(x - hx, z - hz), (x + hx, z - hz), (x + hx, z + hz), (x - hx, z + hz)]
    vertices = ", ".join("[%s, %s, %s]" % (fmt(cx), fmt(y), fmt(cz)) for cx, cz in corners)
    emission = fmt(LAMP_EMISSION_W_M2 / unit**2)
    return f"""# Written by scripts/real_rooms.py: the model as it is, and one ceiling panel light, since
# the room comes without a lamp of its own. The lamp is {LAMP_SIZE_M[0]} x {LAMP_SIZE_M[1]} m
# ({fmt(unit)} scene units per metre), facing down, {LAMP_DROP_M} m below the highest
# down-facing horizontal face above the room's centre (the median of the face centroids)
# that has air below it; see the script's docstring.
name = "{name}"

[[material]]
name = "ceiling_lamp"
reflectance = [0, 0, 0]
emission = [{emission}, {emission}, {emission}]   # {LAMP_EMISSION_W_M2:g} W/m^2, per unit^2

[[object]]
name = "room"
type = "mesh"
file = "{model_ref}"

[[object]]
name = "ceiling_lamp"
type = "polygon"
vertices = [{vertices}]
material = "ceiling_lamp"
"""


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("models", nargs="+", metavar="MODEL.obj", help="OBJ files of rooms")
    parser.add_argument("--out-dir", help="write the TOMLs here (default: next to each model)")
    parser.add_argument("--force", action="store_true", help="overwrite existing TOMLs")
    parser.add_argument("--units-per-metre", type=float, help="scene units per metre (default: guessed)")
    parser.add_argument("--ceiling", type=float, metavar="Y", help="the ceiling's height (skips the search)")
    parser.add_argument("--at", type=float, nargs=2, metavar=("X", "Z"), help="the lamp's centre in x and z")
    args = parser.parse_args(argv)
    if args.units_per_metre is not None and not args.units_per_metre > 0.0:
        parser.error("--units-per-metre must be > 0")
    failed = False
    for model in args.models:
        stem = os.path.splitext(os.path.basename(model))[0]
        out_dir = args.out_dir or os.path.dirname(os.path.abspath(model))
        target = os.path.join(out_dir, stem + ".toml")
        if os.path.exists(target) and not args.force:
            print(f"{target}: exists, not overwritten (--force overwrites it)", file=sys.stderr)
            failed = True
            continue
        try:
            vertices, faces = load_obj(model)
            x, y, z, unit, notes = place_lamp(vertices, faces, args)
        except (OSError, ValueError, IndexError) as e:
            # A missing file, a bad number or a face naming a vertex that is not there.
            print(f"{model}: {e}", file=sys.stderr)
            failed = True
            continue
        os.makedirs(out_dir, exist_ok=True)
        # Relative to the TOML (as the loader reads it) when the model is at or below it, so
        # the two move together; absolute otherwise, rather than a chain of `../`.
        model_ref = os.path.relpath(os.path.abspath(model), os.path.abspath(out_dir))
        if model_ref.startswith(".."):
            model_ref = os.path.abspath(model)
        with open(target, "w", encoding="utf-8") as f:
            f.write(scene_toml(stem, model_ref.replace(os.sep, "/"), x, y, z, unit))
        print(f"{target}: {model_ref}, {len(faces)} faces; lamp at ({fmt(x)}, {fmt(y)}, {fmt(z)})")
        for note in notes:
            print(f"    {note}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
