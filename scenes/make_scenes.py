#!/usr/bin/env python3
"""Generates Radiant's built-in scenes as self-contained .gltf files (buffers as data URIs).

    python3 scenes/make_scenes.py [output_dir]     (default: the directory of this script)

Python 3 standard library only. The outputs are committed; rerun after editing this file.
Units are metres, Y is up, +Z points out of the Cornell box's open front towards the camera.

Scenes
  cornell_box     ~1 m Cornell box (white floor, ceiling and back wall, red left wall, green right
                  wall, open front), a diffuse tall box and a diffuse sphere, one point light under
                  the ceiling, a camera looking in through the open front.
  cornell_mirror  the same, with a perfect mirror sphere (metallic 1, roughness 0).
  cornell_glass   the same, with a smooth glass sphere (KHR_materials_transmission 1, ior 1.5).
  cornell_glossy  the paper's "Glosbox" (Stürzlinger & Bastos 1997): the same box whose larger (tall)
                  block is a glossy metal (metallic 1, roughness 0.3), for photon splatting on glossy
                  surfaces.
  ao_creases      objects on a floor and against two walls, with creases, contact points and a
                  90 degree groove, for ambient-occlusion work; one point light.
  explosion       thesis ch. 7's explosion in a room: fire (115 particles), smoke (28) and dust (16)
                  as RADIANT_particle_system generators (api/schema/media.json) around crates, a warm
                  point light at the fire's heart and a cool fill light.
"""

import base64
import json
import math
import os
import struct
import sys

# Reflectances of the classic Cornell box, in linear RGB.
WHITE = [0.73, 0.73, 0.73, 1.0]
RED = [0.63, 0.065, 0.05, 1.0]
GREEN = [0.14, 0.45, 0.091, 1.0]


class Builder:
    """Accumulates meshes, nodes and materials and emits one glTF document with one buffer."""

    def __init__(self):
        self.blob = bytearray()
        self.doc = {
            "asset": {"version": "2.0", "generator": "radiant scenes/make_scenes.py"},
            "scene": 0,
            "scenes": [{"name": "", "nodes": []}],
            "nodes": [], "meshes": [], "materials": [], "accessors": [], "bufferViews": [],
            "buffers": [],
        }
        self.extensions_used = set()

    def _view(self, data, target):
        while len(self.blob) % 4:
            self.blob.append(0)
        offset = len(self.blob)
        self.blob += data
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": offset, "byteLength": len(data),
                                        "target": target})
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, values, comps, kind, with_bounds=False):
        data = struct.pack("<%df" % (len(values) * comps), *[c for v in values for c in v])
        acc = {"bufferView": self._view(data, 34962), "componentType": 5126, "count": len(values),
               "type": kind}
        if with_bounds:
            acc["min"] = [min(v[i] for v in values) for i in range(comps)]
            acc["max"] = [max(v[i] for v in values) for i in range(comps)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def _indices(self, indices):
        fmt, ctype = ("<%dH", 5123) if max(indices) < 65536 else ("<%dI", 5125)
        data = struct.pack(fmt % len(indices), *indices)
        self.doc["accessors"].append({"bufferView": self._view(data, 34963), "componentType": ctype,
                                      "count": len(indices), "type": "SCALAR"})
        return len(self.doc["accessors"]) - 1

    def material(self, name, color, metallic=0.0, roughness=1.0, double_sided=False, extensions=None):
        m = {"name": name, "pbrMetallicRoughness": {
            "baseColorFactor": color, "metallicFactor": metallic, "roughnessFactor": roughness}}
        if double_sided:
            m["doubleSided"] = True
        if extensions:
            m["extensions"] = extensions
            self.extensions_used.update(extensions.keys())
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def mesh(self, name, geometry, material):
        pos, nrm, uv, idx = geometry
        prim = {"attributes": {"POSITION": self._accessor(pos, 3, "VEC3", True),
                               "NORMAL": self._accessor(nrm, 3, "VEC3"),
                               "TEXCOORD_0": self._accessor(uv, 2, "VEC2")},
                "indices": self._indices(idx), "material": material, "mode": 4}
        self.doc["meshes"].append({"name": name, "primitives": [prim]})
        return len(self.doc["meshes"]) - 1

    def node(self, name, mesh=None, translation=None, rotation=None, scale=None, camera=None,
             light=None, extras=None):
        n = {"name": name}
        if mesh is not None:
            n["mesh"] = mesh
        if camera is not None:
            n["camera"] = camera
        if light is not None:
            n["extensions"] = {"KHR_lights_punctual": {"light": light}}
        if translation:
            n["translation"] = translation
        if rotation:
            n["rotation"] = rotation
        if scale:
            n["scale"] = scale
        if extras:
            n["extras"] = extras
        self.doc["nodes"].append(n)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def particle_system(self, name, system, translation=None):
        """A node carrying RADIANT_particle_system (particles from a seeded generator)."""
        n = {"name": name, "extensions": {"RADIANT_particle_system": system}}
        if translation:
            n["translation"] = translation
        self.extensions_used.add("RADIANT_particle_system")
        self.doc["nodes"].append(n)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def point_light(self, name, intensity, color=(1.0, 1.0, 1.0)):
        ext = self.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})
        ext["lights"].append({"name": name, "type": "point", "color": list(color),
                              "intensity": intensity})
        self.extensions_used.add("KHR_lights_punctual")
        return len(ext["lights"]) - 1

    def perspective_camera(self, name, yfov, znear=0.01):
        self.doc.setdefault("cameras", []).append(
            {"name": name, "type": "perspective", "perspective": {"yfov": yfov, "znear": znear}})
        return len(self.doc["cameras"]) - 1

    def finish(self, scene_name):
        self.doc["scenes"][0]["name"] = scene_name
        if self.extensions_used:
            self.doc["extensionsUsed"] = sorted(self.extensions_used)
        self.doc["buffers"] = [{"byteLength": len(self.blob),
                                "uri": "data:application/octet-stream;base64," +
                                       base64.b64encode(bytes(self.blob)).decode("ascii")}]
        return json.dumps(self.doc, indent=1, separators=(",", ": ")) + "\n"


