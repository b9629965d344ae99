#!/usr/bin/env bash
# Regenerates the README's pictures in docs/images from the built-in sculpture and, when
# ../shared/data (or $SUBSCAN_TEST_DATA) is present, the Stanford Happy Buddha scans.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build --target subscan subscan_figures >&2
data=${SUBSCAN_TEST_DATA:-../shared/data}
mkdir -p docs/images
build/tools/subscan_figures stages synthetic:sculpture docs/images/stages-sculpture.png --yaw 30 --pitch 20 --size 400 450
build/tools/subscan_figures compare synthetic:sculpture docs/images/compare-sculpture.png --yaw 30 --pitch 20 --size 400 450
if [[ -f "$data/happy_stand_registered.ply" ]]; then
    build/tools/subscan_figures stages "$data/happy_stand_registered.ply" docs/images/stages-happy.png --yaw 0 --pitch 10 --size 400 560
    build/tools/subscan_figures compare "$data/happy_stand_registered.ply" docs/images/compare-happy.png --yaw 0 --pitch 10 --size 500 700
else
    echo "make-figures: $data not found; skipped the Happy Buddha figures" >&2
fi
ls -1 docs/images
