"""kinetic: kinetic data structures over moving objects, from Python.

One class per structure (``Sort``, ``Tournament``, ``Extent``, ``KdTree``, ``RangeTree``,
``LongestSideKdTree``, ``SegmentTree``, ``Hull``, ``Delaunay``, ``ClosestPair``, ``Bvh``,
``SweepAndPrune``: ``CLASSES`` has every one, by its command-line name) over numpy arrays of
motion coefficients; scenarios (``generate``, ``load_scenario``, ``Scenario``), the runner
(``run``) and the paper's experiments (``experiment_sorting``, ``experiment_tournament``). See
docs/python.md.
"""

from . import _kinetic
from . import sweep  # noqa: F401  (kinetic.sweep(runs, out, ...): many runs on Dask distributed)
from ._kinetic import (  # noqa: F401
    PreconditionError,
    Scenario,
    ScenarioError,
    SessionError,
    UsageError,
    __version__,
    datasets,
    experiment_sorting,
    experiment_tournament,
    generate,
    load_scenario,
    run,
    structures,
)

#: The class of each structure, by its command-line name (``kinetic run --structure NAME``), in
#: the order ``structures()`` lists them: the library's one list of structures names them.
CLASSES = {s["name"]: getattr(_kinetic, s["python_class"]) for s in structures()}
globals().update({cls.__name__: cls for cls in CLASSES.values()})


def session(scenario, structure, **options):
    """A session of the structure named ``structure`` over the scenario's objects at its start
    time (its timeline is not applied: drive the session yourself). ``options`` go to the class
    (``scheduler``, ``eps``, ``horizon``; ``axis`` for Sort and Tournament)."""
    if structure not in CLASSES:
        raise UsageError('session: no structure "%s" (built: %s)' % (structure, ", ".join(CLASSES)))
    cls = CLASSES[structure]
    wants = {s["name"]: s["objects"] for s in structures()}[structure]
    if wants != scenario.objects:
        raise UsageError(
            "session: %s takes %s; the scenario's objects are %s" % (structure, wants, scenario.objects)
        )
    kwargs = dict(ids=scenario.ids, origins=scenario.origins, start=scenario.start_time)
    kwargs.update(options)
    if scenario.objects == "boxes":
        return cls(scenario.motions, scenario.half_extents, **kwargs)
    return cls(scenario.motions, **kwargs)


__all__ = [name for name in dir() if not name.startswith("_")]
