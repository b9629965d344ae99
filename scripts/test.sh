#!/usr/bin/env bash
# The whole test suite: installs what is missing, builds, runs every test with ctest (the
# Python module's pytest suite among them, label python), then the unit tests again under
# AddressSanitizer + UndefinedBehaviorSanitizer (without the Python module), then each reader's
# fuzzer for a short while. Real-scan tests read $SUBSCAN_TEST_DATA or ../shared/data and are
# skipped with a message when neither exists.
set -euo pipefail
cd "$(dirname "$0")/.."

fuzz_seconds=${SUBSCAN_FUZZ_SECONDS:-15}
jobs=$(nproc)

scripts/setup-deps.sh

echo "== build (Release)"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$jobs"

echo "== tests"
ctest --test-dir build --output-on-failure -j "$jobs"

echo "== unit tests under ASan + UBSan"
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSUBSCAN_SANITIZE=ON \
    -DSUBSCAN_BUILD_BENCH=OFF >/dev/null
cmake --build build-asan -j "$jobs" --target subscan_unit_tests
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan -L unit --output-on-failure -j "$jobs"

if [[ "$fuzz_seconds" -gt 0 ]]; then
    echo "== fuzzing each reader for ${fuzz_seconds}s"
    scripts/fuzz.sh --seconds "$fuzz_seconds"
fi
echo "== all tests passed"
