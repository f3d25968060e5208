#!/usr/bin/env python3
"""Where the error of a cornell_glass frame lies (issue 14's goal): splits the squared error of frames
against a ground truth into regions of the built-in `cornell_glass` seen from its own camera, and each
region's error into bias and noise from two frames that differ only in their seed:

    bench/caustics_regions.py --truth T.exr --a A.exr --b B.exr [--caustics C.exr] [--layer beauty] [--label L]

Regions are found by casting the camera's pixel-centre rays against the scene's analytic geometry
(scenes/make_scenes.py `cornell`): the glass sphere, the tall block, the ceiling, the walls, and the
floor split into the caustic (pixels where --caustics, an EXR with a `caustics` layer, exceeds 0.1), the sphere's and the block's shadows from the point light (outside the caustic), and the
rest. A pixel on a silhouette belongs to what its centre sees.

Per region: pixels, its share of the frame's sum of squared error, its MSE, the mean signed error
(frame - truth), and noise = mean (A - B)^2 / 2 (the variance of one frame, if A and B are independent
estimates), bias^2 = MSE - noise. MSE is over the three colour channels, as stats.metrics.rmse.
EXRs are read with `oiiotool --dumpdata`; Python standard library only.
"""
import argparse
import math
import os
import subprocess
import tempfile

CAM = (0.0, 0.5, 1.94)
YFOV = 0.685914  # round(radians(39.3), 6), as make_scenes.py
LIGHT = (0.0, 0.85, 0.0)
SPHERE_C, SPHERE_R = (0.19, 0.17, 0.13), 0.17
CAUSTIC_THRESHOLD = 0.1  # radiance of the caustics layer that marks the caustic region
BOX_T, BOX_S, BOX_YAW = (-0.17, 0.3, -0.15), (0.3, 0.6, 0.3), math.radians(17.0)


def read_layer(path, layer):
    """(width, height, rows top to bottom of [r, g, b]) of one layer of an EXR."""
    chans = "R,G,B" if layer == "beauty" else f"{layer}.R,{layer}.G,{layer}.B"
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "x.exr")
        subprocess.run(["oiiotool", path, "--ch", chans, "-d", "float", "-o", out], check=True)
        text = subprocess.run(["oiiotool", "--dumpdata", out], check=True, capture_output=True, text=True).stdout
    lines = text.splitlines()
    w, h = (int(v) for v in lines[0].split(":")[1].split(",")[0].split(" x "))
    rows = [[None] * w for _ in range(h)]
    for line in lines[1:]:
        if not line.strip().startswith("Pixel ("):
            continue
        coords, vals = line.split(":")
        x, y = (int(v) for v in coords.strip()[len("Pixel ("):-1].split(","))
        rows[y][x] = tuple(float(v) for v in vals.split())  # y = 0 is the top row
    return w, h, rows


def sub(a, b): return (a[0] - b[0], a[1] - b[1], a[2] - b[2])
def dot(a, b): return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def hit_sphere(o, d, c, r):
    oc = sub(o, c)
    b = dot(oc, d)
    disc = b * b - (dot(oc, oc) - r * r)
    if disc < 0:
        return None
    s = math.sqrt(disc)
    for t in (-b - s, -b + s):
        if t > 1e-6:
            return t
    return None


def to_box(p):
    """World point or direction (relative) into the tall block's unit-box frame (rotation only)."""
    c, s = math.cos(-BOX_YAW), math.sin(-BOX_YAW)
    return (c * p[0] + s * p[2], p[1], -s * p[0] + c * p[2])


def hit_box(o, d):
    lo = to_box(sub(o, BOX_T))
    ld = to_box(d)
    t0, t1 = 1e-6, 1e30
    for i in range(3):
        h = BOX_S[i] / 2
        if abs(ld[i]) < 1e-12:
            if abs(lo[i]) > h:
                return None
            continue
        a, b = (-h - lo[i]) / ld[i], (h - lo[i]) / ld[i]
        t0, t1 = max(t0, min(a, b)), min(t1, max(a, b))
    return t0 if t0 <= t1 else None


