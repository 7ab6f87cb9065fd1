#!/usr/bin/env python3
"""kill -9 at random moments, and two runs at once, writing one folder.

After every kill, each grid under its final name must be accepted by its manifest (`bake
verify`: size and checksum, then OpenVDB in a child process), and each render's EXR must be
either the previous one or a whole new one with its preview beside it. A rerun then succeeds
and leaves no temporary behind. Two bakes, or two renders, into one folder at once leave only
pairs and files that match.

Usage: kill_test.py BAKE VDBTRACE SOURCE_DIR [KILLS] [SEED]
"""
import os
import random
import signal
import subprocess
import sys
import tempfile
import time

bake, vdbtrace, src = sys.argv[1:4]
kills = int(sys.argv[4]) if len(sys.argv) > 4 else 12
rng = random.Random(int(sys.argv[5]) if len(sys.argv) > 5 else 14)
scene = os.path.join(src, "scenes", "three-firs.json")
bough = os.path.join(src, "scenes", "bough.json")
failures = []


def fail(what):
    print("FAIL:", what)
    failures.append(what)


def temporaries(folder):
    return sorted(n for n in os.listdir(folder) if ".tmp-" in n)


def run(args):
    return subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def killed_after(args, seconds):
    """Starts args, kills it with SIGKILL after `seconds` (if still running); its exit status."""
    p = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(seconds)
    p.send_signal(signal.SIGKILL)
    return p.wait()


def timed(args):
    start = time.monotonic()
    r = run(args)
    if r.returncode != 0:
        fail(f"{' '.join(args)}: exit {r.returncode}: {r.stderr.strip()}")
    return time.monotonic() - start


def verified(folder, when):
    r = run([bake, "verify", folder])
    if r.returncode != 0:
        refused = [line for line in r.stdout.splitlines() if "refused" in line]
        fail(f"{when}: {len(refused)} refused: {refused[:2]}")


def exr_whole(exr):
    """Whether every pixel of `exr` can be read (oiiotool reads them all for --printstats)."""
    return run(["oiiotool", exr, "--printstats"]).returncode == 0


with tempfile.TemporaryDirectory() as work:
    # bake scene, killed at random moments between two voxel sizes (so that files change).
    folder = os.path.join(work, "bake")
    sizes = ["1", "1.5"]
    whole = timed([bake, "scene", scene, "--voxel-size", sizes[0], "--out-dir", folder])
    interrupted = 0
    for k in range(kills):
        status = killed_after([bake, "scene", scene, "--voxel-size", sizes[(k + 1) % 2],
                               "--out-dir", folder], rng.uniform(0.0, 1.2 * whole))
        interrupted += status == -signal.SIGKILL
        verified(folder, f"bake killed ({k})")
    print(f"bake scene: {interrupted} of {kills} runs killed mid-way ({whole:.2f} s a run)")
    # The moment random kills miss: between a manifest's rename and its grid's.
    killed = subprocess.run([bake, "scene", scene, "--voxel-size", sizes[1], "--out-dir", folder],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            env=dict(os.environ, PINE_KILL_BEFORE_RENAME="tree_001.vdb"))
    if killed.returncode != -signal.SIGKILL:
        fail(f"fault injection did not kill bake scene (status {killed.returncode})")
    verified(folder, "bake killed between a manifest's rename and its grid's")
    timed([bake, "scene", scene, "--voxel-size", sizes[0], "--out-dir", folder])
    verified(folder, "rerun after the kills")
    if temporaries(folder):
        fail(f"temporaries left after a rerun: {temporaries(folder)}")

    # Two bakes into one folder at once, of different voxel sizes: each pair from one of them.
    for trial in range(3):
        runs = [subprocess.Popen([bake, "scene", scene, "--voxel-size", size, "--out-dir",
                                  folder], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
                for size in sizes]
        for p in runs:
            _, err = p.communicate()
            if p.returncode != 0:
                fail(f"concurrent bake: exit {p.returncode}: {err.decode().strip()}")
        verified(folder, f"two bakes at once ({trial})")
        if temporaries(folder):
            fail(f"temporaries left by two bakes at once: {temporaries(folder)}")

    # render, killed at random moments: the previous EXR and PNG, or a whole new pair.
    out = os.path.join(work, "render", "b.exr")
    os.makedirs(os.path.dirname(out))
    whole = timed([vdbtrace, "render", bough, "--out", out])
    png = out[:-4] + ".png"

    def stamps():
        return os.stat(out).st_mtime_ns, os.stat(png).st_mtime_ns

    for k in range(kills):
        exr_before, png_before = stamps()
        killed_after([vdbtrace, "render", bough, "--out", out], rng.uniform(0.0, 1.2 * whole))
        if not exr_whole(out):
            fail(f"render killed ({k}): {out} is not a whole EXR")
        exr_after, png_after = stamps()
        if exr_after != exr_before and png_after == png_before:
            fail(f"render killed ({k}): a new EXR beside the previous preview")
    # Killed just before the preview's rename, then just before the EXR's: the EXR is never
    # newer than its preview.
    for name in ["b.png", "b.exr"]:
        exr_before, png_before = stamps()
        killed = subprocess.run([vdbtrace, "render", bough, "--out", out],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                env=dict(os.environ, PINE_KILL_BEFORE_RENAME=name))
        if killed.returncode != -signal.SIGKILL:
            fail(f"fault injection did not kill render before {name} ({killed.returncode})")
        exr_after, png_after = stamps()
        if exr_after != exr_before:
            fail(f"render killed before renaming {name}: the EXR was replaced")
        if not exr_whole(out):
            fail(f"render killed before renaming {name}: {out} is not a whole EXR")
    timed([vdbtrace, "render", bough, "--out", out])
    if temporaries(os.path.dirname(out)):
        fail(f"render: temporaries left after a rerun: {temporaries(os.path.dirname(out))}")

print(f"kill test: {len(failures)} failed")
sys.exit(1 if failures else 0)
