#!/bin/sh
# Builds bench_compare in Release and runs it, writing into bench/compare/results/:
#   compare.md           the markdown tables printed by the program, after a header (date, machine, load)
#   compare.csv          one row per (surface, target, contender) run (columns: see the program's header)
#   hist_hand_10k.csv    min-angle histograms (1-degree bins) of every contender on hand at ~10k vertices
# and the hand ~10k meshes of every contender into BUILD/compare-meshes/ (OFF, not committed).
# Usage: bench/compare/run_compare.sh [BUILD_DIR] [bench_compare options, e.g. --quick]
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-"$root/build-cmp"}
[ $# -gt 0 ] && shift
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DVITRI_BUILD_TESTS=OFF >/dev/null
cmake --build "$build" --target bench_compare -j2
out="$root/bench/compare/results"
mkdir -p "$out" "$build/compare-meshes"
{
  echo "Date: $(date -u '+%Y-%m-%d %H:%M UTC')"
  echo "Machine: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) CPUs; $(g++ --version | head -1)"
  echo "Load before: $(uptime | sed 's/.*load average/load average/')"
  echo "Command: bench_compare $* --csv compare.csv --hist hist_hand_10k.csv"
  echo
  "$build/bench/compare/bench_compare" "$@" --csv "$out/compare.csv" --hist "$out/hist_hand_10k.csv" \
    --meshes "$build/compare-meshes"
  echo
  echo "Load after: $(uptime | sed 's/.*load average/load average/')"
} > "$out/compare.md"
echo "wrote $out/compare.md, compare.csv, hist_hand_10k.csv"
