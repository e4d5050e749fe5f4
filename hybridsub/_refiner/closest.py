"""Closest points on a triangle mesh, for many points at once.

A k-d tree on the triangles' centroids proposes the k nearest triangles of each point; the
kernel (:mod:`._closest_kernels`) finds the closest point on each. The answer is exact, not a
heuristic: a triangle whose centroid is farther than d from a point has no point nearer than
d − r (r: the largest centroid-to-vertex distance), so a point is settled once its k-th
centroid is at least its best distance + r away; the others are asked again with twice the
candidates, until every triangle has been tried.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._closest_kernels import closest_among

_FIRST_CANDIDATES = 8
_MAX_SPLIT = 16
_MAX_CANDIDATES = 256


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

    The k-d tree holds sample points of the triangles: a triangle of reach r (largest
    centroid-to-corner distance) is split evenly into s² similar pieces, s = ceil(r / ρ)
    (ρ: the median reach, s at most 16), and contributes their centroids, so every point of
    a triangle is within ρ' = max r / s of one of its samples. A triangle none of whose
    samples is among a query's k nearest (the k-th at distance D) is then at least D − ρ'
    away: a query is settled once D − ρ' reaches its best distance; the others are asked
    again with twice the candidates (past 256, every face is tried). Each :meth:`search` first tries the candidates of the
    last query, with D lowered by how far the mesh's vertices moved since (summed), so a
    fit whose surface moves less and less asks the tree for fewer and fewer points.
    """

    def __init__(self, faces: np.ndarray, queries: np.ndarray):
        self.faces = np.ascontiguousarray(faces, dtype=np.int64)
        self.queries = np.ascontiguousarray(queries, dtype=np.float64)
        m = len(self.queries)
        self.k = min(_FIRST_CANDIDATES, len(self.faces))
        self.candidates = np.full((m, self.k), -1, dtype=np.int64)
        self.kth = np.full(m, -np.inf)          # k-th sample's distance at the query
        self.drift = np.zeros(m)                # how far any vertex may have moved since then
        self.last = None                        # vertex positions at the last search
        self.split = None                       # pieces per side, per face (set at the first search)

    def search(self, P: np.ndarray) -> Footpoints:
        P = np.ascontiguousarray(P, dtype=np.float64)
        faces, queries = self.faces, self.queries
        m = len(queries)
        tri = P[faces]
        reach = np.sqrt(((tri - tri.mean(axis=1)[:, None, :]) ** 2).sum(axis=2)).max(axis=1)
        if self.split is None:
            rho = max(float(np.median(reach)), 1e-300)
            self.split = np.minimum(np.ceil(reach / rho), _MAX_SPLIT).astype(np.int64).clip(1)
        rho = float((reach / self.split).max())
        if self.last is not None:
            self.drift += float(np.sqrt(((P - self.last) ** 2).sum(axis=1)).max())
        self.last = P
        face = np.full(m, -1, dtype=np.int64)
        bary = np.zeros((m, 3))
        d2 = np.full(m, np.inf)
        closest_among(queries, P, faces, self.candidates, face, bary, d2)
        todo = np.flatnonzero(self.kth - self.drift - rho < np.sqrt(d2))
        if len(todo):
            owner, sample = _samples(tri, self.split)
            from scipy.spatial import cKDTree  # (imported when used: it costs start-up time)

            tree = cKDTree(sample)
        k = self.k
        while len(todo):
            cd, ci = tree.query(queries[todo], k=k, workers=-1)
            cand = np.ascontiguousarray(owner[ci.reshape(len(todo), k)])
            f, b, d = face[todo], bary[todo], d2[todo]
            closest_among(queries[todo], P, faces, cand, f, b, d)
            face[todo], bary[todo], d2[todo] = f, b, d
            kth = np.full(len(todo), np.inf) if k >= len(owner) else cd.reshape(len(todo), k)[:, -1]
            if k == self.k:  # keep the first round's candidates for the next search
                self.candidates[todo], self.kth[todo], self.drift[todo] = cand, kth, 0.0
            todo = todo[kth - rho < np.sqrt(d)]
            k = min(2 * k, len(owner))
            if k > _MAX_CANDIDATES and len(todo):  # far from a coarse, uneven mesh: try every face
                _every_face(queries, P, faces, todo, face, bary, d2)
                break
        Q = np.einsum("mi,mij->mj", bary, P[faces[face]])
        return Footpoints(face, bary, Q, np.sqrt(d2))


def _every_face(queries, P, faces, todo, face, bary, d2, chunk_bytes=1 << 24) -> None:
    """The closest point of each query in ``todo`` among all faces, in chunks of queries."""
    nf = len(faces)
    step = max(1, chunk_bytes // (8 * nf))
    for lo in range(0, len(todo), step):
        t = todo[lo:lo + step]
        every = np.tile(np.arange(nf, dtype=np.int64), (len(t), 1))
        f, b, d = face[t], bary[t], d2[t]
        closest_among(queries[t], P, faces, every, f, b, d)
        face[t], bary[t], d2[t] = f, b, d


def _samples(tri: np.ndarray, split: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Owner face and position of the samples: the centroids of each face's s² pieces."""
    owners, points = [], []
    for s in np.unique(split):
        fs = np.flatnonzero(split == s)
        b = _piece_centroids(int(s))                               # (s², 3) barycentric
        owners.append(np.repeat(fs, len(b)))
        points.append(np.einsum("pi,fij->fpj", b, tri[fs]).reshape(-1, 3))
    return np.concatenate(owners), np.concatenate(points)


def _piece_centroids(s: int) -> np.ndarray:
    """Barycentric centroids of the s² triangles of a triangle split evenly s times per side."""
    up = [(i + 1 / 3, j + 1 / 3, s - 1 - i - j + 1 / 3) for i in range(s) for j in range(s - i)]
    down = [(i + 2 / 3, j + 2 / 3, s - 2 - i - j + 2 / 3) for i in range(s - 1) for j in range(s - 1 - i)]
    return np.array(up + down) / s
