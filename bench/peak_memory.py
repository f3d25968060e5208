#!/usr/bin/env python3
"""Issue 30's memory goal: the peak resident set of one daemon through a sequence of heavy legitimate
frames (a field of 36 glass and metal spheres, the two glossiest shared samples under the shared maps,
the Cornell box with 4M photons, 16,667 stacked triangles, the field again at 512 px). Starts its own
radiantd (defaults, plus ARGS after --), renders each frame in turn with the client and reads the
daemon's VmHWM / VmRSS from /proc after each, with the frame's stats.memory.

    python3 bench/peak_memory.py [--radiantd build/server/radiantd] [--client build/client/radiant]
                                 [--port 18190] [-- radiantd flags...]

Prints one Markdown table (docs/PERFORMANCE.md, "Peak memory of heavy legitimate frames"). Linux only
(/proc); Python 3 standard library only.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def status_mib(pid):
    out = {}
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            key, _, value = line.partition(":")
            if key in ("VmHWM", "VmRSS"):
                out[key] = int(value.split()[0]) // 1024
    return out


def wait_ready(server, seconds=60):
    """Waits until the daemon at `server` answers /v1/ready (also bench/memory_budgets_full.py)."""
    for _ in range(seconds * 10):
        try:
            urllib.request.urlopen(server + "/v1/ready", timeout=1)
            return
        except Exception:
            time.sleep(0.1)


def stacked_triangles(path):
    # The hostile scene-cache test's soup: 16,667 unit triangles 1e-4 apart (50,001 vertices).
    import base64
    import struct
    n = 50001
    data = b"".join(struct.pack("<3f", float(i % 3 == 1), float(i % 3 == 2), -i * 1e-4) for i in range(n))
    gltf = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
                           "min": [0, 0, -(n - 1) * 1e-4], "max": [1, 1, 0]}],
            "bufferViews": [{"buffer": 0, "byteLength": len(data)}],
            "buffers": [{"byteLength": len(data),
                         "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}]}
    with open(path, "w") as f:
        json.dump(gltf, f)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--radiantd", default=os.path.join(ROOT, "build/server/radiantd"))
    ap.add_argument("--client", default=os.path.join(ROOT, "build/client/radiant"))
    ap.add_argument("--testdata", default=os.path.join(ROOT, "..", "shared", "testdata"))
    ap.add_argument("--port", type=int, default=18190)
    ap.add_argument("flags", nargs="*", help="radiantd flags (after --)")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="peak-memory-")
    field = os.path.join(tmp, "field36.gltf")
    with open(field, "w") as f:
        f.write(subprocess.run([sys.executable, os.path.join(ROOT, "bench", "glass_metal_field.py"), "36"],
                               check=True, capture_output=True, text=True).stdout)
    stack = os.path.join(tmp, "stack.gltf")
    stacked_triangles(stack)
    samples = os.path.join(args.testdata, "gltf-samples")
    envs = os.path.join(args.testdata, "environments")
    frames = [
        ("glass_metal_field 36, point light, 256 px", [field, "--size", "256x256"]),
        ("MetalRoughSpheres under qwantani, 256 px",
         [os.path.join(samples, "MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb"),
          "--environment", os.path.join(envs, "qwantani_afternoon_puresky_1k.hdr"), "--size", "256x256"]),
        ("DamagedHelmet under chinese_garden, 256 px",
         [os.path.join(samples, "DamagedHelmet/glTF/DamagedHelmet.gltf"),
          "--environment", os.path.join(envs, "chinese_garden_1k.hdr"), "--size", "256x256"]),
        ("cornell_box with photon_gi.photons 4,000,000, 256 px",
         ["--builtin", "cornell_box", "--size", "256x256", "--set", "photon_gi.photons=4000000"]),
        ("the 16,667 stacked triangles, 256 px", [stack, "--size", "256x256"]),
        ("glass_metal_field 36 again, 512 px", [field, "--size", "512x512"]),
    ]
    server = "http://127.0.0.1:%d" % args.port
    log = open(os.path.join(tmp, "radiantd.log"), "w")
    daemon = subprocess.Popen([args.radiantd, "--port", str(args.port)] + args.flags, stdout=log, stderr=log)
    try:
        wait_ready(server)
        info = json.load(urllib.request.urlopen(server + "/v1/info"))
        renderer = info.get("device", {}).get("renderer", "?")
        m = status_mib(daemon.pid)
        print("GL renderer: %s; memory target %s MiB\n" % (
            renderer, info.get("limits", {}).get("memory_target_bytes", 0) // 2**20))
        print("| frame (in this order, one daemon) | s | peak RSS after it | RSS after it | "
              "stats.memory released |")
        print("|---|---|---|---|---|")
        print("| (started) | | %d MiB | %d MiB | |" % (m["VmHWM"], m["VmRSS"]))
        for name, render in frames:
            stats = os.path.join(tmp, "stats.json")
            t0 = time.time()
            subprocess.run([args.client, "--server", server, "render"] + render +
                           ["-o", os.path.join(tmp, "frame.png"), "--stats", stats, "-q"], check=True)
            seconds = time.time() - t0
            released = json.load(open(stats))["stats"].get("memory", {}).get("released_bytes", 0)
            m = status_mib(daemon.pid)
            print("| %s | %.1f | %d MiB | %d MiB | %d MiB |" % (name, seconds, m["VmHWM"], m["VmRSS"],
                                                              released // 2**20))
            sys.stdout.flush()
    finally:
        daemon.terminate()
        daemon.wait()


if __name__ == "__main__":
    main()
