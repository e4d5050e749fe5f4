"""Numba kernels of the parameter chart (:mod:`.chart`).

Private. Contiguous arrays in, outputs allocated by the caller.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import kernel


@kernel(inline="always")
def _glue_one(shape, twin, f, out):
    """The corners of face ``f``'s three edge-neighbours in its frame, ``out`` (3, 3, 2) (zero
    on the boundary): the rigid motion that lays the shared edges on each other."""
    for i in range(3):
        tw = twin[3 * f + i]
        if tw < 0:
            out[i] = 0.0
            continue
        g, j = tw // 3, tw % 3
        # Here the halfedge runs corner i → i + 1 (u → w); there corner j → j + 1 (w → u).
        ux, uy = shape[f, i, 0], shape[f, i, 1]
        wx, wy = shape[f, (i + 1) % 3, 0], shape[f, (i + 1) % 3, 1]
        px, py = shape[g, (j + 1) % 3, 0], shape[g, (j + 1) % 3, 1]
        qx, qy = shape[g, j, 0], shape[g, j, 1]
        # The rotation taking direction q - p onto w - u: cos and sin of the angle between them.
        ax, ay, bx, by = qx - px, qy - py, wx - ux, wy - uy
        r = 1.0 / math.sqrt((ax * ax + ay * ay) * (bx * bx + by * by))
        c_, s_ = (ax * bx + ay * by) * r, (ax * by - ay * bx) * r
        tx = ux - (c_ * px - s_ * py)
        ty = uy - (s_ * px + c_ * py)
        for c in range(3):
            x, y = shape[g, c, 0], shape[g, c, 1]
            out[i, c, 0] = (c_ * x - s_ * y) + tx
            out[i, c, 1] = (s_ * x + c_ * y) + ty


@kernel
def child_corners(F, twin, shape, faces1, parent, sup_ids, sup_w, out):
    """Each child corner placed from the first of its parent's four faces (the parent, then
    its edge-neighbours glued onto it) that holds every support of that corner.

    ``faces1`` (m', 3) and ``parent`` (m',): the children; ``sup_ids``, ``sup_w`` (n', 3):
    the chart supports of every new vertex (id −1: unused). Fills ``out`` (m', 3, 2);
    returns False if a corner has no such face.
    """
    slot = np.full(len(F), -1, np.int64)
    gids = np.empty((len(faces1), 4, 3), np.int64)
    gpos = np.empty((len(faces1), 4, 3, 2))
    used = 0
    for k in range(len(faces1)):
        p = parent[k]
        if slot[p] < 0:  # the parent's four faces, once
            slot[p] = used
            for c in range(3):
                gids[used, 0, c] = F[p, c]
                gpos[used, 0, c, 0] = shape[p, c, 0]
                gpos[used, 0, c, 1] = shape[p, c, 1]
                tw = twin[3 * p + c]
                for a in range(3):
                    gids[used, c + 1, a] = F[tw // 3, a] if tw >= 0 else -2  # −2 matches nothing
            _glue_one(shape, twin, p, gpos[used, 1:])
            used += 1
        s0 = slot[p]
        for c in range(3):
            vid = faces1[k, c]
            found = -1
            for g in range(4):
                ok = True
                for s in range(3):
                    v = sup_ids[vid, s]
                    if v >= 0 and v != gids[s0, g, 0] and v != gids[s0, g, 1] and v != gids[s0, g, 2]:
                        ok = False
                        break
                if ok:
                    found = g
                    break
            if found < 0:
                return False
            x = 0.0
            y = 0.0
            for s in range(3):
                v = sup_ids[vid, s]
                j = 0  # the group's first corner with that id (unused supports: corner 0, weight 0)
                for i in range(3):
                    if gids[s0, found, i] == v:
                        j = i
                        break
                w = sup_w[vid, s]
                x += w * gpos[s0, found, j, 0]
                y += w * gpos[s0, found, j, 1]
            out[k, c, 0] = x
            out[k, c, 1] = y
    return True


@kernel
def fill_supports(F, edge_point, trisected, face_point, ids, w):
    """:func:`.chart.plan_supports` for the new vertices: ``ids``, ``w`` (n', 3) filled in
    place (old vertices already set), halfedges in order (the last of an edge's two wins)."""
    for h in range(len(edge_point)):
        e = edge_point[h]
        if e < 0:
            continue
        f, i = h // 3, h % 3
        a, b = F[f, i], F[f, (i + 1) % 3]
        ids[e, 0], ids[e, 1] = a, b
        if trisected[f] == i:
            w[e, 0], w[e, 1] = 2.0 / 3.0, 1.0 / 3.0
            ids[e + 1, 0], ids[e + 1, 1] = a, b
            w[e + 1, 0], w[e + 1, 1] = 1.0 / 3.0, 2.0 / 3.0
        else:
            w[e, 0], w[e, 1] = 0.5, 0.5
    for f in range(len(face_point)):
        p = face_point[f]
        if p >= 0:
            for c in range(3):
                ids[p, c] = F[f, c]
                w[p, c] = 1.0 / 3.0
