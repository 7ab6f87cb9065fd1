#!/usr/bin/env bash
# vdbtrace as a user runs it: exit codes, one-line errors, nothing written on failure, real
# outputs on success. Usage: vdbtrace_cli_test.sh VDBTRACE SOURCE_DIR
set -u
vdbtrace=$1
src=$2
tool=$vdbtrace
# shellcheck source=cli_test_lib.sh
source "$(dirname "$0")/cli_test_lib.sh"

expect_error "missing scene" 2 "missing.json" -- render "$work/missing.json" --out "$work/a.exr"
printf '{"camera": {' >"$work/broken.json"
expect_error "malformed scene" 2 "broken.json:1:" -- render "$work/broken.json" --out "$work/a.exr"
expect_error "unwritable output" 2 "no/such/dir" -- render "$src/scenes/bough.json" --out "$work/no/such/dir/a.exr"
expect_error "unknown method" 2 "not available" -- render "$src/scenes/bough.json" --method nonsense --out "$work/a.exr"
expect_error "bad option" 2 "force-level" -- render "$src/scenes/bough.json" --out "$work/a.exr" --force-level 7
# An unknown option is named, though CLI11 finds what is missing first.
expect_error "unknown option, scene missing" 2 "not expected: --bogus (see --help)" -- render --bogus
expect_error "misspelt --out" 2 "not expected: --ot a.exr (see --help)" -- render "$src/scenes/bough.json" --ot a.exr
expect_error "threads not a number" 2 "threads: must be a whole number >= 0, got 'abc'" -- render "$src/scenes/bough.json" --out "$work/a.exr" --threads abc
expect_error "a voxel size of nan" 2 "voxel-size: must be a number > 0, got 'nan'" -- render "$src/scenes/bough.json" --method reference --out "$work/a.exr" --voxel-size nan
expect_error "a voxel size of 1e308" 2 "voxel size must be > 0 and at most 100000 cm" -- render "$src/scenes/bough.json" --method reference --out "$work/a.exr" --voxel-size 1e308
expect_error "another method's option" 2 "samples applies to --method geometry, not multiscale" -- render "$src/scenes/bough.json" --out "$work/a.exr" --samples 4
expect_error "another method's option" 2 "voxel-size applies to --method reference, not geometry" -- render "$src/scenes/bough.json" --method geometry --out "$work/a.exr" --voxel-size 1
[ "$("$vdbtrace" --version)" = "vdbtrace $(sed -n 's/^project(PineMultiscale VERSION \([0-9.]*\).*/\1/p' "$src/CMakeLists.txt")" ] \
    || fail "--version: $("$vdbtrace" --version)"
# --threads after the subcommand too; progress as plain lines, in order, when stderr is a file.
"$vdbtrace" render "$src/scenes/bough.json" --out "$work/p.exr" --threads 1 2>"$work/err" \
    || fail "render with --threads after the subcommand: $(tail -1 "$work/err")"
! grep -q $'\r' "$work/err" || fail "progress with carriage returns into a file"
grep "rendering" "$work/err" | awk '{ sub("%", "", $3); if ($3 + 0 < last) bad = 1; last = $3 + 0 } END { exit bad }' \
    || fail "progress out of order: $(grep rendering "$work/err" | tr '\n' ' ')"
[ "$(grep -c rendering "$work/err")" -le 11 ] || fail "more than 11 progress lines in a file"
# On a terminal (script(1) gives it one): a bar rewritten in place, ending its line.
if command -v script >/dev/null; then
    script -q -e -c "'$vdbtrace' render '$src/scenes/bough.json' --out '$work/tty.exr'" /dev/null >"$work/tty" 2>&1 \
        || fail "render on a terminal failed: $(tail -c 300 "$work/tty")"
    grep -q $'\rvdbtrace: rendering \[#*\.*\] *[0-9]*%' "$work/tty" || fail "no progress bar on a terminal: $(head -c 300 "$work/tty" | cat -v)"
    grep -q 'rendering \[########################\] 100%' "$work/tty" || fail "the bar does not end full"
    rm -f "$work/tty" "$work/tty.exr" "$work/tty.png"
fi
grep -q "1 tree, 3 branches, 271 needles" "$work/err" || fail "counts: $(head -1 "$work/err")"
rm -f "$work/p.exr" "$work/p.png"
# Outputs that would destroy an input, each other or a device, and formats the name does not
# say: refused before any work, the files left as they were.
cp "$src/scenes/bough.json" "$work/scene.json"
expect_error "output is the scene" 2 "must end in .exr" -- render "$work/scene.json" --out "$work/scene.json"
cp "$src/scenes/bough.json" "$work/scene.exr"  # a scene's name says nothing of its format
expect_error "output is the scene, named .exr" 2 "also an input" -- render "$work/scene.exr" --out "$work/scene.exr"
cmp -s "$src/scenes/bough.json" "$work/scene.exr" || fail "a refused render changed the scene"
rm "$work/scene.exr"
expect_error "png output" 2 "must end in .exr" -- render "$work/scene.json" --out "$work/a.png"
expect_error "stats onto the image" 2 "same file" -- render "$work/scene.json" --out "$work/a.exr" --stats "$work/a.exr"
expect_error "stats onto the preview" 2 "--stats '$work/a.png' is the preview written beside '$work/a.exr': give the stats another name" -- \
    render "$work/scene.json" --out "$work/a.exr" --stats "$work/a.png"
