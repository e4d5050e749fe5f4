"""Closest points on a triangle mesh, for many points at once.

The faces are binned into a uniform grid of cells (every cell its bounding box touches); a
kernel (:mod:`._closest_kernels`) visits each point's cells in shells of growing radius and
stops once no face in the next shell can be closer than the best found. The answer is exact,
not a heuristic, for points near the surface and far from it alike.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._closest_kernels import bin_faces, closest_in_grid

#: Grid cell size in mean edge lengths.
_CELL_EDGES = 1.5
#: Cells per face at most (a coarse cell size for meshes spread thin over a large box).
_CELLS_PER_FACE = 8


@dataclass(frozen=True, eq=False)
class Footpoints:
    """Closest points of m query points on a mesh: ``face`` (m,), ``bary`` (m, 3) barycentric
    coordinates on it, ``points`` (m, 3) the closest points, ``distance`` (m,)."""

    face: np.ndarray
    bary: np.ndarray
    points: np.ndarray
    distance: np.ndarray


def closest_points(P: np.ndarray, faces: np.ndarray, queries: np.ndarray) -> Footpoints:
    """The point of the triangle mesh ``(P, faces)`` closest to each query point.

    Parameters
    ----------
    P : (n, 3) float64
    faces : (f, 3) int64, f >= 1
    queries : (m, 3) float64

    Examples
    --------
    >>> P = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    >>> fp = closest_points(P, np.array([[0, 1, 2], [1, 3, 2]]), np.array([[0.9, 0.9, 2.0], [-1, 0, 0]]))
    >>> fp.face.tolist(), fp.points.round(6).tolist(), fp.distance.round(6).tolist()
    ([1, 0], [[0.9, 0.9, 0.0], [0.0, 0.0, 0.0]], [2.0, 1.0])
    """
    return ClosestPoints(faces, queries).search(P)


class ClosestPoints:
    """Closest points of fixed query points on a mesh of fixed faces whose vertices move.

    Each :meth:`search` bins the faces at the current positions into a grid of cells about
    1.5 mean edge lengths wide and tries each query's previous closest face first, so a fit
    whose surface moves little visits one or two cells per point.
    """

    def __init__(self, faces: np.ndarray, queries: np.ndarray):
        self.faces = np.ascontiguousarray(faces, dtype=np.int64)
        self.queries = np.ascontiguousarray(queries, dtype=np.float64)
        self.previous = np.full(len(self.queries), -1, dtype=np.int64)
        self.used = np.unique(self.faces)  # the vertices the grid must hold

    def search(self, P: np.ndarray) -> Footpoints:
        P = np.ascontiguousarray(P, dtype=np.float64)
        faces, m = self.faces, len(self.queries)
        lo, h, dims = _grid(P[self.used], P[faces])
        start = np.zeros(int(np.prod(dims)) + 1, dtype=np.int64)
        cell_faces = bin_faces(P, faces, np.zeros(len(faces)), lo, h, dims, start)
        face = self.previous.copy()
        bary = np.zeros((m, 3))
        d2 = np.full(m, np.inf)
        closest_in_grid(self.queries, P, faces, lo, h, dims, start, cell_faces, face, bary, d2)
        self.previous = face
        Q = np.einsum("mi,mij->mj", bary, P[faces[face]])
        return Footpoints(face, bary, Q, np.sqrt(d2))


def _grid(used: np.ndarray, tri: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
    """Corner, cell size and cells per axis of the grid over the vertices ``used`` (k, 3) of
    the triangles ``tri`` (f, 3, 3)."""
    lo, hi = used.min(axis=0), used.max(axis=0)
    edge = float(np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2).mean())
    extent = np.maximum(hi - lo, 0.0)
    h = max(_CELL_EDGES * edge, float(extent.max()) * 1e-9, 1e-300)
    while True:
        dims = np.maximum(np.ceil(extent / h).astype(np.int64), 1)
        if int(np.prod(dims)) <= max(_CELLS_PER_FACE * len(tri), 64):
            return lo, h, dims
        h *= 1.5
