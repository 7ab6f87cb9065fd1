#!/usr/bin/env bash
# bake as a user runs it: exit codes, one-line errors, nothing written on failure, real
# outputs on success. Usage: bake_cli_test.sh BAKE SOURCE_DIR
set -u
bake=$1
src=$2
tool=$bake
# shellcheck source=cli_test_lib.sh
source "$(dirname "$0")/cli_test_lib.sh"

bough=$src/scenes/bough.json
expect_error "missing scene" 2 "missing.json" -- tree "$work/missing.json" --tree 0 --voxel-size 1 --out "$work/a.vdb"
printf '{"camera": {' >"$work/broken.json"
expect_error "malformed scene" 2 "broken.json:1:" -- tree "$work/broken.json" --tree 0 --voxel-size 1 --out "$work/a.vdb"
expect_error "malformed scene, all trees" 2 "broken.json:1:" -- scene "$work/broken.json" --voxel-size 1 --out-dir "$work"
expect_error "unwritable output" 2 "no/such/dir" -- tree "$bough" --tree 0 --voxel-size 1 --out "$work/no/such/dir/a.vdb"
expect_error "output folder that cannot be made" 2 "broken.json/dir" -- scene "$bough" --voxel-size 1 --out-dir "$work/broken.json/dir"
# The output is checked before the scene is read, and before any work.
expect_error "unwritable output, bad scene" 2 "no/such/dir" -- tree "$work/broken.json" --tree 0 --voxel-size 1 --out "$work/no/such/dir/a.vdb"
expect_error "no such tree" 2 "no tree 5" -- tree "$bough" --tree 5 --voxel-size 1 --out "$work/a.vdb"
expect_error "zero voxel size" 2 "voxel-size" -- tree "$bough" --tree 0 --voxel-size 0 --out "$work/a.vdb"
expect_error "negative voxel size" 2 "voxel-size" -- scene "$bough" --voxel-size -1 --out-dir "$work"
# Near 1e308 OpenVDB cannot invert the grid's transform: refused before the bake, no folder made.
expect_error "huge voxel size" 2 "voxel size must be > 0 and at most 100000 cm" -- tree "$bough" --tree 0 --voxel-size 1e308 --out "$work/a.vdb"
expect_error "huge voxel size, all trees" 2 "at most 100000 cm" -- scene "$bough" --voxel-size 1e308 --out-dir "$work/never"
[ ! -e "$work/never" ] || fail "a refused scene bake made its folder"
expect_error "bad levels" 2 "levels" -- tree "$bough" --tree 0 --voxel-size 1 --levels 0 --out "$work/a.vdb"
expect_error "missing option" 2 "out" -- tree "$bough" --tree 0 --voxel-size 1
expect_error "no subcommand" 2 "subcommand" --
expect_error "grids not named .vdb" 2 "must end in .vdb" -- tree "$bough" --tree 0 --voxel-size 1 --out "$work/a.exr"
expect_error "unknown unit" 2 "units" -- tree "$bough" --tree 0 --voxel-size 1 --units ft --out "$work/a.vdb"
expect_error "unknown frame" 2 "frame" -- scene "$bough" --voxel-size 1 --frame local --out-dir "$work"
# Voxels too fine for the machine: refused before the bake.
expect_error "fine voxels, one tree" 2 "voxels of 0.001 cm" -- tree "$src/scenes/three-firs.json" --tree 2 --voxel-size 1e-3 --out "$work/a.vdb"
# Voxels so fine that their count overflows: said so, not "inf voxels ... inf GiB".
expect_error "voxels past counting" 2 "more than 1e308 voxels of 1e-300 cm would need more memory than any machine has" -- \
    tree "$src/scenes/bough.json" --tree 0 --voxel-size 1e-300 --out "$work/a.vdb"
