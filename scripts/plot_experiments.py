#!/usr/bin/env python3
"""Draws the figures of `kinetic experiment` (Abam, Agarwal, de Berg, Yu, Section 6) from its CSV files.

Usage: plot_experiments.py DIR

Each DIR/err_*.csv has one row per part (bin) of the time window and, for every run, the maximum
of the run's error over that bin: err(t) = max_i |y_i(t) - z_i(t)| for kinetic sorting
(err_grids.csv, err_parabola.csv, err_randdc.csv -> Figures 6-8), err(t) = z(t) - y(t) for the
kinetic tournament (err_tournament_randcr.csv -> Figure 9). Times are in the time units of the
scenario, errors in its position units (after the experiment's scaling of the positions).

For every figure two files are written:

  figN_<name>.png      one panel per run, linear y axis, as in the paper. Every panel has the
                       same x range (the whole window). The robust runs' panels share one y
                       scale, and the classic run's panel shares it too unless its error is more
                       than 1000 times larger (then it has its own scale, said in its title).
  figN_<name>_log.png  every run's error on the same logarithmic y axis, so that the orders of
                       magnitude of classic and robust runs can be read off.

A run whose error never exceeds the rounding-noise level, 1e-12 * P with P the largest |position|
in the window (from DIR/runs.csv or DIR/tournament_runs.csv and the dataset's definition), is
labelled "rounding noise" and not drawn as an error; a run whose error is exactly 0 everywhere (the
exact scheduler) is stated in words, never drawn on a log axis.

DIR/delaunay_runs.csv (`kinetic experiment delaunay`) gives delaunay_eps.png: against eps, the
robust flips' delay (maximum and RMS, with the grid width w for scale) and the geometric error
at the sample times (the share of samples where an edge is not Delaunay, and the largest excess
over 180 degrees of the two angles opposite such an edge).
"""

import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from matplotlib.ticker import LogLocator, NullFormatter  # noqa: E402

# (csv name, png name, log-overlay png name, dataset, kind)
FIGURES = [
    ("err_grids.csv", "fig6_grids.png", "fig6_grids_log.png", "grids", "sorting"),
    ("err_parabola.csv", "fig7_parabola.png", "fig7_parabola_log.png", "parabola", "sorting"),
    ("err_randdc.csv", "fig8_randdc.png", "fig8_randdc_log.png", "randdc", "sorting"),
    ("err_tournament_randcr.csv", "fig9_tournament_randcr.png",
     "fig9_tournament_randcr_log.png", "randcr", "tournament"),
]

# An error below NOISE_RELATIVE * P (P = the largest |position| in the window) is at the level of
# the rounding of the positions themselves (about 1e-16 * P per evaluation): not a wrong order.
NOISE_RELATIVE = 1e-12
# The classic panel shares the robust panels' y scale unless its maximum is this much larger.
SHARE_RATIO = 1e3

TITLES = {
    "sorting": "Kinetic sorting on %s",
    "tournament": "Kinetic tournament (maximum) on %s",
}
ERR_DEFINITION = {
    "sorting": "err(t) = max_i |y_i(t) - z_i(t)|: y = positions in the maintained order, "
               "z = positions sorted in floating point",
    "tournament": "err(t) = z(t) - y(t): z = true maximum (upper envelope), "
                  "y = maximum maintained by the tournament",
}

CLASSIC_COLOR = "tab:red"
NOISE_COLOR = "0.45"
ROBUST_COLORS = ["#08306b", "#2171b5", "#6baed6", "#9ecae1"]  # largest eps first


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


def read_runs(directory):
    """dataset -> {"n": int, "scale": float} from runs.csv / tournament_runs.csv (when present)."""
    info = {}
    for name in ("runs.csv", "tournament_runs.csv"):
        path = os.path.join(directory, name)
        if not os.path.exists(path):
            continue
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                try:
                    info.setdefault(row["dataset"], {"n": int(row["n"]),
                                                     "scale": float(row.get("scale") or 1.0)})
                except (KeyError, ValueError):
                    pass
    return info


