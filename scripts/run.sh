#!/usr/bin/env bash
# The main job, from a fresh Debian 12 machine: install what is missing, build (Release), and
# measure the paper's approximations (`analytic sweep`) into out/sweep.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DPINE_BUILD_BENCHMARKS=ON
cmake --build build
build/bin/analytic sweep --out out/sweep
echo "run: report in out/sweep (summary.json, sweep.png, CSV)" >&2
