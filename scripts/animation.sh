#!/usr/bin/env bash
# The paper forest's camera path (scenes/paper-forest.json: the forest receding, frames 1-24)
# rendered with the multiscale tracer at 320 x 240 on one process, then under
# `mpirun -np R` for each R given (default 2; oversubscribed where the machine has fewer cores,
# each rank taking its share of them), each into out/animation/R/forest.####.exr (+ PNG);
# every frame of every rank count checked identical to one process's, bit for bit (idiff), and
# the frames per CPU-second (all ranks' CPU) and per wall second of each run written to
# out/animation/scaling.csv.
#
#   bash scripts/animation.sh [R...]
#
# About 45 s of wall time per run on 2 cores. Uses build/bin (build first: scripts/run.sh) and
# Open MPI's mpirun (scripts/install-deps.sh installs it). A run interrupted is resumed: the
# frames already rendered are kept.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${VDBTRACE:-build/bin/vdbtrace}
[ -x "$bin" ] || { echo "animation: $bin is missing: build first" >&2; exit 2; }
ranks=("$@")
[ ${#ranks[@]} -gt 0 ] || ranks=(2)
command -v mpirun >/dev/null || { echo "animation: mpirun is missing (openmpi-bin)" >&2; exit 2; }
# Containers run as root, which Open MPI refuses unless told; the loopback interface stands
# for a cluster's network.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
out=out/animation
csv=$out/scaling.csv
mkdir -p "$out"
echo "ranks,frames,wall_seconds,cpu_seconds,frames_per_cpu_second,frames_per_wall_second,cores" >"$csv.tmp"
for r in 1 "${ranks[@]}"; do
    rm -rf "${out:?}/$r" && mkdir -p "$out/$r"
    launch=()
    if [ "$r" -gt 1 ]; then
        launch=(mpirun --oversubscribe -np "$r" --mca btl self,tcp --mca btl_tcp_if_include lo
                --mca oob_tcp_if_include lo)
    fi
    # stderr kept in render.log and shown without its progress lines (a pipeline: the log is
    # whole before it is read).
    { "${launch[@]}" "$bin" render scenes/paper-forest.json --frames 1-24 --resolution 320x240 \
        --out "$out/$r/forest.exr" 2>&1 1>&3 | tee "$out/$r/render.log" | grep -v "%" >&2; } 3>&1
    # "vdbtrace: 24 frames in W s, C CPU-s on R ranks (F per CPU-second)"
    line=$(grep -E "^vdbtrace: [0-9]+ frames? in" "$out/$r/render.log" | tail -1)
    /usr/bin/python3 - "$line" "$r" "$(nproc)" >>"$csv.tmp" <<'PY'
import re, sys
m = re.search(r"(\d+) frames? in ([0-9.e+-]+) s, ([0-9.e+-]+) CPU-s on (\d+) rank", sys.argv[1])
if not m:
    sys.exit("animation: no summary line in the render's log")
frames, wall, cpu, ranks = int(m[1]), float(m[2]), float(m[3]), int(m[4])
if ranks != int(sys.argv[2]):
    sys.exit("animation: ran on %d ranks, asked for %s" % (ranks, sys.argv[2]))
print("%d,%d,%.3f,%.3f,%.4f,%.4f,%s" % (ranks, frames, wall, cpu, frames / cpu, frames / wall,
                                         sys.argv[3]))
PY
    if [ "$r" -gt 1 ]; then
        for exr in "$out/1"/forest.*.exr; do
            idiff -fail 0 -warn 0 -a "$exr" "$out/$r/${exr##*/}" >/dev/null ||
                { echo "animation: ${exr##*/} differs under $r ranks" >&2; exit 1; }
        done
        echo "animation: $r ranks: all frames identical to one process's" >&2
    fi
done
mv "$csv.tmp" "$csv"
column -s, -t "$csv" >&2
