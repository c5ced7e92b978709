"""Every structure's queries held against a brute force over exact positions (fractions), on
random and degenerate motions, at random query times and at the degenerate inputs' time of
simultaneous events. The exact scheduler must agree exactly; the robust one up to what its
guarantees allow (an object within V_max * eps of a decision boundary may be on either side)."""

from fractions import Fraction
import itertools
import math

import numpy as np
import pytest

import kinetic
from conftest import (
    DEGENERATE,
    convex_hull,
    cross,
    degenerate_motions,
    exact_squared_distance,
    incircle_after,
    orientation_after,
    taylor,
    exact_positions,
    in_box,
    near_box_side,
    query_times,
    random_motions,
    speed_bound,
    squared_distance,
)

SCHEDULERS = ["exact", "robust"]
EPS = 1e-9


def tolerance(scheduler, motions, factor=64.0):
    return 0.0 if scheduler == "exact" else factor * EPS * max(1.0, speed_bound(motions))


def inputs(d, n=24):
    """(label, motions) for random linear and quadratic motions and every degenerate kind."""
    out = [("linear-%d" % s, random_motions(s, n, d, 2)) for s in (1, 2)]
    out += [("quadratic-%d" % s, random_motions(s, n, d, 3)) for s in (3,)]
    out += [(kind, degenerate_motions(7, n, d, kind)) for kind in DEGENERATE]
    return out


def random_box(rng, d):
    lo = rng.uniform(-1.2, 0.8, size=d)
    return np.stack([lo, lo + rng.uniform(0.1, 1.5, size=d)], axis=1)


@pytest.mark.parametrize("scheduler", SCHEDULERS)
@pytest.mark.parametrize("label,motions", inputs(1, 30))
def test_sort(scheduler, label, motions):
    s = kinetic.Sort(motions, scheduler=scheduler)
    tol = tolerance(scheduler, motions)
    for t in query_times(11, 6):
        s.advance(t)
        order = s.sorted()
        assert sorted(order.tolist()) == list(range(len(motions)))
        x = exact_positions(motions, None, t)
        for a, b in zip(order[:-1], order[1:]):
            assert x[b][0] >= x[a][0] - Fraction(tol), (label, t, a, b)
    assert s.validate()


@pytest.mark.parametrize("scheduler", SCHEDULERS)
@pytest.mark.parametrize("label,motions", inputs(2, 30))
def test_tournament_and_extent(scheduler, label, motions):
    top = kinetic.Tournament(motions, axis=1, extreme="max", scheduler=scheduler)
    low = kinetic.Tournament(motions, axis=0, extreme="min", scheduler=scheduler)
    box = kinetic.Extent(motions, scheduler=scheduler)
    tol = Fraction(tolerance(scheduler, motions, factor=64.0 * 8))
    for t in query_times(12, 6):
        for s in (top, low, box):
            s.advance(t)
        x = exact_positions(motions, None, t)
        assert x[top.top()][1] >= max(p[1] for p in x) - tol
        assert x[low.top()][0] <= min(p[0] for p in x) + tol
        e = box.extent()
        assert e.shape == (2, 2)
        for axis in range(2):
            assert box.min(axis) == e[axis, 0] and box.max(axis) == e[axis, 1]
            assert x[e[axis, 0]][axis] <= min(p[axis] for p in x) + tol
            assert x[e[axis, 1]][axis] >= max(p[axis] for p in x) - tol


@pytest.mark.parametrize("scheduler", SCHEDULERS)
@pytest.mark.parametrize("cls,d", [(kinetic.KdTree, 1), (kinetic.KdTree, 2), (kinetic.KdTree, 3),
                                   (kinetic.RangeTree, 1), (kinetic.RangeTree, 2),
                                   (kinetic.RangeTree, 3), (kinetic.LongestSideKdTree, 2)])
