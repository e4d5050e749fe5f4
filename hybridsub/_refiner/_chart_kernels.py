"""Numba kernels of the parameter chart (:mod:`.chart`).

Private. Contiguous arrays in, outputs allocated by the caller.
"""

from __future__ import annotations

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