def position_scale(dataset, info, t_max):
    """P = a bound on |x(t)| over the window |t| <= t_max, from the dataset's definition
    (docs/datasets.md); 1 + t_max (lines with coefficients in [-1, 1]) when it is unknown."""
    n, scale = info.get("n"), info.get("scale", 1.0)
    if n and dataset in ("grids", "parabola"):
        c = math.ceil(math.sqrt(n)) - 1  # grid coordinates in [-c, c]
        if dataset == "grids":  # x = a t + b, |a|, |b| <= c
            return scale * c * (1.0 + t_max)
        return scale * ((t_max + c) ** 2 + c)  # x = (t - t_i)^2 + x_j, |t_i|, |x_j| <= c
    if dataset in ("randdc", "randcr"):  # x = a t + b, a^2 + b^2 <= 1
        return math.hypot(1.0, t_max)
    return 1.0 + t_max


def eps_of(name):
    if name.startswith("robust_"):
        try:
            return float(name.split("_", 1)[1])
        except ValueError:
            return None
    return None


def label(name):
    if name == "classic":
        return "classic (floating-point event times)"
    if name.startswith("classic_exact_decisions_rounded_"):
        return ("classic with exact decisions, event times rounded to "
                + name[len("classic_exact_decisions_rounded_"):])
    if name.startswith("classic_rounded_"):
        return "classic, event times rounded to " + name[len("classic_rounded_"):]
    if name == "exact":
        return "exact (every event at its exact time)"
    if name.startswith("robust_"):
        return "robust, \u03b5 = " + name.split("_", 1)[1]
    return name


def short_label(name):
    if name.startswith("classic_exact_decisions_rounded_"):
        return "classic, exact decisions (times rounded to %s)" % name[
            len("classic_exact_decisions_rounded_"):]
    if name.startswith("classic_rounded_"):
        return "classic (times rounded to %s)" % name[len("classic_rounded_"):]
    if name.startswith("robust_"):
        return "robust \u03b5 = " + name.split("_", 1)[1]
    return name


def sci(x):
    """1.8e-15 -> '1.8e-15', 53.7 -> '53.7'."""
    if x == 0:
        return "0"
    if 1e-2 <= abs(x) < 1e4:
        return "%.3g" % x
    mantissa, exponent = ("%.2e" % x).split("e")
    return "%se%d" % (mantissa.rstrip("0").rstrip("."), int(exponent))


def classify(values, threshold):
    peak = max(values) if values else 0.0
    if peak == 0.0:
        return "zero"
    if peak < threshold:
        return "noise"
    return "error"


def colors_for(names):
    robust = sorted((n for n in names if eps_of(n) is not None), key=lambda n: -eps_of(n))
    colors = {}
    for k, n in enumerate(robust):
        colors[n] = ROBUST_COLORS[min(k, len(ROBUST_COLORS) - 1)]
    for n in names:
        if n not in colors:
            if n.startswith("classic_exact_decisions"):
                colors[n] = "tab:purple"
            else:
                colors[n] = CLASSIC_COLOR if n.startswith("classic") else "tab:green"
    return colors


def steps(t_lo, t_hi, ys):
    """A step per bin: the maximum of err over [t_lo, t_hi]."""
    xs, yy = [], []
    for lo, hi, y in zip(t_lo, t_hi, ys):
        xs += [lo, hi]
        yy += [y, y]
    return xs, yy


def decade_exponent(top):
    return int(math.floor(math.log10(top))) if top > 0 else 0


def superscript(e):
    return str(e).translate(str.maketrans("-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074"
                                                          "\u2075\u2076\u2077\u2078\u2079"))


