"""Every error path raises a Python exception carrying the library's message; nothing crashes
the interpreter, and a refused call leaves the session as it was."""

import math

import numpy as np
import pytest

import kinetic


def line_motions(n=5, d=2):
    m = np.zeros((n, d, 2))
    m[:, :, 0] = np.arange(n)[:, None]
    m[:, :, 1] = 1.0
    return m


@pytest.mark.parametrize(
    "motions,match",
    [
        (np.zeros((3,)), "expected \\(n, d, k\\)"),
        (np.zeros((3, 2, 2, 2)), "expected \\(n, d, k\\)"),
        (np.zeros((3, 2, 0)), "empty"),
        (np.zeros((3, 2, 9)) + 1.0, "degree"),
        (np.full((3, 2, 2), np.nan), "not finite"),
        (np.full((3, 2, 2), np.inf), "not finite"),
        ("abc", "not an array of numbers"),
        ([[["x"]]], "not an array of numbers"),
    ],
)
def test_bad_motions(motions, match):
    with pytest.raises(kinetic.PreconditionError, match=match):
        kinetic.KdTree(motions)


def test_errors_are_value_errors_with_the_place():
    with pytest.raises(ValueError) as e:
        kinetic.KdTree(np.full((3, 2, 2), np.nan))
    assert str(e.value).startswith("KdTree: object 0 (id 0) coordinate 0")


def test_bad_ids_origins_options():
    m = line_motions()
    with pytest.raises(kinetic.PreconditionError, match="ids must be"):
        kinetic.KdTree(m, ids=[1, 2])
    with pytest.raises(kinetic.PreconditionError, match="present already"):
        kinetic.KdTree(m, ids=[1, 2, 3, 3, 4])
    with pytest.raises(kinetic.PreconditionError, match="origins"):
        kinetic.KdTree(m, origins=[0.0, 1.0])
    with pytest.raises(kinetic.PreconditionError, match="not finite"):
        kinetic.KdTree(m, origins=math.nan)
    with pytest.raises(kinetic.PreconditionError, match="scheduler \"fast\""):
        kinetic.KdTree(m, scheduler="fast")
    with pytest.raises(kinetic.PreconditionError, match="eps"):
        kinetic.KdTree(m, eps=0.0)
    with pytest.raises(kinetic.PreconditionError, match="eps"):
        kinetic.KdTree(m, eps=math.nan)
    with pytest.raises(kinetic.PreconditionError, match="horizon"):
        kinetic.KdTree(m, start=1.0, horizon=0.5)
    with pytest.raises(kinetic.PreconditionError, match="start time"):
        kinetic.KdTree(m, start=math.inf)
    with pytest.raises(kinetic.PreconditionError, match="ids must be"):
        kinetic.KdTree(m, ids=["a", "b", "c", "d", "e"])
    with pytest.raises(kinetic.PreconditionError, match="dtype float64"):
        kinetic.KdTree(m, ids=[0.5, 1.7, 2.2, 3.0, 4.0])
    with pytest.raises(kinetic.PreconditionError, match="dtype float64"):
        kinetic.KdTree(m, ids=np.array([np.nan, 1, 2, 3, 4]))
    with pytest.raises(kinetic.PreconditionError, match="beyond the 64-bit"):
        kinetic.KdTree(m, ids=np.array([2**63, 1, 2, 3, 4], dtype=np.uint64))
    big = kinetic.KdTree(m, ids=np.array([2**63 - 1, 1, 2, 3, 4], dtype=np.uint64))
    assert (2**63 - 1) in big and 2**70 not in big and "x" not in big and 0 not in big
    with pytest.raises(kinetic.PreconditionError, match="coordinates"):
        kinetic.KdTree(np.zeros((0, 2**32 + 1, 1)))
    with pytest.raises(kinetic.PreconditionError, match="coordinates"):
        kinetic.Bvh(np.zeros((0, 2**30, 1)), np.zeros((0, 2**30)))


