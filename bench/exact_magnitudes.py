"""Exact Delaunay runs at extreme magnitudes against the same runs at ordinary ones.

The exact in-circle arithmetic grows with the magnitudes of the motions' coefficients, and
`delaunay` and `closest-pair` take coefficients (expanded about t = 0) of magnitude
2^-128 <= |c| < 2^128, or 0 (docs/scheduling.md, "Extreme magnitudes"). This benchmark plays
random scenarios through `kinetic run --structure delaunay --scheduler exact`: 3 to 20 points on
lines and parabolas with coefficients in [-5, 5], of which one to four (coefficients, or an
origin) are replaced by +-(1 to 1.9) * 2^k, k uniform in [-E, E]; half of them with
`end_time` 10, half with none (run until no event is left); one or two flight-plan updates.
The baseline is the same generator with E = 0 (the replaced values ordinary), measured in the
same run. It prints, for each, the runs answered and refused (exit 2: beyond the limit) and the
wall seconds per answered run (mean, 99th percentile, max), and the ratios to the baseline.

    python3 bench/exact_magnitudes.py                       # E = 140, 600 runs, seed 6
    python3 bench/exact_magnitudes.py --runs 100 --quick    # a smoke test
    python3 bench/exact_magnitudes.py --kinetic build/release/kinetic --exponent 300
"""

import argparse
import json
import os
import platform
import random
import subprocess
import sys
import tempfile
import time


def scenario(r, exponent):
    def ordinary():
        return r.uniform(-5, 5) if r.random() < 0.8 else float(r.randint(-3, 3))

    def far():
        return r.choice([1, -1]) * 2.0 ** r.randint(-exponent, exponent) * r.uniform(1, 1.9)

    def motion():
        return [[ordinary() for _ in range(r.randint(1, 3))] for _ in range(2)]

    n = r.randint(3, 20)
    objects = [{"id": i, "motion": motion()} for i in range(n)]
    timeline = [{"time": r.uniform(0, 10), "op": "query", "query": {"type": "closest_pair"}}
                for _ in range(3)]
    for _ in range(r.randint(0, 2)):
        timeline.append({"time": r.uniform(0, 10), "op": "update", "id": r.randrange(n),
                         "motion": motion()})
    targets = objects + [e for e in timeline if e["op"] == "update"]
    for _ in range(r.randint(1, 4)):
        o = r.choice(targets)
        if r.random() < 0.25:
            o["origin"] = far()
        else:
            axis = r.choice(o["motion"])
            axis[r.randrange(len(axis))] = far()
    timeline.sort(key=lambda e: e["time"])
    s = {"format": "kinetic-scenario/1", "dimension": 2, "objects": objects,
         "timeline": timeline}
    if r.random() < 0.5:
        s["end_time"] = 10.0
    return s


def measure(kinetic, exponent, runs, seed, timeout, folder):
    r = random.Random(seed)
    seconds, refused, slowest = [], 0, None
    for i in range(runs):
        path = os.path.join(folder, f"e{exponent}_{i}.json")
        with open(path, "w") as f:
            json.dump(scenario(r, exponent), f)
        start = time.perf_counter()
        p = subprocess.run([kinetic, "run", path, "--structure", "delaunay", "--scheduler",
                            "exact"], capture_output=True, text=True, timeout=timeout)
        elapsed = time.perf_counter() - start
        if p.returncode == 2:
            refused += 1
            continue
        if p.returncode != 0:
            sys.exit(f"run {i} (E = {exponent}) failed with exit {p.returncode}: {p.stderr}")
        seconds.append(elapsed)
        if slowest is None or elapsed > slowest[0]:
            slowest = (elapsed, i)
    seconds.sort()
    mean = sum(seconds) / len(seconds)
    p99 = seconds[min(len(seconds) - 1, int(0.99 * len(seconds)))]
    return {"answered": len(seconds), "refused": refused, "mean": mean, "p99": p99,
            "max": seconds[-1], "slowest_run": slowest[1]}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--kinetic", default="build/release/kinetic", help="the kinetic program")
    ap.add_argument("--exponent", type=int, default=140, help="E: magnitudes 2^-E to 2^E")
    ap.add_argument("--runs", type=int, default=600)
    ap.add_argument("--seed", type=int, default=6)
    ap.add_argument("--timeout", type=float, default=120.0, help="seconds per run at most")
    ap.add_argument("--quick", action="store_true", help="100 runs")
    a = ap.parse_args()
    runs = 100 if a.quick else a.runs
    print(f"# exact_magnitudes: delaunay, exact scheduler, {runs} runs per row, seed {a.seed}, "
          f"{a.kinetic}; {platform.machine()}, {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory(prefix="kinetic_magnitudes_") as folder:
        base = measure(a.kinetic, 0, runs, a.seed, a.timeout, folder)
        far = measure(a.kinetic, a.exponent, runs, a.seed, a.timeout, folder)
    print(f"{'magnitudes':>16} {'answered':>8} {'refused':>7} {'mean s':>8} {'p99 s':>8} "
          f"{'max s':>8}")
    for name, m in ((f"ordinary (E=0)", base), (f"2^+-{a.exponent}", far)):
        print(f"{name:>16} {m['answered']:>8} {m['refused']:>7} {m['mean']:>8.3f} "
              f"{m['p99']:>8.3f} {m['max']:>8.3f}")
    print(f"ratio to ordinary: mean {far['mean'] / base['mean']:.2f}x, "
          f"p99 {far['p99'] / base['p99']:.2f}x, max {far['max'] / base['max']:.2f}x "
          f"(slowest: run {far['slowest_run']} of E = {a.exponent})")


if __name__ == "__main__":
    main()
