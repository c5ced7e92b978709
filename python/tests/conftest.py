"""Shared helpers of the Python tests: motions (random and degenerate), exact positions with
fractions, and the brute-force answers the structures are held against.

Every random input comes from a fixed seed that is part of the test's name (pytest prints it on
a failure)."""

from fractions import Fraction

import numpy as np

import kinetic


def exact_position(coefficients, origin, t):
    """sum_j c_j (t - origin)^j per coordinate, exactly (coefficients: (d, k) doubles)."""
    dt = Fraction(t) - Fraction(origin)
    out = []
    for row in coefficients:
        value = Fraction(0)
        for c in reversed(list(row)):
            value = value * dt + Fraction(float(c))
        out.append(value)
    return tuple(out)


def exact_positions(motions, origins, t):
    motions = np.asarray(motions, dtype=float)
    if motions.ndim == 2:
        motions = motions[:, None, :]
    origins = np.zeros(len(motions)) if origins is None else np.broadcast_to(origins, len(motions))
    return [exact_position(motions[i], origins[i], t) for i in range(len(motions))]


def random_motions(seed, n, d, k, scale=1.0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-scale, scale, size=(n, d, k))


def degenerate_motions(seed, n, d, kind):
    """Inputs where events coincide: 'equal' (groups of identical trajectories), 'common' (every
    object on a line through one point at t = 0.5: n(n-1)/2 simultaneous crossings),
    'tangent' (parabolas touching one another at t = 0.5 without crossing), 'grid' (integer
    coordinates and small integer speeds: many exact ties)."""
    rng = np.random.default_rng(seed)
    if kind == "equal":
        base = rng.uniform(-1, 1, size=(max(1, n // 3), d, 2))
        return base[rng.integers(0, len(base), size=n)]
    if kind == "common":
        speeds = rng.uniform(-1, 1, size=(n, d))
        m = np.zeros((n, d, 2))
        m[:, :, 1] = speeds
        m[:, :, 0] = -0.5 * speeds + 0.25  # x(0.5) = 0.25 on every axis
        return m
    if kind == "tangent":
        m = np.zeros((n, d, 3))
        a = rng.integers(-3, 4, size=(n, d)).astype(float)
        # a (t - 0.5)^2 + 0.125 = a t^2 - a t + (a / 4 + 0.125): all touch at t = 0.5
        m[:, :, 0] = a / 4 + 0.125
        m[:, :, 1] = -a
        m[:, :, 2] = a
        return m
    if kind == "grid":
        m = np.zeros((n, d, 2))
        m[:, :, 0] = rng.integers(-4, 5, size=(n, d))
        m[:, :, 1] = rng.integers(-2, 3, size=(n, d))
        return m
    raise ValueError(kind)


DEGENERATE = ["equal", "common", "tangent", "grid"]


def query_times(seed, count, end=1.0):
    """Random times in (0, end), plus 0.5 (the simultaneous events of the degenerate inputs)."""
    rng = np.random.default_rng(seed + 1000)
    return sorted(set([float(x) for x in rng.uniform(0.0, end, size=count)] + [0.5]))


def speed_bound(motions, end=1.0):
    """A bound on |x'(t)| over [0, end] for every object and axis (motions with origin 0)."""
    motions = np.asarray(motions, dtype=float)
    k = motions.shape[-1]
    bound = 0.0
    for j in range(1, k):
        bound_j = np.abs(motions[..., j]).max() * j * max(1.0, end) ** (j - 1)
        bound += bound_j
    return float(bound)


def in_box(p, box):
    return all(Fraction(float(lo)) <= x <= Fraction(float(hi)) for x, (lo, hi) in zip(p, box))


def near_box_side(p, box, tol):
    return any(abs(float(x) - lo) <= tol or abs(float(x) - hi) <= tol for x, (lo, hi) in zip(p, box))


def squared_distance(p, q):
    return sum((a - Fraction(float(b))) ** 2 for a, b in zip(p, q))


def exact_squared_distance(p, q):
    return sum((a - b) ** 2 for a, b in zip(p, q))


def cross(o, a, b):
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def convex_hull(points):
    """Andrew's monotone chain on exact points: the vertices counter-clockwise from the lowest
    then leftmost one, without points inside an edge."""
    pts = sorted(set(points), key=lambda p: (p[1], p[0]))
    if len(pts) <= 2:
        return pts
    pts_x = sorted(set(points))
    lower, upper = [], []
    for p in pts_x:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts_x):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    hull = lower[:-1] + upper[:-1]
    start = min(range(len(hull)), key=lambda i: (hull[i][1], hull[i][0]))
    return hull[start:] + hull[:start]


def structures_with(query):
    return [s["name"] for s in kinetic.structures() if query in s["queries"]]


# --- Signs "just after t": the answer of a structure at an event time is the one just after it.


def taylor(row, origin, t):
    """The coefficients in d of x(t + d) for x = sum_j c_j (s - origin)^j (exact)."""
    dt = Fraction(t) - Fraction(origin)
    out = [Fraction(0)] * len(row)
    for j, c in enumerate(row):
        binom = 1
        for i in range(j + 1):  # (dt + d)^j = sum_i C(j, i) dt^(j - i) d^i
            out[i] += Fraction(float(c)) * binom * dt ** (j - i)
            binom = binom * (j - i) // (i + 1)
    return out


def poly_add(a, b):
    n = max(len(a), len(b))
    return [(a[i] if i < len(a) else 0) + (b[i] if i < len(b) else 0) for i in range(n)]


def poly_sub(a, b):
    return poly_add(a, [-x for x in b])


def poly_mul(a, b):
    out = [Fraction(0)] * (len(a) + len(b) - 1)
    for i, x in enumerate(a):
        if x:
            for j, y in enumerate(b):
                out[i + j] += x * y
    return out


def sign_after(poly):
    """The sign of the polynomial just after 0 (of its first non-zero coefficient)."""
    for c in poly:
        if c:
            return 1 if c > 0 else -1
    return 0


def orientation_after(pa, pb, pc):
    ux, uy = poly_sub(pb[0], pa[0]), poly_sub(pb[1], pa[1])
    vx, vy = poly_sub(pc[0], pa[0]), poly_sub(pc[1], pa[1])
    return sign_after(poly_sub(poly_mul(ux, vy), poly_mul(uy, vx)))


def incircle_after(pa, pb, pc, pd):
    """> 0 when pd is strictly inside the circle through pa, pb, pc (counter-clockwise) just after."""
    rows = []
    for q in (pa, pb, pc):
        u, v = poly_sub(q[0], pd[0]), poly_sub(q[1], pd[1])
        rows.append((u, v, poly_add(poly_mul(u, u), poly_mul(v, v))))
    (a1, a2, a3), (b1, b2, b3), (c1, c2, c3) = rows
    det = poly_mul(a1, poly_sub(poly_mul(b2, c3), poly_mul(b3, c2)))
    det = poly_sub(det, poly_mul(a2, poly_sub(poly_mul(b1, c3), poly_mul(b3, c1))))
    det = poly_add(det, poly_mul(a3, poly_sub(poly_mul(b1, c2), poly_mul(b2, c1))))
    return sign_after(det)
