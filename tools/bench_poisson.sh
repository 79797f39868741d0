#!/usr/bin/env bash
# vitri against Open3D's screened Poisson reconstruction (issue 12, docs/benchmarks.md "Against Poisson
# (Open3D)"). Installs the Debian packages the comparison needs (python3-open3d, python3-numpy,
# python3-scipy: bench only, never the CI test path), builds the vitri CLI in Release (build-rel/), and runs
# bench/compare/poisson/compare.py with the system python (/usr/bin/python3, where Debian's packages are).
# Usage: bash tools/bench_poisson.sh [--quick] [compare.py options]  (the full sweep takes about an hour
# on 2 cores; --quick: 10^4 and 10^5 points only). Results: bench/compare/results/poisson.{md,csv}.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/deps.sh cmake ninja-build g++ libeigen3-dev libstb-dev liblzf-dev time python3 python3-open3d python3-numpy \
  python3-scipy
cmake -S . -B build-rel -G Ninja -DCMAKE_BUILD_TYPE=Release -DVITRI_BUILD_TESTS=OFF -DVITRI_BUILD_BENCH=OFF
cmake --build build-rel --target vitri_cli -j"$(nproc 2>/dev/null || echo 2)"
lscpu | grep 'Model name' || true
/usr/bin/python3 bench/compare/poisson/compare.py --vitri build-rel/apps/vitri "$@"
