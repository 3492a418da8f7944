#!/usr/bin/env python3
"""Writes the roof assets of grammars/keep.clay (run from this folder; no dependencies).

- tower-roof.glb: an octagonal spire for a tower (glTF 2.0, binary), base radius 1 m at 7 m,
  apex at 9.8 m, one slate material.
- donjon-roof.obj (+ .mtl): a gabled roof over the donjon's 4 m x 3 m hall, eaves at 6 m, ridge
  at 8 m along x.

Coordinates as Clay reads them (docs/language.md, `mesh`): metres, y up; the piece's floor plan
is (x, -z). Every solid is convex, so each triangle is wound to face away from its centre.
"""
import json
import math
import struct


def outward(vertices, triangles):
    n = len(vertices)
    centre = [sum(v[k] for v in vertices) / n for k in range(3)]
    out = []
    for a, b, c in triangles:
        pa, pb, pc = vertices[a], vertices[b], vertices[c]
        u = [pb[k] - pa[k] for k in range(3)]
        w = [pc[k] - pa[k] for k in range(3)]
        normal = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
        mid = [(pa[k] + pb[k] + pc[k]) / 3 - centre[k] for k in range(3)]
        out.append((a, b, c) if sum(normal[k] * mid[k] for k in range(3)) > 0 else (a, c, b))
    return out


def spire():
    radius, base, apex = 1.0, 7.0, 9.8
    ring = []
    for k in range(8):
        t = math.radians(22.5 + 45 * k)
        # Piece point (r cos t, r sin t) is asset (x, -z).
        ring.append((radius * math.cos(t), base, -radius * math.sin(t)))
    vertices = ring + [(0.0, apex, 0.0), (0.0, base, 0.0)]
    triangles = []
    for k in range(8):
        triangles.append((k, (k + 1) % 8, 8))  # a side
        triangles.append((k, (k + 1) % 8, 9))  # the floor
    return vertices, outward(vertices, triangles)


def write_glb(path, vertices, triangles, colour):
    positions = b"".join(struct.pack("<3f", *v) for v in vertices)
    indices = b"".join(struct.pack("<3H", *t) for t in triangles)
    pad = (4 - len(indices) % 4) % 4
    blob = positions + indices + b"\0" * pad
    lo = [min(v[k] for v in vertices) for k in range(3)]
    hi = [max(v[k] for v in vertices) for k in range(3)]
    doc = {
        "asset": {"version": "2.0", "generator": "clay grammars/assets/make-roofs.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "spire", "mesh": 0}],
        "meshes": [{"name": "spire", "primitives": [
            {"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "materials": [{"name": "slate", "pbrMetallicRoughness": {
            "baseColorFactor": colour, "metallicFactor": 0.0, "roughnessFactor": 0.9}}],
        "buffers": [{"byteLength": len(blob)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(positions), "target": 34962},
            {"buffer": 0, "byteOffset": len(positions), "byteLength": len(indices), "target": 34963},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(vertices), "type": "VEC3",
             "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5123, "count": 3 * len(triangles), "type": "SCALAR"},
        ],
    }
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * ((4 - len(text) % 4) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(blob), b"BIN\0") + blob
    with open(path, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)


def gable():
    eaves, ridge = 6.0, 8.0
    # Piece corners (x, y) -> asset (x, h, -y).
    vertices = [(-2.0, eaves, 1.5), (2.0, eaves, 1.5), (2.0, eaves, -1.5), (-2.0, eaves, -1.5),
                (-2.0, ridge, 0.0), (2.0, ridge, 0.0)]
    triangles = [(0, 1, 5), (0, 5, 4),  # south slope
                 (3, 2, 5), (3, 5, 4),  # north slope
                 (0, 3, 4), (1, 2, 5),  # the gables
                 (0, 1, 2), (0, 2, 3)]  # the floor
    return vertices, outward(vertices, triangles)


def write_obj(path, vertices, triangles):
    with open(path.replace(".obj", ".mtl"), "w") as f:
        f.write("# donjon roof tiles (grammars/assets/make-roofs.py)\nnewmtl tiles\nKd 0.478 0.231 0.180\n")
    with open(path, "w") as f:
        f.write("# a gabled roof for the keep's donjon (grammars/assets/make-roofs.py)\n")
        f.write("mtllib donjon-roof.mtl\no roof\n")
        for v in vertices:
            f.write("v %g %g %g\n" % v)
        f.write("usemtl tiles\n")
        for t in triangles:
            f.write("f %d %d %d\n" % tuple(i + 1 for i in t))


if __name__ == "__main__":
    write_glb("tower-roof.glb", *spire(), [0.07, 0.09, 0.12, 1.0])
    write_obj("donjon-roof.obj", *gable())
