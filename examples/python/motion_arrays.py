"""numpy helpers shared by the Python examples: positions evaluated from the coefficient arrays
the ``kinetic`` classes take (in floating point, for comparisons; the structures decide
exactly)."""

import numpy as np


def evaluate(motions, origins, t):
    """Positions at time t, shape (n, d), of motions (n, d, k) in powers of (t - origin):
    Horner's rule on the coefficient array (highest coefficient first)."""
    dt = (t - origins)[:, None]
    x = np.zeros(motions.shape[:2])
    for j in range(motions.shape[2] - 1, -1, -1):
        x = x * dt + motions[:, :, j]
    return x