expect_error "stats onto the scene" 2 "also an input" -- render "$work/scene.json" --out "$work/a.exr" --stats "$work/scene.json"
expect_error "device output" 2 "not a regular file" -- render "$work/scene.json" --out "$work/a.exr" --stats /dev/null
cmp -s "$src/scenes/bough.json" "$work/scene.json" || fail "a refused render changed the scene"
# A finite but enormous light would overflow float radiance: refused from the scene, before
# any tree is grown or pixel traced (the render's own check, after it, is render_driver_test's).
sed 's/"intensity": 18000/"intensity": 1e308/' "$work/scene.json" >"$work/bright.json"
grep -q 1e308 "$work/bright.json" || fail "bright.json: the light was not changed"
expect_error "a light too bright for float radiance" 2 "lights\[0\].intensity: 1e+308 times the colour .* more than float radiance can hold" -- render "$work/bright.json" --out "$work/bright.exr"
[ ! -e "$work/bright.exr" ] || fail "a refused render was written"
rm "$work/bright.json"
[ -c /dev/null ] || fail "/dev/null is no longer a device"
rm "$work/scene.json"
# A folder where a preview goes is refused before the render, which it cost, and before any
# other file is written (with --aov level the preview was written and the EXR not).
mkdir "$work/pv.png" "$work/lv.level.png"
expect_error "preview onto a folder" 2 "cannot write '.*pv.png': it is a folder" -- render "$src/scenes/bough.json" --resolution 8x6 --out "$work/pv.exr"
expect_error "level preview onto a folder" 2 "cannot write '.*lv.level.png': it is a folder" -- render "$src/scenes/bough.json" --resolution 8x6 --aov level --out "$work/lv.exr"
[ ! -e "$work/pv.exr" ] && [ ! -e "$work/lv.exr" ] && [ ! -e "$work/lv.png" ] || fail "a refused render wrote: $(ls "$work")"
rmdir "$work/pv.png" "$work/lv.level.png"
# Trees the tracer cannot hold, refused once they are grown, before any pixel: a bough of
# 1e7 cm bears 1e7 cones, each walked by the law (1e12 ran for hours without a progress
# line); a branch beyond 1e9 cm, where the tracer's float bounds end.
sed 's/"segment": 6,/"segment": 1e7,/' "$src/scenes/bough.json" >"$work/long.json"
grep -q 1e7 "$work/long.json" || fail "long.json: the segment was not changed"
expect_error "a bough of ten million cones" 2 "long.json: tree 0: a bough 1e+07 cm long bears 1.*e+07 cones .* more than 10000" -- render "$work/long.json" --resolution 16x12 --out "$work/long.exr"
sed 's/"segment": 6,/"segment": 1e12,/' "$src/scenes/bough.json" >"$work/far.json"
expect_error "a branch beyond 1e9 cm" 2 "far.json: tree 0: a branch reaches (1e+12, 0, 30) cm, more than 1000000000 cm" -- render "$work/far.json" --resolution 16x12 --out "$work/long.exr"
[ ! -e "$work/long.exr" ] || fail "a refused render was written"
rm "$work/long.json" "$work/far.json"
# Resource bombs refused from the scene alone, before any tree is grown or pixel traced.
sed 's/"resolution": \[640, 480\]/"resolution": [16384, 16384]/' "$src/scenes/bough.json" >"$work/huge.json"
grep -q 16384 "$work/huge.json" || fail "huge.json: the resolution was not changed"
expect_error "huge image" 2 "image 16384 x 16384 needs about" -- render "$work/huge.json" --out "$work/a.exr" --max-memory 8
expect_error "tiny memory limit" 2 "more than --max-memory" -- render "$src/scenes/bough.json" --out "$work/a.exr" --max-memory 0.01
newline=$'\n'
expect_error "a name with a newline" 2 "no/such" -- render "$src/scenes/bough.json" --out "$work/no/such${newline}dir/a.exr"
escape=$'\e'
expect_error "a name with a terminal escape" 2 'no/such\\x1b\[31mdir' -- render "$src/scenes/bough.json" --out "$work/no/such${escape}[31mdir/a.exr"
grep -q "$escape" "$work/err" && fail "an error line echoed a terminal escape: $(cat -v "$work/err")"
expect_error "a bad option's value with a newline" 2 "is not available" -- render "$src/scenes/bough.json" --out "$work/a.exr" --method "geo${newline}metry"
expect_error "fine voxels" 2 "voxels of 0.0001 cm" -- render "$src/scenes/three-firs.json" --method reference --voxel-size 1e-4 --out "$work/a.exr"
expect_error "compare, huge resolution" 2 "at most 16384" -- compare "$src/scenes/bough.json" --resolution 100000x100000 --out-dir "$work/cmp"
expect_error "compare, large resolution" 2 "images kept for the report needs about" -- compare "$src/scenes/bough.json" --resolution 16000x16000 --out-dir "$work/cmp" --max-memory 8
expect_error "compare, an even repeat" 2 "odd number" -- compare "$src/scenes/bough.json" --repeat 2 --out-dir "$work/cmp"
expect_error "bench, a repeat with a tail" 2 "odd number" -- bench "$src/scenes/bough.json" --repeat 3x
expect_error "compare, shadows without self-shadowing" 2 'without "self_shadowing"' -- compare "$src/scenes/hill.json" --quick --resolution 32x24 --out-dir "$work/cmp"
[ -z "$(ls -A "$work/cmp" 2>/dev/null)" ] || fail "a refused compare wrote $(ls "$work/cmp")"
rm -rf "$work/cmp"  # made, empty, by the check that it can be written
expect_error "many needles" 2 "needle cylinders" -- render "$src/scenes/paper-forest.json" --method geometry --out "$work/a.exr" --max-memory 0.3
rm "$work/huge.json"
[ -z "$(ls "$work" | grep -v -e '^out$' -e '^err$' -e '^broken.json$')" ] || fail "failed runs left files: $(ls "$work")"

# A scene (or image) in a folder of reports, under a name the run writes there, is not
# written over: each command that writes a folder refuses before any work.
mkdir "$work/inplace"
inplace() {  # NAME, then the command with @ for the copy's path
    local name=$1 copy=$work/inplace/$1
    shift
    cp "$src/scenes/bough.json" "$copy"
    local args=()
    for a in "$@"; do args+=("${a//@/$copy}"); done
    expect_error "an input named $name in the output folder" 2 "is an input of this run" -- "${args[@]}"
    cmp -s "$src/scenes/bough.json" "$copy" || fail "a refused run changed its input $name"
    rm "$copy"
}
inplace report.md compare @ --out-dir "$work/inplace" --quick --resolution 8x6 --no-plot
inplace trees.csv compare @ --out-dir "$work/inplace" --quick --resolution 8x6 --no-plot
inplace frames.csv animate-compare @ --out-dir "$work/inplace" --resolution 8x6 --no-plot
inplace growth.csv bench @ --grow resolution --grow-steps 2 --grow-dir "$work/inplace" --no-plot --geometry-samples 0
inplace step-1.json bench @ --grow resolution --grow-steps 2 --grow-dir "$work/inplace" --no-plot --geometry-samples 0
# A later frame's preview, not only the first's.
cp "$src/scenes/bough.json" "$work/inplace/a.0002.png"
expect_error "a scene named as frame 2's preview" 2 "is an input of this run" -- render "$work/inplace/a.0002.png" --out "$work/inplace/a.exr" --frames 1-3 --resolution 8x6
cmp -s "$src/scenes/bough.json" "$work/inplace/a.0002.png" || fail "a refused animation changed its scene"
[ "$(ls "$work/inplace")" = a.0002.png ] || fail "refused runs left files: $(ls "$work/inplace")"
rm -r "$work/inplace"
expect_error "frames past the limit" 2 "10000000 frames, more than 100000" -- render "$src/scenes/bough.json" --out "$work/a.exr" --frames 0-9999999
# nan is no default: CLI11's ranges let it through.
expect_error "a level blend of nan" 2 "level-blend: must be a number from 1 to 2, got 'nan'" -- render "$src/scenes/bough.json" --out "$work/a.exr" --level-blend nan
expect_error "a law cache of nan" 2 "law-cache: must be a number from 1 to 1e+07, got 'nan'" -- render "$src/scenes/bough.json" --out "$work/a.exr" --law-cache nan

# An existing output survives a failed render.
echo keep >"$work/keep.exr"
"$vdbtrace" render "$work/broken.json" --out "$work/keep.exr" 2>/dev/null
[ "$(cat "$work/keep.exr")" = keep ] || fail "a failed render overwrote an existing output"

# Success: EXR, PNG preview, level image, stats; one summary line last on stderr.
"$vdbtrace" render "$src/scenes/bough.json" --out "$work/b.exr" --stats "$work/b.json" --aov level 2>"$work/err" \
    || fail "render of bough.json failed: $(tail -1 "$work/err")"
for f in b.exr b.png b.level.png b.json; do [ -s "$work/$f" ] || fail "missing output $f"; done
tail -1 "$work/err" | grep -q "cone rays" || fail "no summary line: $(tail -1 "$work/err")"
grep -q '"shadow_rays"' "$work/b.json" || fail "stats lack shadow_rays"
# The EXR as compositors and pbrt-v4 read it: Z (infinite where nothing is hit), only the AOVs
# the method computes, typed render time, samples and camera matrices.
exr_info() { oiiotool --info -v "$1" 2>&1; }
exr_info "$work/b.exr" >"$work/info"
grep -q "channel list: R, G, B, A, Z, diffuse.Y, foliage.Y, foliage_luminance.Y, level.Y, specular.Y, tree.Y" "$work/info" \
    || fail "multiscale EXR channels: $(grep 'channel list' "$work/info")"
