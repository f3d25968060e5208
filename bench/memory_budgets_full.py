#!/usr/bin/env python3
"""Issue 30's last memory case: every budget full at once, against --memory-limit-bytes (1.5e9 by default).

Starts its own radiantd (defaults, plus ARGS after --) and, while a 4M-photon Cornell frame runs, fills
  - the decode memory (--decode-memory-bytes): renders queued behind it, each naming its own uploaded
    scene that holds a 4096 x 4096 texture (64 MiB decoded, a 70 KB PNG),
  - the request bodies (--body-memory-bytes): concurrent 48 MiB uploads,
and samples the daemon's resident set every 20 ms. Prints the peak (sampled and the kernel's VmHWM)
and every HTTP status by kind of request: the goal is a peak under the limit, no 5xx but 503s with
Retry-After, and every accepted render done.

    python3 bench/memory_budgets_full.py [--radiantd build/server/radiantd] [--port 18191] [-- flags...]

Linux only (/proc); Python 3 standard library only. docs/PERFORMANCE.md, "Peak memory with every budget full".
"""
import argparse
import base64
import collections
import json
import os
import struct
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request
import zlib

from peak_memory import wait_ready

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def png_rgba(width, height, rgba):
    row = b"\0" + bytes(rgba) * width
    raw = zlib.compress(row * height, 9)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", raw) + chunk(b"IEND", b""))


def textured_quad(png, n):
    # One textured quad facing the default camera; `n` makes each document (and digest) distinct.
    pos = struct.pack("<12f", -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0)
    uv = struct.pack("<8f", 0, 1, 1, 1, 1, 0, 0, 0)
    idx = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    data = pos + uv + idx
    return json.dumps({
        "asset": {"version": "2.0"}, "extras": {"n": n}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}],
        "images": [{"uri": "data:image/png;base64," + base64.b64encode(png).decode()}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                        {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}]}).encode()


