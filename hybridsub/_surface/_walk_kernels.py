"""Numba kernels of the walk through the patch cache (:mod:`.walk`): the child choice, the
last interpolation, regular patches' quartics and regular input faces (the rows carried back
and the data carried forward: :mod:`._carry_kernels`).

Private. Contiguous arrays in, outputs allocated by the caller.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from .._jit import kernel, threaded_and_serial

#: Candidates whose smallest barycentric coordinates differ by less are a tie.
TIE = 1e-14
#: A point whose smallest barycentric coordinate in a candidate is above this is inside it,
#: and no later candidate can be chosen (the children tile the patch: theirs are <= 0).
INSIDE = 1e-9
#: A point whose largest barycentric coordinate is this close to 1 is that vertex: the last
#: interpolation gives it the vertex's limit position exactly.
AT_VERTEX = 1e-14
#: Points per task of the threaded kernels (each point is independent of the others).
TASK = 64


@kernel(inline="always")
def _pick_one(q, k, bary, grad, cand_start, cand_count, M, b):
    """Point ``q``'s child face among key ``k``'s candidates (the largest smallest barycentric
    coordinate; the first of those equal to ``TIE``, so a point on an edge stays on the
    centre face's side): its coordinates there and their derivatives in (u, v) replace
    ``bary[q]`` and ``grad[q]`` (3, 2). ``M`` (c, 3, 3) takes a point's barycentric
    coordinates into each candidate's, so it takes their derivatives too. Returns the
    candidate."""
    s = cand_start[k]
    best = -np.inf
    chosen = -1
    nb0 = nb1 = nb2 = 0.0
    for j in range(s, s + cand_count[k]):
        lo = np.inf
        for i in range(3):
            b[i] = M[j, i, 0] * bary[q, 0] + M[j, i, 1] * bary[q, 1] + M[j, i, 2] * bary[q, 2]
            lo = min(lo, b[i])
        if lo > best + TIE:
            best = lo
            chosen = j
            nb0, nb1, nb2 = b[0], b[1], b[2]
            if lo > INSIDE:  # inside this child: the others, which tile round it, have lo <= 0
                break
    j = chosen
    bary[q, 0], bary[q, 1], bary[q, 2] = nb0, nb1, nb2
    # Relative, not the child's corners in (u, v): those differ by less than a rounding
    # error on the slivers that grow along creases at the depths points there are taken to.
    for d in range(2):
        for a in range(3):
            b[a] = M[j, a, 0] * grad[q, 0, d] + M[j, a, 1] * grad[q, 1, d] + M[j, a, 2] * grad[q, 2, d]
        for a in range(3):
            grad[q, a, d] = b[a]
    return j


def _walk_known(todo, level, state, keys, path, stop, bary, grad, cand_start, cand_count, M, child, regular,
                stop_regular, depth, at_vertex, vertex_stop, every):
    """The walk (``walk._descend``) of the points ``todo`` as far as the table knows the way.

    Point ``q`` is at ``level[q]`` on key ``keys[q, level[q]]`` (``state[q]`` 1: it has
    chosen ``path[q, level[q]]`` there, whose child patch was not cut yet). It goes down,
    choosing a child per level (``_pick_one``), to ``depth[q]`` or (with ``stop_regular``) to
    the first regular key, and then ``stop[q]`` is set and ``state[q]`` 0; or it halts at a
    key whose candidates are not known (``state[q]`` 2) or at a candidate whose child patch is
    not cut (``state[q]`` 1) for the caller to fill the table and call again.
    ``at_vertex[q]`` (−1 on the first call) gets the first level (a multiple of ``every``:
    2 for Kobbelt's boundary, whose limits are taken at even levels) where the point is a
    vertex of its face (``AT_VERTEX``); with ``vertex_stop`` it stops there, its value being
    that vertex's limit position. Threaded over tasks of points (``walk_known``;
    ``walk_known_serial`` the same on one thread)."""
    for task in prange((len(todo) + TASK - 1) // TASK):
        b = np.empty(3)
        for i in range(task * TASK, min(len(todo), (task + 1) * TASK)):
            q = todo[i]
            lev = level[q]
            if state[q] == 1:
                keys[q, lev + 1] = child[path[q, lev]]
                lev += 1
            state[q] = 0
            while True:
                k = keys[q, lev]
                if (at_vertex[q] < 0 and lev % every == 0
                        and max(bary[q, 0], bary[q, 1], bary[q, 2]) >= 1.0 - AT_VERTEX):
                    at_vertex[q] = lev
                    if vertex_stop:
                        stop[q] = lev
                        break
                if (stop_regular and regular[k] == 1) or lev == depth[q]:
                    stop[q] = lev
                    break
                if cand_start[k] < 0:
                    state[q] = 2
                    break
                j = _pick_one(q, k, bary, grad, cand_start, cand_count, M, b)
                path[q, lev] = j
                if child[j] < 0:
                    state[q] = 1
                    break
                keys[q, lev + 1] = child[j]
                lev += 1
            level[q] = lev


walk_known, walk_known_serial = threaded_and_serial(_walk_known)


@kernel
def stencil_points(rec, bary, grad, inv, full, node, W):
    """``descent.stencil_weights`` per point from a stencil record ``rec``: ``inv`` (s, 6, 6)
    the inverse of each record's interpolation matrix, ``full`` whether it is used (else
    linear), ``node`` (s, 9) the face's centroid (2), size (1) and corners (6). Fills ``W``
    (q, r, 6): value, ∂/∂u, ∂/∂v, ∂²/∂u², ∂²/∂u∂v, ∂²/∂v², the first r of them."""
    nr = W.shape[1]
    rhs = np.empty((6, 6))
    w = np.empty((6, 6))
    J = np.empty((2, 2))
    for q in range(len(rec)):
        k = rec[q]
        sc = node[k, 2]
        xs = (bary[q, 0] * node[k, 3] + bary[q, 1] * node[k, 5] + bary[q, 2] * node[k, 7] - node[k, 0]) / sc
        xt = (bary[q, 0] * node[k, 4] + bary[q, 1] * node[k, 6] + bary[q, 2] * node[k, 8] - node[k, 1]) / sc
        e1s, e1t = node[k, 5] / sc - node[k, 3] / sc, node[k, 6] / sc - node[k, 4] / sc
        e2s, e2t = node[k, 7] / sc - node[k, 3] / sc, node[k, 8] / sc - node[k, 4] / sc
        w[:] = 0.0
        if full[k]:
            rhs[:] = 0.0
            rhs[0, 0], rhs[1, 0], rhs[2, 0], rhs[3, 0], rhs[4, 0], rhs[5, 0] = 1.0, xs, xt, xs * xs, xs * xt, xt * xt
            rhs[1, 1], rhs[3, 1], rhs[4, 1] = 1.0, 2 * xs, xt
            rhs[2, 2], rhs[4, 2], rhs[5, 2] = 1.0, xs, 2 * xt
            rhs[3, 3], rhs[4, 4], rhs[5, 5] = 2.0, 1.0, 2.0
            for i in range(6):  # w = A⁻ᵀ rhs
                for c in range(6):
                    acc = 0.0
                    for j in range(6):
                        acc += inv[k, j, i] * rhs[j, c]
                    w[i, c] = acc
        else:  # linear: rows of the inverse of (e1 e2) are d bary1,2 / d(s, t)
            det = e1s * e2t - e2s * e1t
            w[0, 0], w[1, 0], w[2, 0] = bary[q, 0], bary[q, 1], bary[q, 2]
            w[1, 1], w[1, 2] = e2t / det, -e2s / det
            w[2, 1], w[2, 2] = -e1t / det, e1s / det
            w[0, 1], w[0, 2] = -(w[1, 1] + w[2, 1]), -(w[1, 2] + w[2, 2])
        top = 0
        for c in range(1, 3):
            if bary[q, c] > bary[q, top]:
                top = c
        if bary[q, top] >= 1.0 - AT_VERTEX:  # at a vertex: its limit position exactly
            for i in range(6):
                w[i, 0] = 0.0
            w[top, 0] = 1.0
        # J = ∂(s,t)/∂(u,v) = (e1 e2) ∂(b1, b2)/∂(u, v)
        i00, i01, i10, i11 = grad[q, 1, 0], grad[q, 1, 1], grad[q, 2, 0], grad[q, 2, 1]
        J[0, 0], J[0, 1] = e1s * i00 + e2s * i10, e1s * i01 + e2s * i11
        J[1, 0], J[1, 1] = e1t * i00 + e2t * i10, e1t * i01 + e2t * i11
        for i in range(6):
            W[q, 0, i] = w[i, 0]
            if nr > 1:
                W[q, 1, i] = w[i, 1] * J[0, 0] + w[i, 2] * J[1, 0]
                W[q, 2, i] = w[i, 1] * J[0, 1] + w[i, 2] * J[1, 1]
            if nr > 3:
                for o, (r1, r2) in enumerate(((0, 0), (0, 1), (1, 1))):
                    acc = 0.0
                    for p in range(2):
                        for s in range(2):
                            acc += J[p, r1] * w[i, 3 + p + s] * J[s, r2]
                    W[q, 3 + o, i] = acc


@kernel
def quartic_points(bary, grad, exps, coef, W):
    """``regular.polynomial_weights``: the quartic Bernstein basis ``coef`` · b^``exps`` (15)
    at every point and its derivatives in (u, v) (``grad`` (q, 3, 2) ∂b/∂(u, v)), into
    ``W`` (q, r, 15): value, ∂/∂u, ∂/∂v, ∂²/∂u², ∂²/∂u∂v, ∂²/∂v², the first r of them."""
    nr = W.shape[1]
    pw = np.zeros((3, 7))  # pw[c, p + 2] = b_c ** p, zero for p < 0
    G = np.empty((2, 2))
    for q in range(len(bary)):
        for c in range(3):
            pw[c, 2] = 1.0
            for p in range(1, 5):
                pw[c, p + 2] = pw[c, p + 1] * bary[q, c]
        G[0, 0], G[0, 1], G[1, 0], G[1, 1] = grad[q, 1, 0], grad[q, 1, 1], grad[q, 2, 0], grad[q, 2, 1]
        for t in range(15):
            i, j, k = exps[t, 0], exps[t, 1], exps[t, 2]
            f = coef[t]
            W[q, 0, t] = f * pw[0, i + 2] * pw[1, j + 2] * pw[2, k + 2]
            if nr == 1:
                continue
            d1 = f * (j * pw[0, i + 2] * pw[1, j + 1] * pw[2, k + 2] - i * pw[0, i + 1] * pw[1, j + 2] * pw[2, k + 2])
            d2 = f * (k * pw[0, i + 2] * pw[1, j + 2] * pw[2, k + 1] - i * pw[0, i + 1] * pw[1, j + 2] * pw[2, k + 2])
            W[q, 1, t] = d1 * G[0, 0] + d2 * G[1, 0]
            W[q, 2, t] = d1 * G[0, 1] + d2 * G[1, 1]
            if nr == 3:
                continue
            t00 = i * (i - 1) * pw[0, i] * pw[1, j + 2] * pw[2, k + 2]
            h11 = f * (j * (j - 1) * pw[0, i + 2] * pw[1, j] * pw[2, k + 2]
                       - 2 * i * j * pw[0, i + 1] * pw[1, j + 1] * pw[2, k + 2] + t00)
            h12 = f * (j * k * pw[0, i + 2] * pw[1, j + 1] * pw[2, k + 1]
                       - i * k * pw[0, i + 1] * pw[1, j + 2] * pw[2, k + 1]
                       - i * j * pw[0, i + 1] * pw[1, j + 1] * pw[2, k + 2] + t00)
            h22 = f * (k * (k - 1) * pw[0, i + 2] * pw[1, j + 2] * pw[2, k]
                       - 2 * i * k * pw[0, i + 1] * pw[1, j + 2] * pw[2, k + 1] + t00)
            for o in range(3):
                r1, r2 = (0, 0) if o == 0 else ((0, 1) if o == 1 else (1, 1))
                W[q, 3 + o, t] = (G[0, r1] * h11 * G[0, r2] + G[0, r1] * h12 * G[1, r2]
                                  + G[1, r1] * h12 * G[0, r2] + G[1, r1] * h22 * G[1, r2])


@kernel
def regular_rings(F, twin, hsharp, face_sharp, corner, out):
    """The twelve control vertices of every regular face (``regular.is_regular`` at level 0,
    interior: each corner untagged with six Loop faces and no crease): its corners, then
    each corner's other neighbours going round it (across the edge coming in to it) from the
    face, each vertex once. ``out`` (m, 12) gets them, −1 rows for the other faces."""
    ring = np.empty(12, np.int64)
    for f in range(len(F)):
        out[f, :] = -1
        n = 3
        for c in range(3):
            ring[c] = F[f, c]
        ok = face_sharp[f]
        for c in range(3):
            v = F[f, c]
            if corner[v]:
                ok = False
            g, cc = f, c
            faces = 0
            while ok:
                w = F[g, (cc + 1) % 3]
                seen = False
                for i in range(n):
                    if ring[i] == w:
                        seen = True
                if not seen:
                    if n == 12:
                        ok = False
                        break
                    ring[n] = w
                    n += 1
                h_in = 3 * g + (cc + 2) % 3
                t = twin[h_in]
                if t < 0 or hsharp[h_in] != 0.0 or hsharp[3 * g + cc] != 0.0 or not face_sharp[g]:
                    ok = False
                    break
                g, cc = t // 3, t % 3
                faces += 1
                if g == f or faces > 6:
                    break
            if faces != 6 or g != f:
                ok = False
        if ok and n == 12:
            for i in range(12):
                out[f, i] = ring[i]


@kernel(inline="always")
def _ring_one(q, W, C, rings, perm, val):
    """Point ``q`` on a regular face: ``perm`` (12,) the order of its control vertices by
    increasing id, ``val`` (r, 12) its rows' values in that order (``W`` (q, r, 15) its
    weights on the quartic's coefficients, ``C`` (15, 12) the coefficients over the face's
    twelve control vertices ``rings`` (q, 12))."""
    for i in range(12):  # insertion sort of the twelve ids
        k = i
        while k > 0 and rings[q, perm[k - 1]] > rings[q, i]:
            perm[k] = perm[k - 1]
            k -= 1
        perm[k] = i
    for i in range(12):
        k = perm[i]
        for r in range(W.shape[1]):
            acc = 0.0
            for j in range(15):
                acc += W[q, r, j] * C[j, k]
            val[r, i] = acc


@kernel
def ring_rows(W, C, rings, ids, vals):
    """Rows of points on regular faces (:func:`_ring_one`): ``ids`` (q, 12) each point's
    control vertices by increasing id, ``vals`` (r, q, 12) its rows' values there."""
    perm = np.empty(12, np.int64)
    val = np.empty((W.shape[1], 12))
    for q in range(len(rings)):
        _ring_one(q, W, C, rings, perm, val)
        for i in range(12):
            ids[q, i] = rings[q, perm[i]]
            for r in range(W.shape[1]):
                vals[r, q, i] = val[r, i]


@kernel
def ring_points(W, C, rings, X, res, at):
    """:func:`ring_rows` times the data ``X`` (n, d): ``res[:, at[q]]`` ((r, ·, d), zeroed by
    the caller) gets the sums of the CSR product of those rows (zeros left out), term for term
    in its order."""
    perm = np.empty(12, np.int64)
    val = np.empty((W.shape[1], 12))
    for q in range(len(rings)):
        _ring_one(q, W, C, rings, perm, val)
        for i in range(12):
            col = rings[q, perm[i]]
            for r in range(W.shape[1]):
                if val[r, i] != 0.0:  # as walk._ring_rows, which leaves zeros out
                    for d in range(X.shape[1]):
                        res[r, at[q], d] += val[r, i] * X[col, d]
