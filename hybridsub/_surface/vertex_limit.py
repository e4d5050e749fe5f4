"""The public limit functions: :func:`limit_matrix`, :func:`limit_positions`,
:func:`limit_normals`, and the one evaluation of a level they share (plan, then local
refinement where needed)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .._input import as_vertices, open_gate
from .._topology import Level, build_level
from .._typing import ArrayLike, Boundary, LoopWeights, Scheme
from .._refiner import refinement_of
from .._refiner.refinement import level_holes
from .local import plan_vertices, refine_locally
from .normals import sector_normals, unit
from .mask_plan import SEC_FAN, SEC_TRANSIENT, edge_sharpness

# ---------------------------------------------------------------------------------------------
# Input preparation: the mesh refined to the level evaluated, its tags per edge, face, vertex
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class LimitSetup:
    """A mesh and its tags, refined to the level the limit is evaluated at."""

    level: Level | None  # the level evaluated (None: no faces)
    tagged: np.ndarray
    esharp: np.ndarray
    face_sharp: np.ndarray
    corner: np.ndarray  # (n,) bool, or with local_corners each vertex's sharpness left (float64)
    refinement: object  # the Refinement to the evaluated level
    n_keep: int  # vertices of the requested level
    same_level: bool  # evaluated at the requested level (else one finer: Kobbelt's parity)
    hole: np.ndarray | None = None  # (m,) the input's holes (None: none)

    def kept_faces(self, levels: int) -> np.ndarray | slice:
        """The faces of level ``levels`` not descending from a hole (a mask, or all)."""
        if self.hole is None:
            return slice(None)
        return ~level_holes(self.refinement.steps[:levels], self.hole)[-1]


def setup_limit(F, sharp_edges, levels, n_vertices, scheme, sharpness, sharp_faces, corners, loop_weights,
                positions=None, feature_angle=None, corner_sharpness=None, boundary="edge_only",
                holes=None, local_corners=False) -> LimitSetup:
    """Check the input and refine it to the level evaluated (see :class:`LimitSetup`).

    With ``local_corners`` (limit positions and matrices) a semi-sharp corner keeps its
    sharpness left at the level evaluated (``corner`` is then vertex sharpness): its star
    alone is refined until the sharpness is spent (:func:`.local.refine_locally`). Without
    (normals, tangents) the whole mesh is refined uniformly until every sharpness is spent
    (⌈s⌉ levels), so the masks of the level evaluated see none (the old vertices keep their
    indices, hence the first ``n_keep``).

    >>> import numpy as np
    >>> s = setup_limit(np.array([[0, 1, 2]]), None, 1, None, "sqrt3", None, None, None, "loop")
    >>> s.same_level, s.n_keep, s.level.n_vertices                 # √3 is evaluated at even levels
    (False, 4, 10)
    """
    inp = open_gate(F, sharp_edges, levels, n_vertices=n_vertices, scheme=scheme, sharpness=sharpness,
                    sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights, positions=positions,
                    feature_angle=feature_angle, corner_sharpness=corner_sharpness, boundary=boundary, holes=holes)
    levels, n = inp.levels, inp.n_vertices
    l_eval = levels
    if inp.corner_sharpness is not None and not local_corners:
        finite = inp.corner_sharpness[np.isfinite(inp.corner_sharpness)]
        l_eval = max(levels, int(np.ceil(finite.max(initial=0.0))))
    # Kobbelt's boundary rule alternates: evaluate where the next step is odd.
    l_eval += 1 if scheme == "sqrt3" and l_eval % 2 else 0
    r = refinement_of(dataclasses.replace(inp, levels=l_eval))
    n_keep = r.steps[levels - 1].n_vertices if levels else n
    faces = r.faces
    n_eval = r.n_vertices
    m = len(faces)
    fsh = np.asarray(r.sharp_faces)
    face_sharp = np.zeros(m, dtype=bool)
    if fsh.dtype == bool:
        face_sharp[:] = fsh
    else:
        face_sharp[fsh] = True
    if scheme == "loop":
        face_sharp[:] = True
    corner = np.zeros(n_eval, dtype=bool)
    corner[np.asarray(r.corners, dtype=np.int64)] = True
    if local_corners and inp.corner_sharpness is not None:
        corner = np.zeros(n_eval)
        left = r.corner_sharpness
        corner[np.asarray(r.corners, dtype=np.int64)] = np.inf if left is None else left
    if m == 0:
        return LimitSetup(None, None, None, face_sharp, corner, r, n_keep, l_eval == levels, inp.hole)
    level = build_level(faces, n_eval)
    tagged, esharp = edge_sharpness(level, np.asarray(r.sharp_edges, np.int64).reshape(-1, 2),
                                    np.asarray(r.sharpness, np.float64), scheme)
    return LimitSetup(level, tagged, esharp, face_sharp, corner, r, n_keep, l_eval == levels, inp.hole)


def _check_tol(tol, max_levels):
    tol = float(tol)
    if not tol > 0:
        raise ValueError(f"tol must be positive, got {tol}")
    if isinstance(max_levels, bool) or int(max_levels) != max_levels or max_levels < 1:
        raise ValueError(f"max_levels must be a positive integer, got {max_levels!r}")
    return tol, int(max_levels)


# ---------------------------------------------------------------------------------------------
# The evaluation of one level
# ---------------------------------------------------------------------------------------------


def _evaluate(s: LimitSetup, scheme, loop_weights, X, want_rows, tol, max_levels):
    """Limit matrix (n × n CSR, or None), plan and sector normals (or None) of the level evaluated."""
    level = s.level
    n = level.n_vertices
    plan = plan_vertices(level, s.esharp, s.face_sharp, s.corner, scheme, loop_weights)
    nrm = sector_normals(level, plan, X) if X is not None else None
    need = np.zeros(n, dtype=bool)
    if want_rows:
        need |= ~plan.pos_ok
    if X is not None:
        need[plan.sectors.vertex[plan.sec_kind == SEC_TRANSIENT]] = True
    centers = np.flatnonzero(need)
    rows = None
    if len(centers):
        rows, est = refine_locally(level, s.tagged, s.face_sharp, s.corner, scheme, loop_weights, centers, plan, X,
                                   want_rows, tol, max_levels)
        if X is not None:
            t = plan.sec_kind == SEC_TRANSIENT
            nrm[t] = est[t]
    if not want_rows:
        return None, plan, nrm
    L = plan.limit_csr(n)
    if rows is not None:
        moved = sp.csr_matrix((np.ones(len(centers)), (centers, np.arange(len(centers)))), shape=(n, len(centers)))
        L = L + moved @ rows
    L = sp.csr_matrix(L)
    L.sum_duplicates()
    L.sort_indices()
    return L, plan, nrm


def _vertex_normals(level: Level, plan, nrm: np.ndarray, X: np.ndarray) -> np.ndarray:
    """Unit normal of every vertex: the normalized sum of its sectors' unit normals."""
    N = np.zeros((level.n_vertices, 3))
    np.add.at(N, plan.sectors.vertex, nrm)
    # Sectors facing opposite ways (a fin: a crease that turns back on itself) cancel; there
    # the vertex gets its control fan's normal instead.
    cancel = np.linalg.norm(N, axis=1) < 1e-6
    if cancel.any():
        Fl = level.faces
        fn = np.cross(X[Fl[:, 1]] - X[Fl[:, 0]], X[Fl[:, 2]] - X[Fl[:, 0]])
        fan = np.zeros_like(N)
        for i in range(3):
            np.add.at(fan, Fl[:, i], fn)
        N[cancel] = fan[cancel]
    return unit(N)


