#!/usr/bin/env bash
# The main job: builds Radiant, starts radiantd on a loopback port, renders the built-in Cornell box
# through the radiant client with full GI into out/ (EXR with AOVs, tone-mapped PNG, stats JSON with the
# error against the reference path tracer), then stops it.
# Usage: scripts/run.sh [builtin-scene-name]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
build=${RADIANT_BUILD_DIR:-build}
scene=${1:-cornell_box}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$build" -j"$(nproc)" --target radiantd radiant
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$(mktemp -d)}
mkdir -p out
log=out/radiantd.log
"$build"/server/radiantd --port 0 --cache-dir out/cache >out/radiantd.stdout 2>"$log" &
pid=$!
trap 'kill -TERM $pid 2>/dev/null; wait $pid 2>/dev/null || true' EXIT
for _ in $(seq 1 200); do
  url=$(grep -o 'http://127.0.0.1:[0-9]*' out/radiantd.stdout 2>/dev/null | head -n1 || true)
  [ -n "$url" ] && break
  sleep 0.1
done
[ -n "$url" ] || { echo "radiantd did not start; see $log"; exit 1; }
export RADIANT_SERVER=$url
# Full GI (direct + photon_gi, + specular where the scene needs it), scored against the reference path
# tracer at 256 samples per pixel: the error goes into the stats (stats.metrics).
"$build"/client/radiant render --builtin "$scene" -o "out/$scene.png" --stats "out/$scene.stats.json" --compare 256
"$build"/client/radiant render --builtin "$scene" -o "out/$scene.exr" --aov beauty --aov direct --aov indirect --aov albedo --aov normal --aov depth
echo "wrote out/$scene.png, out/$scene.exr and out/$scene.stats.json (daemon log: $log)"