def request(server, method, path, body=None, ctype="application/json", timeout=300):
    req = urllib.request.Request(server + path, data=body, method=method, headers={"Content-Type": ctype})
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            return r.status, r.read(), dict(r.headers)
    except urllib.error.HTTPError as e:
        return e.code, e.read(), dict(e.headers)
    except Exception as e:  # connection closed on a refused body
        return "closed (%s)" % type(e).__name__, b"", {}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--radiantd", default=os.path.join(ROOT, "build/server/radiantd"))
    ap.add_argument("--port", type=int, default=18191)
    ap.add_argument("--scenes", type=int, default=16, help="queued renders, each naming its own 64 MiB scene")
    ap.add_argument("--bodies", type=int, default=8, help="concurrent 48 MiB uploads")
    ap.add_argument("flags", nargs="*", help="radiantd flags (after --)")
    args = ap.parse_args()
    server = "http://127.0.0.1:%d" % args.port
    tmp = tempfile.mkdtemp(prefix="radiant-budgets-")
    log = open(os.path.join(tmp, "radiantd.log"), "w")
    daemon = subprocess.Popen([args.radiantd, "--port", str(args.port)] + args.flags, stdout=log, stderr=log)
    statuses = collections.defaultdict(collections.Counter)
    samples = []
    stop = threading.Event()
    events = []
    t_start = time.time()

    def sample():
        while not stop.is_set():
            try:
                with open("/proc/%d/status" % daemon.pid) as f:
                    for line in f:
                        if line.startswith("VmRSS:"):
                            samples.append((time.time() - t_start, int(line.split()[1]) // 1024))
            except OSError:
                return
            time.sleep(0.02)

    try:
        wait_ready(server)
        info = json.load(urllib.request.urlopen(server + "/v1/info"))
        limits = info.get("limits", {})
        print("GL renderer: %s" % info.get("device", {}).get("renderer", "?"))
        print("limits: memory %d MiB (target %d MiB), decode memory %d MiB, body memory %d MiB, queue %s" % (
            limits.get("memory_limit_bytes", 0) >> 20, limits.get("memory_target_bytes", 0) >> 20,
            limits.get("decode_memory_effective_bytes", 0) >> 20, limits.get("body_memory_effective_bytes", 0) >> 20,
            limits.get("max_queue", "?")))
        # The scenes, uploaded one by one (each decode is admitted on its own; the cache keeps some).
        docs = [textured_quad(png_rgba(4096, 4096, (40 + 13 * i % 200, 90, 200, 255)), i) for i in range(args.scenes)]
        digests = []
        for doc in docs:
            code, body, _ = request(server, "PUT", "/v1/scenes", doc, "model/gltf+json")
            statuses["upload a 64 MiB scene"][code] += 1
            if code in (200, 201):
                digests.append(json.loads(body)["digest"])
        threading.Thread(target=sample, daemon=True).start()
        jobs = []
        code, body, _ = request(server, "POST", "/v1/renders", json.dumps({
            "scene": {"builtin": "cornell_box"}, "width": 256, "height": 256, "async": True,
            "passes": {"photon_gi": {"photons": 4000000}}}).encode())
        statuses["cornell_box, 4M photons, 256 px"][code] += 1
        if code == 202:
            jobs.append(json.loads(body)["id"])
        time.sleep(1.0)  # the photon frame is tracing

        def queue_render(digest):
            code, body, _ = request(server, "POST", "/v1/renders", json.dumps({
                "scene": {"digest": digest}, "width": 64, "height": 64, "async": True}).encode())
            statuses["queued render of its own scene"][code] += 1
            events.append((time.time() - t_start, "render %s" % code))
            if code == 202:
                jobs.append(json.loads(body)["id"])

        def big_body(i):
            pad = b"x" * (48 << 20)
            doc = b'{"asset":{"version":"2.0"},"extras":{"n":%d,"pad":"' % (1000 + i) + pad + b'"}}'
            code, _, _ = request(server, "PUT", "/v1/scenes", doc, "model/gltf+json")
            statuses["48 MiB upload"][code] += 1
            events.append((time.time() - t_start, "body %s" % code))

        threads = [threading.Thread(target=queue_render, args=(d,)) for d in digests]
        threads += [threading.Thread(target=big_body, args=(i,)) for i in range(args.bodies)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        done = collections.Counter()
        for job in jobs:
            for _ in range(3000):
                code, body, _ = request(server, "GET", "/v1/renders/" + job)
                state = json.loads(body).get("state") if code == 200 else code
                if state not in ("queued", "running"):
                    break
                time.sleep(0.1)
            done[state] += 1
            if state == "failed":
                print("failed job:", json.loads(body).get("error", body)[:300] if isinstance(json.loads(body).get("error"), str) else json.dumps(json.loads(body).get("error"))[:300])
        stop.set()
        with open("/proc/%d/status" % daemon.pid) as f:
            hwm = next(int(l.split()[1]) // 1024 for l in f if l.startswith("VmHWM:"))
        print("\n| request | answers |\n|---|---|")
        for kind, counter in statuses.items():
            print("| %s | %s |" % (kind, ", ".join("%s x%d" % (k, v) for k, v in sorted(counter.items(), key=str))))
        print("| accepted renders, final state | %s |" % ", ".join("%s x%d" % kv for kv in sorted(done.items())))
        print("\npeak resident: %d MiB sampled, %d MiB VmHWM (limit %d MiB); samples %d" % (
            max([m for _, m in samples] or [0]), hwm, limits.get("memory_limit_bytes", 0) >> 20, len(samples)))
        if os.environ.get("TRACE"):
            last = -1
            for t, m in samples:
                if int(t * 2) != last:
                    last = int(t * 2)
                    print("t=%.1f rss=%d %s" % (t, m, [e for te, e in events if t - 0.5 < te <= t]))
        metrics = urllib.request.urlopen(server + "/metrics").read().decode()
        for line in metrics.splitlines():
            if line.startswith(("radiant_memory_refused", "radiant_decodes_refused", "radiant_bodies_refused")):
                print(line)
    finally:
        stop.set()
        daemon.terminate()
        daemon.wait()


if __name__ == "__main__":
    main()
