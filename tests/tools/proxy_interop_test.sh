#!/usr/bin/env bash
# Baked proxies as another tool sees them: pyopenvdb reads density (extinction per metre, a
# field), color, the metadata and the instance list, the tree standing at its own origin; a
# render reads them back onto the scene's lattice; grids of another scene are refused and a
# grid without its manifest is read with a warning.
# Usage: proxy_interop_test.sh BAKE VDBTRACE SOURCE_DIR
set -u
bake=$1
vdbtrace=$2
src=$3
tool=$vdbtrace
# shellcheck source=cli_test_lib.sh
source "$(dirname "$0")/cli_test_lib.sh"

/usr/bin/python3 -c 'import pyopenvdb' 2>/dev/null \
    || { echo "FAIL: pyopenvdb is missing (python3-openvdb; scripts/install-deps.sh installs it)"; exit 1; }

# A small three-firs, baked in metres in each tree's frame (the default) and in cm in the world.
/usr/bin/python3 - "$src/scenes/three-firs.json" "$work/scene.json" <<'PY'
import json, sys
scene = json.load(open(sys.argv[1]))
scene["camera"]["resolution"] = [96, 72]
json.dump(scene, open(sys.argv[2], "w"))
PY
"$bake" scene "$work/scene.json" --voxel-size 2 --out-dir "$work/m" 2>"$work/err" || fail "bake (m): $(tail -1 "$work/err")"
"$bake" scene "$work/scene.json" --voxel-size 2 --units cm --frame world --out-dir "$work/cm" 2>"$work/err" \
    || fail "bake (cm): $(tail -1 "$work/err")"

/usr/bin/python3 - "$work/m" "$work/cm" <<'PY' || fail "pyopenvdb's view of the bake"
import json, os, sys
import pyopenvdb as vdb

m_dir, cm_dir = sys.argv[1], sys.argv[2]
instances = json.load(open(os.path.join(m_dir, "instances.json")))
assert instances["units"] == "m", instances
for entry in instances["instances"]:
    grids, meta = vdb.readAll(os.path.join(m_dir, entry["grids"]))
    byname = {g.name: g for g in grids}
    for name in ["density", "color", "layer_gradient", "layer_opacity", "needle_direction",
                 "needle_coverage", "density_level_1", "density_level_2"]:
        assert name in byname, (name, list(byname))
    assert meta["pine:format_version"] == 4 and meta["pine:units"] == "m", meta
    assert meta["pine:frame"] == "tree" and meta["pine:tree"] == entry["tree"], meta
    density, color = byname["density"], byname["color"]
    lo, hi = density.evalMinMax()
    assert 0 < lo < hi / 2, ("density is not a field", lo, hi)
    c_lo, c_hi = color.evalMinMax()
    assert all(0 < c <= 1 for c in c_lo + c_hi), (c_lo, c_hi)
    assert abs(density.transform.voxelSize()[0] - 0.02) < 1e-12

    # The same tree baked in cm in the world frame: the same optical mass (extinction x
    # volume, an area) in either unit, and the instance's transform puts the tree back.
    cm_grids, cm_meta = vdb.readAll(os.path.join(cm_dir, entry["grids"]))
    cm_density = [g for g in cm_grids if g.name == "density"][0]
    assert cm_meta["pine:units"] == "cm" and cm_meta["pine:frame"] == "world", cm_meta
    def mass(grid, unit_cm):
        total = 0.0
        for item in grid.citerOnValues():
            total += item["value"] * item["count"]
        return total * (grid.transform.voxelSize()[0] * unit_cm) ** 3 / unit_cm
    m_mass, cm_mass = mass(density, 100.0), mass(cm_density, 1.0)
    assert abs(m_mass - cm_mass) < 1e-5 * cm_mass, (m_mass, cm_mass)
    def centre(grid):
        lo, hi = grid.evalActiveVoxelBoundingBox()
        return [(a + b) / 2 for a, b in zip(grid.transform.indexToWorld(lo),
                                            grid.transform.indexToWorld(hi))]
    # In its own frame the tree stands at the origin: its crown's middle above its base.
    x, y, z = centre(density)
    assert abs(x) < 1.0 and abs(y) < 1.0 and z > 0, (x, y, z)
    lo, hi = density.evalActiveVoxelBoundingBox()
    corners = [density.transform.indexToWorld((i, j, k)) for i in (lo[0], hi[0])
               for j in (lo[1], hi[1]) for k in (lo[2], hi[2])]
    M = entry["tree_to_world"]
    placed = [[sum(M[r][c] * p[c] for c in range(3)) + M[r][3] for r in range(3)] for p in corners]
    world = [sum(p[r] for p in placed) / len(placed) for r in range(3)]
    expected = [v / 100.0 for v in centre(cm_density)]
    assert all(abs(a - b) < 1e-6 for a, b in zip(world, expected)), (world, expected)