grep -q "samplesPerPixel: 1$" "$work/info" || fail "multiscale EXR lacks samplesPerPixel 1"
# bough.json is a close-up: no pixel of it is split, one cone each.
grep -q "pine:cones_per_pixel: 1$" "$work/info" || fail "multiscale EXR lacks pine:cones_per_pixel 1: $(grep cones_per_pixel "$work/info")"
grep -q "renderTimeSeconds: [0-9.e-]*$" "$work/info" || fail "EXR lacks a float renderTimeSeconds"
grep -q "worldToCamera: " "$work/info" && grep -q "worldToNDC: " "$work/info" || fail "EXR lacks camera matrices"
# OpenEXR's convention (row vectors): the camera's position maps to the origin, p M = 0, and
# the translation lies in the last row (a column-vector matrix would have it in the last column).
/usr/bin/python3 - "$work/info" "$src/scenes/bough.json" <<'PY' || fail "worldToCamera is not OpenEXR's row-vector matrix"
import json, re, sys
text = open(sys.argv[1]).read()
m = [float(v) for v in re.search(r"worldToCamera: ([^\n]*)", text).group(1).split(",")]
M = [m[0:4], m[4:8], m[8:12], m[12:16]]
eye = json.load(open(sys.argv[2]))["camera"]["position"] + [1.0]
image = [sum(eye[i] * M[i][j] for i in range(4)) for j in range(4)]
assert all(abs(v) < 1e-3 for v in image[:3]) and abs(image[3] - 1) < 1e-6, image
assert all(abs(M[i][3]) < 1e-9 for i in range(3)) and M[3][3] == 1.0, M
PY
grep -q 'pine:needle_level_max: 0.25$' "$work/info" || fail "level thresholds not typed: $(grep level_max "$work/info")"
oiiotool "$work/b.exr" --ch A --printstats 2>&1 | grep -q "Stats Min: 0.0* (float)" || fail "bough.json should leave background"
# Where alpha is 0 nothing is hit: Z is +inf there (oiiotool counts it as an Inf pixel).
oiiotool "$work/b.exr" --ch Z --printstats 2>&1 | grep -q "InfCount: [1-9]" || fail "Z is not infinite where nothing is hit"
"$vdbtrace" render "$src/scenes/bough.json" --method geometry --samples 2 --out "$work/g.exr" 2>/dev/null \
    || fail "geometry render failed"
exr_info "$work/g.exr" >"$work/info"
grep -q "channel list: R, G, B, A, Z, diffuse.Y, foliage.Y, foliage_luminance.Y, specular.Y, tree.Y$" "$work/info" \
    || fail "geometry EXR channels: $(grep 'channel list' "$work/info")"
grep -q "samplesPerPixel: 2$" "$work/info" || fail "geometry EXR lacks samplesPerPixel 2"
# Without --law-cache, a multiscale render whose law profiles alone would not fit --max-memory
# keeps them within what the rest leaves (at least 16 MiB): the same image, the cache within it;
# with less left, or with --law-cache given, it is refused as before.
pf="$src/scenes/paper-forest.json"
total=$("$vdbtrace" render "$pf" --resolution 320x240 --max-memory 0.0001 --out "$work/m.exr" 2>&1 \
    | sed -n 's/.*(\([0-9]*\) MiB in all).*/\1/p')
[ -n "$total" ] || fail "the refusal names no estimate in all"
limit=$(/usr/bin/python3 -c "print(($total - 6) / 1024)")
"$vdbtrace" render "$pf" --resolution 320x240 --out "$work/m0.exr" -q || fail "paper forest failed"
"$vdbtrace" render "$pf" --resolution 320x240 --max-memory "$limit" --out "$work/m1.exr" \
    --stats "$work/m1.json" 2>"$work/err" || fail "a render its law profiles can fit was refused: $(tail -1 "$work/err")"
budget=$(sed -n 's/.*law profiles within \([0-9]*\) MiB.*/\1/p' "$work/err")
[ -n "$budget" ] || fail "the render did not say it bounds its law profiles: $(cat "$work/err")"
idiff -q -fail 0 -failpercent 0 "$work/m0.exr" "$work/m1.exr" >/dev/null 2>&1 \
    || fail "bounded law profiles changed the image: $(idiff "$work/m0.exr" "$work/m1.exr" | tail -2)"
/usr/bin/python3 - "$work/m1.json" "$budget" <<'PY2' || fail "the law profiles were not kept within the budget"
import json, sys
p = json.load(open(sys.argv[1]))["law_profiles"]
assert p["peak_bytes"] <= int(sys.argv[2]) * 2**20, p
assert p["views"]["dropped"] + p["from_lights"]["dropped"] > 0, p
PY2
expect_error "too little left for law profiles" 2 "max-memory" -- render "$pf" --resolution 320x240 \
    --max-memory "$(/usr/bin/python3 -c "print(($total - 20) / 1024)")" --out "$work/m2.exr"
expect_error "a --law-cache too large" 2 "max-memory" -- render "$pf" --resolution 320x240 \
    --max-memory "$limit" --law-cache 200 --out "$work/m2.exr"

# Each render carries its trees' foliage summed fragment by fragment; `diff` judges each tree
# by them: its biases are the two headers' ratios.
"$vdbtrace" diff "$work/b.exr" "$work/g.exr" --out "$work/bd" 2>/dev/null || fail "diff failed"
{ exr_info "$work/b.exr"; echo "--- reference"; cat "$work/info"; } >"$work/both"
/usr/bin/python3 - "$work/both" "$work/bd/errors.json" <<'PY2' || fail "diff's per-tree biases are not the headers' sums'"
import json, re, sys
image, reference = open(sys.argv[1]).read().split("--- reference")
def sums(text):
    rows = json.loads(json.loads(re.search(r'pine:tree_foliage: (".*")', text).group(1)))
    return {t: (c, l) for t, c, l in rows}
a, b = sums(image), sums(reference)
j = json.load(open(sys.argv[2]))
assert j["tree_attribution"] == "fragments", j.get("tree_attribution")
assert [r["tree"] for r in j["trees"]] == sorted(b), (j["trees"], b)
for r in j["trees"]:
    (ca, la), (cb, lb) = a[r["tree"]], b[r["tree"]]
    assert abs(r["coverage_bias"] - (ca / cb - 1)) < 1e-12, r
    assert abs(r["luminance_bias"] - ((la / ca) / (lb / cb) - 1)) < 1e-12, r
PY2
# A render box-filtered to the truth's pixels after it was written (scripts/forest_levels.sh)
# keeps the sums of its own pixels: diff reads them in the resized image's, by the frame its
# header names (they had read 4 times the coverage here, 16 times at a quarter's footprints).
"$vdbtrace" render "$src/scenes/bough.json" --resolution 1280x960 --out "$work/b2.exr" 2>/dev/null \
    || fail "a 1280x960 render of bough.json failed"
exr_info "$work/b2.exr" | grep -q "pine:tree_foliage_frame: \"1280x960\"" \
    || fail "the render's header does not name the frame of its sums"
