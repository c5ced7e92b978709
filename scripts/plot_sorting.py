#!/usr/bin/env python3
"""Draws Figures 6-8 of the kinetic-sorting experiment (seed paper 000, Section 6).

Usage: plot_sorting.py DIR

Reads DIR/err_<dataset>.csv, written by `kinetic experiment sorting`: one row per part (bin) of
the time window, with the maximum of err(t) = max_i |y_i(t) - z_i(t)| over that bin for every
run (classic, robust at each eps). Writes DIR/fig6_grids.png, DIR/fig7_parabola.png and
DIR/fig8_randdc.png: one panel per run, each with its own vertical scale, as in the paper.
"""

import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FIGURES = [("grids", "fig6", "GRIDS"), ("parabola", "fig7", "PARABOLA"), ("randdc", "fig8", "RANDDC")]


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    t_lo = [float(r[0]) for r in body]
    t_hi = [float(r[1]) for r in body]
    series = {}
    for j, name in enumerate(header[2:], start=2):
        series[name] = [float(r[j]) for r in body]
    return t_lo, t_hi, series


def label(name):
    if name == "classic":
        return "classic (floating-point event times)"
    return "robust, eps = " + name.split("_", 1)[1]


def plot(directory, dataset, fig_name, title):
    path = os.path.join(directory, "err_%s.csv" % dataset)
    if not os.path.exists(path):
        return None
    t_lo, t_hi, series = read(path)
    names = list(series)
    fig, axes = plt.subplots(len(names), 1, figsize=(8, 2.1 * len(names)), sharex=True)
    if len(names) == 1:
        axes = [axes]
    for k, (ax, name) in enumerate(zip(axes, names)):
        ys = series[name]
        # A step per bin: the maximum of err over [t_lo, t_hi].
        xs, yy = [], []
        for lo, hi, y in zip(t_lo, t_hi, ys):
            xs += [lo, hi]
            yy += [y, y]
        ax.plot(xs, yy, linewidth=0.7, color="tab:red" if name == "classic" else "tab:blue")
        ax.set_ylabel("err")
        ax.set_title("(%d) %s: max %.3g" % (k + 1, label(name), max(ys) if ys else 0.0), fontsize=9)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 3))
        ax.grid(True, linewidth=0.3)
    axes[-1].set_xlabel("t")
    fig.suptitle("Maximum error of kinetic sorting on %s (max of err(t) per 1/%d of the window)"
                 % (title, len(t_lo)), fontsize=10)
    fig.tight_layout()
    out = os.path.join(directory, "%s_%s.png" % (fig_name, dataset))
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


def main():
    if len(sys.argv) != 2:
        sys.stderr.write(__doc__)
        return 2
    directory = sys.argv[1]
    written = [p for p in (plot(directory, d, f, t) for d, f, t in FIGURES) if p]
    for p in written:
        print("plot: " + p)
    return 0 if written else 1


if __name__ == "__main__":
    sys.exit(main())
