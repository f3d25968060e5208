#!/usr/bin/env bash
# The GPU check (issue 31): one short script for a machine with a GPU, in under 8 minutes. It builds
# Radiant (no fuzz build), checks that the daemon's GL context is a hardware one on the EGL device
# platform, runs the gl and http test tiers, then the standard frames at 1920x1080 (every built-in
# scene and sample model, default request: the passes the planner picks, warm daemon, 3 timed frames
# each), and writes one Markdown summary with the GL renderer string (and gpu-check-stats.tgz beside
# it: every frame's stats JSON). Nothing here assumes a GPU vendor; on llvmpipe it runs too (and says
# so), which is how it is tested.
#
# Usage: scripts/gpu-check.sh [--bundle FILE] [SUMMARY.md]   (summary default: $OUT/gpu-check.md if
#                                                 $OUT is set, else gpu-check.md)
#   --bundle FILE      run what scripts/gpu-bundle.py packed on another machine instead of building here
#                      (for a GPU machine without Radiant's Debian packages): unpacks it beside FILE,
#                      makes the paths the build tree was made at point here, and puts its libraries
#                      first on LD_LIBRARY_PATH, then the NVIDIA driver's folder if there is one, and
#                      the programs it packed (gnuplot) first on PATH
#   RADIANT_BUILD_DIR  build directory (default build-gpu)
#   GPU_CHECK_TIERS    ctest labels to run (default "gl http"; "" skips the tests)
#   GPU_CHECK_SIZE     frame size of the standard frames (default 1920x1080)
#   GPU_CHECK_FRAMES   timed frames per scene (default 3)
#   GPU_CHECK_TEST_TIMEOUT  seconds per test (default 300)
#   GPU_CHECK_TESTDATA the folder of gltf-samples/ and environments/ (default ../shared/testdata)
# The figures go into docs/PERFORMANCE.md ("GPU check") by hand, with the renderer string and date.
set -uo pipefail
cd "$(dirname "$0")/.."
bundle=""
if [ "${1:-}" = --bundle ]; then bundle=$2; shift 2; fi
summary=${1:-${OUT:+$OUT/gpu-check.md}}
summary=${summary:-gpu-check.md}
build=${RADIANT_BUILD_DIR:-build-gpu}
tiers=${GPU_CHECK_TIERS-gl http}
size=${GPU_CHECK_SIZE:-1920x1080}
frames=${GPU_CHECK_FRAMES:-3}
work=$(mktemp -d)
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$work}
start=$(date +%s)
status=0
note() { echo "$*" | tee -a "$work/notes.md"; }

# Build: no apt here (a GPU machine may have no network); the packages must be installed already,
# or the build comes packed (--bundle).
t0=$(date +%s)
if [ -n "$bundle" ]; then
  dir=$(cd "$(dirname "$bundle")" && pwd)/unpacked
  rm -rf "$dir" && mkdir -p "$dir" && tar -xJf "$bundle" -C "$dir" || { echo "gpu-check: cannot unpack $bundle" >&2; exit 1; }
  read -r root made shared < <(python3 -c 'import json,sys; p=json.load(open(sys.argv[1])); print(p["root"], p["build"], p["shared"])' "$dir/paths.json")
  # The executables and CTest files name the checkout, build tree and test data by the paths they had.
  if ! [ "$root" -ef . ]; then
    [ -e "$root" ] && { echo "gpu-check: $root exists and is not this checkout" >&2; exit 1; }
    mkdir -p "$(dirname "$root")" && ln -s "$PWD" "$root"
  fi
  if ! [ "$made" -ef "$dir/build" ]; then
    [ -e "$made" ] && ! [ -L "$made" ] && { echo "gpu-check: $made exists" >&2; exit 1; }
    rm -f "$made" && ln -s "$dir/build" "$made"
  fi
  if ! [ "$shared/testdata" -ef "$dir/shared/testdata" ]; then
    [ -e "$shared" ] && { echo "gpu-check: $shared exists" >&2; exit 1; }
    mkdir -p "$(dirname "$shared")" && ln -s "$dir/shared" "$shared"
  fi
  nv=""
  for d in /usr/local/nvidia/lib64 /usr/local/nvidia/lib; do [ -d "$d" ] && nv="$nv:$d"; done
  export LD_LIBRARY_PATH="$dir/lib$nv${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" PATH="$dir/bin:$PATH"
  egl=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
  [ -z "${__EGL_VENDOR_LIBRARY_FILENAMES:-}" ] && [ -f "$egl" ] && export __EGL_VENDOR_LIBRARY_FILENAMES=$egl
  build=$made
  note "- prebuilt: $(basename "$bundle") ($(du -m "$bundle" | cut -f1) MiB), build tree $made"