oiiotool "$work/b2.exr" --resize:filter=box 640x480 -o "$work/b2s.exr" || fail "oiiotool --resize failed"
"$vdbtrace" diff "$work/b2s.exr" "$work/g.exr" --out "$work/b2d" 2>/dev/null || fail "diff of a resized render failed"
{ exr_info "$work/b2s.exr"; echo "--- same"; cat "$work/bd/errors.json"; } >"$work/both"
/usr/bin/python3 - "$work/both" "$work/b2d/errors.json" <<'PY2' || fail "diff read a resized render's sums in the pixels it was rendered with"
import json, re, sys
header, native = open(sys.argv[1]).read().split("--- same")
rows = json.loads(json.loads(re.search(r'pine:tree_foliage: (".*")', header).group(1)))
coverage = {t: c / 4 for t, c, l in rows}
native = {r["tree"]: r for r in json.loads(native)["trees"]}
j = json.load(open(sys.argv[2]))
assert j["trees"], j
for r in j["trees"]:
    assert abs(r["coverage"] - coverage[r["tree"]]) <= 1e-9 * coverage[r["tree"]], r
    # The same bough at half the footprint: its coverage bias as at the scene's own pixels.
    assert abs(r["coverage_bias"] - native[r["tree"]]["coverage_bias"]) < 0.05, (r, native)
PY2
# diff: no folder named; an image in the folder as error.exr; a refused pair makes no folder.
expect_error "diff into no folder" 2 "--out: no folder named" -- diff "$work/b.exr" "$work/g.exr" --out ''
mkdir "$work/din" && cp "$work/b.exr" "$work/din/error.exr"
expect_error "diff over its image" 2 "is an input of this run" -- diff "$work/din/error.exr" "$work/g.exr" --out "$work/din"
cmp -s "$work/b.exr" "$work/din/error.exr" || fail "a refused diff changed its image"
rm -r "$work/din"
# A folder where errors.json goes: refused before error.exr is written.
mkdir -p "$work/din/errors.json"
expect_error "diff onto a folder" 2 "cannot write '.*errors.json': it is a folder" -- diff "$work/b.exr" "$work/g.exr" --out "$work/din"
[ "$(ls "$work/din")" = errors.json ] || fail "a refused diff wrote: $(ls "$work/din")"
rm -r "$work/din"
"$vdbtrace" render "$src/scenes/bough.json" --resolution 9x6 --out "$work/odd.exr" -q || fail "a 9x6 render failed"
expect_error "diff of two sizes" 2 "differ in size" -- diff "$work/b.exr" "$work/odd.exr" --out "$work/dnew"
[ ! -e "$work/dnew" ] || fail "a refused diff made its folder"
expect_error "diff scale below 0" 2 "scale: must be a number >= 0, got '-1'" -- diff "$work/b.exr" "$work/g.exr" --out "$work/bd" --scale -1
# --sample-seed 0 is the default pattern; another seed is another (independent) image. The
# double-precision cylinders render what the native curves render but for rounding.
"$vdbtrace" render "$src/scenes/bough.json" --method geometry --samples 2 --sample-seed 0 --out "$work/g0.exr" -q \
    && idiff -q -fail 0 -failpercent 0 "$work/g.exr" "$work/g0.exr" >/dev/null 2>&1 \
    || fail "--sample-seed 0 is not the default pattern"
"$vdbtrace" render "$src/scenes/bough.json" --method geometry --samples 2 --sample-seed 1 --out "$work/g1.exr" -q \
    || fail "--sample-seed 1 failed"
idiff -q -fail 0.01 "$work/g.exr" "$work/g1.exr" >/dev/null 2>&1 && fail "--sample-seed 1 renders the same samples"
"$vdbtrace" render "$src/scenes/bough.json" --method geometry --samples 2 --needle-primitive cylinder --out "$work/gc.exr" -q \
    || fail "--needle-primitive cylinder failed"
idiff -q -fail 1e-3 -failpercent 0.5 -warn 1e-3 -warnpercent 0.5 "$work/g.exr" "$work/gc.exr" >/dev/null 2>&1 \
    || fail "curves and cylinders differ: $(idiff -fail 1e-3 "$work/g.exr" "$work/gc.exr" | tail -3)"
expect_error "an unknown primitive" 2 "needle-primitive" -- render "$src/scenes/bough.json" --method geometry --out "$work/a.exr" --needle-primitive capsule
# Flat needle ends draw the end discs the default's open needles pass, and the stats say which.
"$vdbtrace" render "$src/scenes/bough.json" --method geometry --samples 2 --needle-ends flat --out "$work/gf.exr" --stats "$work/gf.json" -q \
    || fail "--needle-ends flat failed"
idiff -q -fail 1e-3 "$work/g.exr" "$work/gf.exr" >/dev/null 2>&1 && fail "--needle-ends flat renders the open needles"
grep -q '"needle_ends": *"flat"' "$work/gf.json" || fail "the stats do not name the flat ends: $(cat "$work/gf.json")"
expect_error "unknown needle ends" 2 "needle-ends" -- render "$src/scenes/bough.json" --method geometry --out "$work/a.exr" --needle-ends round
expect_error "an unknown bark" 2 "bark" -- render "$src/scenes/bough.json" --out "$work/a.exr" --bark wood
expect_error "an unknown layer correlation" 2 "layer-correlation" -- render "$src/scenes/bough.json" --out "$work/a.exr" --layer-correlation some
expect_error "another method's option" 2 "sample-seed applies to --method geometry, not multiscale" -- render "$src/scenes/bough.json" --out "$work/a.exr" --sample-seed 3
# A crop is the whole frame's pixels, as the EXR's data window; --resolution keeps the view;
# --quiet leaves stderr empty on success.
for m in multiscale geometry; do
    "$vdbtrace" render "$src/scenes/bough.json" --method $m --resolution 64x48 --out "$work/full.exr" --quiet 2>"$work/err" \
        || fail "render --resolution ($m): $(cat "$work/err")"
    [ -s "$work/err" ] && fail "--quiet wrote to stderr: $(cat "$work/err")"
    "$vdbtrace" render "$src/scenes/bough.json" --method $m --resolution 64x48 --crop 10,5,50,40 --out "$work/crop.exr" -q 2>/dev/null \
        || fail "render --crop ($m) failed"
    oiiotool --info -v "$work/crop.exr" >"$work/info"
    grep -q "40 x   35" "$work/info" && grep -q "pixel data origin: x=10, y=5" "$work/info" \
        && grep -q "full/display size: 64 x 48" "$work/info" || fail "crop window: $(cat "$work/info")"
    oiiotool "$work/full.exr" --crop 40x35+10+5 -o "$work/full-crop.exr"
    idiff -q -fail 0 -failpercent 0 "$work/full-crop.exr" "$work/crop.exr" >/dev/null 2>&1 \
        || fail "the crop ($m) differs from the frame's pixels: $(idiff "$work/full-crop.exr" "$work/crop.exr" | tail -2)"
done
oiiotool --info "$work/full.exr" | grep -q "64 x   48" || fail "--resolution not applied: $(oiiotool --info "$work/full.exr")"
expect_error "crop outside the frame" 2 "crop 0,0,100,10 reaches outside the 64 x 48 frame" -- \
    render "$src/scenes/bough.json" --resolution 64x48 --crop 0,0,100,10 --out "$work/c.exr"
expect_error "crop backwards" 2 "crop" -- render "$src/scenes/bough.json" --crop 10,10,5,20 --out "$work/c.exr"
expect_error "bad resolution" 2 "resolution" -- render "$src/scenes/bough.json" --resolution 0x10 --out "$work/c.exr"
[ -e "$work/c.exr" ] && fail "a refused crop wrote an image"
expect_error "level image of a method without levels" 2 "--aov level: method 'geometry' has no levels" -- \
    render "$src/scenes/bough.json" --method geometry --aov level --out "$work/g2.exr"

