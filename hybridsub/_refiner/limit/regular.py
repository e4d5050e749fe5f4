"""Regular Loop patches: where the walk may stop.

Over a face whose three corners and their neighbours are interior Loop vertices of valence
6, with no tag (crease, corner) among the patch's edges and vertices, the Loop limit surface
is one quartic polynomial (the box spline) of the face's barycentric coordinates. The walk
(:mod:`.walk`) stops at such a patch: the polynomial is the one through the exact limit
positions of the 15 vertices of the face's second refinement (barycentric coordinates i/4),
found by the walk itself (two levels down, where each is a vertex and takes its limit mask),
in the Bernstein basis. Values and derivatives are then exact, with no last interpolation.
"""

from __future__ import annotations

from math import factorial

import numpy as np

from ._cache_kernels import quartic_points

#: Exponents (i, j, k), i + j + k = 4, of the quartic Bernstein basis over (b0, b1, b2).
EXPONENTS = np.array([(i, j, 4 - i - j) for i in range(4, -1, -1) for j in range(4 - i, -1, -1)])
#: The vertices of the face's second refinement, barycentric.
GRID = EXPONENTS / 4.0
_COEF = np.array([factorial(4) / (factorial(i) * factorial(j) * factorial(k)) for i, j, k in EXPONENTS])


def _pow(x: np.ndarray, n: np.ndarray) -> np.ndarray:
    """x ** n with negative n giving 0 (the terms they multiply vanish)."""
    return np.where(n >= 0, x ** np.maximum(n, 0), 0.0)


def bernstein(bary: np.ndarray, order: int = 0):
    """The 15 basis functions at ``bary`` (q, 15); ``order`` 1: also their derivatives along
    b1 and b2 (b0 = 1 − b1 − b2); 2: also the second derivatives (11, 12, 22)."""
    b = [bary[:, c, None] for c in range(3)]
    i, j, k = (EXPONENTS[:, c][None] for c in range(3))

    def term(di, dj, dk, factor):
        return factor * _COEF * _pow(b[0], i - di) * _pow(b[1], j - dj) * _pow(b[2], k - dk)

    out = [term(0, 0, 0, 1)]
    if order >= 1:
        out += [term(0, 1, 0, j) - term(1, 0, 0, i), term(0, 0, 1, k) - term(1, 0, 0, i)]
    if order >= 2:
        ii = i * (i - 1)
        out += [term(0, 2, 0, j * (j - 1)) - 2 * term(1, 1, 0, i * j) + term(2, 0, 0, ii),
                term(0, 1, 1, j * k) - term(1, 0, 1, i * k) - term(1, 1, 0, i * j) + term(2, 0, 0, ii),
                term(0, 0, 2, k * (k - 1)) - 2 * term(1, 0, 1, i * k) + term(2, 0, 0, ii)]
    return out


#: Coefficients from values at GRID: c = GRID_INVERSE @ values.
GRID_INVERSE = np.linalg.inv(bernstein(GRID)[0])


def polynomial_weights(bary: np.ndarray, uv: np.ndarray, n_rows: int) -> np.ndarray:
    """Weights (q, n_rows, 15) on the 15 coefficients: value, ∂/∂u, ∂/∂v, ∂²/∂u², ∂²/∂u∂v,
    ∂²/∂v², from :func:`bernstein` and the face's corners in (u, v), ``uv`` (q, 3, 2)."""
    W = np.empty((len(bary), n_rows, 15))
    quartic_points(np.ascontiguousarray(bary, dtype=np.float64), np.ascontiguousarray(uv, dtype=np.float64),
                   EXPONENTS, _COEF, W)
    return W


def is_regular(F: np.ndarray, twin: np.ndarray, hsharp, face_sharp: np.ndarray, corner: np.ndarray) -> bool:
    """Whether a patch (canonical: its centre is face 0) is a regular Loop patch: every face
    Loop, no tag, and the centre's corners and their neighbours interior of valence 6."""
    if hsharp is not None or corner.any() or not face_sharp.all():
        return False
    ring = np.unique(F[np.isin(F, F[0]).any(axis=1)])
    faces_at = np.bincount(F.ravel(), minlength=len(corner))
    open_at = np.zeros(len(corner), bool)
    open_at[F.ravel()[twin < 0]] = True  # the start of a boundary halfedge
    return bool((faces_at[ring] == 6).all() and not open_at[ring].any())
