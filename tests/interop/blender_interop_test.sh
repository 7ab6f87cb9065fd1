#!/usr/bin/env bash
# A baked tree in Blender, as a user would use it: imported headless (volume_import, the OBJ
# mesh, instances.json's placement), rendered in Cycles with direct light only, and its
# coverage (alpha) compared with the fibre-law reference render of the same view from the same
# grids. Blender renders `density` as an isotropic medium (the needles placed independently),
# the reference the needles evenly spaced in their cones, so the two differ by what that
# choice makes (measured: coverage -2.0%, per-pixel mean |alpha difference| 0.0093 at 96 x 72,
# -2.1% and 0.0096 at 320 x 240);
# the bounds below are about twice that. A misplaced tree (transform, frame), a density in the
# wrong unit or a missing mesh breaks them by a factor of several.
# Usage: blender_interop_test.sh BAKE VDBTRACE SOURCE_DIR [KEEP_DIR WIDTH HEIGHT]
# (KEEP_DIR: keep both images there, e.g. for the README). Exit 77 (skipped) without Blender.
set -u
bake=$1
vdbtrace=$2
src=$3
keep=${4:-}
width=${5:-96}
height=${6:-72}
tool=$vdbtrace
# shellcheck source=../tools/cli_test_lib.sh
source "$src/tests/tools/cli_test_lib.sh"
command -v blender >/dev/null || { echo "SKIP: blender is not installed (scripts/install-deps.sh --test)"; exit 77; }

# One fir of three-firs.json, turned, on no ground, seen whole.
/usr/bin/python3 - "$src/scenes/three-firs.json" "$work/scene.json" "$width" "$height" <<'PY'
import json, sys
scene = json.load(open(sys.argv[1]))
scene["camera"] = {"position": [40, -330, 80], "look_at": [0, 0, 52], "up": [0, 0, 1],
                   "fov_deg": 24, "resolution": [int(sys.argv[3]), int(sys.argv[4])]}
scene["ground"] = {"type": "none"}
scene["trees"] = [{"species": "fir", "position": [30, 20], "rotation_deg": 75, "seed": 5}]
json.dump(scene, open(sys.argv[2], "w"))
PY
"$bake" scene "$work/scene.json" --voxel-size 1 --out-dir "$work/bake" -q || fail "bake"
blender -b --factory-startup --python-exit-code 1 -P "$src/tests/interop/blender_render.py" -- \
    "$work/bake" "$work/scene.json" "$work/blender" "$width" "$height" >"$work/blender.log" 2>&1 \
    || { fail "blender: $(grep -i -m3 error "$work/blender.log")"; tail -20 "$work/blender.log"; }
"$vdbtrace" render "$work/scene.json" --method reference --grids "$work/bake/tree_000.vdb" \
    --subpixels 4 --out "$work/reference.exr" -q || fail "reference render"

oiiotool "$work/blender.exr" --ch A -o "$work/a-blender.exr" && oiiotool "$work/reference.exr" --ch A -o "$work/a-reference.exr" \
    || fail "no alpha to compare"
mean() { oiiotool "$1" --printstats | sed -n 's/.*Stats Avg: \([0-9.e+-]*\).*/\1/p'; }
blender_cover=$(mean "$work/a-blender.exr")
reference_cover=$(mean "$work/a-reference.exr")
per_pixel=$(idiff "$work/a-blender.exr" "$work/a-reference.exr" 2>&1 | sed -n 's/.*Mean error = \([0-9.e+-]*\).*/\1/p')
echo "blender interop: coverage $blender_cover (Blender) against $reference_cover (reference), per-pixel mean |difference| $per_pixel"
/usr/bin/python3 - "$blender_cover" "$reference_cover" "$per_pixel" <<'PY' || fail "Blender's coverage is not the reference's"
import sys
blender, reference, per_pixel = (float(v) for v in sys.argv[1:4])
assert reference > 0.03, reference  # the tree is in view
assert abs(blender / reference - 1) < 0.05, (blender, reference)
assert per_pixel < 0.025, per_pixel
PY
if [ -n "$keep" ]; then
    # Side by side, each over the scene's sky, sRGB: Blender on the left, the reference right.
    mkdir -p "$keep"
    oiiotool "$work/blender.exr" --ch R,G,B,A --pattern constant:color=0.55,0.7,0.9,1 "${width}x${height}" 4 --over \
        "$work/reference.exr" --ch R,G,B,A --pattern constant:color=0.55,0.7,0.9,1 "${width}x${height}" 4 --over \
        --mosaic 2x1 --ch R,G,B --colorconvert linear sRGB -d uint8 -o "$keep/blender-vs-reference.png" \
        || fail "side-by-side image"
fi
echo "blender interop: $failures failed"
[ "$failures" -eq 0 ]
