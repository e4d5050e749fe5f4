"""Topology problems, named: the messages for what a Level cannot be built from.

Each function returns a :class:`~hybridsub.MeshError` (it does not raise) that names the
faces, the edge or the row at fault and says how to fix it; the callers raise it.

>>> import numpy as np
>>> str(duplicate_faces_error(np.array([[0, 1, 2], [1, 2, 0]])))[:36]
'faces 0 and 1 are duplicate faces: b'
"""

from __future__ import annotations

import numpy as np

from .._errors import MeshError
from .edges import group_halfedges, halfedge_ends


def not_an_edge_error(pairs: np.ndarray, missing: np.ndarray) -> MeshError:
    """Sharp edge rows ``missing`` (indices into ``pairs``) are not edges of the mesh."""
    j = int(missing[0])
    u, w = int(pairs[j, 0]), int(pairs[j, 1])
    why = f"it joins vertex {u} to itself" if u == w else f"no face has both vertex {u} and vertex {w}"
    more = f" ({len(missing)} such rows)" if len(missing) > 1 else ""
    return MeshError(f"sharp edge {j} = [{u}, {w}] is not an edge of the mesh: {why}{more}")


def duplicate_faces_error(F: np.ndarray) -> MeshError | None:
    """A MeshError naming the first face that repeats an earlier one's vertices, or None."""
    if len(F) < 2:
        return None
    S = np.sort(F, axis=1)
    order = np.lexsort((S[:, 2], S[:, 1], S[:, 0]))  # stable: ties in face order
    Ss = S[order]
    same = (Ss[1:] == Ss[:-1]).all(axis=1)
    if not same.any():
        return None
    new = np.concatenate([[True], ~same])
    first = order[new][np.cumsum(new) - 1]  # the lowest face of each group
    dup = order[1:][same]
    orig = first[1:][same]
    k = int(np.argmin(dup))
    f, g = int(orig[k]), int(dup[k])
    rotations = [np.roll(F[g], r) for r in range(3)]
    how = "the same" if any((x == F[f]).all() for x in rotations) else "opposite"
    return MeshError(
        f"faces {f} and {g} are duplicate faces: both are the triangle on vertices {sorted(F[f].tolist())}, "
        f"with {how} orientation ({int(same.sum())} duplicate face{'s' if same.sum() > 1 else ''} in all); "
        "remove the duplicates "
        "first, e.g. with trimesh: mesh.update_faces(mesh.unique_faces())"
    )


def topology_error(F: np.ndarray) -> MeshError | None:
    """The first topology problem of F, described with a fix: duplicate faces, then edges in
    three or more faces, then edges whose two faces disagree on orientation. None if none."""
    dup = duplicate_faces_error(F)
    if dup is not None:
        return dup
    u, w = halfedge_ends(F)
    g = group_halfedges(u, w)
    order, starts, sizes = g.order, g.starts, g.sizes
    a, b = g.first, g.second
    many = sizes >= 3
    if many.any():
        k = int(np.flatnonzero(many)[np.argmin(a[many])])
        faces = sorted((order[starts[k]:starts[k] + sizes[k]] // 3).tolist())
        lo, hi = sorted((int(u[a[k]]), int(w[a[k]])))
        more = f"; {int(many.sum())} such edges in all" if many.sum() > 1 else ""
        return MeshError(
            f"edge ({lo}, {hi}) is shared by {len(faces)} faces {faces}: the "
            f"mesh is not edge-manifold (every edge must lie in one or two faces){more}. Remove the extra "
            "faces, or pass non_manifold=\"cut\" to cut the mesh along such edges (they become creases "
            "where the pieces meet; see docs/errors.md)"
        )
    flipped = (sizes == 2) & (u[a] == u[b])
    if flipped.any():
        k = int(np.flatnonzero(flipped)[np.argmin(a[flipped])])
        h1, h2 = int(a[k]), int(b[k])
        more = f"; {int(flipped.sum())} such edges in all" if flipped.sum() > 1 else ""
        return MeshError(
            f"faces {h1 // 3} and {h2 // 3} both run along edge {int(u[h1])}->{int(w[h1])} in the same "
            f"direction: the mesh is not consistently oriented{more}. Reverse the vertex order of the faces "
            "on one side (e.g. trimesh.repair.fix_winding(mesh), or igl.bfs_orient(F)); a surface that "
            "cannot be oriented (a Möbius strip) can be cut along such edges with non_manifold=\"cut\""
        )
    return None
