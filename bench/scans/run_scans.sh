#!/usr/bin/env bash
# vitri against Poisson (Open3D, CGAL) on simulated scans with a known truth and on the shared real scans
# (bench/scans/README.md). Installs what is missing (Debian packages, bench only), builds the scan tools in
# BUILD (default build-scans, Release), then runs bench/scans/run_scans.py with Debian's python.
# Usage: [VITRI=path/to/vitri] [BUILD=build-scans] bash bench/scans/run_scans.sh [run_scans.py options]
#   VITRI: the CLI under test (default build-release/apps/vitri; built here in BUILD when VITRI=build).
# Examples:
#   bash bench/scans/run_scans.sh                                  # everything, 10^5 points (hours)
#   bash bench/scans/run_scans.sh --points 30000 --models bunny,knot1 --variants clean,noise1 \
#        --scans lidar_cars,hippo1_view --orient                   # a small subset (minutes)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
build=${BUILD:-build-scans}
bash tools/deps.sh cmake ninja-build g++ libeigen3-dev libstb-dev libcgal-dev liblzf-dev time imagemagick python3 \
  python3-open3d python3-numpy
targets="vitri_scan_cases vitri_scan_metrics bench_orient vitri_scan_cgal_poisson"
vitri=${VITRI:-build-release/apps/vitri}
if [ "$vitri" = build ]; then
  targets="$targets vitri_cli"
  vitri="$build/apps/vitri"
fi
[ -f "$build/CMakeCache.txt" ] || cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DVITRI_BUILD_BENCH=ON \
  -DVITRI_BUILD_TESTS=OFF
cmake --build "$build" --target $targets -j"${JOBS:-2}"
[ -x "$vitri" ] || { echo "run_scans: no vitri CLI at $vitri (set VITRI=path, or VITRI=build)"; exit 1; }
exec /usr/bin/python3 bench/scans/run_scans.py --build "$build" --vitri "$vitri" "$@"