def test_range(scheduler, cls, d):
    rng = np.random.default_rng(21 + d)
    for label, motions in inputs(d, 30):
        s = cls(motions, scheduler=scheduler)
        tol = tolerance(scheduler, motions)
        for t in query_times(13, 4):
            s.advance(t)
            x = exact_positions(motions, None, t)
            boxes = [random_box(rng, d) for _ in range(4)]
            boxes.append(np.array([[0.25, 0.25]] * d))  # the common point of 'common'
            batch = s.range_many(np.array(boxes))
            flat, offsets = s.range_many(np.array(boxes), flat=True)
            assert offsets[0] == 0 and offsets[-1] == len(flat) and len(offsets) == len(boxes) + 1
            for i, answer in enumerate(batch):
                assert flat[offsets[i]:offsets[i + 1]].tolist() == answer.tolist()
            for box, answer_many in zip(boxes, batch):
                answer = s.range(box)
                assert answer.tolist() == answer_many.tolist()
                assert answer.tolist() == sorted(answer.tolist())
                truth = {i for i, p in enumerate(x) if in_box(p, box)}
                for i in set(answer.tolist()) ^ truth:
                    assert tol > 0 and near_box_side(x[i], box, tol), (label, t, i, box)


@pytest.mark.parametrize("scheduler", SCHEDULERS)
def test_longest_side_nearest_farthest_approx(scheduler):
    rng = np.random.default_rng(31)
    for label, motions in inputs(2, 30):
        s = kinetic.LongestSideKdTree(motions, scheduler=scheduler)
        tol = Fraction(tolerance(scheduler, motions))
        for t in query_times(14, 4):
            s.advance(t)
            x = exact_positions(motions, None, t)
            for eps in (0.0, 0.1):
                q = rng.uniform(-1, 1, size=2)
                dist = [squared_distance(p, q) ** 0.5 for p in x]
                near = s.nearest(q, eps)
                far = s.farthest(q, eps)
                assert float(dist[near]) <= (1 + eps) * float(min(dist)) + float(tol) + 1e-12
                assert float(dist[far]) >= (1 - eps) * float(max(dist)) - float(tol) - 1e-12
                assert s.nearest_many(np.array([q]), eps).tolist() == [near]
                radius = rng.uniform(0.1, 0.8)
                got = set(s.approx_range(eps, disk=(q, radius)).tolist())
                for i, di in enumerate(dist):
                    if float(di) < radius - float(tol):
                        assert i in got, (label, t, i)
                    if i in got:
                        assert float(di) <= radius + eps * 2 * radius + float(tol) + 1e-12
                square = np.array([[q[0], q[1]], [q[0] + radius, q[1]],
                                   [q[0] + radius, q[1] + radius], [q[0], q[1] + radius]])
                got = set(s.approx_range(eps, polygon=square).tolist())
                box = [(q[0], q[0] + radius), (q[1], q[1] + radius)]
                for i, p in enumerate(x):
                    if in_box(p, box) and not near_box_side(p, box, float(tol)):
                        assert i in got


def interval_motions(motions):
    """Intervals [a(t), a(t) + w]: a the first coordinate's motion, w >= 0 constant."""
    n = len(motions)
    m = np.zeros((n, 2, motions.shape[2]))
    m[:, 0, :] = motions[:, 0, :]
    m[:, 1, :] = motions[:, 0, :]
    m[:, 1, 0] += np.abs(motions[:, 1, 0]) * 0.5 if motions.shape[1] > 1 else 0.25
    return m


