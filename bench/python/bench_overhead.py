"""The per-query overhead of calling kinetic's queries from Python rather than from C++.

For three structures over n = 10^4 moving objects (advanced to t = 1) it times one small
query called from Python (``timeit``; best of several rounds) against the same query in a
C++ loop inside the module (the ``_seconds_per_*`` methods: seconds per call, no Python in
between), and prints the difference, the overhead of one call:

- ``KdTree.range(box)``: 2-D points on random lines, a box holding about 10 points; the box
  passed as a numpy array (2, 2) and as a Python list;
- ``SegmentTree.stab(x)``: intervals [c - w, c + w] moving at one speed each (so left <= right
  at every time), an x inside about 10 of them;
- ``LongestSideKdTree.nearest(point, eps)``: the same points; the point as a numpy array and
  as a tuple (advancing it to t = 1 processes about 680,000 events at n = 10^4, a few
  seconds).

Then the batch forms against as many single calls from Python: ``range_many`` over 1000
boxes, ``stab_many`` over 1000 xs and ``nearest_many`` over 1000 points, per query.

Run it with the interpreter that has the ``kinetic`` module installed (see docs/python.md),
on an otherwise idle machine:

    python3 bench/python/bench_overhead.py
    python3 bench/python/bench_overhead.py --quick     # fewer repetitions, for a smoke test
"""

import argparse
import os
import platform
import sys
import timeit

import numpy as np

import kinetic


def best_python(stmt, env, number, rounds):
    """Seconds per call of stmt (a string, run with the names of env), best of rounds."""
    timer = timeit.Timer(stmt, globals=env)
    return min(timer.repeat(repeat=rounds, number=number)) / number


def best_cpp(call, rounds):
    """Seconds per call from one of the _seconds_per_* C++ loops, best of rounds."""
    return min(call() for _ in range(rounds))


def small_boxes(rng, x, q, hits):
    """q boxes (q, 2, 2), squares centred on random points, of the side that holds about
    `hits` points at the points' mean density."""
    lo, hi = x.min(axis=0), x.max(axis=0)
    side = np.sqrt(hits * np.prod(hi - lo) / len(x))
    centres = x[rng.integers(0, len(x), size=q)]
    return np.stack([centres - side / 2, centres + side / 2], axis=2)