print("pyopenvdb: %d trees read" % len(instances["instances"]))
PY

# vdb_lod names the levels it makes of density as our pyramid names its own.
if command -v vdb_lod >/dev/null; then
    vdb_lod "$work/m/tree_000.vdb" "$work/lod.vdb" -range 1-2 -name density >/dev/null 2>&1 || fail "vdb_lod failed"
    theirs=$(vdb_print "$work/lod.vdb" | awk '{print $1}' | sort | paste -sd' ' -)
    ours=$(vdb_print "$work/m/tree_000.vdb" | awk '{print $1}' | grep '^density_level_' | sort | paste -sd' ' -)
    [ "$theirs" = "density_level_1 density_level_2" ] && [ "$ours" = "$theirs" ] \
        || fail "vdb_lod's levels ($theirs) are not named as ours ($ours)"
else
    fail "vdb_lod is missing (libopenvdb-tools)"
fi

# A render reads the proxies back onto the scene's voxels: the image is the in-process bake's.
trees=("$work/m/tree_000.vdb" "$work/m/tree_001.vdb" "$work/m/tree_002.vdb")
"$vdbtrace" render "$work/scene.json" --method reference --voxel-size 2 --out "$work/inproc.exr" 2>"$work/err" \
    || fail "render, in-process bake: $(tail -1 "$work/err")"
"$vdbtrace" render "$work/scene.json" --method reference --grids "${trees[@]}" --out "$work/proxies.exr" 2>"$work/err" \
    || fail "render of the proxies: $(tail -1 "$work/err")"
grep -q "warning" "$work/err" && fail "verified proxies gave a warning: $(cat "$work/err")"
idiff -q -fail 1e-6 -failpercent 0 "$work/inproc.exr" "$work/proxies.exr" >/dev/null 2>&1 \
    || fail "the proxies' render differs from the in-process bake's: $(idiff "$work/inproc.exr" "$work/proxies.exr" | tail -3)"

# Grids of another scene, or of this scene's tree moved, are refused in one line.
"$bake" tree "$src/scenes/bough.json" --tree 0 --voxel-size 2 --out "$work/other.vdb" 2>/dev/null
expect_error "grids of another scene" 2 "was baked from tree 0 of '.*bough.json', whose boughs differ" -- \
    render "$work/scene.json" --method reference --grids "$work/other.vdb" --out "$work/x.exr"
/usr/bin/python3 - "$work/scene.json" "$work/moved.json" <<'PY'
import json, sys
scene = json.load(open(sys.argv[1]))
scene["trees"] = scene["trees"][:1]
json.dump(scene, open(sys.argv[2], "w"))
PY
expect_error "a tree the scene lacks" 2 "was baked from tree 2 of .*which '.*moved.json' does not have (it has 1)" -- \
    render "$work/moved.json" --method reference --grids "$work/m/tree_002.vdb" --out "$work/x.exr"
[ -e "$work/x.exr" ] && fail "a refused render wrote its image"

expect_error "one tree twice" 2 "are both tree 1 of" -- render "$work/scene.json" --method reference \
    --grids "$work/m/tree_001.vdb" "$work/cm/tree_001.vdb" --out "$work/x.exr"
"$vdbtrace" render "$work/scene.json" --method reference --grids "$work/m/tree_001.vdb" --out "$work/some.exr" 2>"$work/err" \
    || fail "render of one tree's proxy: $(tail -1 "$work/err")"
grep -q "warning: --grids holds 1 of the 3 trees" "$work/err" || fail "no warning for missing trees: $(cat "$work/err")"

# Without its manifest (copied or edited elsewhere) a proxy is read, with a warning.
rm "$work/m/tree_001.vdb.json"
"$vdbtrace" render "$work/scene.json" --method reference --grids "${trees[@]}" --out "$work/unverified.exr" 2>"$work/err" \
    || fail "render of an unverified proxy: $(tail -1 "$work/err")"
grep -q "warning: '.*tree_001.vdb': no manifest 'tree_001.vdb.json' beside it: read from its metadata alone, unverified" "$work/err" \
    || fail "no warning for an unverified proxy: $(cat "$work/err")"

echo "proxy interop: $failures failed"
[ "$failures" -eq 0 ]