def r6(v):
    """Rounds to 6 decimals so the committed files are stable across platforms."""
    return [round(c, 6) + 0.0 for c in v]


def quad(corner, edge_u, edge_v):
    """A rectangle corner + s*edge_u + t*edge_v; front face (CCW) on the side of edge_u x edge_v."""
    n = [edge_u[1] * edge_v[2] - edge_u[2] * edge_v[1], edge_u[2] * edge_v[0] - edge_u[0] * edge_v[2],
         edge_u[0] * edge_v[1] - edge_u[1] * edge_v[0]]
    length = math.sqrt(sum(c * c for c in n))
    n = [c / length for c in n]
    pos, uv = [], []
    for s, t in ((0, 0), (1, 0), (1, 1), (0, 1)):
        pos.append(r6([corner[i] + s * edge_u[i] + t * edge_v[i] for i in range(3)]))
        uv.append([float(s), float(1 - t)])
    return pos, [r6(n)] * 4, uv, [0, 1, 2, 0, 2, 3]


def merge(*parts):
    pos, nrm, uv, idx = [], [], [], []
    for p, n, t, i in parts:
        base = len(pos)
        pos += p
        nrm += n
        uv += t
        idx += [base + k for k in i]
    return pos, nrm, uv, idx


def unit_box():
    """The cube [-0.5, 0.5]^3 with outward faces and per-face normals (24 vertices)."""
    h = 0.5
    return merge(
        quad([-h, -h, h], [1, 0, 0], [0, 1, 0]),    # +Z
        quad([h, -h, -h], [-1, 0, 0], [0, 1, 0]),   # -Z
        quad([h, -h, h], [0, 0, -1], [0, 1, 0]),    # +X
        quad([-h, -h, -h], [0, 0, 1], [0, 1, 0]),   # -X
        quad([-h, h, h], [1, 0, 0], [0, 0, -1]),    # +Y
        quad([-h, -h, -h], [1, 0, 0], [0, 0, 1]))   # -Y


