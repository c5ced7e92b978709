"""Orthogonal range queries on a kinetic kd-tree of moving points, checked against numpy.

2,000 points move on random straight lines in the plane (``kinetic.generate('random-linear',
dimension=2)``). A ``kinetic.KdTree`` follows them; the script advances it to several times
and at each asks random closed boxes, one at a time (``range(box)``) and all at once
(``range_many(boxes)``, an array (q, 2, 2)), and compares every answer with a numpy brute
force over the positions evaluated from the coefficient array. It prints the agreements and
the time per query seen from Python for the kd-tree and for the numpy brute force.

Run it with the interpreter that has the ``kinetic`` module installed (see docs/python.md):

    python3 examples/python/kdtree_range.py
    python3 examples/python/kdtree_range.py --n 20000 --queries 500

Exit status 0 iff every answer agrees.
"""

import argparse
import sys
import time

import numpy as np

import kinetic
from motion_arrays import evaluate

# The kd-tree decides "is this point in the box" exactly, on the motions themselves; numpy
# evaluates the positions in floating point, so a point within rounding of a box side may fall
# on the other side of it in numpy. Such points (within TOLERANCE of a side) are left out of the
# comparison: either answer is right for them as far as numpy can tell.
TOLERANCE = 1e-9


def brute_force(x, ids, box):
    """The ids whose position is in the closed box (d, 2), ascending, and the mask of the
    points within TOLERANCE of one of the box's sides."""
    lo, hi = box[:, 0], box[:, 1]
    inside = np.all((lo <= x) & (x <= hi), axis=1)
    near_side = np.any((np.abs(x - lo) <= TOLERANCE) | (np.abs(x - hi) <= TOLERANCE), axis=1)
    return np.sort(ids[inside]), near_side


def random_boxes(rng, x, q, side_fraction, snap_fraction):
    """q closed boxes (q, d, 2) with random corners over the points' bounding box and sides up
    to side_fraction of its extent. In a snap_fraction of them the lower corner is put on a
    point's position as numpy computes it, so that the point lies on two sides of the box (up
    to rounding): the cases the comparison has to leave out."""
    lo_all, hi_all = x.min(axis=0), x.max(axis=0)
    extent = hi_all - lo_all
    lo = rng.uniform(lo_all - 0.05 * extent, hi_all, size=(q, x.shape[1]))
    snapped = rng.random(q) < snap_fraction
    lo[snapped] = x[rng.integers(0, len(x), size=int(snapped.sum()))]
    side = rng.uniform(0.0, side_fraction, size=(q, x.shape[1])) * extent
    return np.stack([lo, lo + side], axis=2)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=2000, help="number of points (default 2000)")
    parser.add_argument("--seed", type=int, default=11, help="seed of motions and boxes")
    parser.add_argument("--queries", type=int, default=200,
                        help="boxes asked at each time (default 200)")
    parser.add_argument("--side", type=float, default=0.2,
                        help="largest box side, as a fraction of the points' extent")
    parser.add_argument("--snap", type=float, default=0.25,
                        help="fraction of boxes with a corner on a point (default 0.25)")
    parser.add_argument("--times", type=float, nargs="+", default=[0.5, 2.0, 4.25, 7.0, 10.0],
                        help="times to advance to (ascending, within [0, 10])")
    args = parser.parse_args(argv)

    scenario = kinetic.generate("random-linear", n=args.n, seed=args.seed, dimension=2)
    motions, origins, ids = scenario.motions, scenario.origins, scenario.ids
    tree = kinetic.KdTree(motions, ids=ids, origins=origins, start=scenario.start_time)
    rng = np.random.default_rng(args.seed)
    print(f"{tree!r}: {args.n} points on random lines, {args.queries} boxes per time")
    print(f"{'t':>6} {'events':>7} {'single':>9} {'many':>9} {'excluded':>9} "
          f"{'avg hits':>8} {'kd us/q':>8} {'many us/q':>9} {'numpy us/q':>10}")

    all_agree = True
    totals = dict(queries=0, agree_single=0, agree_many=0, excluded=0, raw_differ=0)
    for t in args.times:
        t0 = time.perf_counter()
        tree.advance(t)
        advance_s = time.perf_counter() - t0
        x = evaluate(motions, origins, t)
        boxes = random_boxes(rng, x, args.queries, args.side, args.snap)

        t0 = time.perf_counter()
        single = [tree.range(b) for b in boxes]
        kd_s = time.perf_counter() - t0
        t0 = time.perf_counter()
        many = tree.range_many(boxes)
        many_s = time.perf_counter() - t0
        t0 = time.perf_counter()
        brute = [brute_force(x, ids, b) for b in boxes]
        numpy_s = time.perf_counter() - t0

        agree_single = agree_many = excluded = hits = 0
        for got, got_many, (expected, near_side) in zip(single, many, brute):
            excluded += int(near_side.sum())
            totals["raw_differ"] += not np.array_equal(got, expected)
            keep = ids[~near_side]
            agree_single += np.array_equal(np.intersect1d(got, keep),
                                           np.intersect1d(expected, keep))
            agree_many += np.array_equal(got_many, got)  # the batch gives the same answers
            hits += len(got)
        q = len(boxes)
        all_agree &= agree_single == q and agree_many == q
        totals["queries"] += q
        totals["agree_single"] += agree_single
        totals["agree_many"] += agree_many
        totals["excluded"] += excluded
        events = tree.counters()["events"]
        print(f"{t:6.2f} {str(events.get('processed', events)):>7} {agree_single:>4}/{q:<4} "
              f"{agree_many:>4}/{q:<4} {excluded:>9} {hits / q:8.1f} {1e6 * kd_s / q:8.2f} "
              f"{1e6 * many_s / q:9.2f} {1e6 * numpy_s / q:10.2f}   "
              f"(advance {1e3 * advance_s:.1f} ms)")

    print(f"\nrange(box) agrees with numpy on {totals['agree_single']}/{totals['queries']} boxes; "
          f"range_many agrees with range on {totals['agree_many']}/{totals['queries']}; "
          f"{totals['excluded']} point-box pairs within {TOLERANCE:g} of a side left out "
          f"(without leaving them out, {totals['raw_differ']} answers differ from numpy's)")
    print("times are per query from Python: 'kd' one range() call per box, 'many' one "
          "range_many() call for all boxes, 'numpy' a vectorised scan of all n positions per box "
          "(positions evaluated once per time, not counted)")
    return 0 if all_agree else 1


if __name__ == "__main__":
    sys.exit(main())
