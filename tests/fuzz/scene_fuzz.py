#!/usr/bin/python3
"""Malformed and hostile scenes through every tool that reads one.

The corpus is generated here, deterministically, from the shipped scenes: the JSON broken
(truncated, not an object, invalid bytes, nested 100,000 deep), each key removed, each value
replaced by a value of another type or an extreme magnitude, unknown keys added, and resource
bombs (huge images, forests, needles per cone, cone spacings, bushy L-systems, lights of
intensity 1e308, vectors of length 1e-200). Each case is run through `vdbtrace render` (and a
sample also through the geometry and reference methods and `bake tree`), each run limited in
time and memory. A run must either succeed, writing an EXR whose pixels are all finite, or exit
with status 2 and one line on stderr; never a signal, another status, a hang, a NaN pixel or a
file left under the output's name by a failed run.

Usage: scene_fuzz.py VDBTRACE BAKE SOURCE_DIR [CASES] [SEED] [--keep DIR]. Exits 1 on any
finding; --keep writes the corpus into DIR to look at; PINE_FUZZ_VERBOSE=1 prints each run's
last line. PINE_SANITIZED=1 (a sanitizer build) lifts the address-space limit and the timeout.
"""
import copy
import json
import os
import random
import resource
import subprocess
import sys
import tempfile
import time

args = [a for a in sys.argv[1:] if not a.startswith("--keep")]
keep = None
if "--keep" in sys.argv:
    keep = sys.argv[sys.argv.index("--keep") + 1]
    args.remove(keep)
vdbtrace, bake, src = args[:3]
cases_wanted = int(args[3]) if len(args) > 3 else 160
rng = random.Random(int(args[4]) if len(args) > 4 else 7)
SANITIZED = os.environ.get("PINE_SANITIZED") == "1"  # ASan reserves terabytes: no RLIMIT_AS
TIMEOUT_S = 240 if SANITIZED else 60

base_scenes = {}
for name in ["bough.json", "three-firs.json", "paper-forest.json"]:
    with open(os.path.join(src, "scenes", name)) as f:
        scene = json.load(f)
    scene["camera"]["resolution"] = [48, 36]  # what renders, renders fast
    for tree in scene["trees"]:  # and grows fast: the forest's keys, not its size
        if "scatter" in tree:
            tree["scatter"]["count"] = min(tree["scatter"]["count"], 3)
    base_scenes[name] = scene


def leaves(value, path=()):
    """Every (path, value) of a JSON value, objects and arrays included."""
    yield path, value
    if isinstance(value, dict):
        for k, v in value.items():
            yield from leaves(v, path + (k,))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from leaves(v, path + (i,))


def replaced(scene, path, value):
    s = copy.deepcopy(scene)
    target = s
    for key in path[:-1]:
        target = target[key]
    if value is KeyError:
        del target[path[-1]]
    else:
        target[path[-1]] = value
    return s


WRONG = [None, True, "text", "", -1, 0, 1, -1e308, 1e308, 5e-324, 1e-200, 1e200,
         123456789012345678901234567890, [], [0], [1, 2], [1e308, 1e308, 1e308], {}, {"x": 1},
         [0, 0, 0], [1e-200, 0, 0], [1e200, 1e200, 0], -0.0]