def uv_sphere(radius, segments=32, rings=16):
    pos, nrm, uv, idx = [], [], [], []
    for r in range(rings + 1):
        theta = math.pi * r / rings
        for s in range(segments + 1):
            phi = 2 * math.pi * s / segments
            n = [math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi)]
            pos.append(r6([radius * c for c in n]))
            nrm.append(r6(n))
            uv.append([round(s / segments, 6), round(r / rings, 6)])
    for r in range(rings):
        for s in range(segments):
            a = r * (segments + 1) + s
            b = a + segments + 1
            if r != 0:
                idx += [a, b, a + 1]
            if r != rings - 1:
                idx += [a + 1, b, b + 1]
    return pos, nrm, uv, idx


def y_rotation(degrees):
    half = math.radians(degrees) / 2
    return r6([0.0, math.sin(half), 0.0, math.cos(half)])


def look_rotation(eye, target):
    """Quaternion (x, y, z, w) turning -Z towards target - eye with +Y as up (no roll)."""
    f = [target[i] - eye[i] for i in range(3)]
    fl = math.sqrt(sum(c * c for c in f))
    f = [c / fl for c in f]
    yaw = math.atan2(-f[0], -f[2])
    pitch = math.asin(f[1])
    qy = [0.0, math.sin(yaw / 2), 0.0, math.cos(yaw / 2)]
    qx = [math.sin(pitch / 2), 0.0, 0.0, math.cos(pitch / 2)]
    # q = qy * qx (pitch about the local X axis, then yaw about world Y)
    x1, y1, z1, w1 = qy
    x2, y2, z2, w2 = qx
    return r6([w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2, w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
               w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2, w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2])


def cornell(variant):
    """Interior x in [-0.5, 0.5], y in [0, 1], z in [-0.5, 0.5]; open at z = +0.5."""
    b = Builder()
    white = b.material("white", WHITE, double_sided=True)
    red = b.material("red", RED, double_sided=True)
    green = b.material("green", GREEN, double_sided=True)
    if variant == "glossy":
        box_white = b.material("glossy_metal", [0.85, 0.85, 0.85, 1.0], metallic=1.0, roughness=0.3)
    else:
        box_white = b.material("tall_box", WHITE)
    if variant == "mirror":
        sphere_mat = b.material("mirror", [0.95, 0.95, 0.95, 1.0], metallic=1.0, roughness=0.0)
    elif variant == "glass":
        sphere_mat = b.material("glass", [1.0, 1.0, 1.0, 1.0], metallic=0.0, roughness=0.0,
                                extensions={"KHR_materials_transmission": {"transmissionFactor": 1.0},
                                            "KHR_materials_ior": {"ior": 1.5}})
    else:
        sphere_mat = b.material("sphere", WHITE)

    # Walls face the inside of the box.
    b.node("floor", b.mesh("floor", quad([-0.5, 0, 0.5], [1, 0, 0], [0, 0, -1]), white))
    b.node("ceiling", b.mesh("ceiling", quad([-0.5, 1, -0.5], [1, 0, 0], [0, 0, 1]), white))
    b.node("back_wall", b.mesh("back_wall", quad([-0.5, 0, -0.5], [1, 0, 0], [0, 1, 0]), white))
    b.node("left_wall", b.mesh("left_wall", quad([-0.5, 0, 0.5], [0, 0, -1], [0, 1, 0]), red))
    b.node("right_wall", b.mesh("right_wall", quad([0.5, 0, -0.5], [0, 0, 1], [0, 1, 0]), green))
    # The classic tall block: 0.3 x 0.6 x 0.3, turned 17 degrees, back left.
    # "radiant_receiver" marks the objects that env_diffuse gives indirect diffuse light to (the
    # environment is everything else); only diffuse objects are receivers.
    receiver = {"radiant_receiver": True}
    b.node("tall_box", b.mesh("tall_box", unit_box(), box_white), translation=[-0.17, 0.3, -0.15],
           rotation=y_rotation(17.0), scale=[0.3, 0.6, 0.3], extras=receiver if variant != "glossy" else None)
    radius = 0.17
    b.node("sphere", b.mesh("sphere", uv_sphere(radius), sphere_mat),
           translation=[0.19, radius, 0.13], extras=receiver if variant == "box" else None)
    # Point light 0.15 m below the ceiling: the floor below it gets E = I / d^2 = 4 / 0.85^2,
    # about 5.5 W/m^2, so the white (0.73) floor's radiance is ~ 0.73 * 5.5 / pi ~ 1.3. Any closer
    # and the ceiling's hot spot (E = I / 0.15^2 ~ 180 W/m^2 right above it) grows sharply,
    # which makes a harsh secondary source for gathering and virtual-light methods.
    b.node("light", light=b.point_light("ceiling_light", 4.0), translation=[0.0, 0.85, 0.0])
    # The classic camera: 39.3 degree vertical fov, the opening filling the frame.
    b.node("camera", camera=b.perspective_camera("front", round(math.radians(39.3), 6)),
           translation=[0.0, 0.5, 1.94])
    return b.finish("cornell_" + variant if variant != "box" else "cornell_box")