# ---------------------------------------------------------------------------------------------
# Public API
# ---------------------------------------------------------------------------------------------


def limit_matrix(F: ArrayLike, sharp_edges: ArrayLike | None = None, *, levels: int = 0,
                 n_vertices: int | None = None, scheme: Scheme = "hybrid", sharpness: ArrayLike | None = None,
                 sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
                 loop_weights: LoopWeights = "loop", feature_angle: float | None = None,
                 vertices: ArrayLike | None = None, tol: float = 1e-12, max_levels: int = 60,
                 corner_sharpness: ArrayLike | None = None, boundary: Boundary = "edge_only",
                 holes: ArrayLike | None = None) -> sp.csr_matrix:
    """The limit matrix: where every vertex of a level goes when refined forever.

    Parameters
    ----------
    F : (m, 3) array_like of int
        Triangles, consistently oriented, every edge in one or two faces.
    sharp_edges : (k, 2) array_like of int, optional
        Crease edges (vertex pairs, either orientation), as for :func:`hybridsub.refine`.
    levels : int
        Give the limit positions of the vertices of this level of refinement (0: the input).
    n_vertices : int, optional
        Number of vertices; default ``F.max() + 1``.
    scheme : {"hybrid", "sqrt3", "loop"}
        The subdivision scheme whose limit is meant.
    sharpness, sharp_faces, corners, corner_sharpness, boundary, loop_weights
        As for :func:`hybridsub.refine` (a semi-sharp corner's limit is that of uniform
        refinement until its sharpness is spent: its star alone is refined so far).
    feature_angle : float, optional
        Also keep sharp the edges whose dihedral angle exceeds this many degrees, with their
        corners, as for :func:`hybridsub.limit_positions`; the angles are measured on
        ``vertices``, which it needs.
    vertices : (n, 3) array_like of float, optional
        Positions: used only to detect features (the matrix itself depends on the
        connectivity and tags alone).
    tol : float
        Vertices without a stationary limit mask (``docs/limit.md``) are refined locally until
        their weights change by less than this.
    max_levels : int
        At most this many local refinements (a ``RuntimeWarning`` says if ``tol`` was missed).
    holes : (m,) bool mask or array_like of int, optional
        Faces not rendered (:func:`hybridsub.refine`): checked, and without effect on the
        limit, which they shape like any face (every vertex keeps its row).

    Returns
    -------
    L : scipy.sparse.csr_matrix, (n_L, n)
        Limit positions of the level-``levels`` vertices are ``L @ V``. Rows are affine
        (sum to 1) and non-negative (up to rounding where a row was extrapolated).

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])   # tetrahedron
    >>> L = hybridsub.limit_matrix(F, scheme="loop")
    >>> L.shape, np.allclose(L.sum(axis=1), 1)
    ((4, 4), True)
    >>> L[0].toarray().round(4)                     # Loop's limit mask at valence 3
    array([[0.4, 0.2, 0.2, 0.2]])
    """
    tol, max_levels = _check_tol(tol, max_levels)
    Vf = None
    if feature_angle is not None:
        if vertices is None:
            raise TypeError("limit_matrix(feature_angle=...) needs vertices= (the positions the angles are measured on)")
        Vf = as_vertices(vertices)
        if n_vertices is not None and n_vertices != len(Vf):
            raise ValueError(f"n_vertices={n_vertices} but vertices has {len(Vf)} rows")
        n_vertices = len(Vf)
    s = setup_limit(F, sharp_edges, levels, n_vertices, scheme, sharpness, sharp_faces, corners, loop_weights,
                    positions=Vf, feature_angle=feature_angle, corner_sharpness=corner_sharpness, boundary=boundary,
                    holes=holes, local_corners=True)
    r = s.refinement
    if s.level is None:
        L = sp.identity(r.n_vertices, format="csr")
    else:
        L, _, _ = _evaluate(s, scheme, loop_weights, None, True, tol, max_levels)
    out = sp.csr_matrix((L @ r.matrix)[: s.n_keep])
    out.sort_indices()
    return out