expect_error "fine voxels, all trees" 2 "more than --max-memory" -- scene "$bough" --voxel-size 0.05 --max-memory 0.01 --out-dir "$work"
# A scene in the output folder under a tree file's name is not baked over.
mkdir "$work/inplace"
cp "$bough" "$work/inplace/tree_000.vdb"
expect_error "output is the scene" 2 "also an input" -- scene "$work/inplace/tree_000.vdb" --voxel-size 1 --out-dir "$work/inplace"
expect_error "tree onto the scene" 2 "also an input" -- tree "$work/inplace/tree_000.vdb" --tree 0 --voxel-size 1 --out "$work/inplace/tree_000.vdb"
cmp -s "$bough" "$work/inplace/tree_000.vdb" || fail "a refused bake changed the scene"
[ "$(ls "$work/inplace")" = tree_000.vdb ] || fail "a refused bake left files: $(ls "$work/inplace")"
rm -r "$work/inplace"
[ -z "$(ls -A "$work" | grep -v -e '^out$' -e '^err$' -e '^broken.json$')" ] || fail "failed runs left files: $(ls -A "$work")"
# A missing output folder is made, as with mkdir -p.
"$tool" scene "$bough" --voxel-size 1 --out-dir "$work/new/dir" 2>/dev/null \
    && [ -f "$work/new/dir/tree_000.vdb" ] || fail "bake scene did not make its output folder"
rm -r "$work/new"
# verify: one line per file, status 2 when any is refused.
mkdir "$work/v"
"$tool" tree "$bough" --tree 0 --voxel-size 1 --out "$work/v/a.vdb" 2>/dev/null
cp "$work/v/a.vdb" "$work/v/b.vdb"
printf 'x' >>"$work/v/b.vdb"
cp "$work/v/a.vdb.json" "$work/v/b.vdb.json"
"$tool" verify "$work/v" >"$work/out" 2>"$work/err"
[ $? -eq 2 ] || fail "verify of a damaged file: exit status is not 2"
grep -q "a.vdb: ok, " "$work/out" || fail "verify: $(cat "$work/out")"
grep -q "b.vdb: refused: .*bytes, the manifest says" "$work/out" || fail "verify: $(cat "$work/out")"
grep -q "1 of 2 files read whole" "$work/err" || fail "verify: $(cat "$work/err")"
# Without its manifest a bake is read from its metadata, and said to be unverified.
rm "$work/v/b.vdb" "$work/v/b.vdb.json" "$work/v/a.vdb.json"
"$tool" verify "$work/v/a.vdb" >"$work/out" 2>"$work/err"
[ $? -eq 3 ] || fail "verify without a manifest: exit status is not 3: $(cat "$work/out")"
grep -q "1 of 1 files read whole, 1 of them unverified" "$work/err" || fail "verify: $(cat "$work/err")"
grep -q "a.vdb: unverified, .*no manifest 'a.vdb.json'" "$work/out" || fail "verify: $(cat "$work/out")"
# A device is named as such, not as a missing file.
"$tool" verify /dev/zero >"$work/out" 2>"$work/err"
[ $? -eq 2 ] || fail "verify of a device: exit status is not 2"
grep -q "^/dev/zero: refused: '/dev/zero': not a regular file$" "$work/out" || fail "verify of a device: $(cat "$work/out")"
rm -r "$work/v"

# One tree: the .vdb, its manifest and its branch mesh; one summary line.
"$bake" tree "$bough" --tree 0 --voxel-size 0.5 --out "$work/b.vdb" 2>"$work/err" \
    || fail "bake tree of bough.json failed: $(tail -1 "$work/err")"
for f in b.vdb b.vdb.json b.obj; do [ -s "$work/$f" ] || fail "missing output $f"; done
[ "$(wc -l <"$work/err")" -eq 1 ] || fail "bake tree: stderr is not one line: $(cat "$work/err")"
grep -q "1 tree, [1-9][0-9]* voxels, [1-9][0-9]* bytes" "$work/err" || fail "no summary line: $(cat "$work/err")"
grep -q '"fnv1a64"' "$work/b.vdb.json" || fail "manifest lacks fnv1a64"

# All trees of a scene, in parallel: tree_000.vdb ... and a summary line last. The temporaries
# a killed bake left (of every file it writes) are removed.
mkdir "$work/forest"
for stale in .tree_000.vdb.tmp-0123456789abcdef .tree_001.obj.tmp-0123456789abcdef \
             .instances.json.tmp-fedcba9876543210 .tree_002.vdb.json.tmp-00000000000000aa; do
    echo half >"$work/forest/$stale"
done
"$bake" scene "$src/scenes/three-firs.json" --voxel-size 2 --levels 2 --out-dir "$work/forest" 2>"$work/err" \
    || fail "bake scene of three-firs.json failed: $(tail -1 "$work/err")"
for f in tree_000.vdb tree_000.vdb.json tree_000.obj tree_002.vdb tree_002.vdb.json instances.json; do
    [ -s "$work/forest/$f" ] || fail "missing output forest/$f"
