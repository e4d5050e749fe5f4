"""Welding: vertices at identical positions merged into one, and the equal-row classes it is
built on (also used to split vertices along UV seams for formats without face-varying UVs)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .mesh import TaggedMesh


def classes(arrays: list, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows equal in every one of ``arrays`` (each with ``n`` rows), as classes numbered by
    first appearance: (class of each row, first row of each class). Positions compare
    exactly (-0.0 equals 0.0).

    Examples
    --------
    >>> cls, first = classes([np.array([5, 3, 5, 3, 7])], 5)
    >>> cls.tolist(), first.tolist()
    ([0, 1, 0, 1, 2], [0, 1, 4])
    """
    lab = np.zeros(n, np.int64)
    for A in arrays:
        A = np.ascontiguousarray(A).reshape(n, -1)
        if A.dtype.kind == "f":
            A = A + 0.0
        _, inv = np.unique(A, axis=0, return_inverse=True)
        _, lab = np.unique(lab * (int(inv.max(initial=0)) + 1) + inv.ravel(), return_inverse=True)
        lab = lab.ravel()
    _, first, inv = np.unique(lab, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")
    rank = np.empty(len(order), np.int64)
    rank[order] = np.arange(len(order))
    return rank[inv.ravel()], first[order]


def weld(mesh: TaggedMesh) -> tuple[TaggedMesh, int, int]:
    """Merge vertices at identical positions (first occurrence keeps its place); faces that
    collapse are dropped. UV indices that end up on one vertex with equal UVs are merged too
    (so that only real UV seams remain). Returns the mesh, the number of vertices merged
    away, and the number of faces dropped.

    Examples
    --------
    >>> V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0]])
    >>> m, merged, dropped = weld(TaggedMesh(V, np.array([[0, 1, 2], [2, 3, 4]])))
    >>> m.faces.tolist(), merged, dropped
    ([[0, 1, 2], [2, 1, 3]], 1, 0)
    """
    V = mesh.vertices
    new, keep_v = classes([V], len(V))
    F = new[mesh.faces]
    ok = (F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0])
    fmap = np.cumsum(ok) - 1
    E = new[mesh.sharp_edges]
    eok = E[:, 0] != E[:, 1]
    S = mesh.sharp_faces[ok[mesh.sharp_faces]] if len(mesh.sharp_faces) else mesh.sharp_faces
    uv, face_uv = mesh.uv, mesh.face_uv
    if uv is not None and face_uv is not None:
        t = face_uv[ok].ravel()
        corner, first = classes([F[ok].ravel(), uv[t]], len(t))
        uv, face_uv = uv[t[first]], corner.reshape(-1, 3)
    out = replace(
        mesh, vertices=V[keep_v], faces=F[ok], sharp_edges=E[eok], sharpness=mesh.sharpness[eok],
        corners=np.unique(new[mesh.corners]), sharp_faces=fmap[S],
        vertex_colors=None if mesh.vertex_colors is None else mesh.vertex_colors[keep_v], uv=uv, face_uv=face_uv,
    )
    return out, len(V) - len(keep_v), int((~ok).sum())
