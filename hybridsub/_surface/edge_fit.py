"""Derivatives of points exactly on a split edge beside a √3 face of the hybrid: from a
quadratic fit of exact values.

There the chart has no derivative across the edge: the edge is halved every step while the
√3 faces beside it shrink by √3, so the last faces of a walk to the edge are needles across
it and the chart shears along it by an amount that does not settle as the edge is approached
(the walk's ``Du``, ``Dv`` there grow with the depth, the along-edge one lost digits, and
normals were up to 90° off). The values are exact at every such point, so the derivatives
are taken from a one-sided quadratic fit of values at one and two :data:`STEP` along the edge
and into the face: the point's own value and four more walks, combined with fixed weights.
``project``'s Newton steps take these first derivatives too (with the walk's own second ones):
with the walk's, a run on the edge stepped along it to the wrong place.
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
    """The points (face ``f``, bary ``b``) on a split edge beside a √3 face, not at its ends:
    their indices and the corner whose coordinate is zero there. The hybrid's only: on
    Kobbelt's boundary (``"sqrt3"``) the walk's derivatives keep their digits."""
    if depths.sqrt3 or not depths.edge.any() or not len(f):
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    k = np.argmin(b, axis=1)
    on = (b[np.arange(len(f)), k] < ON_EDGE) & (b.max(axis=1) < 1 - AT_CORNER)
    on &= depths.edge[f, (k + 1) % 3]  # halfedge i (corner i to i + 1) is where b[(i + 2) % 3] = 0
    idx = np.flatnonzero(on)
    return idx, k[idx]


def samples(b: np.ndarray, k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The fit's samples (4, q, 3) of the edge points ``b`` (zero coordinate ``k``), and the
    weights (2, 5, q) that turn the values at the points and their samples into ``Du, Dv``.

    Into the face is towards corner ``k`` from the edge's farther end (its coordinate ≥ ½),
    along the edge away from it, so every sample stays in the face."""
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
    W = np.einsum("qab,bj->ajq", np.linalg.inv(J), _FIT)  # (2, 5, q): Du, Dv
    return pts, np.ascontiguousarray(W)


def combine(W: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``Du, Dv`` (2, q, d) from the values (5, q, d) at the points and their samples."""
    return np.einsum("rjq,jqd->rqd", W, values)


def combine_rows(W: np.ndarray, rows: list) -> list:
    """As :func:`combine` for value rows: five CSR matrices (q, n), the points' and their samples'."""
    return [sp.csr_matrix(sum(sp.diags(W[r, j]) @ rows[j] for j in range(len(rows)))) for r in range(2)]
