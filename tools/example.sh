#!/usr/bin/env bash
# Builds vitri (Release) and meshes the bundled hand model at three levels of detail.
# Usage: bash tools/example.sh   (meshes written to out/hand-0.obj, out/hand-1.obj, out/hand-2.obj)
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build_release.sh
mkdir -p out
./build-release/apps/vitri mesh data/hand.off -o out/hand.obj --precision 0.04 --precision 0.02 --precision 0.01
echo "meshes written: $(ls out/hand-*.obj | tr '\n' ' ')"