def ao_creases():
    """A floor meeting two walls (two creases and a corner) with objects that make more."""
    b = Builder()
    white = b.material("white", [0.8, 0.8, 0.8, 1.0], double_sided=True)
    grey = b.material("grey", [0.6, 0.6, 0.6, 1.0])
    # Floor 3 x 3 m at y = 0, back wall at z = -1, left wall at x = -1.
    b.node("floor", b.mesh("floor", quad([-1, 0, 2], [3, 0, 0], [0, 0, -3]), white))
    b.node("back_wall", b.mesh("back_wall", quad([-1, 0, -1], [3, 0, 0], [0, 2, 0]), white))
    b.node("left_wall", b.mesh("left_wall", quad([-1, 0, 2], [0, 0, -3], [0, 2, 0]), white))
    box = b.mesh("box", unit_box(), grey)
    # A cube pushed into the corner: creases with the floor and both walls.
    b.node("corner_box", box, translation=[-0.75, 0.25, -0.75], scale=[0.5, 0.5, 0.5],
           extras={"purpose": "corner crease"})
    # A tall slab against the back wall.
    b.node("wall_slab", box, translation=[0.6, 0.6, -0.9], scale=[0.4, 1.2, 0.2])
    # Steps: two stacked boxes make an inner step crease.
    b.node("step_low", box, translation=[0.9, 0.1, 0.6], scale=[0.6, 0.2, 0.6])
    b.node("step_high", box, translation=[0.9, 0.3, 0.45], scale=[0.6, 0.2, 0.3])
    # A sphere resting on the floor: the contact point.
    radius = 0.3
    b.node("sphere", b.mesh("sphere", uv_sphere(radius), grey), translation=[-0.1, radius, 0.5])
    # A 90 degree V groove (two boards leaning together), its crease along X at y = 0.
    groove = merge(quad([0, 0, 0], [0.6, 0, 0], [0, 0.3, -0.3]),   # faces +Y +Z side
                   quad([0.6, 0, 0], [-0.6, 0, 0], [0, 0.3, 0.3]))  # faces +Y -Z side
    b.node("v_groove", b.mesh("v_groove", groove, white), translation=[-0.8, 0.0, 1.3],
           extras={"purpose": "90 degree crease"})
    b.node("light", light=b.point_light("key_light", 12.0), translation=[0.6, 2.2, 1.2])
    eye, target = [2.2, 1.6, 3.0], [0.0, 0.3, 0.0]
    b.node("camera", camera=b.perspective_camera("overview", round(math.radians(45.0), 6)),
           translation=eye, rotation=look_rotation(eye, target))
    return b.finish("ao_creases")


