"""Numba kernels of the patch cache's keys (:mod:`.cache`): canonical orders, key records
and hashes, regular Loop patches.

Private. Contiguous arrays in, outputs allocated by the caller.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import kernel


@kernel
def canonical_order(F, twin, n, fstart, centre, fperm, vperm, vstart, entry):
    """Faces and vertices of every piece in a canonical order.

    Pieces are contiguous: node ``i`` owns faces ``fstart[i]:fstart[i + 1]`` (and the vertices
    they use). Breadth first from the node's ``centre`` face, entered at its corner 0; every
    other face is entered at the halfedge it was reached through, and its neighbours are
    queued in corner order from there. Vertices are numbered as first met. Faces not reached
    through edges follow in their stored order. Fills ``fperm`` (faces in canonical order),
    ``vperm`` (vertices in canonical order), ``vstart`` (k + 1) their ranges per node and
    ``entry`` (m) the corner each face was entered at.
    """
    m = len(F)
    fmark = np.zeros(m, np.bool_)
    vseen = np.zeros(n, np.bool_)
    nv = 0
    for i in range(len(centre)):
        a, b = fstart[i], fstart[i + 1]
        vstart[i] = nv
        nf = a
        fperm[nf] = centre[i]
        fmark[centre[i]] = True
        entry[centre[i]] = 0
        nf += 1
        head = a
        nxt = a  # next stored face to try when the queue runs dry
        while head < b:
            if head == nf:  # not reached through edges: the next unreached face in stored order
                while fmark[nxt]:
                    nxt += 1
                fperm[nf] = nxt
                fmark[nxt] = True
                entry[nxt] = 0
                nf += 1
            f = fperm[head]
            head += 1
            s = entry[f]
            for j in range(3):
                v = F[f, (s + j) % 3]
                if not vseen[v]:
                    vseen[v] = True
                    vperm[nv] = v
                    nv += 1
            for j in range(3):
                t = twin[3 * f + (s + j) % 3]
                if t >= 0 and not fmark[t // 3]:
                    g = t // 3
                    fmark[g] = True
                    entry[g] = t % 3
                    fperm[nf] = g
                    nf += 1
    vstart[len(centre)] = nv


@kernel
def face_records(F, twin, hbits, face_sharp, shape, fperm, frank, vrank, entry, fstart, node_of, scale, grid, out,
                 norm):
    """Per canonical face, its corners from the one it was entered at (``entry``): their
    canonical labels, twins, tags and the normalised shape.

    ``out`` (m, 13) int64: corner labels (3), canonical twin halfedges (3, −1 none), sharp
    face (1), ``hbits`` of the halfedges (3: their sharpness's bits), and the shape normalised by a rigid
    motion of its own (corner 0 at the origin, corner 1 on +x) and the piece's ``scale``,
    rounded to ``grid`` (3: corner 1's x, corner 2's x and y). ``norm`` (m, 3, 2) gets that
    normalised shape unrounded.
    """
    for r in range(len(fperm)):
        f = fperm[r]
        i = node_of[r]
        base = fstart[i]
        s0 = entry[f]
        for c in range(3):
            cc = (s0 + c) % 3
            out[r, c] = vrank[F[f, cc]]
            t = twin[3 * f + cc]
            out[r, 3 + c] = 3 * (frank[t // 3] - base) + (t % 3 - entry[t // 3] + 3) % 3 if t >= 0 else -1
            out[r, 7 + c] = hbits[3 * f + cc]
        out[r, 6] = 1 if face_sharp[f] else 0
        s1, s2 = (s0 + 1) % 3, (s0 + 2) % 3
        ax, ay = shape[f, s0, 0], shape[f, s0, 1]
        ex, ey = shape[f, s1, 0] - ax, shape[f, s1, 1] - ay
        ln = math.sqrt(ex * ex + ey * ey)
        co, si = ex / ln, ey / ln
        dx, dy = shape[f, s2, 0] - ax, shape[f, s2, 1] - ay
        s = scale[i]
        norm[r, 0, 0] = 0.0
        norm[r, 0, 1] = 0.0
        norm[r, 1, 0] = ln / s
        norm[r, 1, 1] = 0.0
        norm[r, 2, 0] = (co * dx + si * dy) / s
        norm[r, 2, 1] = (co * dy - si * dx) / s
        out[r, 10] = round(norm[r, 1, 0] / grid)
        out[r, 11] = round(norm[r, 2, 0] / grid)
        out[r, 12] = round(norm[r, 2, 1] / grid)


@kernel(inline="always")
def _mix(z):
    """splitmix64's finaliser: every input bit moves every output bit."""
    z = z + np.uint64(0x9E3779B97F4A7C15)
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@kernel
def key_hashes(rec, fstart, cv, vstart, parity, out):
    """A 128-bit hash of every piece's key (two independently seeded chains over its face
    records, its vertices' corner flags, its sizes and the step parity): ``out`` (k, 2)."""
    for i in range(len(fstart) - 1):
        h1 = _mix(np.uint64(parity) ^ np.uint64(0x243F6A8885A308D3))
        h2 = _mix(np.uint64(parity) ^ np.uint64(0x13198A2E03707344))
        for r in range(fstart[i], fstart[i + 1]):
            for c in range(rec.shape[1]):
                w = np.uint64(rec[r, c])
                h1 = _mix(h1 ^ w)
                h2 = _mix(h2 + w * np.uint64(0xA4093822299F31D1))
        for v in range(vstart[i], vstart[i + 1]):
            w = np.uint64(cv[v])
            h1 = _mix(h1 ^ w)
            h2 = _mix(h2 + w * np.uint64(0xA4093822299F31D1))
        n = np.uint64(fstart[i + 1] - fstart[i]) << np.uint64(32) | np.uint64(vstart[i + 1] - vstart[i])
        out[i, 0] = _mix(h1 ^ n)
        out[i, 1] = _mix(h2 + n)


#: The bits of an infinite sharpness (``face_records`` keeps sharpness as its float's bits).
INF_BITS = np.array([np.inf]).view(np.int64)[0]


@kernel(inline="always")
def _crease(rec, r, h):
    """Whether halfedge ``h`` of record ``r`` is on a crease: tagged, or a boundary."""
    return rec[r, 3 + h] < 0 or rec[r, 7 + h] != 0


@kernel(inline="always")
def _infinite(rec, r, h):
    return rec[r, 3 + h] < 0 or rec[r, 7 + h] == INF_BITS


@kernel
def _regular_corner(rec, a, b, c):
    """The kind of the centre's (record ``a``) corner ``c`` for the box spline: 0 not regular,
    1 interior (six Loop faces, no crease), 2 on a regular crease (two infinitely sharp
    crease edges, three Loop faces between them on the centre's side)."""
    side = 1
    closed = False
    ok = rec[a, 6] != 0
    r, cc = a, c
    while True:  # one way round: across the edges coming in to the corner
        h = (cc + 2) % 3
        if _crease(rec, r, h):
            ok = ok and _infinite(rec, r, h)
            break
        t = rec[r, 3 + h]
        r, cc = a + t // 3, t % 3
        if r == a:
            closed = True
            break
        side += 1
        ok = ok and rec[r, 6] != 0
        if side > 6:
            return 0
    if not closed:
        r, cc = a, c
        while True:  # the other way: across the edges going out
            if _crease(rec, r, cc):
                ok = ok and _infinite(rec, r, cc)
                break
            t = rec[r, 3 + cc]
            r, cc = a + t // 3, (t % 3 + 1) % 3
            side += 1
            ok = ok and rec[r, 6] != 0
            if side > 6:
                return 0
    if not ok:
        return 0
    if closed:
        return 1 if side == 6 else 0
    v = rec[a, c]
    creases = 0
    for r in range(a, b):  # every edge at v once: going out of v, or a boundary coming in
        for k in range(3):
            if rec[r, k] == v:
                if _crease(rec, r, k):
                    creases += 1
                if rec[r, 3 + (k + 2) % 3] < 0:
                    creases += 1
    return 2 if side == 3 and creases == 2 else 0


@kernel
def regular_flags(rec, fstart, cv, vstart, out):
    """``regular.is_regular`` of every piece from its canonical records (:func:`face_records`)
    and corner flags ``cv``: ``out`` (k,) 1 or 0."""
    for i in range(len(fstart) - 1):
        a, b = fstart[i], fstart[i + 1]
        ok = True
        on_crease = 0
        last = -1
        first = -1
        for c in range(3):
            kind = _regular_corner(rec, a, b, c)
            if kind == 0 or cv[vstart[i] + rec[a, c]]:
                ok = False
            elif kind == 2:
                on_crease += 1
                if first < 0:
                    first = c
                last = c
        if ok and on_crease == 3:
            ok = False
        if ok and on_crease == 2:  # the centre's edge between them must be the crease
            h = first if last == first + 1 else last
            ok = _crease(rec, a, h)
        out[i] = 1 if ok else 0
