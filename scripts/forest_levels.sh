# Shared by scripts/level_decomposition.sh and scripts/light_directions.sh (sourced, not run):
# the paper forest forced to one multiscale level at a time, box-downsampled to 320 x 240 and
# measured per tree against an explicit-needle truth (`vdbtrace diff` over its "tree" AOV).
# The caller sets `tool` (its name, for messages) and `out` (the folder to render into), and
# runs from the repository's root.
bin=${VDBTRACE:-build/bin/vdbtrace}
[ -x "$bin" ] || { echo "$tool: $bin is missing: build first" >&2; exit 2; }
command -v oiiotool >/dev/null || { echo "$tool: oiiotool is missing" >&2; exit 2; }
mkdir -p "$out"

# The forest at a resolution, with an effect set, optionally its branches 30 times thinner
# ("thin") and its sun moved (the direction towards it, JSON).
forest_scene() {  # forest_scene NAME WIDTH HEIGHT EFFECTS_JSON [thin|-] [TOWARDS_LIGHT_JSON]
  /usr/bin/python3 - "$out/$1.json" "$2" "$3" "$4" "${5:--}" "${6:-}" <<'PY'
import json, sys
path, w, h, effects = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), json.loads(sys.argv[4])
scene = json.load(open("scenes/paper-forest.json"))
scene["camera"]["resolution"] = [w, h]
scene["effects"] = effects
if sys.argv[5] == "thin":
    for species in scene["species"].values():
        species["lsystem"]["trunk_radius"] /= 30
if sys.argv[6]:
    scene["lights"][0]["direction"] = json.loads(sys.argv[6])
json.dump(scene, open(path, "w"), indent=1)
PY
}
# The explicit needles' truth of NAME.json (TRUTH_SPP samples per pixel, default 1024).
truth() {  # truth NAME TAG
  echo "$tool: $2, ${TRUTH_SPP:-1024} spp" >&2
  "$bin" render "$out/$1.json" --method geometry --samples "${TRUTH_SPP:-1024}" \
    --out "$out/$2.exr" 2>/dev/null
}
# Renders NAME.json at level LEVEL into TAG.exr, box-downsampled to 320 x 240, measured
# against TRUTH.exr into TAG.diff.
render_level() {  # render_level NAME LEVEL TAG [TRUTH]
  echo "$tool: $3" >&2
  "$bin" render "$out/$1.json" --force-level "$2" --out "$out/$3.full.exr" 2>/dev/null
  oiiotool "$out/$3.full.exr" --resize:filter=box 320x240 -o "$out/$3.exr"
  "$bin" diff "$out/$3.exr" "$out/${4:-truth}.exr" --out "$out/$3.diff" >/dev/null 2>&1
}
# One line: TAG's per-tree coverage and luminance bias, median, worst and trees off by > 3%.
per_tree() {  # per_tree LABEL TAG
  /usr/bin/python3 - "$1" "$out/$2.diff/errors.json" <<'PY'
import json, statistics, sys
rows = json.load(open(sys.argv[2]))["trees"]
line = "%-44s" % sys.argv[1]
for key in ("coverage_bias", "luminance_bias"):
    b = [r[key] for r in rows if r[key] is not None]  # null: the tree is black in the truth
    if not b:
        line += "  %s undefined" % key[:3]
        continue
    worst = max(b, key=abs)
    line += "  %s median %+5.1f%% worst %+5.1f%% off %2d/%d" % (
        key[:3], 100 * statistics.median(b), 100 * worst, sum(abs(x) > 0.03 for x in b), len(b))
print(line)
PY
}
