#!/usr/bin/env bash
# A full disk, as a small tmpfs: every tool exits 2 with one line, leaves the previous file as
# it was and no temporary behind. Needs root (mount); skipped (77) where it cannot mount.
# Usage: full_disk_test.sh VDBTRACE BAKE SOURCE_DIR ANALYTIC
set -u
vdbtrace=$1
bake=$2
src=$3
analytic=$4
tool=$vdbtrace
# shellcheck source=cli_test_lib.sh
source "$(dirname "$0")/cli_test_lib.sh"
disk=$work/disk
mkdir "$disk"
mount_disk() {  # mount_disk BYTES: a fresh tmpfs of that size at $disk
    umount "$disk" 2>/dev/null
    mount -t tmpfs -o "size=$1" tmpfs "$disk" 2>/dev/null
}
mount_disk 1m || { echo "full_disk_test: cannot mount a tmpfs here: skipped"; exit 77; }
trap 'umount "$disk" 2>/dev/null; rm -rf "$work"' EXIT
scene=$src/scenes/bough.json

# The sizes of what a render writes, measured off the disk under test.
"$vdbtrace" render "$scene" --out "$work/b.exr" 2>/dev/null || fail "render of bough.json failed"
exr=$(stat -c %s "$work/b.exr")
png=$(stat -c %s "$work/b.png")

leftovers() { ls -A "$disk" | grep '\.tmp-' ; }

# Too small for the EXR: nothing new under a final name, the previous image kept.
mount_disk $((exr / 2))
echo old >"$disk/b.exr"
# (found after the render: its progress lines come first, the error last)
"$vdbtrace" render "$scene" --out "$disk/b.exr" >"$work/out" 2>"$work/err"
[ $? -eq 2 ] || fail "EXR onto a full disk: exit status is not 2"
tail -1 "$work/err" | grep -q "b.exr" || fail "EXR onto a full disk: $(tail -1 "$work/err")"
[ "$(cat "$disk/b.exr")" = old ] || fail "a failed EXR write replaced the previous file"
[ ! -e "$disk/b.png" ] || fail "a failed render left a PNG"
[ -z "$(leftovers)" ] || fail "temporaries left: $(leftovers)"

# Room for the EXR, not for its PNG: the PNG is refused, the previous one kept (libpng alone
# does not report a short write), and so is the previous EXR: no new EXR beside an old preview.
mount_disk $((exr + png / 2))
echo old >"$disk/b.png"
echo old >"$disk/b.exr"
"$vdbtrace" render "$scene" --out "$disk/b.exr" >"$work/out" 2>"$work/err"
[ $? -eq 2 ] || fail "PNG onto a full disk: exit status is not 2"
tail -1 "$work/err" | grep -q "b.png" || fail "PNG onto a full disk: $(tail -1 "$work/err")"
[ "$(cat "$disk/b.png")" = old ] || fail "a failed PNG write replaced the previous file"
[ "$(cat "$disk/b.exr")" = old ] || fail "a failed PNG write left a new EXR beside the old PNG"
[ -z "$(leftovers)" ] || fail "temporaries left: $(leftovers)"

# bake: the previous grid and manifest stay a matching pair.
tool=$bake
"$bake" tree "$scene" --tree 0 --voxel-size 0.5 --out "$work/t.vdb" 2>/dev/null || fail "bake failed"
vdb=$(stat -c %s "$work/t.vdb")
mount_disk $((vdb / 2))
echo old >"$disk/t.vdb"
echo '{}' >"$disk/t.vdb.json"
expect_error "bake onto a full disk" 2 "t.vdb" -- tree "$scene" --tree 0 --voxel-size 0.5 --out "$disk/t.vdb"
[ "$(cat "$disk/t.vdb")" = old ] && [ "$(cat "$disk/t.vdb.json")" = '{}' ] \
    || fail "a failed bake replaced the previous pair"
[ -z "$(leftovers)" ] || fail "temporaries left: $(leftovers)"

# analytic sweep: its tables onto a disk with room for none of them (exit 2, not 1).
tool=$analytic
mount_disk 4k
"$analytic" sweep --out "$disk/sweep" --cone-cases 50 --no-plot >"$work/out" 2>"$work/err"
[ $? -eq 2 ] || fail "sweep onto a full disk: exit status is not 2"
# (found after a stage of the sweep: its progress lines come first, the error last)
tail -1 "$work/err" | grep -q "f_fit.csv': No space left" || fail "sweep onto a full disk: $(tail -1 "$work/err")"
[ -z "$(find "$disk" -name '*.tmp-*')" ] || fail "sweep left temporaries: $(find "$disk" -name '*.tmp-*')"

echo "full disk: $failures failed"
[ "$failures" -eq 0 ]