@pytest.mark.parametrize("scheduler", SCHEDULERS)
def test_segment_tree_stab(scheduler):
    rng = np.random.default_rng(41)
    for label, motions in inputs(2, 30):
        m = interval_motions(motions)
        s = kinetic.SegmentTree(m, scheduler=scheduler)
        tol = tolerance(scheduler, m)
        for t in query_times(15, 4):
            s.advance(t)
            x = exact_positions(m, None, t)
            xs = list(rng.uniform(-1.5, 1.5, size=5)) + [0.25]
            flat, offsets = s.stab_many(np.array(xs), flat=True)
            for i, many in enumerate(s.stab_many(np.array(xs))):
                assert flat[offsets[i]:offsets[i + 1]].tolist() == many.tolist()
            for q, many in zip(xs, s.stab_many(np.array(xs))):
                got = s.stab(q)
                assert got.tolist() == many.tolist()
                truth = {i for i, (lo, hi) in enumerate(x) if lo <= Fraction(q) <= hi}
                for i in set(got.tolist()) ^ truth:
                    lo, hi = x[i]
                    assert tol > 0 and min(abs(float(lo) - q), abs(float(hi) - q)) <= tol


@pytest.mark.parametrize("scheduler", SCHEDULERS)
def test_hull(scheduler):
    for label, motions in inputs(2, 30):
        s = kinetic.Hull(motions, scheduler=scheduler)
        for t in query_times(16, 4):
            s.advance(t)
            x = exact_positions(motions, None, t)
            got = [x[i] for i in s.hull()]
            truth = convex_hull(x)
            if scheduler == "exact":
                assert got == truth, (label, t)
            else:
                # Robust: the hull can be off only by points nearly on it; every point must be
                # inside the maintained polygon up to the tolerance.
                tol = tolerance(scheduler, motions) * 8
                if len(truth) < 3 or len(got) < 3:
                    assert set(got) == set(truth), (label, t)
                    continue
                for p in x:  # every point inside the maintained polygon, up to tol
                    for a, b in zip(got, got[1:] + got[:1]):
                        length = float(squared_distance(a, [float(v) for v in b])) ** 0.5
                        assert float(cross(a, b, p)) >= -tol * max(1.0, length), (label, t)
                for v in got:  # every maintained vertex on the true hull's boundary, up to tol
                    depth = min(float(cross(a, b, v)) / max(1e-300, float(
                        squared_distance(a, [float(u) for u in b])) ** 0.5)
                        for a, b in zip(truth, truth[1:] + truth[:1]))
                    assert depth <= tol, (label, t)


def test_delaunay_and_closest_pair():
    for label, motions in inputs(2, 16):
        if motions.shape[2] > 3:
            continue
        dt = kinetic.Delaunay(motions, scheduler="exact")
        cp = kinetic.ClosestPair(motions, scheduler="exact")
        robust = kinetic.ClosestPair(motions)
        assert dt.scheduler == "exact" and cp.scheduler == "exact"
        assert robust.scheduler == "robust"
        # The robust closest pair's bound (docs/closest-pair.md): 24 rho beyond the closest,
        # rho <= 2 n eps V (Theorem 4 of Abam, Agarwal, de Berg, Yu), unless two points are
        # closer than 7 rho.
        rho = 2 * len(motions) * EPS * max(1.0, speed_bound(motions))
        for t in query_times(17, 3):
            dt.advance(t)
            cp.advance(t)
            robust.advance(t)
            x = exact_positions(motions, None, t)
            distinct = len(set(x))
            d2 = [(exact_squared_distance(x[i], x[j]), i, j)
                  for i, j in itertools.combinations(range(len(x)), 2)]
            best = min(d2)[0]
            q = [0.1, -0.2]
            near = dt.nearest(q)
            d_near = exact_squared_distance(x[near], (Fraction(0.1), Fraction(-0.2)))
            assert all(d_near <= exact_squared_distance(p, (Fraction(0.1), Fraction(-0.2)))
                       for p in x)
            for s in (dt, cp):
                a, b = s.closest_pair()
                assert a < b
                assert exact_squared_distance(x[a], x[b]) == best, (label, t)
            a, b = robust.closest_pair()
            assert a < b
            if float(best) ** 0.5 > 7 * rho:
                got = float(exact_squared_distance(x[a], x[b])) ** 0.5
                assert got <= float(best) ** 0.5 + 24 * rho + 1e-12, (label, t)
            tris = dt.delaunay()
            # The answer is the triangulation just after t (docs/delaunay.md): every triangle
            # counter-clockwise and no point inside a circumcircle, just after t.
            after = [[taylor(row, 0.0, t) for row in motions[i]] for i in range(len(motions))]
            for a, b, c in tris:
                assert orientation_after(after[a], after[b], after[c]) > 0, (label, t)
                for i in range(len(motions)):
                    assert incircle_after(after[a], after[b], after[c], after[i]) <= 0, (label, t)
            if distinct == len(x) and t != 0.5 and len(convex_hull(x)) >= 3:
                # A generic instant: the triangles tile the hull.
                hull = convex_hull(x)
                hull_area = sum(cross(hull[0], a, b) for a, b in zip(hull[1:], hull[2:]))
                area = sum(cross(x[a], x[b], x[c]) for a, b, c in tris)
                assert area == hull_area, (label, t)


