"""Numba kernels of the patch cache's keys (:mod:`.cache`): canonical orders, key records
and hashes, regular Loop patches.

Private. Contiguous arrays in, outputs allocated by the caller.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import kernel

#: The height of the unit equilateral triangle.
HALF_SQRT3 = math.sqrt(3.0) / 2


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
        _normalise(shape, f, s0, scale[i], grid, r, out, norm)


@kernel(inline="always")
def _normalise(shape, f, s0, s, grid, r, out, norm):
    """Face ``f``'s corners from corner ``s0`` moved by a rigid motion (corner 0 at the origin,
    corner 1 on +x) and scaled by ``1 / s``: ``norm[r]``, and rounded to ``grid`` in
    ``out[r, 10:13]``."""
    s1, s2 = (s0 + 1) % 3, (s0 + 2) % 3
    ax, ay = shape[f, s0, 0], shape[f, s0, 1]
    ex, ey = shape[f, s1, 0] - ax, shape[f, s1, 1] - ay
    ln = math.sqrt(ex * ex + ey * ey)
    co, si = ex / ln, ey / ln
    dx, dy = shape[f, s2, 0] - ax, shape[f, s2, 1] - ay
    norm[r, 0, 0] = 0.0
    norm[r, 0, 1] = 0.0
    norm[r, 1, 0] = ln / s
    norm[r, 1, 1] = 0.0
    norm[r, 2, 0] = (co * dx + si * dy) / s
    norm[r, 2, 1] = (co * dy - si * dx) / s
    # The chart's faces are equilateral: taken as the exact triangle whichever corner they
    # were entered at (the rotation's rounding would make a key's representative depend on
    # the first patch met).
    near = abs(norm[r, 1, 0] - 1.0) + abs(norm[r, 2, 0] - 0.5) + abs(norm[r, 2, 1] - HALF_SQRT3)
    if near < 1e-12:
        norm[r, 1, 0] = 1.0
        norm[r, 2, 0] = 0.5
        norm[r, 2, 1] = HALF_SQRT3
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


@kernel(inline="always")
def _round(acc, w, p, q, r):
    """One word into one lane: multiply, rotate, multiply (xxHash's round)."""
    acc = acc + w * p
    acc = (acc << r) | (acc >> (np.uint64(64) - r))
    return acc * q


@kernel(inline="always")
def _lanes(a, p, q, r, w0, w1, w2, w3):
    a[0] = _round(a[0], w0, p, q, r)
    a[1] = _round(a[1], w1, p, q, r)
    a[2] = _round(a[2], w2, p, q, r)
    a[3] = _round(a[3], w3, p, q, r)


@kernel(inline="always")
def _merge(a, n):
    """The four lanes and the sizes ``n`` through the finaliser: every bit moves every bit."""
    h = _mix(a[0])
    h = _mix(h ^ a[1])
    h = _mix(h ^ a[2])
    h = _mix(h ^ a[3])
    return _mix(h ^ n)


@kernel
def key_hashes(rec, fstart, cv, vstart, parity, out):
    """A 128-bit hash of every piece's key (two independently seeded hashes, each of four
    lanes, over its face records, its vertices' corner flags, its sizes and the step
    parity): ``out`` (k, 2)."""
    p1, q1, r1 = np.uint64(0xC2B2AE3D27D4EB4F), np.uint64(0x9E3779B185EBCA87), np.uint64(31)
    p2, q2, r2 = np.uint64(0xA4093822299F31D1), np.uint64(0x165667B19E3779F9), np.uint64(27)
    a = np.empty(4, np.uint64)
    b = np.empty(4, np.uint64)
    ncol = rec.shape[1]
    for i in range(len(fstart) - 1):
        for j in range(4):
            a[j] = _mix(np.uint64(parity) ^ np.uint64(0x243F6A8885A308D3 + j))
            b[j] = _mix(np.uint64(parity) ^ np.uint64(0x13198A2E03707344 + j))
        for r in range(fstart[i], fstart[i + 1]):
            c = 0
            while c + 4 <= ncol:
                w0, w1 = np.uint64(rec[r, c]), np.uint64(rec[r, c + 1])
                w2, w3 = np.uint64(rec[r, c + 2]), np.uint64(rec[r, c + 3])
                _lanes(a, p1, q1, r1, w0, w1, w2, w3)
                _lanes(b, p2, q2, r2, w0, w1, w2, w3)
                c += 4
            while c < ncol:
                w = np.uint64(rec[r, c])
                a[0] = _round(a[0], w, p1, q1, r1)
                b[0] = _round(b[0], w, p2, q2, r2)
                c += 1
        v = vstart[i]
        while v + 4 <= vstart[i + 1]:
            w0, w1, w2, w3 = np.uint64(cv[v]), np.uint64(cv[v + 1]), np.uint64(cv[v + 2]), np.uint64(cv[v + 3])
            _lanes(a, p1, q1, r1, w0, w1, w2, w3)
            _lanes(b, p2, q2, r2, w0, w1, w2, w3)
            v += 4
        while v < vstart[i + 1]:
            w = np.uint64(cv[v])
            a[1] = _round(a[1], w, p1, q1, r1)
            b[1] = _round(b[1], w, p2, q2, r2)
            v += 1
        n = np.uint64(fstart[i + 1] - fstart[i]) << np.uint64(32) | np.uint64(vstart[i + 1] - vstart[i])
        out[i, 0] = _merge(a, n)
        out[i, 1] = _merge(b, n)


#: The bits of an infinite sharpness (``face_records`` keeps sharpness as its float's bits).
INF_BITS = np.array([np.inf]).view(np.int64)[0]
#: The bits of −0.0 (a sharpness equal to 0).
MINUS_ZERO_BITS = np.array([-0.0]).view(np.int64)[0]


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


@kernel
def transition_hashes(row, col, vbits, bounds, out):
    """A 128-bit hash of every transition's contents (entries ``bounds[i]:bounds[i + 1]`` of
    ``row``, ``col`` and ``vbits``, the weights' bits; as :func:`key_hashes`): ``out`` (k, 2)."""
    p1, q1, r1 = np.uint64(0xC2B2AE3D27D4EB4F), np.uint64(0x9E3779B185EBCA87), np.uint64(31)
    p2, q2, r2 = np.uint64(0xA4093822299F31D1), np.uint64(0x165667B19E3779F9), np.uint64(27)
    a = np.empty(4, np.uint64)
    b = np.empty(4, np.uint64)
    low = np.uint64(0xFFFFFFFF)
    for i in range(len(bounds) - 1):
        for j in range(4):
            a[j] = _mix(np.uint64(0x452821E638D01377 + j))
            b[j] = _mix(np.uint64(0xBE5466CF34E90C6C + j))
        e = bounds[i]
        while e + 2 <= bounds[i + 1]:
            w0 = (np.uint64(row[e]) << np.uint64(32)) | (np.uint64(col[e]) & low)
            w2 = (np.uint64(row[e + 1]) << np.uint64(32)) | (np.uint64(col[e + 1]) & low)
            w1, w3 = np.uint64(vbits[e]), np.uint64(vbits[e + 1])
            _lanes(a, p1, q1, r1, w0, w1, w2, w3)
            _lanes(b, p2, q2, r2, w0, w1, w2, w3)
            e += 2
        if e < bounds[i + 1]:
            w0 = (np.uint64(row[e]) << np.uint64(32)) | (np.uint64(col[e]) & low)
            w1 = np.uint64(vbits[e])
            a[0] = _round(a[0], w0, p1, q1, r1)
            a[1] = _round(a[1], w1, p1, q1, r1)
            b[0] = _round(b[0], w0, p2, q2, r2)
            b[1] = _round(b[1], w1, p2, q2, r2)
        n = np.uint64(bounds[i + 1] - bounds[i])
        out[i, 0] = _merge(a, n)
        out[i, 1] = _merge(b, n)


@kernel
def gather_pieces(keys, f0, nf, rep_f, rep_twin, rep_shape, foff, voff, faces, twin, shape):
    """The representatives of ``keys`` (faces ``f0[k]:f0[k] + nf[k]`` of the stored corners
    ``rep_f``, twins ``rep_twin`` and shapes ``rep_shape``, see :class:`.cache.PatchTable`)
    as one mesh of disjoint pieces, piece ``i`` from face ``foff[i]`` and vertex ``voff[i]``:
    fills ``faces`` (m, 3), ``twin`` (3m) and ``shape`` (m, 3, 2)."""
    for i in range(len(keys)):
        a, fo, vo = f0[keys[i]], foff[i], voff[i]
        for r in range(nf[keys[i]]):
            g = fo + r
            for c in range(3):
                faces[g, c] = rep_f[a + r, c] + vo
                t = rep_twin[a + r, c]
                twin[3 * g + c] = t + 3 * fo if t >= 0 else -1
            shape[g, 0, 0] = 0.0
            shape[g, 0, 1] = 0.0
            shape[g, 1, 0] = rep_shape[a + r, 0]
            shape[g, 1, 1] = 0.0
            shape[g, 2, 0] = rep_shape[a + r, 1]
            shape[g, 2, 1] = rep_shape[a + r, 2]


@kernel
def representative_rows(new, rec, fstart, norm, fs, cv, vstart, faces, twin, sharp_face, shape, hbits, crec, corner,
                        sharp):
    """The rows the pieces ``new`` keep as representatives, one after another: from their
    face records ``rec`` (:func:`face_records`), corners ``faces`` (m, 3), ``twin`` (m, 3),
    halfedge sharpness bits ``hbits`` (m, 3), the connectivity and tags ``crec`` (m, 10)
    (the records without their shapes), sharp faces ``sharp_face`` from ``fs``, shapes
    ``shape`` (m, 3: corner 1's x, corner 2's x and y) from ``norm``; corner tags ``corner``
    from ``cv``; ``sharp`` (k,) whether a piece has a tagged halfedge."""
    g = 0
    u = 0
    for i in range(len(new)):
        p = new[i]
        any_sharp = False
        for r in range(fstart[p], fstart[p + 1]):
            for c in range(3):
                faces[g, c] = rec[r, c]
                twin[g, c] = rec[r, 3 + c]
                hbits[g, c] = rec[r, 7 + c]
                if rec[r, 7 + c] != 0 and rec[r, 7 + c] != MINUS_ZERO_BITS:
                    any_sharp = True
            for c in range(10):
                crec[g, c] = rec[r, c]
            sharp_face[g] = fs[r]
            shape[g, 0] = norm[r, 1, 0]
            shape[g, 1] = norm[r, 2, 0]
            shape[g, 2] = norm[r, 2, 1]
            g += 1
        sharp[i] = any_sharp
        for v in range(vstart[p], vstart[p + 1]):
            corner[u] = cv[v]
            u += 1
