"""Numba kernels of one step's stencils: S applied to data directly, S assembled as CSR, and
a CSR product.

Private. Same conventions as the topology kernels (contiguous arrays and scalars in, outputs
allocated by the caller, ``stencils``). Rows: each old vertex (itself, then its neighbours in
edge order), then the edge points in edge order, then the face points. ``apply_step`` and
``matrix_row_sizes`` / ``fill_matrix`` walk them identically, so ``apply_step(X) == S @ X``
bit for bit. The vertex rows read the four coefficients of ``vertex_coefficients``; edge
points take ``_rules.edge_weights``; face points are centroids.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from .._jit import NO_PARFORS, kernel, threaded_and_serial
from .._prefetch import prefetch
from .._rules.step_rules import EDGE_TRISECT, KOBBELT_TRISECTION, edge_weights
from .._topology import dest, edge_sharpness, opposite, origin, owned_edge, owned_ends_in
from ._simd import lane, madd4, vzero

_T0, _T1, _T2 = KOBBELT_TRISECTION
_THIRD = 1.0 / 3.0
_U1, _U2, _U3, _U4 = np.uintp(1), np.uintp(2), np.uintp(3), np.uintp(4)  # unsigned offsets: no negative-index test
_ROW_AHEAD = 16  # entries of A between prefetching a row of B and reading it
_AHEAD = 32  # halfedges between a prefetch and its use (docs/performance.md, "Kernel design")


@kernel(inline="always")
def _prefetch_edge_point_reads(h, F, twin, edge_point, X):
    """Prefetch what the edge point of halfedge ``h + _AHEAD`` reads across its edge (the
    far face's vertex of ``X``), and the far face of ``h + 2 _AHEAD`` (for that read): a
    chain of two loads that miss the caches, as faces across an edge lie anywhere in ``F``.
    Edges without a point (flipped) are skipped."""
    n_half = twin.shape[0]
    far = h + 2 * _AHEAD
    if far < n_half and edge_point[far] >= 0 and twin[far] > far:
        prefetch(F, twin[far])
    near = h + _AHEAD
    if near < n_half and edge_point[near] >= 0 and twin[near] > near:
        prefetch(X, X.shape[1] * opposite(F, twin[near]))


@kernel(inline="always")
def _has_edge_points(face_point, n, n_new):
    """Whether a step of ``n`` old vertices and ``n_new`` in all makes edge points: they are
    numbered before the face points, so the first face point says how many there are (√3's
    steps have none but on a boundary, and their edge loop is then skipped)."""
    for f in range(face_point.shape[0]):
        if face_point[f] >= 0:
            return face_point[f] > n
    return n_new > n


# Rows of the step's data, X[·] weighted, each column summed left to right as written (the
# bits of the loop over columns); three columns unrolled, with unsigned indices (Numba tests
# a signed index for a negative value on every access; docs/performance.md, "Kernel design").


@kernel(inline="always")
def _sum1(out, r, wa, a, X):
    """``out[r] = wa * X[a]``."""
    if X.shape[1] == 3:
        ur, ua = np.uintp(r), np.uintp(a)
        for j in range(3):
            out[ur, j] = wa * X[ua, j]
    else:
        for j in range(X.shape[1]):
            out[r, j] = wa * X[a, j]


@kernel(inline="always")
def _add1(out, r, wa, a, X):
    """``out[r] += wa * X[a]``."""
    if X.shape[1] == 3:
        ur, ua = np.uintp(r), np.uintp(a)
        for j in range(3):
            out[ur, j] += wa * X[ua, j]
    else:
        for j in range(X.shape[1]):
            out[r, j] += wa * X[a, j]


@kernel(inline="always")
def _sum2(out, r, wa, a, wb, b, X):
    """``out[r] = wa * X[a] + wb * X[b]``."""
    if X.shape[1] == 3:
        ur, ua, ub = np.uintp(r), np.uintp(a), np.uintp(b)
        for j in range(3):
            out[ur, j] = wa * X[ua, j] + wb * X[ub, j]
    else:
        for j in range(X.shape[1]):
            out[r, j] = wa * X[a, j] + wb * X[b, j]


@kernel(inline="always")
def _sum3(out, r, wa, a, wb, b, wc, c, X):
    """``out[r] = wa * X[a] + wb * X[b] + wc * X[c]``."""
    if X.shape[1] == 3:
        ur, ua, ub, uc = np.uintp(r), np.uintp(a), np.uintp(b), np.uintp(c)
        for j in range(3):
            out[ur, j] = wa * X[ua, j] + wb * X[ub, j] + wc * X[uc, j]
    else:
        for j in range(X.shape[1]):
            out[r, j] = wa * X[a, j] + wb * X[b, j] + wc * X[c, j]


@kernel(inline="always")
def _sum4(out, r, wa, a, wb, b, wc, c, wd, d, X):
    """``out[r] = wa * X[a] + wb * X[b] + wc * X[c] + wd * X[d]``."""
    if X.shape[1] == 3:
        ur, ua, ub, uc, ud = np.uintp(r), np.uintp(a), np.uintp(b), np.uintp(c), np.uintp(d)
        for j in range(3):
            out[ur, j] = wa * X[ua, j] + wb * X[ub, j] + wc * X[uc, j] + wd * X[ud, j]
    else:
        for j in range(X.shape[1]):
            out[r, j] = wa * X[a, j] + wb * X[b, j] + wc * X[c, j] + wd * X[d, j]


@kernel(inline="always")
def _neighbour_coefficient(v, s, coef):
    """Vertex ``v``'s weight of its neighbour across an edge of sharpness ``s``. The vertex
    pass of :func:`_apply_step` tests ``s == 0.0`` (most edges) before calling it: the same
    test in here compiles to a slower loop."""
    c = coef[1, v]
    if s > 0.0:
        c += coef[2, v]
        if s > 1.0:
            c += coef[3, v]
    return c


def _apply_step(X, F, twin, hsharp, has_tags, hkind, edge_point, face_point, coef, bnext, bprev, out, chunks, fetch):
    """Fill ``out`` (n_new, k) with the next level's data ``S @ X``, without forming S.

    Old vertices gather from their neighbours in edge order. ``chunks`` threads each take
    one range of vertices and walk all edges, keeping their own vertices' terms, so every
    vertex is summed in the same order whatever the number of threads. Edge and face
    points, one row each, are computed in parallel.
    """
    n = coef.shape[1]
    m = F.shape[0]
    for c in prange(chunks):
        lo = c * n // chunks
        hi = (c + 1) * n // chunks
        for v in range(lo, hi):
            _sum1(out, v, coef[0, v], v, X)
        for f in range(m):
            for i in range(3):
                u, w, mine_u, mine_w = owned_ends_in(F, twin, f, i, lo, hi)
                if not (mine_u or mine_w):
                    continue
                s = edge_sharpness(3 * f + i, twin, hsharp, has_tags)
                if mine_u:
                    cu = coef[1, u] if s == 0.0 else _neighbour_coefficient(u, s, coef)
                    if cu != 0.0:
                        _add1(out, u, cu, w, X)
                if mine_w:
                    cw = coef[1, w] if s == 0.0 else _neighbour_coefficient(w, s, coef)
                    if cw != 0.0:
                        _add1(out, w, cw, u, X)
    n_half = 3 * m if _has_edge_points(face_point, n, out.shape[0]) else 0  # (prange(a if c else b) runs serially)
    # one thread runs the serial twin, where these loops are plain ones
    for h in prange(n_half):
        _edge_point_row(h, X, F, twin, hsharp, has_tags, hkind, edge_point, bnext, bprev, out, fetch)
    for f in prange(m):
        _face_point_row(f, X, F, face_point, out)


@kernel(inline="always")
def _edge_point_row(h, X, F, twin, hsharp, has_tags, hkind, edge_point, bnext, bprev, out, fetch):
    """The row of the edge point(s) of halfedge ``h``'s edge, if ``h`` owns one."""
    if fetch:
        _prefetch_edge_point_reads(h, F, twin, edge_point, X)
    r = edge_point[h]
    t = twin[h]
    if r < 0 or (t >= 0 and t < h):
        return
    u = origin(F, h)
    w = dest(F, h)
    if hkind[h] == EDGE_TRISECT:
        p0 = origin(F, bprev[h])
        p3 = dest(F, bnext[h])
        _sum3(out, r, _T0, p0, _T1, u, _T2, w, X)
        _sum3(out, r + 1, _T2, u, _T1, w, _T0, p3, X)
        return
    wab, wcd = edge_weights(edge_sharpness(h, twin, hsharp, has_tags))
    if wcd == 0.0:
        _sum2(out, r, wab, u, wab, w, X)
    else:
        _sum4(out, r, wab, u, wab, w, wcd, opposite(F, h), wcd, opposite(F, t), X)


@kernel(inline="always")
def _face_point_row(f, X, F, face_point, out):
    """The row of face ``f``'s point, if it has one: the centroid."""
    r = face_point[f]
    if r >= 0:
        _sum3(out, r, _THIRD, F[f, 0], _THIRD, F[f, 1], _THIRD, F[f, 2], X)


apply_step, apply_step_serial = threaded_and_serial(_apply_step)


@kernel(parallel=NO_PARFORS)
def matrix_row_sizes(F, twin, hsharp, has_tags, hkind, edge_point, face_point, coef, bnext, bprev, indptr):
    """Fill ``indptr`` (n_new + 1, zeroed) with the CSR row offsets of the step's matrix."""
    n = coef.shape[1]
    m = F.shape[0]
    n_new = indptr.shape[0] - 1
    for v in range(n):
        indptr[v + 1] = 1
    for f in range(m):
        for i in range(3):
            h, u, w = owned_edge(F, twin, f, i)
            if h < 0:
                continue
            s = edge_sharpness(h, twin, hsharp, has_tags)
            if _neighbour_coefficient(u, s, coef) != 0.0:
                indptr[u + 1] += 1
            if _neighbour_coefficient(w, s, coef) != 0.0:
                indptr[w + 1] += 1
            r = edge_point[h]
            if r < 0:
                continue
            if hkind[h] == EDGE_TRISECT:
                indptr[r + 1] = 3
                indptr[r + 2] = 3
            else:
                indptr[r + 1] = 2 if edge_weights(s)[1] == 0.0 else 4
    for f in range(m):
        if face_point[f] >= 0:
            indptr[face_point[f] + 1] = 3
    for r in range(n_new):
        indptr[r + 1] += indptr[r]


@kernel(parallel=NO_PARFORS)
def fill_matrix(F, twin, hsharp, has_tags, hkind, edge_point, face_point, coef, bnext, bprev, indptr,
                indices, data):
    """Fill the CSR ``indices`` and ``data`` of the step's matrix, rows in apply_step's order."""
    n = coef.shape[1]
    m = F.shape[0]
    fill = indptr[:n].copy()
    for v in range(n):
        indices[fill[v]] = v
        data[fill[v]] = coef[0, v]
        fill[v] += 1
    for f in range(m):
        for i in range(3):
            h, u, w = owned_edge(F, twin, f, i)
            if h < 0:
                continue
            s = edge_sharpness(h, twin, hsharp, has_tags)
            c = _neighbour_coefficient(u, s, coef)
            if c != 0.0:
                indices[fill[u]] = w
                data[fill[u]] = c
                fill[u] += 1
            c = _neighbour_coefficient(w, s, coef)
            if c != 0.0:
                indices[fill[w]] = u
                data[fill[w]] = c
                fill[w] += 1
            r = edge_point[h]
            if r >= 0:
                _fill_edge_row(indptr[r], h, u, w, s, F, twin, hkind, bnext, bprev, indices, data)
    for f in range(m):
        r = face_point[f]
        if r >= 0:
            q = indptr[r]
            for i in range(3):
                indices[q + i] = F[f, i]
                data[q + i] = _THIRD


@kernel(inline="always")
def _fill_edge_row(q, h, u, w, s, F, twin, hkind, bnext, bprev, indices, data):
    """The CSR entries, from ``q``, of the edge point(s) of halfedge ``h`` = u→w."""
    if hkind[h] == EDGE_TRISECT:
        indices[q] = origin(F, bprev[h])
        indices[q + 1] = u
        indices[q + 2] = w
        indices[q + 3] = u
        indices[q + 4] = w
        indices[q + 5] = dest(F, bnext[h])
        data[q] = _T0
        data[q + 1] = _T1
        data[q + 2] = _T2
        data[q + 3] = _T2
        data[q + 4] = _T1
        data[q + 5] = _T0
        return
    wab, wcd = edge_weights(s)
    indices[q] = u
    indices[q + 1] = w
    data[q] = wab
    data[q + 1] = wab
    if wcd != 0.0:
        indices[q + 2] = opposite(F, h)
        indices[q + 3] = opposite(F, twin[h])
        data[q + 2] = wcd
        data[q + 3] = wcd


def _csr_apply(indptr, indices, data, X, out):
    """``out = S @ X`` for CSR S, rows in parallel, each summed in stored order (as SciPy)."""
    k = X.shape[1]
    for r in prange(indptr.shape[0] - 1):
        for j in range(k):
            out[r, j] = 0.0
        for q in range(indptr[r], indptr[r + 1]):
            c = indices[q]
            w = data[q]
            for j in range(k):
                out[r, j] += w * X[c, j]


csr_apply, csr_apply_serial = threaded_and_serial(_csr_apply)


@kernel(inline="always")
def _prefetch_b_row(q, a_indices, b_indptr, b_indices, b_data):
    """Prefetch the row of B that entry ``q + _ROW_AHEAD`` of A reads (its columns and
    weights), and where the row of entry ``q + 2 _ROW_AHEAD`` starts: A's columns pick B's
    rows all over B, each found through ``b_indptr`` (two loads that miss, one on the other)."""
    far = q + np.uintp(2 * _ROW_AHEAD)
    if far < a_indices.shape[0]:
        prefetch(b_indptr, a_indices[far])
    near = q + np.uintp(_ROW_AHEAD)
    if near < a_indices.shape[0]:
        start = b_indptr[a_indices[near]]
        prefetch(b_indices, start)
        prefetch(b_data, start)


@kernel
def product_bound(a_indptr, a_indices, b_indptr, n_cols):
    """Entries ``A @ B`` can have at most (CSR patterns): row i of the product has at most
    ``sum(nnz(B[j]) for j in A[i])`` entries, and at most ``n_cols``."""
    total = 0
    for i in range(len(a_indptr) - 1):
        row = 0
        for q in range(a_indptr[i], a_indptr[i + 1]):
            j = a_indices[q]
            row += b_indptr[j + 1] - b_indptr[j]
        total += min(row, n_cols)
    return total


@kernel(parallel=True)
def product_pattern(a_indptr, a_indices, b_indptr, b_indices, n_cols, chunks, counts, fetch):
    """``counts[i]``: the distinct columns of row i of ``A @ B`` (CSR patterns), ``chunks``
    ranges of rows in parallel."""
    m = len(a_indptr) - 1
    for c in prange(chunks):
        mark = np.full(n_cols, -1, np.int32)
        for i in range(c * m // chunks, (c + 1) * m // chunks):
            n = 0
            i32 = np.int32(i)
            for q in range(np.uintp(a_indptr[i]), np.uintp(a_indptr[i + 1])):
                if fetch:
                    _prefetch_b_row(q, a_indices, b_indptr, b_indices, b_indices)
                j = np.uintp(a_indices[q])
                for p in range(np.uintp(b_indptr[j]), np.uintp(b_indptr[j + _U1])):
                    k = np.uintp(b_indices[p])
                    if mark[k] != i32:
                        mark[k] = i32
                        n += 1
            counts[i] = n


@kernel(parallel=True)
def product_fill(a_indptr, a_indices, a_data, b_indptr, b_indices, b_data, n_cols, chunks, c_indptr, c_indices,
                 c_data, kept, fetch):
    """Row i of ``A @ B`` into ``c_indices``, ``c_data`` from ``c_indptr[i]``, columns sorted,
    the sums that are exactly zero dropped (``kept[i]`` entries left), as SciPy's product
    followed by ``sort_indices``: each sum starts at zero and adds ``A[i, j] * B[j, k]`` in
    the order of A's row, then of B's rows, so it has SciPy's bits."""
    m = len(a_indptr) - 1
    for c in prange(chunks):
        sums = np.zeros(n_cols)
        mark = np.full(n_cols, -1, np.int32)
        for i in range(c * m // chunks, (c + 1) * m // chunks):
            o = np.uintp(c_indptr[i])
            n = np.uintp(0)
            i32 = np.int32(i)
            for q in range(np.uintp(a_indptr[i]), np.uintp(a_indptr[i + 1])):
                if fetch:
                    _prefetch_b_row(q, a_indices, b_indptr, b_indices, b_data)
                j = np.uintp(a_indices[q])
                v = a_data[q]
                for p in range(np.uintp(b_indptr[j]), np.uintp(b_indptr[j + _U1])):
                    k = np.uintp(b_indices[p])
                    sums[k] += v * b_data[p]
                    if mark[k] != i32:
                        mark[k] = i32
                        c_indices[o + n] = k
                        n += _U1
            for t in range(o + _U1, o + n):  # insertion sort: rows are short
                k = c_indices[t]
                u = t
                while u > o and c_indices[u - _U1] > k:
                    c_indices[u] = c_indices[u - _U1]
                    u -= _U1
                c_indices[u] = k
            w = np.uintp(0)
            for t in range(o, o + n):
                k = np.uintp(c_indices[t])
                if sums[k] != 0.0:
                    c_indices[o + w] = k
                    c_data[o + w] = sums[k]
                    w += _U1
                sums[k] = 0.0
            kept[i] = w


# ---------------------------------------------------------------------------------------
# Coded stencils: a CSR matrix whose few distinct weights are stored once, each entry
# holding a uint16 code into that table and a uint16 column where the columns allow (4 bytes
# an entry instead of 12 with int32 indices). The products sum each row in stored order, as
# ``_csr_apply``: the same bits.

_EMPTY_KEY = -1  # a slot of the hash table holding no weight (no float64 has these bits: a NaN)


@kernel
def weight_codes(bits, codes, table):
    """Fill ``codes`` (uint16) with the index in ``table`` of each weight, whose float64 bits
    are ``bits`` (int64); ``table`` (int64, its length the most codes) collects the distinct
    bits in order of first use. Returns their number, or -1 when there are more."""
    slots = 4 * table.shape[0]
    keys = np.full(slots, _EMPTY_KEY, np.int64)
    vals = np.zeros(slots, np.int64)
    n = 0
    last_bits = _EMPTY_KEY
    last_code = 0
    for q in range(bits.shape[0]):
        b = bits[q]
        if b == last_bits:
            codes[q] = last_code
            continue
        s = (b ^ (b >> 29)) * 0x2545F4914F6CDD1D
        i = (s >> 40) % slots
        while keys[i] != b and keys[i] != _EMPTY_KEY:
            i = (i + 1) % slots
        if keys[i] == _EMPTY_KEY:
            if n == table.shape[0]:
                return -1
            keys[i] = b
            vals[i] = n
            table[n] = b
            n += 1
        last_bits = b
        last_code = vals[i]
        codes[q] = last_code
    return n


def _coded_apply(indptr, indices, codes, weights, X, out):
    """``out = S @ X`` for coded stencils and any (n, k) ``X``, rows in parallel, each summed
    in stored order."""
    k = X.shape[1]
    for r in prange(indptr.shape[0] - 1):
        for j in range(k):
            out[r, j] = 0.0
        for q in range(indptr[r], indptr[r + 1]):
            c = indices[q]
            w = weights[codes[q]]
            for j in range(k):
                out[r, j] += w * X[c, j]


coded_apply, coded_apply_serial = threaded_and_serial(_coded_apply)


def _coded_apply3(indptr, indices, codes, weights, x4, out):
    """``out = S @ X`` for one frame of positions: ``x4`` the (n, 4) positions with a fourth
    column of padding, ``out`` (rows, 3), both flattened. A row's three sums run side by side
    in the lanes of one vector register (``_simd``), each lane a multiply then an add in the
    row's stored order: the scalar loop's bits. Entries are counted by an unsigned index
    instead of views of the row: a signed one costs each access Numba's negative-index test,
    a view per row its bounds arithmetic (rows hold ten entries on average; the measured
    effect is in docs/performance.md, "Kernel design")."""
    for r in prange(indptr.shape[0] - 1):
        q = np.uintp(indptr[r])
        end = np.uintp(indptr[r + 1])
        acc = vzero()
        while q < end:
            acc = madd4(acc, weights[codes[q]], x4, _U4 * np.uintp(indices[q]))
            q += _U1
        o = _U3 * np.uintp(r)
        out[o] = lane(acc, 0)
        out[o + _U1] = lane(acc, 1)
        out[o + _U2] = lane(acc, 2)


coded_apply3, coded_apply3_serial = threaded_and_serial(_coded_apply3)
