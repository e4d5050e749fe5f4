"""Numba kernels that carry a point's weights from its last patch to its first (the walk's
rows, onto the control vertices or applied to the data: :func:`back_rows`,
:func:`back_points`) and its data forward the other way (:func:`forward_points`, the
derivatives of deep points), through the steps the walk recorded (:mod:`.walk`).

Private. Contiguous arrays in, outputs allocated by the caller.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from .._jit import NO_PARFORS, kernel, threaded_and_serial
from ._walk_kernels import TASK

_U0, _U1 = np.uintp(0), np.uintp(1)


@kernel(inline="always")
def _back_any(buf, s, t, e, end, t_row, t_col, t_val):
    """``buf[t] += T^T buf[s]`` over the entries ``e:end`` of one transition, by rows: rows
    whose sums are all zero are skipped."""
    nr = buf.shape[2]
    src = buf[s]
    dst = buf[t]
    e = np.uintp(e)  # unsigned indices, as in _back_value
    end = np.uintp(end)
    while e < end:
        a = t_row[e]
        ua = np.uintp(a)
        live = False
        for r in range(nr):
            if src[ua, r] != 0.0:
                live = True
        if live:
            while e < end and t_row[e] == a:
                x = t_val[e]
                b = np.uintp(t_col[e])
                for r in range(nr):
                    dst[b, r] += src[ua, r] * x
                e += _U1
        else:
            while e < end and t_row[e] == a:
                e += _U1


@kernel(inline="always")
def _back3(buf, s, t, e, end, t_row, t_col, t_val):
    """:func:`_back_any` for three rows (value, ∂/∂u, ∂/∂v) held in registers: the same sums.
    Unsigned indices, as in :func:`_back_value`."""
    src = buf[s]
    dst = buf[t]
    rows = t_row[e:end]
    cols = t_col[e:end]
    vals = t_val[e:end]
    n = np.uintp(len(rows))
    i = _U0
    while i < n:
        a = rows[i]
        ua = np.uintp(a)
        r0 = src[ua, 0]
        r1 = src[ua, 1]
        r2 = src[ua, 2]
        if r0 != 0.0 or r1 != 0.0 or r2 != 0.0:
            while i < n and rows[i] == a:
                x = vals[i]
                b = np.uintp(cols[i])
                dst[b, 0] += r0 * x
                dst[b, 1] += r1 * x
                dst[b, 2] += r2 * x
                i += _U1
        else:
            while i < n and rows[i] == a:
                i += _U1


@kernel(inline="always")
def _back_one(q, buf, W, slots, block, stop, path, keys, nv, blk_v0, blk_c0, blk_nc, blk_col, blk_val, t_start, t_end,
              t_row, t_col, t_val):
    """Point ``q``'s rows (any number) over its first patch's vertices into ``buf[s]``;
    returns ``s``."""
    nr = W.shape[1]
    d = stop[q]
    s = 0
    ns = slots[q]
    for v in range(nv[keys[q, d]]):
        for r in range(nr):
            buf[0, v, r] = 0.0
    b = block[q]
    for k in range(blk_nc[b]):
        v = blk_col[blk_c0[b] + k]
        off = blk_v0[b] + k * ns
        for r in range(nr):
            acc = 0.0
            for j in range(ns):
                acc += W[q, r, j] * blk_val[off + j]
            buf[0, v, r] = acc
    for lev in range(d - 1, -1, -1):
        c = path[q, lev]
        t = 1 - s
        for v in range(nv[keys[q, lev]]):
            for r in range(nr):
                buf[t, v, r] = 0.0
        _back_any(buf, s, t, t_start[c], t_end[c], t_row, t_col, t_val)
        s = t
    return s


@kernel(inline="always")
def _back_value(q, buf, W, slots, block, stop, path, keys, nv, blk_v0, blk_c0, blk_nc, blk_col, blk_val, t_start, t_end,
                t_row, t_col, t_val):
    """:func:`_back_one` for the value row alone (``W`` (q, 1, ·)), its loops written for one
    row: the same sums, some 30% faster."""
    d = stop[q]
    ns = slots[q]
    for v in range(nv[keys[q, d]]):
        buf[0, v, 0] = 0.0
    b = block[q]
    for k in range(blk_nc[b]):
        off = blk_v0[b] + k * ns
        acc = 0.0
        for j in range(ns):
            acc += W[q, 0, j] * blk_val[off + j]
        buf[0, blk_col[blk_c0[b] + k], 0] = acc
    s = 0
    for lev in range(d - 1, -1, -1):
        c = path[q, lev]
        t = 1 - s
        src = buf[s, :, 0]
        dst = buf[t, :, 0]
        for v in range(nv[keys[q, lev]]):
            dst[v] = 0.0
        rows = t_row[t_start[c]:t_end[c]]
        cols = t_col[t_start[c]:t_end[c]]
        vals = t_val[t_start[c]:t_end[c]]
        n = np.uintp(len(rows))
        e = _U0
        # Unsigned indices: a signed one costs each access Numba's negative-index test (a
        # third of this loop's time).
        while e < n:
            a = rows[e]
            r0 = src[np.uintp(a)]
            if r0 != 0.0:
                while e < n and rows[e] == a:
                    dst[np.uintp(cols[e])] += r0 * vals[e]
                    e += _U1
            else:
                while e < n and rows[e] == a:
                    e += _U1
        s = t
    return s


@kernel(inline="always")
def _back_three(q, buf, W, slots, block, stop, path, keys, nv, blk_v0, blk_c0, blk_nc, blk_col, blk_val, t_start,
                t_end, t_row, t_col, t_val):
    """:func:`_back_one` for three rows (value, ∂/∂u, ∂/∂v), its loops written for them: the
    same sums."""
    d = stop[q]
    ns = slots[q]
    for v in range(nv[keys[q, d]]):
        buf[0, v, 0] = 0.0
        buf[0, v, 1] = 0.0
        buf[0, v, 2] = 0.0
    b = block[q]
    for k in range(blk_nc[b]):
        off = blk_v0[b] + k * ns
        a0 = a1 = a2 = 0.0
        for j in range(ns):
            x = blk_val[off + j]
            a0 += W[q, 0, j] * x
            a1 += W[q, 1, j] * x
            a2 += W[q, 2, j] * x
        v = blk_col[blk_c0[b] + k]
        buf[0, v, 0], buf[0, v, 1], buf[0, v, 2] = a0, a1, a2
    s = 0
    for lev in range(d - 1, -1, -1):
        c = path[q, lev]
        t = 1 - s
        for v in range(nv[keys[q, lev]]):
            buf[t, v, 0] = 0.0
            buf[t, v, 1] = 0.0
            buf[t, v, 2] = 0.0
        _back3(buf, s, t, t_start[c], t_end[c], t_row, t_col, t_val)
        s = t
    return s


@kernel(parallel=NO_PARFORS)
def _back_point(q, buf, W, slots, block, stop, path, keys, nv, blk_v0, blk_c0, blk_nc, blk_col, blk_val, t_start,
                t_end, t_row, t_col, t_val):
    """Point ``q``'s rows over its first patch's vertices into ``buf[s]``; returns ``s``. One
    and three rows have loops of their own (inside the general ones they ran at half the
    speed); all three give the same sums."""
    if W.shape[1] == 3:
        return _back_three(q, buf, W, slots, block, stop, path, keys, nv, blk_v0, blk_c0, blk_nc, blk_col, blk_val,
                           t_start, t_end, t_row, t_col, t_val)
    if W.shape[1] == 1:
        return _back_value(q, buf, W, slots, block, stop, path, keys, nv, blk_v0, blk_c0, blk_nc, blk_col, blk_val,
                           t_start, t_end, t_row, t_col, t_val)
    return _back_one(q, buf, W, slots, block, stop, path, keys, nv, blk_v0, blk_c0, blk_nc, blk_col, blk_val, t_start,
                     t_end, t_row, t_col, t_val)


@kernel(inline="always")
def _largest(stop, keys, nv):
    """The largest patch the points meet (vertices): the room a point's rows need."""
    nmax = 0
    for q in range(len(stop)):
        for lev in range(stop[q] + 1):
            nmax = max(nmax, nv[keys[q, lev]])
    return nmax