def generated():
    """(name, text) of every case, hostile bytes first, then value mutations sampled."""
    bough = json.dumps(base_scenes["bough.json"])
    out = [
        ("empty", ""), ("null", "null"), ("array", "[]"), ("number", "42"),
        ("string", '"scene"'), ("bom", "\ufeff" + bough),
        ("invalid-utf8", bough[:40] + "\udcff" + bough[40:]),
        ("nul-byte", bough[:60] + "\x00" + bough[60:]),
        ("deep-array", "[" * 100000 + "]" * 100000),
        ("deep-object", '{"a":' * 100000 + "1" + "}" * 100000),
        ("duplicate-key", bough[:-1] + ', "camera": 1}'),
        ("nan-literal", bough.replace('"fov_deg": 40', '"fov_deg": NaN')),
        ("huge-number-text", bough.replace('"fov_deg": 40', '"fov_deg": 1' + "0" * 400)),
        ("long-string", bough.replace('"name": "bough"', '"name": "' + "x" * 1000000 + '"')),
    ]
    for cut in [1, 10, len(bough) // 3, len(bough) // 2, len(bough) - 1]:
        out.append((f"truncated-{cut}", bough[:cut]))

    bombs = []
    s = copy.deepcopy(base_scenes["bough.json"])
    s["camera"]["resolution"] = [16384, 16384]
    bombs.append(("huge-image", s))
    s = copy.deepcopy(base_scenes["three-firs.json"])
    s["trees"] = [{"scatter": {"species": "fir", "count": 100000, "region": [[0, 0], [5000, 5000]],
                               "seed": 1}}]
    bombs.append(("forest-100000", s))
    s = copy.deepcopy(base_scenes["bough.json"])
    s["species"]["branch"]["needles"]["base"]["per_cone"] = 1000000
    bombs.append(("needles-per-cone", s))
    s = copy.deepcopy(base_scenes["bough.json"])
    s["species"]["branch"]["needles"]["base"]["cone_spacing"] = 1e-6
    s["species"]["branch"]["needles"]["tip"]["cone_spacing"] = 1e-6
    bombs.append(("cone-spacing", s))
    s = copy.deepcopy(base_scenes["three-firs.json"])
    s["trees"] = s["trees"][:1]
    s["species"]["fir"]["lsystem"].update(axiom="A", rules={"A": "F[&A][^A]"}, iterations=17)
    bombs.append(("bushy-lsystem", s))
    s = copy.deepcopy(base_scenes["three-firs.json"])
    s["species"]["fir"]["lsystem"].update(axiom="A", rules={"A": "AA"}, iterations=30)
    bombs.append(("doubling-lsystem", s))
    s = copy.deepcopy(base_scenes["bough.json"])
    s["lights"][0]["intensity"] = 1e308
    bombs.append(("light-1e308", s))
    s = copy.deepcopy(base_scenes["bough.json"])
    s["camera"]["up"] = [0, 0, 1e-200]
    bombs.append(("up-1e-200", s))
    s = copy.deepcopy(base_scenes["bough.json"])
    s["camera"]["up"] = [0, 0, 1e200]
    bombs.append(("up-1e200", s))
    s = copy.deepcopy(base_scenes["bough.json"])
    s["camera"]["look_at"] = s["camera"]["position"]
    bombs.append(("look-at-eye", s))
    s = copy.deepcopy(base_scenes["bough.json"])
    s["camera"]["up"] = [0, 30, -10]  # along the view direction
    bombs.append(("up-along-view", s))
    # Camera paths: too many frames, the most frames allowed (each checked as the file is
    # read), and a smooth curve overshooting its keys' field of view below 0.
    s = copy.deepcopy(base_scenes["bough.json"])
    s["camera_path"] = {"keys": [{"frame": 0}, {"frame": 9999999, "fov_deg": 20}],
                        "frames": [0, 9999999]}
    bombs.append(("path-frames-bomb", s))
    s = copy.deepcopy(base_scenes["bough.json"])
    s["camera_path"] = {"keys": [{"frame": 0}, {"frame": 99999, "position": [0, -60, 0]}],
                        "frames": [0, 99999]}
    bombs.append(("path-100000-frames", s))
    s = copy.deepcopy(base_scenes["bough.json"])
    s["camera_path"] = {"keys": [{"frame": 0, "fov_deg": 170}, {"frame": 1, "fov_deg": 170},
                                 {"frame": 2, "fov_deg": 1}, {"frame": 30, "fov_deg": 1}]}
    bombs.append(("path-overshoot", s))
    out += [(name, json.dumps(s)) for name, s in bombs]

    mutations = []
    for scene_name, scene in base_scenes.items():
        stem = scene_name[:-5]
        for path, value in leaves(scene):
            if not path or (path and path[-1] == "comment"):
                continue
            where = ".".join(str(p) for p in path)
            mutations.append((f"{stem}-remove-{where}", replaced(scene, path, KeyError)))
            for i, wrong in enumerate(WRONG):
                if wrong == value and type(wrong) is type(value):
                    continue
                mutations.append((f"{stem}-{where}-wrong{i}", replaced(scene, path, wrong)))
            if isinstance(value, dict):
                mutations.append((f"{stem}-{where}-unknown-key",
                                  replaced(scene, path, dict(value, colour_of_sky=1))))
    rng.shuffle(mutations)
    out += [(name, json.dumps(s)) for name, s in mutations[:max(0, cases_wanted - len(out))]]
    return out


def limit_memory():
    if not SANITIZED:
        resource.setrlimit(resource.RLIMIT_AS, (6 << 30, 6 << 30))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


def run(argv):
    try:
        r = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           timeout=TIMEOUT_S, preexec_fn=limit_memory)
        return r.returncode, r.stderr.decode("utf-8", "replace")
    except subprocess.TimeoutExpired:
        return "timeout", ""


def finite_pixels(exr):
    """No NaN in any channel, no infinity but in Z (OpenEXR's depth: +inf where nothing is
    hit)."""
    info = subprocess.run(["oiiotool", "--info", "-v", exr], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True)
    r = subprocess.run(["oiiotool", exr, "--printstats"], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, text=True)
    if r.returncode != 0 or info.returncode != 0:
        return False, "unreadable: " + (r.stderr + info.stderr).strip()[:200]
    channels = []
    for line in info.stdout.splitlines():
        if line.strip().startswith("channel list:"):
            channels = [c.strip() for c in line.split(":", 1)[1].split(",")]
    for line in r.stdout.splitlines():
        line = line.strip()
        if line.startswith("Stats NanCount:") or line.startswith("Stats InfCount:"):
            counts = [int(n) for n in line.split(":")[1].split()]
            if len(counts) != len(channels):
                return False, f"{line} for channels {channels}"
            for channel, n in zip(channels, counts):
                if n and not (channel == "Z" and line.startswith("Stats InfCount:")):
                    return False, f"{line} ({channel})"
    return True, ""


