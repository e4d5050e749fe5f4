"""Linear face-varying values (``uv_mode="linear"``): old values kept, midpoints on split
edges, centroids for face points. The UV matrix of a step as CSR, or applied directly with
the same sums in the same order (so the same bits).

>>> import numpy as np
>>> from hybridsub._input.gate import open_gate
>>> from hybridsub._refiner.loop import walk
>>> inp = open_gate([[0, 1, 2], [0, 2, 3]], levels=1, uv_faces=[[0, 1, 2], [3, 4, 5]])
>>> s = next(walk(inp))
>>> linear_uv_matrix(s.uv.level, s.uv.plan).shape
(14, 6)
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .._topology import Level, linear_rows
from .stencils import apply_matrix


def linear_uv_matrix(uvl: Level, plan) -> sp.csr_matrix:
    """UV matrix of ``uv_mode="linear"``: old values kept, midpoints, centroids (CSR, built
    directly, columns sorted)."""
    t = uvl.n_vertices
    E, T, degenerate = linear_rows(uvl, plan)
    indptr = np.concatenate([np.arange(t + 1), t + 2 * np.arange(1, len(E) + 1),
                             t + 2 * len(E) + 3 * np.arange(1, len(T) + 1)])
    indices = np.concatenate([np.arange(t), E.ravel(), T.ravel()])
    data = np.concatenate([np.ones(t), np.full(E.size, 0.5), np.full(T.size, 1.0 / 3.0)])
    S = sp.csr_matrix((data, indices, indptr), shape=(plan.n_new, t))
    if degenerate:
        S.sum_duplicates()  # a degenerate UV edge (p, p) gives one entry 1.0
    S.has_sorted_indices = True
    return S


def linear_uv_apply(uvl: Level, plan, UV: np.ndarray) -> np.ndarray:
    """``linear_uv_matrix(uvl, plan) @ UV`` without forming it: the same sums in the same order,
    so the same bits (a degenerate UV edge or face goes through the matrix, whose merged
    entries sum differently)."""
    E, T, degenerate = linear_rows(uvl, plan)
    if degenerate:
        return apply_matrix(linear_uv_matrix(uvl, plan), UV)
    t, w = uvl.n_vertices, 1.0 / 3.0
    out = np.empty((plan.n_new, UV.shape[1]))
    out[:t] = UV
    out[t:t + len(E)] = 0.5 * UV[E[:, 0]] + 0.5 * UV[E[:, 1]]
    out[t + len(E):] = w * UV[T[:, 0]] + w * UV[T[:, 1]] + w * UV[T[:, 2]]
    return out
