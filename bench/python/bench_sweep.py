"""kinetic.sweep on a local Dask cluster: the speed-up of 2 worker processes over 1 on the
sorting experiment's runs, and the scheduler's overhead per run on many short runs.

1. The sorting experiment's 15 runs (GRIDS, PARABOLA, RANDDC at --n, on the datasets' own
   coordinates; classic, robust at eps 1e-6, 1e-7, 1e-8, exact) through ``kinetic.run`` (without
   the experiment's error sampling) as a sweep, on a local cluster of 1 worker process, then of
   2; the rows of both are checked equal (all but their wall times). Reported: wall seconds
   each, and the ratio.
2. ``--short`` runs (random-linear, n = 2: microseconds each) on 2 workers: the sweep's wall time
   per run minus the runs' own time per run (as measured on their workers, divided by the
   workers) is what Dask and the sweep add per run (submission, scheduling, the result's trip
   back, the row written).

The clusters are started before the clock starts (a cluster's start is paid once per sweep).

    python3 bench/python/bench_sweep.py                 # the interpreter with kinetic installed
    python3 bench/python/bench_sweep.py --short 200     # fewer short runs
"""

import argparse
import os
import platform
import tempfile
import time

import distributed

from kinetic import sweep


def timed_sweep(runs, workers):
    cluster = distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    client = distributed.Client(cluster)
    client.wait_for_workers(workers)
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        rows = sweep.sweep(runs, os.path.join(tmp, "rows.jsonl"), client=client, progress=False)
        wall = time.perf_counter() - start
    client.close()
    cluster.close()
    return rows, wall


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, default=900)
    parser.add_argument("--short", type=int, default=1000, help="short runs for the overhead")
    args = parser.parse_args()
    print("# bench_sweep: kinetic.sweep on a local Dask cluster (distributed %s)"
          % distributed.__version__)
    print("# machine: %d hardware threads, %s, Python %s" % (os.cpu_count(), platform.machine(),
                                                             platform.python_version()))
    runs = []
    for dataset in ("grids", "parabola", "randdc"):
        for scheduler, eps in (("classic", 1e-9), ("robust", 1e-6), ("robust", 1e-7),
                               ("robust", 1e-8), ("exact", 1e-9)):
            runs.append(dict(dataset=dataset, n=args.n, seed=1, structure="sort",
                             scheduler=scheduler, eps=eps))
    one, wall1 = timed_sweep(runs, 1)
    two, wall2 = timed_sweep(runs, 2)
    same = [{k: v for k, v in r.items() if k != "wall_s"} for r in one] == \
           [{k: v for k, v in r.items() if k != "wall_s"} for r in two]
    print("\nThe sorting experiment's %d runs (n = %d) as a sweep:" % (len(runs), args.n))
    print("  1 worker:  %.2f s" % wall1)
    print("  2 workers: %.2f s   speed-up %.2fx   rows equal: %s" % (wall2, wall1 / wall2, same))
    failed = [r for r in one + two if r["status"] != "ok"]
    if failed:
        print("  failed runs: %s" % failed[0]["error"])

    short = [dict(dataset="random-linear", n=2, seed=s, structure="sort") for s in range(args.short)]
    rows, wall = timed_sweep(short, 2)
    own = sum(r["wall_s"] for r in rows) / 2
    print("\n%d short runs on 2 workers: %.2f s, %.2f ms per run; the runs' own time %.3f ms per"
          " run; the overhead %.2f ms per run" % (len(short), wall, 1e3 * wall / len(short),
                                                  1e3 * own / len(short),
                                                  1e3 * (wall - own) / len(short)))


if __name__ == "__main__":
    main()
