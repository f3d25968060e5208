#!/usr/bin/env python3
"""Renders the images bench/caustics_regions.py splits (issue 14's goal on cornell_glass), into DIR:

    bench/caustics_frames.py --server URL --out DIR [--size 128] [--truth-spp 1024] [--truth FILE]
                             [--frame-json '{"photon_gi": {}, "caustics": {}}'] [--name default]
                             [--supersampling 2] [--no-reference]

  truth.exr        the reference at --truth-spp, seed 99 (skipped when --truth is given or DIR has it)
  ref256_s5.exr, ref256_s6.exr   the reference at 256 spp, seeds 5 and 6 (the `reference` layer)
  NAME_s1.exr, NAME_s2.exr       the frame (passes from --frame-json) at seeds 1 and 2, photons traced
                   first from another camera (as bench/caustics_goal.py), AOVs beauty, direct,
                   indirect, specular, caustics where produced
Prints each render's stats.passes (name, cpu_ms) as JSON lines on stderr. Standard library only.
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from photon_gi_goal import call, render  # noqa: E402

OTHER_CAMERA = {"position": [0.25, 0.55, 1.7], "target": [0.0, 0.45, 0.0], "up": [0, 1, 0], "yfov_deg": 42}


def fetch(server, r, path):
    with open(path, "wb") as f:
        f.write(call(server, r["frames"][0]["url"], ctype="image/x-exr"))


def log(tag, r):
    st = r["stats"]
    print(json.dumps({"frame": tag, "render_ms": st.get("render_ms"),
                      "passes": [(p["name"], round(p["cpu_ms"], 1)) for p in st["passes"]]}), file=sys.stderr)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--server", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--truth-spp", type=int, default=1024)
    ap.add_argument("--frame-json", default='{"photon_gi": {}, "caustics": {}}')
    ap.add_argument("--name", default="default")
    ap.add_argument("--supersampling", type=int, default=2)
    ap.add_argument("--no-reference", action="store_true")
    a = ap.parse_args()
    S = a.server
    os.makedirs(a.out, exist_ok=True)
    base = {"scene": {"builtin": "cornell_glass"}, "width": a.size, "height": a.size}
    exr = lambda aovs: [{"format": "exr", "half": False, "aovs": aovs}]  # noqa: E731
    truth = os.path.join(a.out, "truth.exr")
    if not os.path.exists(truth):
        r, _ = render(S, dict(base, seed=99, passes={"reference": {"spp": a.truth_spp}, "photon_gi": False},
                              outputs=exr(["reference"])))
        log("truth", r)
        fetch(S, r, truth)
    if not a.no_reference:
        for seed in (5, 6):
            path = os.path.join(a.out, f"ref256_s{seed}.exr")
            if os.path.exists(path):
                continue
            r, _ = render(S, dict(base, seed=seed, passes={"reference": {"spp": 256}, "photon_gi": False},
                                  outputs=exr(["reference"])))
            log(f"ref256 seed {seed}", r)
            fetch(S, r, path)
    passes = json.loads(a.frame_json)
    aovs = ["beauty", "direct"] + [x for x, p in (("indirect", "photon_gi"), ("specular", "specular"),
                                                  ("caustics", "caustics")) if passes.get(p, {}) is not False]
    for seed in (1, 2):
        req = dict(base, seed=seed, passes=passes, supersampling=a.supersampling)
        render(S, dict(req, camera=OTHER_CAMERA, outputs=exr(["beauty"])))  # traces the photons
        r, _ = render(S, dict(req, outputs=exr(aovs)))
        log(f"{a.name} seed {seed}", r)
        fetch(S, r, os.path.join(a.out, f"{a.name}_s{seed}.exr"))


if __name__ == "__main__":
    main()
