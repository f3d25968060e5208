#!/usr/bin/env python3
"""A scene of many specular objects for issue 31's profile: N spheres (glass, smooth and rough metal,
in turn) in a grid on a white floor under one point light, inside the Cornell box's walls' colours.

    python3 bench/glass_metal_field.py [N] [--no-light] > /tmp/field.gltf      (default N = 36)

--no-light: no point light, so the daemon's default studio environment lights it (its key becomes a
shadowed directional light; the caustics pass, which traces punctual lights, is then not planned).

Not a built-in scene (the daemon's list stays the six of scenes/): render it by upload, e.g.
    radiant render /tmp/field.gltf --size 256 -o /tmp/field.png
Python 3 standard library only; reuses scenes/make_scenes.py's builder.
"""
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes"))
import make_scenes as ms  # noqa: E402


def field(n, light=True):
    b = ms.Builder()
    white = b.material("white", ms.WHITE, double_sided=True)
    red = b.material("red", ms.RED, double_sided=True)
    green = b.material("green", ms.GREEN, double_sided=True)
    glass = b.material("glass", [1.0, 1.0, 1.0, 1.0], metallic=0.0, roughness=0.0,
                       extensions={"KHR_materials_transmission": {"transmissionFactor": 1.0},
                                   "KHR_materials_ior": {"ior": 1.5}})
    mirror = b.material("mirror", [0.95, 0.95, 0.95, 1.0], metallic=1.0, roughness=0.0)
    gold = b.material("rough_gold", [1.0, 0.78, 0.34, 1.0], metallic=1.0, roughness=0.15)
    kinds = [glass, mirror, gold]
    size = 4.0
    h = size / 2
    b.node("floor", b.mesh("floor", ms.quad([-h, 0, h], [size, 0, 0], [0, 0, -size]), white))
    b.node("back_wall", b.mesh("back_wall", ms.quad([-h, 0, -h], [size, 0, 0], [0, size, 0]), white))
    b.node("left_wall", b.mesh("left_wall", ms.quad([-h, 0, h], [0, 0, -size], [0, size, 0]), red))
    b.node("right_wall", b.mesh("right_wall", ms.quad([h, 0, -h], [0, 0, size], [0, size, 0]), green))
    side = math.ceil(math.sqrt(n))
    pitch = (size - 0.6) / side
    radius = 0.35 * pitch
    spheres = [b.mesh("sphere_%d" % k, ms.uv_sphere(radius), kinds[k]) for k in range(3)]
    for i in range(n):
        x = -h + 0.3 + pitch * (i % side + 0.5)
        z = -h + 0.3 + pitch * (i // side + 0.5)
        b.node("object_%d" % i, spheres[i % 3], translation=ms.r6([x, radius, z]))
    if light:
        b.node("light", light=b.point_light("key", 60.0), translation=[0.0, 3.2, 0.5])
    eye = [0.0, 2.6, 5.2]
    b.node("camera", camera=b.perspective_camera("front", round(math.radians(45.0), 6)), translation=eye,
           rotation=ms.look_rotation(eye, [0.0, 0.3, 0.0]))
    return b.finish("glass_metal_field_%d" % n)


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--no-light"]
    sys.stdout.write(field(int(args[0]) if args else 36, "--no-light" not in sys.argv[1:]))
