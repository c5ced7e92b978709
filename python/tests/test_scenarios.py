"""Scenarios from Python: generation, JSON round trips, the runner, the registry's list, sessions
from scenarios, and the paper's experiments on a small size."""

import json

import numpy as np
import pytest

import kinetic
from conftest import exact_positions


def test_generate_is_deterministic_and_round_trips(tmp_path):
    a = kinetic.generate("random-linear", n=40, seed=5, dimension=2, queries=3,
                         query_type="range", updates=2, inserts=2, removes=1)
    b = kinetic.generate("random-linear", n=40, seed=5, dimension=2, queries=3,
                         query_type="range", updates=2, inserts=2, removes=1)
    assert a == b and a.to_json() == b.to_json()
    path = tmp_path / "s.json"
    a.save(str(path))
    c = kinetic.load_scenario(str(path))
    assert c == a
    assert kinetic.Scenario.from_json(a.to_json()) == a
    assert kinetic.Scenario.from_json(json.dumps(a.to_dict())) == a
    assert len(a) == 40 and a.dimension == 2 and a.objects == "points"
    assert a.motions.shape == (40, 2, 2) and a.ids.tolist() == list(range(40))
    ops = [op["op"] for op in a.timeline]
    assert ops.count("query") == 3 and ops.count("update") == 2 and ops.count("remove") == 1
    assert a != kinetic.generate("random-linear", n=40, seed=6, dimension=2)


@pytest.mark.parametrize("dataset", ["grids", "parabola", "randdc", "boxes-linear", "circle"])
def test_datasets(dataset):
    s = kinetic.generate(dataset, n=25, seed=3)
    assert len(s) == 25
    if dataset.startswith("boxes"):
        assert s.objects == "boxes" and s.half_extents.shape == (25, s.dimension)
    else:
        assert s.half_extents is None


def test_run_answers_match_a_session():
    sc = kinetic.generate("random-linear", n=60, seed=9, dimension=2, queries=5,
                          query_type="range")
    result = kinetic.run(sc, "kdtree", events=True)
    assert result["outcome"] == "completed"
    assert len(result["answers"]) == 5
    assert len(result["events"]) == result["stats"]["events"]["external"] > 0
    assert all(e["kind"] and e["ids"] for e in result["events"])
    s = kinetic.session(sc, "kdtree")
    for op, answer in zip([o for o in sc.timeline if o["op"] == "query"], result["answers"]):
        s.advance(op["time"])
        assert s.range(np.array(op["query"]["box"])).tolist() == answer["result"]
        assert answer["time"] == op["time"]


def test_run_without_a_scheduler_takes_the_structures_default():
    """Robust where the structure takes the scenario under it; the Delaunay triangulation takes
    points on lines only under robust, so a scenario with a parabola runs under exact (never a
    refusal for a missing option), with exact's answers; asked for, robust refuses it."""
    sc = kinetic.generate("random-linear", n=12, seed=4, dimension=2, queries=3,
                          query_type="delaunay")
    assert kinetic.run(sc, "delaunay")["stats"]["scheduler"] == "robust"
    d = sc.to_dict()
    d["objects"][2]["motion"][1] = [0.0, 1.0, 0.5]
    parabola = kinetic.Scenario.from_dict(d)
    by_default = kinetic.run(parabola, "delaunay")
    assert by_default["stats"]["scheduler"] == "exact"
    exact = kinetic.run(parabola, "delaunay", scheduler="exact")
    assert by_default["answers"] == exact["answers"] and len(exact["answers"]) == 3
    with pytest.raises(ValueError, match="degree <= 1 under --scheduler robust"):
        kinetic.run(parabola, "delaunay", scheduler="robust")


def interval_scenario(n, seed, queries):
    """Moving intervals [x(t), x(t) + w] (never inside out), with stabbing queries."""
    rng = np.random.default_rng(seed)
    objects = []
    for i in range(n):
        x0, v, w = rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(0, 0.5)
        objects.append({"id": i, "motion": [[x0, v], [x0 + w, v]]})
    timeline = [{"time": 10.0 * (k + 1) / (queries + 1), "op": "query",
                 "query": {"type": "stab", "x": float(rng.uniform(-2, 2))}}
                for k in range(queries)]
    return kinetic.Scenario.from_dict({
        "format": "kinetic-scenario/1", "dimension": 2, "objects_are": "intervals",
        "start_time": 0.0, "end_time": 10.0, "objects": objects, "timeline": timeline})