def test_structure_refusals():
    with pytest.raises(kinetic.PreconditionError, match="plane"):
        kinetic.LongestSideKdTree(np.zeros((3, 3, 2)))
    with pytest.raises(kinetic.PreconditionError, match="axis"):
        kinetic.Sort(np.zeros((3, 1, 2)), axis=2)
    with pytest.raises(kinetic.PreconditionError, match="extreme"):
        kinetic.Tournament(np.zeros((3, 1, 2)), extreme="median")
    with pytest.raises(kinetic.PreconditionError, match="inside out"):
        m = np.zeros((2, 2, 2))
        m[:, 0, 0] = 0.0
        m[:, 1, 0] = 1.0
        m[:, 1, 1] = -2.0  # the right end passes the left at t = 0.5
        kinetic.SegmentTree(m).advance(1.0)
    with pytest.raises(kinetic.PreconditionError):
        kinetic.Delaunay(line_motions(), scheduler="classic")
    with pytest.raises(kinetic.PreconditionError, match="degree"):
        kinetic.Hull(np.ones((4, 2, 6)))
    with pytest.raises(kinetic.PreconditionError, match="half_extents"):
        kinetic.Bvh(line_motions(), np.ones((5, 3)))
    with pytest.raises(kinetic.PreconditionError, match="half extent"):
        kinetic.SweepAndPrune(line_motions(), -np.ones((5, 2)))


def test_session_misuse_leaves_it_usable():
    s = kinetic.KdTree(line_motions())
    s.advance(2.0)
    before = s.positions().copy()
    with pytest.raises(kinetic.PreconditionError, match="finite time"):
        s.advance(math.inf)
    with pytest.raises(kinetic.PreconditionError, match="finite time"):
        s.at(math.inf)
    with pytest.raises(kinetic.PreconditionError, match="before the session's time"):
        s.advance(1.0)
    with pytest.raises(kinetic.PreconditionError):
        s.advance(math.nan)
    with pytest.raises(kinetic.PreconditionError, match="no object with id 77"):
        s.update(77, np.zeros((2, 2)))
    with pytest.raises(kinetic.PreconditionError, match="no object with id 77"):
        s.remove(77)
    with pytest.raises(kinetic.PreconditionError, match="no object with id 77"):
        s.position(77)
    with pytest.raises(kinetic.PreconditionError, match="present already"):
        s.insert(1, np.zeros((2, 2)))
    with pytest.raises(kinetic.PreconditionError, match="expected \\(2, k\\)"):
        s.insert(9, np.zeros((3, 2)))
    with pytest.raises(kinetic.PreconditionError, match="not finite"):
        s.update(1, [[math.nan, 0.0], [0.0, 0.0]])
    with pytest.raises(kinetic.PreconditionError, match="box has shape"):
        s.range([[0, 1]])
    with pytest.raises(kinetic.PreconditionError, match="box"):
        s.range([[0, math.nan], [0, 1]])
    with pytest.raises(kinetic.PreconditionError, match="boxes have shape"):
        s.range_many(np.zeros((2, 3, 2)))
    assert s.now == 2.0 and len(s) == 5 and s.validate()
    assert np.array_equal(s.positions(), before) and s.ids().tolist() == [0, 1, 2, 3, 4]
    assert s.range([[-10, 10], [-10, 10]]).tolist() == [0, 1, 2, 3, 4]


