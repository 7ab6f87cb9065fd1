#!/usr/bin/python3
"""Plot `vdbtrace bench --grow` as one PNG: CPU seconds and peak memory against the scale.

Usage: MPLBACKEND=Agg /usr/bin/python3 scripts/plot_growth.py DIR

Reads DIR/growth.json (written by `vdbtrace bench --grow AXIS --grow-dir DIR`) and writes
DIR/growth.png (atomically, via DIR/growth.png.tmp.png): two log-log panels, each method's
CPU seconds and its own peak of resident memory against the step's scale (trees, pixels or
needles times those of the scene as is), with the fitted growth exponent in the legend and a
line of slope 1 for reference.
"""
import json
import os
import sys

import matplotlib
matplotlib.use(os.environ.get("MPLBACKEND", "Agg"))
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402


def main(folder):
    with open(os.path.join(folder, "growth.json")) as f:
        growth = json.load(f)
    rows = growth["rows"]
    methods = []
    for r in rows:
        if r["method"] not in methods:
            methods.append(r["method"])
    what = {"trees-region": "trees (same region)", "trees-density": "trees (same density)",
            "resolution": "pixels", "needles": "needles per cm of branch"}[growth["axis"]]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, key, label in ((axes[0], "cpu_seconds", "CPU seconds (all threads)"),
                           (axes[1], "peak_memory_mib", "peak resident memory, MiB")):
        for method in methods:
            pts = [(r["scale"], r[key]) for r in rows if r["method"] == method]
            xs, ys = zip(*pts)
            e = growth["exponents"][method][key]
            ax.plot(xs, ys, "o-", label="%s (x^%.2f)" % (method, e))
        xs = sorted({r["scale"] for r in rows})
        first = min(r[key] for r in rows if r["scale"] == xs[0])
        ax.plot(xs, [first * x for x in xs], ":", color="grey", label="slope 1")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_major_formatter(matplotlib.ticker.ScalarFormatter())
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xticks(xs)
        ax.set_xlabel("scale: %s x" % what)
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("%s grown along %s, %s" % (os.path.basename(growth["scene"]), growth["axis"],
                                            growth["machine"]), fontsize=9)
    fig.tight_layout()
    out = os.path.join(folder, "growth.png")
    tmp = out + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, out)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: plot_growth.py DIR")
    main(sys.argv[1])