# The models: faithful by default, --paper as printed, recorded in the stats; a scene naming an
# unknown one is refused with its key.
grep -q '"bough_law": "exact"' "$work/b.json" || fail "default bough law not recorded as exact"
grep -q '"layer_model": "fibre"' "$work/b.json" || fail "default layer model not recorded as fibre"
"$vdbtrace" render "$src/scenes/bough.json" --paper --out "$work/p.exr" --stats "$work/p.json" 2>"$work/err" \
    || fail "render --paper failed: $(tail -1 "$work/err")"
grep -q '"bough_law": "linear"' "$work/p.json" || fail "--paper did not choose the linear law"
grep -q '"layer_model": "paper"' "$work/p.json" || fail "--paper did not choose the paper's layers"
grep -q '"shadow_origin": "axis"' "$work/p.json" || fail "--paper did not choose shadows from the axis"
grep -q '"shadow_origin": "needles"' "$work/b.json" || fail "default shadow origin not recorded as needles"
grep -q '"level_blend": 1.5' "$work/b.json" || fail "default level blend not recorded as 1.5"
grep -q '"level_blend": 1.0' "$work/p.json" || fail "--paper did not turn the level blend off"
# Thresholds moved closer on the command line narrow the scene's band to what keeps the two
# bands apart (recorded as drawn); a band given beside them that is too wide is refused.
"$vdbtrace" render "$src/scenes/bough.json" --cone-level-max 0.3 --resolution 16x12 --out "$work/n.exr" \
    --stats "$work/n.json" 2>"$work/err" || fail "render --cone-level-max 0.3 failed: $(tail -1 "$work/err")"
/usr/bin/python3 -c 'import json, math, sys; b = json.load(open(sys.argv[1]))["level_blend"]; sys.exit(abs(b - math.sqrt(0.3 / 0.25)) > 1e-12)' \
    "$work/n.json" || fail "--cone-level-max 0.3 did not record the narrowed band: $(grep level_blend "$work/n.json")"
grep -q "level_blend 1.5 narrowed to 1.09545 to keep the bands about needle_level_max 0.25 and cone_level_max 0.3 apart" "$work/err" ||
    fail "the narrowed band was not said: $(head -2 "$work/err")"
expect_error "an EXR without a name" 2 "--out '$work/.exr': the file needs a name before .exr" -- \
    render "$src/scenes/bough.json" --out "$work/.exr"
# A number the tool cannot hold says why: 5e-324 is > 0 to the user, 0 or a denormal to a double.
expect_error "an underflowing number" 2 "--cone-level-max: must be a number > 0, got '5e-324', which is below the smallest normal double" -- \
    render "$src/scenes/bough.json" --cone-level-max 5e-324 --out "$work/n2.exr"
expect_error "an overflowing number" 2 "--cone-level-max: must be a number > 0, got '1e400', which overflows a double" -- \
    render "$src/scenes/bough.json" --cone-level-max 1e400 --out "$work/n2.exr"
expect_error "a number with a tail" 2 "--cone-level-max: must be a number > 0, got '3abc'" -- \
    render "$src/scenes/bough.json" --cone-level-max 3abc --out "$work/n2.exr"
# Spaces about a number are refused either side (a leading one was taken, a trailing one not).
expect_error "a number after a space" 2 "--cone-level-max: must be a number > 0, got ' 3', with spaces about it" -- \
    render "$src/scenes/bough.json" --cone-level-max " 3" --out "$work/n2.exr"
expect_error "a bounded whole number after a space" 2 "--samples: must be a whole number from 1 to 65536, got ' 4', with spaces about it" -- \
    render "$src/scenes/bough.json" --method geometry --samples " 4" --out "$work/n2.exr"
expect_error "a whole number before a space" 2 "--threads: must be a whole number >= 0, got '2 ', with spaces about it" -- \
    render "$src/scenes/bough.json" --threads "2 " --out "$work/n2.exr"
expect_error "a band too wide for the thresholds" 2 "--level-blend 2 must be at most sqrt(cone_level_max / needle_level_max) (1.09545) for cone_level_max 0.3" -- \
    render "$src/scenes/bough.json" --level-blend 2 --cone-level-max 0.3 --out "$work/n2.exr"
grep -q '"layer_correlation": "needles"' "$work/b.json" || fail "default layer correlation not recorded as needles"
grep -q '"layer_correlation": "independent"' "$work/p.json" || fail "--paper did not make the layers independent"
grep -q '"occluder_profile": "cones"' "$work/b.json" || fail "default occluder profile not recorded as cones"
grep -q '"occluder_profile": "even"' "$work/p.json" || fail "--paper did not read the occluders even"
"$vdbtrace" render "$src/scenes/bough.json" --paper --layer-model fibre --out "$work/p.exr" --stats "$work/p.json" 2>/dev/null \
    || fail "render --paper --layer-model fibre failed"
grep -q '"layer_model": "fibre"' "$work/p.json" || fail "--layer-model did not override --paper"
# bough.json with render.bough_law as the JSON string $1 (escapes and all), as law.json.
law_scene() {
    /usr/bin/python3 - "$src/scenes/bough.json" "$work/law.json" "$1" <<'PY'
import json, sys
scene = json.load(open(sys.argv[1]))
scene.setdefault("render", {})["bough_law"] = json.loads('"' + sys.argv[3] + '"')
json.dump(scene, open(sys.argv[2], "w"))
PY
}
law_scene quadratic
expect_error "unknown bough law" 2 "law.json: render.bough_law: unknown bough law 'quadratic' (known: exact, linear, corrected)" \
    -- render "$work/law.json" --out "$work/q.exr"
[ ! -e "$work/q.exr" ] || fail "a refused scene wrote an image"
# A NUL in the name is shown, not where the message ends.
law_scene 'x\u0000y'
expect_error "a NUL in a law's name" 2 "unknown bough law 'x\\\\x00y' (known: exact" \
    -- render "$work/law.json" --out "$work/q.exr"

# The reference method reads what bake wrote, and refuses a damaged file with one line.
bake="$(dirname "$vdbtrace")/bake"
if [ -x "$bake" ]; then
    "$bake" tree "$src/scenes/bough.json" --tree 0 --voxel-size 0.5 --out "$work/t.vdb" 2>/dev/null \
        || fail "bake tree failed"
    "$vdbtrace" render "$src/scenes/bough.json" --method reference --grids "$work/t.vdb" \
        --subpixels 1 --out "$work/r.exr" 2>"$work/err" || fail "reference from grids: $(tail -1 "$work/err")"
    [ -s "$work/r.exr" ] || fail "reference wrote no image"
    oiiotool --info -v "$work/r.exr" | grep -q "channel list: R, G, B, A, Z, diffuse.Y, foliage.Y, foliage_luminance.Y, specular.Y, tree.Y$" \
        || fail "reference EXR channels: $(oiiotool --info -v "$work/r.exr" | grep 'channel list')"
    # A file says which tree it is (pine:tree): the reference sums its foliage as that tree's.
    "$bake" tree "$src/scenes/three-firs.json" --tree 1 --voxel-size 1 --out "$work/t1.vdb" \
        2>/dev/null || fail "bake tree --tree 1 failed"
    "$vdbtrace" render "$src/scenes/three-firs.json" --method reference --grids "$work/t1.vdb" \
        --subpixels 1 --resolution 80x60 --out "$work/r1.exr" 2>"$work/err" \
        || fail "reference from tree 1's grids failed"
    # Its light grids, before any pixel, tell their progress on lines of their own.
    grep -E "^vdbtrace: (lighting [0-9]+ voxels( for [0-9]+ lights)?|rendering) +[0-9]+%$" "$work/err" | awk '
        /lighting/ { if (rendering) bad = 1; lit = $NF }
        /rendering/ { rendering = 1 }
        END { exit bad || lit != "100%" || !rendering }' \
        || fail "the reference's light grids' progress: $(grep % "$work/err" | tr '\n' ' ')"
    oiiotool --info -v "$work/r1.exr" | /usr/bin/python3 -c '