class Figure:
    """The data of one figure and what the plots say about it."""

    def __init__(self, directory, csv_name, dataset, kind):
        self.t_lo, self.t_hi, self.series = read(os.path.join(directory, csv_name))
        if not self.series or not self.t_lo:
            raise ValueError(csv_name + " has no runs or no rows")
        self.names = list(self.series)
        self.dataset, self.kind = dataset, kind
        self.info = read_runs(directory).get(dataset, {})
        self.x0, self.x1 = self.t_lo[0], self.t_hi[-1]
        self.P = position_scale(dataset, self.info, max(abs(self.x0), abs(self.x1)))
        self.threshold = NOISE_RELATIVE * self.P
        self.kinds = {n: classify(self.series[n], self.threshold) for n in self.names}
        self.peak = {n: max(self.series[n]) if self.series[n] else 0.0 for n in self.names}
        self.colors = colors_for(self.names)

    def title(self):
        t = TITLES[self.kind] % self.dataset.upper()
        if self.info.get("n"):
            t += ", n = %d" % self.info["n"]
        scale = self.info.get("scale", 1.0)
        return t

    def scale_text(self):
        """What the dataset's scale is, in words ("" when unscaled)."""
        scale = self.info.get("scale", 1.0)
        if scale == 1.0:
            return ""
        inverse = 1.0 / scale
        factor = ("1/%d" % round(inverse)) if abs(inverse - round(inverse)) < 1e-9 else sci(scale)
        return ("positions scaled by %s (every coefficient: the grid's points then lie in "
                "[-1, 1], like RANDDC's unit disk; times unchanged; docs/datasets.md, \"Scale\"); "
                "err and P are in the scaled units" % factor)

    def caption(self):
        """The lines under a figure: what err(t) is, the bins, the scale."""
        return "\n".join(x for x in (ERR_DEFINITION[self.kind], self.bins_text(),
                                     self.scale_text()) if x)

    def bins_text(self):
        width = (self.x1 - self.x0) / len(self.t_lo)
        return "max of err(t) over each 1/%d of the window (%s time units)" % (len(self.t_lo),
                                                                              sci(width))

    def noise_text(self):
        return ("rounding-noise level (grey dots): err < 10\u207b\u00b9\u00b2 P = %s "
                "(P = %s, largest |position|)" % (sci(self.threshold), sci(self.P)))

    def scale_groups(self):
        """name -> group id of the panels drawn with a linear y axis; panels of one group share
        their y limits."""
        errors = [n for n in self.names if self.kinds[n] == "error"]
        robust = [n for n in errors if eps_of(n) is not None]
        groups = {n: "shared" for n in robust}
        shared_peak = max((self.peak[n] for n in robust), default=0.0)
        for n in errors:
            if n in groups:
                continue
            if shared_peak == 0.0 or self.peak[n] <= SHARE_RATIO * shared_peak:
                groups[n] = "shared"
            else:
                groups[n] = "own:" + n
        return groups


def panel_numbers(names, members):
    return ", ".join("(%d)" % (names.index(m) + 1) for m in members)


