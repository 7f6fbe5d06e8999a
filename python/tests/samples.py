"""Generated clouds the Python tests share."""

import math

import numpy as np


def torus(n, seed, noise=0.0):
    """n random points on the torus of radii 1 and 0.4, evenly spread by area, with
    Gaussian noise of sigma noise."""
    rng = np.random.default_rng(seed)
    u, v = np.empty(0), np.empty(0)
    while len(u) < n:
        a, b = rng.uniform(0.0, 2.0 * math.pi, (2, n))
        keep = rng.uniform(0.0, 1.4, n) < 1.0 + 0.4 * np.cos(b)
        u, v = np.concatenate((u, a[keep])), np.concatenate((v, b[keep]))
    u, v = u[:n], v[:n]
    r = 1.0 + 0.4 * np.cos(v)
    points = np.column_stack((r * np.cos(u), r * np.sin(u), 0.4 * np.sin(v)))
    return points + rng.normal(0.0, noise, points.shape) if noise else points