import json, re, sys
rows = json.loads(json.loads(re.search(r"pine:tree_foliage: (\".*\")", sys.stdin.read()).group(1)))
assert len(rows) == 1 and rows[0][0] == 1 and rows[0][1] > 10 and rows[0][2] > 0, rows
' || fail "the reference from tree 1's grids did not sum its foliage as tree 1's"
    # The grids read count in the memory estimate (they had not: only their light grids, by
    # active voxels); a limit too low to read a sound file says so, not only "damaged?".
    "$bake" tree "$src/scenes/three-firs.json" --tree 1 --voxel-size 0.25 --out "$work/t25.vdb" \
        2>/dev/null || fail "bake tree at 0.25 cm failed"
    expect_error "grids read beyond --max-memory" 2 "the baked grids read (" -- render \
        "$src/scenes/three-firs.json" --method reference --grids "$work/t25.vdb" \
        --resolution 80x60 --max-memory 0.3 --out "$work/m.exr"
    expect_error "a limit too low to read grids" 2 "(the limit too low for a file of" -- render \
        "$src/scenes/three-firs.json" --method reference --grids "$work/t25.vdb" \
        --resolution 80x60 --max-memory 0.01 --out "$work/m.exr"
    [ ! -e "$work/m.exr" ] || fail "a refused render wrote its image"
    head -c 1000 "$work/t.vdb" >"$work/cut.vdb" && cp "$work/t.vdb.json" "$work/cut.vdb.json"
    expect_error "damaged grids" 2 "manifest" -- render "$src/scenes/bough.json" --method reference \
        --grids "$work/cut.vdb" --out "$work/d.exr"
    [ ! -e "$work/d.exr" ] || fail "a refused render wrote its image"
fi

# A folder name is a folder name: the plot script is started without a shell.
odd="$work/a';touch \"$work/INJECTED\";'b"
"$vdbtrace" compare "$src/scenes/bough.json" --quick --resolution 32x24 --out-dir "$odd" 2>"$work/err" \
    || fail "compare into an oddly named folder: $(tail -1 "$work/err")"
[ -s "$odd/report.md" ] || fail "compare wrote no report into $odd"
[ ! -e "$work/INJECTED" ] || fail "a folder name ran as a shell command"

# bench: multiscale and geometry timed in one run; the JSON holds what the lines say, the
# ratio is of the two medians, each median within its runs' least and most.
/usr/bin/python3 -c 'import json, sys
scene = json.load(open(sys.argv[1]))
scene["camera"]["resolution"] = [48, 36]
json.dump(scene, open(sys.argv[2], "w"))' "$src/scenes/three-firs.json" "$work/small-firs.json"
"$vdbtrace" bench "$work/small-firs.json" --repeat 3 --geometry-samples 2 \
    --json "$work/bench.json" >"$work/bench.out" 2>"$work/err" \
    || fail "bench: $(tail -1 "$work/err")"
/usr/bin/python3 - "$work/bench.json" "$work/bench.out" <<'PY' \
    || fail "bench JSON: $(cat "$work/bench.out")"
import json, math, sys
j = json.load(open(sys.argv[1]))
out = open(sys.argv[2]).read()
for m in ("multiscale", "geometry"):
    r = j[m]
    assert 0 < r["cpu_seconds_min"] <= r["cpu_seconds"] <= r["cpu_seconds_max"], r
    assert r["wall_seconds"] > 0, r
assert j["geometry"]["samples_per_pixel"] == 2 and j["repeats"] == 3
ratio = j["multiscale"]["cpu_seconds"] / j["geometry"]["cpu_seconds"]
assert math.isclose(j["cpu_ratio_multiscale_over_geometry"], ratio, rel_tol=1e-12), ratio
assert j["multiscale"]["model"]["bough_law"] == "exact", j["multiscale"]["model"]
assert abs(sum(j["multiscale"]["pixel_share"].values()) - 1) < 1e-9
assert j["multiscale"]["cones_per_pixel"] >= 1, j["multiscale"]  # split pixels trace more
assert j["resolution"] == [48, 36] and j["startup_cpu_seconds"] > 0
# The printed lines say the JSON's numbers (6 significant digits).
printed = dict(line.rsplit(" ", 1) for line in out.splitlines() if line.startswith("CPU ratio"))
assert math.isclose(float(printed["CPU ratio multiscale / geometry"]), ratio, rel_tol=1e-5), out
assert ("multiscale render: CPU seconds %g [%g, %g]" % (j["multiscale"]["cpu_seconds"],
        j["multiscale"]["cpu_seconds_min"], j["multiscale"]["cpu_seconds_max"])) in out, out
assert "geometry 2 spp render: CPU seconds %g" % j["geometry"]["cpu_seconds"] in out, out
PY
# The runs go round by round, each method once a round: back to back, a drift in the machine's
# speed would time one method in one stretch of it.
/usr/bin/python3 - "$work/err" <<'PY' || fail "bench's rounds: $(grep 100% "$work/err")"
import sys
done = [l.split(": ", 1)[1].rsplit(" ", 1)[0].strip() for l in open(sys.argv[1])
        if l.rstrip().endswith("100%")]
rounds = [name for i in (1, 2, 3) for name in ("multiscale %d" % i, "geometry 2 spp %d" % i)]
assert done == rounds, done
PY
# Its shadow columns are the ones a render of the scene makes (three firs: a sun, shadows on).
"$vdbtrace" render "$work/small-firs.json" --method multiscale --out "$work/small-firs.exr" \
    --stats "$work/small-firs.stats.json" >/dev/null 2>"$work/err" \
    || fail "render small firs: $(tail -1 "$work/err")"
/usr/bin/python3 - "$work/bench.json" "$work/small-firs.stats.json" "$work/bench.out" <<'PY' \
    || fail "bench's shadow columns: $(cat "$work/bench.out")"
import json, sys
bench, stats = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
b = bench["multiscale"]["shadow_columns_bytes"]
assert b > 0 and b == stats["shadow_columns_bytes"], (b, stats.get("shadow_columns_bytes"))
assert "shadow columns %g MiB" % (b / 2**20) in open(sys.argv[3]).read()
PY
expect_error "bench JSON into a missing folder" 2 "no/such" -- \
    bench "$work/small-firs.json" --json "$work/no/such/b.json"
cp "$work/small-firs.json" "$work/kept.json"
expect_error "bench JSON over its scene" 2 "also an input" -- \
    bench "$work/small-firs.json" --json "$work/small-firs.json"
cmp -s "$work/kept.json" "$work/small-firs.json" || fail "bench --json overwrote its scene"
expect_error "bench even repeats" 2 "odd number" -- bench "$work/small-firs.json" --repeat 2