def plot_panels(fig_data, out):
    f = fig_data
    names = f.names
    groups = f.scale_groups()
    heights = [1.0 if f.kinds[n] == "error" else 0.42 for n in names]
    fig, axes = plt.subplots(len(names), 1, figsize=(8.5, 0.9 + 1.9 * sum(heights)), sharex=True,
                             gridspec_kw={"height_ratios": heights})
    if len(names) == 1:
        axes = [axes]
    tops = {}
    for n, g in groups.items():
        tops[g] = max(tops.get(g, 0.0), f.peak[n])
    for k, (ax, name) in enumerate(zip(axes, names)):
        ys = f.series[name]
        kind = f.kinds[name]
        head = "(%d) %s" % (k + 1, label(name))
        ax.grid(True, linewidth=0.3)
        ax.set_xlim(f.x0, f.x1)
        if kind == "zero":
            ax.set_yticks([])
            ax.set_ylim(0, 1)
            ax.text(0.5, 0.5, "err(t) = 0 at every t: no error at any time (nothing to draw)",
                    transform=ax.transAxes, ha="center", va="center", fontsize=9,
                    color=f.colors[name])
            ax.set_title(head + ": max 0", fontsize=9)
            continue
        if kind == "noise":
            ax.set_yticks([])
            ax.set_ylim(0, 1)
            what = ("not a wrong order: it differs from the floating-point sort only between "
                    "positions equal within rounding" if f.kind == "sorting" else
                    "not a wrong maximum: it differs from the true one only between lines "
                    "equal within rounding (at their crossings)")
            ax.text(0.5, 0.5, "rounding noise only: err(t) \u2264 %s < %s = 10\u207b\u00b9\u00b2 P "
                    "(P = %s, largest |position|)\n%s"
                    % (sci(f.peak[name]), sci(f.threshold), sci(f.P), what),
                    transform=ax.transAxes, ha="center", va="center", fontsize=8.5,
                    color=NOISE_COLOR)
            ax.set_title("%s: rounding noise (< %s), max %s" % (head, sci(f.threshold),
                                                                sci(f.peak[name])), fontsize=9)
            continue
        group = groups[name]
        top = tops[group]
        e = decade_exponent(top)
        unit = 10.0 ** e if abs(e) >= 3 else 1.0
        xs, yy = steps(f.t_lo, f.t_hi, ys)
        ax.plot(xs, [y / unit for y in yy], linewidth=0.7, color=f.colors[name])
        ax.set_ylim(0, 1.08 * top / unit)
        ax.set_ylabel(("err [10%s position units]" % superscript(e)) if unit != 1.0
                      else "err [position units]", fontsize=8)
        if group == "shared" and f.peak[name] < 0.1 * top:
            ax.text(0.99, 0.93, "small on the shared scale (%.2g of its top): shape in the "
                    "log plot" % (f.peak[name] / top), transform=ax.transAxes, ha="right",
                    va="top", fontsize=7.5, color="0.35")
        members = [n for n in names if groups.get(n) == group]
        if group.startswith("own:"):
            note = "own y scale"
        elif len(members) > 1:
            note = "y scale shared with " + panel_numbers(
                names, [m for m in members if m != name])
        else:
            note = ""
        ax.set_title("%s: max %s%s" % (head, sci(f.peak[name]), ("  [%s]" % note) if note else ""),
                     fontsize=9)
    axes[-1].set_xlabel("t (time units of the scenario)")
    fig.suptitle(f.title(), fontsize=11)
    fig.tight_layout()
    fig.text(0.01, -0.005, f.caption(), fontsize=8, va="top", ha="left", color="0.25")
    fig.savefig(out, dpi=110, bbox_inches="tight", pad_inches=0.12)
    plt.close(fig)


def draw_log_envelope(ax, t_lo, t_hi, ys, threshold, color, zorder):
    """One run on a log axis, a dot per bin at the maximum of err over the bin (a dot rather than
    a step, so that an isolated bin, narrower than a pixel, stays visible and the jumps between
    bins do not draw vertical lines across decades). Bins with err = 0 are left out (0 is not a
    value on a log axis); bins at the rounding-noise level (< threshold) are drawn in grey."""
    for keep, c, z in ((lambda y: y >= threshold, color, zorder),
                       (lambda y: 0 < y < threshold, NOISE_COLOR, 1)):
        cx = [0.5 * (lo + hi) for lo, hi, y in zip(t_lo, t_hi, ys) if keep(y)]
        cy = [y for y in ys if keep(y)]
        if cx:
            ax.plot(cx, cy, linestyle="none", marker="o", markersize=1.5, markeredgewidth=0,
                    color=c, alpha=0.85, zorder=z)


