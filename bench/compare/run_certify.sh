#!/bin/sh
# Builds bench_compare_certify in Release and runs it at low priority, writing into bench/compare/results/:
#   certify-DATE.md   the Markdown report (date, machine, commit, command, tables, summary)
#   certify-DATE.csv  one row per run (columns: see bench/compare/compare_certify.cpp's header)
# Usage: bench/compare/run_certify.sh [BUILD_DIR] [bench_compare_certify options]
# Default options: the three shared models, global and local functions, precisions 0.1, 0.05, 0.025 of
# the diagonal, floors 0.1, 0.5, 1.0, cap 120 s per certified run, 300 s per CGAL run (about 1.5 h on
# 2 cores).
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-"$root/build-bench42"}
[ $# -gt 0 ] && shift
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DVITRI_BUILD_BENCH=ON >/dev/null
nice -n 10 cmake --build "$build" --target bench_compare_certify -j2
out="$root/bench/compare/results"
day=$(date -u '+%Y-%m-%d')
if [ $# -eq 0 ]; then
  set -- --models hand,bunny,knot1 --local hand,bunny,knot1 --precisions 0.1,0.05,0.025 \
    --floors 0.1,0.5,1.0 --cap 120 --cgal-cap 300
fi
nice -n 10 "$build/bench/compare/bench_compare_certify" "$@" --csv "$out/certify-$day.csv" \
  --md "$out/certify-$day.md"
echo "wrote $out/certify-$day.md, certify-$day.csv"
