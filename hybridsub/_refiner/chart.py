"""The parameter chart: where every refined vertex lies over the input.

Every face of every level is an equilateral triangle of a frame of its own, and the two faces
of an edge form a rhombus there (each the other's mirror image). A step keeps the old vertices
where they are, puts edge points at the midpoints of their edges (Kobbelt's boundary
trisection points at the thirds), face points at the centroids of their faces, all in the
parent face's frame: a child face's corners are found there, those of a neighbour face's
points after gluing the neighbour onto the parent along their shared edge (a rigid motion).
So a child's place in its parent depends on the connectivity and tags alone, never on the
shapes of the levels above: the limit surface's patches repeat wherever their connectivity
does (``docs/limit.md``). The map from a face to the input is piecewise affine (a point of a
child that straddles two parents is carried through the parent it lies in).

>>> import numpy as np
>>> F = np.array([[0, 1, 2], [2, 1, 3]]); shape = np.repeat(EQUILATERAL[None], 2, axis=0)
>>> twin = np.array([-1, 3, -1, 1, -1, -1])
>>> glued = glue(shape, twin, F)           # face 1 seen from face 0, across edge 1 → 2
>>> np.round(glued[0, 1, 2], 6).tolist()   # face 1's third vertex: the rhombus's far corner
[1.5, 0.866025]
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ._chart_kernels import child_corners, fill_supports

#: The input faces' corners in their own frames: equilateral, unit sides.
EQUILATERAL = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, np.sqrt(3.0) / 2]])


def barycentric(tri: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Barycentric coordinates of points ``x`` (..., 2) in triangles ``tri`` (..., 3, 2)."""
    a, b, c = tri[..., 0, :], tri[..., 1, :], tri[..., 2, :]
    e1, e2, d = b - a, c - a, x - a
    det = e1[..., 0] * e2[..., 1] - e1[..., 1] * e2[..., 0]
    u = (d[..., 0] * e2[..., 1] - d[..., 1] * e2[..., 0]) / det
    v = (e1[..., 0] * d[..., 1] - e1[..., 1] * d[..., 0]) / det
    return np.stack([1.0 - u - v, u, v], axis=-1)


def rigid(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray):
    """The rotation R (..., 2, 2) and translation t (..., 2) taking segment p0p1 onto q0q1."""
    dp, dq = p1 - p0, q1 - q0
    ap = np.arctan2(dp[..., 1], dp[..., 0])
    aq = np.arctan2(dq[..., 1], dq[..., 0])
    c, s = np.cos(aq - ap), np.sin(aq - ap)
    R = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)
    t = q0 - np.einsum("...ij,...j->...i", R, p0)
    return R, t


