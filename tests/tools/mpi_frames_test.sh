#!/usr/bin/env bash
# Frames and tiles over MPI ranks (mpirun --oversubscribe on the loopback interface): every
# image identical, bit for bit, to the one-process render; a killed rank fails the job with
# mpirun's message and leaves no partial frame under a final name; the job then resumes.
# Usage: mpi_frames_test.sh VDBTRACE SOURCE_DIR. Exit 77 (skipped) without mpirun or without
# the MPI module beside VDBTRACE.
set -u
tool=$1
src=$2
. "$(dirname "$0")/cli_test_lib.sh"

command -v mpirun >/dev/null || { echo "SKIP: no mpirun"; exit 77; }
[ -e "$(dirname "$tool")/libpine_mpi_ranks.so" ] || { echo "SKIP: built without MPI"; exit 77; }
# Containers run tests as root, which Open MPI refuses unless told.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mpi() {
    local n=$1
    shift
    mpirun --oversubscribe -np "$n" --mca btl self,tcp --mca btl_tcp_if_include lo \
        --mca oob_tcp_if_include lo "$tool" "$@"
}
scene=$src/scenes/three-firs.json
small=(--resolution 64x48 --quiet)

# same A B: two EXRs with identical pixels in every channel.
same() {
    idiff -fail 0 -warn 0 -a "$1" "$2" >"$work/idiff" 2>&1 ||
        fail "$(basename "$2") differs from the one-process render: $(tail -3 "$work/idiff")"
}

mkdir -p "$work/one" "$work/r2" "$work/r3" "$work/band" "$work/kill"
"$tool" render "$scene" "${small[@]}" --frames 1-4 --out "$work/one/f.exr" ||
    fail "one process: exit $?"
for n in 2 3; do
    mpi "$n" render "$scene" "${small[@]}" --frames 1-4 --out "$work/r$n/f.exr" ||
        fail "$n ranks: exit $?"
    for f in 1 2 3 4; do same "$work/one/f.000$f.exr" "$work/r$n/f.000$f.exr"; done
done

# One image: bands of rows over the ranks, put together by rank 0.
"$tool" render "$scene" "${small[@]}" --out "$work/one/still.exr" || fail "still: exit $?"
mpi 3 render "$scene" "${small[@]}" --out "$work/band/still.exr" || fail "3-rank still: exit $?"
same "$work/one/still.exr" "$work/band/still.exr"
mpi 2 render "$scene" "${small[@]}" --frames 3 --out "$work/band/f.exr" --method geometry \
    --samples 2 || fail "2-rank frame: exit $?"
"$tool" render "$scene" "${small[@]}" --frames 3 --out "$work/one/g.exr" --method geometry \
    --samples 2 || fail "geometry frame: exit $?"
same "$work/one/g.0003.exr" "$work/band/f.0003.exr"

# Fewer tile rows than ranks (2 bands, 3 ranks), and fewer frames than ranks (2 frames, 3).
"$tool" render "$scene" --resolution 64x24 --quiet --out "$work/one/flat.exr" || fail "flat: exit $?"
mpi 3 render "$scene" --resolution 64x24 --quiet --out "$work/band/flat.exr" || fail "3 ranks, 2 bands: exit $?"
same "$work/one/flat.exr" "$work/band/flat.exr"
mpi 3 render "$scene" "${small[@]}" --frames 1-2 --out "$work/r3/two.exr" || fail "3 ranks, 2 frames: exit $?"
for f in 1 2; do same "$work/one/f.000$f.exr" "$work/r3/two.000$f.exr"; done
# An error on the leader alone (its folder gone) ends the job: one line naming the rank, status 2.
mpi 2 render "$scene" "${small[@]}" --out "$work/gone/x.exr" >/dev/null 2>"$work/err"
status=$?
[ "$status" -eq 2 ] || fail "leader's error: mpirun exited $status, expected 2"
grep -q "^vdbtrace: rank 0 of 2: cannot write .*folder .* is missing (ending the job)$" "$work/err" ||
    fail "leader's error: $(head -3 "$work/err")"

# Rank 1 killed once rank 0 has written a frame: the job fails, saying which rank died.
big=(--resolution 320x240 --frames 1-12)
mpi 2 render "$scene" "${big[@]}" --out "$work/kill/f.exr" >"$work/kill.out" 2>&1 &
job=$!
killed=""
for _ in $(seq 1 600); do
    if ls "$work/kill"/f.*.exr >/dev/null 2>&1; then
        for pid in $(pgrep -f "render $scene"); do
            if tr '\0' '\n' <"/proc/$pid/environ" 2>/dev/null | grep -qx OMPI_COMM_WORLD_RANK=1; then
                kill -9 "$pid" && killed=$pid
            fi
        done
        break
    fi
    sleep 0.1
done
wait "$job"
status=$?
grep -i "signal\|killed" "$work/kill.out" | head -2
[ -n "$killed" ] || fail "kill: found no rank 1 to kill"
[ "$status" -ne 0 ] || fail "kill: mpirun exited 0 after a rank was killed"
grep -qi "signal 9\|killed" "$work/kill.out" || fail "kill: no message names the dead rank: $(tail -5 "$work/kill.out")"
kept=$(ls "$work/kill"/f.*.exr 2>/dev/null | wc -l)
echo "kill: rank 1 (pid $killed) killed, mpirun exited $status, $kept of 12 frames whole"
[ "$kept" -ge 1 ] && [ "$kept" -lt 12 ] || fail "kill: $kept frames under final names, expected 1-11"
# Every frame under a final name is whole: identical to the one-process render of it.
"$tool" render "$scene" "${big[@]}" --quiet --out "$work/one/big.exr" || fail "big: exit $?"
for exr in "$work/kill"/f.*.exr; do same "$work/one/big.${exr##*/f.}" "$exr"; done
# The job resumes: the frames kept are not rendered again, the rest are, all identical.
mpi 2 render "$scene" "${big[@]}" --out "$work/kill/f.exr" 2>"$work/resume.err" ||
    fail "resume: exit $?"
grep -q "$kept of 12 frames already rendered by this job, kept" "$work/resume.err" ||
    fail "resume: did not keep the $kept frames: $(grep -v % "$work/resume.err" | head -3)"
for f in $(seq -f %04g 1 12); do same "$work/one/big.$f.exr" "$work/kill/f.$f.exr"; done

# Under a launcher without the module beside the executable: refused, not rendered N times.
cp "$tool" "$work/lone-vdbtrace"
OMPI_COMM_WORLD_SIZE=2 "$work/lone-vdbtrace" render "$scene" "${small[@]}" \
    --out "$work/x.exr" 2>"$work/err"
[ $? -eq 2 ] || fail "no module: expected exit 2"
grep -q "the MPI module libpine_mpi_ranks.so is missing" "$work/err" ||
    fail "no module: $(cat "$work/err")"
# Other commands are not split: refused under more than one rank.
mpi 2 diff "$work/one/still.exr" "$work/one/still.exr" --out "$work/d" >/dev/null 2>"$work/err" &&
    fail "diff under 2 ranks was accepted"
grep -q "only render splits its work" "$work/err" || fail "diff under 2 ranks: $(head -2 "$work/err")"

[ "$failures" -eq 0 ] && echo "mpi frames: all passed"
exit $((failures > 0))
