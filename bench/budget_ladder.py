#!/usr/bin/env python3
"""Budget ladder: how often a frame with a time_budget_ms runs within it, with the daemon's speed factor
measured (radiantd --speed-factor auto, the default) against pinned to the table's own machine (1), in one
run, optionally with CPU-heavy processes beside the daemons (issue 31's goal: 90% of the budgets met with
another CPU-heavy process running).

    bench/budget_ladder.py [--radiantd build/server/radiantd] [--load N] [--size 64] [--rounds 2]
                           [--scenes cornell_box,cornell_glass,explosion] [--modes auto,1] [-o ladder.json]

Per mode a fresh daemon; per scene one warm-up frame (shaders, scene upload), then for each round the
budgets 1, 1.5, 2.5, 4 and 8 times the cheapest configuration's predicted ms *at speed factor 1* (the
same budgets in both modes), each frame with a fresh seed (photons, networks traced cold, as the table's
cost sweeps were). A frame fits when stats.budget.measured_ms <= its budget. A budget is feasible when it
is at least the median time of the scene's 1x frames (which run the cheapest configuration): below that
no choice fits, and on a machine slower than the table's (a loaded one) the 1x budgets are not. The
modes run interleaved by round so that both see the same load. --load N starts N busy-loop processes for the whole run.
Prints one line per frame and a table per mode; -o writes every record as JSON.
"""
import argparse
import json
import multiprocessing
import os
import re
import subprocess
import sys
import time
import urllib.request

SCENE_PASSES = {
    "cornell_box": {},
    "cornell_glass": {},
    # The media ladder of tests/http/server/BudgetTest.cpp: the illumination network owns the media.
    "explosion": {"photon_gi": False, "illumination_network": {"warm_start": False}},
}
FACTORS = [1.0, 1.5, 2.5, 4.0, 8.0]


def busy():
    while True:
        pass


class Daemon:
    def __init__(self, radiantd, speed):
        self.proc = subprocess.Popen([radiantd, "--port", "0", "--request-timeout", "600", "--speed-factor", speed],
                                     stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        line = self.proc.stdout.readline()
        m = re.search(r"listening on (http://127\.0\.0\.1:\d+)", line)
        if not m:
            raise SystemExit(f"radiantd did not start: {line!r}")
        self.url = m.group(1)
        for _ in range(600):
            try:
                with urllib.request.urlopen(self.url + "/v1/ready", timeout=5) as r:
                    if r.status == 200:
                        break
            except Exception:
                time.sleep(0.1)

    def render(self, body):
        req = urllib.request.Request(self.url + "/v1/renders", data=json.dumps(body).encode(),
                                     headers={"Content-Type": "application/json"})
        with urllib.request.urlopen(req, timeout=900) as r:
            return json.loads(r.read())

    def close(self):
        self.proc.terminate()
        try:
            self.proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.proc.kill()


def request(scene, size, seed, budget=None):
    passes = json.loads(json.dumps(SCENE_PASSES[scene]))
    if "illumination_network" in passes:
        passes["illumination_network"]["seed"] = seed  # a cold network per frame, as in the table's sweep
    body = {"scene": {"builtin": scene}, "width": size, "height": size, "seed": seed,
            "outputs": [{"format": "exr", "aovs": ["beauty"]}]}
    if passes:
        body["passes"] = passes
    if budget is not None:
        body["time_budget_ms"] = budget
    return body


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--radiantd", default="build/server/radiantd")
    ap.add_argument("--load", type=int, default=0, help="busy-loop processes beside the daemons")
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--scenes", default=",".join(SCENE_PASSES))
    ap.add_argument("--modes", default="auto,1", help="radiantd --speed-factor values, one daemon each")
    ap.add_argument("-o", "--output")
    a = ap.parse_args()
    scenes, modes = a.scenes.split(","), a.modes.split(",")
    loaders = [multiprocessing.Process(target=busy, daemon=True) for _ in range(a.load)]
    for p in loaders:
        p.start()
    daemons = {m: Daemon(a.radiantd, m) for m in modes}
    records = []
    started = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    load_before = os.getloadavg()
    try:
        # The budgets, in the table's units: the cheapest configuration's prediction at factor 1.
        budgets = {}
        pinned = daemons.get("1") or Daemon(a.radiantd, "1")
        for s in scenes:
            probe = pinned.render(request(s, a.size, 7, budget=1))
            budgets[s] = [probe["stats"]["budget"]["predicted_ms"] * f * 1.0001 for f in FACTORS]
        if "1" not in daemons:
            pinned.close()
        for d in daemons.values():
            for s in scenes:
                d.render(request(s, a.size, 8))  # warm-up: shaders, scene upload
        seed = 1000
        for rnd in range(a.rounds):
            for s in scenes:
                for budget in budgets[s]:
                    seed += 1
                    for m, d in daemons.items():
                        r = d.render(request(s, a.size, seed, budget))
                        b = r["stats"]["budget"]
                        rec = {"mode": m, "scene": s, "round": rnd, "budget_ms": budget, "seed": seed,
                               "predicted_ms": b["predicted_ms"], "measured_ms": b["measured_ms"],
                               "speed": b.get("speed"), "fits": b["measured_ms"] <= budget,
                               "params": {t: v.get("params") for t, v in b["techniques"].items() if v.get("params")},
                               "techniques": {t: {k: v.get(k) for k in ("predicted_ms", "measured_ms")}
                                              for t, v in b["techniques"].items()}}
                        records.append(rec)
                        print(f"{m:>5} {s:14} budget {budget:8.1f} ms  predicted {b['predicted_ms']:8.1f}  "
                              f"measured {b['measured_ms']:8.1f}  factor {b.get('speed', {}).get('factor', 1):.2f}  "
                              f"{'fits' if rec['fits'] else 'OVER'}", flush=True)
    finally:
        for d in daemons.values():
            d.close()
        for p in loaders:
            p.terminate()
    print(f"\nstarted {started}, load average before {load_before}, after {os.getloadavg()}, --load {a.load}")
    # A budget below what the cheapest configuration takes on this machine now cannot be met by any
    # choice: the 1x budgets choose the cheapest, so the median of their frames' times is that floor
    # (per mode and scene). "feasible" counts the budgets at or above it.
    floor = {}
    for m in modes:
        for s in scenes:
            cheap = sorted(r["measured_ms"] for r in records
                           if r["mode"] == m and r["scene"] == s and r["budget_ms"] == budgets[s][0])
            floor[(m, s)] = cheap[len(cheap) // 2] if cheap else 0.0
    for r in records:
        r["feasible"] = r["budget_ms"] >= floor[(r["mode"], r["scene"])]
    print("| speed factor | scene | frames within budget | feasible budgets met | median measured / budget |")
    print("|---|---|---|---|---|")
    for m in modes:
        for s in scenes + ["all"]:
            rs = [r for r in records if r["mode"] == m and (s == "all" or r["scene"] == s)]
            if not rs:
                continue
            ratios = sorted(r["measured_ms"] / r["budget_ms"] for r in rs)
            fe = [r for r in rs if r["feasible"]]
            print(f"| {m} | {s} | {sum(r['fits'] for r in rs)}/{len(rs)} | {sum(r['fits'] for r in fe)}/{len(fe)} | "
                  f"{ratios[len(ratios) // 2]:.2f} |")
    if a.output:
        with open(a.output, "w") as f:
            json.dump({"started": started, "load": a.load, "size": a.size, "records": records}, f, indent=1)


if __name__ == "__main__":
    sys.exit(main())
