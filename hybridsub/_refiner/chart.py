"""The parameter chart: where every refined vertex lies over the input.

Every input face is an equilateral triangle of the chart, and the two faces of an edge form a
rhombus. A step keeps the old vertices where they are, puts edge points at the midpoints of
their edges (Kobbelt's boundary trisection points at the thirds), face points at the centroids
of their faces. The chart is flat away from the input vertices, so the shape of each refined
face — its three corners in a 2-D frame of its own — is all a step needs: a child face's
corners are found in its parent's frame, those of a neighbour face's points after gluing the
neighbour onto the parent along their shared edge (a rigid motion of the chart).

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
    """Each face's corners over the input, followed step by step: ``inface`` (m,) the input
    face whose unfolded chart holds the face, ``B`` (m, 3, 3) its corners' barycentric
    coordinates there (negative across an edge of that face).

    ``step(st)`` follows one :class:`RefinementStep` (faces, matrix, face_parent);
    :meth:`points` puts points given over a face onto input faces.
    """

    def __init__(self, F0: np.ndarray, n0: int, twin_of):
        self.F0, self.F, self.n = F0, F0, n0
        self.twin_of = twin_of
        self.shape = np.repeat(EQUILATERAL[None], len(F0), axis=0)
        self.B = np.repeat(np.eye(3)[None], len(F0), axis=0)
        self.inface = np.arange(len(F0))
        self.twin0 = twin_of(F0, n0)
        self.twin = self.twin0

    def step(self, st) -> None:
        ids, w = matrix_supports(st.matrix, self.n)
        parent = st.face_parent
        shape1 = child_shapes(self.F, self.twin, self.shape, st.faces, parent, ids, w)
        lam = barycentric(self.shape[parent][:, None], shape1)
        self.B = lam @ self.B[parent]
        self.inface = self.inface[parent]
        self.shape, self.F, self.n = shape1, st.faces, st.n_vertices
        self.twin = self.twin_of(self.F, self.n)
        self._rehome()

    def _rehome(self, tol: float = 1e-12) -> None:
        """Faces whose centroid has left their input face across one edge move to the chart of
        the input face across it. Faces drift round a vertex level by level (√3's flips); left
        in the chart they started in, they would end up across the vertex, where the way back
        onto an input face is not unique (a vertex whose faces do not add up to a plane)."""
        for _ in range(8):
            c = self.B.mean(axis=1)
            j = np.argmin(c, axis=1)
            r = np.arange(len(c))
            cj = c[r, j]
            others = np.sort(c, axis=1)[:, 1]
            move = np.flatnonzero((cj < -tol) & (others >= -tol))
            if not len(move):
                return
            t = self.twin0[3 * self.inface[move] + (j[move] + 1) % 3]
            ok = t >= 0
            move, t = move[ok], t[ok]
            if not len(move):
                return
            jj, a = j[move][:, None], (t % 3)[:, None]
            b = self.B[move]  # (k, 3 corners, 3)
            k3 = np.arange(3)[None, :]
            bj = np.take_along_axis(b, np.broadcast_to(jj[:, None], (len(move), 3, 1)), axis=2)[..., 0]
            bj1 = np.take_along_axis(b, np.broadcast_to(((jj + 1) % 3)[:, None], (len(move), 3, 1)), axis=2)[..., 0]
            bj2 = np.take_along_axis(b, np.broadcast_to(((jj + 2) % 3)[:, None], (len(move), 3, 1)), axis=2)[..., 0]
            nb = np.empty_like(b)
            rows = np.arange(len(move))[:, None]
            for col, val in ((a, bj2 + bj), ((a + 1) % 3, bj1 + bj), ((a + 2) % 3, -bj)):
                nb[rows, k3, np.broadcast_to(col, (len(move), 3))] = val
            self.B[move] = nb
            self.inface[move] = t // 3

    def points(self, faces: np.ndarray, bary: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points ``bary`` (k, 3) over the current faces ``faces`` (k,) as (input face, bary)."""
        b = np.einsum("ki,kij->kj", bary, self.B[faces])
        return onto_input_faces(self.inface[faces], b, self.twin0, self.F0)


def best_held_corners(F: np.ndarray, B: np.ndarray, n: int) -> np.ndarray:
    """For each of ``n`` vertices, the corner (flat index into ``F``) whose chart ``B`` (m, 3,
    3) holds it least unfolded: across the fewest edges of its face's input face, then on the
    fewest of their lines, then the least far, then the first; −1 for a vertex no face uses.
    A corner with two negative coordinates lies across a vertex of its input face, and round a
    vertex whose faces do not add up to a plane the way across it is not unique."""
    flat = F.ravel()
    first = np.full(n, -1, np.int64)
    if len(flat):
        Bc = B.reshape(-1, 3)
        across = (Bc < -1e-9).sum(axis=1)
        on_line = (np.abs(Bc) <= 1e-9).sum(axis=1)
        outside = np.round(np.minimum(Bc, 0.0).sum(axis=1), 9)
        corner = np.arange(len(flat))
        order = np.lexsort((corner, -outside, on_line, across, flat))  # by vertex, the best-held first
        lead = np.ones(len(order), bool)
        lead[1:] = flat[order[1:]] != flat[order[:-1]]
        first[flat[order[lead]]] = order[lead]
    return first


def vertex_origins(F0: np.ndarray, n0: int, steps, twin_of) -> tuple[np.ndarray, np.ndarray]:
    """(face, bary) of every vertex of the last of ``steps`` over the input faces ``F0``.

    ``steps`` are :class:`RefinementStep` objects (faces, matrix, face_parent); ``twin_of(F, n)``
    gives a level's halfedge twins. Each vertex is reported through the face of the finest
    level that uses it whose chart holds it least unfolded (across the fewest edges of that
    face's input face, then on the fewest of their lines, then the least far; the first such
    face in face order): a corner
    with two negative coordinates lies across a vertex of its input face, and round a vertex
    whose faces do not add up to a plane the way across it is not unique, while a face that
    holds the vertex within one edge of its input face names the one the refinement put it
    in. A vertex no face uses gets face −1 and bary (1, 0, 0).
    """
    charts = FaceCharts(F0, n0, twin_of)
    for st in steps:
        charts.step(st)
    F, n, B, inface, twin0 = charts.F, charts.n, charts.B, charts.inface, charts.twin0
    flat = F.ravel()
    first = best_held_corners(F, B, n)
    face = np.full(n, -1, np.int64)
    bary = np.zeros((n, 3))
    bary[:, 0] = 1.0
    used = first >= 0
    face[used] = inface[first[used] // 3]
    bary[used] = B[first[used] // 3, first[used] % 3]
    if used.any():
        face[used], bary[used] = onto_input_faces(face[used], bary[used], twin0, F0)
    return face, bary
