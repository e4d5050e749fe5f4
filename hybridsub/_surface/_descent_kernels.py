"""Numba kernels of the descent (:mod:`.descent`).

Private. Contiguous arrays in.
"""

from __future__ import annotations

import numpy as np

from .._jit import kernel
from .._topology import group_by_origin


@kernel(inline="always")
def _push(arr, n, x):
    """``arr`` with ``x`` at ``n`` (doubled when full)."""
    if n == len(arr):
        arr = np.concatenate((arr, np.empty(max(n, 1), np.int64)))
    arr[n] = x
    return arr


@kernel
def ring_pairs(F, n, centre, rings):
    """(node, face) pairs, sorted: the faces within ``rings`` vertex rings of each node's
    centre face, over a mesh ``F`` of ``n`` vertices."""
    m = len(F)
    by_origin, ptr = group_by_origin(F, n)  # a vertex's faces: its outgoing halfedges' faces
    vmark = np.full(n, -1, np.int64)
    fmark = np.full(m, -1, np.int64)
    out_n = np.empty(max(16, 32 * len(centre)), np.int64)
    out_f = np.empty(len(out_n), np.int64)
    size = 0
    verts = np.empty(16, np.int64)
    faces = np.empty(16, np.int64)
    for i in range(len(centre)):
        nv = 0
        for c in range(3):
            v = F[centre[i], c]
            if vmark[v] != i:
                vmark[v] = i
                verts = _push(verts, nv, v)
                nv += 1
        nf = 0
        lo = 0
        for r in range(rings):
            hi = nv
            for a in range(lo, hi):
                v = verts[a]
                for k in range(ptr[v], ptr[v + 1]):
                    f = by_origin[k] // 3
                    if fmark[f] == i:
                        continue
                    fmark[f] = i
                    faces = _push(faces, nf, f)
                    nf += 1
                    if r < rings - 1:
                        for c in range(3):
                            w = F[f, c]
                            if vmark[w] != i:
                                vmark[w] = i
                                verts = _push(verts, nv, w)
                                nv += 1
            lo = hi
        for a in range(nf):  # insertion sort: a few dozen faces
            x = faces[a]
            out_n = _push(out_n, size + a, i)
            out_f = _push(out_f, size + a, x)
            b = size + a
            while b > size and out_f[b - 1] > x:
                out_f[b] = out_f[b - 1]
                b -= 1
            out_f[b] = x
        size += nf
    return out_n[:size], out_f[:size]


@kernel
def ring_pairs_within(F, n, centre, lo, hi, rings):
    """:func:`ring_pairs` where each centre's rings lie within faces ``lo[i]:hi[i]`` (its
    piece of a mesh of disjoint pieces): the same pairs, by scanning the piece once a ring
    instead of grouping the whole mesh's halfedges."""
    vtag = np.full(n, -1, np.int64)  # the centre that reached a vertex last
    vround = np.zeros(n, np.int64)  # the ring it was reached in
    out_n = np.empty(max(16, 32 * len(centre)), np.int64)
    out_f = np.empty(len(out_n), np.int64)
    size = 0
    for i in range(len(centre)):
        for c in range(3):
            vtag[F[centre[i], c]] = i
            vround[F[centre[i], c]] = 0
        for r in range(rings):
            for f in range(lo[i], hi[i]):
                hit = False
                for c in range(3):
                    v = F[f, c]
                    if vtag[v] == i and vround[v] <= r:
                        hit = True
                if not hit:
                    continue
                if r == rings - 1:
                    out_n = _push(out_n, size, i)
                    out_f = _push(out_f, size, f)
                    size += 1
                else:
                    for c in range(3):
                        v = F[f, c]
                        if vtag[v] != i:
                            vtag[v] = i
                            vround[v] = r + 1
    return out_n[:size], out_f[:size]


@kernel
def cut_pieces(F, twin, n, node, f):
    """The faces ``f`` of each node (pairs sorted by node, then face) copied apart.

    Returns the new faces (k, 3), the old vertex of every new vertex (numbered by node, then
    old id) and the new halfedge twins (−1 where the neighbour is not in the same piece).
    """
    k = len(f)
    vmark = np.full(n, -1, np.int64)
    vnew = np.empty(n, np.int64)
    fmark = np.full(len(F), -1, np.int64)
    fnew = np.empty(len(F), np.int64)
    newF = np.empty((k, 3), np.int64)
    vsel = np.empty(3 * k, np.int64)
    tw_out = np.empty(3 * k, np.int64)
    nv = 0
    a = 0
    while a < k:
        b = a
        while b < k and node[b] == node[a]:
            b += 1
        i = node[a]
        start = nv
        for r in range(a, b):
            fmark[f[r]] = i
            fnew[f[r]] = r
            for c in range(3):
                v = F[f[r], c]
                if vmark[v] != i:
                    vmark[v] = i
                    vsel[nv] = v
                    nv += 1
        vsel[start:nv].sort()
        for j in range(start, nv):
            vnew[vsel[j]] = j
        for r in range(a, b):
            for c in range(3):
                newF[r, c] = vnew[F[f[r], c]]
                t = twin[3 * f[r] + c]
                if t >= 0 and fmark[t // 3] == i:
                    tw_out[3 * r + c] = 3 * fnew[t // 3] + t % 3
                else:
                    tw_out[3 * r + c] = -1
        a = b
    return newF, vsel[:nv].copy(), tw_out
