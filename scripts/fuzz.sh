#!/usr/bin/env bash
# Builds the libFuzzer harnesses (tests/fuzz/) with clang, ASan and UBSan in their own build dir and runs
# each for FUZZ_SECONDS (default 60), seeded with tests/data/crashers. scripts/test.sh (so CI) builds them
# with --build-only and registers one CTest test per harness that runs it with --no-build.
# Usage: scripts/fuzz.sh [--build-only|--no-build] [request|gltf|http|draco|image ...]
#        Build dir: $RADIANT_FUZZ_BUILD_DIR (default build-fuzz/)
# A crash is written to <build>/artifacts/<harness>/; copy it into tests/data/crashers/<corpus>/ so the
# normal suite keeps it as a regression test (tests/unit/scene/CrashersTest.cpp, tests/http/hostile).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${RADIANT_FUZZ_BUILD_DIR:-build-fuzz}
seconds=${FUZZ_SECONDS:-60}
mode=all
case ${1:-} in --build-only) mode=build; shift ;; --no-build) mode=run; shift ;; esac
harnesses=("$@")
[ ${#harnesses[@]} -eq 0 ] && harnesses=(request gltf http draco image)
if [ $mode != run ]; then
  CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRADIANT_FUZZ=ON \
    -DRADIANT_BUILD_TESTS=OFF -DRADIANT_BUILD_BENCH=OFF
  targets=()
  for h in "${harnesses[@]}"; do targets+=("${h}_fuzzer"); done
  cmake --build "$build" -j"$(nproc)" --target "${targets[@]}"
fi
[ $mode = build ] && exit 0
status=0
for h in "${harnesses[@]}"; do
  case $h in request) seeds=requests ;; gltf) seeds=gltf ;; http) seeds=http ;; draco) seeds=draco ;; image) seeds=images ;;
    *) echo "unknown harness $h"; exit 2 ;; esac
  corpus=$build/corpus/$h
  artifacts=$build/artifacts/$h/
  mkdir -p "$corpus" "$artifacts"
  cp -n tests/data/crashers/$seeds/* "$corpus"/ 2>/dev/null || true
  echo "fuzz: $h for ${seconds}s"
  # -rss_limit_mb: the decode budgets keep a correct build far below it. -timeout: an input that runs
  # 25 s is a hang (a GLB whose HDR texture looped stb_image for good went unreported at the default 1200 s).
  # The http harness's server logs one JSON line per request to stderr: filtered out here.
  # tests/fuzz/lsan.supp: leaks inside third-party libraries (each one explained there).
  if ! LSAN_OPTIONS="suppressions=$(pwd)/tests/fuzz/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}" \
        "$build/tests/fuzz/${h}_fuzzer" "$corpus" -max_total_time="$seconds" -timeout=25 -rss_limit_mb=2048 -max_len=262144 \
        -artifact_prefix="$artifacts" -print_final_stats=1 2> >(grep -v '^{"duration_ms' >&2); then
    echo "fuzz: $h FOUND A CRASH (see $artifacts)"
    status=1
  fi
done
exit $status