def hit_room(o, d):
    """(t, name) of the nearest wall of the open box, or None."""
    best = None
    planes = (("floor", 1, 0.0), ("ceiling", 1, 1.0), ("back", 2, -0.5), ("left", 0, -0.5), ("right", 0, 0.5))
    for name, axis, v in planes:
        if abs(d[axis]) < 1e-12:
            continue
        t = (v - o[axis]) / d[axis]
        if t <= 1e-6:
            continue
        p = tuple(o[i] + t * d[i] for i in range(3))
        inside = all(-0.5 - 1e-6 <= p[i] <= 0.5 + 1e-6 for i in (0, 2)) and -1e-6 <= p[1] <= 1 + 1e-6
        if inside and (best is None or t < best[0]):
            best = (t, name)
    return best


def occluded(p, q, what):
    d = sub(q, p)
    L = math.sqrt(dot(d, d))
    d = (d[0] / L, d[1] / L, d[2] / L)
    t = hit_sphere(p, d, SPHERE_C, SPHERE_R) if what == "sphere" else hit_box(p, d)
    return t is not None and t < L


def classify(w, h, caustic):
    tan = math.tan(YFOV / 2)
    labels = []
    for y in range(h):
        row = []
        for x in range(w):
            dx = (2 * (x + 0.5) / w - 1) * tan * (w / h)
            dy = (1 - 2 * (y + 0.5) / h) * tan
            n = math.sqrt(dx * dx + dy * dy + 1)
            d = (dx / n, dy / n, -1 / n)
            cand = []
            ts = hit_sphere(CAM, d, SPHERE_C, SPHERE_R)
            if ts:
                cand.append((ts, "glass sphere"))
            tb = hit_box(CAM, d)
            if tb:
                cand.append((tb, "tall block"))
            r = hit_room(CAM, d)
            if r:
                cand.append(r)
            if not cand:
                row.append("background")
                continue
            t, name = min(cand)
            if name == "floor":
                p = tuple(CAM[i] + t * d[i] for i in range(3))
                if caustic and max(caustic[y][x]) > CAUSTIC_THRESHOLD:
                    name = "floor: caustic"
                elif occluded(p, LIGHT, "sphere"):
                    name = "floor: sphere's shadow"
                elif occluded(p, LIGHT, "box"):
                    name = "floor: block's shadow"
                else:
                    name = "floor: lit"
            elif name in ("back", "left", "right"):
                name = "walls (" + name + ")"
            row.append(name)
        labels.append(row)
    return labels


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--truth", required=True)
    ap.add_argument("--a", required=True, help="the frame (seed A)")
    ap.add_argument("--b", help="the same frame at another seed (noise estimate)")
    ap.add_argument("--caustics", help="an EXR with a caustics layer (the caustic region's mask)")
    ap.add_argument("--layer", default="beauty", help="the layer of --a/--b to score (truth: beauty)")
    ap.add_argument("--truth-layer", default="reference")
    ap.add_argument("--label", default="frame")
    a = ap.parse_args()
    w, h, T = read_layer(a.truth, a.truth_layer)
    _, _, A = read_layer(a.a, a.layer)
    B = read_layer(a.b, a.layer)[2] if a.b else None
    C = read_layer(a.caustics, "caustics")[2] if a.caustics else None
    labels = classify(w, h, C)
    stats = {}
    total = 0.0
    for y in range(h):
        for x in range(w):
            s = stats.setdefault(labels[y][x], [0, 0.0, 0.0, 0.0, 0.0, 0.0])
            se = sum((A[y][x][c] - T[y][x][c]) ** 2 for c in range(3)) / 3
            s[0] += 1
            s[1] += se
            s[2] += sum(A[y][x][c] - T[y][x][c] for c in range(3)) / 3
            s[3] += sum(T[y][x]) / 3
            if B:
                s[4] += sum((A[y][x][c] - B[y][x][c]) ** 2 for c in range(3)) / 6
            total += se
    n = w * h
    print(f"**{a.label}**: RMSE {math.sqrt(total / n):.4f} over {w}x{h}\n")
    print("| region | pixels | share of squared error | RMSE in region | truth mean | mean error | noise share | bias share |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for name, s in sorted(stats.items(), key=lambda kv: -kv[1][1]):
        px, se, err, tm, noise = s[0], s[1], s[2], s[3], s[4]
        noise_txt = bias_txt = "-"
        if B:
            noise_txt = f"{noise / total:.3f}"
            bias_txt = f"{max(0.0, se - noise) / total:.3f}"
        print(f"| {name} | {px} | {se / total:.3f} | {math.sqrt(se / px):.4f} | {tm / px:.3f} | {err / px:+.4f} | "
              f"{noise_txt} | {bias_txt} |")


if __name__ == "__main__":
    main()
