"""A level: a mesh's faces with its halfedge twins and tags, built once from the input
(:func:`checked_level` names every topology problem) and derived for every later level by
:mod:`.emit`.

Halfedge ``h = 3 f + i`` of face ``f`` runs ``F[f, i] → F[f, (i+1) % 3]``; ``twin[h]`` is the
halfedge across (−1 on the boundary).

>>> import numpy as np
>>> level = checked_level(np.array([[0, 1, 2], [0, 2, 3]]), 4)
>>> level.twin.tolist(), level.n_edges
([-1, -1, 3, 2, -1, -1], 5)
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from .._errors import MeshError
from . import _kernels as K
from .errors import duplicate_faces_error, not_an_edge_error, topology_error


class Level:
    """Connectivity and tags of one level.

    Attributes
    ----------
    faces : (m, 3) int64
    n_vertices : int
    twin : (3m,) int64
        Halfedge across each halfedge ``3f + i`` (−1 on the boundary).
    hsharp : (3m,) float64 or None
        Tagged sharpness of each halfedge's edge (0 untagged, inf infinitely sharp); None
        when nothing is tagged.
    face_sharp : (m,) bool
        Sharp faces (refined 1-to-4).
    """

    def __init__(self, faces, n_vertices, twin, hsharp=None, face_sharp=None, by_origin=None):
        self.faces = faces
        self.n_vertices = int(n_vertices)
        self.twin = twin
        self.hsharp = hsharp
        self.face_sharp = np.zeros(len(faces), dtype=bool) if face_sharp is None else face_sharp
        self._by_origin = by_origin

    @property
    def n_faces(self) -> int:
        return self.faces.shape[0]

    @cached_property
    def far_apart(self) -> bool:
        """Whether the faces across this level's edges lie far from their own in memory
        (:func:`far_twins`): the one test, made once per level, that decides whether the
        level's kernels prefetch what they read across edges (its topology, its data, and
        the product of its step matrix with the matrices before it)."""
        return bool(K.far_twins(self.twin)) if len(self.twin) else False

    @cached_property
    def _edges(self):
        edge_of = np.empty(len(self.twin), np.int64)  # NumPy's pages: huge ones for big levels
        owner = np.empty(len(self.twin), np.int64)
        return edge_of, owner[:K.number_edges(self.twin, edge_of, owner)].copy()

    @property
    def edge_of(self) -> np.ndarray:
        """(3m,) edge of each halfedge, edges numbered in order of first appearance."""
        return self._edges[0]

    @property
    def edge_owner(self) -> np.ndarray:
        """(ne,) lower-numbered halfedge of each edge."""
        return self._edges[1]

    @property
    def n_edges(self) -> int:
        return self.edge_owner.shape[0]

    @cached_property
    def edge_vertices(self) -> np.ndarray:
        """(ne, 2) edges as vertex pairs in their owner halfedge's orientation."""
        h = self.edge_owner
        f, i = h // 3, h % 3
        ev = np.stack([self.faces[f, i], self.faces[f, (i + 1) % 3]], axis=1)
        ev.flags.writeable = False  # computed once, shared
        return ev

    @property
    def boundary_edge(self) -> np.ndarray:
        return self.twin[self.edge_owner] < 0

    @cached_property
    def valence(self) -> np.ndarray:
        """(n,) number of distinct neighbours of each vertex."""
        val = np.bincount(self.edge_vertices.ravel(), minlength=self.n_vertices)
        val.flags.writeable = False  # computed once, shared
        return val

    @property
    def by_origin(self) -> np.ndarray:
        """(3m,) halfedges grouped by origin vertex (see ``origin_start``)."""
        return self._origin_groups()[0]

    @property
    def origin_start(self) -> np.ndarray:
        """(n + 1,) ``by_origin[origin_start[v]:origin_start[v+1]]`` leave vertex v."""
        return self._origin_groups()[1]

    def _origin_groups(self):
        if self._by_origin is None:
            by_origin = np.empty(3 * self.n_faces, np.int64)
            self._by_origin = by_origin, K.fill_by_origin(self.faces, self.n_vertices, by_origin)
        return self._by_origin

    def find_halfedges(self, pairs: np.ndarray) -> np.ndarray:
        """A halfedge of each vertex pair's edge, −1 where the mesh has no such edge."""
        pairs = np.array(pairs, dtype=np.int64, order="C").reshape(-1, 2)  # a writable copy: one kernel signature
        return K.find_halfedges(pairs, self.faces, self.by_origin, self.origin_start)

    def find_edges(self, pairs: np.ndarray) -> np.ndarray:
        """Edge index of each vertex pair, −1 where the mesh has no such edge."""
        h = self.find_halfedges(pairs)
        return np.where(h >= 0, self.edge_of[np.maximum(h, 0)], -1)

    def tag(self, pairs: np.ndarray, sharpness: np.ndarray, face_sharp: np.ndarray) -> "Level":
        """This level with creases (vertex pairs, sharpness > 0) and sharp faces tagged.

        Raises MeshError naming the first pair that is not an edge; a pair listed twice keeps
        its largest sharpness.
        """
        hsharp = None
        if len(pairs):
            h = self.find_halfedges(pairs)
            if (h < 0).any():
                raise not_an_edge_error(pairs, np.flatnonzero(h < 0))
            hsharp = np.zeros(3 * self.n_faces)
            np.maximum.at(hsharp, h, sharpness)
            t = self.twin[h]
            inner = t >= 0
            np.maximum.at(hsharp, t[inner], sharpness[inner])
        return Level(self.faces, self.n_vertices, self.twin, hsharp, face_sharp, self._by_origin)


def build_level(faces: np.ndarray, n_vertices: int) -> Level:
    """Build the halfedge twins of a mesh, or raise MeshError naming the offending edge.

    ``faces`` must already be an (m, 3) int64 array with indices in range and no repeated
    vertex within a face.
    """
    F = np.ascontiguousarray(faces, dtype=np.int64)
    twin, err = K.twin_search(F, n_vertices)
    if err != K.OK:
        raise topology_error(F) or MeshError("the mesh is not an oriented edge-manifold")
    return Level(F, n_vertices, twin)


def checked_level(F: np.ndarray, n: int, pairs: np.ndarray | None = None) -> Level:
    """``build_level(F, n)``, with every topology problem reported by name.

    Reports duplicate faces, non-manifold edges and inconsistent orientation (with how to fix
    each), and sharp edges (``pairs``) that are not edges of the mesh.
    """
    level = build_level(F, n)
    # A face whose three edges all lie in the same other face: a duplicate with opposite
    # orientation, the two making a closed two-triangle "pillow" the twin search accepts.
    if K.first_pillow(level.twin) >= 0:
        raise duplicate_faces_error(F)
    if pairs is not None and len(pairs):
        eid = level.find_edges(pairs)
        missing = (eid < 0) | (pairs[:, 0] == pairs[:, 1])
        if missing.any():
            raise not_an_edge_error(pairs, np.flatnonzero(missing))
    return level