def test_run_writes_a_trace(tmp_path):
    sc = kinetic.generate("random-linear", n=20, seed=3, dimension=2, queries=2,
                          query_type="range")
    path = tmp_path / "run.trace"
    result = kinetic.run(sc, "kdtree", trace=str(path))
    lines = [json.loads(line) for line in path.read_text().splitlines()]
    assert lines[0]["format"] == "kinetic-trace/2" and lines[0]["structure"] == "kdtree"
    assert kinetic.Scenario.from_dict(lines[0]["scenario"]) == sc
    assert [l["result"] for l in lines if l.get("k") == "query"] == [a["result"] for a in result["answers"]]
    assert lines[-1]["k"] == "end" and lines[-1]["events"]["processed"] == result["stats"]["events"]["processed"]
    with pytest.raises(kinetic.PreconditionError, match="cannot write the trace"):
        kinetic.run(sc, "kdtree", trace=str(tmp_path / "no" / "dir" / "x.trace"))


def test_run_every_structure():
    for info in kinetic.structures():
        name = info["name"]
        query = info["queries"][0]
        if info["objects"] == "boxes":
            sc = kinetic.generate("boxes-linear", n=30, seed=2, queries=2, query_type=query)
        elif info["objects"] == "intervals":
            sc = interval_scenario(30, 2, 2)
        else:
            d = max(info["min_dimension"], 2 if query not in ("sorted", "max", "min") else 1)
            d = min(d, info["max_dimension"])
            sc = kinetic.generate("random-linear", n=30, seed=2, dimension=d, queries=2,
                                  query_type=query)
        scheduler = "robust" if "robust" in info["schedulers"] else info["schedulers"][0]
        result = kinetic.run(sc, name, scheduler=scheduler, validate=True)
        assert result["outcome"] == "completed", (name, result["message"])
        assert len(result["answers"]) == 2
        assert result["stats"]["structure"] == name
        assert name in kinetic.CLASSES


def test_run_intervals_matches_a_session():
    sc = interval_scenario(40, 5, 6)
    result = kinetic.run(sc, "segment-tree")
    s = kinetic.session(sc, "segment-tree")
    for op, answer in zip(sc.timeline, result["answers"]):
        s.advance(op["time"])
        assert s.stab(op["query"]["x"]).tolist() == answer["result"]
    with pytest.raises(kinetic.UsageError, match="takes points"):
        kinetic.session(sc, "kdtree")
    with pytest.raises(kinetic.UsageError, match="no structure"):
        kinetic.session(sc, "quadtree")


def test_session_from_scenario_positions():
    sc = kinetic.generate("random-poly", n=20, seed=4, dimension=3, degree=3)
    s = kinetic.session(sc, "kdtree", scheduler="exact")
    t = 0.37
    s.advance(sc.start_time + t)
    x = exact_positions(sc.motions, sc.origins, sc.start_time + t)
    assert np.allclose(s.positions(), np.array([[float(v) for v in p] for p in x]))


def test_structures_list():
    names = [s["name"] for s in kinetic.structures()]
    assert names == list(kinetic.CLASSES) or sorted(names) == sorted(kinetic.CLASSES)
    for s in kinetic.structures():
        assert s["queries"] and s["description"] and s["schedulers"]


def test_experiments_small():
    e = kinetic.experiment_sorting(datasets=["grids"], n=49, eps=[1e-6], bins=50)
    assert "Table 1" in e["report"]
    schedulers = [r["scheduler"] for r in e["runs"]]
    assert schedulers.count("robust") == 1 and "classic" in schedulers and "exact" in schedulers
    robust = [r for r in e["runs"] if r["scheduler"] == "robust"][0]
    assert robust["theorem1_violations"] == 0 and robust["theorem2_holds"]
    assert robust["envelope"].shape == (50,)
    exact = [r for r in e["runs"] if r["scheduler"] == "exact"][0]
    assert exact["err_max"] == 0.0 and exact["final_inversions"] == 0
    t = kinetic.experiment_tournament(n=200, eps=[1e-3], bins=20)
    robust = [r for r in t["runs"] if r["scheduler"] == "robust"][0]
    assert robust["theorem7_violations"] == 0
    assert "classic" in [r["scheduler"] for r in t["runs"]]
    exact = [r for r in t["runs"] if r["scheduler"] == "exact"][0]
    assert exact["wrong_fraction"] == 0.0 and exact["err_max"] < 1e-14
    no_exact = kinetic.experiment_tournament(n=200, eps=[1e-3], bins=20, exact=False)
    assert "exact" not in [r["scheduler"] for r in no_exact["runs"]]
