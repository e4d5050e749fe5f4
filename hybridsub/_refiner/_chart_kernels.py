"""Numba kernels of the parameter chart (:mod:`.chart`).

Private. Contiguous arrays in, outputs allocated by the caller.
"""

from __future__ import annotations

import math

from .._jit import kernel


@kernel
def place_corners(sup_ids, sup_w, pi, group_ids, group_pos, out):
    """Each child corner placed from the first of its parent's four faces (the parent, then
    its edge-neighbours glued onto it) that holds every support of that corner.

    ``sup_ids``, ``sup_w`` (m', 3, 3): supports of each child's corners (id −1: unused);
    ``pi`` (m',): the parent row of each child in ``group_ids`` (p, 4, 3) and ``group_pos``
    (p, 4, 3, 2). Fills ``out`` (m', 3, 2); returns False if a corner has no such face.
    """
    for k in range(sup_ids.shape[0]):
        p = pi[k]
        for c in range(3):
            found = -1
            for g in range(4):
                ok = True
                for s in range(3):
                    v = sup_ids[k, c, s]
                    if v < 0:
                        continue
                    if v != group_ids[p, g, 0] and v != group_ids[p, g, 1] and v != group_ids[p, g, 2]:
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
                v = sup_ids[k, c, s]
                j = 0  # the first corner of the group with that id (unused supports: corner 0, weight 0)
                for i in range(3):
                    if group_ids[p, found, i] == v:
                        j = i
                        break
                w = sup_w[k, c, s]
                x += w * group_pos[p, found, j, 0]
                y += w * group_pos[p, found, j, 1]
            out[k, c, 0] = x
            out[k, c, 1] = y
    return True


@kernel
def glue_corners(shape, twin, faces_at, out):
    """The corners of each face's three edge-neighbours in that face's frame: ``out`` (k, 3, 3, 2)
    (zero on the boundary), as :func:`.chart.glue` (the rigid motion of the shared edge)."""
    for k in range(faces_at.shape[0]):
        f = faces_at[k]
        for i in range(3):
            tw = twin[3 * f + i]
            if tw < 0:
                for c in range(3):
                    out[k, i, c, 0] = 0.0
                    out[k, i, c, 1] = 0.0
                continue
            g, j = tw // 3, tw % 3
            # Here the halfedge runs corner i → i + 1 (u → w); there corner j → j + 1 (w → u).
            ux, uy = shape[f, i, 0], shape[f, i, 1]
            wx, wy = shape[f, (i + 1) % 3, 0], shape[f, (i + 1) % 3, 1]
            px, py = shape[g, (j + 1) % 3, 0], shape[g, (j + 1) % 3, 1]
            qx, qy = shape[g, j, 0], shape[g, j, 1]
            a = math.atan2(wy - uy, wx - ux) - math.atan2(qy - py, qx - px)
            c_, s_ = math.cos(a), math.sin(a)
            tx = ux - (c_ * px - s_ * py)
            ty = uy - (s_ * px + c_ * py)
            for c in range(3):
                x, y = shape[g, c, 0], shape[g, c, 1]
                out[k, i, c, 0] = (c_ * x - s_ * y) + tx
                out[k, i, c, 1] = (s_ * x + c_ * y) + ty
