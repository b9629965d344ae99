#!/usr/bin/env bash
# Installs what is missing, builds subscan, renders the built-in demo scan (a virtual scan of
# the sculpture scene: no data file and no GPU needed) as a reconstructed surface and prints
# the PNG's path.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build --target subscan >&2

mkdir -p out
build/src/subscan render synthetic:sculpture --mode sss --material marble-jimenez -o out/demo.png --width 1280 --height 720 >&2
echo "$(pwd)/out/demo.png"
