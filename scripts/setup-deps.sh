#!/usr/bin/env bash
# Installs the Debian 12 packages subscan needs to build, test and run (DESIGN.md §10).
# Idempotent: when everything is present it only asks dpkg and returns in well under a second.
set -euo pipefail

packages=(
    # build
    cmake g++ ninja-build pkg-config
    # compiler cache (CMake uses it when present; scripts/test.sh reuses objects across clones)
    ccache
    # fuzzing (scripts/fuzz.sh): clang with its libFuzzer/sanitizer runtimes
    clang libclang-rt-14-dev
    # GL: loader, EGL headers, Mesa's software rasterizer for GPU-less machines
    libepoxy-dev libegl-dev libgl1-mesa-dri libegl-mesa0
    # viewer
    libglfw3-dev libimgui-dev xvfb xauth
    # libraries
    libglm-dev libstb-dev libcli11-dev libfmt-dev nlohmann-json3-dev libfast-float-dev
    liblzf-dev libnanoflann-dev libeigen3-dev libpugixml-dev
    # tests and benchmarks
    libgtest-dev libgmock-dev libbenchmark-dev
    # tests: compiles the 64-bit rasterizer's shaders where no driver can run them
    glslang-tools
    # the Python module (import subscan) and its tests; PIL reads the CLI's PNGs in them and
    # shows pictures in the examples
    python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest python3-pil
    # run time: `subscan turntable -o OUT.mp4` encodes with ffmpeg (folders of PNGs need nothing)
    ffmpeg
    # tests (label npm): independent readers from npm (laz-perf) read the files we write
    nodejs npm
)

# One dpkg-query for all packages; those it does not report as installed are missing.
installed=$(dpkg-query -W -f='${Package} ${Status}\n' "${packages[@]}" 2>/dev/null |
    awk '$4 == "installed" { print $1 }' || true)
missing=()
for package in "${packages[@]}"; do
    grep -qx "$package" <<<"$installed" && continue
    # NodeSource's nodejs brings its own npm and conflicts with Debian's: an npm command will do.
    [[ $package == npm ]] && command -v npm >/dev/null && continue
    missing+=("$package")
done
[[ ${#missing[@]} -eq 0 ]] && exit 0

echo "setup-deps: installing ${missing[*]}" >&2
sudo=()
if [[ $(id -u) -ne 0 ]]; then
    command -v sudo >/dev/null || { echo "setup-deps: not root and no sudo; install as root: ${missing[*]}" >&2; exit 1; }
    sudo=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