@kernel(parallel=NO_PARFORS)
def back_rows(W, slots, block, stop, path, keys, nv, blk_v0, blk_c0, blk_nc, blk_col, blk_val, t_start, t_end, t_row,
              t_col, t_val, out):
    """Every point's rows over its first patch's vertices: the weights ``W`` (q, r, 15) on its
    last patch's ``slots`` (q,) rows (stencil vertices' limit rows, or a quartic's
    coefficients) in the table's block ``block`` (q,) (``cache.PatchTable``'s ``blk_*``), then
    back through the steps.

    ``stop`` (q,) the level each point stopped at, ``path`` (q, d) the candidates chosen,
    ``keys`` (q, d + 1) the keys met; ``out`` (q, nv_max, r) zeroed by the caller.
    """
    buf = np.zeros((2, _largest(stop, keys, nv), W.shape[1]))  # this level's rows and the next's
    for q in range(len(stop)):
        s = _back_point(q, buf, W, slots, block, stop, path, keys, nv, blk_v0, blk_c0, blk_nc, blk_col, blk_val,
                        t_start, t_end, t_row, t_col, t_val)
        for v in range(nv[keys[q, 0]]):
            for r in range(W.shape[1]):
                out[q, v, r] = buf[s, v, r]


@kernel(inline="always")
def _gather33(q, rows, b, n, order, vids, X, res, at):
    """The last loop of :func:`_back_points` for three rows of three-column data, its nine
    sums in registers (``res`` is zero on entry): the same additions in the same order."""
    s00 = s01 = s02 = s10 = s11 = s12 = s20 = s21 = s22 = 0.0
    for k in range(n):
        loc = order[b + k]
        col = vids[b + loc]
        x0, x1, x2 = X[col, 0], X[col, 1], X[col, 2]
        a = rows[loc, 0]
        if a != 0.0:  # as walk_rows, which leaves zeros out of its matrices
            s00 += a * x0
            s01 += a * x1
            s02 += a * x2
        a = rows[loc, 1]
        if a != 0.0:
            s10 += a * x0
            s11 += a * x1
            s12 += a * x2
        a = rows[loc, 2]
        if a != 0.0:
            s20 += a * x0
            s21 += a * x1
            s22 += a * x2
    o = at[q]
    res[0, o, 0], res[0, o, 1], res[0, o, 2] = s00, s01, s02
    res[1, o, 0], res[1, o, 1], res[1, o, 2] = s10, s11, s12
    res[2, o, 0], res[2, o, 1], res[2, o, 2] = s20, s21, s22


