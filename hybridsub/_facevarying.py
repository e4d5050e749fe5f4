"""Face-varying data (UVs with seams): refining an index mesh ``(UV, FUV)`` beside ``(V, F)``.

Textures come as per-corner indices: ``FUV (m, 3)`` aligned face by face with ``F`` (OBJ's
``f v/vt``). A *seam* is an interior edge whose two faces disagree on the UV indices at its
ends. The UV index mesh is refined with the geometry's own split/flip decisions, so the
refined ``FUV'`` stays aligned face by face with ``F'``:

- geometry: seams are split (R4 edge point), never flipped; they are not creases;
- the UV index mesh has the geometry's halfedges, its twins cut along seams, so its boundary
  is the mesh boundary plus both sides of every seam (and it is built from the geometry's
  adjacency, never from UV indices alone: a UV index pair that happens to recur elsewhere
  does not glue faces);
- its new points follow the same layout as the geometry's (old UVs, one point per split UV
  edge in UV edge order, one per face point in face order), and its faces are emitted by the
  same kernel in the same order, so child ``k`` of face ``f`` is the same triangle in both.

``uv_mode="linear"``: old values stay, edge points are midpoints, face points centroids.
``uv_mode="smooth"``: the scheme's rules on the UV index mesh, its boundary as creases,
geometric creases and corners carried onto it; a UV index used by several separate face
sectors, by several geometric vertices or at a bow-tie vertex is kept as one value and made
a UV corner.
See ``docs/face_varying.md``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from . import _kernels as K
from . import _rules as R
from . import _validate as val
from ._errors import MeshError
from ._refine import Refinement, RefinementStep
from ._stencils import step_matrix
from ._topology import Level, child_creases, child_level, face_parents, plan_step
from ._typing import ArrayLike, LoopWeights, Scheme, UVMode

UV_MODES = ("linear", "smooth")


class FaceVaryingRefinement(NamedTuple):
    """What :func:`refine_face_varying` returns: two refinements with aligned faces.

    Attributes
    ----------
    geometry : Refinement
        The mesh's refinement (seams split, never flipped); ``geometry.apply(V)`` refines
        positions or any per-vertex data.
    uv : Refinement
        The UV index mesh's refinement: ``uv.faces`` is ``FUV'`` (row ``f`` is the same
        triangle as ``geometry.faces[f]``), ``uv.apply(UV)`` refines UVs or any per-UV-index
        data, ``uv.matrix`` is the composite UV matrix. ``uv.sharp_edges``/``uv.sharpness``
        are the geometric creases carried onto the UV index mesh's interior edges (as UV
        index pairs; seams are UV boundary, creases implicitly, and like every boundary edge
        not listed), ``uv.corners`` the UV indices kept as corners in ``"smooth"`` mode
        (carried corner tags, and UV indices shared by separate sectors or vertices, or at bow-tie
        vertices).
    """

    geometry: Refinement
    uv: Refinement


def seam_edges(F: ArrayLike, FUV: ArrayLike) -> np.ndarray:
    """Seams of a textured mesh: interior edges whose two faces disagree on the UV indices.

    Parameters
    ----------
    F, FUV : (m, 3) array_like of int
        Faces and their per-corner UV indices (aligned row by row).

    Returns
    -------
    (k, 2) int64 ndarray
        Seam edges as vertex pairs, in edge order (the orientation of the lower-numbered
        halfedge).

    Examples
    --------
    >>> import hybridsub
    >>> F = [[0, 1, 2], [0, 2, 3]]
    >>> hybridsub.seam_edges(F, [[0, 1, 2], [3, 4, 5]]).tolist()
    [[2, 0]]
    """
    Fi, n = val.as_faces(F, None)
    T = _as_uv_faces(FUV, len(Fi), None)
    if not len(Fi):
        return np.empty((0, 2), np.int64)
    level = val.checked_level(Fi, n)
    seam = _seam_halfedges(level, T)
    return level.edge_vertices[seam[level.edge_owner]]


def refine_face_varying(F: ArrayLike, FUV: ArrayLike, sharp_edges: ArrayLike | None = None, levels: int = 1, *,
                        n_vertices: int | None = None, n_uvs: int | None = None, scheme: Scheme = "hybrid",
                        uv_mode: UVMode = "linear", sharpness: ArrayLike | None = None,
                        sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
                        loop_weights: LoopWeights = "loop") -> FaceVaryingRefinement:
    """Refine a mesh's connectivity together with its face-varying (UV) index mesh.

    Parameters
    ----------
    F : (m, 3) array_like of int
        Triangles, consistently oriented, every edge in one or two faces.
    FUV : (m, 3) array_like of int
        UV index of each face corner (row ``f`` belongs to face ``f``); a face may repeat a UV
        index (a degenerate UV triangle).
    sharp_edges, levels, sharpness, sharp_faces, corners, loop_weights
        As in :func:`hybridsub.refine`.
    n_vertices : int, optional
        Number of vertices; default ``F.max() + 1``.
    n_uvs : int, optional
        Number of UV values; default ``FUV.max() + 1``. Unused values are kept and never move.
    scheme : {"hybrid", "loop"}
        ``"sqrt3"`` cannot honour seams (a √3 flip across a seam would make a triangle that
        spans two UV charts) and raises ``ValueError``.
    uv_mode : {"linear", "smooth"}
        ``"linear"``: old UVs stay, edge points are midpoints, face points centroids
        (OpenSubdiv's ``FVAR_LINEAR_ALL``). ``"smooth"``: the scheme's rules on the UV index
        mesh, its boundary (mesh boundary and seams) as creases (OpenSubdiv's
        ``FVAR_LINEAR_NONE``, see ``docs/face_varying.md`` for the one difference).

    Returns
    -------
    FaceVaryingRefinement
        ``(geometry, uv)``: two :class:`Refinement` objects whose faces are aligned row by row.

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> F = np.array([[0, 1, 2], [0, 2, 3]]); FUV = np.array([[0, 1, 2], [3, 4, 5]])  # seam 0-2
    >>> geo, uv = hybridsub.refine_face_varying(F, FUV, levels=1)
    >>> geo.faces.shape, uv.faces.shape, geo.matrix.shape, uv.matrix.shape
    ((12, 3), (12, 3), (11, 4), (14, 6))
    """
    levels = val.check_options(scheme, levels, loop_weights)
    if scheme == "sqrt3":
        raise ValueError(
            'scheme="sqrt3" cannot honour UV seams (Kobbelt\'s √3 flips every edge, and a flip across a seam '
            'makes a triangle spanning two UV charts); use scheme="hybrid" (√3 with seams split) or "loop"'
        )
    if uv_mode not in UV_MODES:
        raise ValueError(f"uv_mode must be one of {UV_MODES}, got {uv_mode!r}")
    Fi, n = val.as_faces(F, n_vertices)
    m = len(Fi)
    T = _as_uv_faces(FUV, m, n_uvs)
    t = int(n_uvs) if n_uvs is not None else (int(T.max()) + 1 if T.size else 0)
    pairs, sharp = val.as_sharp_edges(sharp_edges, sharpness, n)
    face_sharp, faces_as_indices = val.as_face_mask(sharp_faces, m)
    corner = val.as_corner_mask(corners, n)
    if scheme == "loop":
        face_sharp[:] = True
    keep = sharp > 0
    pairs, sharp = pairs[keep], sharp[keep]

    def faces_out(mask):
        return np.flatnonzero(mask) if faces_as_indices else mask

    corners_out = np.flatnonzero(corner)
    if m == 0:  # no faces: nothing to refine, every level is the input
        return _unrefined(Fi, T, n, t, pairs, sharp, faces_out, face_sharp, corners_out, levels)

    geo_steps, uv_steps = [], []
    face_parent = np.arange(m, dtype=np.int64)
    level = val.checked_level(Fi, n, pairs).tag(pairs, sharp, face_sharp)
    uvl = _uv_level(level, T, t)
    uv_corner = _carried_corners(level, uvl, corner)
    uv_corners_out = np.flatnonzero(uv_corner | _irregular_uv(level, uvl))
    uv_pairs, uv_sharp = np.empty((0, 2), np.int64), np.empty(0)
    for step in range(1, levels + 1):
        plan = plan_step(level, corner, scheme, step, loop_weights, force_split=_seam_halfedges(level, uvl.faces))
        # The UV index mesh: the same split/flip decisions, its boundary (mesh boundary and
        # seams) as creases, geometric creases and corners carried onto it.
        uv_fixed = uv_corner | _irregular_uv(level, uvl)
        uv_plan = plan_step(uvl, uv_fixed, scheme, step, loop_weights, force_split=plan.hkind == R.EDGE_SPLIT)
        if not np.array_equal(uv_plan.hkind, plan.hkind):
            raise AssertionError("UV index mesh and geometry disagree on split edges")  # pragma: no cover
        S = step_matrix(level, plan)
        S_uv = step_matrix(uvl, uv_plan) if uv_mode == "smooth" else _linear_matrix(uvl, uv_plan)
        pairs, sharp = child_creases(level, plan)
        uv_pairs, uv_sharp = child_creases(uvl, uv_plan)
        faces, child, offsets = child_level(level, plan)
        uv_faces, uv_child, _ = child_level(uvl, uv_plan)
        parent = face_parents(offsets)
        face_parent = face_parent[parent]
        corner = np.concatenate([corner, np.zeros(plan.n_new - len(corner), dtype=bool)])
        uv_corner = np.concatenate([uv_corner, np.zeros(uv_plan.n_new - len(uv_corner), dtype=bool)])
        mask = faces_out(child.face_sharp)
        geo_steps.append(RefinementStep(faces, S, pairs, sharp, mask, corners_out, parent))
        uv_steps.append(RefinementStep(uv_faces, S_uv, uv_pairs, uv_sharp, mask, uv_corners_out, parent))
        level, uvl = child, uv_child
    geo = Refinement(level.faces if levels else Fi.copy(), pairs, sharp, faces_out(level.face_sharp), corners_out,
                     face_parent, geo_steps, n)
    uv = Refinement(uvl.faces if levels else T.copy(), uv_pairs, uv_sharp, faces_out(level.face_sharp),
                    uv_corners_out, face_parent.copy(), uv_steps, t)
    return FaceVaryingRefinement(geo, uv)


def subdivide_face_varying(V: ArrayLike, F: ArrayLike, UV: ArrayLike, FUV: ArrayLike,
                           sharp_edges: ArrayLike | None = None, levels: int = 1, *, scheme: Scheme = "hybrid",
                           uv_mode: UVMode = "linear", sharpness: ArrayLike | None = None,
                           sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
                           loop_weights: LoopWeights = "loop", return_matrix: bool = False) -> tuple:
    """Subdivide a textured triangle mesh: positions and UVs with seams, faces kept aligned.

    Parameters
    ----------
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, 3) array_like of int
        Triangles, consistently oriented, every edge in one or two faces.
    UV : (t, k) array_like of float
        Face-varying values (UVs, usually k = 2; any per-corner data works).
    FUV : (m, 3) array_like of int
        Index into ``UV`` of each face corner, aligned row by row with ``F``.
    sharp_edges, levels, sharpness, sharp_faces, corners, loop_weights
        As in :func:`hybridsub.subdivide`.
    scheme : {"hybrid", "loop"}
        ``"hybrid"`` splits seam edges (R4) instead of flipping them, so its geometry differs
        from :func:`subdivide` along seams; ``"loop"`` geometry equals :func:`subdivide`'s.
        ``"sqrt3"`` raises ``ValueError``.
    uv_mode : {"linear", "smooth"}
        ``"linear"`` (default): UVs are interpolated linearly, textures never distort
        (OpenSubdiv ``FVAR_LINEAR_ALL``). ``"smooth"``: UVs are subdivided like positions, UV
        boundaries and seams as creases (OpenSubdiv ``FVAR_LINEAR_NONE``).
    return_matrix : bool
        Also return the composite matrices ``S`` (``V2 == S @ V``) and ``S_uv``
        (``UV2 == S_uv @ UV``).

    Returns
    -------
    V2 : (n', 3) ndarray
    F2 : (m', 3) int64 ndarray
    UV2 : (t', k) ndarray
    FUV2 : (m', 3) int64 ndarray
        Row ``f`` of ``FUV2`` holds the UV indices of the corners of ``F2[f]``.
    S, S_uv : scipy.sparse.csr_matrix
        Only with ``return_matrix=True``.

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]); F = np.array([[0, 1, 2], [0, 2, 3]])
    >>> UV = np.array([[0., 0], [1, 0], [1, 1], [0, 0], [1, 1], [0, 1]]); FUV = np.array([[0, 1, 2], [3, 4, 5]])
    >>> V2, F2, UV2, FUV2 = hybridsub.subdivide_face_varying(V, F, UV, FUV, levels=2)
    >>> V2.shape, F2.shape, UV2.shape, FUV2.shape
    ((33, 3), (48, 3), (38, 2), (48, 3))
    """
    A = np.asarray(V)
    Vf = val.as_vertices(A)
    UVf = _as_uv_values(UV)
    r = refine_face_varying(F, FUV, sharp_edges, levels, n_vertices=len(Vf), n_uvs=len(UVf), scheme=scheme,
                            uv_mode=uv_mode, sharpness=sharpness, sharp_faces=sharp_faces, corners=corners,
                            loop_weights=loop_weights)
    out_dtype = A.dtype if np.issubdtype(A.dtype, np.floating) else np.float64
    V2 = r.geometry.apply(Vf).astype(out_dtype, copy=False)
    U = np.asarray(UV)
    uv_dtype = U.dtype if np.issubdtype(U.dtype, np.floating) else np.float64
    UV2 = r.uv.apply(UVf).astype(uv_dtype, copy=False)
    if return_matrix:
        return V2, r.geometry.faces, UV2, r.uv.faces, r.geometry.matrix, r.uv.matrix
    return V2, r.geometry.faces, UV2, r.uv.faces


# ---------------------------------------------------------------------------------------
# The UV index mesh of one level.


def _seam_halfedges(level: Level, T: np.ndarray) -> np.ndarray:
    """(3m,) bool: interior halfedges whose face and twin face disagree on a UV index."""
    twin = level.twin
    h = np.flatnonzero(twin >= 0)
    g = twin[h]
    o = T.ravel()
    nxt = h - h % 3 + (h % 3 + 1) % 3
    gnxt = g - g % 3 + (g % 3 + 1) % 3
    seam = np.zeros(len(twin), dtype=bool)
    seam[h] = (o[h] != o[gnxt]) | (o[nxt] != o[g])
    return seam


def _uv_level(level: Level, T: np.ndarray, t: int) -> Level:
    """The UV index mesh as a Level on the geometry's halfedges, twins cut along seams, with
    the geometry's tags (a tag on a seam is moot: seams are UV boundary, creases anyway)."""
    twin = np.where(_seam_halfedges(level, T), -1, level.twin)
    return Level(np.ascontiguousarray(T, dtype=np.int64), int(t), twin, level.hsharp, level.face_sharp)


def _irregular_uv(level: Level, uvl: Level) -> np.ndarray:
    """(t,) bool: UV indices that cannot be one smooth value, kept as UV corners.

    A UV index used by several separate face sectors around a vertex (more than one UV
    boundary halfedge leaves it), by several geometric vertices (which includes a face
    repeating a UV index), or at a vertex where several fans meet (a bow-tie, a corner of the
    geometry; OpenSubdiv sharpens every face-varying value there too).
    """
    t, n = uvl.n_vertices, max(level.n_vertices, 1)
    o = uvl.faces.ravel()
    fv = level.faces.ravel()
    uv_fans = np.bincount(o[uvl.twin < 0], minlength=t)
    pairs = np.unique(o * np.int64(n) + fv)
    users = np.bincount(pairs // n, minlength=t)
    bowtie = np.bincount(fv[level.twin < 0], minlength=level.n_vertices) > 1
    out = (uv_fans > 1) | (users > 1)
    out[o[bowtie[fv]]] = True
    return out


def _carried_corners(level: Level, uvl: Level, corner: np.ndarray) -> np.ndarray:
    """(t,) bool: UV indices at tagged corner vertices."""
    out = np.zeros(uvl.n_vertices, dtype=bool)
    out[uvl.faces.ravel()[corner[level.faces.ravel()]]] = True
    return out


def _linear_matrix(uvl: Level, plan) -> sp.csr_matrix:
    """UV matrix of ``uv_mode="linear"``: old values kept, midpoints, centroids."""
    t = uvl.n_vertices
    owner = uvl.edge_owner
    has_point = plan.edge_point[owner] >= 0
    e = owner[has_point]
    f = np.flatnonzero(plan.face_point >= 0)
    rows = np.concatenate([np.arange(t), np.repeat(plan.edge_point[e], 2), np.repeat(plan.face_point[f], 3)])
    cols = np.concatenate([np.arange(t), uvl.edge_vertices[has_point].ravel(), uvl.faces[f].ravel()])
    data = np.concatenate([np.ones(t), np.full(2 * len(e), 0.5), np.full(3 * len(f), 1.0 / 3.0)])
    S = sp.csr_matrix((data, (rows, cols)), shape=(plan.n_new, t))
    S.sum_duplicates()  # a degenerate UV edge (p, p) gives one entry 1.0
    return S


# ---------------------------------------------------------------------------------------
# Input checking.


def _as_uv_faces(FUV, m: int, n_uvs) -> np.ndarray:
    A = np.asarray(FUV)
    if A.ndim != 2 or A.shape[1] != 3 or A.shape[0] != m:
        raise MeshError(f"FUV must have shape ({m}, 3), one row of UV indices per face, got {A.shape}")
    if A.dtype == bool or not (np.issubdtype(A.dtype, np.integer) or (
            np.issubdtype(A.dtype, np.floating) and np.all(np.isfinite(A)) and np.all(A == np.round(A)))):
        raise TypeError(f"FUV must hold integer UV indices, got dtype {A.dtype}")
    T = np.ascontiguousarray(A, dtype=np.int64)
    if T.size:
        if (T < 0).any():
            f = int(np.flatnonzero((T < 0).any(axis=1))[0])
            raise MeshError(f"FUV row {f} has a negative UV index: {T[f].tolist()}")
        if n_uvs is not None and T.max() >= n_uvs:
            f = int(np.flatnonzero((T >= n_uvs).any(axis=1))[0])
            raise MeshError(f"FUV row {f} = {T[f].tolist()} refers to UV {int(T[f].max())}, but there are only "
                            f"{n_uvs} UV values (valid indices 0..{n_uvs - 1})")
    return T


def _as_uv_values(UV) -> np.ndarray:
    A = np.asarray(UV)
    if A.dtype == object or not (np.issubdtype(A.dtype, np.floating) or np.issubdtype(A.dtype, np.integer)):
        raise TypeError(f"UV must be a numeric array of shape (t, k), got dtype {A.dtype}")
    if A.ndim not in (1, 2):
        raise MeshError(f"UV must have shape (t, k) (one row per UV value), got {A.shape}")
    A = np.ascontiguousarray(A, dtype=np.float64)
    bad = ~np.isfinite(A.reshape(len(A), -1)).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise MeshError(f"UV value {i} is not finite: {A[i].tolist()}")
    return A


def _unrefined(Fi, T, n, t, pairs, sharp, faces_out, face_sharp, corners_out, levels):
    """No faces: every level is the input."""
    m = len(Fi)
    ident = np.arange(m, dtype=np.int64)
    geo_steps = [RefinementStep(Fi.copy(), sp.identity(n, format="csr"), pairs, sharp, faces_out(face_sharp),
                                corners_out, ident) for _ in range(levels)]
    uv_steps = [RefinementStep(T.copy(), sp.identity(t, format="csr"), np.empty((0, 2), np.int64), np.empty(0),
                               faces_out(face_sharp), np.empty(0, np.int64), ident) for _ in range(levels)]
    geo = Refinement(Fi.copy(), pairs, sharp, faces_out(face_sharp), corners_out, ident, geo_steps, n)
    uv = Refinement(T.copy(), np.empty((0, 2), np.int64), np.empty(0), faces_out(face_sharp),
                    np.empty(0, np.int64), ident.copy(), uv_steps, t)
    return FaceVaryingRefinement(geo, uv)