def interval_motions(rng, n, field, half_width):
    """(n, 2, 2): left = c - w, right = c + w, both with the same velocity v, so the interval
    keeps its width 2w >= 0 at every time."""
    c = rng.uniform(0.0, field, n)
    w = rng.uniform(0.0, half_width, n)
    v = rng.uniform(-1.0, 1.0, n)
    return np.stack([np.stack([c - w, v], axis=1), np.stack([c + w, v], axis=1)], axis=1)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=10_000, help="objects per structure (10^4)")
    parser.add_argument("--t", type=float, default=1.0, help="the time advanced to (1)")
    parser.add_argument("--number", type=int, default=20_000,
                        help="calls per timing round of a single query (20000)")
    parser.add_argument("--rounds", type=int, default=7, help="rounds; the best is kept (7)")
    parser.add_argument("--batch", type=int, default=1000, help="queries per batch call (1000)")
    parser.add_argument("--eps", type=float, default=0.1, help="nearest()'s eps (0.1)")
    parser.add_argument("--seed", type=int, default=1, help="seed of motions and queries (1)")
    parser.add_argument("--quick", action="store_true",
                        help="number 2000, rounds 3: a smoke test, not a measurement")
    args = parser.parse_args(argv)
    if args.quick:
        args.number, args.rounds = 2000, 3
    number, rounds = args.number, args.rounds
    rng = np.random.default_rng(args.seed)

    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print("Per-query overhead of kinetic's Python bindings")
    print(f"  n = {args.n} objects per structure, advanced to t = {args.t:g}")
    print(f"  single queries: best of {rounds} rounds of {number} calls (timeit); C++ loops: "
          f"best of {rounds} rounds of {number} calls")
    print(f"  batches: {args.batch} queries per call, best of {rounds} rounds")
    print(f"  interpreter {sys.executable} (Python {platform.python_version()}), "
          f"numpy {np.__version__}, kinetic {kinetic.__version__}")
    print(f"  {platform.machine()}, {os.cpu_count()} CPUs, load average {load:.2f}")

    # --- the structures -------------------------------------------------------------------
    points = kinetic.generate("random-linear", n=args.n, seed=args.seed, dimension=2)
    kd = kinetic.KdTree(points.motions, ids=points.ids, origins=points.origins)
    kd.advance(args.t)
    ls = kinetic.LongestSideKdTree(points.motions, ids=points.ids, origins=points.origins)
    ls.advance(args.t)
    x = kd.positions()  # rows in ids order; the ids are 0..n-1

    field = 1000.0
    intervals = interval_motions(rng, args.n, field, half_width=10.0 * field / args.n)
    seg = kinetic.SegmentTree(intervals)
    seg.advance(args.t)

    box = small_boxes(rng, x, 1, hits=10)[0]
    box_list = box.tolist()
    point = x[rng.integers(0, args.n)] + 0.01
    point_tuple = (float(point[0]), float(point[1]))
    centres = (intervals[:, 0, 0] + intervals[:, 1, 0]) / 2 + intervals[:, 0, 1] * args.t
    stab_x = float(centres[rng.integers(0, args.n)])

    boxes = small_boxes(rng, x, args.batch, hits=10)
    box_lists = boxes.tolist()
    points_q = x[rng.integers(0, args.n, size=args.batch)] + 0.01
    xs = centres[rng.integers(0, args.n, size=args.batch)]

    print(f"  answers: range {len(kd.range(box))} ids, stab {len(seg.stab(stab_x))} ids, "
          f"batch range {np.mean([len(a) for a in kd.range_many(boxes)]):.1f} ids/box, "
          f"batch stab {np.mean([len(a) for a in seg.stab_many(xs)]):.1f} ids/x")

    env = dict(kd=kd, ls=ls, seg=seg, box=box, box_list=box_list, point=point,
               point_tuple=point_tuple, stab_x=stab_x, eps=args.eps, boxes=boxes,
               box_lists=box_lists, points_q=points_q, xs=xs)
    us = 1e6

    # --- single queries: Python call vs C++ loop -------------------------------------------
    rows = []
    cpp_range = best_cpp(lambda: kd._seconds_per_range(box, number), rounds)
    rows.append(("KdTree.range(box), box numpy (2, 2)", cpp_range,
                 best_python("kd.range(box)", env, number, rounds)))
    rows.append(("KdTree.range(box), box Python list", cpp_range,
                 best_python("kd.range(box_list)", env, number, rounds)))
    cpp_stab = best_cpp(lambda: seg._seconds_per_stab(stab_x, number), rounds)
    rows.append(("SegmentTree.stab(x), x float", cpp_stab,
                 best_python("seg.stab(stab_x)", env, number, rounds)))
    cpp_nearest = best_cpp(lambda: ls._seconds_per_nearest(point, args.eps, number), rounds)
    rows.append((f"LongestSideKdTree.nearest(p, {args.eps:g}), p numpy", cpp_nearest,
                 best_python("ls.nearest(point, eps)", env, number, rounds)))
    rows.append((f"LongestSideKdTree.nearest(p, {args.eps:g}), p tuple", cpp_nearest,
                 best_python("ls.nearest(point_tuple, eps)", env, number, rounds)))

    # --- batches: one call for `batch` queries vs `batch` single calls ---------------------
    b = args.batch
    batch_number = max(1, number // b)  # about as many queries per round as above
    per_query = lambda stmt: best_python(stmt, env, batch_number, rounds) / b  # noqa: E731
    # The C++ reference of a batch: the mean over its queries of each one's C++ loop time.
    reps = max(1, number // 100)
    cpp_boxes = np.mean([kd._seconds_per_range(q, reps) for q in boxes])
    cpp_xs = np.mean([seg._seconds_per_stab(float(v), reps) for v in xs])
    cpp_points = np.mean([ls._seconds_per_nearest(p, args.eps, reps) for p in points_q])
    batch_rows = [
        (f"range_many({b} boxes)", cpp_boxes, per_query("kd.range_many(boxes)")),
        (f"range_many({b} boxes, flat=True)", cpp_boxes,
         per_query("kd.range_many(boxes, flat=True)")),
        (f"{b} x range(box), numpy boxes", cpp_boxes,
         per_query("for q in boxes: kd.range(q)")),
        (f"{b} x range(box), list boxes", cpp_boxes,
         per_query("for q in box_lists: kd.range(q)")),
        (f"stab_many({b} xs)", cpp_xs, per_query("seg.stab_many(xs)")),
        (f"stab_many({b} xs, flat=True)", cpp_xs, per_query("seg.stab_many(xs, flat=True)")),
        (f"{b} x stab(x)", cpp_xs, per_query("for v in xs.tolist(): seg.stab(v)")),
        (f"nearest_many({b} points)", cpp_points, per_query("ls.nearest_many(points_q, eps)")),
        (f"{b} x nearest(p), numpy points", cpp_points,
         per_query("for p in points_q: ls.nearest(p, eps)")),
    ]

    def table(title, rows):
        print(f"\n{title}")
        head = f"{'query':<44} {'C++ us/call':>11} {'Python us/call':>14} {'overhead us':>11} {'ratio':>6}"
        print(head)
        print("-" * len(head))
        for name, cpp, py in rows:
            print(f"{name:<44} {cpp * us:11.3f} {py * us:14.3f} {(py - cpp) * us:11.3f} "
                  f"{py / cpp:6.2f}")

    table("Single queries (the same query each call)", rows)
    table(f"Batches, per query ({b} different queries; C++: the mean of each query's C++ loop)",
          batch_rows)
    print("\noverhead = Python - C++; C++ = the query inside the module in a loop (the "
          "_seconds_per_* methods), Python = the call from Python, argument conversion, the "
          "in-use check and the numpy id array of the answer included. The batches' C++ "
          "reference repeats each query with warm caches while a batch meets each query once, "
          "so their overhead column is an upper bound.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
