#!/usr/bin/env bash
# Installs what the vitri command needs and builds it (Release, with the studio): build-release/apps/vitri.
# Used by tools/example.sh and tools/studio.sh. Usage: bash tools/build_release.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/deps.sh cmake make g++ libeigen3-dev catch2 libstb-dev pkg-config libcpp-httplib-dev libjs-three \
                   liblzf-dev
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DVITRI_BUILD_TESTS=OFF -DVITRI_BUILD_BENCH=OFF
cmake --build build-release -j"$jobs" --target vitri_cli