def label_right_edge(ax, marks, y_bottom, y_top):
    """Labels horizontal lines at the right edge of a log axis, moved apart where they would
    overlap (at least 4 % of the axis height between two labels)."""
    span = math.log10(y_top) - math.log10(y_bottom)
    gap = 0.04 * span
    placed = []
    for value, text, color in sorted(marks, key=lambda m: -m[0]):
        y = math.log10(value)
        if placed and placed[-1] - y < gap:
            y = placed[-1] - gap
        placed.append(y)
        ax.annotate(text, (1.0, 10.0 ** y), xycoords=("axes fraction", "data"), xytext=(3, 0),
                    textcoords="offset points", va="center", fontsize=7.5, color=color)


def plot_overlay(fig_data, out):
    f = fig_data
    drawn = [n for n in f.names if f.kinds[n] != "zero"]
    positive = [y for n in drawn for y in f.series[n] if y > 0]
    top = max(positive, default=1.0)
    low = min(min(positive, default=f.threshold), f.threshold)
    y_top = 10.0 ** math.ceil(math.log10(top) + 0.3)
    y_bottom = 10.0 ** math.floor(math.log10(low) - 0.3)
    fig, ax = plt.subplots(figsize=(8.5, 5.2))
    ax.set_yscale("log")
    ax.set_xlim(f.x0, f.x1)
    ax.set_ylim(y_bottom, y_top)
    ax.axhspan(y_bottom, f.threshold, color="0.88", zorder=0)
    handles = [Patch(color="0.88", label=f.noise_text())]
    # Robust from the largest eps down, so that the smaller errors are on top, then classic (its
    # errors are sparse in the tournament and would be hidden below the robust ones).
    order = sorted(drawn, key=lambda n: (eps_of(n) is None, -(eps_of(n) or 0.0)))
    for z, name in enumerate(order):
        color = NOISE_COLOR if f.kinds[name] == "noise" else f.colors[name]
        draw_log_envelope(ax, f.t_lo, f.t_hi, f.series[name], f.threshold, color, 3 + z)
        if f.kinds[name] == "noise":
            text = "%s: rounding noise (< %s), max %s: not an error" % (
                short_label(name), sci(f.threshold), sci(f.peak[name]))
        else:
            text = "%s: max %s" % (short_label(name), sci(f.peak[name]))
        handles.append(Line2D([], [], color=color, linestyle="none", marker="o", markersize=4,
                              label=text))
    marks = []  # (value, text, colour) labelled at the right edge
    if f.kind == "sorting":
        for name in f.names:
            eps = eps_of(name)
            if eps is not None and y_bottom < eps < y_top:
                ax.axhline(eps, color=f.colors[name], linewidth=0.8, linestyle=(0, (1, 2)))
                marks.append((eps, "\u03b5 = %s" % sci(eps), f.colors[name]))
        if any(eps_of(n) is not None for n in f.names):
            handles.append(Line2D([], [], color="0.3", linewidth=0.8, linestyle=(0, (1, 2)),
                                  label="\u03b5 of the robust run of the same colour"))
    else:
        # The tournament's errors are sparse spikes: a line at each run's maximum.
        for name in order:
            if f.kinds[name] != "error":
                continue
            ax.axhline(f.peak[name], color=f.colors[name], linewidth=0.8, linestyle="--")
            marks.append((f.peak[name], "max %s" % sci(f.peak[name]), f.colors[name]))
        handles.append(Line2D([], [], color="0.3", linewidth=0.8, linestyle="--",
                              label="maximum of the run of the same colour"))
    label_right_edge(ax, marks, y_bottom, y_top)
    for name in f.names:
        if f.kinds[name] == "zero":
            handles.append(Line2D([], [], linestyle="none", marker="",
                                  label="%s: err(t) = 0 at every t (nothing to draw on a log axis)"
                                  % short_label(name)))
    # A grid line at every power of ten, so that orders of magnitude can be read off.
    ax.yaxis.set_minor_locator(LogLocator(base=10.0, subs=(1.0,), numticks=100))
    ax.yaxis.set_minor_formatter(NullFormatter())
    ax.grid(True, which="major", linewidth=0.4)
    ax.grid(True, which="minor", axis="y", linewidth=0.2, color="0.8")
    ax.set_xlabel("t (time units of the scenario)")
    ax.set_ylabel("err(t), position units (log scale)")
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2,
              fontsize=7.5, frameon=False)
    ax.set_title("%s: every run on one log axis" % f.title(), fontsize=11)
    fig.text(0.01, -0.005, f.caption() + "\ngaps: err = 0 there", fontsize=8, va="top", ha="left",
             color="0.25")
    fig.tight_layout()
    fig.savefig(out, dpi=110, bbox_inches="tight")
    plt.close(fig)