def limit_positions(V: ArrayLike, F: ArrayLike, sharp_edges: ArrayLike | None = None, *, levels: int = 0,
                    scheme: Scheme = "hybrid", sharpness: ArrayLike | None = None,
                    sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
                    loop_weights: LoopWeights = "loop", feature_angle: float | None = None, tol: float = 1e-12,
                    max_levels: int = 60, corner_sharpness: ArrayLike | None = None,
                    boundary: Boundary = "edge_only", holes: ArrayLike | None = None) -> np.ndarray:
    """Limit positions of a mesh's vertices: the points of the limit surface they converge to.

    Parameters
    ----------
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, 3) array_like of int
        Triangles, consistently oriented, every edge in one or two faces.
    sharp_edges, levels, scheme, sharpness, sharp_faces, corners, loop_weights, tol, max_levels, corner_sharpness, boundary, holes
        As for :func:`limit_matrix` (holes do not move any limit position).
    feature_angle : float, optional
        Also tag the features :func:`hybridsub.detect_features` finds at this angle (degrees),
        as :func:`hybridsub.subdivide` does.

    Returns
    -------
    (n_L, 3) ndarray
        Limit positions of the vertices of level ``levels`` (in the dtype of ``V`` if it is
        floating-point).

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    >>> P = hybridsub.limit_positions(V, F, scheme="sqrt3")     # Kobbelt: β_3 = 5/8
    >>> P[0] * 6
    array([1., 1., 1.])
    """
    A = np.asarray(V)
    Vf = as_vertices(A)
    tol, max_levels = _check_tol(tol, max_levels)
    s = setup_limit(F, sharp_edges, levels, len(Vf), scheme, sharpness, sharp_faces, corners, loop_weights,
                    positions=Vf, feature_angle=feature_angle, corner_sharpness=corner_sharpness, boundary=boundary,
                    holes=holes, local_corners=True)
    X = s.refinement.apply(Vf)
    if s.level is not None:
        L, _, _ = _evaluate(s, scheme, loop_weights, None, True, tol, max_levels)
        X = L @ X
    out_dtype = A.dtype if np.issubdtype(A.dtype, np.floating) else np.float64
    return np.ascontiguousarray(X[: s.n_keep], dtype=out_dtype)


