#!/usr/bin/env python3
"""Generates api/presets.json, the preset table behind the render request's "quality" and
"time_budget_ms" (api/Presets.h), from `radiant sweep` results measured on the built-in scenes.

    bench/presets.py all  [--server URL] [--radiant build/client/radiant] [-o api/presets.json] [--dir bench-presets]
    bench/presets.py spec [--server URL] [--dir bench-presets]      # ground truths + bench-presets/presets.spec.json
    bench/presets.py fit  RESULTS.jsonl [...] [-o api/presets.json] [--command TEXT]

`all` = spec, then `radiant sweep DIR/presets.spec.json -o DIR/results.jsonl`, then fit. Run it against a
radiantd on the machine the table is for (a GPU server regenerates its own table with the same command)
with a long --request-timeout; rebuild afterwards (the table is embedded in the binary).

What is measured (TECHNIQUES below; each technique on its canonical built-in scene):
  cost sweeps  every configuration at each of SIZES, one point each with its own seed, warmup 0 and
               repeats 1, so that the seed-keyed caches (photon records, reference images) are cold: the
               cost is that of a first render. Shaders are warmed first by one untimed sweep.
  error sweeps every configuration at ERROR_SIZE, seed 0, with a compare block: photon_gi's indirect and
               ambient_occlusion's ao against the reference renderer at 256 / 64 spp; the reference
               itself against an uploaded ground truth (the reference at TRUTH_SPP spp, seed 99) because a
               compare reference with the frame's own seed would share its first samples.

The fit (Python standard library only):
  cost model   per technique, ms = sum of coef * product(vars) (vars: "pixels" and the technique's numeric
               parameters), least squares over the cost records with non-negative coefficients (a term
               whose coefficient comes out negative is dropped and the rest refitted), refitted once
               without outliers (residual > 4x the median and > 5 ms). The measured cost of a pass is
               api::passCostMs: cpu_ms + the counters trace_ms and splat_build_ms (not gpu_ms: llvmpipe
               runs GL work asynchronously, so a pass's GPU timer also spans later passes' CPU work). Every
               other pass seen in the records gets coef + coef * pixels, and the frame's overhead
               (render_ms - the passes' cost) likewise.
  front        per technique, the error records sorted by the model's cost at ERROR_SIZE, keeping the
               points that lower the RMSE (the Pareto front); errors are those of ERROR_SIZE.
  presets      draft = the cheapest front point, reference = the most accurate, preview and final = the
               points nearest 1/3 and 2/3 of the way in log cost.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from photon_gi_goal import call, render  # noqa: E402  (the same HTTP helpers)

SIZES = [32, 64]
ERROR_SIZE = 64
TRUTH_SPP = 1024

# technique -> canonical scene, extra request keys, swept configurations, cost model terms, compare block.
TECHNIQUES = {
    "reference": {
        "scene": "cornell_box",
        "passes": {"photon_gi": False},
        "configs": [{"spp": s} for s in (1, 2, 4, 8, 16, 32, 64)],
        "terms": [[], ["pixels", "spp"]],
        "compare": {"aov": "reference"},  # against the uploaded ground truth
        "output_aov": "reference",
    },
    "photon_gi": {
        "scene": "cornell_box",
        "passes": {},
        "configs": [{"photons": n, "C": c} for n in (20000, 50000, 100000, 250000, 500000) for c in (10, 20)],
        "terms": [[], ["photons"], ["pixels"], ["pixels", "C", "C"]],
        "compare": {"aov": "indirect", "spp": 1024},
        "output_aov": "indirect",
    },
    "ambient_occlusion": {
        "scene": "ao_creases",
        "extra": {"ambient": [1, 1, 1]},
        "passes": {"photon_gi": False},
        "configs": [{"samples": s} for s in (2, 4, 8, 16, 32)],
        "terms": [[], ["pixels"], ["pixels", "samples"]],
        "compare": {"aov": "ao", "spp": 64},
        "output_aov": "ao",
        "warmup": 1,  # compiles the shader of each sample count; AO has no seed-keyed cache
    },
}


def base_request(name, t, size, seed):
    passes = dict(t["passes"])
    passes[name] = {}
    # One raster sample per pixel: a request with quality or time_budget_ms and no supersampling of its
    # own runs at 1 (api/Validate.cpp), so the table is measured there (the plain default is 2).
    r = {"scene": {"builtin": t["scene"]}, "width": size, "height": size, "seed": seed, "supersampling": 1,
         "passes": passes, "outputs": [{"format": "exr", "aovs": ["beauty"] + ([t["output_aov"]] if t["output_aov"] != "beauty" else [])}]}
    r.update(t.get("extra", {}))
    return r


def zip_group(name, points):
    """points: list of (config, size, seed) -> one zip group over the dotted paths."""
    group = {}
    for config, size, seed in points:
        for k, v in config.items():
            group.setdefault(f"passes.{name}.{k}", []).append(v)
        group.setdefault("width", []).append(size)
        group.setdefault("height", []).append(size)
        group.setdefault("seed", []).append(seed)
    return group


def make_spec(server, out_dir):
    os.makedirs(out_dir, exist_ok=True)
    sweeps = []
    # Shader compilation and scene upload happen once per daemon: one untimed render per technique.
    for name, t in TECHNIQUES.items():
        sweeps.append({"name": f"presets-warm-{name}", "technique": name, "base": base_request(name, t, 32, 7),
                       "repeats": 1, "warmup": 0})
    seed = 1000
    for name, t in TECHNIQUES.items():
        points = []
        for size in SIZES:
            for config in t["configs"]:
                points.append((config, size, seed))
                seed += 1
        sweeps.append({"name": f"presets-cost-{name}", "technique": name, "base": base_request(name, t, 32, 0),
                       "zip": [zip_group(name, points)], "repeats": 1, "warmup": t.get("warmup", 0)})
    for name, t in TECHNIQUES.items():
        compare = dict(t["compare"])
        if name == "reference":
            base = {"scene": {"builtin": t["scene"]}, "width": ERROR_SIZE, "height": ERROR_SIZE, "seed": 99,
                    "passes": {"reference": {"spp": TRUTH_SPP}, "photon_gi": False},
                    "outputs": [{"format": "exr", "half": False, "aovs": ["reference"]}]}
            t0 = time.time()
            truth, _ = render(server, base)
            exr = call(server, truth["frames"][0]["url"], ctype="image/x-exr")
            compare["against"] = call(server, "/v1/images", exr, method="PUT", ctype="image/x-exr")
            compare["against"] = json.loads(compare["against"])["digest"] if isinstance(compare["against"], bytes) \
                else compare["against"]["digest"]
            print(f"ground truth: reference {TRUTH_SPP} spp at {ERROR_SIZE}x{ERROR_SIZE}, "
                  f"{time.time() - t0:.1f} s", file=sys.stderr)
        points = [(config, ERROR_SIZE, 0) for config in t["configs"]]
        sweeps.append({"name": f"presets-error-{name}", "technique": name,
                       "base": base_request(name, t, ERROR_SIZE, 0), "zip": [zip_group(name, points)],
                       "repeats": 1, "warmup": 0, "compare": compare})
    spec = os.path.join(out_dir, "presets.spec.json")
    with open(spec, "w") as f:
        json.dump({"sweeps": sweeps}, f, indent=1)
    return spec


# --- fitting ---------------------------------------------------------------------------------------

def pass_cost(p):
    """api::passCostMs of a sweep record's pass entry (medians)."""
    ms = p["cpu_ms"]["median"]
    for k in ("trace_ms", "splat_build_ms"):
        ms += p.get("counters", {}).get(k, 0.0)
    return ms


