# Shared by the scripts/mutate-*.sh checks; source it. check_mutations TEST_BINARY MUTATION...
# applies each mutation, "name|file under shaders/|exact text|its wrong replacement", to a copy
# of shaders/ loaded through SUBSCAN_SHADER_DIR, runs TEST_BINARY, and prints whether it failed
# (caught) or passed (survived). Returns non-zero when a mutation survived or no longer applies.
check_mutations() {
    local test_binary=$1
    shift
    [[ -x "$test_binary" ]] || { echo "mutate: build $test_binary first" >&2; return 1; }
    local work
    work=$(mktemp -d)
    local survived=0 mutation name file from to
    for mutation in "$@"; do
        IFS='|' read -r name file from to <<<"$mutation"
        rm -rf "$work/shaders"
        cp -r shaders "$work/shaders"
        if ! FROM="$from" TO="$to" perl -0pi -e 's/\Q$ENV{FROM}\E/$ENV{TO}/ or die "not found\n"' \
            "$work/shaders/$file"; then
            echo "mutate: '$name' no longer applies to shaders/$file" >&2
            rm -rf "$work"
            return 1
        fi
        if SUBSCAN_SHADER_DIR="$work/shaders" "$test_binary" >"$work/log" 2>&1; then
            echo "SURVIVED  $name"
            survived=1
        else
            echo "caught    $name ($(grep -c '^\[  FAILED  \] .*ms)' "$work/log") tests failed)"
        fi
    done
    rm -rf "$work"
    return "$survived"
}
