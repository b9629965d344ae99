#!/usr/bin/env bash
# Regenerates the documentation's pictures in docs/images from the Stanford Happy Buddha scan in
# ../shared/data (or $SUBSCAN_TEST_DATA).
set -euo pipefail
cd "$(dirname "$0")/.."
data=${SUBSCAN_TEST_DATA:-../shared/data}
scan="$data/happy_stand_registered.ply"
if [[ ! -f "$scan" ]]; then
    echo "make-figures: $scan not found; set SUBSCAN_TEST_DATA to the folder holding it" >&2
    exit 1
fi
scripts/setup-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build --target subscan subscan_figures >&2
mkdir -p docs/images
# A close-up, where the points leave gaps, like the paper's Figure 2.
build/tools/subscan_figures stages "$scan" docs/images/stages-happy.png --yaw 0 --pitch 10 --distance 0.09 --size 400 400
build/tools/subscan_figures compare "$scan" docs/images/compare-happy.png --yaw 0 --pitch 10 --distance 0.18 --size 420 560
build/tools/subscan_figures materials "$scan" docs/images/materials-happy.png --yaw 0 --pitch 10 --distance 0.18 --size 420 560
build/tools/subscan_figures single "$scan" docs/images/single-happy.png --yaw 0 --pitch 10 --distance 0.18 --size 320 420
build/tools/subscan_figures shadows "$scan" docs/images/shadows-happy.png --yaw 0 --pitch 10 --distance 0.3 --size 300 460
build/tools/subscan_figures backlit "$scan" docs/images/backlit-happy.png --yaw 0 --pitch 10 --distance 0.3 --size 300 460
# Two renders side by side, 8 white pixels between them.
side_by_side() {
    /usr/bin/python3 - "$1" "$2" "$3" <<'PY'
import sys
from PIL import Image
left, right = Image.open(sys.argv[1]).convert("RGB"), Image.open(sys.argv[2]).convert("RGB")
pair = Image.new("RGB", (left.width + 8 + right.width, left.height), (255, 255, 255))
pair.paste(left, (0, 0))
pair.paste(right, (left.width + 8, 0))
pair.save(sys.argv[3])
PY
}
tmp=$(mktemp -d)
trap 'rm -r "$tmp"' EXIT
# The depth camera's table scene from render's default orbit and from its own sensor.
table="$data/table_scene_mug_stereo_textured.pcd"
if [[ -f "$table" ]]; then
    build/src/subscan render "$table" --mode surface --width 480 --height 360 -o "$tmp/orbit.png" 2>/dev/null
    build/src/subscan render "$table" --mode surface --view sensor --width 480 --height 360 -o "$tmp/sensor.png" 2>/dev/null
    side_by_side "$tmp/orbit.png" "$tmp/sensor.png" docs/images/sensor-table.png
fi
# The local spacing: the global h (left) against it (right), on autzen's trees from close by
# and on the virtual LiDAR station from where it stood.
echo '{"surface": {"local_spacing": false}}' >"$tmp/global.json"
autzen="$data/autzen_trim.las"
if [[ -f "$autzen" ]]; then
    for kind in global local; do
        settings=()
        [[ $kind == global ]] && settings=(--settings "$tmp/global.json")
        build/src/subscan render "$autzen" --mode surface --pitch 50 --distance 250 --width 560 --height 420 "${settings[@]}" -o "$tmp/autzen-$kind.png"
    done
    side_by_side "$tmp/autzen-global.png" "$tmp/autzen-local.png" docs/images/local-spacing-autzen.png
fi
for kind in global local; do
    settings=()
    [[ $kind == global ]] && settings=(--settings "$tmp/global.json")
    build/src/subscan render synthetic:outdoor-station --mode surface --view sensor --width 480 --height 360 "${settings[@]}" -o "$tmp/station-$kind.png"
done
side_by_side "$tmp/station-global.png" "$tmp/station-local.png" docs/images/local-spacing-station.png
# The points' normals: the nearest point's per pixel (left) and the mean of a pixel's points'
# (right, raster.normal_blend), from far enough that a pixel holds several points.
echo '{"raster": {"normal_blend": 0}}' >"$tmp/nearest.json"
build/src/subscan render "$scan" --mode surface --width 320 --height 320 --settings "$tmp/nearest.json" -o "$tmp/nearest.png"
build/src/subscan render "$scan" --mode surface --width 320 --height 320 -o "$tmp/blended.png"
side_by_side "$tmp/nearest.png" "$tmp/blended.png" docs/images/normal-blend.png
# The screen-space normals towards the outline: the bunny's mesh (the truth), its vertices'
# surface with those normals as blended, and with them towards the outline.
bunny="$data/bun_zipper.ply"
if [[ -f "$bunny" ]]; then
    echo '{"surface": {"normals": "screen", "outline_normals": false}}' >"$tmp/blended.json"
    echo '{"surface": {"normals": "screen"}}' >"$tmp/towards.json"
    for kind in blended towards; do
        settings=(--settings "$tmp/$kind.json")
        build/src/subscan eval "$bunny" --points vertices --width 256 --height 256 --views 1 "${settings[@]}" --export-views "$tmp/$kind" >/dev/null
    done
    side_by_side "$tmp/towards/view0_truth.png" "$tmp/blended/view0_surface.png" "$tmp/truth-blended.png"
    side_by_side "$tmp/truth-blended.png" "$tmp/towards/view0_surface.png" docs/images/outline-normals.png
fi
# A close-up of the bunny's range scans: the hidden point test before its probe for a surface
# far in front (the shaders of commit 65482c0, which this binary still runs) and with it.
scans="$data/bunny_scans_registered.ply"
if [[ -f "$scans" ]]; then
    git archive 65482c0 shaders | tar -x -C "$tmp"
    for kind in before after; do
        shaders=()
        [[ $kind == before ]] && shaders=(env SUBSCAN_SHADER_DIR="$tmp/shaders")
        "${shaders[@]}" build/src/subscan render "$scans" --mode surface --width 360 --height 360 --distance 0.06 -o "$tmp/front-$kind.png"
    done
    side_by_side "$tmp/front-before.png" "$tmp/front-after.png" docs/images/close-up-front.png
fi
ls -1 docs/images