def term_value(vars_, params, pixels):
    v = 1.0
    for n in vars_:
        v *= pixels if n == "pixels" else float(params[n])
    return v


def solve(a, b):
    """Gaussian elimination with partial pivoting; a is n x n."""
    n = len(a)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for c in range(n):
        piv = max(range(c, n), key=lambda r: abs(m[r][c]))
        if abs(m[piv][c]) < 1e-300:
            raise ValueError("singular")
        m[c], m[piv] = m[piv], m[c]
        for r in range(n):
            if r != c:
                f = m[r][c] / m[c][c]
                for k in range(c, n + 1):
                    m[r][k] -= f * m[c][k]
    return [m[i][n] / m[i][i] for i in range(n)]


def fit_terms(terms, rows):
    """fit_terms_once, then once more without the records whose residual is above 4 times the median
    absolute residual (and above 5 ms): a shared machine's stalls and one-off work (a shader compiled on
    first use) are not the configuration's cost."""
    out, resid = fit_terms_once(terms, rows)
    if not out:
        return out, resid, 0
    res = [abs(ms - predict(out, p, px)) for (p, px, ms) in rows]
    med = sorted(res)[len(res) // 2]
    kept = [r for r, e in zip(rows, res) if e <= max(4 * med, 5.0)]
    if len(rows) > len(kept) > len(terms):
        out, resid = fit_terms_once(terms, kept)
        return out, resid, len(rows) - len(kept)
    return out, resid, 0


def fit_terms_once(terms, rows):
    """rows: (params, pixels, ms). Least squares with non-negative coefficients, each column scaled to
    unit RMS so that the normal equations stay well conditioned."""
    if not rows:
        return [], None
    active = list(range(len(terms)))
    while active:
        cols = [[term_value(terms[j], p, px) for (p, px, _) in rows] for j in active]
        scale = [math.sqrt(sum(x * x for x in col) / len(col)) or 1.0 for col in cols]
        cols = [[x / s for x in col] for col, s in zip(cols, scale)]
        y = [ms for (_, _, ms) in rows]
        ata = [[sum(ci[k] * cj[k] for k in range(len(y))) for cj in cols] for ci in cols]
        aty = [sum(ci[k] * y[k] for k in range(len(y))) for ci in cols]
        try:
            coef = [c / s for c, s in zip(solve(ata, aty), scale)]
        except ValueError:
            coef = [-1.0] * len(active)
        if all(c >= 0 for c in coef):
            out = [{"coef": c, "vars": terms[j]} for c, j in zip(coef, active)]
            pred = [sum(t["coef"] * term_value(t["vars"], p, px) for t in out) for (p, px, _) in rows]
            resid = math.sqrt(sum((a - b) ** 2 for a, b in zip(pred, y)) / len(y))
            return out, resid
        active.pop(min(range(len(coef)), key=lambda i: coef[i]))  # drop the most negative term
    return [], float("nan")


def predict(terms, params, pixels):
    return sum(t["coef"] * term_value(t["vars"], params, pixels) for t in terms)


def fit(records, command):
    ok = [r for r in records if "error" not in r and r.get("passes")]
    device = next((r.get("device") for r in ok if r.get("device")), {})
    table = {"generated": {
        "by": "bench/presets.py fit (never edit this file by hand; regenerate it on the machine it is for)",
        "command": command, "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "device": device,
        "sizes": SIZES, "error_size": ERROR_SIZE,
        "note": "cost = api::passCostMs of a cold first render (own seed); error = RMSE against the reference at "
                "error_size on the technique's canonical built-in scene"}, "techniques": {}}
    cost = [r for r in ok if r["sweep"].startswith("presets-cost-")]
    other_rows, overhead_rows = {}, []
    for r in cost:
        px = r["request"]["width"] * r["request"]["height"]
        total = 0.0
        for p in r["passes"]:
            c = pass_cost(p)
            total += c
            if p["name"] != r["technique"]:
                other_rows.setdefault(p["name"], []).append(({}, px, c))
        overhead_rows.append(({}, px, r["render_ms"]["median"] - total))
    for name, t in TECHNIQUES.items():
        rows = []
        for r in cost:
            if r["technique"] != name:
                continue
            p = next((q for q in r["passes"] if q["name"] == name), None)
            if p is None:
                continue
            params = dict(r["request"]["passes"][name])
            rows.append((params, r["request"]["width"] * r["request"]["height"], pass_cost(p)))
        if not rows:
            continue
        terms, resid, dropped = fit_terms(t["terms"], rows)
        entry = {"model": {"terms": terms, "rms_residual_ms": resid, "records": len(rows), "outliers_dropped": dropped}}
        errs = [r for r in ok if r["sweep"] == f"presets-error-{name}" and r.get("metrics")]
        pts = []
        for r in errs:
            params = {k: r["request"]["passes"][name][k] for k in t["configs"][0]}
            px = r["request"]["width"] * r["request"]["height"]
            pts.append({"params": params, "error": r["metrics"]["rmse"], "predicted_ms": predict(terms, params, px)})
        pts.sort(key=lambda q: q["predicted_ms"])
        front = []
        for q in pts:
            if not front or q["error"] < front[-1]["error"]:
                front.append(q)
        if front:
            entry["error"] = {"metric": "rmse", "aov": t["compare"]["aov"], "scene": t["scene"],
                              "width": ERROR_SIZE, "height": ERROR_SIZE, "seed": 0,
                              "against": "reference" if "spp" in t["compare"] else
                              f"the reference at {TRUTH_SPP} spp, seed 99 (uploaded)"}
            if "spp" in t["compare"]:
                entry["error"]["spp"] = t["compare"]["spp"]
            entry["front"] = front
            lc = [math.log(max(q["predicted_ms"], 1e-6)) for q in front]

            def nearest(frac):
                target = lc[0] + frac * (lc[-1] - lc[0])
                return min(range(len(front)), key=lambda i: abs(lc[i] - target))
            entry["presets"] = {"draft": 0, "preview": nearest(1 / 3), "final": nearest(2 / 3),
                                "reference": len(front) - 1}
        table["techniques"][name] = entry
    for name, rows in sorted(other_rows.items()):
        if name in table["techniques"]:
            continue
        terms, resid, dropped = fit_terms([[], ["pixels"]], rows)
        table["techniques"][name] = {"model": {"terms": terms, "rms_residual_ms": resid, "records": len(rows),
                                               "outliers_dropped": dropped}}
    terms, resid, dropped = fit_terms([[], ["pixels"]], overhead_rows)
    table["overhead"] = {"terms": terms, "rms_residual_ms": resid, "records": len(overhead_rows),
                         "outliers_dropped": dropped}
    return table


def read_jsonl(paths):
    out = []
    for p in paths:
        with open(p) as f:
            for line in f:
                line = line.strip()
                if line:
                    try:
                        out.append(json.loads(line))
                    except json.JSONDecodeError:
                        pass
    latest = {}
    for r in out:
        latest[r.get("point_id", id(r))] = r
    return list(latest.values())


def write_table(table, path):
    with open(path, "w") as f:
        json.dump(table, f, indent=1, sort_keys=True)
        f.write("\n")
    print(f"wrote {path}", file=sys.stderr)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("command", choices=["all", "spec", "fit"])
    ap.add_argument("results", nargs="*")
    ap.add_argument("--server", default=os.environ.get("RADIANT_SERVER", "http://127.0.0.1:8080"))
    ap.add_argument("--radiant", default="build/client/radiant")
    ap.add_argument("--dir", default="bench-presets")
    ap.add_argument("-o", "--output", default="api/presets.json")
    ap.add_argument("--command-text", default=None, help="recorded as generated.command")
    a = ap.parse_args()
    command = a.command_text or "bench/presets.py " + " ".join(sys.argv[1:])
    if a.command in ("all", "spec"):
        spec = make_spec(a.server, a.dir)
        print(f"wrote {spec}", file=sys.stderr)
        if a.command == "spec":
            return
        results = os.path.join(a.dir, "results.jsonl")
        subprocess.run([a.radiant, "sweep", spec, "-o", results, "--server", a.server, "--quiet"], check=False)
        a.results = [results]
    if not a.results:
        ap.error("fit needs the results files")
    write_table(fit(read_jsonl(a.results), command), a.output)


if __name__ == "__main__":
    main()
