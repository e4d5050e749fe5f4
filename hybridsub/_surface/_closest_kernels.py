"""Numba kernels of the closest point on a triangle mesh: among candidate triangles, or
exactly through a uniform grid of cells.

Private. Contiguous float64 / int64 arrays in, outputs allocated by the caller. The closest
point on one triangle follows the Voronoi regions of its vertices, edges and face (Ericson,
*Real-Time Collision Detection*, 5.1.5), as barycentric coordinates.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from .._jit import kernel


@kernel(inline="always")
def _closest_on_triangle(px, py, pz, P, a, b, c):
    """Barycentric (u, v, w) of the point of triangle (a, b, c) of ``P`` closest to p."""
    abx, aby, abz = P[b, 0] - P[a, 0], P[b, 1] - P[a, 1], P[b, 2] - P[a, 2]
    acx, acy, acz = P[c, 0] - P[a, 0], P[c, 1] - P[a, 1], P[c, 2] - P[a, 2]
    apx, apy, apz = px - P[a, 0], py - P[a, 1], pz - P[a, 2]
    d1 = abx * apx + aby * apy + abz * apz
    d2 = acx * apx + acy * apy + acz * apz
    if d1 <= 0.0 and d2 <= 0.0:
        return 1.0, 0.0, 0.0
    bpx, bpy, bpz = px - P[b, 0], py - P[b, 1], pz - P[b, 2]
    d3 = abx * bpx + aby * bpy + abz * bpz
    d4 = acx * bpx + acy * bpy + acz * bpz
    if d3 >= 0.0 and d4 <= d3:
        return 0.0, 1.0, 0.0
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        t = d1 / (d1 - d3)
        return 1.0 - t, t, 0.0
    cpx, cpy, cpz = px - P[c, 0], py - P[c, 1], pz - P[c, 2]
    d5 = abx * cpx + aby * cpy + abz * cpz
    d6 = acx * cpx + acy * cpy + acz * cpz
    if d6 >= 0.0 and d5 <= d6:
        return 0.0, 0.0, 1.0
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        t = d2 / (d2 - d6)
        return 1.0 - t, 0.0, t
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        t = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return 0.0, 1.0 - t, t
    denom = va + vb + vc
    if not denom > 0.0:  # a degenerate triangle: its first vertex
        return 1.0, 0.0, 0.0
    v = vb / denom
    w = vc / denom
    return 1.0 - v - w, v, w


@kernel(parallel=True)
def closest_among(points, P, faces, candidates, face_out, bary_out, d2_out):
    """For each point, the closest point on its candidate triangles (``candidates[i]``, -1 ends).

    Fills ``face_out`` (m,), ``bary_out`` (m, 3) and the squared distance ``d2_out`` (m,);
    a point keeps the first of equally distant triangles. Points are independent rows.
    """
    m, k = candidates.shape
    for i in prange(m):
        px, py, pz = points[i, 0], points[i, 1], points[i, 2]
        best = face_out[i]
        bd = d2_out[i]
        for j in range(k):
            f = candidates[i, j]
            if f < 0:
                break
            best, bd = _try_face(px, py, pz, P, faces, f, best, bd, bary_out[i])
        face_out[i] = best
        d2_out[i] = bd


@kernel
def bin_faces(P, faces, grow, lo, h, dims, start):
    """Cell lists of a uniform grid: every face in each cell its bounding box, grown by
    ``grow[f]`` on every side, touches.

    ``lo`` (3,) the grid's corner, ``h`` the cell size, ``dims`` (3,) cells per axis;
    ``start`` (nx·ny·nz + 1,) zeroed by the caller, filled with each cell's offset. Returns
    the faces of the cells, concatenated (cell ``c`` holds ``out[start[c]:start[c + 1]]``).
    """
    nf = faces.shape[0]
    box = np.empty((nf, 6), np.int64)
    for f in range(nf):
        for a in range(3):
            x0 = min(P[faces[f, 0], a], P[faces[f, 1], a], P[faces[f, 2], a]) - grow[f]
            x1 = max(P[faces[f, 0], a], P[faces[f, 1], a], P[faces[f, 2], a]) + grow[f]
            box[f, a] = min(max(int((x0 - lo[a]) / h), 0), dims[a] - 1)
            box[f, 3 + a] = min(max(int((x1 - lo[a]) / h), 0), dims[a] - 1)
    for f in range(nf):
        for i in range(box[f, 0], box[f, 3] + 1):
            for j in range(box[f, 1], box[f, 4] + 1):
                for k in range(box[f, 2], box[f, 5] + 1):
                    start[(i * dims[1] + j) * dims[2] + k + 1] += 1
    for c in range(1, start.shape[0]):
        start[c] += start[c - 1]
    fill = start[:-1].copy()
    out = np.empty(start[-1], np.int64)
    for f in range(nf):
        for i in range(box[f, 0], box[f, 3] + 1):
            for j in range(box[f, 1], box[f, 4] + 1):
                for k in range(box[f, 2], box[f, 5] + 1):
                    c = (i * dims[1] + j) * dims[2] + k
                    out[fill[c]] = f
                    fill[c] += 1
    return out


@kernel(inline="always")
def _try_face(px, py, pz, P, faces, f, best, bd, bary):
    """Face ``f`` tried for point p: ``(f, its squared distance)`` with ``bary`` (3,) set when
    it is nearer than ``bd`` (or no face was found yet), else ``(best, bd)`` unchanged."""
    a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
    u, v, w = _closest_on_triangle(px, py, pz, P, a, b, c)
    qx = u * P[a, 0] + v * P[b, 0] + w * P[c, 0]
    qy = u * P[a, 1] + v * P[b, 1] + w * P[c, 1]
    qz = u * P[a, 2] + v * P[b, 2] + w * P[c, 2]
    d = (qx - px) ** 2 + (qy - py) ** 2 + (qz - pz) ** 2
    if best < 0 or d < bd:
        bary[0], bary[1], bary[2] = u, v, w
        return f, d
    return best, bd


@kernel(inline="always")
def _cell_d2(px, py, pz, lo, h, i, j, k):
    """Squared distance from p to the box of cell (i, j, k)."""
    return _gap(px, lo[0] + i * h, h) + _gap(py, lo[1] + j * h, h) + _gap(pz, lo[2] + k * h, h)


@kernel(inline="always")
def _gap(x, c0, h):
    """Squared distance from x to the interval [c0, c0 + h]."""
    if x < c0:
        return (c0 - x) ** 2
    if x > c0 + h:
        return (x - c0 - h) ** 2
    return 0.0


@kernel(inline="always")
def _home(x, lo, h, dim):
    """The cell index along one axis of coordinate ``x`` clamped into the grid, and the
    clamped coordinate's distance to that cell's nearer wall."""
    c = min(max(x, lo), lo + dim * h)
    i = min(max(int((c - lo) / h), 0), dim - 1)
    return i, min(c - (lo + i * h), lo + (i + 1) * h - c)


@kernel(parallel=True)
def closest_in_grid(points, P, faces, lo, h, dims, start, cell_faces, face_out, bary_out, d2_out):
    """The closest point of each point on the mesh, exactly, through the grid of :func:`bin_faces`.

    Cells are visited in shells of growing Chebyshev radius r round the cell of the point
    clamped into the grid; every face point in shell r is at least (r − 1) h + δ away (δ:
    the clamped point's distance to its own cell's walls; clamping onto the grid's box never
    lengthens a distance to a point inside it), so the search stops once that reaches the
    best distance. ``face_out[i] >= 0`` on entry is tried first (a warm start).
    """
    m = points.shape[0]
    nmax = max(dims[0], max(dims[1], dims[2]))
    for i in prange(m):
        px, py, pz = points[i, 0], points[i, 1], points[i, 2]
        bary = bary_out[i]
        best, bd = -1, np.inf
        if face_out[i] >= 0:
            best, bd = _try_face(px, py, pz, P, faces, face_out[i], best, bd, bary)
        ci, wx = _home(px, lo[0], h, dims[0])
        cj, wy = _home(py, lo[1], h, dims[1])
        ck, wz = _home(pz, lo[2], h, dims[2])
        delta = max(min(wx, min(wy, wz)), 0.0)
        for r in range(nmax + 1):
            if r > 0:
                lb = (r - 1) * h + delta
                if lb * lb >= bd:
                    break
            for di in range(-r, r + 1):
                ii = ci + di
                if ii < 0 or ii >= dims[0]:
                    continue
                for dj in range(-r, r + 1):
                    jj = cj + dj
                    if jj < 0 or jj >= dims[1]:
                        continue
                    inner = abs(di) < r and abs(dj) < r
                    dk = -r
                    while dk <= r:
                        kk = ck + dk
                        if 0 <= kk < dims[2] and _cell_d2(px, py, pz, lo, h, ii, jj, kk) < bd:
                            cell = (ii * dims[1] + jj) * dims[2] + kk
                            for t in range(start[cell], start[cell + 1]):
                                best, bd = _try_face(px, py, pz, P, faces, cell_faces[t], best, bd, bary)
                        dk += 2 * r if inner and r > 0 else 1
        face_out[i] = best
        d2_out[i] = bd


@kernel(inline="always")
def _face_d2(px, py, pz, P, faces, f):
    """Squared distance from p to triangle ``f``, and its barycentric coordinates there."""
    a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
    u, v, w = _closest_on_triangle(px, py, pz, P, a, b, c)
    qx = u * P[a, 0] + v * P[b, 0] + w * P[c, 0]
    qy = u * P[a, 1] + v * P[b, 1] + w * P[c, 1]
    qz = u * P[a, 2] + v * P[b, 2] + w * P[c, 2]
    return (qx - px) ** 2 + (qy - py) ** 2 + (qz - pz) ** 2, u, v, w


@kernel
def face_rings(faces, vf_start, vf_faces, rings, n_vertices):
    """The vertices within ``rings`` rings of each face, as CSR ``(start, vertices)``.

    Ring 1 holds the vertices of the faces that share a vertex with the face, ring 2 adds
    those of the faces that share a vertex with ring 1. ``vf_start`` (n + 1,), ``vf_faces``:
    the faces round each vertex (CSR).
    """
    nf = faces.shape[0]
    stamp = np.full(n_vertices, -1, np.int64)
    start = np.zeros(nf + 1, np.int64)
    out = np.empty(0, np.int64)
    for fill in range(2):
        stamp[:] = -1
        n = 0
        for f in range(nf):
            for a in range(3):
                va = faces[f, a]
                for s in range(vf_start[va], vf_start[va + 1]):
                    g = vf_faces[s]
                    for b in range(3):
                        vb = faces[g, b]
                        if stamp[vb] != f:
                            stamp[vb] = f
                            if fill:
                                out[n] = vb
                            n += 1
                        if rings > 1:
                            for t in range(vf_start[vb], vf_start[vb + 1]):
                                h = vf_faces[t]
                                for c in range(3):
                                    vc = faces[h, c]
                                    if stamp[vc] != f:
                                        stamp[vc] = f
                                        if fill:
                                            out[n] = vc
                                        n += 1
            if not fill:
                start[f + 1] = n
        if not fill:
            out = np.empty(n, np.int64)
    return start, out


@kernel(parallel=True)
def ring_deviation(P, faces, ring_start, ring, out):
    """For each face, the largest distance from it to a vertex of its ring (``face_rings``)."""
    for f in prange(faces.shape[0]):
        best = 0.0
        for s in range(ring_start[f], ring_start[f + 1]):
            v = ring[s]
            d2, _, _, _ = _face_d2(P[v, 0], P[v, 1], P[v, 2], P, faces, f)
            best = max(best, d2)
        out[f] = np.sqrt(best)


@kernel(parallel=True)
def faces_within(points, P, faces, eps, ring_start, ring, lo, h, dims, start, cell_faces, bound, out_face,
                 out_bary, out_d, out_lb, count):
    """For each point i, the faces f whose lower bound on the distance to the limit surface over
    them is below ``bound[i]``.

    The limit surface over f lies in the convex hull of its ring's vertices, so no nearer to
    p than ``d − eps[f]`` (d = dist(p, f)) nor than ``d − max_v n·(v − c)`` (c the closest
    point of f, n = (p − c) / d: the plane through c normal to n, pushed out to the ring, has
    the hull on one side). The grid is :func:`bin_faces`' with every face's box grown by its
    ``eps[f]``, over the grown boxes: the hull lies in the grown box, so a face none of whose
    cells is nearer p than ``bound[i]`` cannot qualify. Its cells are visited in shells as
    :func:`closest_in_grid` does, until no cell of the next shell is nearer than
    ``bound[i]``. Keeps the ``out_face.shape[1]`` nearest such faces (by distance),
    their closest points' barycentric coordinates ``out_bary`` (m, K, 3), distances
    ``out_d`` (m, K) and lower bounds ``out_lb`` (m, K); ``count[i]`` counts the faces that
    qualified (above K: some left out).
    """
    m = points.shape[0]
    K = out_face.shape[1]
    nmax = max(dims[0], max(dims[1], dims[2]))
    for i in prange(m):
        px, py, pz = points[i, 0], points[i, 1], points[i, 2]
        reach = bound[i]
        n = 0
        ci, wx = _home(px, lo[0], h, dims[0])
        cj, wy = _home(py, lo[1], h, dims[1])
        ck, wz = _home(pz, lo[2], h, dims[2])
        delta = max(min(wx, min(wy, wz)), 0.0)
        for r in range(nmax + 1):
            if r > 0 and (r - 1) * h + delta >= reach:
                break
            for di in range(-r, r + 1):
                ii = ci + di
                if ii < 0 or ii >= dims[0]:
                    continue
                for dj in range(-r, r + 1):
                    jj = cj + dj
                    if jj < 0 or jj >= dims[1]:
                        continue
                    inner = abs(di) < r and abs(dj) < r
                    dk = -r
                    while dk <= r:
                        kk = ck + dk
                        if 0 <= kk < dims[2] and _cell_d2(px, py, pz, lo, h, ii, jj, kk) < reach * reach:
                            cell = (ii * dims[1] + jj) * dims[2] + kk
                            for t in range(start[cell], start[cell + 1]):
                                n = _offer(px, py, pz, P, faces, eps, ring_start, ring, cell_faces[t], bound[i], n,
                                           out_face[i], out_bary[i], out_d[i], out_lb[i])
                        dk += 2 * r if inner and r > 0 else 1
        count[i] = n


@kernel(inline="always")
def _offer(px, py, pz, P, faces, eps, ring_start, ring, f, bound, n, out_face, out_bary, out_d, out_lb):
    """Face f offered to one point's survivors (``faces_within``); returns the new count."""
    K = out_face.shape[0]
    d2, u, v, w = _face_d2(px, py, pz, P, faces, f)
    d = np.sqrt(d2)
    lb = d - eps[f]
    if lb >= bound:
        return n
    a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
    if d > 0.0:
        cx = u * P[a, 0] + v * P[b, 0] + w * P[c, 0]
        cy = u * P[a, 1] + v * P[b, 1] + w * P[c, 1]
        cz = u * P[a, 2] + v * P[b, 2] + w * P[c, 2]
        nx, ny, nz = (px - cx) / d, (py - cy) / d, (pz - cz) / d
        reach = 0.0
        for s in range(ring_start[f], ring_start[f + 1]):
            x = ring[s]
            reach = max(reach, nx * (P[x, 0] - cx) + ny * (P[x, 1] - cy) + nz * (P[x, 2] - cz))
        lb = max(lb, d - reach)
        if lb >= bound:
            return n
    for s in range(min(n, K)):
        if out_face[s] == f:
            return n
    s = min(n, K)
    if s == K:
        if d >= out_d[K - 1]:
            return n + 1
        s = K - 1
    while s > 0 and out_d[s - 1] > d:
        out_face[s] = out_face[s - 1]
        out_d[s] = out_d[s - 1]
        out_lb[s] = out_lb[s - 1]
        for e in range(3):
            out_bary[s, e] = out_bary[s - 1, e]
        s -= 1
    out_face[s] = f
    out_d[s] = d
    out_lb[s] = lb
    out_bary[s, 0], out_bary[s, 1], out_bary[s, 2] = u, v, w
    return n + 1


