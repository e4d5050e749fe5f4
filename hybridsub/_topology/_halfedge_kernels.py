"""Numba primitives on implicit halfedges, inlined into every kernel that walks a mesh.

Private. Halfedge ``h = 3 f + i`` of face ``f`` runs ``F[f, i] → F[f, (i+1) % 3]``; ``twin[h]``
is the halfedge across (−1 on the boundary). ``F`` is an (m, 3) int64 array.

>>> import numpy as np
>>> F = np.array([[0, 1, 2]])
>>> int(origin(F, 1)), int(dest(F, 1)), int(opposite(F, 1)), int(next_in_face(2)), int(prev_in_face(0))
(1, 2, 0, 0, 2)
"""

from __future__ import annotations

import numpy as np

from .._jit import kernel


@kernel(inline="always")
def dest(F, h):
    """The vertex halfedge h points to."""
    return F[h // 3, (h % 3 + 1) % 3]


@kernel(inline="always")
def origin(F, h):
    """The vertex halfedge h leaves."""
    return F[h // 3, h % 3]


@kernel(inline="always")
def opposite(F, h):
    """The vertex of h's face that is not on h."""
    return F[h // 3, (h % 3 + 2) % 3]


@kernel(inline="always")
def next_in_face(h):
    """The next halfedge of h's face."""
    return h - h % 3 + (h % 3 + 1) % 3


@kernel(inline="always")
def prev_in_face(h):
    """The previous halfedge of h's face."""
    return h - h % 3 + (h % 3 + 2) % 3


@kernel(inline="always")
def edge_sharpness(h, twin, hsharp, has_tags):
    """Sharpness of h's edge this step: inf on the boundary, the tag inside (0 untagged)."""
    if twin[h] < 0:
        return np.inf
    if has_tags:
        return hsharp[h]
    return 0.0


@kernel(inline="always")
def owned_edge(F, twin, f, i):
    """(h, u, w): halfedge ``h = 3 f + i`` and its ends u → w, h = −1 when it does not own
    its edge (the lower-numbered halfedge of an edge owns it). Face and corner in: no
    division by 3 (a fifth of a walk over every edge)."""
    h = 3 * f + i
    t = twin[h]
    return h if t < 0 or t > h else -1, F[f, i], F[f, i + 1 if i < 2 else 0]


@kernel(inline="always")
def owned_ends_in(F, twin, f, i, lo, hi):
    """(u, w, u in lo:hi, w in lo:hi) for the edge u→w of halfedge ``3 f + i`` if it owns
    it (:func:`owned_edge`), else two Falses: a walk over every edge, face by face, that
    keeps one range of vertices' terms, in the serial order, as the threaded kernels do."""
    h, u, w = owned_edge(F, twin, f, i)
    if h < 0:
        return u, w, False, False
    return u, w, lo <= u < hi, lo <= w < hi


@kernel(inline="always")
def far_twins(twin):
    """Whether the faces across this level's edges lie far from their own in memory: of 1024
    halfedges evenly spread, more than one in eight has its twin 4096 faces or more away, on
    a level of more than 32k faces. Only there does prefetching the reads across edges pay;
    elsewhere the hint only costs (docs/performance.md, "Kernel design")."""
    n = twin.shape[0]
    if n <= 3 * 2**15:
        return False
    step = n // 1024
    far = 0
    for k in range(1024):
        h = k * step
        t = twin[h]
        if t >= 0 and abs(t - h) >= 3 * 4096:
            far += 1
    return 8 * far > 1024
