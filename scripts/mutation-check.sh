# Shared by the scripts/mutate-*.sh checks; source it.
#
# check_mutations TEST_BINARY MUTATION... applies each mutation to a copy of shaders/ loaded
# through SUBSCAN_SHADER_DIR, runs TEST_BINARY, and prints whether it failed (caught) or passed
# (survived). A mutation is "name|file under shaders/|exact text|its wrong replacement", and may
# go on with more "|file|text|replacement" triples that belong to the same wrong change.
#
# check_source_mutations TEST_TARGET MUTATION... does the same with files under src/: each is
# changed in place, the test target rebuilt in build/, run, and the file put back (also when the
# script is interrupted); build/ is rebuilt clean at the end.
#
# Both return non-zero when a mutation survived or no longer applies.

# replace_exactly FILE FROM TO: replaces the first FROM in FILE, or fails.
replace_exactly() {
    FROM="$2" TO="$3" perl -0pi -e 's/\Q$ENV{FROM}\E/$ENV{TO}/ or die "not found\n"' "$1"
}

# report_run STATUS NAME LOG: prints the verdict on a test run that ended with STATUS.
report_run() {
    local status=$1 name=$2 log=$3
    if [[ "$status" -eq 0 ]]; then
        echo "SURVIVED  $name"
        return 1
    fi
    echo "caught    $name ($(grep -c '^\[  FAILED  \] .*ms)' "$log") tests failed)"
}

check_mutations() {
    local test_binary=$1
    shift
    [[ -x "$test_binary" ]] || { echo "mutate: build $test_binary first" >&2; return 1; }
    local work
    work=$(mktemp -d)
    local survived=0 mutation name file from to rest
    for mutation in "$@"; do
        IFS='|' read -r name rest <<<"$mutation"
        rm -rf "$work/shaders"
        cp -r shaders "$work/shaders"
        while [[ -n "$rest" ]]; do
            IFS='|' read -r file from to rest <<<"$rest"
            if ! replace_exactly "$work/shaders/$file" "$from" "$to"; then
                echo "mutate: '$name' no longer applies to shaders/$file" >&2
                rm -rf "$work"
                return 1
            fi
        done
        local status=0
        SUBSCAN_SHADER_DIR="$work/shaders" "$test_binary" >"$work/log" 2>&1 || status=$?
        report_run "$status" "$name" "$work/log" || survived=1
    done
    rm -rf "$work"
    return "$survived"
}

check_source_mutations() {
    local target=$1
    shift
    local work
    work=$(mktemp -d)
    local survived=0 mutation name file from to
    for mutation in "$@"; do
        IFS='|' read -r name file from to <<<"$mutation"
        cp "$file" "$work/original"
        # Put the file back however this ends; a copy keeps any uncommitted change of it.
        trap 'cp "$work/original" "$file"' EXIT INT TERM
        if ! replace_exactly "$file" "$from" "$to"; then
            echo "mutate: '$name' no longer applies to $file" >&2
            return 1
        fi
        if ! cmake --build build --target "$target" >"$work/build.log" 2>&1; then
            cp "$work/original" "$file"
            echo "mutate: '$name' does not build:" >&2
            tail -20 "$work/build.log" >&2
            return 1
        fi
        local status=0
        "build/tests/$target" >"$work/log" 2>&1 || status=$?
        report_run "$status" "$name" "$work/log" || survived=1
        cp "$work/original" "$file"
        touch "$file"  # newer than the mutated object, so the next build recompiles it
        trap - EXIT INT TERM
    done
    cmake --build build >/dev/null
    rm -rf "$work"
    return "$survived"
}