def _one_side_sectors(level: Level, sec) -> np.ndarray:
    """(n,) the sector that gives a vertex with several sectors its one side; -1 where no face is.

    OpenSubdiv's rule (Sdc's crease limit tangent masks take the span counter-clockwise from
    the first crease edge in the vertex's edge order, which starts at the outgoing edge of its
    first face): the sector of the vertex's first face corner (in face order) if that corner's
    outgoing edge starts the sector, else the next sector counter-clockwise.
    """
    n = level.n_vertices
    out = np.full(n, -1, dtype=np.int64)
    corners = level.faces.ravel()
    first = np.full(n, len(corners), dtype=np.int64)
    np.minimum.at(first, corners, np.arange(len(corners)))
    v = np.flatnonzero(first < len(corners))
    h0 = first[v]
    s0 = sec.he_sector[h0]
    at_start = (sec.slots[sec.slot_start[:-1][s0]] == h0) | ~sec.open[s0]
    key = sec.vertex * np.int64(n) + sec.first_ring  # the sector of a vertex that starts at q
    order = np.argsort(key, kind="stable")
    want = sec.vertex[s0] * np.int64(n) + sec.last_ring[s0]  # the next one starts where s0 ends
    i = np.minimum(np.searchsorted(key[order], want), len(order) - 1)
    found = key[order[i]] == want
    out[v] = np.where(at_start | ~found, s0, order[i])
    return out


CREASE_NORMALS = ("average", "one_side")


def _sector_evaluation(V, F, sharp_edges, levels, scheme, sharpness, sharp_faces, corners, loop_weights,
                       feature_angle, tol, max_levels, corner_sharpness, boundary, holes):
    """What :func:`limit_normals` and :func:`limit_tangents` share: the setup, the finest
    level's faces and the rendered ones among them, and ``(X, plan, sector normals)`` of the
    level evaluated (None without faces)."""
    Vf = as_vertices(np.asarray(V))
    tol, max_levels = _check_tol(tol, max_levels)
    s = setup_limit(F, sharp_edges, levels, len(Vf), scheme, sharpness, sharp_faces, corners, loop_weights,
                    positions=Vf, feature_angle=feature_angle, corner_sharpness=corner_sharpness, boundary=boundary,
                    holes=holes)
    r = s.refinement
    F_out = r.steps[levels - 1].faces if levels else r.faces
    keep = s.kept_faces(levels)
    if s.level is None:
        return s, F_out, keep, None
    X = r.apply(Vf)
    _, plan, nrm = _evaluate(s, scheme, loop_weights, X, False, tol, max_levels)
    return s, F_out, keep, (X, plan, nrm)


