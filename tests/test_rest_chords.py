"""The chords a perturbed part may rest on (F3) keep the hull vertices between their ends within
twice the shape tolerance: the farthest of them, found by a binary search on the edge
directions (``uncertain._chord_sagitta``), against every vertex measured."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from feederkit.hull import convex_hull
from feederkit.mechanics.uncertain import _chord_sagitta


def _every_vertex(h: np.ndarray, m: int) -> np.ndarray:
    """Per vertex i, the largest distance from chord (i, i + m) of the vertices between."""
    n = len(h)
    out = np.zeros(n)
    for i in range(n):
        a, b = h[i], h[(i + m) % n]
        d = b - a
        for k in range(1, m):
            r = h[(i + k) % n] - a
            out[i] = max(out[i], abs(d[0] * r[1] - d[1] * r[0]) / math.hypot(*d))
    return out


def _chords(h: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray]:
    d = h[(np.arange(len(h)) + m) % len(h)] - h
    return d, np.hypot(d[:, 0], d[:, 1])


def _ring(seed: int, n: int, noise: float) -> np.ndarray:
    rng = random.Random(seed)
    pts = []
    for k in range(n):
        a = 2 * math.pi * k / n + rng.uniform(-0.4, 0.4) * math.pi / n
        f = 10.0 * (1.0 + rng.uniform(-noise, noise))
        pts.append((f * math.cos(a), f * math.sin(a)))
    return np.asarray(convex_hull(pts), dtype=float)


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize(("n", "noise"), [(7, 0.3), (30, 0.05), (120, 0.002)])
def test_the_farthest_vertex_between_a_chords_ends_is_the_one_every_vertex_gives(seed, n, noise):
    h = _ring(seed, n, noise)
    farthest = _chord_sagitta(h)
    for m in range(2, len(h) - 1):
        d, length = _chords(h, m)
        assert np.allclose(farthest(m, d, length), _every_vertex(h, m), rtol=1e-9, atol=1e-12)


def test_a_ring_that_is_not_convex_and_counter_clockwise_is_measured_vertex_by_vertex():
    ccw = _ring(3, 20, 0.05)
    for h in (ccw[::-1].copy(), np.vstack([ccw[:10], [[0.0, 0.0]], ccw[10:]])):
        farthest = _chord_sagitta(h)
        for m in (2, 5, 9):
            d, length = _chords(h, m)
            assert np.allclose(farthest(m, d, length), _every_vertex(h, m), rtol=1e-9)
