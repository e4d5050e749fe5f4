"""Derivatives of points exactly on a split edge beside a √3 face (the hybrid's creases,
boundaries and sharp/smooth interfaces, Kobbelt's boundary): from a quadratic fit of exact
values.

There the surface has no derivative across the edge in the chart: the edge is halved
(trisected) every step while the √3 faces beside it shrink by √3, and the difference quotient
into the face grows without bound as the edge is approached (the walk's ``Du``, ``Dv`` there
grow with the depth). The values are exact at every such point, so the derivatives
are taken from a one-sided quadratic fit of values at one and two :data:`STEP` along the edge
and into the face: the point's own value and four more walks, combined with fixed weights.
``project``'s Newton steps take these first derivatives too (with the walk's own second ones):
with the walk's, a run on the edge stepped along it to the wrong place.

On an infinitely sharp crease between two crease vertices the derivative along the edge is
the crease curve's own: the rules there see only crease vertices (B1 midpoints, B2
(1/8, 3/4, 1/8)), so the curve is the uniform cubic B-spline of the crease polygon
(:func:`crease_polygons`), and its derivative replaces the fit's along the edge (whose
differences of values over 1e-5 lost digits: up to 3.4e-6 relative); the along-edge samples
are then not walked.
``docs/limit.md`` ("Points on a split edge") gives the accuracy against the vertices' tangent
masks.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .depth import PointDepths

#: The fit's step in barycentric units.
STEP = 1e-5
#: Points within this of a corner are the corner's (their own rules, ``depth.py``).
AT_CORNER = 1e-12
#: A point whose least coordinate is below this (under one rounding unit of the other two) is
#: on the edge for the walk too: its derivatives there are the edge's, and as broken.
ON_EDGE = 1e-16

# Offsets (along, into) of the samples in steps after the point itself, and the weights that
# give ∂σ, ∂ν (σ along, ν into; per step) from the values at the point and the samples: the
# one-sided second-order differences of the quadratic through them.
_OFFSETS = np.array([[1, 0], [2, 0], [0, 1], [0, 2]], float)
_FIT = np.array([
    [-1.5, 2.0, -0.5, 0.0, 0.0],
    [-1.5, 0.0, 0.0, 2.0, -0.5],
])


def on_split_edge(depths: PointDepths, f: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The points (face ``f``, bary ``b``) on a split edge beside a √3 face (the hybrid's, and
    Kobbelt's boundary in ``"sqrt3"``), not at its ends: their indices and the corner whose
    coordinate is zero there."""
    if not depths.edge.any() or not len(f):
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    k = np.argmin(b, axis=1)
    on = (b[np.arange(len(f)), k] < ON_EDGE) & (b.max(axis=1) < 1 - AT_CORNER)
    on &= depths.edge[f, (k + 1) % 3]  # halfedge i (corner i to i + 1) is where b[(i + 2) % 3] = 0
    idx = np.flatnonzero(on)
    return idx, k[idx]


