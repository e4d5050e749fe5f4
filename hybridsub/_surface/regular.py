"""Regular Loop patches: where the walk may stop.

Over a face whose three corners are untagged interior Loop vertices of valence 6 with no
crease, the Loop limit surface is one quartic polynomial (the box spline of the corners'
twelve neighbours) of the face's barycentric coordinates: the limit over a face depends only
on its corners' rules and those of the edges at its corners, whatever the neighbours'
valences and tags. So it is on one side of a straight infinitely sharp crease (or boundary):
a corner on it with exactly two crease edges and three Loop faces between them on the face's
side follows the crease rules, which are the regular rules applied to "phantom" vertices
mirrored across the crease (c' = a + v − c), and the mirroring persists under refinement; the
face's corners on the crease, if two, must be joined by the crease. The walk
(:mod:`.walk`) stops at such a patch: the polynomial is the one through the exact limit
positions of the 15 vertices of the face's second refinement (barycentric coordinates i/4),
found by the walk itself (two levels down, where each is a vertex and takes its limit mask),
in the Bernstein basis. Values and derivatives are then exact, with no last interpolation.
"""

from __future__ import annotations

from math import factorial

import numpy as np

from ._walk_kernels import quartic_points

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


def regular_torus(n: int = 6):
    """A closed n × n torus grid of triangles, every vertex of valence 6: ``V``, ``F``."""
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a, b = 2 * np.pi * i.ravel() / n, 2 * np.pi * j.ravel() / n
    V = np.stack([(2 + np.cos(b)) * np.cos(a), (2 + np.cos(b)) * np.sin(a), np.sin(b)], 1)
    x, y = i.ravel(), j.ravel()
    ids = [x * n + y, (x + 1) % n * n + y, (x + 1) % n * n + (y + 1) % n, x * n + (y + 1) % n]
    F = np.concatenate([np.stack([ids[0], ids[1], ids[2]], 1), np.stack([ids[0], ids[2], ids[3]], 1)])
    return V, F


#: Coefficients from values at GRID: c = GRID_INVERSE @ values.
GRID_INVERSE = np.linalg.inv(bernstein(GRID)[0])


def polynomial_weights(bary: np.ndarray, grad: np.ndarray, n_rows: int) -> np.ndarray:
    """Weights (q, n_rows, 15) on the 15 coefficients: value, ∂/∂u, ∂/∂v, ∂²/∂u², ∂²/∂u∂v,
    ∂²/∂v², from :func:`bernstein` and the derivatives ``grad`` (q, 3, 2) of ``bary`` in (u, v)."""
    W = np.empty((len(bary), n_rows, 15))
    quartic_points(np.ascontiguousarray(bary, dtype=np.float64), np.ascontiguousarray(grad, dtype=np.float64),
                   EXPONENTS, _COEF, W)
    return W


def is_regular(F: np.ndarray, twin: np.ndarray, hsharp, face_sharp: np.ndarray, corner: np.ndarray) -> bool:
    """Whether a patch (canonical: its centre is face 0) is a regular Loop patch (see the
    module doc): each of the centre's corners untagged with six Loop faces and no crease, or
    on a straight infinitely sharp crease (exactly two crease edges, three Loop faces between
    them on the centre's side); crease corners, if two, joined by the centre's edge."""
    sharp = np.zeros(3 * len(F)) if hsharp is None else np.asarray(hsharp, dtype=np.float64)
    crease = (twin < 0) | (sharp != 0)
    kinds = []
    for v in F[0]:
        if corner[v]:
            return False
        faces = np.flatnonzero((F == v).any(axis=1))
        # The edges at v, as vertex pairs, with whether each is a crease and infinitely sharp.
        edges = {}
        for f in faces:
            for k in range(3):
                a, b = F[f, k], F[f, (k + 1) % 3]
                if v in (a, b):
                    e = (min(a, b), max(a, b))
                    c, inf = edges.get(e, (False, True))
                    h = 3 * f + k
                    edges[e] = (c or crease[h], inf and (twin[h] < 0 or sharp[h] == np.inf))
        creases = [e for e, (c, _) in edges.items() if c]
        # The centre's side: faces at v reached from it across edges at v that are not creases.
        side, todo = {0}, [0]
        while todo:
            f = todo.pop()
            for g in faces:
                shared = set(F[f]) & set(F[g])
                if g not in side and len(shared) == 2:
                    e = tuple(sorted(shared))
                    if v in e and not edges[e][0]:
                        side.add(g)
                        todo.append(g)
        if not face_sharp[list(side)].all():
            return False
        if not creases and len(faces) == 6 and len(edges) == 6:
            kinds.append(False)
        elif len(creases) == 2 and all(edges[e][1] for e in creases) and len(side) == 3:
            kinds.append(True)
        else:
            return False
    on = [v for v, k in zip(F[0], kinds) if k]
    if len(on) == 3:
        return False
    if len(on) == 2:
        k = [i for i in range(3) if {F[0, i], F[0, (i + 1) % 3]} == set(on)][0]
        return bool(crease[k])
    return True
