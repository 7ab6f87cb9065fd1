#!/usr/bin/env bash
# The published comparisons (docs/compare/*/report.md, issue 10): `vdbtrace compare` on
# three-firs.json and paper-forest.json at their cameras' 640 x 480, every method against a
# truth of 256 samples per pixel (checked against 1024), each render timed as the median of
# three runs, the error budget included. The paper forest names "shadows" without
# "self_shadowing", which explicit needles cannot render apart, so it is compared with both
# (--self-shadowing). Each report's folder, without its EXRs, replaces docs/compare/NAME.
#
#   bash scripts/compare_reports.sh [NAME...]   NAME: three-firs, paper-forest (default: both)
#
# About 4 minutes for the three firs and 36 for the forest on 2 cores (2026-12-05); uses
# build/bin (build first) and matplotlib for the plots. Run it on a machine left alone: the
# times are CPU seconds, but a loaded machine still moves them.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${VDBTRACE:-build/bin/vdbtrace}
[ -x "$bin" ] || { echo "compare_reports: $bin is missing: build first" >&2; exit 2; }
names=("$@")
[ ${#names[@]} -gt 0 ] || names=(three-firs paper-forest)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for name in "${names[@]}"; do
    case $name in
        three-firs) extra=() ;;
        paper-forest) extra=(--self-shadowing) ;;
        *) echo "compare_reports: no report named $name (three-firs, paper-forest)" >&2; exit 2 ;;
    esac
    "$bin" compare "scenes/$name.json" "${extra[@]}" --truth-samples 256 \
        --out-dir "$work/$name"
    rm -f "$work/$name"/*.exr
    rm -rf "docs/compare/$name.new"
    cp -r "$work/$name" "docs/compare/$name.new"
    rm -rf "docs/compare/$name"
    mv "docs/compare/$name.new" "docs/compare/$name"
    echo "compare_reports: docs/compare/$name/report.md"
done
