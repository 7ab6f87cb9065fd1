#!/usr/bin/python3
"""Where in the trees one render departs from another (docs/models.md, "Whole scenes").

    python3 scripts/tree_bands.py RENDER.exr TRUTH.exr [--bands N]

Segments the pixels by the truth's `tree` AOV and each tree's bounding box in the image, cuts
each tree into N bands across (left to right) and N bands down (top to bottom), and prints per
band, over all trees of 20 rows or more, the render's foliage coverage, foliage luminance and
luminance per unit coverage against the truth's (the `foliage` and `foliage_luminance` AOVs
summed over the band's pixels). Both images must have the same size and those AOVs (vdbtrace
render writes them). Reads the EXRs through oiiotool (openimageio-tools).
"""
import argparse
import collections
import os
import re
import subprocess
import sys

PIXEL = re.compile(r"^\s*Pixel \((\d+), (\d+)\):(.*)$")


def channels(path, names):
    """{(x, y): tuple of the named channels} of an EXR, through oiiotool."""
    if not os.path.isfile(path):
        sys.exit("tree_bands: %s: no such file" % path)
    try:
        info = subprocess.run(["oiiotool", "--info", "-v", path], check=True,
                              capture_output=True, text=True).stdout
        dump = subprocess.run(["oiiotool", "--dumpdata", path], check=True,
                              capture_output=True, text=True).stdout
    except FileNotFoundError:
        sys.exit("tree_bands: oiiotool is missing (openimageio-tools)")
    except subprocess.CalledProcessError as e:
        lines = (e.stderr or "").strip().splitlines()
        sys.exit("tree_bands: cannot read %s%s" % (path, ": " + lines[0] if lines else ""))
    listed = re.search(r"channel list: (.*)", info)
    if not listed:
        sys.exit("tree_bands: %s lists no channels" % path)
    order = [c.strip() for c in listed.group(1).split(",")]
    missing = [n for n in names if n not in order]
    if missing:
        sys.exit("tree_bands: %s has no %s channel" % (path, ", ".join(missing)))
    at = [order.index(n) for n in names]
    out = {}
    for line in dump.splitlines():
        m = PIXEL.match(line)
        if m:
            values = m.group(3).split()
            out[(int(m.group(1)), int(m.group(2)))] = tuple(float(values[i]) for i in at)
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("render")
    parser.add_argument("truth")
    parser.add_argument("--bands", type=int, default=5, help="bands across and down (default 5)")
    args = parser.parse_args()
    if not 1 <= args.bands <= 50:
        sys.exit("tree_bands: --bands must be 1 to 50")
    truth = channels(args.truth, ["foliage.Y", "foliage_luminance.Y", "tree.Y"])
    render = channels(args.render, ["foliage.Y", "foliage_luminance.Y"])
    if set(truth) != set(render):
        sys.exit("tree_bands: the two images differ in size")
    box = {}
    for (x, y), (coverage, _, tree) in truth.items():
        if tree >= 0 and coverage > 0:
            b = box.setdefault(int(tree), [x, x, y, y])
            b[0], b[1] = min(b[0], x), max(b[1], x)
            b[2], b[3] = min(b[2], y), max(b[3], y)
    sums = {"across (left to right)": collections.defaultdict(lambda: [0.0] * 4),
            "down (top to bottom)": collections.defaultdict(lambda: [0.0] * 4)}
    trees = set()
    for (x, y), (coverage, luminance, tree) in truth.items():
        b = box.get(int(tree))
        if b is None or b[3] - b[2] < 20:
            continue
        trees.add(int(tree))
        across = min(args.bands - 1, (x - b[0]) * args.bands // (b[1] - b[0] + 1))
        down = min(args.bands - 1, (y - b[2]) * args.bands // (b[3] - b[2] + 1))
        for name, band in (("across (left to right)", across), ("down (top to bottom)", down)):
            s = sums[name][band]
            s[0] += coverage
            s[1] += luminance
            s[2] += render[(x, y)][0]
            s[3] += render[(x, y)][1]
    if not trees:
        sys.exit("tree_bands: no tree of 20 rows or more in %s" % args.truth)
    print("%d trees; the render against the truth, per band" % len(trees))
    for name, bands in sums.items():
        print(name)
        for band in sorted(bands):
            tc, tl, rc, rl = bands[band]
            if tc <= 0 or rc <= 0 or tl <= 0:
                continue
            print("  band %d: truth's luminance per coverage %.4f; coverage %+.1f%%, "
                  "luminance %+.1f%%, per coverage %+.1f%%"
                  % (band, tl / tc, 100 * (rc / tc - 1), 100 * (rl / tl - 1),
                     100 * ((rl / rc) / (tl / tc) - 1)))


if __name__ == "__main__":
    main()
