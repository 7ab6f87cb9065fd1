#!/usr/bin/env bash
# Does the reference converge as its voxels shrink, and to what (docs/models.md, "The
# reference's light")? One paper-forest fir lit as the forest is
# (scenes/studies/one-fir.json, 320 x 240), against an explicit-needle truth of TRUTH_SPP
# samples per pixel (default 1024), rendered by the reference at each voxel size of VOXELS
# (cm, default "0.5 0.25 0.125"), in diffuse light alone and with every effect (shadows and
# self-shadowing). Prints each render's per-tree luminance and coverage bias and user CPU
# seconds.
#
#   bash scripts/reference_convergence.sh [DIR]     renders into DIR (default: a temporary folder)
#
# Takes about three minutes on 2 cores with the default sizes; 0.0625 cm adds about thirteen
# minutes and 7 GB. Uses build/bin (build first).
set -euo pipefail
cd "$(dirname "$0")/.."
tool=reference_convergence
bin=${VDBTRACE:-build/bin/vdbtrace}
[ -x "$bin" ] || { echo "$tool: $bin is missing: build first" >&2; exit 2; }
out=${1:-$(mktemp -d)}
mkdir -p "$out"

scene() {  # scene NAME EFFECTS_JSON
  /usr/bin/python3 - "$out/$1.json" "$2" <<'PY'
import json, sys
scene = json.load(open("scenes/studies/one-fir.json"))
scene["camera"]["resolution"] = [320, 240]
scene["effects"] = json.loads(sys.argv[2])
json.dump(scene, open(sys.argv[1], "w"), indent=1)
PY
}

bias() {  # bias LABEL DIFF_DIR SECONDS: the one tree's biases
  /usr/bin/python3 - "$1" "$2/errors.json" "$3" <<'PY'
import json, sys
tree = json.load(open(sys.argv[2]))["trees"][0]
print("%-36s luminance %+6.2f%%  coverage %+6.2f%%  %7.1f user-s" % (
    sys.argv[1], 100 * tree["luminance_bias"], 100 * tree["coverage_bias"], float(sys.argv[3])))
PY
}

for effects in 'diffuse:["diffuse"]' 'every:["diffuse", "shadows", "self_shadowing"]'; do
  name=${effects%%:*}
  scene "$name" "${effects#*:}"
  echo "$tool: $name, truth at ${TRUTH_SPP:-1024} spp" >&2
  "$bin" render "$out/$name.json" --method geometry --samples "${TRUTH_SPP:-1024}" \
    --out "$out/$name.truth.exr" 2>/dev/null
  for h in ${VOXELS:-0.5 0.25 0.125}; do
    echo "$tool: $name, reference at $h cm" >&2
    /usr/bin/time -f %U -o "$out/$name.$h.time" "$bin" render "$out/$name.json" \
      --method reference --voxel-size "$h" --out "$out/$name.$h.exr" 2>/dev/null
    "$bin" diff "$out/$name.$h.exr" "$out/$name.truth.exr" --out "$out/$name.$h.diff" \
      >/dev/null 2>&1
    bias "$name, reference at $h cm" "$out/$name.$h.diff" "$(cat "$out/$name.$h.time")"
  done
done
