#!/usr/bin/env python3
"""Draws the figures of `kinetic experiment` (Abam, Agarwal, de Berg, Yu, Section 6) from its CSV files.

Usage: plot_experiments.py DIR

Each DIR/err_*.csv has one row per part (bin) of the time window and, for every run, the maximum
of the run's error over that bin: err(t) = max_i |y_i(t) - z_i(t)| for kinetic sorting
(err_grids.csv, err_parabola.csv, err_randdc.csv -> Figures 6-8), err(t) = z(t) - y(t) for the
kinetic tournament (err_tournament_randcr.csv -> Figure 9). One panel per run, each with its own
vertical scale, as in the paper.
"""

import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# (csv name, png name, title)
FIGURES = [
    ("err_grids.csv", "fig6_grids.png", "Maximum error of kinetic sorting on GRIDS"),
    ("err_parabola.csv", "fig7_parabola.png", "Maximum error of kinetic sorting on PARABOLA"),
    ("err_randdc.csv", "fig8_randdc.png", "Maximum error of kinetic sorting on RANDDC"),
    ("err_tournament_randcr.csv", "fig9_tournament_randcr.png",
     "Geometric error of the kinetic tournament on RANDCR"),
]


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
    if name.startswith("classic_rounded_"):
        return "classic, event times rounded to " + name[len("classic_rounded_"):]
    if name == "exact":
        return "exact (every event at its exact time)"
    if name.startswith("robust_"):
        return "robust, eps = " + name.split("_", 1)[1]
    return name


def plot(directory, csv_name, png_name, title):
    path = os.path.join(directory, csv_name)
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
        color = ("tab:red" if name.startswith("classic") else
                 "tab:green" if name == "exact" else "tab:blue")
        ax.plot(xs, yy, linewidth=0.7, color=color)
        ax.set_ylabel("err")
        ax.set_title("(%d) %s: max %.3g" % (k + 1, label(name), max(ys) if ys else 0.0), fontsize=9)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 3))
        ax.grid(True, linewidth=0.3)
    axes[-1].set_xlabel("t")
    fig.suptitle("%s (max of err(t) per 1/%d of the window)" % (title, len(t_lo)), fontsize=10)
    fig.tight_layout()
    out = os.path.join(directory, png_name)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


def main():
    if len(sys.argv) != 2:
        sys.stderr.write(__doc__)
        return 2
    directory = sys.argv[1]
    written = [p for p in (plot(directory, c, f, t) for c, f, t in FIGURES) if p]
    for p in written:
        print("plot: " + p)
    return 0 if written else 1


if __name__ == "__main__":
    sys.exit(main())