done
[ "$(ls -A "$work/forest" | grep -c '\.vdb$')" -eq 3 ] || fail "expected 3 trees: $(ls -A "$work/forest")"
[ -z "$(ls -A "$work/forest" | grep -v -e '\.vdb$' -e '\.vdb\.json$' -e '\.obj$' -e '^instances\.json$')" ] \
    || fail "temporary files left: $(ls -A "$work/forest")"
/usr/bin/python3 - "$work/forest/instances.json" <<'EOF2' || fail "instances.json does not list the three trees"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["format"] == "pine-instances" and j["units"] == "m", j
assert [i["grids"] for i in j["instances"]] == ["tree_000.vdb", "tree_001.vdb", "tree_002.vdb"], j
assert all(i["mesh"].endswith(".obj") and len(i["tree_to_world"]) == 4 for i in j["instances"]), j
EOF2
tail -1 "$work/err" | grep -q "3 trees, .* voxels, .* bytes, .* s, peak .* MiB" || fail "no summary line: $(tail -1 "$work/err")"
# A scene of fewer trees baked into the same folder removes the files the previous list named
# and the new one does not; verify calls a tree file the folder's list does not name unverified.
mkdir "$work/kept" && cp "$work/forest/tree_002.vdb" "$work/forest/tree_002.vdb.json" "$work/kept/"
"$bake" scene "$bough" --voxel-size 2 --levels 2 --out-dir "$work/forest" 2>"$work/err" \
    || fail "bake scene of bough.json over three firs failed: $(tail -1 "$work/err")"
grep -q "removed 6 files of the previous bake in '$work/forest'" "$work/err" || fail "no removal line: $(cat "$work/err")"
[ "$(ls -A "$work/forest" | tr '\n' ' ')" = "instances.json tree_000.obj tree_000.vdb tree_000.vdb.json " ] \
    || fail "a smaller scene's bake left: $(ls -A "$work/forest")"
"$bake" verify "$work/forest" >"$work/out" 2>/dev/null || fail "verify of a rebaked folder: $(cat "$work/out")"
cp "$work/kept/"* "$work/forest/"
"$bake" verify "$work/forest" >"$work/out" 2>"$work/err"
[ $? -eq 3 ] || fail "verify of an unlisted tree file: exit status is not 3: $(cat "$work/out")"
grep -q "tree_000.vdb: ok, " "$work/out" || fail "verify: $(cat "$work/out")"
grep -q "tree_002.vdb: unverified, .*(not in $work/forest/instances.json, left by another bake?)$" "$work/out" \
    || fail "verify of an unlisted tree file: $(cat "$work/out")"
# The previous list's names are trusted only as bare names of regular files: never the list
# itself, the scene, a folder or a file outside; a list that is not one removes nothing.
mkdir -p "$work/safe/sub"
cp "$bough" "$work/safe/scene.json"
echo keep >"$work/outside.vdb"
echo '{"format": "pine-instances", "instances": [{"grids": "../outside.vdb", "mesh": "instances.json"},
      {"grids": "scene.json", "mesh": "sub"}]}' >"$work/safe/instances.json"
"$bake" scene "$work/safe/scene.json" --voxel-size 2 --levels 1 --out-dir "$work/safe" 2>"$work/err" \
    || fail "bake over a hostile list failed: $(tail -1 "$work/err")"
[ -f "$work/outside.vdb" ] && [ -f "$work/safe/scene.json" ] && [ -d "$work/safe/sub" ] && [ -s "$work/safe/instances.json" ] \
    || fail "a hostile list removed what it must not: $(ls -A "$work" "$work/safe")"
grep -q "removed" "$work/err" && fail "a hostile list removed something: $(cat "$work/err")"
echo '{"format": 5, "instances": [{"grids": "tree_000.obj"}]}' >"$work/safe/instances.json"
"$bake" scene "$work/safe/scene.json" --voxel-size 2 --levels 1 --out-dir "$work/safe" 2>"$work/err" \
    || fail "bake over a list of another format failed: $(tail -1 "$work/err")"
[ -f "$work/safe/tree_000.obj" ] || fail "a list of another format removed a file"
if command -v vdb_print >/dev/null; then
    vdb_print "$work/forest/tree_000.vdb" | grep -q "density_level_1" || fail "vdb_print lacks density_level_1"
fi

"$bake" --help >/dev/null || fail "--help"
"$bake" tree --help >/dev/null || fail "tree --help"
"$bake" scene --help >/dev/null || fail "scene --help"

echo "bake cli: $failures failed"
[ "$failures" -eq 0 ]