def samples(b: np.ndarray, k: np.ndarray, curve: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The fit's samples (4, q, 3) of the edge points ``b`` (zero coordinate ``k``), the
    weights W (2, 5, q) and A (2, q): ``Du, Dv = Σ_j W[:, j] value_j + A ∂σ``, with the values
    at the points and their samples and ∂σ the derivative along the edge per step.

    Where ``curve`` (q,) is True, ∂σ is the crease curve's (:func:`curve_along`) and the two
    samples along the edge get no weight; elsewhere A is 0 and the fit gives ∂σ too. Into the
    face is towards corner ``k`` from the edge's farther end (its coordinate ≥ ½), along the
    edge away from it, so every sample stays in the face."""
    q = len(b)
    rows = np.arange(q)
    c1, c2 = (k + 1) % 3, (k + 2) % 3
    far = np.where(b[rows, c1] >= b[rows, c2], c1, c2)
    near = np.where(far == c1, c2, c1)
    along = np.zeros((q, 3))
    along[rows, near], along[rows, far] = 1.0, -1.0
    into = np.zeros((q, 3))
    into[rows, k], into[rows, far] = 1.0, -1.0
    pts = b[None] + STEP * (_OFFSETS[:, :1, None] * along[None] + _OFFSETS[:, 1:, None] * into[None])
    pts[:, rows, far] = 1.0 - pts[:, rows, near] - pts[:, rows, k]  # each sums to 1 exactly
    # (σ, ν) → (u, v) = (b1, b2): J's rows are the two directions' (u, v) per step.
    J = STEP * np.stack([along[:, 1:], into[:, 1:]], axis=1)  # (q, 2, 2)
    Jinv = np.linalg.inv(J)
    W = np.einsum("qab,bj->ajq", Jinv, _FIT)  # (2, 5, q): Du, Dv
    A = np.zeros((2, q))
    if curve is not None and curve.any():
        W[:, :, curve] = np.einsum("qa,j->ajq", Jinv[curve, :, 1], _FIT[1])
        A[:, curve] = Jinv[curve, :, 0].T
    return pts, np.ascontiguousarray(W), A


def crease_polygons(inp) -> np.ndarray | None:
    """(3m, 4) int64: for each halfedge ``3f + i`` (corner i to i + 1) of the hybrid on an
    infinitely sharp crease (tagged or a boundary) whose two ends are crease vertices (two
    crease edges, none semi-sharp, no corner), the crease polygon round it ``(p₀, a, b, p₃)``;
    −1 elsewhere. None where no halfedge has one."""
    if inp.scheme != "hybrid":
        return None
    lvl = inp.level
    F = np.asarray(inp.faces, np.int64)
    n = inp.n_vertices
    twin = np.asarray(lvl.twin, np.int64)
    s = np.zeros(len(twin)) if lvl.hsharp is None else np.asarray(lvl.hsharp, np.float64)
    s = np.where(twin < 0, np.inf, s)
    ends = np.stack([F, np.roll(F, -1, axis=1)], -1).reshape(-1, 2)
    once = (s > 0) & ((twin < 0) | (np.arange(len(twin)) < twin))  # each crease edge once
    E = ends[once]
    count = np.bincount(E.ravel(), minlength=n)
    semi = np.zeros(n, bool)
    semi[E[np.isfinite(s[once])].ravel()] = True
    regular = (count == 2) & ~np.asarray(inp.corner, bool) & ~semi
    h = np.flatnonzero(np.isinf(s) & regular[ends[:, 0]] & regular[ends[:, 1]])
    if not len(h):
        return None
    v, w = np.concatenate([E[:, 0], E[:, 1]]), np.concatenate([E[:, 1], E[:, 0]])
    order = np.argsort(v, kind="stable")
    start = np.searchsorted(v[order], np.arange(n))
    first, second = w[order][np.minimum(start, len(v) - 1)], w[order][np.minimum(start + 1, len(v) - 1)]
    a, b = ends[h, 0], ends[h, 1]
    out = np.full((len(twin), 4), -1, np.int64)
    out[h] = np.stack([np.where(first[a] == b, second[a], first[a]), a, b,
                       np.where(first[b] == a, second[b], first[b])], axis=1)
    return out


def on_crease_curve(polygons: np.ndarray | None, f: np.ndarray, k: np.ndarray) -> np.ndarray:
    """(q,) bool: the edge points (face ``f``, zero coordinate ``k``) lie on a crease polygon's edge."""
    if polygons is None:
        return np.zeros(len(f), bool)
    return polygons[3 * f + (k + 1) % 3, 0] >= 0


def curve_along(polygons: np.ndarray, f: np.ndarray, b: np.ndarray, k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The crease curve's derivative per step along the fit's direction (:func:`samples`) at
    edge points on a crease polygon's edge: weights and vertex columns (q, 4)."""
    q = len(f)
    rows = np.arange(q)
    c1, c2 = (k + 1) % 3, (k + 2) % 3
    t = b[rows, c2]  # the polygon's parameter from a (corner c1) to b (corner c2)
    sign = np.where(b[rows, c1] >= b[rows, c2], 1.0, -1.0)  # the fit steps away from the farther end
    dw = np.stack([-3 * (1 - t) ** 2, 9 * t**2 - 12 * t, -9 * t**2 + 6 * t + 3, 3 * t**2], axis=1) / 6
    return (STEP * sign)[:, None] * dw, polygons[3 * f + c1]


def combine(W: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``Du, Dv`` (2, q, d) from the values (5, q, d) at the points and their samples."""
    return np.einsum("rjq,jqd->rqd", W, values)


def combine_rows(W: np.ndarray, rows: list) -> list:
    """As :func:`combine` for value rows: five CSR matrices (q, n), the points' and their samples'."""
    return [sp.csr_matrix(sum(sp.diags(W[r, j]) @ rows[j] for j in range(len(rows)))) for r in range(2)]