findings = []
outcomes = {"written": 0, "refused": 0}


timings = []  # (seconds, case, subcommand, status, last stderr line)


def check(name, argv, out):
    start = time.monotonic()
    status, err = run(argv)
    timings.append((time.monotonic() - start, name, argv[1], status,
                    err.strip().split("\n")[-1][-150:]))
    lines = [line for line in err.replace("\r", "\n").splitlines() if line.strip()]
    what = f"{name}: {os.path.basename(argv[0])} {argv[1]}"
    if status == 0:
        if out.endswith(".exr"):
            ok, why = finite_pixels(out)
            if not ok:
                findings.append(f"{what}: exit 0 with non-finite pixels ({why})")
        outcomes["written"] += 1
    elif status == 2:
        # Progress and the scene's summary may come first; the error is the last line, the
        # tool's own (not a library's or the runtime's words).
        last = lines[-1] if lines else ""
        if not last.startswith(os.path.basename(argv[0]) + ": "):
            findings.append(f"{what}: exit 2 without the tool's one-line error: {last[:200]}")
        if any(marker in err for marker in ["terminate called", "Assertion", "runtime error:",
                                            "AddressSanitizer", "std::bad_alloc"]):
            findings.append(f"{what}: exit 2 after {last[:200]}")
        for left in [out, out[:-4] + ".png", out + ".json"]:
            if os.path.exists(left):
                findings.append(f"{what}: a refused run left {os.path.basename(left)}")
        outcomes["refused"] += 1
    else:
        findings.append(f"{what}: status {status}: {lines[-1][:200] if lines else ''}")
    for f in os.listdir(os.path.dirname(out)):
        if ".tmp-" in f:
            findings.append(f"{what}: temporary {f} left")
            os.remove(os.path.join(os.path.dirname(out), f))
    for f in [out, out[:-4] + ".png", out + ".json"]:
        if os.path.exists(f):
            os.remove(f)


with tempfile.TemporaryDirectory() as work:
    corpus = generated()
    first_mutation = next((k for k, (name, _) in enumerate(corpus)
                           if name.startswith(("bough-", "three-firs-", "paper-forest-"))),
                          len(corpus))
    if keep:
        os.makedirs(keep, exist_ok=True)
    for k, (name, text) in enumerate(corpus):
        scene = os.path.join(work, "scene.json")
        with open(scene, "w", encoding="utf-8", errors="surrogateescape") as f:
            f.write(text)
        if keep:
            with open(os.path.join(keep, name[:200] + ".json"), "w", encoding="utf-8",
                      errors="surrogateescape") as f:
                f.write(text)
        out = os.path.join(work, "out", "image.exr")
        os.makedirs(os.path.dirname(out), exist_ok=True)
        check(name, [vdbtrace, "render", scene, "--out", out, "--max-memory", "4"], out)
        if k < first_mutation or k % 4 == 0:  # bombs, and every fourth mutation, everywhere
            check(name, [vdbtrace, "render", scene, "--method", "geometry", "--out", out,
                         "--max-memory", "4"], out)
            check(name, [vdbtrace, "render", scene, "--method", "reference", "--voxel-size",
                         "2", "--out", out, "--max-memory", "4"], out)
            check(name, [bake, "tree", scene, "--tree", "0", "--voxel-size", "2", "--out",
                         out[:-4] + ".vdb", "--max-memory", "4"], out[:-4] + ".vdb")
        if sys.stderr.isatty():
            print(f"\r{k + 1}/{len(corpus)} scenes", end="", file=sys.stderr, flush=True)
        elif (k + 1) % 20 == 0 or k + 1 == len(corpus):
            print(f"{k + 1}/{len(corpus)} scenes", file=sys.stderr, flush=True)
    if sys.stderr.isatty():
        print(file=sys.stderr)

if os.environ.get("PINE_FUZZ_VERBOSE"):  # every run's answer, then the slowest
    for t in timings:
        print("%s %s %s: %s" % t[1:])
    for t in sorted(timings)[-10:]:
        print("%.2f s %s %s %s" % t[:4])
    print("total %.1f s over %d runs" % (sum(t[0] for t in timings), len(timings)))
for f in findings:
    print("FINDING:", f)
print(f"scene fuzz: {len(corpus)} scenes, {outcomes['written']} runs written, "
      f"{outcomes['refused']} refused, {len(findings)} findings")
sys.exit(1 if findings else 0)
