#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan, in build-sanitize: scripts/sanitize-build.sh)
# and fuzzes each reader (and the index writer) for N seconds, as many readers at a time as there are cores.
#   scripts/fuzz.sh [--seconds N] [ply|las|laz|copc|pcd|xyz|e57|off|index|ept ...]   default: 300 s each, all
# Seeds: tiny files written here or by the unit tests that build them (LAZ, COPC, E57; from the
# Release build in build/), plus small real scans from ../shared/data when present (copied into
# the build folder only). A finding stops the script with a non-zero exit and
# leaves the input under build-sanitize/artifacts/.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=300
readers=()
while [[ $# -gt 0 ]]; do
    case "$1" in
        --seconds) seconds="$2"; shift 2 ;;
        ply|las|laz|copc|pcd|xyz|e57|off|index|ept) readers+=("$1"); shift ;;
        *) echo "usage: scripts/fuzz.sh [--seconds N] [ply|las|laz|copc|pcd|xyz|e57|off|index|ept ...]" >&2; exit 2 ;;
    esac
done
[[ ${#readers[@]} -gt 0 ]] || readers=(ply las laz copc pcd xyz e57 off index ept)

scripts/setup-deps.sh
build=build-sanitize
scripts/sanitize-build.sh "${readers[@]/#/fuzz_}" >/dev/null

# Seeds the unit tests build (a LAZ encoder, an E57 writer live there): run them from the
# Release build, building just those tests when it lacks them.
test_seeds() {  # test-binary environment-variable directory
    local test=$1 variable=$2 dir=$3
    if [[ ! -x build/tests/$test ]]; then
        cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
        cmake --build build --target "$test" >/dev/null
    fi
    env "$variable=$dir" "build/tests/$test" >/dev/null
}

# Little-endian integers for the hand-made LAS seed.
le() {  # value bytes
    local value=$1 bytes=$2 i
    for ((i = 0; i < bytes; i++)); do
        printf "\\x$(printf %02x $(((value >> (8 * i)) & 255)))"
    done
}
write_seeds() {  # reader directory
    local reader=$1 dir=$2
    case "$reader" in
        ply)
            printf 'ply\nformat ascii 1.0\ncomment seed\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n3 0 1 2\n' >"$dir/ascii.ply"
            { printf 'ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nproperty list uchar float extra\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n'
              printf '\x00\x00\x80\x3f\x00\x00\x00\x40\x00\x00\x40\x40\x01\x00\x00\x80\x3f'
              printf '\x00\x00\x80\x3f\x00\x00\x00\x40\x00\x00\x40\x40\x00'
              printf '\x03\x00\x00\x00\x00\x01\x00\x00\x00\x01\x00\x00\x00'; } >"$dir/binary.ply"
            ;;
        pcd)
            printf '# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n1 2 3 16711680\nnan nan nan 0\n' >"$dir/ascii.pcd"
            ;;
        xyz)
            printf 'x,y,z,r,g,b\n1,2,3,255,0,0\n4,5,6,0,255,0\n' >"$dir/header.csv"
            printf '2\n1 2 3 -100 10 20 30\n4 5 6 200 40 50 60\n' >"$dir/scan.pts"
            printf '1.5 2.5 3.5\n-1e3 +2 nan\n' >"$dir/plain.xyz"
            ;;
        las)
            {   # LAS 1.2, point format 2 (26 bytes), two points, 227-byte header, no VLRs
                printf 'LASF'; le 0 4; printf '%16s' '' | tr ' ' '\0'; le 1 1; le 2 1
                printf '%64s' '' | tr ' ' '\0'; le 1 2; le 2024 2; le 227 2; le 227 4; le 0 4
                le 2 1; le 26 2; le 2 4; le 2 4; le 0 16
                local scale=$((0x3F847AE147AE147B))  # the double 0.01
                le $scale 8; le $scale 8; le $scale 8; le 0 24  # scale, then offset 0
                le 0 48                                          # bounds (not checked here)
                for p in 1 2; do le $p 4; le $((p * 2)) 4; le $((p * 3)) 4; le 100 2; le 0 6
                    le 65535 2; le 0 2; le 255 2; done; } >"$dir/format2.las"
            ;;
        off)
            printf 'OFF\n# cube\n8 6 12\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n' >"$dir/cube.off"
            printf 'STCNOFF 2 1 0\n1 2 3 0 0 1 0.5 0.5 0.5 1 0.25 0.75\n4OFF\n3 0 1 1\n' >"$dir/variants.off"
            printf 'COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2\n' >"$dir/colour.off"
            ;;
        ept)  # an ept.json, a NUL byte, a hierarchy page (EptFuzzer.cpp)
            { printf '{"bounds":[0,0,0,8,8,8],"boundsConforming":[1,1,1,7,7,7],"dataType":"laszip",'
              printf '"hierarchyType":"json","points":30,"span":128,"version":"1.0.0"}\0'
              printf '{"0-0-0-0":10,"1-0-0-0":20,"1-1-1-1":-1}'; } >"$dir/small.ept"
            ;;
        index)  # format 7, 2 extra bytes, nodes of 5 points; then 38-byte records
            # No pipe into head: under pipefail, seq's SIGPIPE when head stops reading would
            # end the script (CI's exit 141, depending on when seq wrote its last block).
            local digits
            digits=$(seq 1 2000)
            { printf '\x01\x02\x05'; printf '%s' "${digits:0:3800}"; } >"$dir/digits.bin"
            ;;
        e57)
            printf 'ASTM-E57' >"$dir/magic.e57"
            test_seeds E57ReaderTest SUBSCAN_E57_SEEDS "$dir"
            ;;
        laz|copc)
            local all="$dir/../all-laz"
            mkdir -p "$all"
            test_seeds LazReaderTest SUBSCAN_LAZ_SEEDS "$all"
            if [[ $reader == copc ]]; then cp "$all"/*.copc.laz "$dir/"; else
                find "$all" -name '*.laz' ! -name '*.copc.laz' -exec cp {} "$dir/" \; ; fi
            ;;
    esac
    local data=../shared/data
    if [[ -d "$data" ]]; then
        case "$reader" in
            ply) cp "$data/bun_zipper_res4.ply" "$dir/" ;;
            las) cp "$data/simple.las" "$dir/" ;;
            pcd) cp "$data/pcl_bunny_ascii.pcd" "$data/autzen_utm_binary.pcd" "$dir/" ;;
        esac
    fi
}

fuzz() {  # reader: fuzzes it for $seconds; its output goes to its log
    local reader=$1
    # -rss_limit_mb/-malloc_limit_mb turn allocation bombs from lying headers into findings.
    "$build/tests/fuzz/fuzz_$reader" -max_total_time="$seconds" -timeout=10 \
        -rss_limit_mb=2048 -malloc_limit_mb=1024 -max_len=65536 -print_final_stats=1 \
        -artifact_prefix="$build/artifacts/$reader-" "$build/corpus/$reader" \
        "$build/seeds/$reader" >"$build/fuzz-$reader.log" 2>&1
}
report() {  # reader status
    local reader=$1 status=$2 log="$build/fuzz-$1.log" executions
    if [[ $status -ne 0 ]]; then
        tail -n 40 "$log" >&2
        echo "fuzz: $reader found a problem; the input is in $build/artifacts/" >&2
        return 1
    fi
    executions=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
    echo "fuzz: $reader ok, $executions executions (log: $log)"
}

mkdir -p "$build/artifacts"
for reader in "${readers[@]}"; do
    mkdir -p "$build/corpus/$reader" "$build/seeds/$reader"
    write_seeds "$reader" "$build/seeds/$reader"
done
# Side by side in groups of one per core; each reader still gets its full N seconds.
failed=0
parallel=$(nproc)
for ((first = 0; first < ${#readers[@]}; first += parallel)); do
    group=("${readers[@]:first:parallel}")
    echo "fuzz: ${group[*]} for ${seconds}s"
    pids=()
    for reader in "${group[@]}"; do
        fuzz "$reader" &
        pids+=($!)
    done
    for i in "${!group[@]}"; do
        status=0
        wait "${pids[i]}" || status=$?
        report "${group[i]}" "$status" || failed=1
    done
    [[ $failed -eq 0 ]] || exit 1
done
