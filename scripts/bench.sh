#!/usr/bin/env bash
# Benchmarks, not tests: timings are measured and reported, never asserted. Builds first if
# needed. 1) cost per evaluation of each shader and of the quadrature it replaces; 2) the
# paper's forest (Figure 11) at 640x480 with the multiscale tracer against geometry at 4 spp in
# the same run: CPU seconds (median of 3) and their ratio, cone rays per second, peak memory,
# share of pixels per level, and section 7's scaling claim (the cost of bough-level pixels with
# N x 2 and dh / 2); the numbers also in build/bench/paper-forest.json.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/bin/vdbtrace ] && [ -x build/bin/analytic_bench ] || bash scripts/run.sh
build/bin/analytic_bench --benchmark_min_time=0.5
mkdir -p build/bench
build/bin/vdbtrace bench scenes/paper-forest.json --scaling --repeat 3 \
    --json build/bench/paper-forest.json
