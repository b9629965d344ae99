#!/usr/bin/env bash
# Configures and builds build-sanitize, the one sanitized tree: clang with AddressSanitizer,
# UndefinedBehaviorSanitizer and libFuzzer's coverage instrumentation. The sanitized unit tests
# (scripts/test.sh) and the fuzzers (scripts/fuzz.sh) both run from it, so the libraries are
# compiled once for both. -O1 with line tables: what the sanitizers need for their checks and
# their stack traces, at half the compile time of -O2 -g.
#   scripts/sanitize-build.sh TARGET...     e.g. subscan_unit_tests subscan_fuzzers
set -euo pipefail
cd "$(dirname "$0")/.."

[[ $# -gt 0 ]] || { echo "usage: scripts/sanitize-build.sh TARGET..." >&2; exit 2; }
CC=clang CXX=clang++ cmake -S . -B build-sanitize -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only -DNDEBUG" \
    -DSUBSCAN_FUZZ=ON -DSUBSCAN_BUILD_BENCH=OFF >/dev/null
cmake --build build-sanitize -j "$(nproc)" --target "$@"