def explosion():
    """A 6 x 3 x 6 m room (open towards the camera) with crates and an explosion at its centre."""
    b = Builder()
    wall = b.material("plaster", [0.7, 0.68, 0.64, 1.0], double_sided=True)
    floor = b.material("concrete", [0.45, 0.45, 0.45, 1.0], double_sided=True)
    wood = b.material("crate", [0.55, 0.38, 0.2, 1.0])
    b.node("floor", b.mesh("floor", quad([-3, 0, 3], [6, 0, 0], [0, 0, -6]), floor))
    b.node("ceiling", b.mesh("ceiling", quad([-3, 3, -3], [6, 0, 0], [0, 0, 6]), wall))
    b.node("back_wall", b.mesh("back_wall", quad([-3, 0, -3], [6, 0, 0], [0, 3, 0]), wall))
    b.node("left_wall", b.mesh("left_wall", quad([-3, 0, 3], [0, 0, -6], [0, 3, 0]), wall))
    b.node("right_wall", b.mesh("right_wall", quad([3, 0, -3], [0, 0, 6], [0, 3, 0]), wall))
    crate = b.mesh("crate", unit_box(), wood)
    b.node("crate_left", crate, translation=[-1.3, 0.35, -0.4], rotation=y_rotation(20.0), scale=[0.7, 0.7, 0.7])
    b.node("crate_right", crate, translation=[1.2, 0.3, 0.5], rotation=y_rotation(-35.0), scale=[0.6, 0.6, 0.6])
    b.node("crate_back", crate, translation=[0.4, 0.5, -1.8], scale=[1.0, 1.0, 1.0])
    # Thesis 7.3: 115 fire, 28 smoke and 16 dust particles. Fire: black body of 2500-3200 K
    # (Fig. 7.10); smoke albedo 0.2, dust 0.9 (7.2.1); g = 0 everywhere (7.2.1).
    b.particle_system("fire", {
        "kind": "fire", "tau": 6.0, "profile": "linear_exact", "emission_scale": 1.5, "seed": 1,
        "temperature": {"bias": 2500, "scale": 700},
        "generator": {"shape": "sphere", "extent": [0.55, 0.45, 0.55], "count": 115, "radius": 0.22,
                      "radius_jitter": 0.4}}, translation=[0.0, 0.75, 0.0])
    b.particle_system("smoke", {
        "kind": "smoke", "tau": 2.5, "profile": "linear_exact", "seed": 2,
        "generator": {"shape": "sphere", "extent": [0.9, 0.5, 0.9], "count": 28, "radius": 0.45,
                      "radius_jitter": 0.3}}, translation=[0.0, 1.6, 0.0])
    b.particle_system("dust", {
        "kind": "dust", "tau": 0.8, "profile": "linear_exact", "seed": 3,
        "generator": {"shape": "box", "extent": [1.6, 0.2, 1.4], "count": 16, "radius": 0.5,
                      "radius_jitter": 0.3}}, translation=[0.0, 0.3, 0.2])
    b.node("fire_light", light=b.point_light("fire_glow", 6.0, (1.0, 0.55, 0.2)), translation=[0.0, 0.8, 0.0])
    b.node("fill_light", light=b.point_light("fill", 3.0, (0.7, 0.8, 1.0)), translation=[-2.0, 2.6, 2.0])
    eye, target = [0.0, 1.4, 5.2], [0.0, 1.0, 0.0]
    b.node("camera", camera=b.perspective_camera("front", round(math.radians(50.0), 6), znear=0.05),
           translation=eye, rotation=look_rotation(eye, target))
    return b.finish("explosion")


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    scenes = {"cornell_box": cornell("box"), "cornell_mirror": cornell("mirror"),
              "cornell_glass": cornell("glass"), "cornell_glossy": cornell("glossy"), "ao_creases": ao_creases(),
              "explosion": explosion()}
    for name, text in scenes.items():
        path = os.path.join(out, name + ".gltf")
        with open(path, "w", encoding="ascii", newline="\n") as f:
            f.write(text)
        print("%s: %d bytes" % (path, len(text)))


if __name__ == "__main__":
    main()
