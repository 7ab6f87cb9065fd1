#!/usr/bin/env bash
# The main job, from a fresh Debian 12 machine: install what is missing, build (Release), render
# the paper's three firs (Figure 9) with the multiscale tracer, compare every method against the
# explicit-needle ground truth on one bough (`vdbtrace compare`, quick settings), and measure the
# paper's approximations (`analytic sweep`). Everything lands in out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DPINE_BUILD_BENCHMARKS=ON
cmake --build build
mkdir -p out
build/bin/vdbtrace render scenes/three-firs.json --method multiscale --out out/three-firs.exr \
    --stats out/three-firs.stats.json --aov level
build/bin/vdbtrace compare scenes/bough.json --quick --resolution 320x240 --out-dir out/compare
build/bin/analytic sweep --out out/sweep
echo "run: out/three-firs.{exr,png,level.png,stats.json}, out/compare/report.md (every method" \
     "against explicit needles, with times) and out/sweep/ (summary.json, sweep.png)" >&2
