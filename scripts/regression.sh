#!/usr/bin/env bash
# Image regression: what every method renders on every shipped scene, recorded before a
# refactor and checked after it, so that the outputs are shown unchanged or each difference is
# explained as a bug fixed (docs/architecture.md, "Regression").
#
#   bash scripts/regression.sh record DIR           renders into DIR (EXR + stats JSON per case)
#   bash scripts/regression.sh check BASE DIR       renders into DIR, then compares with BASE:
#                                                   every channel of every pixel (RGBA and AOVs)
#                                                   within 1e-6 (idiff), every stats count equal
#
# Cases: each scene of scenes/ at 160 x 120 (same view: fov is vertical, aspect 4:3 kept), plus
# three-firs with diffuse alone; each with multiscale (auto and forced to levels 1, 2, 3), the
# reference (1 cm voxels, 2 x 2 rays) and geometry (4 spp). Uses build/bin (build first).
# Times (seconds, thread_seconds_per_level) and paths are not compared; a stats key the base
# lacks is listed, not failed (a newer binary records more of what it chose).
#
# REGRESSION_ARGS adds options to every render of this run, e.g. REGRESSION_ARGS=--paper to
# check that the paper's choices still render what a binary from before the faithful models
# rendered by default.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-}
case "$mode" in
  record) [ $# -eq 2 ] || { echo "usage: $0 record DIR" >&2; exit 2; }; out=$2 ;;
  check) [ $# -eq 3 ] || { echo "usage: $0 check BASE DIR" >&2; exit 2; }; base=$2; out=$3 ;;
  *) echo "usage: $0 record DIR | check BASE DIR" >&2; exit 2 ;;
esac
bin=${VDBTRACE:-build/bin/vdbtrace}  # another build: VDBTRACE=path/to/vdbtrace
[ -x "$bin" ] || { echo "regression: $bin is missing: build first" >&2; exit 2; }
command -v idiff >/dev/null || { echo "regression: idiff (openimageio-tools) is missing" >&2; exit 2; }
mkdir -p "$out/scenes"

# Small copies of the shipped scenes.
/usr/bin/python3 - "$out/scenes" scenes/*.json <<'EOF'
import json, os, sys
out = sys.argv[1]
for path in sys.argv[2:]:
    scene = json.load(open(path))
    scene["camera"]["resolution"] = [160, 120]
    name = os.path.splitext(os.path.basename(path))[0]
    json.dump(scene, open(os.path.join(out, name + ".json"), "w"), indent=1)
    if name == "three-firs":
        scene["effects"] = ["diffuse"]
        json.dump(scene, open(os.path.join(out, name + "-diffuse.json"), "w"), indent=1)
EOF

cases=0
for scene in "$out"/scenes/*.json; do
  name=$(basename "$scene" .json)
  while read -r tag args; do
    if ! "$bin" --threads 2 render "$scene" $args ${REGRESSION_ARGS:-} --out "$out/$name.$tag.exr" \
        --stats "$out/$name.$tag.stats.json" 2>"$out/render.log"; then
      echo "regression: $name $tag failed: $(tail -1 "$out/render.log")" >&2
      exit 1
    fi
    cases=$((cases + 1))
  done <<'EOF'
ms-auto --method multiscale
ms-L1 --method multiscale --force-level 1
ms-L2 --method multiscale --force-level 2
ms-L3 --method multiscale --force-level 3
reference --method reference --voxel-size 1 --subpixels 2
geometry --method geometry --samples 4
EOF
  echo "regression: $name rendered" >&2
done
[ "$mode" = record ] && { echo "regression: $cases cases recorded in $out" >&2; exit 0; }

failed=0
channels() { oiiotool --info -v "$1" | sed -n 's/^ *channel list: //p' | tr -d ' ' | tr ',' '\n'; }
for exr in "$base"/*.exr; do
  stem=$(basename "$exr" .exr)
  # The channels both hold are compared; a channel one side lacks (an AOV a method does not
  # compute, depth.Y become Z along the view axis) is listed, not compared.
  common=$(comm -12 <(channels "$exr" | sort) <(channels "$out/$stem.exr" | sort) | paste -sd, -)
  apart=$(comm -3 <(channels "$exr" | sort) <(channels "$out/$stem.exr" | sort) | tr -d '\t' | paste -sd' ' -)
  [ -z "$apart" ] || echo "regression: $stem: not in both, not compared: $apart" >&2
  if [ -z "$common" ]; then
    echo "regression: $stem: no channel in both" >&2
    failed=$((failed + 1))
    continue
  fi
  oiiotool "$exr" --ch "$common" -o "$out/.base.exr" && oiiotool "$out/$stem.exr" --ch "$common" -o "$out/.new.exr"
  if ! idiff -q -fail 1e-6 -failpercent 0 -warn 1e-6 "$out/.base.exr" "$out/.new.exr" >/dev/null 2>&1; then
    echo "regression: $stem: pixels differ:" >&2
    idiff -fail 1e-6 "$out/.base.exr" "$out/.new.exr" 2>&1 | sed -n '/Mean error/,/Max error/p' >&2 || true
    failed=$((failed + 1))
  fi
  rm -f "$out/.base.exr" "$out/.new.exr"
  if ! /usr/bin/python3 - "$base/$stem.stats.json" "$out/$stem.stats.json" <<'EOF'
import json, sys
def counts(path):
    j = json.load(open(path))
    for k in ("seconds", "thread_seconds_per_level", "scene"):
        j.pop(k, None)
    return j
a, b = counts(sys.argv[1]), counts(sys.argv[2])
if a != b:
    def flat(j, prefix=""):
        out = {}
        for k, v in j.items():
            if isinstance(v, dict):
                out.update(flat(v, prefix + k + "."))
            else:
                out[prefix + k] = v
        return out
    fa, fb = flat(a), flat(b)
    added = sorted(set(fb) - set(fa))
    if added:
        print("  recorded now, not in the base: " + ", ".join(added), file=sys.stderr)
    differ = [k for k in sorted(fa) if fa[k] != fb.get(k)]
    for k in differ:
        print(f"  {k}: {fa.get(k)} -> {fb.get(k)}", file=sys.stderr)
    sys.exit(1 if differ else 0)
EOF
  then
    echo "regression: $stem: stats differ (above)" >&2
    failed=$((failed + 1))
  fi
done
echo "regression: $cases cases, $failed differences against $base" >&2
[ "$failed" -eq 0 ]
