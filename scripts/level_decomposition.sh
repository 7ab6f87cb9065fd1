#!/usr/bin/env bash
# Where each level's per-tree error in a forest comes from (docs/models.md, "Level threshold"):
# the paper forest at 320 x 240 with self-shadowing, against an explicit-needle truth
# (TRUTH_SPP samples per pixel, default 1024), each multiscale level forced on every bough hit
# (`--force-level`), rendered at the scene's own footprints and at finer ones (level 1 at 8x
# the pixels, levels 2 and 3 at 4x), box-downsampled to 320 x 240 and measured per tree
# (`vdbtrace diff` over the truth's "tree" AOV).
#
# The same with the trees' branches 30 times thinner (a truth of their own): what the solid
# branches inside the boughs cost each level.
#
# Then, at the fine footprints, level 2 and level 3 against level 1 (the needles themselves,
# each with the models' shadows) with the effects added one by one: what each level's
# aggregation costs, apart from the shadow models all levels share. The needles have both kinds
# of shadow or neither, so this part compares levels, not needles; its per-tree ratios use the
# truth's tree regions (each level's bias against the truth, divided).
#
#   bash scripts/level_decomposition.sh [DIR]     renders into DIR (default: a temporary folder)
#
# Takes about seven minutes on 2 cores. Uses build/bin (build first) and oiiotool.
set -euo pipefail
cd "$(dirname "$0")/.."
tool=level_decomposition
out=${1:-$(mktemp -d)}
source scripts/forest_levels.sh

ratio() {  # ratio LABEL TAG BASE: TAG against BASE, per tree
  /usr/bin/python3 - "$1" "$out/$2.diff/errors.json" "$out/$3.diff/errors.json" <<'PY'
import json, statistics, sys
load = lambda p: {r["tree"]: r for r in json.load(open(p))["trees"]}
a, b = load(sys.argv[2]), load(sys.argv[3])
line = "%-44s" % sys.argv[1]
for key in ("coverage_bias", "luminance_bias"):
    # null: the tree is black in a truth, and has no ratio
    r = sorted((1 + a[k][key]) / (1 + b[k][key]) - 1 for k in a
               if k in b and a[k][key] is not None and b[k][key] is not None)
    if not r:
        line += "  %s undefined" % key[:3]
        continue
    line += "  %s median %+5.1f%% p10 %+5.1f%% p90 %+5.1f%% off %2d/%d" % (
        key[:3], 100 * statistics.median(r), 100 * r[len(r) // 10],
        100 * r[9 * len(r) // 10], sum(abs(x) > 0.03 for x in r), len(r))
print(line)
PY
}

all='["diffuse", "self_shadowing", "shadows"]'
forest_scene x1 320 240 "$all"
forest_scene x4 1280 960 "$all"
forest_scene x8 2560 1920 "$all"
truth x1 truth

echo "Per tree against the needles, every effect (self-shadowing, shadows):"
render_level x1 3 L3; per_tree "level 3 at the scene's footprints" L3
render_level x1 2 L2; per_tree "level 2 at the scene's footprints" L2
render_level x4 3 L3.fine; per_tree "level 3, footprints / 4" L3.fine
render_level x4 2 L2.fine; per_tree "level 2, footprints / 4" L2.fine
render_level x8 1 L1.fine; per_tree "level 1, footprints / 8" L1.fine

echo
echo "The same with branches 30 times thinner, against needles of their own:"
forest_scene thin1 320 240 "$all" thin
forest_scene thin4 1280 960 "$all" thin
forest_scene thin8 2560 1920 "$all" thin
truth thin1 thin.truth
render_level thin1 3 thin.L3 thin.truth; per_tree "level 3 at the scene's footprints" thin.L3
render_level thin4 3 thin.L3.fine thin.truth; per_tree "level 3, footprints / 4" thin.L3.fine
render_level thin8 1 thin.L1.fine thin.truth; per_tree "level 1, footprints / 8" thin.L1.fine

echo
echo "Per tree against level 1 (footprints / 8), the effects added one by one:"
for effects in diffuse self shadows; do
  case $effects in
    diffuse) set='["diffuse"]' ;;
    self) set='["diffuse", "self_shadowing"]' ;;
    shadows) set='["diffuse", "self_shadowing", "shadows"]' ;;
  esac
  if [ "$effects" = shadows ]; then
    base=L1.fine; l2=L2.fine; l3=L3.fine
  else
    forest_scene "e4.$effects" 1280 960 "$set"
    forest_scene "e8.$effects" 2560 1920 "$set"
    render_level "e8.$effects" 1 "L1.$effects"; base="L1.$effects"
    render_level "e4.$effects" 2 "L2.$effects"; l2="L2.$effects"
    render_level "e4.$effects" 3 "L3.$effects"; l3="L3.$effects"
  fi
  ratio "level 2 / level 1, + $effects" "$l2" "$base"
  ratio "level 3 / level 1, + $effects" "$l3" "$base"
done
echo "level_decomposition: images in $out" >&2