def grid_point_before(t, eps=EPS):
    """The robust scheduler's grid point at or before t: (j + 1/2) w, w the largest power of two
    <= (sqrt(3) / 2) eps (docs/crop.md)."""
    w = 2.0 ** math.floor(math.log2(eps * 0.8660254037844386))
    g = (math.floor(t / w - 0.5) + 0.5) * w
    while g > t:
        g -= w
    while g + w <= t:
        g += w
    return g


def test_delaunay_robust_is_exact_at_the_grid_point_before_the_query():
    # Robust by default for points on lines: the triangles are the Delaunay triangulation just
    # after the grid point at or before the query (docs/delaunay.md, "Robust scheduling").
    for label, motions in inputs(2, 16):
        degree = max([j for j in range(motions.shape[2]) if np.any(motions[:, :, j] != 0)] + [0])
        if degree > 1:
            # Beyond lines the default is the exact scheduler (the one that takes parabolas), and
            # beyond parabolas the refusal names the degree.
            if degree == 2:
                assert kinetic.Delaunay(motions).scheduler == "exact", label
            else:
                with pytest.raises(kinetic.PreconditionError, match="degree <= 2"):
                    kinetic.Delaunay(motions)
            with pytest.raises(kinetic.PreconditionError, match="degree <= 1 under the robust"):
                kinetic.Delaunay(motions, scheduler="robust")
            continue
        dt = kinetic.Delaunay(motions)
        assert dt.scheduler == "robust"
        for t in query_times(19, 3):
            dt.advance(t)
            g = grid_point_before(t)
            after = [[taylor(row, 0.0, g) for row in motions[i]] for i in range(len(motions))]
            tris = dt.delaunay()
            for a, b, c in tris:
                assert orientation_after(after[a], after[b], after[c]) > 0, (label, t)
                for i in range(len(motions)):
                    assert incircle_after(after[a], after[b], after[c], after[i]) <= 0, (label, t)
            x = exact_positions(motions, None, g)
            if len(set(x)) == len(x) and len(convex_hull(x)) >= 3:
                hull = convex_hull(x)
                hull_area = sum(cross(hull[0], a, b) for a, b in zip(hull[1:], hull[2:]))
                area = sum(cross(x[a], x[b], x[c]) for a, b, c in tris)
                assert area == hull_area, (label, t)