# bench --grow: each step a scene file as stated, both methods timed at each, the exponents
# the log-log slopes of what the table says; refusals before any work.
"$vdbtrace" bench "$work/small-firs.json" --grow resolution --grow-steps 2 --grow-factor 4 \
    --geometry-samples 1 --grow-dir "$work/grow" --no-plot >"$work/grow.out" 2>"$work/err" \
    || fail "bench --grow: $(tail -1 "$work/err")"
/usr/bin/python3 - "$work/grow" "$work/grow.out" <<'PY' || fail "bench --grow: $(cat "$work/grow.out")"
import csv, json, math, os, sys
d = sys.argv[1]
g = json.load(open(os.path.join(d, "growth.json")))
rows = g["rows"]
assert [(r["step"], r["method"]) for r in rows] == [
    (0, "multiscale"), (0, "geometry"), (1, "multiscale"), (1, "geometry")], rows
for k, size in ((0, [48, 36]), (1, [96, 72])):
    step = json.load(open(os.path.join(d, "step-%d.json" % k)))
    assert step["camera"]["resolution"] == size, step["camera"]
    for r in rows[2 * k:2 * k + 2]:
        assert r["pixels"] == size[0] * size[1] and r["scale"] == 4 ** k and r["trees"] == 3, r
        assert r["cpu_seconds"] > 0 and r["peak_memory_mib"] > 0, r
for m in ("multiscale", "geometry"):
    a, b = [r for r in rows if r["method"] == m]
    for key in ("cpu_seconds", "peak_memory_mib"):
        e = math.log(b[key] / a[key]) / math.log(4)
        assert math.isclose(g["exponents"][m][key], e, rel_tol=1e-9, abs_tol=1e-12), (m, key)
assert len(list(csv.DictReader(open(os.path.join(d, "growth.csv"))))) == 4
assert "multiscale: CPU seconds grow as scale^" in open(sys.argv[2]).read()
PY
"$vdbtrace" bench "$work/small-firs.json" --resolution 32x24 --geometry-samples 0 \
    --json "$work/bench-res.json" >/dev/null 2>"$work/err" || fail "bench --resolution: $(tail -1 "$work/err")"
/usr/bin/python3 -c 'import json, sys
j = json.load(open(sys.argv[1]))
assert j["resolution"] == [32, 24], j["resolution"]' "$work/bench-res.json" || fail "bench --resolution: not 32x24"
# bench --law-cache: the multiscale runs keep their law profiles within it, as render does:
# with 1 MiB some are dropped and computed again, never more than it kept at once; without,
# none is dropped.
for cache in "" "--law-cache 1"; do
  # shellcheck disable=SC2086
  "$vdbtrace" bench "$work/small-firs.json" --resolution 160x120 --geometry-samples 0 $cache \
      --json "$work/bench-cache${cache:+d}.json" >"$work/bench-cache.out" 2>"$work/err" \
      || fail "bench ${cache:-without --law-cache}: $(tail -1 "$work/err")"
done
/usr/bin/python3 - "$work/bench-cached.json" "$work/bench-cache.json" <<'PY' \
    || fail "bench --law-cache: $(cat "$work/bench-cache.out")"
import json, sys
cached, kept = (json.load(open(f))["multiscale"] for f in sys.argv[1:3])
assert cached["law_cache_mib"] == 1 and "law_cache_mib" not in kept, cached
c, k = cached["law_profiles"], kept["law_profiles"]
assert k["views"]["dropped"] == 0 and k["from_lights"]["dropped"] == 0, k
assert k["views"]["computed"] > 0, k
assert c["views"]["dropped"] + c["from_lights"]["dropped"] > 0, c
assert c["views"]["computed"] >= k["views"]["computed"], (c, k)
assert k["peak_bytes"] > 1.05 * 1024 * 1024 >= c["peak_bytes"], (c, k)  # one profile over
assert c["from_lights"]["computed"] > k["from_lights"]["computed"], (c, k)
PY
expect_error "bench --law-cache below 1 MiB" 2 "law-cache" -- \
    bench "$work/small-firs.json" --law-cache 0.5
expect_error "bench --grow without a folder" 2 "grow-dir" -- bench "$work/small-firs.json" --grow resolution
expect_error "bench --grow-dir without --grow" 2 "--grow-dir requires --grow" -- bench "$work/small-firs.json" --grow-dir "$work/g0"
expect_error "bench --grow-steps without --grow" 2 "--grow-steps requires --grow" -- bench "$work/small-firs.json" --grow-steps 3
expect_error "bench --grow-factor without --grow" 2 "--grow-factor requires --grow" -- bench "$work/small-firs.json" --grow-factor 3
expect_error "bench --no-plot without --grow" 2 "--no-plot requires --grow" -- bench "$work/small-firs.json" --no-plot
expect_error "bench --grow, no scatter" 2 "no \"scatter\"" -- \
    bench "$work/small-firs.json" --grow trees-region --grow-dir "$work/grow-none"
[ ! -e "$work/grow-none" ] || fail "a refused --grow made its folder"
expect_error "bench --grow over --max-memory" 2 "more than --max-memory" -- \
    bench "$work/small-firs.json" --grow resolution --grow-dir "$work/grow3" --max-memory 0.1
[ ! -e "$work/grow3" ] || fail "a --grow refused for its memory made its folder"
expect_error "bench --grow with --json" 2 "does not apply" -- \
    bench "$work/small-firs.json" --grow resolution --grow-dir "$work/grow2" --json "$work/b.json"

"$vdbtrace" --help >/dev/null || fail "--help"
# OpenImageIO (some 250 libraries, 0.3 s) loads with the first image, not before every command.
LD_DEBUG=libs "$vdbtrace" --help 2>"$work/libs" >/dev/null
grep -q "libOpenImageIO" "$work/libs" && fail "--help loads OpenImageIO"
LD_DEBUG=libs "$vdbtrace" render "$src/scenes/bough.json" --resolution 8x6 --out "$work/lazy.exr" \
    -q 2>"$work/libs" >/dev/null
grep -q "libOpenImageIO" "$work/libs" || fail "writing an image does not load OpenImageIO"
[ -s "$work/lazy.exr" ] || fail "no image written once OpenImageIO is loaded"
# Without the module beside it (or in ../lib/pine) a render stops before its work, in one line.
mkdir -p "$work/alone" && cp "$vdbtrace" "$work/alone/vdbtrace"
"$work/alone/vdbtrace" render "$src/scenes/bough.json" --resolution 8x6 --out "$work/alone/a.exr" \
    2>"$work/alone/err"
status=$?
[ "$status" -eq 2 ] || fail "a missing image module exits $status, not 2"
grep -q "the image module libpine_image_codec.so is missing" "$work/alone/err" ||
    fail "a missing image module: $(tail -1 "$work/alone/err")"
