#!/usr/bin/env python3
"""Writes scenes/cornell.obj + cornell.mtl and scenes/cornell.gltf from scenes/cornell.toml.

We made these model files ourselves, from the measured Cornell box of the TOML scene, so the
three describe the same box: the tests check they solve to the same per-object radiosity.

* OBJ: one `o` per object, faces exactly as the TOML polygons (quads stay quads), Kd/Ke.
* glTF 2.0: one node and mesh per object, each polygon fanned into triangles (glTF has only
  triangles; the importer meshes a coplanar pair that makes a convex quad as that quad),
  baseColorFactor = reflectance, emissiveFactor x KHR_materials_emissive_strength = emission,
  and the TOML camera as a perspective camera node. Buffers are embedded (base64 data URI).

Run from the repository root: python3 scripts/make_cornell_models.py
"""

import base64
import json
import math
import struct
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENE = tomllib.loads((ROOT / "scenes/cornell.toml").read_text())


def faces_of(obj):
    if obj["type"] == "polygon":
        return [obj["vertices"]]
    if obj["type"] == "polygons":
        return obj["faces"]
    raise SystemExit(f"object type {obj['type']} not handled")


def num(v):
    """Shortest text that reads back as the same float (as the TOML has it)."""
    return repr(float(v)).removesuffix(".0") if float(v) == int(v) else repr(float(v))


def write_obj():
    header = "# Cornell box, written by scripts/make_cornell_models.py from scenes/cornell.toml\n"
    mtl = [header]
    for m in SCENE["material"]:
        mtl.append(f"newmtl {m['name']}\n")
        mtl.append("Kd " + " ".join(num(v) for v in m["reflectance"]) + "\n")
        mtl.append("Ke " + " ".join(num(v) for v in m.get("emission", [0, 0, 0])) + "\n\n")
    (ROOT / "scenes/cornell.mtl").write_text("".join(mtl))
    out = [header, "mtllib cornell.mtl\n"]
    count = 0
    for o in SCENE["object"]:
        out.append(f"\no {o['name']}\nusemtl {o['material']}\n")
        for face in faces_of(o):
            for v in face:
                out.append("v " + " ".join(num(c) for c in v) + "\n")
            out.append("f " + " ".join(str(count + 1 + k) for k in range(len(face))) + "\n")
            count += len(face)
    (ROOT / "scenes/cornell.obj").write_text("".join(out))


def write_gltf():
    materials = []
    index_of = {}
    for i, m in enumerate(SCENE["material"]):
        index_of[m["name"]] = i
        e = m.get("emission", [0, 0, 0])
        strength = max(e)
        mat = {
            "name": m["name"],
            "pbrMetallicRoughness": {
                "baseColorFactor": [*m["reflectance"], 1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": 1.0,
            },
        }
        if strength > 0:
            mat["emissiveFactor"] = [c / strength for c in e]
            mat["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}
        materials.append(mat)

    blob = bytearray()
    views, accessors, meshes, nodes = [], [], [], []
    for o in SCENE["object"]:
        positions, indices = [], []
        for face in faces_of(o):
            base = len(positions)
            positions.extend(face)
            for k in range(1, len(face) - 1):
                indices.extend([base, base + k, base + k + 1])
        # Positions: float32 VEC3, with the min/max glTF requires.
        pos_bytes = b"".join(struct.pack("<3f", *p) for p in positions)
        f32 = [struct.unpack("<3f", struct.pack("<3f", *p)) for p in positions]
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(pos_bytes), "target": 34962})
        blob += pos_bytes
        accessors.append({
            "bufferView": len(views) - 1, "componentType": 5126, "count": len(positions), "type": "VEC3",
            "min": [min(p[c] for p in f32) for c in range(3)],
            "max": [max(p[c] for p in f32) for c in range(3)],
        })
        ind_bytes = struct.pack(f"<{len(indices)}H", *indices)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(ind_bytes), "target": 34963})
        blob += ind_bytes
        while len(blob) % 4:
            blob += b"\0"
        accessors.append({"bufferView": len(views) - 1, "componentType": 5123, "count": len(indices), "type": "SCALAR"})
        meshes.append({"name": o["name"], "primitives": [{
            "attributes": {"POSITION": len(accessors) - 2}, "indices": len(accessors) - 1,
            "material": index_of[o["material"]],
        }]})
        nodes.append({"name": o["name"], "mesh": len(meshes) - 1})

    cam = SCENE["camera"]
    direction = [b - a for a, b in zip(cam["position"], cam["look_at"])]
    # The camera looks down its -z; this box's camera looks down world +z: half a turn about y.
    assert direction[0] == 0 and direction[1] == 0 and direction[2] > 0
    nodes.append({"name": "camera", "camera": 0, "translation": cam["position"], "rotation": [0.0, 1.0, 0.0, 0.0]})
    doc = {
        "asset": {"version": "2.0", "generator": "radiosity scripts/make_cornell_models.py (from scenes/cornell.toml)"},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"name": SCENE["name"], "nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "cameras": [{"type": "perspective", "perspective": {"yfov": math.radians(cam["fov_y_deg"]), "znear": 1.0}}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{
            "byteLength": len(blob),
            "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode(),
        }],
    }
    (ROOT / "scenes/cornell.gltf").write_text(json.dumps(doc, indent=1) + "\n")


write_obj()
write_gltf()