def plot(directory, csv_name, png_name, log_png_name, dataset, kind):
    path = os.path.join(directory, csv_name)
    if not os.path.exists(path):
        return []
    try:
        data = Figure(directory, csv_name, dataset, kind)
    except ValueError as e:
        sys.stderr.write("plot: %s skipped: %s\n" % (path, e))
        return []
    out = os.path.join(directory, png_name)
    plot_panels(data, out)
    out_log = os.path.join(directory, log_png_name)
    plot_overlay(data, out_log)
    return [out, out_log]


def plot_delaunay(directory):
    """delaunay_eps.png from delaunay_runs.csv: delays and geometric error against eps."""
    path = os.path.join(directory, "delaunay_runs.csv")
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["scheduler"] == "robust"]
    if not rows:
        return []
    rows.sort(key=lambda r: float(r["eps"]))
    eps = [float(r["eps"]) for r in rows]
    grid = [float(r["grid"]) for r in rows]
    delay_max = [float(r["delay_max"]) for r in rows]
    delay_rms = [float(r["delay_rms"]) for r in rows]
    wrong = [100.0 * float(r["wrong_fraction"]) for r in rows]
    excess = [float(r["angle_excess_max"]) for r in rows]
    n = rows[0]["n"]
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    left.loglog(eps, grid, "k--", label="grid width w")
    left.loglog(eps, delay_max, "o-", color="tab:red", label="largest delay")
    left.loglog(eps, delay_rms, "s-", color="tab:blue", label="RMS delay")
    left.set_xlabel("eps")
    left.set_ylabel("delay of a flip (time units)")
    left.set_title("Delay of the flips")
    left.legend(loc="upper left")
    left.grid(True, which="both", alpha=0.3)
    right.semilogx(eps, wrong, "o-", color="tab:red", label="samples with an edge not Delaunay (%)")
    right.set_xlabel("eps")
    right.set_ylabel("% of the sample times", color="tab:red")
    right.set_ylim(0, 100)
    twin = right.twinx()
    twin.semilogx(eps, excess, "s-", color="tab:blue", label="largest angle excess (degrees)")
    twin.set_ylabel("largest excess over 180 degrees (degrees)", color="tab:blue")
    twin.set_ylim(bottom=0)
    right.set_title("Geometric error at the sample times")
    lines = right.get_lines() + twin.get_lines()
    right.legend(lines, [line.get_label() for line in lines], loc="upper left")
    right.grid(True, which="both", alpha=0.3)
    fig.suptitle("Robust kinetic Delaunay triangulation, random points on lines, n = %s" % n)
    fig.tight_layout()
    out = os.path.join(directory, "delaunay_eps.png")
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return [out]


def main():
    if len(sys.argv) != 2:
        sys.stderr.write(__doc__)
        return 2
    directory = sys.argv[1]
    written = [p for fig in FIGURES for p in plot(directory, *fig)]
    written += plot_delaunay(directory)
    for p in written:
        print("plot: " + p)
    return 0 if written else 1


if __name__ == "__main__":
    sys.exit(main())
