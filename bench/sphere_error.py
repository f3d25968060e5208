#!/usr/bin/env python3
"""The error on the sphere of a built-in Cornell box (issue 32's goal for `cornell_mirror`: "the mirror
sphere within 10% of the reference", RMSE over the sphere's pixels relative to their mean), split by
what the sphere's pixels reflect, with the truth's own noise measured from two truth seeds:

    bench/sphere_error.py --truth T1.exr --truth2 T2.exr --a A1.exr [--b A2.exr]

T1/T2: the reference pass at two seeds (`radiant render --pass reference --set reference.spp=2048
--aov reference --seed 99` and `--seed 98`); A1/A2: the default frame at two seeds (their beauty).
The frames are averaged (A1, A2) and so are the truths; the table scores the averaged frame against
the averaged truth, and the truths' noise (half their difference's RMS, the averaged truth's) is the
floor any frame meets. Pixels are the sphere's by casting the camera's pixel-centre rays at the
analytic sphere (bench/caustics_regions.py's scene constants); "rim" is where the view ray meets it
at cos < 0.3, the rest is split by the mirror direction: up (ceiling), down (floor), sideways (walls).
"""
import argparse
import math

import caustics_regions as cr


def mean_of(a, b):
    return [[tuple((p + q) / 2 for p, q in zip(pa, pb)) for pa, pb in zip(ra, rb)] for ra, rb in zip(a, b)]


def zone(w, h, x, y):
    tan = math.tan(cr.YFOV / 2)
    dx = (2 * (x + 0.5) / w - 1) * tan * (w / h)
    dy = (1 - 2 * (y + 0.5) / h) * tan
    n = math.sqrt(dx * dx + dy * dy + 1)
    d = (dx / n, dy / n, -1 / n)
    t = cr.hit_sphere(cr.CAM, d, cr.SPHERE_C, cr.SPHERE_R)
    if t is None:
        return None
    p = [cr.CAM[i] + t * d[i] for i in range(3)]
    nrm = [(p[i] - cr.SPHERE_C[i]) / cr.SPHERE_R for i in range(3)]
    cos_v = -sum(nrm[i] * d[i] for i in range(3))
    if cos_v < 0.3:
        return "rim (cos < 0.3)"
    ry = d[1] + 2 * cos_v * nrm[1]
    return "reflects the ceiling" if ry > 0.3 else "reflects the floor" if ry < -0.3 else "reflects the walls"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--truth", required=True)
    ap.add_argument("--truth2", required=True)
    ap.add_argument("--a", required=True)
    ap.add_argument("--b")
    ap.add_argument("--layer", default="beauty")
    ap.add_argument("--truth-layer", default="reference")
    a = ap.parse_args()
    w, h, t1 = cr.read_layer(a.truth, a.truth_layer)
    t2 = cr.read_layer(a.truth2, a.truth_layer)[2]
    frame = cr.read_layer(a.a, a.layer)[2]
    if a.b:
        frame = mean_of(frame, cr.read_layer(a.b, a.layer)[2])
    truth = mean_of(t1, t2)
    zones = {}
    for y in range(h):
        for x in range(w):
            z = zone(w, h, x, y)
            if z is None:
                continue
            se = sum((frame[y][x][c] - truth[y][x][c]) ** 2 for c in range(3)) / 3
            err = sum(frame[y][x][c] - truth[y][x][c] for c in range(3)) / 3
            tn = sum((t1[y][x][c] - t2[y][x][c]) ** 2 for c in range(3)) / 3 / 4  # the mean's variance
            for key in (z, "sphere"):
                s = zones.setdefault(key, [0, 0.0, 0.0, 0.0, 0.0])
                s[0] += 1
                s[1] += se
                s[2] += err
                s[3] += sum(truth[y][x]) / 3
                s[4] += tn
    total = zones["sphere"][1]
    print("| pixels | n | share of squared error | RMSE / truth mean | truth noise / truth mean | mean error |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, s in sorted(zones.items(), key=lambda kv: (kv[0] != "sphere", -kv[1][1])):
        n, se, err, tm, tn = s
        mean = tm / n
        print(f"| {name} | {n} | {se / total:.3f} | {math.sqrt(se / n) / mean:.4f} | {math.sqrt(tn / n) / mean:.4f} | "
              f"{err / n:+.4f} |")


if __name__ == "__main__":
    main()