@kernel
def survivor_components(start, tri, twin, slot, label):
    """Connected components of each point's surviving triangles.

    ``start`` (m + 1,) the CSR offsets of each point's survivors ``tri``; ``twin`` (3f,) the
    level's halfedge twins, −1 across a wall (a crease or the boundary): survivors meet only
    across other edges; ``slot`` (f,) all −1 (scratch, left so). ``label`` (len(tri),) is
    filled with, for each survivor, the offset of the first survivor of its component.
    """
    for i in range(start.shape[0] - 1):
        a, b = start[i], start[i + 1]
        for s in range(a, b):
            label[s] = s
            slot[tri[s]] = s
        for s in range(a, b):
            t = tri[s]
            for e in range(3):
                h = twin[3 * t + e]
                if h < 0:
                    continue
                r = slot[h // 3]
                if r < 0:
                    continue
                x, y = _root(label, s), _root(label, r)
                if x != y:
                    label[max(x, y)] = min(x, y)
        for s in range(a, b):
            label[s] = _root(label, s)
            slot[tri[s]] = -1


@kernel(inline="always")
def _root(label, s):
    while label[s] != s:
        label[s] = label[label[s]]
        s = label[s]
    return s


@kernel
def survivor_minima(start, tri, twin, slot, out):
    """Which survivors are nearer their query than every surviving neighbour: each point's
    survivors (``start``, ``tri`` as in :func:`survivor_components`, sorted by their distance
    within a point, so that an earlier survivor is as near or nearer), compared across the
    edges that are not walls (``twin``, −1 across a wall). ``slot`` (f,) all −1 (scratch, left
    so); ``out`` (len(tri),) bool."""
    for i in range(start.shape[0] - 1):
        a, b = start[i], start[i + 1]
        for s in range(a, b):
            slot[tri[s]] = s
        for s in range(a, b):
            low = True
            t = tri[s]
            for e in range(3):
                h = twin[3 * t + e]
                if h >= 0:
                    r = slot[h // 3]
                    if 0 <= r < s:
                        low = False
            out[s] = low
        for s in range(a, b):
            slot[tri[s]] = -1
