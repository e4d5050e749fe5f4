"""Order-independent comparison of two triangle meshes (used against CGAL/OpenSubdiv data)."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def canonical_triangles(F: np.ndarray) -> np.ndarray:
    """Rotate each triangle so its smallest index comes first (orientation kept), then sort rows."""
    F = np.asarray(F, dtype=np.int64)
    r = np.argmin(F, axis=1)
    rows = np.arange(len(F))
    G = np.stack([F[rows, (r + k) % 3] for k in range(3)], axis=1)
    return G[np.lexsort(G.T[::-1])]


def match_vertices(V: np.ndarray, Vref: np.ndarray) -> tuple[np.ndarray, float]:
    """Nearest reference vertex of each vertex, and the largest distance / bbox diagonal."""
    diag = float(np.linalg.norm(Vref.max(0) - Vref.min(0))) or 1.0
    d, idx = cKDTree(Vref).query(V)
    return idx, float(d.max()) / diag if len(d) else 0.0


def mesh_difference(V, F, Vref, Fref, tol: float = 1e-12) -> str | None:
    """None if (V, F) equals (Vref, Fref) up to vertex and face order, else what differs.

    Vertices are matched one-to-one to the nearest reference vertex within ``tol`` × the
    bounding-box diagonal; faces, mapped through the matching, must be the same set of
    oriented triangles.
    """
    V, F = np.asarray(V, float), np.asarray(F, np.int64)
    Vref, Fref = np.asarray(Vref, float), np.asarray(Fref, np.int64)
    if V.shape != Vref.shape or F.shape != Fref.shape:
        return f"shapes {V.shape}/{F.shape} differ from reference {Vref.shape}/{Fref.shape}"
    idx, dmax = match_vertices(V, Vref)
    if len(np.unique(idx)) != len(idx):
        return f"vertices do not match one-to-one (largest distance {dmax:.1e} x diagonal)"
    if dmax > tol:
        return f"largest vertex distance {dmax:.1e} x diagonal > {tol:.0e}"
    if not np.array_equal(canonical_triangles(idx[F]), canonical_triangles(Fref)):
        return "same vertices, different triangles"
    return None
