"""``python -m kinetic sweep SPEC --out ROWS.jsonl``: a sweep of runs on Dask distributed
(kinetic.sweep, docs/scale-out.md)."""

import sys

from . import sweep


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] != "sweep":
        sys.stderr.write("usage: python -m kinetic sweep SPEC --out ROWS.jsonl [--workers N | "
                         "--address A] [--answers] [--quiet]\n")
        return 2
    return sweep.main(argv[1:])


if __name__ == "__main__":
    sys.exit(main())
