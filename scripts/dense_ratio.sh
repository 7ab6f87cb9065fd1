#!/usr/bin/env bash
# A benchmark, not a test: issue 11's "dense 1280 firs in the paper's region at most 3x the 80
# firs' time". The multiscale render's CPU seconds (median of --repeat 3, no geometry) of
# scenes/large/paper-forest-1280.json and scenes/paper-forest.json, measured in PAIRS
# interleaved pairs (default 3) so that the shared machine's load falls on both alike; prints
# each pair's ratio and their median, and writes them to build/bench/dense-ratio.json.
# About four minutes on two cores. Builds first if needed.
set -euo pipefail
cd "$(dirname "$0")/.."
pairs=${1:-3}
[[ "$pairs" =~ ^[1-9][0-9]*$ ]] || { echo "usage: $0 [PAIRS]" >&2; exit 2; }
[ -x build/bin/vdbtrace ] || bash scripts/run.sh
out=build/bench
mkdir -p "$out"
for i in $(seq 1 "$pairs"); do
  for scene in large/paper-forest-1280 paper-forest; do
    name=$(basename "$scene")
    echo "dense_ratio: pair $i of $pairs, $name" >&2
    build/bin/vdbtrace --quiet bench "scenes/$scene.json" --geometry-samples 0 --repeat 3 \
        --json "$out/dense-ratio.$name.$i.json" >/dev/null
  done
done
python3 - "$out" "$pairs" <<'EOF'
import json, statistics, sys
out, pairs = sys.argv[1], int(sys.argv[2])
def cpu(name, i):
    with open(f"{out}/dense-ratio.{name}.{i}.json") as f:
        return json.load(f)["multiscale"]["cpu_seconds"]
rows = [(cpu("paper-forest-1280", i), cpu("paper-forest", i)) for i in range(1, pairs + 1)]
ratios = [d / s for d, s in rows]
for (d, s), r in zip(rows, ratios):
    print(f"1280 firs {d:.2f} CPU-s, 80 firs {s:.2f} CPU-s: ratio {r:.2f}")
median = statistics.median(ratios)
print(f"median ratio {median:.2f} over {pairs} pairs (issue 11 asks for at most 3)")
with open(f"{out}/dense-ratio.json", "w") as f:
    json.dump({"pairs": [{"dense_cpu_seconds": d, "forest_cpu_seconds": s, "ratio": r}
                         for (d, s), r in zip(rows, ratios)],
               "median_ratio": median}, f, indent=1)
EOF
