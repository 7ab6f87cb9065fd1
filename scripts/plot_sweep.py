#!/usr/bin/python3
"""Plot the Meyer & Neyret 2000 approximation sweep as one 2x2 PNG.

Usage: MPLBACKEND=Agg /usr/bin/python3 scripts/plot_sweep.py DIR

Reads f_fit.csv, linear_law_opacity.csv, linear_law.csv and summary.json from
DIR and writes DIR/sweep.png (atomically, via DIR/sweep.png.tmp.png).

Panels:
  (a) F fit: the exact diffuse needle factor g and the paper's fit F_fit
      against delta alpha (left axis), with |F_fit - g| on a right axis; the
      maximum error and where it occurs are annotated.
  (b) Bough opacity, view orthogonal to the branch, against nA (log x): exact
      transmittance (solid) vs the paper's linear law 1-(1-A)^n ~ nA
      (dashed, unclamped) for each layer opacity A; alpha = 1 is marked, and
      the paper's benchmark bough is shown (star = exact, cross = linear).
  (c) Relative error of the linear law's (unclamped) opacity against nA
      (log-log), one curve per A, with 1% / 5% / 20% guides and the paper
      bough's nA.
  (d) Heat map of the relative error of the bough's reflected radiance
      (linear law vs exact) over nA (log x) and view angle to the branch,
      A = 0.2349, with 1% / 5% / 20% contours and the paper bough (nA, 90 deg).
"""
import csv
import json
import os
import sys

import matplotlib
matplotlib.use(os.environ.get("MPLBACKEND", "Agg"))
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402

NA_LABEL = "nA (layer opacity x layers crossed through the axis)"
VIEW_LABEL = "view angle to branch (deg)"
LEVELS = (0.01, 0.05, 0.2)
LEVEL_NAMES = {0.01: "1%", 0.05: "5%", 0.2: "20%"}


def fail(msg):
    sys.exit(f"plot_sweep: {msg}")


def load_csv(directory, name, columns):
    """Return {column: float array} for the required columns of DIR/name."""
    path = os.path.join(directory, name)
    try:
        with open(path, newline="") as fh:
            rows = list(csv.reader(fh))
    except OSError as exc:
        fail(f"cannot read {path}: {exc.strerror}")
    if len(rows) < 2:
        fail(f"{path}: no data rows")
    header = [h.strip() for h in rows[0]]
    missing = [c for c in columns if c not in header]
    if missing:
        fail(f"{path}: missing column(s) {', '.join(missing)}")
    idx = [header.index(c) for c in columns]
    data = []
    for lineno, row in enumerate(rows[1:], start=2):
        if not row:
            continue
        try:
            data.append([float(row[i]) for i in idx])
        except (ValueError, IndexError):
            fail(f"{path}:{lineno}: malformed row")
    arr = np.array(data)
    if not np.all(np.isfinite(arr)):
        fail(f"{path}: non-finite values")
    return {c: arr[:, k] for k, c in enumerate(columns)}


def load_paper_bough(directory):
    path = os.path.join(directory, "summary.json")
    try:
        with open(path) as fh:
            pb = json.load(fh)["linear_law"]["paper_bough"]
        return {k: float(pb[k]) for k in ("nA", "alpha_linear_unclamped", "alpha_exact")}
    except OSError as exc:
        fail(f"cannot read {path}: {exc.strerror}")
    except (ValueError, KeyError, TypeError) as exc:
        fail(f"{path}: malformed linear_law.paper_bough ({exc!r})")


def panel_f_fit(ax, f):
    x, err = f["delta_alpha"], f["abs_error"]
    ax.plot(x, f["g"], color="C0", lw=2, label="g (exact)")
    ax.plot(x, f["F_fit"], color="C1", lw=1.5, ls="--", label="F_fit (paper)")
    ax.set_xlabel("delta alpha (rad)")
    ax.set_ylabel("needle factor")
    ax.set_xlim(0, np.pi)
    right = ax.twinx()
    right.plot(x, err, color="C3", lw=1, label="|F_fit - g|")
    right.set_ylabel("absolute error |F_fit - g|", color="C3")
    right.tick_params(axis="y", colors="C3")
    right.set_ylim(0, 1.35 * err.max())
    # All (near-)equal maxima: contiguous runs above 99.9% of the max.
    top = np.flatnonzero(err >= 0.999 * err.max())
    runs = np.split(top, np.flatnonzero(np.diff(top) > 1) + 1)
    peaks = [r[np.argmax(err[r])] for r in runs]
    right.plot(x[peaks], err[peaks], "v", color="C3", ms=7)
    where = ", ".join(f"{x[i]:.2f}" for i in peaks)
    right.annotate(f"max error {err.max():.4f} at delta alpha = {where} rad",
                   xy=(0.5, 0.97), xycoords="axes fraction", ha="center", va="top",
                   color="C3", fontsize=9)
    lines = ax.get_lines() + right.get_lines()[:1]
    ax.legend(lines, [l.get_label() for l in lines], loc="center right", fontsize=9)
    ax.set_title("(a) diffuse needle factor: paper's fit F vs exact g")


