#!/usr/bin/env bash
# Builds vitri with AddressSanitizer + UndefinedBehaviorSanitizer and runs the whole test suite.
# Usage: bash tools/test.sh   (build tree: build-test/)
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/deps.sh cmake make g++ libeigen3-dev catch2 libstb-dev pkg-config libcpp-httplib-dev libjs-three \
                   chromium chromium-driver python3-selenium liblzf-dev \
                   pybind11-dev python3-dev python3-numpy python3-pytest python3-open3d \
                   python3-distributed  # python/ (docs/python.md); Dask for the blocks (docs/blocks.md)
jobs=$(nproc 2>/dev/null || echo 2)
# -g1: line tables only (the sanitizers' stack traces keep file:line): 2.5 GB of build tree instead of
# 5.8 GB with full debug information (a CI machine ran out of disk space linking the tests).
cmake -S . -B build-test -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
      -DVITRI_SANITIZE=address,undefined \
      -DVITRI_BUILD_BENCH=OFF -DVITRI_WERROR=ON -DVITRI_BUILD_PYTHON=ON -DPython_EXECUTABLE=/usr/bin/python3
cmake --build build-test -j"$jobs"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --test-dir build-test --output-on-failure -j"$jobs"
