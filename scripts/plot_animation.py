#!/usr/bin/python3
"""Plot `vdbtrace animate-compare` over the frames as one PNG.

Usage: MPLBACKEND=Agg /usr/bin/python3 scripts/plot_animation.py DIR

Reads DIR/frames.csv (frame, method, residual_rms, mean_luminance) and writes
DIR/flicker_frames.png (atomically, via DIR/flicker_frames.png.tmp.png): above, each method's
departure from the pixels' lines frame by frame (a frame that pops is a spike; "nan" where a
frame has none to tell, the path's first and last, is left out of the line); below, each
method's mean luminance (the scene's change along the path, which the lines remove).
"""
import csv
import os
import sys

import matplotlib
matplotlib.use(os.environ.get("MPLBACKEND", "Agg"))
import matplotlib.pyplot as plt  # noqa: E402


def main(folder):
    series = {}
    with open(os.path.join(folder, "frames.csv")) as f:
        for row in csv.DictReader(f):
            s = series.setdefault(row["method"], ([], [], []))
            s[0].append(int(row["frame"]))
            # Empty at the first and last frames, which have no neighbours to be off the line of.
            s[1].append(float(row["residual_rms"] or "nan"))
            s[2].append(float(row["mean_luminance"]))
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for method, (frames, residual, luminance) in series.items():
        top.plot(frames, residual, marker="o", markersize=3, label=method)
        bottom.plot(frames, luminance, marker="o", markersize=3, label=method)
    top.set_ylabel("luminance off each pixel's line (RMS)")
    top.set_title("Flicker frame by frame")
    top.grid(alpha=0.3)
    top.legend()
    bottom.set_xlabel("frame")
    bottom.set_ylabel("mean luminance")
    bottom.grid(alpha=0.3)
    fig.tight_layout()
    out = os.path.join(folder, "flicker_frames.png")
    tmp = out + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, out)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: plot_animation.py DIR")
    main(sys.argv[1])
