#!/usr/bin/python3
"""Damaged .vdb files through the tools that read them (`bake verify`, `vdbtrace render
--method reference --grids`), in the three manifest situations: none, the original (which no
longer matches), and one rewritten to match the damaged bytes (a file edited elsewhere).

Bytes are flipped, zeroed in blocks, cut short, or set to 0x7f (a huge count), half of them in
the first 2 KiB (header, metadata, topology). Each file must be read or refused with status 2
and one line naming it, never a signal or a hang: OpenVDB 10.0.1 crashes on some such bytes,
so the tools parse foreign ones in a child process first.

Under scripts/sanitize.sh a sanitizer's report from the child (OpenVDB's own memory errors on
damaged bytes, which the child exists to contain) ends that child and counts as a refusal; the
tool around it is what must survive.

Usage: vdb_fuzz.py BAKE VDBTRACE SOURCE_DIR [FILES] [SEED]. Exits 1 on any finding.
"""
import json
import os
import random
import shutil
import subprocess
import sys
import tempfile

bake, vdbtrace, src = sys.argv[1:4]
count = int(sys.argv[4]) if len(sys.argv) > 4 else 60
rng = random.Random(int(sys.argv[5]) if len(sys.argv) > 5 else 3)
SANITIZED = os.environ.get("PINE_SANITIZED") == "1"
TIMEOUT_S = 600 if SANITIZED else 120
findings = []


def fnv1a64(data):
    h = 14695981039346656037
    for b in data:
        h = ((h ^ b) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return h


def matching_manifest(path, data):
    with open(path + ".json", "w") as f:
        json.dump({"file": os.path.basename(path), "bytes": len(data),
                   "fnv1a64": "%016x" % fnv1a64(data)}, f)


def damaged(data, trial):
    data = bytearray(data)
    span = min(2048, len(data)) if trial % 8 < 4 else len(data)
    at = rng.randrange(span)
    kind = trial % 4
    if kind == 0:
        data[at] ^= 1 << rng.randrange(8)
    elif kind == 1:
        data[at:at + 4096] = bytes(len(data[at:at + 4096]))
    elif kind == 2:
        del data[at:]
    else:
        data[at:at + 4] = b"\x7f" * len(data[at:at + 4])
    return bytes(data)


def run(argv):
    try:
        r = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           timeout=TIMEOUT_S)
        return r.returncode, r.stdout.decode("utf-8", "replace"), r.stderr.decode("utf-8",
                                                                                  "replace")
    except subprocess.TimeoutExpired:
        return "timeout", "", ""


with tempfile.TemporaryDirectory() as work:
    scene = os.path.join(src, "scenes", "bough.json")
    good = os.path.join(work, "good.vdb")
    status, _, err = run([bake, "tree", scene, "--tree", "0", "--voxel-size", "0.8", "--out",
                          good])
    if status != 0:
        sys.exit(f"vdb_fuzz: cannot bake: {err.strip()}")
    with open(good, "rb") as f:
        original = f.read()
    folders = {name: os.path.join(work, name) for name in ["matching", "original", "none"]}
    for folder in folders.values():
        os.mkdir(folder)
    for trial in range(count):
        data = damaged(original, trial)
        while data == original:  # zeros over zeros, 0x7f over 0x7f: no damage, drawn again
            data = damaged(original, trial)
        name = "t%03d.vdb" % trial
        for situation, folder in folders.items():
            path = os.path.join(folder, name)
            with open(path, "wb") as f:
                f.write(data)
            if situation == "matching":
                matching_manifest(path, data)
            elif situation == "original":
                shutil.copy(good + ".json", path + ".json")

    read = {}
    for situation, folder in folders.items():
        status, out, err = run([bake, "verify", folder])
        lines = out.splitlines()
        # 2: some refused; 3: none refused, some read without a manifest.
        if status not in ((0, 2) if situation != "none" else (2, 3)):
            findings.append(f"bake verify, manifest {situation}: status {status}: "
                            f"{err.strip()[-300:]}")
            continue
        if len(lines) != count:
            findings.append(f"bake verify, manifest {situation}: {len(lines)} lines for "
                            f"{count} files")
        # Without a manifest a file is read from its metadata (": unverified, "), in the same
        # isolated child as one whose manifest matches.
        accepted = ": ok, " if situation != "none" else ": unverified, "
        read[situation] = sum(accepted in line for line in lines)
        for line in lines:
            if accepted not in line and ": refused: " not in line:
                findings.append(f"bake verify, manifest {situation}: {line[:200]}")
        if situation == "original" and read[situation]:
            findings.append(f"bake verify read {read[situation]} damaged files whose manifest "
                            f"is {situation}")

    # The renderer's own path, on a few of the files its manifest check lets through.
    bough = os.path.join(work, "bough.json")
    with open(scene) as f:
        s = json.load(f)
    s["camera"]["resolution"] = [32, 24]
    with open(bough, "w") as f:
        json.dump(s, f)
    for trial in range(0, count, max(1, count // 8)):
        path = os.path.join(folders["matching"], "t%03d.vdb" % trial)
        out = os.path.join(work, "r.exr")
        status, _, err = run([vdbtrace, "render", bough, "--method", "reference", "--grids",
                              path, "--out", out])
        lines = [line for line in err.replace("\r", "\n").splitlines() if line.strip()]
        if status == 2:
            if "t%03d.vdb" % trial not in lines[-1]:
                findings.append(f"render --grids t{trial:03d}: {lines[-1][:200]}")
        elif status != 0:
            findings.append(f"render --grids t{trial:03d}: status {status}: "
                            f"{lines[-1][:200] if lines else ''}")
        for f in [out, out[:-4] + ".png"]:
            if os.path.exists(f):
                os.remove(f)

for f in findings:
    print("FINDING:", f)
print(f"vdb fuzz: {count} damaged files x 3 manifest situations; read with a matching "
      f"manifest: {read.get('matching', '?')}, without one: {read.get('none', '?')}; "
      f"{len(findings)} findings")
sys.exit(1 if findings else 0)
