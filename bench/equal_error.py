#!/usr/bin/env python3
"""Issue 32's headline: the equal-error speed-up of the default frame over the reference path tracer.

For each built-in scene, on one daemon, at SIZE x SIZE:
  1. the truth: the reference at --truth-spp (compare.spp), rendered once by the first request and then
     cached by the daemon (it draws its own fixed seed, independent of every request's);
  2. the default frame (no passes named) scored against it, rendered cold with a fresh seed (so its
     photons are traced in the timed run) -- time = stats.render_ms minus the truth's reference_ms;
  3. the reference pass alone at each of --spp (photon_gi off), scored against the same truth in its own
     mode (compare.aov = reference), time = the reference pass's CPU ms.
How the truth's own noise is counted: both scores hold it. The reference's MSE against the truth is
fitted as MSE(s) = a / s + b by least squares (b: the truth's noise plus any common bias, a: the
reference's variance per sample; a fit with b < 0, fireflies at the smallest spp, takes b = 0 and a from
the largest spp); the default frame's own squared error is MSE_frame - b, so the
reference matches it at s* = a / (MSE_frame - b) samples per pixel, which costs t(s*) from a linear fit
t(s) = t0 + c s of the measured times. Speed-up = t(s*) / frame time. When MSE_frame <= b the frame is
closer to the truth than the truth's own noise can tell: s* is reported as "> truth".

    python3 bench/equal_error.py --server http://127.0.0.1:8080 [--size 64] [--truth-spp 4096]
        [--spp 64,256,1024] [--scene cornell_box ...] [--client build/client/radiant]

Prints one Markdown table (docs/PERFORMANCE.md, "Unbiased transport and the denoiser"). Python 3
standard library only.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def render(args, tmp, request):
    path = os.path.join(tmp, "request.json")
    with open(path, "w") as f:
        json.dump(request, f)
    stats = os.path.join(tmp, "stats.json")
    subprocess.run([args.client, "--server", args.server, "render", "--request", path, "-o",
                    os.path.join(tmp, "frame.exr"), "--stats", stats, "-q"], check=True)
    with open(stats) as f:
        s = json.load(f)
    return s.get("stats", s)


def fit_inverse(points):
    """Least squares of y = a / s + b over (s, y)."""
    xs = [1.0 / s for s, _ in points]
    ys = [y for _, y in points]
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    a = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx
    return a, my - a * mx


def fit_line(points):
    xs = [s for s, _ in points]
    ys = [t for _, t in points]
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    c = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    return my - c * mx, c


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--server", default="http://127.0.0.1:8080")
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--truth-spp", type=int, default=4096)
    ap.add_argument("--spp", default="64,256,1024")
    ap.add_argument("--scene", action="append")
    ap.add_argument("--client", default=os.path.join(ROOT, "build/client/radiant"))
    args = ap.parse_args()
    spps = [int(s) for s in args.spp.split(",")]
    scenes = args.scene or ["cornell_box"]
    tmp = tempfile.mkdtemp(prefix="equal-error-")
    rows = []
    for scene in scenes:
        base = {"scene": {"builtin": scene}, "width": args.size, "height": args.size,
                "outputs": [{"aovs": ["beauty"], "format": "exr"}]}
        # The default frame: the first run also renders (and caches) the truth; the second, with a new
        # seed, traces its photons again and is the timed one.
        frame = dict(base, compare={"against": "reference", "aov": "beauty", "spp": args.truth_spp})
        render(args, tmp, dict(frame, seed=1))
        st = render(args, tmp, dict(frame, seed=2))
        frame_mse = st["metrics"]["rmse"] ** 2
        frame_ms = st["render_ms"] - st["metrics"].get("reference_ms", 0.0)
        points, times = [], []
        for spp in spps:
            req = dict(base, outputs=[{"aovs": ["reference"], "format": "exr"}],
                       passes={"photon_gi": False, "reference": {"spp": spp}},
                       compare={"against": "reference", "aov": "reference", "spp": args.truth_spp}, seed=3)
            s = render(args, tmp, req)
            ref = [p for p in s["passes"] if p["name"] == "reference"][0]
            points.append((spp, s["metrics"]["rmse"] ** 2))
            times.append((spp, max(ref["cpu_ms"], ref.get("gpu_ms", 0.0))))
        a, b = fit_inverse(points)
        if b < 0:  # fireflies at the smallest spp bend the curve: the truth's noise is then taken as 0 and
            b = 0.0  # a from the largest spp, the point nearest the asymptote
            a = points[-1][0] * points[-1][1]
        t0, c = fit_line(times)
        own = frame_mse - b
        if own > 0:
            s_eq = a / own
            t_eq = t0 + c * s_eq
            rows.append((scene, frame_mse ** 0.5, own ** 0.5, frame_ms, b ** 0.5 if b > 0 else 0.0, points, times,
                         f"{s_eq:.0f}", f"{t_eq:.0f}", f"{t_eq / frame_ms:.1f}x"))
        else:
            rows.append((scene, frame_mse ** 0.5, 0.0, frame_ms, b ** 0.5 if b > 0 else 0.0, points, times,
                         f"> {args.truth_spp} (truth)", "", ""))
        print(f"{scene}: frame rmse {frame_mse ** 0.5:.4f} ({frame_ms:.0f} ms), reference {points}, times {times}, "
              f"fit a {a:.4g} b {b:.4g}", file=sys.stderr)
    print(f"| scene | default frame RMSE vs {args.truth_spp} spp (own, truth noise removed) | frame ms | truth noise "
          f"| reference RMSE at " + ", ".join(str(s) for s in spps) + " spp | reference spp at equal error "
          "| its ms | speed-up |")
    print("|---|---|---|---|---|---|---|---|")
    for scene, rmse, own, ms, noise, points, times, s_eq, t_eq, speed in rows:
        refs = ", ".join(f"{m ** 0.5:.4f}" for _, m in points)
        print(f"| {scene} | {rmse:.4f} ({own:.4f}) | {ms:.0f} | {noise:.4f} | {refs} | {s_eq} | {t_eq} | {speed} |")


if __name__ == "__main__":
    main()
