#!/usr/bin/env bash
# Builds vitri (Release) with the studio and starts it on a bundled model: open http://127.0.0.1:8080/
# Usage: bash tools/studio.sh [MODEL] [vitri studio options...]   (default: data/hand.off --sides outside
#        --precision 0.015: 2394 constraints, about 10k mesh vertices)
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build_release.sh
if [ $# -eq 0 ]; then
  set -- data/hand.off --sides outside --precision 0.015
fi
exec ./build-release/apps/vitri studio "$@"
