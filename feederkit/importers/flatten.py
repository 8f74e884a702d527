"""Bounded adaptive flattening of cubic Bezier pieces (the curves of DXF paths), in numpy.

ezdxf flattens a piece (``Bezier4P.flattening``) by splitting it into 4 segments and halving
each segment until the curve's midpoint lies within the distance of its chord's midpoint,
in C, recursing into both halves up to a depth of 1000. When that test can never pass (a NaN
or infinite coordinate makes every comparison false) it makes about 2**1000 calls and never
returns, beyond the reach of any deadline. This module runs the same subdivision (the same 4
segments, the same test, the same points, so a real curve flattens to the same vertices),
but level by level over all the pieces of a drawing at once: the levels are capped, every
level's vertices are counted against the import budget (which also checks its deadline),
and a point that is not finite is refused (docs/import.md, budgets).
"""

from __future__ import annotations

import numpy as np

from feederkit.importers.budget import Budget, ImportLimits

MIN_SEGMENTS = 4
"""Segments each piece starts with before halving (ezdxf's default)."""

MAX_LEVELS = 40
"""Halvings of a segment at most: 2**-42 of a piece's parameter range, where floating point
no longer separates the chord from the curve. A real curve needs about 10."""


class NonFiniteCurve(ValueError):
    """A curve point is NaN or infinite; ``piece`` is the index of its Bezier piece."""

    def __init__(self, piece: int) -> None:
        super().__init__("NaN or infinite curve points")
        self.piece = piece


def bezier_points(cp: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Points (m, 2) of cubic Bezier pieces ``cp`` (m, 4, 2) at parameters ``t`` (m,).

    Bernstein form relative to the first control point, which is added last (as ezdxf does:
    a large offset would cost the small differences their precision).
    """
    p0 = cp[:, 0]
    t = t[:, None]
    t2 = t * t
    s = 1.0 - t
    b = 3.0 * s * s * t
    c = 3.0 * s * t2
    d = t2 * t
    return (cp[:, 1] - p0) * b + (cp[:, 2] - p0) * c + (cp[:, 3] - p0) * d + p0


def _check_finite(points: np.ndarray, piece: np.ndarray) -> None:
    bad = ~np.isfinite(points).all(axis=1)
    if bad.any():
        raise NonFiniteCurve(int(piece[np.flatnonzero(bad)[0]]))


def cubic_flattening(
    cp: np.ndarray, distance: float, budget: Budget | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The vertices of cubic Bezier pieces ``cp`` (m, 4, 2) flattened within ``distance``.

    Returns ``(piece, points)``: for each vertex after each piece's start point, the index of
    its piece and the point, ordered by piece and then along the curve (each piece ends on
    its last control point). A segment is halved while the curve's midpoint is ``distance``
    or farther from the chord's midpoint, at most :data:`MAX_LEVELS` times. Raises
    :class:`NonFiniteCurve` for a NaN or infinite point, and the budget's InputError when
    the vertices (finished and still to come) pass ``--max-vertices`` or time runs out.
    Without ``budget`` the default budget applies: a tolerance that floating point cannot
    meet would otherwise double the segments at every level until memory runs out.
    """
    budget = budget or Budget(ImportLimits(), "the curve")
    cp = np.asarray(cp, dtype=float).reshape(-1, 4, 2)
    m = len(cp)
    if m == 0:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 2))
    budget.need("vertices", m * MIN_SEGMENTS, "vertices after flattening")
    steps = np.arange(1, MIN_SEGMENTS + 1) / MIN_SEGMENTS
    piece = np.repeat(np.arange(m), MIN_SEGMENTS)
    t1 = np.tile(steps, m)
    t0 = t1 - 1.0 / MIN_SEGMENTS
    t0[::MIN_SEGMENTS] = 0.0
    end = bezier_points(cp[piece], t1)
    end[MIN_SEGMENTS - 1 :: MIN_SEGMENTS] = cp[:, 3]
    start = np.roll(end, 1, axis=0)
    start[::MIN_SEGMENTS] = cp[:, 0]
    _check_finite(end, piece)
    done_piece: list[np.ndarray] = []
    done_t: list[np.ndarray] = []
    done_pts: list[np.ndarray] = []
    for level in range(MAX_LEVELS + 1):
        mid_t = (t0 + t1) * 0.5
        mid = bezier_points(cp[piece], mid_t)
        _check_finite(mid, piece)
        chord = start + (end - start) * 0.5
        delta = mid - chord
        near = np.sqrt(delta[:, 0] * delta[:, 0] + delta[:, 1] * delta[:, 1]) < distance
        if level == MAX_LEVELS:  # floating point cannot tell these chords from the curve
            near[:] = True
        done_piece.append(piece[near])
        done_t.append(t1[near])
        done_pts.append(end[near])
        budget.vertices(int(near.sum()))
        far = ~near
        if not far.any():
            break
        piece, t0, t1, start, end, mid, mid_t = (
            a[far] for a in (piece, t0, t1, start, end, mid, mid_t)
        )
        budget.need("vertices", 2 * len(piece), "vertices after flattening")
        piece = np.repeat(piece, 2)
        t0 = np.column_stack((t0, mid_t)).ravel()
        t1 = np.column_stack((mid_t, t1)).ravel()
        start, end = (
            np.stack((start, mid), axis=1).reshape(-1, 2),
            np.stack((mid, end), axis=1).reshape(-1, 2),
        )
    pieces = np.concatenate(done_piece)
    order = np.lexsort((np.concatenate(done_t), pieces))
    return pieces[order], np.concatenate(done_pts)[order]