def glue_maps(shape: np.ndarray, twin: np.ndarray, faces_at: np.ndarray):
    """For faces ``faces_at`` (k,), the rigid map of each edge-neighbour's frame onto theirs.

    Returns ``nbr`` (k, 3) the neighbour across halfedge i (−1 on the boundary) and ``R``
    (k, 3, 2, 2), ``t`` (k, 3, 2): ``x_here = R @ x_there + t``.
    """
    h = 3 * faces_at[:, None] + np.arange(3)
    tw = twin[h]
    nbr = np.where(tw >= 0, tw // 3, -1)
    j = np.where(tw >= 0, tw % 3, 0)
    g = np.maximum(nbr, 0)
    here = shape[faces_at]  # (k, 3, 2)
    u_here, w_here = here, np.roll(here, -1, axis=1)  # halfedge i runs corner i → i + 1
    # The neighbour's halfedge j runs w → u.
    w_there = shape[g, j]
    u_there = shape[g, (j + 1) % 3]
    R, t = rigid(u_there, w_there, u_here, w_here)
    return nbr, R, t


def glue(shape: np.ndarray, twin: np.ndarray, F: np.ndarray, faces_at: np.ndarray | None = None) -> np.ndarray:
    """Corners (k, 3, 3, 2) of each face's three edge-neighbours, in that face's frame (NaN on the boundary)."""
    faces_at = np.arange(len(F)) if faces_at is None else faces_at
    nbr, R, t = glue_maps(shape, twin, faces_at)
    out = np.einsum("kiab,kicb->kica", R, shape[np.maximum(nbr, 0)]) + t[:, :, None, :]
    out[nbr < 0] = np.nan
    return out


def plan_supports(F: np.ndarray, plan, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Chart weights of every vertex of the next level over this level's: (n', 3) ids, (n', 3) weights.

    Old vertices keep their place, edge points sit at midpoints (Kobbelt's trisection points
    at the thirds), face points at centroids. Unused slots have id −1 and weight 0.
    """
    n1 = plan.n_new
    ids = np.full((n1, 3), -1, np.int64)
    w = np.zeros((n1, 3))
    ids[:n, 0] = np.arange(n)
    w[:n, 0] = 1.0
    fill_supports(np.ascontiguousarray(F, dtype=np.int64), np.ascontiguousarray(plan.edge_point, dtype=np.int64),
                  np.ascontiguousarray(plan.trisected, dtype=np.int64),
                  np.ascontiguousarray(plan.face_point, dtype=np.int64), ids, w)
    return ids, w


def matrix_supports(S: sp.csr_matrix, n: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`plan_supports` read off a step matrix's rows (for a :class:`Refinement`, which keeps no plans).

    A row of three weights 1/3 is a face point; otherwise the two largest weights are the
    edge's ends: a midpoint if they are equal, else a trisection point (2/3 at the larger).
    """
    S = sp.csr_matrix(S)
    n1 = S.shape[0]
    ids = np.full((n1, 3), -1, np.int64)
    w = np.zeros((n1, 3))
    ids[:n, 0] = np.arange(n)
    w[:n, 0] = 1.0
    nnz = np.diff(S.indptr)[n:]
    rows = np.arange(n, n1)
    if not len(nnz):
        return ids, w
    width = max(int(nnz.max()), 3)
    pad_i = np.full((len(rows), width), -1, np.int64)
    pad_w = np.full((len(rows), width), -1.0)
    r = np.repeat(np.arange(len(rows)), nnz)
    col = np.arange(len(r)) - np.repeat(S.indptr[n:-1] - S.indptr[n], nnz)
    pad_i[r, col] = S.indices[S.indptr[n]:]
    pad_w[r, col] = S.data[S.indptr[n]:]
    order = np.argsort(-pad_w, axis=1, kind="stable")
    pi = np.take_along_axis(pad_i, order, 1)
    pw = np.take_along_axis(pad_w, order, 1)
    face = (nnz == 3) & np.all(np.abs(pad_w[:, :3] - 1.0 / 3.0) < 1e-12, axis=1)
    ids[rows, 0], ids[rows, 1] = pi[:, 0], pi[:, 1]
    same = np.abs(pw[:, 0] - pw[:, 1]) < 1e-9
    w[rows, 0] = np.where(same, 0.5, 2.0 / 3.0)
    w[rows, 1] = np.where(same, 0.5, 1.0 / 3.0)
    fr = rows[face]
    ids[fr] = pad_i[face, :3]
    w[fr] = 1.0 / 3.0
    return ids, w


def child_shapes(F: np.ndarray, twin: np.ndarray, shape: np.ndarray, faces1: np.ndarray, parent: np.ndarray,
                 sup_ids: np.ndarray, sup_w: np.ndarray) -> np.ndarray:
    """Each child face's corners (m', 3, 2) in its parent's frame.

    ``faces1`` and ``parent`` may be any subset of the next level's faces. A child's corner is
    a chart combination of the corners of one face: its parent, or one of the parent's
    edge-neighbours glued onto it (a neighbour's face point, Kobbelt's apexes). The first
    of those four faces that holds every support is used: around a vertex of low valence the
    chart is not flat, and the same vertex glued through two neighbours lies in two places.
    """
    out = np.empty((len(faces1), 3, 2))
    ok = child_corners(np.ascontiguousarray(F, dtype=np.int64), np.ascontiguousarray(twin, dtype=np.int64),
                       np.ascontiguousarray(shape, dtype=np.float64), np.ascontiguousarray(faces1, dtype=np.int64),
                       np.ascontiguousarray(parent, dtype=np.int64), np.ascontiguousarray(sup_ids, dtype=np.int64),
                       np.ascontiguousarray(sup_w, dtype=np.float64), out)
    if not ok:  # pragma: no cover - the emission patterns guarantee it
        raise AssertionError("a child corner is not a combination of its parent's neighbourhood")
    return out


def _across(face, bary, twin0, tol):
    """One reflection: points with a coordinate below ``-tol`` expressed over the face across
    the edge opposite that corner (the rhombus's other triangle); boundary points stay."""
    j = np.argmin(bary, axis=1)
    out = bary[np.arange(len(bary)), j] < -tol
    t = twin0[3 * face[out] + (j[out] + 1) % 3]
    ok = t >= 0
    idx = np.flatnonzero(out)[ok]
    t, jj = t[ok], j[out][ok]
    b = bary[idx]
    r = np.arange(len(idx))
    bj, bj1, bj2 = b[r, jj], b[r, (jj + 1) % 3], b[r, (jj + 2) % 3]
    nb = np.empty_like(b)
    a = t % 3  # the face across: its corner a is our corner j + 2, a + 1 is j + 1, a + 2 the far one
    nb[r, a], nb[r, (a + 1) % 3], nb[r, (a + 2) % 3] = bj2 + bj, bj1 + bj, -bj
    face[idx], bary[idx] = t // 3, nb
    return len(idx) > 0


def onto_input_faces(face: np.ndarray, bary: np.ndarray, twin0: np.ndarray, F0: np.ndarray, max_faces: int = 8):
    """Points given in an input face's unfolded chart moved onto an input face that contains them.

    A point with a negative coordinate lies across the edge opposite that corner: it is
    expressed over the face across, and again from there (a point near a vertex may be
    several faces round it), at most ``max_faces`` times; at the boundary it is clamped onto
    the face. Tiny negatives are rounding.
    """
    face, bary = face.copy(), bary.copy()
    for _ in range(max_faces):
        if not _across(face, bary, twin0, 1e-12):
            break
    bary = np.clip(bary, 0.0, None)
    return face, bary / bary.sum(axis=1, keepdims=True)


class FaceCharts:
    """Where points of a refined level lie over the input, followed step by step.

    Every face of every level is an equilateral triangle of its own frame, its edge-neighbours
    glued on as mirror images (the rhombus of two faces), so a step's children have fixed
    places in their parent's frame: a child corner is a chart combination (midpoint,
    Kobbelt's third, centroid) of the parent's corners or of a neighbour's, the neighbour's
    far corner being the parent's corner mirrored across their edge. ``step(st)`` follows one
    :class:`RefinementStep` (faces, matrix, face_parent) and keeps each child's corners in its
    parent's frame; :meth:`points` carries points given over the last level's faces up, one
    level at a time, across an edge where a point lies in its parent's neighbour, onto the
    input faces.
    """

    def __init__(self, F0: np.ndarray, n0: int, twin_of):
        self.F0, self.F, self.n = F0, F0, n0
        self.twin_of = twin_of
        self.twin0 = twin_of(F0, n0)
        self.twin = self.twin0
        self.levels = []  # per step: each child's corners in its parent's frame (m', 3, 3), the parents, their twins

    def step(self, st) -> None:
        ids, w = matrix_supports(st.matrix, self.n)
        parent = st.face_parent
        shape = np.broadcast_to(EQUILATERAL, (len(self.F), 3, 2))
        lam = barycentric(EQUILATERAL, child_shapes(self.F, self.twin, shape, st.faces, parent, ids, w))
        self.levels.append((lam, np.asarray(parent, dtype=np.int64), self.twin))
        self.F, self.n = st.faces, st.n_vertices
        self.twin = self.twin_of(self.F, self.n)

    def points(self, faces: np.ndarray, bary: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points ``bary`` (k, 3) over the current faces ``faces`` (k,) as (input face, bary)."""
        f, b = np.asarray(faces, dtype=np.int64), np.asarray(bary, dtype=np.float64)
        for lam, parent, twin in reversed(self.levels):
            b = np.einsum("ki,kij->kj", b, lam[f])
            f, b = onto_input_faces(parent[f], b, twin, None)
        return f, b

    def vertices(self, faces: np.ndarray, n: int, only: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(face, bary) over the input of each of the current level's ``n`` vertices (or of
        the vertices ``only``), through the first of the faces ``faces`` that uses it (face −1,
        bary (1, 0, 0) where none does)."""
        face = np.full(n, -1, np.int64)
        bary = np.zeros((n, 3))
        bary[:, 0] = 1.0
        flat = (3 * np.asarray(faces, dtype=np.int64)[:, None] + np.arange(3)).ravel()
        used, first = np.unique(self.F.ravel()[flat], return_index=True)
        last = np.full(n, -1, np.int64)
        last[used] = flat[first]  # the first corner of each vertex
        if only is not None:
            last = last[only]
            face, bary = face[:len(last)], bary[:len(last)]
        used = np.flatnonzero(last >= 0)
        if len(used):
            face[used], bary[used] = self.points(last[used] // 3, np.eye(3)[last[used] % 3])
        return face, bary


def vertex_origins(F0: np.ndarray, n0: int, steps, twin_of) -> tuple[np.ndarray, np.ndarray]:
    """(face, bary) of every vertex of the last of ``steps`` over the input faces ``F0``.

    ``steps`` are :class:`RefinementStep` objects (faces, matrix, face_parent); ``twin_of(F, n)``
    gives a level's halfedge twins. Each vertex is carried up from the first face of the last
    level that uses it (:meth:`FaceCharts.points`); one on an input edge or at an input vertex
    is reported over one of the input faces there. A vertex no face uses gets face −1 and
    bary (1, 0, 0).
    """
    charts = FaceCharts(F0, n0, twin_of)
    for st in steps:
        charts.step(st)
    return charts.vertices(np.arange(len(charts.F)), charts.n)