def panel_opacity(ax, o, pb):
    for k, a in enumerate(np.unique(o["A"])):
        s = o["A"] == a
        ax.plot(o["nA"][s], o["alpha_exact"][s], color=f"C{k}", lw=2, label=f"A = {a:.4g}")
        ax.plot(o["nA"][s], o["alpha_linear_unclamped"][s], color=f"C{k}", lw=1.5, ls="--")
    ax.plot([], [], color="gray", lw=2, label="exact (solid)")
    ax.plot([], [], color="gray", lw=1.5, ls="--", label="linear law, unclamped (dashed)")
    ax.axhline(1.0, color="k", lw=0.8, ls=":")
    ax.text(o["nA"].min() * 1.2, 1.03, "alpha = 1", fontsize=9, va="bottom")
    ax.plot(pb["nA"], pb["alpha_exact"], "*", color="k", ms=14, zorder=5)
    ax.plot(pb["nA"], pb["alpha_linear_unclamped"], "X", color="k", ms=10, zorder=5)
    ax.annotate(f"paper's bough: linear {pb['alpha_linear_unclamped']:.2f}"
                f" vs exact {pb['alpha_exact']:.2f}",
                xy=(pb["nA"], pb["alpha_linear_unclamped"]), xytext=(0.03, 0.82),
                textcoords="axes fraction", fontsize=9,
                arrowprops=dict(arrowstyle="->", color="k", lw=0.8))
    ax.set_xscale("log")
    ax.set_ylim(0, max(2.0, 1.35 * pb["alpha_linear_unclamped"]))
    ax.set_xlabel(NA_LABEL)
    ax.set_ylabel("bough opacity alpha")
    ax.legend(loc="upper left", bbox_to_anchor=(0.0, 0.78), fontsize=9)
    ax.set_title("(b) bough opacity, view orthogonal to branch (dashed lines leave the top)")


def panel_opacity_error(ax, o, pb):
    for k, a in enumerate(np.unique(o["A"])):
        s = o["A"] == a
        ax.plot(o["nA"][s], o["rel_error_unclamped"][s], color=f"C{k}", lw=1.8,
                label=f"A = {a:.4g}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    for lev in LEVELS:
        ax.axhline(lev, color="gray", lw=0.8, ls=":")
        ax.text(pb["nA"] * 0.85, lev / 1.08, LEVEL_NAMES[lev], fontsize=9,
                color="dimgray", ha="right", va="top")
    ax.axvline(pb["nA"], color="k", lw=0.8, ls="--")
    ax.text(pb["nA"] * 0.92, 0.03, "paper's bough", transform=ax.get_xaxis_transform(),
            rotation=90, ha="right", va="bottom", fontsize=9)
    ax.set_xlabel(NA_LABEL)
    ax.set_ylabel("relative error of opacity |linear - exact| / exact")
    ax.legend(loc="lower left", fontsize=9)
    ax.set_title("(c) linear-law opacity error, view orthogonal (unclamped)")


def panel_radiance(fig, ax, d, pb):
    nas, views = np.unique(d["nA"]), np.unique(d["view_deg"])
    if nas.size * views.size != d["nA"].size:
        fail("linear_law.csv: (nA, view_deg) is not a complete grid")
    err = np.full((views.size, nas.size), np.nan)
    err[np.searchsorted(views, d["view_deg"]), np.searchsorted(nas, d["nA"])] = \
        d["radiance_rel_error"]
    if np.isnan(err).any():
        fail("linear_law.csv: (nA, view_deg) grid has duplicate or missing cells")
    err = np.clip(err, 1e-4, 1e1)
    mesh = ax.pcolormesh(nas, views, err, shading="nearest", cmap="viridis",
                         norm=LogNorm(vmin=1e-4, vmax=1e1))
    cbar = fig.colorbar(mesh, ax=ax)
    cbar.set_label("relative error of bough radiance, linear law vs exact")
    present = [lev for lev in LEVELS if err.min() < lev < err.max()]
    if present:
        cs = ax.contour(nas, views, err, levels=present, colors="k", linewidths=1.2)
        ax.clabel(cs, fmt=LEVEL_NAMES, fontsize=9)
    absent = [LEVEL_NAMES[lev] for lev in LEVELS if lev not in present]
    if absent:
        ax.text(0.02, 0.03, f"no {' / '.join(absent)} contour: error range here is "
                f"{err.min():.3g} .. {err.max():.3g}", transform=ax.transAxes,
                fontsize=9, color="w", va="bottom")
    ax.plot(pb["nA"], 90.0, "*", color="w", mec="k", ms=16, clip_on=False, zorder=5)
    ax.annotate("paper's bough", xy=(pb["nA"], 90.0), xytext=(-12, -20),
                textcoords="offset points", ha="right", color="w", fontsize=9)
    ax.set_xscale("log")
    ax.set_xlabel(NA_LABEL)
    ax.set_ylabel(VIEW_LABEL)
    ax.set_title("(d) bough radiance error over nA and view angle (A = 0.2349)")


def main():
    if len(sys.argv) != 2:
        fail("usage: plot_sweep.py DIR")
    directory = sys.argv[1]
    f = load_csv(directory, "f_fit.csv", ["delta_alpha", "g", "F_fit", "abs_error"])
    o = load_csv(directory, "linear_law_opacity.csv",
                 ["A", "nA", "alpha_linear_unclamped", "alpha_exact", "rel_error_unclamped"])
    d = load_csv(directory, "linear_law.csv", ["nA", "view_deg", "radiance_rel_error"])
    pb = load_paper_bough(directory)

    fig, axes = plt.subplots(2, 2, figsize=(15, 10))
    panel_f_fit(axes[0, 0], f)
    panel_opacity(axes[0, 1], o, pb)
    panel_opacity_error(axes[1, 0], o, pb)
    panel_radiance(fig, axes[1, 1], d, pb)
    fig.suptitle("Meyer & Neyret 2000: approximations measured against quadrature",
                 fontsize=15)
    fig.tight_layout()

    out = os.path.join(directory, "sweep.png")
    tmp = out + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, out)


if __name__ == "__main__":
    main()
