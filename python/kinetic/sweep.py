"""Sweeps: many kinetic runs, each a task on Dask distributed, written as rows as they complete;
resumable (a run is keyed by its parameters, and a run already written is not run again) and
fault-tolerant (a run whose worker dies is run again elsewhere; a run that fails is a row with
its error). See docs/scale-out.md.

A run is a dict of parameters:

- the scenario: ``scenario`` (a kinetic-scenario/1 file), or ``dataset`` with the generator's
  parameters (``n``, ``seed``, ``dimension``, ``degree``, ``start``, ``end``, ``queries``,
  ``query_type``, ``updates``, ``inserts``, ``removes``, ``scale``; as ``kinetic.generate``);
- ``structure`` (as ``kinetic run --structure``), ``scheduler`` (optional: the structure's
  default), ``eps`` (default 1e-9), ``measure_delays`` (robust: every event's delay measured,
  in the stats), ``time_limit`` (seconds: a run that takes longer is a failed row).

Its row: ``key`` (of the parameters), ``run`` (the parameters), ``status`` ("ok" or "error"),
``outcome``, ``message``, ``stats`` (as ``kinetic run --stats`` without its timings),
``answers_digest`` (SHA-256 of the answers, one canonical JSON line each), ``answer_count``,
``answers`` (only when asked), ``error`` (for a failed run) and ``wall_s`` (the run's time on its
worker: the one field that differs between two sweeps of the same runs).
"""

import hashlib
import itertools
import json
import os
import sys
import time
import types

#: The fields of a run's parameters, besides ``structure``.
SCENARIO_FIELDS = ("scenario", "dataset")
GENERATOR_FIELDS = (
    "n", "seed", "dimension", "degree", "start", "end", "queries", "query_type", "updates",
    "inserts", "removes", "scale",
)
RUN_FIELDS = ("structure", "scheduler", "eps", "measure_delays", "time_limit")
#: The stats that measure time, left out of a row's stats (they are not the run's result).
TIMING_STATS = ("wall_time_s", "events_per_second", "time_per_event_us")


def grid(**axes):
    """Every combination of the axes' values (a list or tuple is an axis; any other value is
    the same in every run), as run dicts, in a fixed order (axes by name, values as given)."""
    names = sorted(axes)
    values = [axes[a] if isinstance(axes[a], (list, tuple)) else [axes[a]] for a in names]
    return [dict(zip(names, combo)) for combo in itertools.product(*values)]


def runs_from_spec(spec):
    """The runs of a sweep specification: a dict with ``runs`` (a list of run dicts) and/or
    ``grid`` (axes, as grid()), the runs of the grid after the listed ones."""
    if not isinstance(spec, dict) or not ({"runs", "grid"} & set(spec)):
        raise ValueError('sweep: a specification is an object with "runs" and/or "grid"')
    unknown = set(spec) - {"runs", "grid"}
    if unknown:
        raise ValueError("sweep: unknown field(s) %s in the specification" % ", ".join(sorted(unknown)))
    runs = list(spec.get("runs", []))
    if "grid" in spec:
        runs += grid(**spec["grid"])
    for i, run in enumerate(runs):
        check_run(run, "run %d" % i)
    return runs


def check_run(run, where="run"):
    """Raises ValueError naming the run and the field unless the run's parameters are complete
    and known."""
    if not isinstance(run, dict):
        raise ValueError("sweep: %s is not an object" % where)
    known = set(SCENARIO_FIELDS) | set(GENERATOR_FIELDS) | set(RUN_FIELDS)
    unknown = set(run) - known
    if unknown:
        raise ValueError("sweep: %s: unknown field(s) %s" % (where, ", ".join(sorted(unknown))))
    if "structure" not in run:
        raise ValueError('sweep: %s: no "structure"' % where)
    if ("scenario" in run) == ("dataset" in run):
        raise ValueError('sweep: %s: give "scenario" (a file) or "dataset", not both or neither' % where)
    if "scenario" in run and set(run) & set(GENERATOR_FIELDS):
        raise ValueError("sweep: %s: generator fields with a scenario file" % where)
    if "dataset" in run and "n" not in run:
        raise ValueError('sweep: %s: a generated scenario needs "n"' % where)


