#!/usr/bin/env python3
"""Issue 31's profile: where a default frame's time goes, per pass, on every built-in scene, every
shared glTF sample (as shipped and under each shared HDR map) and the glass-and-metal fields of
bench/glass_metal_field.py. Each frame is the default request at SIZE x SIZE, rendered twice on one
daemon: the first ("cold": the scene's derived data built, e.g. the specular maps and the photons; the
shaders are compiled by the first scene only) with each pass's ms (its prepare_ms plus the larger of its
execute's CPU and GPU time; on llvmpipe each pass finishes its GPU work inside its own bracket:
stats.pass_timing), and the second ("warm": the derived data reused) as render ms only.

    python3 bench/default_frames.py --server http://127.0.0.1:8080 [--size 256] [--client build/client/radiant]

Prints one Markdown table (docs/PERFORMANCE.md, "Default frames"). Python 3 standard library only.
"""
import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--server", default="http://127.0.0.1:8080")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--client", default=os.path.join(ROOT, "build/client/radiant"))
    ap.add_argument("--testdata", default=os.path.join(ROOT, "..", "shared", "testdata"))
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="default-frames-")
    frames = []
    for name in ["cornell_box", "cornell_glass", "cornell_mirror", "cornell_glossy", "ao_creases", "explosion"]:
        frames.append((name, "", ["--builtin", name]))
    maps = sorted(glob.glob(os.path.join(args.testdata, "environments", "*.hdr")))
    for model in sorted(glob.glob(os.path.join(args.testdata, "gltf-samples", "*"))):
        files = sorted(glob.glob(os.path.join(model, "glTF-Binary", "*.glb"))) or sorted(glob.glob(os.path.join(model, "glTF", "*.gltf")))
        if not files:
            continue
        for env in [""] + maps:
            frames.append((os.path.basename(model), os.path.basename(env), [files[0]] + (["--environment", env] if env else [])))
    for n, light in [(12, True), (36, True), (12, False), (36, False)]:
        path = os.path.join(tmp, "field%d%s.gltf" % (n, "" if light else "_nolight"))
        with open(path, "w") as f:
            f.write(subprocess.run([sys.executable, os.path.join(ROOT, "bench", "glass_metal_field.py"), str(n)] +
                                   ([] if light else ["--no-light"]), check=True, capture_output=True, text=True).stdout)
        frames.append(("glass_metal_field %d%s" % (n, "" if light else " (studio environment)"), "", [path]))
    print("| scene | environment | cold render ms | warm render ms | passes of the cold frame (ms) | specular maps |")
    print("|---|---|---|---|---|---|")
    for name, env, source in frames:
        runs = []
        for k in range(2):
            stats = os.path.join(tmp, "stats%d.json" % k)
            r = subprocess.run([args.client, "--server", args.server, "render"] + source +
                               ["--size", "%dx%d" % (args.size, args.size), "-o", os.path.join(tmp, "frame.png"),
                                "--stats", stats, "-q"], capture_output=True, text=True)
            if r.returncode != 0:
                break
            runs.append(json.load(open(stats))["stats"])
        if len(runs) < 2:
            print("| %s | %s | failed: %s | | | |" % (name, env or "as shipped", r.stderr.strip()[:120]))
            continue
        s = runs[0]
        # A pass's time: its prepare() (photon tracing, BVH and map builds) plus the larger of its
        # execute's CPU and GPU ms.
        def ms(p):
            return p.get("prepare_ms", 0) + max(p.get("cpu_ms", 0), p.get("gpu_ms", 0))
        passes = ", ".join("%s %d" % (p["name"], round(ms(p))) for p in s["passes"])
        spec = [p for p in s["passes"] if p["name"] == "specular"]
        maps = ""
        if spec:
            c = spec[0].get("counters", {})
            maps = "%d objects, %d texels%s" % (c.get("objects", 0), c.get("cube_resolution", 0),
                                                 " (kept for caustics)" if c.get("maps_kept_for_caustics") else "")
        print("| %s | %s | %d | %d | %s | %s |" % (name, env or "as shipped", round(s["render_ms"]), round(runs[1]["render_ms"]),
                                                passes, maps), flush=True)


if __name__ == "__main__":
    main()
