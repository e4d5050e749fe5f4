"""Derivatives of points exactly on a split edge beside a √3 face of the hybrid: from a
quadratic fit of exact values.

There the chart has no derivative across the edge: the edge is halved every step while the
√3 faces beside it shrink by √3, so the last faces of a walk to the edge are needles across
it and the chart shears along it by an amount that does not settle as the edge is approached
(the walk's ``Du``, ``Dv`` there grow with the depth, the along-edge one lost digits, and
normals were up to 90° off). The values are exact at every such point, so the derivatives
are taken from a one-sided quadratic fit of values at :data:`STEP` along the edge and into
the face: six values per point, each a walk of its own, combined with fixed weights.
``docs/limit.md`` ("Points on a split edge") gives the accuracy against the vertices' tangent
masks.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .depth import PointDepths

#: The fit's step in barycentric units (samples at one and two steps along and into the face).
STEP = 1e-5
#: Points within this of a corner are the corner's (their own rules, ``depth.py``).
AT_CORNER = 1e-12

# Offsets (along, into) of the six samples in steps, and the weights that give, from their
# values, ∂σ, ∂ν, ∂σσ, ∂σν, ∂νν of the quadratic through them (σ along, ν into; per step).
_OFFSETS = np.array([[0, 0], [1, 0], [2, 0], [0, 1], [0, 2], [1, 1]], float)
_FIT = np.array([
    [-1.5, 2.0, -0.5, 0.0, 0.0, 0.0],  # ∂σ (one-sided, second order)
    [-1.5, 0.0, 0.0, 2.0, -0.5, 0.0],  # ∂ν
    [1.0, -2.0, 1.0, 0.0, 0.0, 0.0],  # ∂σσ
    [1.0, -1.0, 0.0, -1.0, 0.0, 1.0],  # ∂σν
    [1.0, 0.0, 0.0, -2.0, 1.0, 0.0],  # ∂νν
])


def on_split_edge(depths: PointDepths, f: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The points (face ``f``, bary ``b``) on a split edge beside a √3 face, not at its ends:
    their indices and the corner whose coordinate is zero there. The hybrid's only: on
    Kobbelt's boundary (``"sqrt3"``) the walk's derivatives keep their digits."""
    if depths.sqrt3 or not depths.edge.any() or not len(f):
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    k = np.argmin(b, axis=1)
    on = (b[np.arange(len(f)), k] == 0) & (b.max(axis=1) < 1 - AT_CORNER)
    on &= depths.edge[f, (k + 1) % 3]  # halfedge i (corner i to i + 1) is where b[(i + 2) % 3] = 0
    idx = np.flatnonzero(on)
    return idx, k[idx]


def samples(b: np.ndarray, k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The fit's sample points (6, q, 3) of the edge points ``b`` (zero coordinate ``k``), and
    the weights (5, 6, q) that turn their values into ``Du, Dv, Duu, Duv, Dvv``.

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
    # (σ, ν) → (u, v) = (b1, b2): J rows are the directions' (u, v) per step.
    J = STEP * np.stack([along[:, 1:], into[:, 1:]], axis=1)  # (q, 2, 2)
    Ji = np.linalg.inv(J)
    first = np.einsum("qab,bj->qaj", Ji, _FIT[:2])  # (q, 2, 6): Du, Dv
    Q = np.stack([np.stack([_FIT[2], _FIT[3]], 0), np.stack([_FIT[3], _FIT[4]], 0)], 0)  # (2, 2, 6)
    H = np.einsum("qab,bcj,qdc->qadj", Ji, Q, Ji)  # (q, 2, 2, 6): J⁻¹ Q J⁻ᵀ
    W = np.stack([first[:, 0], first[:, 1], H[:, 0, 0], H[:, 0, 1], H[:, 1, 1]], 0)  # (5, q, 6)
    return pts, np.ascontiguousarray(W.transpose(0, 2, 1))


def combine(W: np.ndarray, values: np.ndarray, n_rows: int) -> np.ndarray:
    """``Du, Dv`` (and with ``n_rows`` 6 the second derivatives) (n_rows − 1, q, d) from the
    samples' values (6, q, d) and :func:`samples`' weights."""
    return np.einsum("rjq,jqd->rqd", W[:n_rows - 1], values)


def combine_rows(W: np.ndarray, rows: list, n_rows: int) -> list:
    """As :func:`combine` for the samples' value rows (six CSR matrices (q, n))."""
    out = []
    for r in range(n_rows - 1):
        M = sum(sp.diags(W[r, j]) @ rows[j] for j in range(6))
        out.append(sp.csr_matrix(M))
    return out