grep -q "rendering" "$work/alone/err" && fail "a missing image module is found after the render"
[ -e "$work/alone/a.exr" ] && fail "a missing image module left an image"
# Animations: frames need a camera path, at least 3 for the temporal report.
expect_error "frames without a path" 2 "has no camera_path" -- render "$src/scenes/bough.json" --frames 1-3 --out "$work/f.exr"
expect_error "bad frame range" 2 "expected A-B" -- render "$src/scenes/three-firs.json" --frames 5-2 --out "$work/f.exr"
expect_error "temporal report without a path" 2 "has no camera_path" -- animate-compare "$src/scenes/bough.json" --out-dir "$work/anim"
expect_error "temporal report of 2 frames" 2 "at least 3 frames" -- animate-compare "$src/scenes/three-firs.json" --frames 1-2 --self-shadowing --out-dir "$work/anim"
expect_error "temporal report, effects unmatched" 2 "self_shadowing" -- animate-compare "$src/scenes/paper-forest.json" --out-dir "$work/anim"
"$vdbtrace" animate-compare "$src/scenes/three-firs.json" --frames 2-5 --resolution 32x24 \
    --self-shadowing --strip 16 --no-plot --truth-samples 4 --out-dir "$work/anim" 2>"$work/err" ||
    fail "animate-compare: exit $?"
grep -q -- "--strip 16: the strip shows 4 frames, as many as there are" "$work/err" ||
    fail "a strip of more frames than there are was not said: $(grep -i strip "$work/err")"
for f in report.md flicker.csv frames.csv strip.png; do
    [ -s "$work/anim/$f" ] || fail "animate-compare wrote no $f"
done
# 3 methods and the truth x (all pixels + 4 bands), and 4 frames each; the truth's row alone
# has no error flicker.
[ "$(tail -n +2 "$work/anim/flicker.csv" | wc -l)" -eq 20 ] || fail "flicker.csv: $(cat "$work/anim/flicker.csv")"
[ "$(grep -c '^[2-5],' "$work/anim/frames.csv")" -eq 16 ] || fail "frames.csv: $(cat "$work/anim/frames.csv")"
# The first and last frames have no residual: an empty field, never "nan".
grep -qiw nan "$work/anim/frames.csv" && fail "frames.csv holds nan: $(cat "$work/anim/frames.csv")"
[ "$(grep -c '^[25],[a-z_0-9]*,,[0-9]' "$work/anim/frames.csv")" -eq 8 ] ||
    fail "frames.csv: the end frames' residuals: $(cat "$work/anim/frames.csv")"
[ "$(grep -c '^truth_geometry_4spp,[a-z]*,[0-9]*,[0-9.e-]*,,' "$work/anim/flicker.csv")" -eq 5 ] ||
    fail "flicker.csv: the truth's rows: $(grep truth "$work/anim/flicker.csv")"
[ "$(grep -c '^geometry_1spp,[a-z]*,[0-9]*,[0-9.e-]*,[0-9]' "$work/anim/flicker.csv")" -eq 5 ] ||
    fail "flicker.csv: no error flicker for geometry_1spp"
grep -q "## Against the truth" "$work/anim/report.md" || fail "report.md has no truth section"
mkdir -p "$work/seq"
"$vdbtrace" render "$src/scenes/three-firs.json" --frames 2-4 --resolution 32x24 --quiet \
    --out "$work/seq/f.exr" || fail "render --frames: exit $?"
for f in 0002 0003 0004; do
    [ -s "$work/seq/f.$f.exr" ] && [ -s "$work/seq/f.$f.png" ] || fail "render --frames wrote no frame $f"
done
[ -e "$work/seq/f.exr" ] && fail "render --frames also wrote the unnumbered name"
# Resuming: the same job keeps its frames (a deleted one is rendered again); other settings
# render every frame again.
rm "$work/seq/f.0003.exr"
"$vdbtrace" render "$src/scenes/three-firs.json" --frames 2-4 --resolution 32x24 \
    --out "$work/seq/f.exr" 2>"$work/err" || fail "resume: exit $?"
grep -q "2 of 3 frames already rendered by this job, kept" "$work/err" || fail "resume: $(grep -v % "$work/err" | head -2)"
[ "$(grep -c 'seq/f.000[2-4].exr: 32x24' "$work/err")" -eq 1 ] || fail "resume rendered other than frame 3"
"$vdbtrace" render "$src/scenes/three-firs.json" --frames 2-4 --resolution 32x24 \
    --method geometry --samples 2 --out "$work/seq/f.exr" 2>"$work/err" || fail "another job: exit $?"
grep -q "kept" "$work/err" && fail "another job's frames were kept"
[ "$(grep -c 'seq/f.000[2-4].exr: 32x24' "$work/err")" -eq 3 ] || fail "another job did not render all 3 frames"
# The same job asking for stats renders again the frames that have none (it kept them all and
# wrote no stats).
"$vdbtrace" render "$src/scenes/three-firs.json" --frames 2-4 --resolution 32x24 \
    --method geometry --samples 2 --out "$work/seq/f.exr" --stats "$work/seq/s.json" 2>"$work/err" ||
    fail "stats on resume: exit $?"
for f in 0002 0003 0004; do
    [ -s "$work/seq/s.$f.json" ] || fail "stats on resume: no s.$f.json: $(grep -v % "$work/err" | head -3)"
done
rm "$work/seq/s.0003.json"
"$vdbtrace" render "$src/scenes/three-firs.json" --frames 2-4 --resolution 32x24 \
    --method geometry --samples 2 --out "$work/seq/f.exr" --stats "$work/seq/s.json" 2>"$work/err" ||
    fail "stats on resume: exit $?"
grep -q "2 of 3 frames already rendered by this job, kept" "$work/err" && [ -s "$work/seq/s.0003.json" ] ||
    fail "stats on resume: frame 3's stats: $(grep -v % "$work/err" | head -3)"
# Stats another job wrote (no job, or another) are not this job's: their frame is rendered again.
printf '{"frame": 2, "method": "multiscale"}\n' >"$work/seq/s.0002.json"
"$vdbtrace" render "$src/scenes/three-firs.json" --frames 2-4 --resolution 32x24 \
    --method geometry --samples 2 --out "$work/seq/f.exr" --stats "$work/seq/s.json" 2>"$work/err" ||
    fail "foreign stats on resume: exit $?"
grep -q "2 of 3 frames already rendered by this job, kept" "$work/err" && grep -q '"job"' "$work/seq/s.0002.json" ||
    fail "foreign stats on resume were kept: $(grep -v % "$work/err" | head -3)"
# A later frame's preview or stats where a folder is: refused before the first frame.
mkdir "$work/seq/g.0004.png"
expect_error "a later frame's preview onto a folder" 2 "cannot write '.*g.0004.png': it is a folder" -- render "$src/scenes/three-firs.json" --frames 2-4 --resolution 8x6 --out "$work/seq/g.exr"
rmdir "$work/seq/g.0004.png"
[ -z "$(ls "$work/seq" | grep '^g\.')" ] || fail "a refused job wrote frames: $(ls "$work/seq")"
# A frame beyond the path's own whose camera cannot render: refused by number.
printf '%s' '{"camera": {"position": [0, -10, 100], "look_at": [0, 10, 100]},
 "camera_path": {"keys": [{"frame": 0}, {"frame": 10, "position": [0, 10, 100], "look_at": [0, -10, 100]}],
                 "interpolation": "linear", "frames": [0, 3]},
 "lights": [{"type": "directional", "direction": [0, 0, 1]}], "trees": []}' >"$work/turn.json"
expect_error "a frame that cannot render" 2 "at frame 5 of .*look_at equals position" -- render "$work/turn.json" --frames 4-6 --resolution 8x6 --out "$work/seq/t.exr"
"$vdbtrace" render --help >/dev/null || fail "render --help"
"$vdbtrace" animate-compare --help >/dev/null || fail "animate-compare --help"
"$vdbtrace" bench --help >/dev/null || fail "bench --help"

echo "vdbtrace cli: $failures failed"
[ "$failures" -eq 0 ]
