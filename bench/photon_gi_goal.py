#!/usr/bin/env python3
"""The goal measurement of photon_gi (issue: "Global illumination on every surface"), in one run on one
machine: on the built-in Cornell box at SIZE x SIZE, how long does the default GI take to reach the RMSE
of the reference path tracer at 256 spp, with photons cached and the camera changed?

    bench/photon_gi_goal.py [--server URL] [--size 256] [--truth-spp 2048] [--truth FILE.exr] [--save-truth FILE.exr]
                            [--scene cornell_box] [--quick]

Start radiantd with a long --request-timeout (the ground truth takes minutes on a CPU); --truth reuses
a ground-truth EXR rendered before (the reference's `reference` AOV of the same scene, size and camera).

Steps (every image scored against the same converged ground truth, uploaded as an image):
  1. ground truth: the reference at --truth-spp (seed 99, independent of the seeds below);
  2. the reference at 256 spp (seed 5): its render time and RMSE;
  3. photon_gi with default settings: one render from another camera (traces the photons), then the
     measured render from the scene camera (photons cached, camera changed): time and RMSE;
  4. the default with gather_step 1 and 3;
  5. unless --quick, the same at a few cheaper and dearer settings, to show where the RMSE of step 2 is reached.
Prints a Markdown table for docs/PERFORMANCE.md. Python standard library only.
"""
import argparse
import json
import os
import sys
import time
import urllib.request


def call(server, path, body=None, method=None, ctype="application/json"):
    data = None
    if body is not None:
        data = body if isinstance(body, bytes) else json.dumps(body).encode()
    req = urllib.request.Request(server + path, data=data, method=method or ("POST" if data else "GET"))
    if data is not None:
        req.add_header("Content-Type", ctype)
    with urllib.request.urlopen(req, timeout=3600) as r:
        raw = r.read()
    return raw if ctype != "application/json" or path.startswith("/v1/frames") else json.loads(raw)


def render(server, request):
    t0 = time.time()
    r = call(server, "/v1/renders", request)
    wall = (time.time() - t0) * 1000.0
    return r, wall


def upload_ground_truth(server, base, truth_spp, truth_file=None, save_truth=None):
    """Renders the reference at truth_spp (seed 99), or reads truth_file, uploads it; returns its digest."""
    if truth_file:
        with open(truth_file, "rb") as f:
            exr = f.read()
        ms = 0.0
    else:
        truth, ms = render(server, dict(base, seed=99, passes={"reference": {"spp": truth_spp}, "photon_gi": False},
                                        outputs=[{"format": "exr", "half": False, "aovs": ["reference"]}]))
        exr = call(server, truth["frames"][0]["url"], ctype="image/x-exr")
        if save_truth:
            with open(save_truth, "wb") as f:
                f.write(exr)
    digest = call(server, "/v1/images", exr, method="PUT", ctype="image/x-exr")
    digest = json.loads(digest)["digest"] if isinstance(digest, bytes) else digest["digest"]
    print(f"ground truth: reference {truth_spp} spp, {ms / 1000:.1f} s", file=sys.stderr)
    return digest


def reference_256(server, base, digest, seed=5):
    """The reference at 256 spp (seed 5) scored against the ground truth: (its pass ms, RMSE, table row)."""
    ref, _ = render(server, dict(base, seed=seed, passes={"reference": {"spp": 256}, "photon_gi": False},
                                 compare={"against": digest, "aov": "reference"},
                                 outputs=[{"format": "exr", "aovs": ["reference"]}]))
    ref_ms = next(p["cpu_ms"] for p in ref["stats"]["passes"] if p["name"] == "reference")
    m = ref["stats"]["metrics"]
    return ref_ms, m["rmse"], ("reference, 256 spp", ref_ms, ref["stats"]["render_ms"], m["rmse"], m["rel_mse"])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--server", default=os.environ.get("RADIANT_SERVER", "http://127.0.0.1:8080"))
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--truth-spp", type=int, default=2048)
    ap.add_argument("--scene", default="cornell_box")
    ap.add_argument("--truth", help="a ground-truth EXR to reuse instead of rendering one")
    ap.add_argument("--save-truth", help="write the ground-truth EXR here (to reuse with --truth)")
    ap.add_argument("--quick", action="store_true", help="only the default and its gather_step variants")
    a = ap.parse_args()
    S = a.server
    info = call(S, "/v1/info")
    renderer = info.get("device", {}).get("renderer", "?")
    base = {"scene": {"builtin": a.scene}, "width": a.size, "height": a.size}

    digest = upload_ground_truth(S, base, a.truth_spp, a.truth, a.save_truth)
    rows = []
    ref_ms, ref_rmse, ref_row = reference_256(S, base, digest)
    rows.append(ref_row)

    other_camera = {"position": [0.25, 0.55, 1.7], "target": [0.0, 0.45, 0.0], "up": [0, 1, 0], "yfov_deg": 42}
    settings = [("photon_gi default (gather_step 2)", {}), ("photon_gi gather_step 1", {"gather_step": 1}),
                ("photon_gi gather_step 3", {"gather_step": 3})]
    for method in () if a.quick else ("splat", "gather"):
        for C in (5, 10, 20):
            for photons in (250000, 1000000):
                settings.append((f"photon_gi {method}, C {C}, {photons // 1000}k photons",
                                 {"method": method, "C": C, "photons": photons}))
    for label, params in settings:
        render(S, dict(base, camera=other_camera, passes={"photon_gi": params},
                       outputs=[{"format": "exr", "aovs": ["beauty"]}]))  # traces (or extends) the photons
        r, ms = render(S, dict(base, passes={"photon_gi": params}, compare={"against": digest, "aov": "beauty"},
                               outputs=[{"format": "exr", "aovs": ["beauty"]}]))
        st = r["stats"]
        pg = next(p for p in st["passes"] if p["name"] == "photon_gi")
        assert pg["counters"]["photons_traced"] == 0, "photons were not cached"
        passes_ms = sum(p["cpu_ms"] for p in st["passes"])
        rows.append((label, passes_ms, st["render_ms"], st["metrics"]["rmse"], st["metrics"]["rel_mse"]))

    print(f"Scene `{a.scene}` at {a.size}x{a.size}, GL renderer `{renderer}`, {time.strftime('%Y-%m-%d')}; "
          f"ground truth: reference at {a.truth_spp} spp. Times are the frame's passes (CPU wall clock, "
          f"the GPU work included) and the whole render; the photon rows have photons cached and the "
          f"camera changed.\n")
    print("| frame | passes ms | render ms | RMSE | relMSE | time / reference-256 | RMSE / reference-256 |")
    print("|---|---|---|---|---|---|---|")
    for label, pm, rm, rmse, rel in rows:
        print(f"| {label} | {pm:.0f} | {rm:.0f} | {rmse:.4f} | {rel:.4f} | {pm / ref_ms:.3f} | {rmse / ref_rmse:.2f} |")


if __name__ == "__main__":
    main()
