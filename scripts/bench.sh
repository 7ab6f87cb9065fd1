#!/usr/bin/env bash
# Cost per evaluation of each shader and of the quadrature it replaces (not a test: timings
# are measured, never asserted). Builds first if needed.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/bin/analytic_bench ] || bash scripts/run.sh
build/bin/analytic_bench --benchmark_min_time=0.5 "$@"
