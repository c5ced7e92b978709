"""Table 1 of Abam, Agarwal, de Berg and Yu (robust kinetic sorting) from Python.

Runs ``kinetic.experiment_sorting`` (the paper's GRIDS, PARABOLA and RANDDC inputs; the
classic, robust and exact schedulers; see docs/experiments.md), prints its report, then
prints Table 1 again from the returned per-run dicts: the delay of the events
(t_pr - t_ex, in units of eps), RMS and maximum, beside the paper's values. With --plot it
draws the error envelopes of one dataset (the maximum of err(t) over each part of the window,
one curve per run) on a log scale.

Run it with the interpreter that has the ``kinetic`` module installed (see docs/python.md):

    python3 examples/python/table1.py                  # n = 900, as the paper (about a minute)
    python3 examples/python/table1.py --n 100 --plot /tmp/err_grids.png

The paper's values are for n = 900; at another n they are shown for reference only.
"""

import argparse
import sys
import time

import numpy as np

import kinetic

PAPER_N = 900
DATASETS = ["grids", "parabola", "randdc"]


def print_table1(runs, n):
    """Table 1 from the runs' dicts: one row per (dataset, eps) of the robust runs."""
    robust = [r for r in runs if r["scheduler"] == "robust" and "delay_rms_in_eps" in r]
    note = "" if n == PAPER_N else f" (the paper's values are for n = {PAPER_N})"
    print(f"Table 1 from the runs: delay t_pr - t_ex in units of eps, n = {n}{note}")
    header = (f"{'dataset':<9} {'eps':>7} {'events':>8}  {'RMS':>6} {'paper':>6}  "
              f"{'max':>6} {'paper':>6}  {'Thm 1':>9} {'Thm 2':>5}")
    print(header)
    print("-" * len(header))

    def paper(value):
        return f"{value:6.2f}" if value is not None else f"{'-':>6}"

    for r in robust:
        thm1 = f"{r['theorem1_violations']}/{r['theorem1_checked']}"
        print(f"{r['dataset']:<9} {r['eps']:7.0e} {r['delays_measured']:8d}  "
              f"{r['delay_rms_in_eps']:6.2f} {paper(r['paper_delay_rms_in_eps'])}  "
              f"{r['delay_max_in_eps']:6.2f} {paper(r['paper_delay_max_in_eps'])}  "
              f"{thm1:>9} {'ok' if r['theorem2_holds'] else 'FAIL':>5}")
    print("Thm 1: violations / pairs checked; Thm 2: every delay <= n s eps")
    return all(r["theorem1_violations"] == 0 and r["theorem2_holds"] for r in robust)


def run_label(r):
    if r["scheduler"] == "robust":
        return f"robust, eps = {r['eps']:g}"
    if r["scheduler"] == "classic":
        return "classic (floating-point event times)"
    return r["scheduler"]


def plot_envelopes(runs, dataset, path):
    """One panel per run of the dataset (as the paper's Figures 6-8, but on a log scale): the
    maximum of err(t) over each part of the window, as steps."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mine = [r for r in runs if r["dataset"] == dataset]
    if not mine:
        sys.exit(f"table1: no run of dataset {dataset!r}")
    drawn = [r for r in mine if np.any(np.asarray(r["envelope"]) > 0)]
    zero = [run_label(r) for r in mine if r not in drawn]  # nothing to draw on a log scale
    fig, axes = plt.subplots(len(drawn), 1, figsize=(9, 1.9 * len(drawn) + 1.0), sharex=True,
                             squeeze=False)
    axes = axes[:, 0]
    for ax, r in zip(axes, drawn):
        env = np.asarray(r["envelope"], dtype=float)
        edges = np.linspace(r["start"], r["end"], len(env) + 1)
        # A log scale has no place for 0 (the order exactly sorted there): the steps drop to the
        # bottom of the panel, so each short excursion of err shows as a spike.
        color = {"classic": "tab:red", "exact": "tab:green"}.get(r["scheduler"], "tab:blue")
        ax.stairs(env, edges, color=color, linewidth=0.7)
        ax.set_yscale("log")
        positive = env[env > 0]
        ax.set_ylim(positive.min() / 3.0, positive.max() * 3.0)
        ax.set_title(f"{run_label(r)}: max err {env.max():.3g}", fontsize=9)
        ax.set_ylabel("err (position\nunits)", fontsize=8)
        ax.grid(True, which="major", linewidth=0.3)
    axes[-1].set_xlabel("time t (time units)")
    title = (f"Kinetic sorting on {dataset.upper()}, n = {mine[0]['n']}: max of "
             f"err(t) = max_i |y_i(t) - z_i(t)| over each 1/{len(mine[0]['envelope'])} "
             "of the window\n(positions scaled into [-1, 1])")
    if zero:
        title += "; err = 0 throughout, not drawn: " + ", ".join(zero)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=PAPER_N,
                        help=f"objects per dataset (default {PAPER_N}, the paper's; "
                             "e.g. 100 for a quick run)")
    parser.add_argument("--seed", type=int, default=1, help="dataset seed (default 1)")
    parser.add_argument("--plot", metavar="PATH", help="draw the error envelopes to PATH (PNG)")
    parser.add_argument("--dataset", default="grids", choices=DATASETS,
                        help="the dataset whose envelopes --plot draws (default grids)")
    parser.add_argument("--no-report", action="store_true",
                        help="print only Table 1, not the experiment's full report")
    args = parser.parse_args(argv)

    t0 = time.perf_counter()
    result = kinetic.experiment_sorting(datasets=DATASETS, n=args.n, seed=args.seed)
    seconds = time.perf_counter() - t0
    if not args.no_report:
        print(result["report"])
    ok = print_table1(result["runs"], args.n)
    print(f"\n{len(result['runs'])} runs in {seconds:.1f} s")
    if args.plot:
        plot_envelopes(result["runs"], args.dataset, args.plot)
        print(f"figure: {args.plot}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