elif ! cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRADIANT_FUZZ_SECONDS=0 >"$work/cmake.log" 2>&1 ||
   ! cmake --build "$build" -j"$(nproc)" >"$work/build.log" 2>&1; then
  tail -40 "$work/cmake.log" "$work/build.log"
  echo "gpu-check: the build failed (packages missing? scripts/setup.sh installs them)" >&2
  exit 1
fi
build_s=$(( $(date +%s) - t0 ))

# The daemon, on a loopback port; its /v1/info names the device.
"$build"/server/radiantd --port 0 --cache-dir "$work/cache" >"$work/radiantd.stdout" 2>"$work/radiantd.log" &
pid=$!
trap 'kill -TERM $pid 2>/dev/null; wait $pid 2>/dev/null; rm -rf "$work"' EXIT
url=""
for _ in $(seq 1 300); do
  url=$(grep -o 'http://127.0.0.1:[0-9]*' "$work/radiantd.stdout" 2>/dev/null | head -n1 || true)
  [ -n "$url" ] && break
  sleep 0.1
done
[ -n "$url" ] || { tail -20 "$work/radiantd.log"; echo "gpu-check: radiantd did not start" >&2; exit 1; }
export RADIANT_SERVER=$url
# The GL context is made after the port line: wait (up to 60 s) until /v1/info names the device.
for _ in $(seq 1 600); do
  "$build"/client/radiant info --json >"$work/info.json" 2>/dev/null &&
    python3 -c 'import json,sys; sys.exit(json.load(open(sys.argv[1]))["device"] is None)' "$work/info.json" && break
  sleep 0.1
done
device=$(python3 -c 'import json,sys; d=json.load(open(sys.argv[1]))["device"]; print(json.dumps(d))' "$work/info.json")
renderer=$(python3 -c 'import json,sys; d=json.load(open(sys.argv[1]))["device"]; print(d.get("renderer","?"), "|", d.get("version","?"), "|", d.get("platform","?"), "| software" if d.get("software") else "| hardware")' "$work/info.json")

# Test tiers (each test starts its own daemons).
declare -A tier_line
for label in $tiers; do
  t0=$(date +%s)
  ctest --test-dir "$build" -L "$label" -j"$(nproc)" --output-on-failure --timeout "${GPU_CHECK_TEST_TIMEOUT:-300}" >"$work/ctest-$label.log" 2>&1 || status=1
  tier_line[$label]="$(grep -E 'tests passed|tests failed' "$work/ctest-$label.log" | tail -1) ($(( $(date +%s) - t0 )) s)"
  grep -E '^\s+[0-9]+ - ' "$work/ctest-$label.log" >>"$work/failed.txt" || true
done

# The standard frames: default request of every built-in scene at $size, one warm-up (shaders, upload),
# then $frames timed frames with fresh seeds; per pass the median of the timed frames' GPU ms.
scenes=$("$build"/client/radiant scenes | awk '/^built-in:/ {b=1; next} /^[a-z]/ {b=0} b && NF {print $1}' | tr '\n' ' ')
[ -n "$scenes" ] || { echo "gpu-check: radiant scenes listed no built-in scene" >&2; exit 1; }
for s in $scenes; do
  for i in $(seq 0 "$frames"); do
    "$build"/client/radiant render --builtin "$s" --size "$size" --seed $((1000 + i)) -o "$work/$s.png" \
      --stats "$work/$s.$i.stats.json" --quiet >>"$work/render.log" 2>&1 || { status=1; note "- $s frame $i failed: $(tail -1 "$work/render.log")"; }
  done
