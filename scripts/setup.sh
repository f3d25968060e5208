#!/usr/bin/env bash
# Installs every Debian package Radiant needs to build, test and run. Idempotent:
# packages already present are skipped, and apt-get update runs only when something is missing.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libepoxy-dev libglm-dev libtinygltf-dev libstb-dev libcpp-httplib-dev nlohmann-json3-dev
  libopenimageio-dev openimageio-tools libwebp-dev libembree-dev libtbb-dev libdraco-dev libmeshoptimizer-dev
  libegl-dev libegl-mesa0 libgl1-mesa-dri libgbm1 mesa-utils
  libgtest-dev libgmock-dev googletest libbenchmark-dev
  clang libclang-rt-14-dev  # the libFuzzer harnesses (scripts/fuzz.sh); the runtime is only recommended by clang
  curl gnuplot-nox
  libcli11-dev  # the radiant CLI's argument parsing, --help and shell completion (client/Cli.*)
  bsdutils      # `script`: tests/http/client runs radiant render on a pseudo-terminal
  nginx-light   # the reverse proxy in front of several daemons (deploy/nginx, tests/http/fleet)
  python3-yaml  # tests/unit/deploy parses the Kubernetes manifests
  chromium      # tests/http/viewer drives the viewer page (/ui/) in headless Chromium over DevTools
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "setup: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "setup: done"
