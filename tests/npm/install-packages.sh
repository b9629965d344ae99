#!/usr/bin/env bash
# Installs the npm packages of tests/npm into a build folder from the committed lock file (npm ci),
# for the interoperability tests (ctest label npm). Usage: install-packages.sh SOURCE_DIR INSTALL_DIR
# Writes INSTALL_DIR/status.txt, which the tests read: "ready" and the path of node, or "skip" and
# why. Without node or npm, or when the registry cannot be reached (and npm's cache lacks the
# packages), it exits 77, which ctest shows as skipped; any other failure of npm is an error.
# Installs again only when the lock file changed.
set -euo pipefail
source_dir=$1
install_dir=$2
status=$install_dir/status.txt
mkdir -p "$install_dir"

skip() {
    printf 'skip\n%s\n' "$1" >"$status"
    echo "npm packages not installed: $1" >&2
    exit 77
}
ready() {
    printf 'ready\n%s\n' "$node" >"$status"
    exit 0
}

node=$(command -v node || command -v nodejs || true)
[[ -n $node ]] || skip "node is not installed (Debian: nodejs, which scripts/setup-deps.sh installs)"
command -v npm >/dev/null || skip "npm is not installed (Debian: npm, which scripts/setup-deps.sh installs)"

cp "$source_dir"/package.json "$source_dir"/package-lock.json "$source_dir"/*.js "$install_dir"/
installed=$install_dir/installed-package-lock.json
if [[ -d $install_dir/node_modules ]] && cmp -s "$source_dir/package-lock.json" "$installed"; then
    ready
fi

log=$install_dir/npm-ci.log
# --ignore-scripts: nothing from the registry runs here; --prefer-offline: npm's cache serves
# what it holds (the lock file's hashes still check it); one quick retry, so that a machine
# without the registry skips in seconds rather than after npm's minute of retries.
if ! (cd "$install_dir" && timeout 300 npm ci --ignore-scripts --prefer-offline --no-audit \
    --no-fund --loglevel=error --fetch-retries=1 --fetch-retry-mintimeout=1000 \
    --fetch-retry-maxtimeout=3000) >"$log" 2>&1; then
    if grep -qE 'ENOTFOUND|EAI_AGAIN|ECONNREFUSED|ECONNRESET|ETIMEDOUT|ENETUNREACH|EHOSTUNREACH|network' "$log"; then
        skip "npm ci cannot reach the registry (see $log)"
    fi
    cat "$log" >&2
    echo "npm ci failed in $install_dir (log above)" >&2
    exit 1
fi
cp "$source_dir/package-lock.json" "$installed"
ready