done
# The sample models (../shared/testdata/gltf-samples, the Khronos layout: glTF-Binary/*.glb, else
# glTF/*.gltf) under the first environment map there, the same way; each render bounded to 120 s.
testdata=${GPU_CHECK_TESTDATA:-${shared:-$(cd .. && pwd)/shared}/testdata}
envmap=$(ls "$testdata"/environments/*.hdr 2>/dev/null | head -n1)
models=""
for d in "$testdata"/gltf-samples/*/; do
  [ -n "$envmap" ] || break
  f=$(ls "$d"glTF-Binary/*.glb 2>/dev/null | head -n1)
  [ -n "$f" ] || f=$(ls "$d"glTF/*.gltf 2>/dev/null | head -n1)
  [ -n "$f" ] || continue
  m=$(basename "$d")
  models="$models $m"
  for i in $(seq 0 "$frames"); do
    timeout 120 "$build"/client/radiant render "$f" --environment "$envmap" --size "$size" --seed $((1000 + i)) \
      -o "$work/$m.png" --stats "$work/$m.$i.stats.json" --quiet >>"$work/render.log" 2>&1 ||
      { status=1; note "- $m frame $i failed: $(tail -1 "$work/render.log")"; break; }
  done
done
frames_table=$(python3 - "$work" "$frames" $scenes $models <<'EOF'
import json, os, statistics, sys
work, frames, scenes = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
rows = ["| scene | render ms (median) | passes: GPU ms / CPU ms (median) | readback / encode ms | skipped |",
        "|---|---|---|---|---|"]
for s in scenes:
    st = []
    for i in range(1, frames + 1):
        p = os.path.join(work, f"{s}.{i}.stats.json")
        if os.path.exists(p):
            st.append(json.load(open(p))["stats"])
    if not st:
        rows.append(f"| {s} | failed | | | |"); continue
    def med(f):
        v = [f(x) for x in st if f(x) is not None]
        return statistics.median(v) if v else float("nan")
    passes = {}
    for x in st:
        for p in x.get("passes", []):
            passes.setdefault(p["name"], []).append((p.get("gpu_ms", 0.0), p.get("cpu_ms", 0.0)))
    ptxt = ", ".join(f"{n} {statistics.median(g for g, _ in v):.1f} / {statistics.median(c for _, c in v):.1f}"
                     for n, v in passes.items())
    skipped = ", ".join(sorted(st[-1].get("skipped", {}).keys()))
    io = f"{med(lambda x: x.get('readback_ms')):.1f} / {med(lambda x: x.get('encode_ms')):.1f}"
    rows.append(f"| {s} | {med(lambda x: x.get('render_ms')):.1f} | {ptxt} | {io} | {skipped} |")
print("\n".join(rows))
EOF
)

mkdir -p "$(dirname "$summary")"
{
  echo "# GPU check, $(date -u '+%Y-%m-%d %H:%M UTC')"
  echo
  echo "- commit: $(git rev-parse --short HEAD 2>/dev/null || echo '?')$(git diff --quiet 2>/dev/null || echo ' (modified)')"
  echo "- GL: $renderer"
  echo "- device: \`$device\`"
  echo "- host: $(nproc) CPUs, $(awk '/MemTotal/ {printf "%.0f GiB", $2/1048576}' /proc/meminfo); build ${build_s} s"
  for label in $tiers; do echo "- ctest -L $label: ${tier_line[$label]}"; done
  if [ -s "$work/failed.txt" ]; then echo; echo "Failed tests:"; echo; sed 's/^/    /' "$work/failed.txt"; fi
  echo
  echo "Standard frames, default request, $size, median of $frames warm frames (\`stats\`); the sample"
  echo "models under $(basename "${envmap:-none}"):"
  echo
  echo "$frames_table"
  [ -s "$work/notes.md" ] && { echo; cat "$work/notes.md"; }
  echo
  echo "Total $(( $(date +%s) - start )) s; status $status."
} >"$summary"
for label in $tiers; do cp "$work/ctest-$label.log" "$(dirname "$summary")/" 2>/dev/null || true; done
tar -C "$work" -czf "$(dirname "$summary")/gpu-check-stats.tgz" $(cd "$work" && ls *.stats.json 2>/dev/null) 2>/dev/null || true
cat "$summary"
exit $status
