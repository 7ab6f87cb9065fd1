#!/usr/bin/env bash
# `cmake --install` as a user runs it: the installed tools work from any folder, on the installed
# scenes, and start the installed plot script (not the source tree's).
# Usage: install_test.sh BUILD_DIR
set -u
build=$1
tool=true
# shellcheck source=cli_test_lib.sh
source "$(dirname "$0")/cli_test_lib.sh"

prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" >"$work/log" 2>&1 || { echo "FAIL: install: $(tail -3 "$work/log")"; exit 1; }
for f in bin/vdbtrace bin/bake bin/analytic share/pine/plot_compare.py share/pine/plot_sweep.py \
         share/pine/scenes/bough.json share/doc/PineMultiscale/README.md; do
    [ -e "$prefix/$f" ] || fail "not installed: $f"
done
# The image module, where the installed tools look for it (src/image_codec.h).
find "$prefix" -path "*/pine/libpine_image_codec.so" | grep -q . ||
    fail "not installed: the image module"
cd /
"$prefix/bin/vdbtrace" --version | grep -q "^vdbtrace [0-9]" || fail "installed vdbtrace --version"
"$prefix/bin/vdbtrace" render "$prefix/share/pine/scenes/bough.json" --resolution 32x24 \
    --out "$work/b.exr" -q || fail "installed vdbtrace cannot render an installed scene"
[ -s "$work/b.exr" ] && [ -s "$work/b.png" ] || fail "installed render wrote no image"
"$prefix/bin/bake" tree "$prefix/share/pine/scenes/bough.json" --tree 0 --voxel-size 1 \
    --out "$work/b.vdb" -q || fail "installed bake"
# The installed plot script is the one compare starts: replaced by one that leaves a mark.
printf 'import sys, pathlib\npathlib.Path(sys.argv[1], "installed-plot-ran").write_text("yes")\n' \
    >"$prefix/share/pine/plot_compare.py"
"$prefix/bin/vdbtrace" compare "$prefix/share/pine/scenes/bough.json" --quick --resolution 32x24 \
    --out-dir "$work/cmp" -q 2>"$work/err" || fail "installed compare: $(tail -1 "$work/err")"
[ -e "$work/cmp/installed-plot-ran" ] || fail "compare did not start the installed plot script"

echo "install: $failures failed"
[ "$failures" -eq 0 ]
