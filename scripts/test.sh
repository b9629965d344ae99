#!/usr/bin/env bash
# The whole test suite: installs what is missing, builds, runs every test with ctest (the
# Python module's pytest suite among them, label python), then the unit tests again under
# AddressSanitizer + UndefinedBehaviorSanitizer (without the Python module), then each reader's
# fuzzer for a short while from the same sanitized build. Real-scan tests read
# $SUBSCAN_TEST_DATA or ../shared/data and are skipped with a message when neither exists.
# Compiles go through ccache when it is installed (scripts/setup-deps.sh installs it); the wall
# time of each phase and the cache's hits are printed at the end.
set -euo pipefail
cd "$(dirname "$0")/.."

fuzz_seconds=${SUBSCAN_FUZZ_SECONDS:-15}
jobs=$(nproc)

phase_name="" phase_start=0 timings=()
end_phase() {
    [[ -n $phase_name ]] && timings+=("$(printf '%-16s %5d s' "$phase_name" $((SECONDS - phase_start)))")
    phase_name=""
}
phase() {  # name
    end_phase
    phase_name=$1 phase_start=$SECONDS
    echo "== $1"
}
summary() {
    end_phase
    echo "== wall time per phase"
    printf '  %s\n' "${timings[@]}" "$(printf '%-16s %5d s' total "$SECONDS")"
    if [[ -s $CCACHE_STATSLOG ]]; then
        ccache --show-log-stats | grep -E '^ *(Hits|Misses):' | sed 's/^ */  ccache /'
    fi
    rm -f "$CCACHE_STATSLOG"
}
# This run's compiles only, whatever else the cache has seen.
export CCACHE_STATSLOG
CCACHE_STATSLOG=$(mktemp)
trap summary EXIT

phase setup
scripts/setup-deps.sh

phase "Release build"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$jobs"

phase tests
ctest --test-dir build --output-on-failure -j "$jobs"

phase "sanitizer build"
scripts/sanitize-build.sh subscan_unit_tests subscan_fuzzers

phase "sanitizer tests"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-sanitize -L unit --output-on-failure -j "$jobs"

if [[ "$fuzz_seconds" -gt 0 ]]; then
    phase fuzzing
    scripts/fuzz.sh --seconds "$fuzz_seconds"
fi
echo "== all tests passed"