def limit_normals(V: ArrayLike, F: ArrayLike, sharp_edges: ArrayLike | None = None, *, levels: int = 0,
                  scheme: Scheme = "hybrid", sharpness: ArrayLike | None = None,
                  sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
                  loop_weights: LoopWeights = "loop", feature_angle: float | None = None,
                  per_face_corner: bool = False, tol: float = 1e-10, max_levels: int = 60,
                  corner_sharpness: ArrayLike | None = None, boundary: Boundary = "edge_only",
                  crease_normals: str = "average", holes: ArrayLike | None = None) -> np.ndarray:
    """Unit normals of the limit surface at the limit positions of a mesh's vertices.

    Smooth vertices get the normal of the limit surface's tangent plane (Kobbelt's and
    Loop's tangent masks). On a crease each side (sector) has its own normal; a vertex gets
    the normalized mean of its sectors' unit normals (``crease_normals="average"``), or the
    normal of one side (``"one_side"``: the side OpenSubdiv's limit tangents, and so Adobe
    Lagrange's normals, take, see ``docs/limit.md``); ``per_face_corner=True`` gives
    each face corner the normal of its sector (split normals, for shading). ``docs/limit.md``
    says what each kind of vertex gets, and where the limit surface has no tangent plane.

    Parameters
    ----------
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, 3) array_like of int
        Triangles, consistently oriented, every edge in one or two faces.
    sharp_edges, levels, scheme, sharpness, sharp_faces, corners, loop_weights, feature_angle, corner_sharpness, boundary
        As for :func:`limit_positions`.
    per_face_corner : bool
        Return one normal per face corner, ``(m_L, 3, 3)``, instead of one per vertex.
    tol, max_levels
        For the vertices without stationary tangent masks, refined locally until the normal
        changes by less than ``tol`` (or ``max_levels`` levels).
    crease_normals : {"average", "one_side"}
        The normal of a vertex with several sectors (crease, corner): the normalized mean of
        its sectors' normals, or the normal of OpenSubdiv's side: the sector of its first face
        corner (in face order) when that corner's outgoing edge is a crease, else the next sector
        counter-clockwise.
    holes : (m,) bool mask or array_like of int, optional
        Faces not rendered (:func:`hybridsub.refine`): they shape the normals like any face;
        ``per_face_corner`` leaves out the rows of the faces descending from them.

    Returns
    -------
    (n_L, 3) ndarray, or (m_L, 3, 3) with ``per_face_corner``
        Unit normals on the side the faces face (right-hand rule on ``F``'s order); zero at
        vertices no face uses.

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    >>> N = hybridsub.limit_normals(V, F, scheme="loop")
    >>> np.allclose(N, V / np.sqrt(3))                 # outward, by symmetry
    True
    """
    if not isinstance(crease_normals, str) or crease_normals not in CREASE_NORMALS:
        raise ValueError(f"crease_normals must be one of {CREASE_NORMALS}, got {crease_normals!r}")
    s, F_out, keep, ev = _sector_evaluation(V, F, sharp_edges, levels, scheme, sharpness, sharp_faces, corners,
                                            loop_weights, feature_angle, tol, max_levels, corner_sharpness, boundary,
                                            holes)
    if ev is None:
        N = np.zeros((s.n_keep, 3))
        return np.zeros((len(F_out), 3, 3))[keep] if per_face_corner else N
    X, plan, nrm = ev
    N = _vertex_normals(s.level, plan, nrm, X)
    if per_face_corner:
        if s.same_level:
            return nrm[plan.sectors.he_sector].reshape(-1, 3, 3)[keep]
        return N[F_out][keep]
    if crease_normals == "one_side":
        first = _one_side_sectors(s.level, plan.sectors)
        used = first >= 0
        N[used] = nrm[first[used]]
    return N[: s.n_keep]


