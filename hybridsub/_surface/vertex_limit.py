"""The public limit functions: :func:`limit_matrix`, :func:`limit_positions`,
:func:`limit_normals`, :func:`limit_tangents`, :func:`limit_mesh`, and the one evaluation of
a level they share: the vertex lane where it applies (``vertex_lane``), else the plan of every
vertex, then local refinement where needed."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from .._input import as_vertices
from .._topology import Level
from .._typing import ArrayLike, Boundary, LoopWeights, Scheme
from .limit_setup import LimitInput, setup_limit, walk_for_limit
from .level_eval import evaluate_level
from .normals import one_side_sectors, unit, vertex_normals
from .mask_plan import SEC_FAN, SEC_TRANSIENT
from .vertex_lane import level_limits


def _check_tol(tol, max_levels):
    tol = float(tol)
    if not tol > 0:
        raise ValueError(f"tol must be positive, got {tol}")
    if isinstance(max_levels, bool) or int(max_levels) != max_levels or max_levels < 1:
        raise ValueError(f"max_levels must be a positive integer, got {max_levels!r}")
    return tol, int(max_levels)


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
        refinement: the level evaluated is refined until its sharpness is spent).
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
        L, _, _ = evaluate_level(s, scheme, loop_weights, None, True, tol, max_levels)
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
    li = walk_for_limit(Vf, F, sharp_edges, levels, scheme, sharpness, sharp_faces, corners, loop_weights,
                        feature_angle=feature_angle, corner_sharpness=corner_sharpness, boundary=boundary, holes=holes,
                        local_corners=True)
    P, _ = _level_limits(li, Vf, loop_weights, True, False, "average", tol, tol, max_levels)
    out_dtype = A.dtype if np.issubdtype(A.dtype, np.floating) else np.float64
    return np.ascontiguousarray(P[: li.n_keep], dtype=out_dtype)


def _level_limits(li: LimitInput, Vf: np.ndarray, loop_weights: str, want_positions: bool, want_normals: bool,
                  crease_normals: str, tol: float, normal_tol: float, max_levels: int):
    """Limit positions and unit normals (each or None, as wanted) of every vertex of the level
    evaluated (the vertex lane)."""
    X = li.X if li.X is not None else li.refinement.apply(Vf)
    if len(li.faces) == 0:
        return X, np.zeros_like(X)
    return level_limits(li, X, loop_weights, want_positions, want_normals, crease_normals, tol, normal_tol, max_levels)


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
    _, plan, nrm = evaluate_level(s, scheme, loop_weights, X, False, tol, max_levels)
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
    _check_crease_normals(crease_normals)
    if not per_face_corner:
        Vf = as_vertices(np.asarray(V))
        tol, max_levels = _check_tol(tol, max_levels)
        li = walk_for_limit(Vf, F, sharp_edges, levels, scheme, sharpness, sharp_faces, corners, loop_weights,
                            feature_angle=feature_angle, corner_sharpness=corner_sharpness, boundary=boundary,
                            holes=holes)
        _, N = _level_limits(li, Vf, loop_weights, False, True, crease_normals, tol, tol, max_levels)
        return N[: li.n_keep]
    s, F_out, keep, ev = _sector_evaluation(V, F, sharp_edges, levels, scheme, sharpness, sharp_faces, corners,
                                            loop_weights, feature_angle, tol, max_levels, corner_sharpness, boundary,
                                            holes)
    if ev is None:
        return np.zeros((len(F_out), 3, 3))[keep]
    X, plan, nrm = ev
    if s.same_level:
        return nrm[plan.sectors.he_sector].reshape(-1, 3, 3)[keep]
    return vertex_normals(s.level, plan, nrm, X)[F_out][keep]


class LimitMesh(NamedTuple):
    """A mesh refined and put on its limit surface (:func:`limit_mesh`)."""

    vertices: np.ndarray  #: (n_L, 3) limit positions of the level's vertices
    faces: np.ndarray  #: (m_L, 3) the level's faces (those of holes left out)
    normals: np.ndarray | None  #: (n_L, 3) unit limit normals, or None


def limit_mesh(V: ArrayLike, F: ArrayLike, sharp_edges: ArrayLike | None = None, *, levels: int = 1,
               scheme: Scheme = "hybrid", sharpness: ArrayLike | None = None, sharp_faces: ArrayLike | None = None,
               corners: ArrayLike | None = None, loop_weights: LoopWeights = "loop",
               feature_angle: float | None = None, normals: bool = True, crease_normals: str = "average",
               tol: float = 1e-12, normal_tol: float = 1e-10, max_levels: int = 60,
               corner_sharpness: ArrayLike | None = None, boundary: Boundary = "edge_only",
               holes: ArrayLike | None = None) -> LimitMesh:
    """A mesh refined ``levels`` times with its vertices on the limit surface, and their normals.

    One refinement and one pass over the vertices give what :func:`hybridsub.refine`,
    :func:`limit_positions` and :func:`limit_normals` give separately (the same numbers):
    what a renderer or an exporter wants from a subdivision surface, as OpenSubdiv's limit
    stencils or Adobe Lagrange's ``subdivide_mesh(use_limit_surface=True)`` give it.

    Parameters
    ----------
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, 3) array_like of int
        Triangles, consistently oriented, every edge in one or two faces.
    sharp_edges, levels, scheme, sharpness, sharp_faces, corners, loop_weights, feature_angle, corner_sharpness, boundary, holes
        As for :func:`limit_positions` (holes: their faces are left out of ``faces``).
    normals : bool
        Also give the unit limit normals (False: ``normals`` is None).
    crease_normals : {"average", "one_side"}
        As for :func:`limit_normals`.
    tol, max_levels
        As for :func:`limit_positions`.
    normal_tol
        As ``tol`` of :func:`limit_normals`.

    Returns
    -------
    LimitMesh
        ``(vertices, faces, normals)``.

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> V, F = hybridsub.load_example("fandisk")
    >>> m = hybridsub.limit_mesh(V, F, levels=2, scheme="loop", feature_angle=30)
    >>> m.vertices.shape == m.normals.shape, len(m.faces) == 16 * len(F)
    (True, True)
    >>> bool(np.allclose(m.vertices, hybridsub.limit_positions(V, F, levels=2, scheme="loop", feature_angle=30)))
    True
    """
    _check_crease_normals(crease_normals)
    if not isinstance(normals, (bool, np.bool_)):
        raise TypeError(f"normals must be True or False, got {normals!r}")
    A = np.asarray(V)
    Vf = as_vertices(A)
    tol, max_levels = _check_tol(tol, max_levels)
    normal_tol, _ = _check_tol(normal_tol, max_levels)
    li = walk_for_limit(Vf, F, sharp_edges, levels, scheme, sharpness, sharp_faces, corners, loop_weights,
                        feature_angle=feature_angle, corner_sharpness=corner_sharpness, boundary=boundary, holes=holes,
                        local_corners=not normals)
    P, N = _level_limits(li, Vf, loop_weights, True, bool(normals), crease_normals, tol, normal_tol, max_levels)
    out_dtype = A.dtype if np.issubdtype(A.dtype, np.floating) else np.float64
    return LimitMesh(np.ascontiguousarray(P[: li.n_keep], dtype=out_dtype), li.out_faces,
                     N[: li.n_keep] if normals else None)


def _check_crease_normals(crease_normals):
    if not isinstance(crease_normals, str) or crease_normals not in CREASE_NORMALS:
        raise ValueError(f"crease_normals must be one of {CREASE_NORMALS}, got {crease_normals!r}")


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
    first = one_side_sectors(s.level, plan.sectors)
    used = first >= 0
    T1, T2 = np.zeros((s.level.n_vertices, 3)), np.zeros((s.level.n_vertices, 3))
    T1[used], T2[used] = t1[first[used]], t2[first[used]]
    if per_face_corner:  # √3 at an odd level: evaluated one level finer, where these vertices are
        return T1[F_out][keep], T2[F_out][keep]
    return T1[: s.n_keep], T2[: s.n_keep]
