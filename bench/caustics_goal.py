#!/usr/bin/env python3
"""The goal measurement of caustics (issue 14): on the built-in cornell_glass at SIZE x SIZE, does the
default frame with caustics land within 1.5x the RMSE of the reference at 256 spp, in under a tenth of
its time? Same procedure as bench/photon_gi_goal.py (whose helpers it uses), one run on one machine:

    bench/caustics_goal.py [--server URL] [--size 128] [--truth-spp 2048] [--truth FILE.exr] [--save-truth FILE.exr]
                           [--supersampling K] [--photon-variants] [--repeat N] [--photon-gi JSON]

  1. ground truth: the reference at --truth-spp (seed 99; path tracer + light-traced caustics);
  2. the reference at 256 spp (seed 5): its time (the reference pass) and RMSE;
  3. frames with photons cached (a first render from another camera traces them), scored on beauty:
     the default frame (caustics on), the same with caustics off, without the secondary lookup (the
     reference has no L S+ D S+ E paths), and caustics at P 256 / C 512.
  4. with --photon-variants, the default frame at photon_gi 100k photons and at gather_step 4.
--repeat N renders each frame N times, alternating with the other camera, and reports the median of
its times, and the reference at N seeds, whose median time the ratio uses (the machine is shared: one frame's time moves by 20-30% between runs). --photon-gi JSON adds
photon_gi parameters to every frame (e.g. '{"C": 8}').
The reference pass caches its images: run each measurement against a fresh radiantd, or its time is a
cache hit's. Prints a Markdown table (with the photon_gi and specular passes' ms) for
docs/PERFORMANCE.md. Python standard library only.
"""
import argparse
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from photon_gi_goal import call, reference_256, render, upload_ground_truth  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--server", default=os.environ.get("RADIANT_SERVER", "http://127.0.0.1:8080"))
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--truth-spp", type=int, default=2048)
    ap.add_argument("--scene", default="cornell_glass")
    ap.add_argument("--truth", help="a ground-truth EXR to reuse instead of rendering one (give its --truth-spp)")
    ap.add_argument("--save-truth", help="write the ground-truth EXR here (to reuse with --truth)")
    ap.add_argument("--supersampling", type=int, default=0, help="the frames' supersampling (0: the HTTP default)")
    ap.add_argument("--photon-variants", action="store_true",
                    help="also rows with cheaper photon_gi settings (100k photons; gather_step 4)")
    ap.add_argument("--repeat", type=int, default=1, help="frames per row; the median time is reported")
    ap.add_argument("--photon-gi", default="{}", help="photon_gi parameters added to every frame (JSON)")
    a = ap.parse_args()
    extra = json.loads(a.photon_gi)
    S = a.server
    info = call(S, "/v1/info")
    renderer = info.get("device", {}).get("renderer", "?")
    base = {"scene": {"builtin": a.scene}, "width": a.size, "height": a.size}
    digest = upload_ground_truth(S, base, a.truth_spp, a.truth, a.save_truth)
    # The reference's time: the median over --repeat seeds (5, 6, ...; a seed's image is cached, so a
    # repeat needs another one); its RMSE: seed 5's, as in every earlier table.
    refs = [reference_256(S, base, digest, seed=5 + i) for i in range(max(1, a.repeat))]
    ref_ms = sorted(r[0] for r in refs)[len(refs) // 2]
    ref_rmse, ref_row = refs[0][1], (refs[0][2][0], ref_ms) + refs[0][2][2:]
    rows = [ref_row + (0.0, 0.0, 0.0, 1)]

    other_camera = {"position": [0.25, 0.55, 1.7], "target": [0.0, 0.45, 0.0], "up": [0, 1, 0], "yfov_deg": 42}
    settings = [("default frame (photon_gi + specular + caustics)", {}),
                ("default frame, caustics off", False),
                ("default frame, caustics without specular_lookup (no LS+DS+E, like the reference)",
                 {"specular_lookup": False}),
                ("default frame, caustics P 256, C 512", {"photon_resolution": 256, "cube_resolution": 512}),
                ("default frame, caustics splat r 0.02", {"method": "splat", "splat_radius": 0.02})]
    photon_settings = [dict(extra)] * len(settings)
    if a.photon_variants:
        settings += [("default frame, photon_gi 100k photons", {}), ("default frame, photon_gi gather_step 4", {})]
        photon_settings += [dict(extra, photons=100000), dict(extra, gather_step=4)]
    frame = dict(base, supersampling=a.supersampling) if a.supersampling else base
    for (label, caustics), photon_gi in zip(settings, photon_settings):
        passes = {"photon_gi": photon_gi, "caustics": caustics}
        runs = []
        for _ in range(max(1, a.repeat)):
            render(S, dict(frame, camera=other_camera, passes=passes, outputs=[{"format": "exr", "aovs": ["beauty"]}]))
            r, ms = render(S, dict(frame, passes=passes, compare={"against": digest, "aov": "beauty"},
                                   outputs=[{"format": "exr", "aovs": ["beauty"]}]))
            runs.append((sum(p["cpu_ms"] for p in r["stats"]["passes"]), r))
        runs.sort(key=lambda x: x[0])
        r = runs[len(runs) // 2][1]
        st = r["stats"]
        passes_ms = sum(p["cpu_ms"] for p in st["passes"])
        cms = next((p["cpu_ms"] for p in st["passes"] if p["name"] == "caustics"), 0.0)
        pms = {p["name"]: p["cpu_ms"] for p in st["passes"]}
        rows.append((label, passes_ms, st["render_ms"], st["metrics"]["rmse"], st["metrics"]["rel_mse"], cms,
                     pms.get("photon_gi", 0.0), pms.get("specular", 0.0), st.get("supersampling", 1)))

    print(f"Scene `{a.scene}` at {a.size}x{a.size}, GL renderer `{renderer}`, {time.strftime('%Y-%m-%d %H:%M')}; "
          f"ground truth: reference at {a.truth_spp} spp. Times are the frame's passes (CPU wall clock, the GPU "
          f"work included) and the whole render; photons cached, camera changed.\n")
    print("| frame | k | passes ms | photon_gi ms | specular ms | caustics ms | render ms | RMSE | relMSE | time / reference-256 | RMSE / reference-256 |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for label, pm, rm, rmse, rel, cms, gms, sms, k in rows:
        print(f"| {label} | {k} | {pm:.0f} | {gms:.0f} | {sms:.0f} | {cms:.0f} | {rm:.0f} | {rmse:.4f} | {rel:.4f} | "
              f"{pm / ref_ms:.3f} | {rmse / ref_rmse:.2f} |")


if __name__ == "__main__":
    main()