def test_query_argument_errors():
    m = line_motions()
    lst = kinetic.LongestSideKdTree(m)
    with pytest.raises(kinetic.PreconditionError, match="point has shape"):
        lst.nearest([1.0, 2.0, 3.0])
    with pytest.raises(kinetic.PreconditionError):
        lst.nearest([1.0, math.inf])
    with pytest.raises(kinetic.PreconditionError):
        lst.farthest([1.0, 2.0], -0.5)
    with pytest.raises(kinetic.PreconditionError, match="one of disk"):
        lst.approx_range(0.1)
    with pytest.raises(kinetic.PreconditionError, match="one of disk"):
        lst.approx_range(0.1, disk=([0, 0], 1.0), polygon=[[0, 0], [1, 0], [0, 1]])
    with pytest.raises(kinetic.PreconditionError):
        lst.approx_range(0.1, disk=([0, 0], -1.0))
    with pytest.raises(kinetic.PreconditionError):
        lst.approx_range(0.1, polygon=[[0, 0], [1, 0]])
    with pytest.raises(kinetic.PreconditionError, match="radius"):
        lst.approx_range(0.1, disk=((0, 0), "x"))
    with pytest.raises(kinetic.PreconditionError, match="disk is"):
        lst.approx_range(0.1, disk=np.zeros(3))
    assert lst.approx_range(0.1, disk=np.array([np.array([0.0, 0.0]), 100.0], dtype=object)).size == 5
    with pytest.raises(kinetic.PreconditionError, match="eps"):
        lst.nearest([0.0, 0.0], -1.0)
    with pytest.raises(kinetic.PreconditionError, match="no object"):
        kinetic.LongestSideKdTree(np.zeros((0, 2, 2)))._seconds_per_nearest([0.0, 0.0], 0.0, 3)
    dt = kinetic.Delaunay(np.random.default_rng(3).uniform(-1, 1, size=(6, 2, 2)))
    with pytest.raises(kinetic.PreconditionError, match="eps"):
        dt.nearest([0.0, 0.0], -0.5)
    with pytest.raises(kinetic.PreconditionError, match="points have shape"):
        lst.nearest_many(np.zeros((3, 3)))
    seg = kinetic.SegmentTree(np.array([[[0.0], [1.0]]]))
    with pytest.raises(kinetic.PreconditionError):
        seg.stab(math.nan)
    with pytest.raises(kinetic.PreconditionError, match="xs have shape"):
        seg.stab_many(np.zeros((2, 2)))
    extent = kinetic.Extent(line_motions())
    with pytest.raises(kinetic.PreconditionError, match="axis 2"):
        extent.max(2)
    assert kinetic.Extent(np.zeros((0, 2, 2))).max(0) is None
    assert kinetic.Extent(np.zeros((0, 2, 2))).extent().shape == (0, 2)
    empty = kinetic.LongestSideKdTree(np.zeros((0, 2, 2)))
    assert empty.nearest([0.0, 0.0]) is None
    with pytest.raises(kinetic.PreconditionError, match="no object"):
        empty.nearest_many(np.zeros((1, 2)))


def test_horizon_and_time_limit():
    s = kinetic.Sort(line_motions(3, 1), horizon=5.0)
    s.advance(5.0)
    with pytest.raises(kinetic.PreconditionError, match="horizon"):
        s.advance(6.0)
    r = kinetic.Sort(line_motions(3, 1), eps=1e-9)
    with pytest.raises(kinetic.PreconditionError):
        r.advance(1e7)  # beyond the robust scheduler's time limit at eps = 1e-9
    r.advance(1.0)


def test_experiment_arguments():
    with pytest.raises(kinetic.PreconditionError, match="n = 0"):
        kinetic.experiment_tournament(n=0, eps=[1e-3])
    with pytest.raises(kinetic.PreconditionError, match="n = 1"):
        kinetic.experiment_sorting(n=1)
    with pytest.raises(kinetic.PreconditionError, match="bins"):
        kinetic.experiment_sorting(n=16, bins=0)
    with pytest.raises(kinetic.PreconditionError, match="eps"):
        kinetic.experiment_tournament(n=16, eps=[0.0])
    with pytest.raises(kinetic.PreconditionError, match="eps"):
        kinetic.experiment_sorting(n=16, eps=[math.nan])
    with pytest.raises(ValueError, match="dataset"):
        kinetic.experiment_sorting(n=16, datasets=["nope"])


def test_scenario_errors(tmp_path):
    with pytest.raises(kinetic.ScenarioError):
        kinetic.Scenario.from_json("{")
    with pytest.raises(kinetic.ScenarioError):
        kinetic.Scenario.from_json('{"dimension": 1}')
    with pytest.raises(kinetic.ScenarioError):
        kinetic.load_scenario(str(tmp_path / "missing.json"))
    with pytest.raises(ValueError, match="dataset"):
        kinetic.generate("no-such-dataset", n=3)
    with pytest.raises(kinetic.PreconditionError, match="query type"):
        kinetic.generate("random-linear", n=3, query_type="median")
    sc = kinetic.generate("random-linear", n=10, queries=2, query_type="sorted")
    with pytest.raises(kinetic.UsageError):
        kinetic.run(sc, "no-such-structure")
    with pytest.raises(kinetic.UsageError):
        kinetic.run(sc, "kdtree")  # kd-trees do not answer 'sorted'
    with pytest.raises(kinetic.PreconditionError, match="scheduler"):
        kinetic.run(sc, "sort", scheduler="fast")
    with pytest.raises(kinetic.PreconditionError, match="cannot write"):
        sc.save(str(tmp_path / "no" / "such" / "dir.json"))
