"""The vertex lane: limit positions and normals of a whole level without a plan of every
vertex.

Almost every vertex of a refined level is smooth (one closed fan of faces of one kind, no
tag) or on a crease or the boundary among Loop faces. Those get their limit position and
normal from their ring in one kernel pass (``_vertex_kernels``), with the weights of the
scheme's rules (``_rules.limit``) tabulated by valence and sector size. The rest — corners,
darts, semi-sharp creases, vertices between √3 and Loop faces, √3 faces at a crease or
Kobbelt's boundary — go through the general evaluation (``level_eval``: the plan, its masks, local refinement
where a vertex has none) on just the faces around them, which is all their masks and local
refinement read.
"""

from __future__ import annotations

import functools

import numpy as np

from .._rules import limit as LR
from .._rules import step_rules as R
from .._topology._kernels import use_threads
from . import _vertex_kernels as VK
from .limit_setup import LimitInput, local_setup
from .level_eval import evaluate_level
from .local import plan_vertices
from .normals import one_side_sectors, sector_normals, vertex_normals

#: Size of the kernel's tables: a vertex of valence MAX_LANE_VALENCE − 1 or more (its open ring needs one
#: entry more) takes the general plan.
MAX_LANE_VALENCE = 64


@functools.lru_cache(maxsize=None)
def _tables(loop_weights: str) -> tuple:
    """The rules' weights by valence and sector size (:func:`_vertex_kernels.vertex_limits`):
    the smooth limit weight per (region, valence), the smooth tangent weights per (valence, j),
    the crease limit mask, the Loop crease sector's across weights (centre, ends) per size and
    its interior weights sin(πj/m)."""
    k = np.arange(MAX_LANE_VALENCE)
    w = np.stack([LR.smooth_limit_weight(k, np.full(len(k), R.REGION_SQRT3), loop_weights),
                  LR.smooth_limit_weight(k, np.full(len(k), R.REGION_LOOP), loop_weights)])
    kk, jj = np.meshgrid(np.maximum(k, 1), k, indexing="ij")
    c, s = LR.smooth_tangent_weights(kk, jj)
    a, b = LR.sector_across_weights(np.maximum(k, 1), "loop")
    out = (w, np.ascontiguousarray(c), np.ascontiguousarray(s), np.array(LR.CREASE_LIMIT_MASK),
           np.ascontiguousarray(np.stack([a, b], axis=1)), np.ascontiguousarray(np.sin(np.pi * jj / kk)))
    for t in out:
        t.flags.writeable = False
    return out


def _corner_slots(F: np.ndarray, n: int):
    """:func:`_vertex_kernels.corner_slots` into int32 arrays where the ids fit (half the
    memory to write and read), else int64."""
    dtype = np.int32 if max(n, len(F)) < 2**31 else np.int64
    A, B, face = (np.empty(3 * len(F), dtype) for _ in range(3))
    return VK.corner_slots(F, n, A, B, face), A, B, face


def _tags(li: LimitInput) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(n,) vertices the lane cannot take for their tags (a tagged corner, an end of a
    semi-sharp crease), and per vertex the infinitely sharp creases at it and their far ends
    (``_vertex_kernels.crease_neighbours``); "sqrt3" has none of them (only its boundary is
    sharp)."""
    n = li.n_vertices
    blocked = np.zeros(n, dtype=bool)
    count, nb = np.zeros(n, np.int64), np.full((n, 2), -1, np.int64)
    if li.scheme == "sqrt3":
        return blocked, count, nb
    pairs, sharpness = li.pairs, li.sharpness
    if len(pairs):
        blocked[pairs[(sharpness > 0) & np.isfinite(sharpness)].ravel()] = True
        count, nb = VK.crease_neighbours(np.ascontiguousarray(pairs, dtype=np.int64),
                                         np.ascontiguousarray(sharpness, dtype=np.float64), n)
    return blocked | (li.corner > 0), count, nb


def level_limits(li: LimitInput, X: np.ndarray, loop_weights: str, want_positions: bool, want_normals: bool,
                 crease_normals: str, tol: float, normal_tol: float, max_levels: int):
    """Limit positions and unit normals (each None unless wanted) of every vertex of the level
    evaluated, from its positions ``X`` (n, 3).

    The normal of a vertex with several sectors is the normalized mean of theirs, or
    (``crease_normals="one_side"``) OpenSubdiv's side, as :func:`hybridsub.limit_normals`;
    ``tol``, ``normal_tol`` and ``max_levels`` bound the local refinement of the vertices
    without stationary masks, as there.

    Examples
    --------
    >>> import numpy as np
    >>> from hybridsub._surface.limit_setup import walk_for_limit
    >>> V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    >>> li = walk_for_limit(V, F, [[0, 1]], 1, "hybrid", None, None, None, "loop")
    >>> P, N = level_limits(li, li.X, "loop", True, True, "average", 1e-12, 1e-10, 60)
    >>> P.shape, bool(np.allclose(np.linalg.norm(N, axis=1), 1))
    ((9, 3), True)
    """
    F = li.faces
    n = li.n_vertices
    X = np.ascontiguousarray(X, dtype=np.float64)
    start, A, B, face = _corner_slots(F, n)
    w, c, s, crease, across, half = _tables(loop_weights)
    blocked, count, nb = _tags(li)
    lane = VK.vertex_limits if use_threads(n) else VK.vertex_limits_serial
    P, N, done = lane(start, A, B, face, X, blocked, count, nb, li.face_sharp.view(np.uint8), w, c, s, crease, across,
                      half, want_normals, crease_normals == "one_side")
    G = np.flatnonzero(~done)
    if len(G):
        sub, used, local = local_setup(li, VK.faces_around(start, face, G, len(F)), np.diff(start))
        Xs = X[used]
        g = local[G]
        at_g = np.zeros(len(used), dtype=bool)
        at_g[g] = True
        plan = plan_vertices(sub.level, sub.esharp, sub.face_sharp, sub.corner, li.scheme, loop_weights, at_g)
        if want_positions:
            L, _, _ = evaluate_level(sub, li.scheme, loop_weights, None, True, tol, max_levels, only=at_g, plan=plan)
            P[G] = L[g] @ Xs
        if want_normals:
            _, _, nrm = evaluate_level(sub, li.scheme, loop_weights, Xs, False, normal_tol, max_levels, only=at_g,
                                       plan=plan)
            Ns = vertex_normals(sub.level, plan, nrm, Xs)
            if crease_normals == "one_side":
                first = one_side_sectors(sub.level, plan.sectors)
                used_s = first >= 0
                Ns[used_s] = nrm[first[used_s]]
            N[G] = Ns[g]
    return (P if want_positions else None), (N if want_normals else None)
