#!/usr/bin/env python3
"""Throughput through 1, 2 and 3 radiantd behind nginx, and the proxy's overhead per request.

    python3 bench/fleet_bench.py --radiantd build/server/radiantd [--radiant build/client/radiant] [--gpu-scenes N]
                                 [--renders 96] [--concurrency 6] [--sweep-points 48]

Starts the daemons (--daemon-id d0..) and nginx with deploy/nginx/radiant.conf (listen port and
daemon addresses replaced, as tests/http/fleet does) on ephemeral loopback ports, then:
  - throughput: `renders` small renders (32x32, direct lighting, 8 scenes round robin, each with its
    X-Radiant-Scene header) from `concurrency` client threads, through the proxy, for 1, 2, 3 daemons;
    Median of --rounds interleaved rounds;
  - sweep (with --radiant): `radiant sweep` of 8 scene files x N/8 settings through the proxy, with
    --inflight 2 per daemon, for 1, 2, 3 daemons: wall time, points/s, efficiency per daemon, and how
    many daemons the scenes landed on (from the records' `server`/daemon id);
  - overhead: 200 sequential GET /v1/health and 200 small renders, direct and through the proxy
    (one daemon), interleaved; medians and their difference.
Prints a Markdown table for docs/PERFORMANCE.md.
"""
import argparse
import hashlib
import http.client
import json
import os
import re
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    p = s.getsockname()[1]
    s.close()
    return p


def start_daemon(radiantd, ident, log, extra=()):
    p = subprocess.Popen([radiantd, "--port", "0", "--daemon-id", ident, *extra], stdout=subprocess.PIPE, stderr=open(log, "w"), text=True)
    line = p.stdout.readline()
    m = re.match(r"radiantd listening on http://127\.0\.0\.1:(\d+)", line)
    if not m:
        raise RuntimeError(f"radiantd: {line!r}")
    return p, int(m.group(1))


def request(port, method, path, body=None, headers=None, timeout=300):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
    c.request(method, path, body=body, headers=headers or {})
    r = c.getresponse()
    data = r.read()
    c.close()
    return r.status, data, r


def wait_ready(port, seconds=120):
    end = time.time() + seconds
    while time.time() < end:
        try:
            if request(port, "GET", "/v1/ready")[0] == 200:
                return
        except OSError:
            pass
        time.sleep(0.1)
    raise RuntimeError(f"port {port} not ready")


def start_nginx(tmp, daemon_ports):
    shipped = ROOT / "deploy" / "nginx"
    port = free_port()
    conf = (shipped / "radiant.conf").read_text().replace("listen 8080;", f"listen 127.0.0.1:{port};")
    (tmp / "radiant.conf").write_text(conf)
    fleet = "".join(f"server 127.0.0.1:{p} max_fails=1 fail_timeout=5s;\n" for p in daemon_ports)
    daemons = "".join(f"upstream radiant_d{i} {{ server 127.0.0.1:{p}; keepalive 8; keepalive_timeout 1s; }}\n"
                      for i, p in enumerate(daemon_ports))
    daemons += "map $radiant_owner_id $radiant_owner {\n    default \"\";\n" + "".join(
        f"    d{i} radiant_d{i};\n" for i in range(len(daemon_ports))) + "}\n"
    (tmp / "radiant.fleet").write_text(fleet)
    (tmp / "radiant.daemons").write_text(daemons)
    t = str(tmp)
    (tmp / "nginx.conf").write_text(
        f"pid {t}/nginx.pid; error_log {t}/error.log warn; daemon off; master_process off;\n"
        f"events {{ worker_connections 512; }}\nhttp {{ access_log off; client_body_temp_path {t}/body; "
        f"proxy_temp_path {t}/proxy; fastcgi_temp_path {t}/f; uwsgi_temp_path {t}/u; scgi_temp_path {t}/s;\n"
        f"include radiant.conf; }}\n")
    p = subprocess.Popen([shutil.which("nginx") or "/usr/sbin/nginx", "-p", t, "-c", f"{t}/nginx.conf"])
    try:
        wait_ready(port, 60)
    except RuntimeError:
        p.kill()
        p.wait()
        raise RuntimeError(f"nginx on port {port}: {(tmp / 'error.log').read_text() if (tmp / 'error.log').exists() else ''}")
    return p, port


def scenes():
    base = (ROOT / "scenes" / "cornell_box.gltf").read_bytes()
    out = []
    for k in range(8):
        b = base + b"\n" * (k + 1)
        out.append((b, "sha256:" + hashlib.sha256(b).hexdigest()))
    return out


