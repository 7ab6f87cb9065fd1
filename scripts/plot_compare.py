#!/usr/bin/python3
"""Plot what accuracy costs in time, from `vdbtrace compare`'s report.csv.

Usage: MPLBACKEND=Agg /usr/bin/python3 scripts/plot_compare.py DIR

Reads DIR/report.csv (columns method, setting, seconds, rmse, rmse_k1, ...)
and writes, each atomically (via NAME.tmp.png):
- DIR/error_vs_time.png: RMSE against the ground truth over render CPU seconds,
  log-log, one curve per method (geometry's samples-per-pixel sweep, the
  reference's voxel-size sweep, the multiscale points labelled L1/L2/L3/auto).
  The ground truth's own row (error 0 by definition) is left out; its time is
  drawn as a vertical line.
- DIR/error_vs_scale.png: RMSE after box-downsampling both images by k, over k,
  one line per render, and the truth's own error against its check (dotted).
  Noise falls as 1/k (the dashed slope), a bias stays flat.
- DIR/tree_bias.png, where DIR/trees.csv has rows: each tree's foliage
  luminance bias against the truth over the truth's coverage of it in pixels,
  one marker per render of the sweep (the error budget's left out), the +-3%
  band shaded.
"""
import csv
import os
import sys

import matplotlib
matplotlib.use(os.environ.get("MPLBACKEND", "Agg"))
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {
    "geometry": ("tab:blue", "o", "geometry (explicit needles), spp"),
    "reference": ("tab:orange", "s", "reference (OpenVDB, eq. 7), voxel"),
    "multiscale": ("tab:green", "D", "multiscale (closed forms)"),
}


LINES = ["-", "--", "-.", ":"]  # a method's settings, in the order of the rows


def fail(msg):
    sys.exit(f"plot_compare: {msg}")


def load(directory):
    path = os.path.join(directory, "report.csv")
    try:
        with open(path, newline="") as fh:
            rows = list(csv.DictReader(fh))
    except OSError as exc:
        fail(f"cannot read {path}: {exc.strerror}")
    for column in ("method", "setting", "seconds", "rmse"):
        if not rows or column not in rows[0]:
            fail(f"{path}: no rows or no column {column}")
    return rows


def save(fig, directory, name):
    out = os.path.join(directory, name)
    tmp = out + ".tmp.png"
    fig.savefig(tmp, dpi=120)
    os.replace(tmp, out)


def finish(fig, ax, directory, name, xlabel, ylabel, title):
    """Labels, a grid and a two-column legend, then the file."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    save(fig, directory, name)


def scales(rows):
    return sorted(int(c[len("rmse_k"):]) for c in rows[0] if c.startswith("rmse_k"))


def plot_scales(rows, directory):
    ks = scales(rows)
    if not ks:
        fail("report.csv has no rmse_k columns")
    fig, ax = plt.subplots(figsize=(7.5, 5.0))
    shades = {}
    for r in rows:
        # The error budget's rows are a table's, not curves to tell apart here.
        if r["method"] == "truth" or r["method"].startswith("budget:"):
            continue
        points = [(k, float(r[f"rmse_k{k}"])) for k in ks if r.get(f"rmse_k{k}")]
        points = [p for p in points if p[1] > 0]
        if not points:
            continue
        xs, ys = zip(*points)
        if r["method"] == "truth_check":
            ax.plot(xs, ys, color="grey", linestyle=":", marker=".",
                    label=f"the truth's own error (against {r['setting']})")
            continue
        colour, marker, _ = STYLE.get(r["method"], ("black", "x", r["method"]))
        shade = shades.get(r["method"], 0)
        shades[r["method"]] = shade + 1
        ax.plot(xs, ys, color=colour, marker=marker, linestyle=LINES[shade % len(LINES)],
                label=f"{r['method']} {r['setting']}")
    top = max(float(r["rmse_k1"]) for r in rows
              if r.get("rmse_k1") and not r["method"].startswith("budget:"))
    if top > 0:
        ax.plot(ks, [top / k for k in ks], color="black", linestyle="--", linewidth=0.8,
                label="1 / k (noise alone)")
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xticks(ks)
    ax.set_xticklabels([str(k) for k in ks])
    finish(fig, ax, directory, "error_vs_scale.png",
           "k: both images box-downsampled by k x k pixels",
           "RMSE of luminance against the ground truth",
           "Error at every scale: noise falls, bias stays")


def plot_trees(directory):
    path = os.path.join(directory, "trees.csv")
    if not os.path.exists(path):
        return
    # An empty bias is undefined (the tree is black in the truth): no point, and no plot
    # where no tree has one.
    with open(path, newline="") as fh:
        trees = [r for r in csv.DictReader(fh)
                 if r["method"] != "truth" and not r["method"].startswith("budget:")
                 and r["luminance_bias"]]
    if not trees:
        return
    fig, ax = plt.subplots(figsize=(7.5, 5.0))
    ax.axhspan(-3, 3, color="grey", alpha=0.15, label="within 3%")
    shades = {}
    for key in dict.fromkeys((r["method"], r["setting"]) for r in trees):
        method, setting = key
        points = [(float(r["coverage_px_truth"]), 100.0 * float(r["luminance_bias"]))
                  for r in trees if (r["method"], r["setting"]) == key]
        colour, marker, _ = STYLE.get(method, ("black", "x", method))
        shade = shades.get(method, 0)
        shades[method] = shade + 1
        xs, ys = zip(*points)
        ax.scatter(xs, ys, color=colour, marker=marker, s=14,
                   alpha=max(0.3, 1.0 - 0.25 * shade), label=f"{method} {setting}")
    ax.set_xscale("log")
    finish(fig, ax, directory, "tree_bias.png", "the tree's foliage in the truth (pixels)",
           "foliage luminance against the truth (%)", "Bias per tree")


def main():
    if len(sys.argv) != 2:
        fail("usage: plot_compare.py DIR")
    directory = sys.argv[1]
    rows = load(directory)
    plot_scales(rows, directory)
    plot_trees(directory)
    fig, ax = plt.subplots(figsize=(7.5, 5.0))
    for method, (colour, marker, label) in STYLE.items():
        points = [(float(r["seconds"]), float(r["rmse"]), r["setting"])
                  for r in rows if r["method"] == method]
        # A log axis cannot show zero error; such a point would be the truth itself.
        points = sorted(p for p in points if p[0] > 0 and p[1] > 0)
        if not points:
            continue
        xs, ys, names = zip(*points)
        line = "none" if method == "multiscale" else "-"
        ax.plot(xs, ys, marker=marker, color=colour, linestyle=line, label=label)
        for x, y, name in points:
            # "auto" equals one forced level in most views: put it below, the rest above.
            offset = (5, -11) if name == "auto" else (5, 4)
            ax.annotate(name, (x, y), textcoords="offset points", xytext=offset,
                        fontsize=8, color=colour)
    for r in rows:
        if r["method"] == "truth":
            ax.axvline(float(r["seconds"]), color="grey", linestyle=":", linewidth=1)
            ax.annotate(f"ground truth ({r['setting']})", (float(r["seconds"]), 1.0),
                        xycoords=("data", "axes fraction"), xytext=(-4, -12),
                        textcoords="offset points", ha="right", fontsize=8, color="grey")
    ax.set_xscale("log")
    ax.set_yscale("log")
    finish(fig, ax, directory, "error_vs_time.png",
           "render CPU seconds (all threads, preparation included)",
           "RMSE of luminance against the ground truth", "What accuracy costs in time")


if __name__ == "__main__":
    main()