def _sector_tangents(level: Level, plan, nrm: np.ndarray, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The two tangents of every sector: its tangent masks applied to ``X`` (not normalised);
    where a sector has none (``SEC_TRANSIENT``, ``SEC_FAN``) or they are degenerate, an
    orthonormal pair of its normal's plane, the first along the sector's first ring edge.
    Oriented so that ``t1 × t2`` is on the side of the sector's normal."""
    T1, T2 = plan.tangent_csr(level.n_vertices)
    t1, t2 = T1 @ X, T2 @ X
    cr = np.cross(t1, t2)
    size = np.linalg.norm(cr, axis=1)
    scale = np.linalg.norm(t1, axis=1) * np.linalg.norm(t2, axis=1)
    kind = plan.sec_kind
    weak = (kind == SEC_TRANSIENT) | (kind == SEC_FAN) | (size <= 1e-12 * scale) | (scale == 0)
    flip = ~weak & (np.einsum("ij,ij->i", cr, nrm) < 0)  # corners: the two crease tangents in turn
    t1[flip], t2[flip] = t2[flip].copy(), t1[flip].copy()
    if weak.any():
        sec = plan.sectors
        n = nrm[weak]
        e = X[sec.first_ring[weak]] - X[sec.vertex[weak]]
        e = e - np.einsum("ij,ij->i", e, n)[:, None] * n
        t1[weak] = unit(e)
        t2[weak] = np.cross(n, t1[weak])
    return t1, t2


def limit_tangents(V: ArrayLike, F: ArrayLike, sharp_edges: ArrayLike | None = None, *, levels: int = 0,
                   scheme: Scheme = "hybrid", sharpness: ArrayLike | None = None,
                   sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
                   loop_weights: LoopWeights = "loop", feature_angle: float | None = None,
                   per_face_corner: bool = False, tol: float = 1e-10, max_levels: int = 60,
                   corner_sharpness: ArrayLike | None = None, boundary: Boundary = "edge_only",
                   holes: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Two tangents of the limit surface at the limit positions of a mesh's vertices.

    The limit tangent masks applied to the positions, as OpenSubdiv's limit stencils
    (``Far::LimitStencilTable``'s du and dv, ``PrimvarRefiner::Limit`` with tangents) give
    them: not normalised, and at a smooth vertex depending on where its ring starts (another
    start turns the pair in its plane; ``T1 × T2`` stays the same). ``T1 × T2`` points to the
    side :func:`limit_normals` does. A vertex with several sectors (crease, corner) gets the
    tangents of one side, OpenSubdiv's (the side ``limit_normals(..., crease_normals="one_side")``
    takes, ``docs/limit.md``); ``per_face_corner=True`` gives
    every face corner its own sector's. On a crease ``T1`` runs along it (``q_0 − q_k`` of the
    sector, ``docs/limit.md``) and ``T2`` across; at a corner they are the two crease edges.
    Where the scheme has no stationary tangent mask (a semi-sharp crease still decaying, a
    vertex between √3 and Loop faces of the hybrid), the pair is orthonormal, spanning the
    plane of the normal that local refinement finds, ``T1`` along the sector's first edge.

    Parameters
    ----------
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, 3) array_like of int
        Triangles, consistently oriented, every edge in one or two faces.
    sharp_edges, levels, scheme, sharpness, sharp_faces, corners, loop_weights, feature_angle
        As for :func:`limit_positions`.
    per_face_corner : bool
        Return the tangents of every face corner, two ``(m_L, 3, 3)`` arrays.
    tol, max_levels, corner_sharpness, boundary, holes
        As for :func:`limit_normals`.

    Returns
    -------
    T1, T2 : (n_L, 3) ndarrays, or (m_L, 3, 3) with ``per_face_corner``
        Zero at vertices no face uses.

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    >>> T1, T2 = hybridsub.limit_tangents(V, F, scheme="loop")
    >>> N = hybridsub.limit_normals(V, F, scheme="loop")
    >>> bool(np.allclose(hybridsub._surface.normals.unit(np.cross(T1, T2)), N))
    True
    >>> bool(np.allclose(np.einsum("ij,ij->i", T1, N), 0))     # in the tangent plane
    True
    """
    s, F_out, keep, ev = _sector_evaluation(V, F, sharp_edges, levels, scheme, sharpness, sharp_faces, corners,
                                            loop_weights, feature_angle, tol, max_levels, corner_sharpness, boundary,
                                            holes)
    if ev is None:
        z = np.zeros((len(F_out), 3, 3))[keep] if per_face_corner else np.zeros((s.n_keep, 3))
        return z, z.copy()
    X, plan, nrm = ev
    t1, t2 = _sector_tangents(s.level, plan, nrm, X)
    if per_face_corner and s.same_level:
        h = plan.sectors.he_sector
        return t1[h].reshape(-1, 3, 3)[keep], t2[h].reshape(-1, 3, 3)[keep]
    first = _one_side_sectors(s.level, plan.sectors)
    used = first >= 0
    T1, T2 = np.zeros((s.level.n_vertices, 3)), np.zeros((s.level.n_vertices, 3))
    T1[used], T2[used] = t1[first[used]], t2[first[used]]
    if per_face_corner:  # √3 at an odd level: evaluated one level finer, where these vertices are
        return T1[F_out][keep], T2[F_out][keep]
    return T1[: s.n_keep], T2[: s.n_keep]