def render_body(digest, size=32):
    return json.dumps({"scene": {"digest": digest}, "width": size, "height": size,
                       "passes": {"photon_gi": False}, "outputs": [{"format": "png", "aovs": ["beauty"]}]})


def render(port, digest):
    status, data, _ = request(port, "POST", "/v1/renders", render_body(digest),
                              {"Content-Type": "application/json", "X-Radiant-Scene": digest})
    if status != 200:
        raise RuntimeError(f"render: {status} {data[:200]!r}")
    res = json.loads(data)
    for f in res["frames"]:
        s, _, _ = request(port, "GET", f["url"])
        assert s == 200
    request(port, "DELETE", "/v1/renders/" + res["id"])


def throughput(port, sc, n, concurrency):
    todo = list(range(n))
    lock = threading.Lock()

    errors = []

    def worker():
        while True:
            with lock:
                if not todo or errors:
                    return
                i = todo.pop()
            try:
                render(port, sc[i % len(sc)][1])
            except Exception as e:  # noqa: BLE001 - reported by the main thread
                with lock:
                    errors.append(e)

    for b, d in sc:  # upload and warm every scene on its daemon
        request(port, "PUT", "/v1/scenes", b, {"Content-Type": "model/gltf+json", "X-Radiant-Scene": d})
        render(port, d)
    t0 = time.perf_counter()
    threads = [threading.Thread(target=worker) for _ in range(concurrency)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    if errors:
        raise errors[0]
    return n / (time.perf_counter() - t0)


def sweep_spec(tmp, n_points):
    """8 scene files (uploaded by the client) x n_points/8 settings of the direct pass's PCF radius."""
    files = []
    for k, (b, _) in enumerate(scenes()):
        f = tmp / f"scene{k}.gltf"
        f.write_bytes(b)
        files.append(str(f))
    settings = list(range(max(1, n_points // len(files))))
    base = {"scene": {"file": files[0]}, "width": 32, "height": 32, "passes": {"photon_gi": False},
            "outputs": [{"format": "png", "aovs": ["beauty"]}]}
    spec = {"name": "fleet-bench", "base": base,
            "axes": {"scene.file": files, "passes.direct.pcf_radius": settings}, "repeats": 1, "warmup": 0}
    path = tmp / "sweep.json"
    path.write_text(json.dumps(spec))
    return path, len(files) * len(settings)


def run_sweep(radiant, port, spec, out, inflight):
    t0 = time.perf_counter()
    r = subprocess.run([radiant, "--server", f"http://127.0.0.1:{port}", "sweep", str(spec), "-o", str(out),
                        "--inflight", str(inflight)], capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if r.returncode != 0:
        raise RuntimeError(f"radiant sweep: {r.returncode} {r.stderr[-400:]}")
    recs = [json.loads(l) for l in out.read_text().splitlines() if l.strip()]
    bad = [x for x in recs if "error" in x]
    if bad:
        raise RuntimeError(f"radiant sweep: {len(bad)} points failed: {bad[0]}")
    return dt, recs


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--radiantd", required=True)
    ap.add_argument("--radiant", help="the client, for the sweep measurement (skipped without it)")
    ap.add_argument("--sweep-points", type=int, default=48)
    ap.add_argument("--renders", type=int, default=96)
    ap.add_argument("--concurrency", type=int, default=6)
    ap.add_argument("--overhead-n", type=int, default=200)
    ap.add_argument("--rounds", type=int, default=3, help="throughput rounds (median reported)")
    ap.add_argument("--gpu-scenes", type=int, help="radiantd --gpu-scenes for every daemon (default: radiantd's)")
    a = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="radiant-fleet-bench-"))
    procs = []
    try:
        extra = ("--gpu-scenes", str(a.gpu_scenes)) if a.gpu_scenes else ()
        daemons = [start_daemon(a.radiantd, f"d{i}", tmp / f"d{i}.log", extra) for i in range(3)]
        procs += [p for p, _ in daemons]
        for _, port in daemons:
            wait_ready(port)
        _, info, _ = request(daemons[0][1], "GET", "/v1/info")
        renderer = json.loads(info)["device"]["renderer"]
        sc = scenes()
        rates = {1: [], 2: [], 3: [], "one scene": []}
        for rnd in range(a.rounds):  # interleaved, so that the machine's load drifts over every count alike
            for n in (1, 2, 3):
                d = tmp / f"r{rnd}n{n}"
                d.mkdir()
                ng, port = start_nginx(d, [p for _, p in daemons[:n]])
                try:
                    rates[n].append(throughput(port, sc, a.renders, a.concurrency))
                    if n == 1:  # the same renders of one scene: a daemon whose caches stay warm
                        rates["one scene"].append(throughput(port, sc[:1], a.renders, a.concurrency))
                    print(f"round {rnd}: {n} daemon(s) {rates[n][-1]:.1f} renders/s", file=sys.stderr)
                finally:
                    ng.terminate()
                    ng.wait()
        rows = [(n, statistics.median(rates[n])) for n in (1, 2, 3)]
        sweep_rows = []
        if a.radiant:
            spec, points = sweep_spec(tmp, a.sweep_points)
            sweeps = {1: [], 2: [], 3: []}
            for rnd in range(a.rounds):
                for n in (1, 2, 3):
                    d = tmp / f"s{rnd}n{n}"
                    d.mkdir()
                    ng, port = start_nginx(d, [p for _, p in daemons[:n]])
                    try:
                        dt, recs = run_sweep(a.radiant, port, spec, d / "r.jsonl", 2 * n)
                        if len(recs) != points:
                            raise RuntimeError(f"sweep: {len(recs)} records for {points} points")
                        sweeps[n].append(dt)
                        print(f"round {rnd}: sweep of {points} points, {n} daemon(s): {dt:.2f} s", file=sys.stderr)
                    finally:
                        ng.terminate()
                        ng.wait()
            sweep_rows = [(n, statistics.median(sweeps[n])) for n in (1, 2, 3)]
        one_scene = statistics.median(rates["one scene"])
        # Overhead, one daemon: direct against through the proxy, interleaved.
        (tmp / "overhead").mkdir()
        ng, port = start_nginx(tmp / "overhead", [daemons[0][1]])
        procs.append(ng)
        direct_port = daemons[0][1]
        times = {"health direct": [], "health proxy": [], "render direct": [], "render proxy": []}
        for i in range(a.overhead_n):
            for name, p in (("direct", direct_port), ("proxy", port)):
                t0 = time.perf_counter()
                request(p, "GET", "/v1/health")
                times["health " + name].append((time.perf_counter() - t0) * 1e3)
                t0 = time.perf_counter()
                render(p, sc[0][1])
                times["render " + name].append((time.perf_counter() - t0) * 1e3)
        med = {k: statistics.median(v) for k, v in times.items()}
        print(f"GL renderer: {renderer}; date: {time.strftime('%Y-%m-%d', time.gmtime())}; "
              f"radiantd --gpu-scenes {a.gpu_scenes or 'default (4)'}; "
              f"{a.renders} renders 32x32 (direct lighting, 8 scenes), {a.concurrency} client threads, "
              f"median of {a.rounds} interleaved rounds\n")
        print("| daemons | renders/s | speed-up | efficiency per daemon |")
        print("|---|---|---|---|")
        for n, r in rows:
            print(f"| {n} | {r:.1f} | {r / rows[0][1]:.2f} | {r / rows[0][1] / n:.2f} |")
        if sweep_rows:
            print(f"\n`radiant sweep` of {points} points (8 scene files x {points // 8} PCF radii, 32x32, uploads "
                  f"included), --inflight 2 per daemon, median of {a.rounds} interleaved rounds:\n")
            print("| daemons | wall s | points/s | speed-up | efficiency per daemon |")
            print("|---|---|---|---|---|")
            for n, t in sweep_rows:
                print(f"| {n} | {t:.2f} | {points / t:.1f} | {sweep_rows[0][1] / t:.2f} | {sweep_rows[0][1] / t / n:.2f} |")
        print(f"\nThe same {a.renders} renders on one scene, one daemon: {one_scene:.1f} renders/s "
              f"({one_scene / rows[0][1]:.1f}x the 8-scene rate: a scene switch costs the caches)")
        print(f"\n| request (median of {a.overhead_n}) | direct ms | through nginx ms | overhead ms |")
        print("|---|---|---|---|")
        for k in ("health", "render"):
            print(f"| {'GET /v1/health' if k == 'health' else 'render 32x32 + frame + DELETE'} | {med[k + ' direct']:.3f} | "
                  f"{med[k + ' proxy']:.3f} | {med[k + ' proxy'] - med[k + ' direct']:.3f} |")
    finally:
        for p in procs:
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
