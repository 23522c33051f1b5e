#!/usr/bin/env bash
# README command 1: installs the Debian packages, builds patchcull (Release) and runs the main
# job on the built-in default scene.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
./build/patchcull "$@"
