"""Kinetic sorting of a dozen points on the line: the trajectories and the swap events.

A dozen points move along the line on random polynomial motions (default: quadratics,
``kinetic.generate('random-poly', ...)``). ``kinetic.run(scenario, 'sort', events=True)``
runs the kinetic sort over the scenario's window and returns every external event: each
swap of two neighbours in the sorted order, at the time their trajectories cross. The script
draws the trajectories in the (t, x) plane and marks each swap at its time and position,
then drives a ``kinetic.Sort`` session itself (``advance(t)``) and checks ``sorted()``
at a few times against ``numpy.argsort`` of the positions evaluated with numpy.

Run it with the interpreter that has the ``kinetic`` module installed (see docs/python.md):

    python3 examples/python/sort_trajectories.py --out /tmp/sort_trajectories.png
    python3 examples/python/sort_trajectories.py --dataset random-linear --n 8 --seed 4

Exit status 0 iff every check agrees.
"""

import argparse
import sys

import numpy as np

import kinetic
from motion_arrays import evaluate


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=12, help="number of points (default 12)")
    parser.add_argument("--seed", type=int, default=5, help="generator seed (default 5)")
    parser.add_argument("--dataset", default="random-poly",
                        choices=["random-poly", "random-linear"],
                        help="motions: random quadratics (default) or random lines")
    parser.add_argument("--degree", type=int, default=2,
                        help="degree of the random-poly motions (default 2)")
    parser.add_argument("--scenario", metavar="PATH",
                        help="read a 1-D scenario file (docs/scenario-format.md) instead")
    parser.add_argument("--checks", type=int, default=7,
                        help="times at which sorted() is checked against numpy (default 7)")
    parser.add_argument("--out", default="sort_trajectories.png",
                        help="where to save the figure (default ./sort_trajectories.png)")
    args = parser.parse_args(argv)

    if args.scenario:
        scenario = kinetic.load_scenario(args.scenario)
    else:
        scenario = kinetic.generate(args.dataset, n=args.n, seed=args.seed, dimension=1,
                                    degree=args.degree)
    if scenario.dimension != 1 or scenario.objects != "points":
        sys.exit("sort_trajectories: needs points in 1 dimension, got " + repr(scenario))
    start = scenario.start_time
    end = scenario.end_time if scenario.end_time is not None else start + 10.0
    motions, origins, ids = scenario.motions, scenario.origins, scenario.ids

    # 1. The events: the runner processes the whole window and logs every swap.
    result = kinetic.run(scenario, "sort", events=True)
    swaps = [e for e in result["events"] if e["kind"] == "swap"]
    row_of = {int(i): r for r, i in enumerate(ids)}
    # A swap happens where the two trajectories cross: both are at the same place then.
    swap_t = np.array([e["time"] for e in swaps])
    swap_x = np.array([evaluate(motions[[row_of[e["ids"][0]]]], origins[[row_of[e["ids"][0]]]],
                                e["time"])[0, 0] for e in swaps])

    # 2. A session driven from Python: sorted() at a few times against numpy's argsort.
    sort = kinetic.session(scenario, "sort")
    all_agree = True
    print(f"{'t':>8}  {'sorted() agrees with argsort':<30}  order (ids)")
    for t in np.linspace(start, end, args.checks):
        sort.advance(t)
        order = sort.sorted()
        x = evaluate(motions, origins, t)[:, 0]
        expected = ids[np.argsort(x, kind="stable")]
        agree = np.array_equal(order, expected)
        if not agree:
            # Only a tie (or a crossing closer than rounding) may order two ids differently:
            # then the positions along sorted() are still non-decreasing.
            xs = x[[row_of[int(i)] for i in order]]
            agree = bool(np.all(np.diff(xs) >= -1e-12 * max(1.0, np.abs(xs).max())))
        all_agree &= agree
        print(f"{t:8.3f}  {'yes' if agree else 'NO':<30}  {' '.join(map(str, order))}")

    # 3. The figure: trajectories in the (t, x) plane, a marker at every swap.
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ts = np.linspace(start, end, 600)
    xs = np.stack([evaluate(motions, origins, t)[:, 0] for t in ts], axis=1)
    fig, ax = plt.subplots(figsize=(9, 5.5))
    colors = plt.cm.tab20(np.linspace(0.0, 1.0, 20))  # distinct colours for up to 20 lines
    for r, i in enumerate(ids):
        ax.plot(ts, xs[r], lw=1.2, color=colors[r % 20])
        ax.annotate(str(i), (ts[-1], xs[r, -1]), xytext=(3, 0), textcoords="offset points",
                    va="center", fontsize=7)
    ax.scatter(swap_t, swap_x, marker="o", s=28, facecolors="none", edgecolors="black",
               zorder=3, label=f"swap events ({len(swaps)})")
    ax.set_xlabel("time t")
    ax.set_ylabel("position x(t)")
    ax.set_title(f"Kinetic sort of {len(ids)} points: trajectories and swap events")
    ax.legend(loc="best")
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)

    stats = result["stats"]
    print(f"\n{len(ids)} points ({args.scenario or args.dataset}), window [{start:g}, {end:g}]: "
          f"{len(swaps)} swaps, {stats['events']['processed']} events processed "
          f"(outcome {result['outcome']}, scheduler {stats['scheduler']})")
    if swaps:
        first = swaps[0]
        print(f"first swap: ids {first['ids'][0]} and {first['ids'][1]} at t = "
              f"{first['time']:.6f}, x = {swap_x[0]:.6f}")
    print(f"sorted() against numpy argsort at {args.checks} times: "
          f"{'all agree' if all_agree else 'MISMATCH'}")
    print(f"figure: {args.out}")
    return 0 if all_agree else 1


if __name__ == "__main__":
    sys.exit(main())