@pytest.mark.parametrize("cls", [kinetic.Bvh, kinetic.FatBvh, kinetic.SweepAndPrune])
@pytest.mark.parametrize("scheduler", SCHEDULERS)
def test_colliding_pairs(cls, scheduler):
    rng = np.random.default_rng(51)
    for label, motions in inputs(2, 24):
        halves = rng.uniform(0.0, 0.3, size=(len(motions), 2))
        s = cls(motions, halves, scheduler=scheduler)
        tol = tolerance(scheduler, motions)
        for t in query_times(18, 4):
            s.advance(t)
            x = exact_positions(motions, None, t)
            truth = set()
            close = set()
            for i, j in itertools.combinations(range(len(x)), 2):
                gaps = [abs(x[i][a] - x[j][a]) - Fraction(halves[i][a]) - Fraction(halves[j][a])
                        for a in range(2)]
                if all(g <= 0 for g in gaps):
                    truth.add((i, j))
                if any(abs(float(g)) <= 2 * tol for g in gaps):
                    close.add((i, j))
            got = {tuple(p) for p in s.colliding_pairs().tolist()}
            assert all(i < j for i, j in got)
            assert (got ^ truth) <= close, (label, t)


@pytest.mark.parametrize("cls", [kinetic.Bvh, kinetic.FatBvh, kinetic.SweepAndPrune])
@pytest.mark.parametrize("scheduler", SCHEDULERS)
def test_contact_changes(cls, scheduler):
    """contact_changes() applied to the previous answer gives colliding_pairs(), at each call."""
    rng = np.random.default_rng(52)
    for label, motions in inputs(2, 24):
        halves = rng.uniform(0.0, 0.3, size=(len(motions), 2))
        s = cls(motions, halves, scheduler=scheduler)
        held = set()
        previous = None
        for t in query_times(18, 4):
            s.advance(t)
            c = s.contact_changes()
            begun = {tuple(p) for p in c["begun"].tolist()}
            ended = {tuple(p) for p in c["ended"].tolist()}
            touched = {tuple(p) for p in c["touched"].tolist()}
            now = {tuple(p) for p in s.colliding_pairs().tolist()}
            assert not begun & held and ended <= held, (label, t)
            assert (held - ended) | begun == now, (label, t)
            assert not touched & (held | now), (label, t)
            for name in ("begun", "ended", "touched"):
                times = c[name + "_times"]
                assert len(times) == len(c[name]), (label, t, name)
                lo = t if previous is None else previous
                assert all(lo <= x <= t for x in times), (label, t, name)
            held, previous = now, t


@pytest.mark.parametrize("seed", [61, 62])
def test_changes_against_brute_force(seed):
    """Long mixed sequences of inserts, updates and removes, with the table kept in Python."""
    rng = np.random.default_rng(seed)
    n, d = 20, 2
    motions = random_motions(seed, n, d, 2)
    table = {i: (motions[i], 0.0) for i in range(n)}
    kd = kinetic.KdTree(motions)
    srt = kinetic.Sort(motions)
    next_id = 1000
    t = 0.0
    for step in range(60):
        t += float(rng.uniform(0.0, 0.1))
        for s in (kd, srt):
            s.advance(t)
        op = rng.integers(0, 3)
        if op == 0 or len(table) < 5:
            m = rng.uniform(-1, 1, size=(d, 2))
            for s in (kd, srt):
                s.insert(next_id, m, origin=t)
            table[next_id] = (m, t)
            next_id += 1
        elif op == 1:
            victim = int(rng.choice(sorted(table)))
            m = rng.uniform(-1, 1, size=(d, 2))
            for s in (kd, srt):
                s.update(victim, m, origin=t)
            table[victim] = (m, t)
        else:
            victim = int(rng.choice(sorted(table)))
            for s in (kd, srt):
                s.remove(victim)
            del table[victim]
        ids = sorted(table)
        assert kd.ids().tolist() == ids and srt.ids().tolist() == ids
        x = {i: exact_positions(table[i][0][None], table[i][1], t)[0] for i in ids}
        for i in ids:
            assert np.allclose(kd.position(i), [float(v) for v in x[i]])
        box = random_box(rng, d)
        truth = sorted(i for i in ids if in_box(x[i], box))
        got = kd.range(box).tolist()
        tol = 1e-6
        for i in set(got) ^ set(truth):
            assert near_box_side(x[i], box, tol), (seed, step, i)
        order = srt.sorted()
        for a, b in zip(order[:-1], order[1:]):
            assert x[b][0] >= x[a][0] - Fraction(tol)
    assert kd.validate() and srt.validate()