def key_of(run):
    """A run's key: SHA-256 of its parameters as canonical JSON (sorted keys), 16 hex digits."""
    text = json.dumps(run, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def execute(run, answers=False):
    """One run, as its row (see the module's documentation). Never raises for a failed run: the
    row says status "error" and the error."""
    from . import _kinetic

    row = {"key": key_of(run), "run": run}
    start = time.perf_counter()
    try:
        check_run(run)
        if "scenario" in run:
            scenario = _kinetic.load_scenario(run["scenario"])
        else:
            options = {k: run[k] for k in GENERATOR_FIELDS if k in run}
            scenario = _kinetic.generate(run["dataset"], **options)
        result = _kinetic.run(
            scenario, run["structure"], scheduler=run.get("scheduler"), eps=run.get("eps", 1e-9),
            measure_delays=bool(run.get("measure_delays", False)),
            time_limit=run.get("time_limit"),
        )
        lines = [json.dumps(a, sort_keys=True, separators=(",", ":")) for a in result["answers"]]
        row.update(
            status="ok",
            outcome=result["outcome"],
            message=result["message"],
            stats={k: v for k, v in result["stats"].items() if k not in TIMING_STATS},
            answers_digest=hashlib.sha256("\n".join(lines).encode()).hexdigest(),
            answer_count=len(lines),
        )
        if answers:
            row["answers"] = result["answers"]
    except Exception as e:  # noqa: BLE001: a failed run is a row, the sweep goes on
        row.update(status="error", error="%s: %s" % (type(e).__name__, e))
    row["wall_s"] = time.perf_counter() - start
    return row


def read_rows(path):
    """The rows written to ``path`` (JSON lines) by key; a last line cut short (the writer
    stopped mid-line) is not a row."""
    rows = {}
    if not os.path.exists(path):
        return rows
    with open(path, encoding="utf-8") as f:
        for line in f:
            if not line.endswith("\n"):
                break
            row = json.loads(line)
            rows[row["key"]] = row
    return rows


def _open_for_append(path):
    # A line cut short by a stopped writer is dropped, so the next row starts a line.
    if os.path.exists(path):
        with open(path, "rb+") as f:
            data = f.read()
            keep = data.rfind(b"\n") + 1
            if keep != len(data):
                f.truncate(keep)
    return open(path, "a", encoding="utf-8")


def sweep(runs, out, *, workers=None, address=None, client=None, answers=False, progress=True,
          on_row=None, chunk=None):
    """Runs every run not yet written to ``out`` (JSON lines, appended as runs complete) as a
    task on Dask distributed, and returns the rows of all the runs (those written before
    included), in the runs' order.

    The cluster: ``client`` (a ``distributed.Client``) when given; else the scheduler at
    ``address``; else a local cluster of ``workers`` worker processes (default: one per core),
    started and stopped here. A run whose worker dies is run again on another (Dask's retries of
    lost tasks; after three losses it is a row with the error); a run that fails is a row with
    its error. Each run is written once, by this process. ``on_row(row)`` is called after each
    row is written; ``progress`` draws a bar and a count on standard error. ``chunk``: runs per task
    (default: 1, or more when there are over 16 runs per worker thread, up to 64: Dask's cost
    per task is milliseconds, a short run's microseconds)."""
    runs = list(runs)
    for i, run in enumerate(runs):
        check_run(run, "run %d" % i)
    order = []
    by_key = {}
    for run in runs:
        k = key_of(run)
        if k not in by_key:
            by_key[k] = run
            order.append(k)
    done = read_rows(out)
    todo = [k for k in order if k not in done]
    if todo:
        own = []
        try:
            if client is None:
                from distributed import Client, LocalCluster

                if address is not None:
                    client = Client(address)
                    own.append(client)
                else:
                    cluster = LocalCluster(
                        n_workers=workers or os.cpu_count() or 1,
                        threads_per_worker=1,
                        processes=True,
                        dashboard_address=None,
                    )
                    own.append(cluster)
                    client = Client(cluster)
                    own.append(client)
            _run_all(client, [by_key[k] for k in todo], out, answers, progress, on_row, done,
                     chunk)
        finally:
            for thing in reversed(own):
                thing.close()
    return [done[k] for k in order]


def execute_many(runs, answers=False):
    """execute() of each run, in order: one task of a sweep."""
    return [execute(run, answers) for run in runs]


def _run_all(client, runs, out, answers, progress, on_row, done, chunk):
    from distributed import as_completed

    # Many short runs go several to a task (Dask's cost per task is milliseconds): a chunk when
    # there are more than 16 runs per worker thread, so that the threads stay evenly busy.
    threads = max(1, sum(client.nthreads().values()))
    size = chunk if chunk is not None else max(1, min(64, len(runs) // (16 * threads)))
    chunks = [runs[i:i + size] for i in range(0, len(runs), size)]
    # One batch of submissions, and the results fetched as they complete, in batches of those
    # completed meanwhile: a round trip per batch, not per run.
    keys = ["kinetic-runs-" + key_of([key_of(run) for run in c]) for c in chunks]
    futures = client.map(execute_many, chunks, [answers] * len(chunks), key=keys, pure=False)
    chunk_of = dict(zip(keys, chunks))
    errors = count = 0
    completed = as_completed(futures, with_results=True, raise_errors=False)
    with _open_for_append(out) as f:
        for batch in completed.batches():
            for future, result in batch:
                if isinstance(result, BaseException):  # e.g. KilledWorker: a task lost 3 times
                    result = [{"key": key_of(run), "run": run, "status": "error",
                               "error": "%s: %s" % (type(result).__name__, result), "wall_s": 0.0}
                              for run in chunk_of[future.key]]
                for row in result:
                    _write(f, row, done, on_row)
                    count += 1
                    errors += row["status"] != "ok"
                if progress:
                    filled = 30 * count // len(runs)
                    sys.stderr.write("\rsweep [%s%s] %d/%d runs written, %d failed"
                                     % ("#" * filled, "." * (30 - filled), count, len(runs), errors))
                    sys.stderr.flush()
    if progress:
        sys.stderr.write("\n")


def _write(f, row, done, on_row):
    f.write(json.dumps(row, sort_keys=True) + "\n")
    f.flush()
    done[row["key"]] = row
    if on_row is not None:
        on_row(row)


def main(argv=None):
    """``python -m kinetic sweep SPEC --out ROWS.jsonl [--workers N | --address A] [--answers]``."""
    import argparse

    parser = argparse.ArgumentParser(prog="python -m kinetic sweep",
                                     description="Run a sweep of kinetic runs on Dask distributed.")
    parser.add_argument("spec", help='a JSON file: {"runs": [...]} and/or {"grid": {...}}')
    parser.add_argument("--out", required=True, help="rows as JSON lines (appended; resumed)")
    parser.add_argument("--workers", type=int, help="local worker processes (default: one per core)")
    parser.add_argument("--address", help="an existing Dask scheduler, e.g. tcp://host:8786")
    parser.add_argument("--answers", action="store_true", help="the answers in every row")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    args = parser.parse_args(argv)
    try:
        with open(args.spec, encoding="utf-8") as f:
            runs = runs_from_spec(json.load(f))
    except (OSError, ValueError) as e:
        sys.stderr.write("sweep: %s: %s\n" % (args.spec, e))
        return 2
    rows = sweep(runs, args.out, workers=args.workers, address=args.address, answers=args.answers,
                 progress=not args.quiet)
    failed = sum(r["status"] != "ok" for r in rows)
    sys.stderr.write("sweep: %d runs in %s, %d failed\n" % (len(rows), args.out, failed))
    return 1 if failed else 0


class _CallableModule(types.ModuleType):
    """``kinetic.sweep(runs, out, ...)`` is ``kinetic.sweep.sweep(runs, out, ...)`` (the
    module's helpers stay its attributes: ``kinetic.sweep.grid``, ``kinetic.sweep.execute``)."""

    def __call__(self, *args, **kwargs):
        return sweep(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
