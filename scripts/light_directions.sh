#!/usr/bin/env bash
# The faithful models' per-tree error in a forest under lights other than the scene's own
# (docs/models.md, "Layer correlation"): the paper forest at 320 x 240 with
# self-shadowing, its sun moved to each of four directions (the scene's, 49 degrees from the
# view; beside the view, 7; to the side, 83; behind the trees, 123), against an explicit-needle
# truth of TRUTH_SPP samples per pixel (default 1024) for each. Each multiscale level is forced
# on every bough hit as in scripts/level_decomposition.sh: level 3 at the scene's footprints,
# level 2 at a quarter of them and level 1 (the needles themselves under the models' shadows)
# at an eighth, box-downsampled to 320 x 240 and measured per tree (`vdbtrace diff`).
#
#   bash scripts/light_directions.sh [DIR]     renders into DIR (default: a temporary folder)
#
# Takes about ten minutes on 2 cores. Uses build/bin (build first) and oiiotool.
set -euo pipefail
cd "$(dirname "$0")/.."
tool=light_directions
out=${1:-$(mktemp -d)}
source scripts/forest_levels.sh

all='["diffuse", "self_shadowing", "shadows"]'
for light in "scene:[-0.5, -0.6, 0.8]" "camera:[-0.05, -0.98, 0.31]" "side:[1, 0, 0.8]" \
             "behind:[0.3, 0.8, 0.8]"; do
  name=${light%%:*}
  towards=${light#*:}
  forest_scene "$name" 320 240 "$all" - "$towards"
  forest_scene "$name.x4" 1280 960 "$all" - "$towards"
  forest_scene "$name.x8" 2560 1920 "$all" - "$towards"
  truth "$name" "$name.truth"
  render_level "$name" 3 "$name.L3" "$name.truth"
  per_tree "$name light, level 3 at the scene's footprints" "$name.L3"
  render_level "$name.x4" 2 "$name.L2" "$name.truth"
  per_tree "$name light, level 2, footprints / 4" "$name.L2"
  render_level "$name.x8" 1 "$name.L1" "$name.truth"
  per_tree "$name light, level 1, footprints / 8" "$name.L1"
done
