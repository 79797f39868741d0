#!/usr/bin/env bash
# Builds vitri (Release) and meshes the bundled hand model at three levels of detail.
# Usage: bash tools/example.sh   (meshes written to out/hand-0.obj, out/hand-1.obj, out/hand-2.obj)
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/deps.sh cmake make g++ libeigen3-dev catch2 libstb-dev pkg-config libcpp-httplib-dev libjs-three
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DVITRI_BUILD_TESTS=OFF -DVITRI_BUILD_BENCH=OFF
cmake --build build-release -j"$jobs" --target vitri_cli
mkdir -p out
./build-release/apps/vitri mesh data/hand.off -o out/hand.obj --precision 0.04 --precision 0.02 --precision 0.01
echo "meshes written: $(ls out/hand-*.obj | tr '\n' ' ')"
