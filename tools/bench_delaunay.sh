#!/usr/bin/env bash
# Delaunay benchmarks: vitri against CGAL (same process) and TetGen (its command line, same points).
# Usage: bash tools/bench_delaunay.sh [bench_delaunay arguments, e.g. --benchmark_filter='bulk|grid/100']
# Installs what is missing, builds Release in build-bench/, runs bench_delaunay (results: docs/benchmarks.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/deps.sh cmake make g++ libeigen3-dev libbenchmark-dev libcgal-dev tetgen liblzf-dev
cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release -DVITRI_BUILD_BENCH=ON -DVITRI_BUILD_TESTS=OFF
cmake --build build-bench --target bench_delaunay -j"$(nproc 2>/dev/null || echo 2)"
lscpu | grep 'Model name' || true
./build-bench/bench/delaunay/bench_delaunay "$@"
