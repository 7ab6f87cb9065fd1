#!/usr/bin/env bash
# The published animation results (issue 13), into docs/animation/:
#   paper-forest/   `vdbtrace animate-compare` of paper-forest.json's camera path (the forest
#                   receding, 24 frames) at 320 x 240 with self-shadowing (the explicit needles
#                   always self-shadow): flicker per method and level band, over the frames,
#                   a strip of frames; each method's error flicker against geometry at 64 spp
#   scaling.csv     scripts/animation.sh 2 4: the same path rendered by `vdbtrace render
#                   --frames 1-24` (multiscale, 320 x 240) on 1 process and under mpirun with 2
#                   and 4 ranks: frames per CPU-second and per wall second, every frame
#                   checked identical to one process's
#
#   bash scripts/animation_reports.sh [report|scaling]   (default: both)
#
# About 8 minutes on 2 cores; uses build/bin (build first), mpirun (openmpi-bin) for the
# scaling, matplotlib for the plot. Run it on a machine left alone: a loaded one moves the
# seconds.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${VDBTRACE:-build/bin/vdbtrace}
[ -x "$bin" ] || { echo "animation_reports: $bin is missing: build first" >&2; exit 2; }
parts=("$@")
[ ${#parts[@]} -gt 0 ] || parts=(report scaling)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scene=scenes/paper-forest.json
mkdir -p docs/animation
for part in "${parts[@]}"; do
    case $part in
    report)
        "$bin" animate-compare "$scene" --self-shadowing --resolution 320x240 \
            --truth-samples 64 --out-dir "$work/paper-forest"
        rm -rf docs/animation/paper-forest
        cp -r "$work/paper-forest" docs/animation/paper-forest
        ;;
    scaling)
        bash scripts/animation.sh 2 4
        cp out/animation/scaling.csv docs/animation/scaling.csv
        ;;
    *) echo "animation_reports: report or scaling, not $part" >&2; exit 2 ;;
    esac
done
