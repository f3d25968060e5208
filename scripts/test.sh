#!/usr/bin/env bash
# Builds Radiant and runs every test (unit, GL on the EGL device, HTTP against the real daemon).
# Usage: scripts/test.sh [extra ctest args]      Build dir: $RADIANT_BUILD_DIR (default build/)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
build=${RADIANT_BUILD_DIR:-build}
jobs=$(nproc)
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build "$build" -j"$jobs"
# Mesa prints harmless XDG_RUNTIME_DIR warnings without a session; give it a private runtime dir.
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$(mktemp -d)}
ctest --test-dir "$build" --output-on-failure -j"$jobs" "$@"
