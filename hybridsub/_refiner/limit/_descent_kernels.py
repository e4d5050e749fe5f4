"""Numba kernels of the descent (:mod:`.descent`).

Private. Contiguous arrays in.
"""

from __future__ import annotations

import numpy as np

from ..._jit import kernel


@kernel
def ring_pairs(F, n, centre, rings):
    """(node, face) pairs, sorted: the faces within ``rings`` vertex rings of each node's
    centre face, over a mesh ``F`` of ``n`` vertices."""
    m = len(F)
    ptr = np.zeros(n + 1, np.int64)
    for f in range(m):
        for c in range(3):
            ptr[F[f, c] + 1] += 1
    for v in range(n):
        ptr[v + 1] += ptr[v]
    fill = ptr[:-1].copy()
    faces_of = np.empty(3 * m, np.int64)
    for f in range(m):
        for c in range(3):
            v = F[f, c]
            faces_of[fill[v]] = f
            fill[v] += 1
    vmark = np.full(n, -1, np.int64)
    fmark = np.full(m, -1, np.int64)
    cap = max(16, 32 * len(centre))
    out_n = np.empty(cap, np.int64)
    out_f = np.empty(cap, np.int64)
    size = 0
    verts = np.empty(16, np.int64)
    faces = np.empty(16, np.int64)
    for i in range(len(centre)):
        nv = 0
        for c in range(3):
            v = F[centre[i], c]
            if vmark[v] != i:
                vmark[v] = i
                if nv == len(verts):
                    verts = np.concatenate((verts, np.empty(nv, np.int64)))
                verts[nv] = v
                nv += 1
        nf = 0
        lo = 0
        for r in range(rings):
            hi = nv
            for a in range(lo, hi):
                v = verts[a]
                for k in range(ptr[v], ptr[v + 1]):
                    f = faces_of[k]
                    if fmark[f] == i:
                        continue
                    fmark[f] = i
                    if nf == len(faces):
                        faces = np.concatenate((faces, np.empty(nf, np.int64)))
                    faces[nf] = f
                    nf += 1
                    if r < rings - 1:
                        for c in range(3):
                            w = F[f, c]
                            if vmark[w] != i:
                                vmark[w] = i
                                if nv == len(verts):
                                    verts = np.concatenate((verts, np.empty(nv, np.int64)))
                                verts[nv] = w
                                nv += 1
            lo = hi
        if size + nf > cap:
            cap = 2 * (size + nf)
            out_n = np.concatenate((out_n[:size], np.empty(cap - size, np.int64)))
            out_f = np.concatenate((out_f[:size], np.empty(cap - size, np.int64)))
        for a in range(nf):  # insertion sort: a few dozen faces
            x = faces[a]
            b = size + a
            while b > size and out_f[b - 1] > x:
                out_f[b] = out_f[b - 1]
                b -= 1
            out_f[b] = x
            out_n[size + a] = i
        size += nf
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
        vsel[start:nv] = np.sort(vsel[start:nv])
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