def _back_points(W, slots, block, stop, path, keys, nv, blk_v0, blk_c0, blk_nc, blk_col, blk_val, t_start, t_end,
                 t_row, t_col, t_val, base, order, vids, X, res, at):
    """:func:`back_rows` times the data ``X`` (n, d): ``res[:, at[q]]`` ((r, ·, d), zeroed by
    the caller) gets ``R_r @ X`` for each point's rows ``R_r`` on the control vertices (its first patch's
    canonical vertex ``k`` is control vertex ``vids[base[q] + k]``; ``order[base[q]:]`` lists
    them by increasing id): the sums of the CSR product of ``walk.walk_rows``, term for term in
    its order (zeros left out, as there), so the same bits. Threaded over tasks of points
    (``back_points``; ``back_points_serial`` the same on one thread)."""
    nmax = _largest(stop, keys, nv)
    for task in prange((len(stop) + TASK - 1) // TASK):
        buf = np.zeros((2, nmax, W.shape[1]))  # this level's rows and the next's
        for q in range(task * TASK, min(len(stop), (task + 1) * TASK)):
            s = _back_point(q, buf, W, slots, block, stop, path, keys, nv, blk_v0, blk_c0, blk_nc, blk_col, blk_val,
                            t_start, t_end, t_row, t_col, t_val)
            if W.shape[1] == 3 and X.shape[1] == 3:
                _gather33(q, buf[s], base[q], nv[keys[q, 0]], order, vids, X, res, at)
            else:
                b = base[q]
                o = at[q]
                for k in range(nv[keys[q, 0]]):
                    loc = order[b + k]
                    col = vids[b + loc]
                    for r in range(W.shape[1]):
                        a = buf[s, loc, r]
                        if a != 0.0:  # as walk_rows, which leaves zeros out of its matrices
                            for d in range(X.shape[1]):
                                res[r, o, d] += a * X[col, d]


back_points, back_points_serial = threaded_and_serial(_back_points)


@kernel(parallel=NO_PARFORS)
def _forward_one(q, buf, W, slots, block, stop, path, keys, nv, blk_v0, blk_c0, blk_nc, blk_col, blk_val, t_start,
                 t_end, t_row, t_col, t_val, base, vids, X, S, res, first):
    """Rows ``first:`` of point ``q`` (derivatives: their weights sum to zero) applied to the
    data ``X`` forward: the first patch's data, each step's, the last patch's slots ``S``, each
    patch's data taken relative to its vertex 0, so that it keeps its precision however small
    the patch (carried back, the rows' weights grow like the inverse of the last face's size
    and cancel: a rounding error of 1e-16 becomes 1e-16 × 3^(depth/2))."""
    nd = X.shape[1]
    b = base[q]
    c0 = vids[b]
    for v in range(nv[keys[q, 0]]):
        col = vids[b + v]
        for k in range(nd):
            buf[0, v, k] = X[col, k] - X[c0, k]
    s = 0
    for lev in range(stop[q]):
        c = path[q, lev]
        t = 1 - s
        n1 = nv[keys[q, lev + 1]]
        for v in range(n1):
            for k in range(nd):
                buf[t, v, k] = 0.0
        src = buf[s]
        dst = buf[t]
        e = np.uintp(t_start[c])
        end = np.uintp(t_end[c])
        while e < end:  # unsigned indices, as in _back_value
            a, p, x = np.uintp(t_row[e]), np.uintp(t_col[e]), t_val[e]
            for k in range(nd):
                dst[a, k] += x * src[p, k]
            e += _U1
        for k in range(nd):
            o = buf[t, 0, k]
            for v in range(n1):
                buf[t, v, k] -= o
        s = t
    ns = slots[q]
    for j in range(ns):
        for k in range(nd):
            S[j, k] = 0.0
    bk = block[q]
    for i in range(blk_nc[bk]):
        v = blk_col[blk_c0[bk] + i]
        off = blk_v0[bk] + i * ns
        for j in range(ns):
            x = blk_val[off + j]
            for k in range(nd):
                S[j, k] += x * buf[s, v, k]
    for r in range(first, W.shape[1]):
        for k in range(nd):
            acc = 0.0
            for j in range(ns):
                acc += W[q, r, j] * S[j, k]
            res[r, q, k] = acc


def _forward_points(W, slots, block, stop, path, keys, nv, blk_v0, blk_c0, blk_nc, blk_col, blk_val, t_start, t_end,
                    t_row, t_col, t_val, base, vids, X, res, first):
    """``res[first:]`` (r, q, d) of :func:`back_points` computed forward (:func:`_forward_one`):
    the derivatives of ``evaluate``, exact to rounding at any depth. Threaded over tasks of
    points (``forward_points``; ``forward_points_serial`` the same on one thread)."""
    nmax = _largest(stop, keys, nv)
    for task in prange((len(stop) + TASK - 1) // TASK):
        buf = np.zeros((2, nmax, X.shape[1]))
        S = np.zeros((W.shape[2], X.shape[1]))
        for q in range(task * TASK, min(len(stop), (task + 1) * TASK)):
            _forward_one(q, buf, W, slots, block, stop, path, keys, nv, blk_v0, blk_c0, blk_nc, blk_col, blk_val,
                         t_start, t_end, t_row, t_col, t_val, base, vids, X, S, res, first)


forward_points, forward_points_serial = threaded_and_serial(_forward_points)
