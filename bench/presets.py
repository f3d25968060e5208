#!/usr/bin/env python3
"""Generates api/presets.json, the preset table behind the render request's "quality" and
"time_budget_ms" (api/Presets.h), from `radiant sweep` results measured on the built-in scenes.

    bench/presets.py all  [--server URL] [--radiant build/client/radiant] [-o api/presets.json] [--dir bench-presets]
    bench/presets.py spec [--server URL] [--dir bench-presets]      # ground truths + bench-presets/presets.spec.json
    bench/presets.py fit  RESULTS.jsonl [...] [-o api/presets.json] [--command-text TEXT]
    bench/presets.py markdown [api/presets.json]                    # docs/PERFORMANCE.md's tables of a table

`all` = spec, then `radiant sweep DIR/presets.spec.json -o DIR/results.jsonl`, then fit. Run it against a
radiantd on the machine the table is for (a GPU server regenerates its own table with the same command)
with a long --request-timeout; rebuild afterwards (the table is embedded in the binary). The whole run
took 285 s on the 2-core llvmpipe machine (load average 11-13), 532 s with the scene-count variants (load
4-5), so `all` is the normal command.

RUNS IN PARTS: `all --only caustics,specular --dir DIR2 [OLD/results.jsonl ...]` measures only those
techniques (same seeds as a full run) and fits the table from the given earlier results files plus the new
run's: a technique the new run measured takes only the new run's records; generated.runs lists every
run (its techniques, start time, duration and load average, from the run.json `all` writes next to its
results), so a merged table says that its parts were measured at different times. The shared models
(gbuffer, direct, shadow_maps, overhead) are fitted over all the parts' records. A fresh daemon per run:
the seed-keyed caches of an earlier run would make the same seeds' costs warm.

What is measured (TECHNIQUES below; each technique on its canonical built-in scene):
  cost sweeps  every configuration at each of SIZES, one point each with its own seed, warmup 0 and
               repeats 1, so that the seed-keyed caches (photon records, reference images) are cold: the
               cost is that of a first render. Shaders are warmed first by one untimed sweep.
  error sweeps every configuration at ERROR_SIZE (or the technique's error_size), seed 0, with a compare
               block: each technique's AOV against the reference in the matching mode (photon_gi's
               indirect, ambient_occlusion's ao, caustics' caustics = the light tracer's L S+ D E class, the
               media techniques' media in the model each solves) at the compare spp in TECHNIQUES; the
               reference itself against an uploaded ground truth (the reference at TRUTH_SPP spp, seed 99)
               because a compare reference with the frame's own seed would share its first samples. A
               technique whose AOV has no ground truth (specular, light_volumes: "no_front" says why) gets
               a cost model and no front: a budget charges its cost and leaves its parameters alone.

  scene counts the cost models' scene variables (api::SceneCounts: "particles" of the scene and the
               request's media, light_volumes' "beams", specular's "specular_objects") are varied by extra
               cost sweeps ("variants": the request's media with generated particles on explosion, other
               built-in scenes with other scatterers for light_volumes, bench/glass_metal_field.py's
               fields of 4 and 12 spheres, uploaded, for specular), and read per record from stats.scene.counts (the sweep
               record's scene_counts), the same numbers the daemon's budget chooser evaluates.
  cost-only    "extra_cost_configs" (at "extra_cost_sizes"): cost points with no error sweep, so never
               front candidates, for what the canonical points cannot tell apart: photon_gi at
               gather_step 4 and supersampling 2 (its block samples against the raster's pixels),
               specular at 128 and 256 px (its per-pixel term against its constant). A config key
               "supersampling" is the request's; "photon_gi.C" is another technique's parameter, a
               variable of this technique's model (specular's maps gather photon_gi's photons).

The fit (Python standard library only):
  cost model   per technique, ms = sum of coef * product(vars) (vars: "pixels", the scene counts and the
               technique's numeric parameters), least squares over the cost records with non-negative coefficients (a term
               whose coefficient comes out negative is dropped and the rest refitted), refitted once
               without outliers (residual > 4x the median and > 5 ms). The measured cost of a pass is
               api::passCostMs: cpu_ms + the counters trace_ms and splat_build_ms (not gpu_ms: llvmpipe
               runs GL work asynchronously, so a pass's GPU timer also spans later passes' CPU work). Every
               other pass seen in the records gets coef + coef * pixels, and the frame's overhead
               (render_ms - the passes' cost) likewise.
  front        per technique, the error records sorted by the model's cost at the error size (ties: the
               most accurate first), keeping the points that lower the RMSE (the Pareto front).
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
SCENE_COUNTS = ("particles", "beams", "specular_objects")  # api::SceneCounts
ERROR_SIZE = 64
TRUTH_SPP = 1024

# The particle-count variants of the media techniques' cost sweeps: explosion's own 159 particles plus a
# request `media` smoke of 480 or 1440 generated particles over the explosion (4x and 10x the particles).
def media_variant(count):
    return {"media": [{"name": "bench_smoke", "kind": "smoke", "tau": 1.0, "seed": 5, "profile": "linear_exact",
                       "generator": {"shape": "sphere", "center": [0, 1.1, 0], "extent": [1.0, 0.7, 1.0],
                                     "count": count, "radius": 0.25, "radius_jitter": 0.3}}]}


MEDIA_VARIANTS = [media_variant(480), media_variant(1440)]

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
        # gather_samples: the gather's block samples (the raster's pixels over the square of the block,
        # stats.scene.counts.photon_gather_block): a default frame of 224 px and more gathers once per
        # 4 x 4 output pixels, k x 4 samples (api::photonGatherStep), where these sweeps (32-128 px, k = 1)
        # gather per 2 x 2; the cost-only points (extra_cost_configs: gather_step 4, supersampling 2) tell
        # that term from the raster's pixels (the upsampling, fix-ups and denoiser run per sample).
        "terms": [[], ["photons"], ["pixels"], ["pixels", "C", "C"], ["gather_samples", "C", "C"]],
        "extra_cost_configs": [{"photons": n, "C": c, "gather_step": s, "supersampling": k}
                               for n in (20000, 250000) for c in (10, 20) for k, s in ((1, 4), (2, 2), (2, 4))],
        # and at 128 px too: a default frame's raster (512 x 512 at 256 px) is far above the sweeps' 64 x 64.
        "extra_cost_sizes": [32, 64, 128],
        "extra_cost_seed": 8000,
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
    # Issue 19 item 6: the other passes a built-in scene plans (caustics and specular on cornell_glass and
    # cornell_mirror, spherical_billboards on explosion) or that a request names (light_volumes,
    # depth_impostors, illumination_network). photon_gi is off in these sweeps: it is not what is timed.
    "caustics": {
        "scene": "cornell_glass",
        "passes": {"photon_gi": False},
        "configs": [{"photon_resolution": p, "cube_resolution": c} for p in (32, 64, 128, 256) for c in (64, 128, 256, 512)],
        # caustic photons traced on the GPU (P^2 texels per light face, per generator: every specular object),
        # the distance cube (6 C^2), splats. The generators (api::SceneCounts "specular_objects") are varied by
        # bench/glass_metal_field.py's fields of 4 and 12 spheres (cornell_glass has 1).
        "terms": [[], ["pixels"], ["specular_objects"], ["specular_objects", "photon_resolution", "photon_resolution"],
                  ["cube_resolution", "cube_resolution"]],
        "variants": [{"field": 4}, {"field": 12}],
        "variant_configs": [{"photon_resolution": p, "cube_resolution": 128} for p in (32, 64, 128)],
        "variant_seed": 7200,
        "compare": {"aov": "caustics", "spp": 1024},  # the light tracer's L S+ D E class
        # At 64x64 every configuration scored 0.105-0.108 (the caustic is a few pixels wide: the error is
        # the ground truth's noise and the kernel's bias); at 128x128 photon_resolution buys accuracy.
        "error_size": 128,
        "output_aov": "caustics",
    },
    "specular": {
        "scene": "cornell_glass",
        # photon_gi on, as in a default frame: the maps gather its photons (the maps' indirect light,
        # maps_indirect), which is most of the pass's cost on cornell_glass (at 64 px, 2.2 s of specular
        # against the 0.2 s the table fitted without them predicted), with photon_gi's kernel: at C = 20
        # the pass took 1.5x its time at C = 10 (2026-12-06 budget ladder), so photon_gi's C (the values
        # of its front, 10 and 20) is a variable of the model ("photon_gi.C": another technique's parameter,
        # 0 when photon_gi is not planned; api::PresetTable::predictMs).
        "passes": {"caustics": False, "photon_gi": {}},
        # Not linear_steps: the layered maps are cached by scene, cube_resolution and layers (not the seed), so
        # a point that changes only the search steps reuses the previous point's maps and is not a cold cost.
        "configs": [{"cube_resolution": c, "layers": n, "photon_gi.C": k}
                    for c in (64, 128, 256, 512) for n in (3, 6) for k in (10, 20)],
        # layered distance maps per specular object (6 C^2 texels per layer, each face drawing what it
        # sees, and gathering photon_gi's photons at its diffuse texels), a per-object set-up, then the
        # per-pixel search. The objects (api::SceneCounts) are varied by bench/glass_metal_field.py's fields
        # of 4 and 12 spheres (uploaded by `spec`; cornell_glass has 1); cube_resolution up to 256 and 3
        # layers there (12 objects x 6 layers of 512^2 cube maps is 3 GB).
        "terms": [[], ["pixels"], ["specular_objects"], ["specular_objects", "cube_resolution", "cube_resolution", "layers"],
                  ["specular_objects", "cube_resolution", "cube_resolution", "layers", "photon_gi.C", "photon_gi.C"]],
        "variants": [{"field": 4}, {"field": 12}],
        "variant_configs": [{"cube_resolution": c, "layers": 3, "photon_gi.C": 10} for c in (64, 128, 256)],
        # Cost-only points at larger frames: at 32 and 64 px alone the per-pixel search's term and the
        # constant trade places (one fit put 0.025 ms per pixel: 6.6 s for a 512 x 512 raster that took 1.3 s).
        "extra_cost_configs": [{"cube_resolution": c, "layers": 3, "photon_gi.C": 10} for c in (64, 256)],
        "extra_cost_sizes": [128, 256],
        "extra_cost_seed": 8100,
        "variant_seed": 7000,  # after every other technique's variant seeds, which stay as they were
        "compare": None,
        "no_front": "the reference has no ground truth for the specular AOV (docs/API.md, compare: no path-class "
                    "filter keeps exactly E S+ D L and E S+ L, no per-pixel mask of the specular pixels)",
        "output_aov": "specular",
    },
    "light_volumes": {
        "scene": "cornell_glass",
        "passes": {"photon_gi": False},
        "configs": [{}, {}, {}],  # no cost knob: the beams are the scene's; three seeds per size
        # The beams (api::SceneCounts): 1920 on cornell_glass (960 glass triangles, reflected and refracted),
        # 960 on cornell_mirror (960 mirror triangles), 12 on cornell_glossy (the glossy tall box).
        "variants": [{"scene": {"builtin": "cornell_mirror"}}, {"scene": {"builtin": "cornell_glossy"}}],
        # beam construction, the beam BVH, then per pixel the beams found through it.
        "terms": [[], ["pixels"], ["beams"], ["pixels", "beams"]],
        "compare": None,
        "no_front": "the light_volumes AOV has no ground truth (first-order L S D E + L G D E only; the reference's "
                    "caustics class is L S+ D E) and the technique has no cost knob",
        "output_aov": "light_volumes",
    },
    # No built-in scene plans env_diffuse by default (a request names it); on ao_creases its receivers are
    # found by the default rule. downsample stays at its default: the lights are 6 (C / downsample)^2 texels,
    # a quotient the model's products of parameters cannot express.
    "env_diffuse": {
        "scene": "ao_creases",
        "passes": {"photon_gi": False},
        "configs": [{"cube_resolution": c} for c in (16, 32, 64, 128, 256)],
        # the cube's faces (6 C^2), then per receiver pixel a sum over the downsampled texels.
        "terms": [[], ["pixels"], ["cube_resolution", "cube_resolution"], ["pixels", "cube_resolution", "cube_resolution"]],
        "compare": {"aov": "indirect_diffuse", "spp": 256},  # the reference's indirect, 1 + bounces
        "output_aov": "indirect_diffuse",
    },
    "spherical_billboards": {
        "scene": "explosion",
        "passes": {"photon_gi": False},
        "configs": [{"resolution_ratio": r} for r in (0.125, 0.25, 0.5, 1)],
        "variants": MEDIA_VARIANTS,
        # per-particle sort and upload, then the billboards' fill: particles x their share of the layer's pixels.
        "terms": [[], ["pixels"], ["particles"], ["pixels", "resolution_ratio", "resolution_ratio"],
                  ["pixels", "resolution_ratio", "resolution_ratio", "particles"]],
        "compare": {"aov": "media", "spp": 64},  # single_scatter_unshadowed
        "output_aov": "media",
    },
    "depth_impostors": {
        "scene": "explosion",
        "passes": {"photon_gi": False},
        "configs": [{"slices": k, "slice_resolution": r, "impostor_resolution": 32} for k in (2, 4, 8, 16) for r in (64, 256)]
                   + [{"slices": 8, "slice_resolution": 128, "impostor_resolution": i} for i in (16, 32, 64)],
        "variants": MEDIA_VARIANTS,
        "variant_configs": [{"slices": k, "slice_resolution": r, "impostor_resolution": 32} for k in (2, 16) for r in (64, 256)]
                           + [{"slices": 8, "slice_resolution": 128, "impostor_resolution": i} for i in (16, 64)],
        # impostor atlas (blocks x I^2, the blocks a fixed number of particles each), K slices of R^2 each
        # (the blocks drawn into each), then K lookups per pixel.
        "terms": [[], ["particles", "impostor_resolution", "impostor_resolution"],
                  ["slices", "slice_resolution", "slice_resolution"], ["particles", "slices"], ["pixels", "slices"]],
        "compare": {"aov": "media", "spp": 16},  # single_scatter (shadowed): 64 spp took 174 s at 64x64 here
        "output_aov": "media",
    },
    "illumination_network": {
        "scene": "explosion",
        "passes": {"photon_gi": False},
        # A cold frame: the network (nodes, directions, visibility) is cached by the technique's own seed, not
        # the frame's, so each cost point gets its own (technique_seed), and warm_start is off so that a point
        # iterates from zero radiance rather than from a previous point's converged network (which made
        # "4 iterations" as accurate as 8 in the 07:01 run). A single frame never has a warm start anyway.
        "fixed": {"warm_start": False},
        "technique_seed": True,
        # A first sweep (nodes 256/1024 x directions 32/128 x iterations 8/32) gave the same RMSE at 8 and 32
        # iterations (warm start converges) and at 32 and 128 directions: the nodes buy the accuracy.
        # sky_single_scatter "network" on every point: "auto" (the default) switches to the exact sky when
        # particles x directions <= 8192 (IlluminationNetwork.cpp, kSkyExactBudget), which costs D x particles
        # chords per march step: 2-7 s instead of 0.2-0.4 s at 64x64 on explosion's 159 particles with 16 or 32
        # directions (the 07:54 run), a switch in the scene's particles that no product of the variables
        # expresses. The front's points name it, so a preset or budget runs what was measured.
        "configs": [{"nodes": n, "directions": d, "iterations": 8, "sky_single_scatter": "network"}
                    for n in (128, 256, 512, 1024, 2048) for d in (16, 32, 64)]
                   + [{"nodes": 1024, "directions": 32, "iterations": i, "sky_single_scatter": "network"} for i in (2, 4)],
        "variants": MEDIA_VARIANTS,
        "variant_configs": [{"nodes": n, "directions": d, "iterations": 8, "sky_single_scatter": "network"}
                            for n in (256, 2048) for d in (16, 64)],
        # links N x D (their opacity: one ray each through the particles), iterated; the marched final render:
        # per pixel and step the nodes' kernel and, per light, the particles.
        "terms": [[], ["pixels"], ["particles"], ["nodes", "directions"], ["nodes", "directions", "particles"],
                  ["nodes", "directions", "iterations"], ["pixels", "particles"], ["pixels", "nodes"]],
        "compare": {"aov": "media", "spp": 16},  # media_mode full
        "output_aov": "media",
    },
}


def selected(only):
    """The techniques a run measures: all of TECHNIQUES, or the --only subset (in TECHNIQUES' order)."""
    if not only:
        return list(TECHNIQUES)
    names = [n.strip() for n in only.split(",") if n.strip()]
    unknown = [n for n in names if n not in TECHNIQUES]
    if unknown:
        raise SystemExit(f"--only: unknown technique(s) {', '.join(unknown)}; known: {', '.join(TECHNIQUES)}")
    return [n for n in TECHNIQUES if n in names]


def base_request(name, t, size, seed):
    passes = dict(t["passes"])
    passes[name] = dict(t.get("fixed", {}))
    # One raster sample per pixel: a request with quality or time_budget_ms and no supersampling of its
    # own runs at 1 (api/Validate.cpp), so the table is measured there (the plain default is 2).
    r = {"scene": {"builtin": t["scene"]}, "width": size, "height": size, "seed": seed, "supersampling": 1,
         "passes": passes, "outputs": [{"format": "exr", "aovs": ["beauty"] + ([t["output_aov"]] if t["output_aov"] != "beauty" else [])}]}
    r.update(t.get("extra", {}))
    return r


def resolve_variant(server, variant):
    """A variant as a request fragment: {"field": N} is bench/glass_metal_field.py's field of N spheres
    (with its point light), uploaded to the daemon and named by its digest."""
    if "field" not in variant:
        return variant
    import glass_metal_field  # noqa: E402  (bench/, on sys.path above)
    gltf = glass_metal_field.field(int(variant["field"])).encode()
    r = call(server, "/v1/scenes", gltf, method="PUT", ctype="model/gltf+json")
    r = json.loads(r) if isinstance(r, bytes) else r
    return {"scene": {"digest": r["digest"]}}


def variant_request(base, variant):
    r = json.loads(json.dumps(base))
    r.update(json.loads(json.dumps(variant)))
    return r


def zip_group(name, points, technique_seed=False):
    """points: list of (config, size, seed) -> one zip group over the dotted paths. technique_seed: the
    technique's own "seed" parameter follows the frame's (its seed-keyed cache is then cold per point)."""
    group = {}
    for config, size, seed in points:
        for k, v in config.items():
            # "photon_gi.C": another technique's parameter (passes.photon_gi.C), a variable of this one's model
            # "supersampling": the request's own (the raster's pixels are k^2 the output's: raster_pixels)
            path = k if k == "supersampling" else f"passes.{k}" if "." in k else f"passes.{name}.{k}"
            group.setdefault(path, []).append(v)
        if technique_seed:
            group.setdefault(f"passes.{name}.seed", []).append(seed)
        group.setdefault("width", []).append(size)
        group.setdefault("height", []).append(size)
        group.setdefault("seed", []).append(seed)
    return group


def make_spec(server, out_dir, names):
    os.makedirs(out_dir, exist_ok=True)
    sweeps = []
    uploaded = {}  # (technique, variant index) -> the variant as sent (a generated scene by its digest)
    techniques = {n: TECHNIQUES[n] for n in names}
    # Shader compilation and scene upload happen once per daemon: one untimed render per technique.
    for name, t in techniques.items():
        sweeps.append({"name": f"presets-warm-{name}", "technique": name, "base": base_request(name, t, 32, 7),
                       "repeats": 1, "warmup": 0})
        for k, v in enumerate(t.get("variants", [])):  # each variant's scene, medium (depth_impostors' blocks)
            uploaded[(name, k)] = resolve_variant(server, v)
            sweeps.append({"name": f"presets-warm-{name}~{k + 1}", "technique": name,
                           "base": variant_request(base_request(name, t, 32, 7), uploaded[(name, k)]),
                           "repeats": 1, "warmup": 0})
    seed = 1000
    for name, t in TECHNIQUES.items():  # every technique's seeds, so that a subset run uses the same ones
        if name not in techniques:
            seed += len(SIZES) * len(t["configs"])
            continue
        points = []
        for size in SIZES:
            for config in t["configs"]:
                points.append((config, size, seed))
                seed += 1
        sweeps.append({"name": f"presets-cost-{name}", "technique": name, "base": base_request(name, t, 32, 0),
                       "zip": [zip_group(name, points, t.get("technique_seed", False))], "repeats": 1,
                       "warmup": t.get("warmup", 0)})
        if t.get("extra_cost_configs"):  # cost-only points (no error sweep: not front candidates), own seeds
            eseed, extra = t["extra_cost_seed"], []
            for size in t.get("extra_cost_sizes", SIZES):
                for config in t["extra_cost_configs"]:
                    extra.append((config, size, eseed))
                    eseed += 1
            sweeps.append({"name": f"presets-cost-{name}~extra", "technique": name,
                           "base": base_request(name, t, 32, 0),
                           "zip": [zip_group(name, extra, t.get("technique_seed", False))], "repeats": 1,
                           "warmup": t.get("warmup", 0)})
    # The scene-count variants: seeds from 5000 on, so that the canonical points keep the seeds of earlier runs.
    vseed = 5000
    for name, t in TECHNIQUES.items():
        own = t.get("variant_seed")  # a technique given its own base leaves the shared counter alone
        oseed = own
        for k, v in enumerate(t.get("variants", [])):
            configs = t.get("variant_configs", t["configs"])
            points = []
            for size in SIZES:
                for config in configs:
                    if own is None:
                        points.append((config, size, vseed))
                        vseed += 1
                    else:
                        points.append((config, size, oseed))
                        oseed += 1
            if name not in techniques:
                continue
            sweeps.append({"name": f"presets-cost-{name}~{k + 1}", "technique": name,
                           "base": variant_request(base_request(name, t, 32, 0), uploaded[(name, k)]),
                           "zip": [zip_group(name, points, t.get("technique_seed", False))], "repeats": 1,
                           "warmup": t.get("warmup", 0)})
    for name, t in techniques.items():
        if t["compare"] is None:
            continue  # no ground truth: a cost model without a front (t["no_front"] says why)
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
        size = t.get("error_size", ERROR_SIZE)
        points = [(config, size, 0) for config in t["configs"]]
        sweeps.append({"name": f"presets-error-{name}", "technique": name,
                       "base": base_request(name, t, size, 0), "zip": [zip_group(name, points)],
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
        if n != "pixels" and n not in params:
            raise SystemExit(f"fit: a cost term names {n!r}, which the record has neither as a parameter nor in "
                             "scene_counts (a results file from a radiant or radiantd older than the scene counts?)")
        v *= pixels if n == "pixels" else float(params[n])
    return v


def raster_pixels(record):
    """The models' "pixels": the raster's, width x height x k^2 at the request's supersampling k (1 in
    every sweep but photon_gi's cost-only points)."""
    k = record["request"].get("supersampling", 1)
    return record["request"]["width"] * record["request"]["height"] * k * k


def with_counts(params, record, terms=()):
    """A record's parameters plus its scene counts (api::SceneCounts, stats.scene.counts), the models' scene
    variables, plus the other techniques' parameters the terms name ("photon_gi.C": the request's
    passes.photon_gi.C; 0 when the request turns that pass off)."""
    p = dict(params)
    p.update(record.get("scene_counts") or {})
    if any("gather_samples" in term for term in terms):  # photon_gi's block samples (api::SceneCounts)
        block = p.get("photon_gather_block")
        if not block:
            raise SystemExit("fit: a photon_gi record without scene_counts.photon_gather_block (a radiantd older "
                             "than the gather-block count?)")
        p["gather_samples"] = raster_pixels(record) / float(block) ** 2
    passes = record["request"]["passes"]
    for n in {n for term in terms for n in term if "." in n}:
        other, key = n.split(".", 1)
        if passes.get(other) is False:
            p[n] = 0.0
        elif isinstance(passes.get(other), dict) and key in passes[other]:
            p[n] = passes[other][key]
        else:
            raise SystemExit(f"fit: a cost term names {n!r}, which the record's request does not set (the sweep "
                             "must set another technique's parameter that a model names)")
    return p


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


def count_checks(t, terms, rows, counted):
    """What the model says against what was measured across the scene counts: per value of the counts, the
    measured cost summed over the records at the largest size of the configurations every variant ran
    (variant_configs: one record each, so a sum rather than one noisy record), and the model's prediction
    of the same sum. tests/unit/api/PresetsTest.cpp compares the two."""
    configs = t.get("variant_configs", t["configs"])
    px = max(SIZES) ** 2
    groups = {}
    for params, pixels, ms in rows:
        if pixels == px and any(all(params.get(k) == v for k, v in c.items()) for c in configs):
            groups.setdefault(tuple(params[n] for n in counted), []).append((params, ms))
    out = []
    for key in sorted(groups):
        recs = groups[key]
        out.append({"pixels": px, "counts": dict(zip(counted, key)), "records": len(recs),
                    "params": [{k: p[k] for k in configs[0]} for p, _ in recs],
                    "measured_ms": sum(ms for _, ms in recs),
                    "predicted_ms": sum(predict(terms, p, px) for p, _ in recs)})
    return out


def predict(terms, params, pixels):
    return sum(t["coef"] * term_value(t["vars"], params, pixels) for t in terms)


def fit(records, command, runs=()):
    ok = [r for r in records if "error" not in r and r.get("passes")]
    device = next((r.get("device") for r in ok if r.get("device")), {})
    table = {"generated": {
        "by": "bench/presets.py fit (never edit this file by hand; regenerate it on the machine it is for)",
        "command": command, "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "device": device,
        "sizes": SIZES, "error_size": ERROR_SIZE,
        "note": "cost = api::passCostMs of a cold first render (own seed); error = RMSE against the reference at "
                "error_size on the technique's canonical built-in scene; a model's scene variables (particles, beams, specular_objects: "
                "api::SceneCounts) were varied by its sweep's variants (model.scene_counts: the values measured); "
                "other scene properties (triangles, a caustics generator's size) are constants of the model",
        "runs": list(runs)}, "techniques": {}}
    cost = [r for r in ok if r["sweep"].startswith("presets-cost-")]
    other_rows, overhead_rows = {}, []
    for r in cost:
        px = raster_pixels(r)
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
            params = with_counts(r["request"]["passes"][name], r, t["terms"])
            rows.append((params, raster_pixels(r), pass_cost(p)))
        if not rows:
            continue
        terms, resid, dropped = fit_terms(t["terms"], rows)
        entry = {"model": {"terms": terms, "rms_residual_ms": resid, "records": len(rows), "outliers_dropped": dropped,
                           "scene": t["scene"]}}
        counted = sorted({n for term in t["terms"] for n in term if n in SCENE_COUNTS})
        if counted:  # the scene counts the records spanned
            entry["model"]["scene_counts"] = {n: sorted({q[0][n] for q in rows}) for n in counted}
            entry["model"]["count_checks"] = count_checks(t, terms, rows, counted)
        errs = [r for r in ok if r["sweep"] == f"presets-error-{name}" and r.get("metrics")]
        pts = []
        for r in errs:
            params = {k: r["request"]["passes"][name][k] for k in t["configs"][0]}
            px = raster_pixels(r)
            pts.append({"params": params, "error": r["metrics"]["rmse"],
                        "predicted_ms": predict(terms, with_counts(params, r, t["terms"]), px)})
        pts.sort(key=lambda q: (q["predicted_ms"], q["error"]))  # of equal cost, only the most accurate stays
        front = []
        for q in pts:
            if not front or q["error"] < front[-1]["error"]:
                front.append(q)
        if front:
            entry["error"] = {"metric": "rmse", "aov": t["compare"]["aov"], "scene": t["scene"],
                              "width": t.get("error_size", ERROR_SIZE), "height": t.get("error_size", ERROR_SIZE),
                              "seed": 0,
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
        elif t.get("no_front"):
            entry["no_front"] = t["no_front"]
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
    """The records of the results files, later files first in authority: a technique measured in a later
    file keeps only that file's records (a re-measured technique's sweep may have other points, so its
    earlier points must not mix in), and within one file the last record of a point wins."""
    per_file = []
    for p in paths:
        recs = {}
        with open(p) as f:
            for line in f:
                line = line.strip()
                if line:
                    try:
                        r = json.loads(line)
                    except json.JSONDecodeError:
                        continue
                    recs[r.get("point_id", id(r))] = r
        per_file.append(list(recs.values()))
    owner = {}  # technique -> index of the last file that measured it
    for i, recs in enumerate(per_file):
        for r in recs:
            owner[r.get("technique")] = i
    return [r for i, recs in enumerate(per_file) for r in recs if owner[r.get("technique")] == i]


def write_table(table, path):
    with open(path, "w") as f:
        json.dump(table, f, indent=1, sort_keys=True)
        f.write("\n")
    print(f"wrote {path}", file=sys.stderr)


def fmt_model(terms):
    out = []
    for t in terms:
        c = f"{t['coef']:.4g}"
        out.append(" * ".join([c] + t["vars"]) if t["vars"] else c)
    return " + ".join(out) or "0"


def markdown(table):
    """docs/PERFORMANCE.md's tables of a preset table: the cost models, then the fronts with preset names."""
    g = table["generated"]
    lines = [f"Table generated {g['date']} on `{g.get('device', {}).get('renderer', '?')}` "
             f"({g.get('device', {}).get('version', '?')}); command `{g['command']}`."]
    for run in g.get("runs", []):
        lines.append(f"Sweep run {run['started']}: {', '.join(run['techniques'])}; {run['seconds']} s; load average "
                     f"(1, 5, 15 min) {run['load_average_before']} before, {run['load_average_after']} after.")
    lines += ["", "| technique | scene | model (ms) | RMS residual ms | records (outliers dropped) |", "|---|---|---|---|---|"]
    for name, e in sorted(table["techniques"].items()):
        m = e["model"]
        scene = m.get('scene', 'any (other passes of the sweeps)')
        for n, vals in m.get("scene_counts", {}).items():
            scene += f" ({n} {', '.join(f'{v:g}' for v in vals)})"
        lines.append(f"| {name} | {scene} | {fmt_model(m['terms'])} | "
                     f"{m['rms_residual_ms']:.3g} | {m['records']} ({m['outliers_dropped']}) |")
    o = table["overhead"]
    lines.append(f"| frame overhead (render_ms - passes) | all | {fmt_model(o['terms'])} | {o['rms_residual_ms']:.3g} | "
                 f"{o['records']} ({o['outliers_dropped']}) |")
    lines += ["", "| technique (scene, AOV, against) | configuration | predicted ms | RMSE | preset |", "|---|---|---|---|---|"]
    for name, e in sorted(table["techniques"].items()):
        if "front" not in e:
            continue
        err = e["error"]
        against = f"reference {err['spp']} spp" if "spp" in err else "uploaded truth"
        for i, q in enumerate(e["front"]):
            names = ", ".join(k for k in ("draft", "preview", "final", "reference") if e["presets"][k] == i)
            lines.append(f"| {name} ({err['scene']}, {err['aov']}, {against}) | {json.dumps(q['params'], sort_keys=True)} | "
                         f"{q['predicted_ms']:.0f} | {q['error']:.4f} | {names} |")
    no_front = [(n, e["no_front"]) for n, e in sorted(table["techniques"].items()) if "no_front" in e]
    if no_front:
        lines += ["", "Cost model without a front:"] + [f"- {n}: {why}" for n, why in no_front]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("command", choices=["all", "spec", "fit", "markdown"])
    ap.add_argument("results", nargs="*")
    ap.add_argument("--server", default=os.environ.get("RADIANT_SERVER", "http://127.0.0.1:8080"))
    ap.add_argument("--radiant", default="build/client/radiant")
    ap.add_argument("--dir", default="bench-presets")
    ap.add_argument("-o", "--output", default="api/presets.json")
    ap.add_argument("--command-text", default=None, help="recorded as generated.command")
    ap.add_argument("--only", default=None,
                    help="all/spec: measure only these techniques (comma-separated); fit the table from this run's "
                         "results together with earlier runs' results files (see RUNS IN PARTS in the docstring)")
    a = ap.parse_intermixed_args()  # results files may follow the options
    command = a.command_text or "bench/presets.py " + " ".join(sys.argv[1:])
    if a.command == "markdown":  # the docs' tables of a table: bench/presets.py markdown [api/presets.json]
        with open(a.results[0] if a.results else a.output) as f:
            print(markdown(json.load(f)))
        return
    if a.command in ("all", "spec"):
        names = selected(a.only)
        t0 = time.time()
        load0 = os.getloadavg()
        spec = make_spec(a.server, a.dir, names)
        print(f"wrote {spec}", file=sys.stderr)
        if a.command == "spec":
            return
        results = os.path.join(a.dir, "results.jsonl")
        subprocess.run([a.radiant, "sweep", spec, "-o", results, "--server", a.server, "--quiet"], check=False)
        run = {"techniques": names, "started": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime(t0)),
               "seconds": round(time.time() - t0, 1), "load_average_before": [round(x, 2) for x in load0],
               "load_average_after": [round(x, 2) for x in os.getloadavg()], "results": "results.jsonl"}
        with open(os.path.join(a.dir, "run.json"), "w") as f:
            json.dump(run, f, indent=1)
        print(f"sweep run: {run['seconds']} s, load average {run['load_average_before']} -> "
              f"{run['load_average_after']}", file=sys.stderr)
        a.results = a.results + [results]  # the newest run last: its points replace earlier ones (read_jsonl)
    if not a.results:
        ap.error("fit needs the results files")
    runs = []
    for path in a.results:  # the run.json `all` wrote next to each results file, when there is one
        info = os.path.join(os.path.dirname(os.path.abspath(path)), "run.json")
        if os.path.exists(info):
            with open(info) as f:
                runs.append(json.load(f))
    write_table(fit(read_jsonl(a.results), command, runs), a.output)


if __name__ == "__main__":
    main()