def test_positions_and_ids():
    m = random_motions(3, 10, 3, 3)
    s = kinetic.KdTree(m, ids=np.arange(100, 110), origins=0.25)
    s.advance(0.75)
    assert s.ids().tolist() == list(range(100, 110))
    x = exact_positions(m, 0.25, 0.75)
    p = s.positions()
    assert p.shape == (10, 3)
    for row, truth in zip(p, x):
        assert row.tolist() == [float(v) for v in truth]
    assert 105 in s and 99 not in s and len(s) == 10
    assert s.dimension == 3 and s.now == 0.75 and s.scheduler == "robust"
    assert s.at(1.0) is s and s.now == 1.0
    c = s.counters()
    assert c["events"]["processed"] > 0 and "structure_counters" in c
    assert c["certificates"]["alive_end"] > 0


@pytest.mark.parametrize("scheduler", SCHEDULERS)
def test_k_nearest_exact_by_distance_then_id(scheduler):
    """k_nearest and k_nearest_many of the kd-tree (d = 1 to 3), the longest-side kd-tree and the
    Delaunay triangulation against exact squared distances (fractions), ties by id, on random and
    degenerate motions; k = 0, 1, 5 and more than n. The robust scheduler may differ only where
    a point's distance is within the tolerance of the k-th nearest."""
    rng = np.random.default_rng(47)
    cases = [(kinetic.KdTree, d) for d in (1, 2, 3)] + [(kinetic.LongestSideKdTree, 2)]
    if scheduler == "exact":
        cases.append((kinetic.Delaunay, 2))
    for cls, d in cases:
        for label, motions in inputs(d, 24):
            if cls is kinetic.Delaunay and motions.shape[2] > 3:
                continue
            s = cls(motions, scheduler=scheduler)
            tol = tolerance(scheduler, motions)
            for t in query_times(5, 3):
                s.advance(t)
                x = exact_positions(motions, None, t)
                points = np.round(rng.uniform(-1, 1, size=(3, d)) * 4) / 4  # ties on a lattice
                for k in (0, 1, 5, 40):
                    many = s.k_nearest_many(points, k)
                    assert many.shape == (3, min(k, len(x)))
                    for row, q in zip(many, points):
                        got = s.k_nearest(q, k).tolist()
                        assert got == row.tolist()
                        exact = [squared_distance(p, q) for p in x]
                        want = sorted(range(len(x)), key=lambda i: (exact[i], i))[:k]
                        if got == want or tol == 0.0:
                            assert got == want, (cls.__name__, label, t, k)
                            continue
                        # Robust: the same distances up to the tolerance, rank by rank.
                        for a, b in zip(got, want):
                            assert abs(float(exact[a]) ** 0.5 - float(exact[b]) ** 0.5) <= tol * d
    kd = kinetic.KdTree(random_motions(5, 10, 3, 2))
    assert kd.nearest(np.zeros(3)) == kd.k_nearest(np.zeros(3), 1)[0]
    assert kd.nearest_many(np.zeros((2, 3))).tolist() == [kd.nearest(np.zeros(3))] * 2
    with pytest.raises(kinetic.PreconditionError, match="point has shape"):
        kd.k_nearest([0.0, 0.0], 3)
    with pytest.raises(kinetic.PreconditionError, match="eps"):
        kd.k_nearest([0.0, 0.0, 0.0], 3, -1.0)
    with pytest.raises(kinetic.PreconditionError, match="points have shape"):
        kd.k_nearest_many(np.zeros((2, 2)), 3)
    with pytest.raises(kinetic.PreconditionError):
        kd.k_nearest([0.0, math.nan, 0.0], 3)
