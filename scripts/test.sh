#!/usr/bin/env bash
# Builds Radiant and runs every test (unit, GL on the EGL device, HTTP against the real daemon, and a
# short libFuzzer run of each harness from an instrumented clang build: scripts/fuzz.sh).
# Usage: scripts/test.sh [extra ctest args]      Build dir: $RADIANT_BUILD_DIR (default build/)
#        RADIANT_FUZZ_SECONDS=N per harness (default 60); 0 skips the fuzz build and runs.
set -euo pipefail
cd "$(dirname "$0")/.."
# Each phase's wall time goes to the log (CI's time is mostly the two builds: keep it lean).
phase_start=$SECONDS
phase() { echo "test.sh: $1 took $((SECONDS - phase_start)) s"; phase_start=$SECONDS; }
bash scripts/setup.sh
phase "set-up"
build=${RADIANT_BUILD_DIR:-build}
jobs=$(nproc)
fuzz_seconds=${RADIANT_FUZZ_SECONDS:-60}
fuzz_dir=""
if [ "$fuzz_seconds" != 0 ]; then
  fuzz_dir=$(pwd)/${RADIANT_FUZZ_BUILD_DIR:-build-fuzz}
  RADIANT_FUZZ_BUILD_DIR=$fuzz_dir bash scripts/fuzz.sh --build-only
  phase "the fuzz build"
fi
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRADIANT_FUZZ_BUILD_DIR="$fuzz_dir" \
  -DRADIANT_FUZZ_SECONDS="$fuzz_seconds"
cmake --build "$build" -j"$jobs"
phase "the build"
# Mesa prints harmless XDG_RUNTIME_DIR warnings without a session; give it a private runtime dir.
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$(mktemp -d)}
ctest --test-dir "$build" --output-on-failure -j"$jobs" "$@"
