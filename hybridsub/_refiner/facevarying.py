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

from . import budget as _budget
from .._rules import refinement as R
from .._input import arrays as val
from .._errors import MeshError
from .refinement import Refinement, RefinementStep, check_uv_mode
from .stencils import apply_matrix, apply_step, step_matrix
from .._topology.level import Level, StepPlan, child_creases, child_level, face_parents, plan_step
from .._typing import ArrayLike, LoopWeights, MemoryLimit, NonManifold, Scheme, UVMode


class FaceVaryingRefinement(NamedTuple):
    """What :func:`refine_face_varying` returns: two refinements with aligned faces.

    Attributes
    ----------
    geometry : Refinement
        The mesh's refinement (seams split, never flipped); ``geometry.apply(V)`` refines
        positions or any per-vertex data. It is what ``refine(F, ..., uv_faces=FUV)``
        returns: ``geometry.uv_faces is uv.faces`` and ``geometry.uv_matrix`` is
        ``uv.matrix``.
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
    T = as_uv_faces(FUV, len(Fi), None)
    if not len(Fi):
        return np.empty((0, 2), np.int64)
    level = val.checked_level(Fi, n)
    seam = _seam_halfedges(level, T)
    return level.edge_vertices[seam[level.edge_owner]]


def refine_face_varying(F: ArrayLike, FUV: ArrayLike, sharp_edges: ArrayLike | None = None, levels: int = 1, *,
                        n_vertices: int | None = None, n_uvs: int | None = None, scheme: Scheme = "hybrid",
                        uv_mode: UVMode = "linear", sharpness: ArrayLike | None = None,
                        sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
                        loop_weights: LoopWeights = "loop", non_manifold: NonManifold = "raise",
                        max_memory: MemoryLimit = None) -> FaceVaryingRefinement:
    """Refine a mesh's connectivity together with its face-varying (UV) index mesh.

    ``refine(F, ..., uv_faces=FUV)`` returns the ``geometry`` part of this, with the UV faces
    and matrices attached (``uv_faces``, ``uv_matrix``); this function also returns the UV
    index mesh's own :class:`Refinement` (``uv.apply``, its steps, its carried creases and
    UV corners).

    Parameters
    ----------
    F : (m, 3) array_like of int
        Triangles, consistently oriented, every edge in one or two faces.
    FUV : (m, 3) array_like of int
        UV index of each face corner (row ``f`` belongs to face ``f``); a face may repeat a UV
        index (a degenerate UV triangle).
    sharp_edges, levels, sharpness, sharp_faces, corners, loop_weights, non_manifold, max_memory
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
    from .refinement import refine

    geo = refine(F, sharp_edges, levels, n_vertices=n_vertices, scheme=scheme, sharpness=sharpness,
                 sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights, non_manifold=non_manifold,
                 max_memory=max_memory, uv_faces=FUV, n_uvs=n_uvs, uv_mode=uv_mode)
    assert geo._uv is not None  # refine attaches it whenever uv_faces is given
    return FaceVaryingRefinement(geo, geo._uv)


def refine_with_uvs(F, FUV, sharp_edges, levels, *, n_vertices, n_uvs, scheme, uv_mode, sharpness, sharp_faces,
                    corners, loop_weights, max_memory) -> Refinement:
    """``refine(..., uv_faces=FUV)``: the geometry's Refinement with the UV index mesh's attached."""
    setup = _setup(F, FUV, sharp_edges, levels, n_vertices, n_uvs, scheme, uv_mode, sharpness, sharp_faces, corners,
                   loop_weights, uv_name="uv_faces")
    faces_out = setup.faces_out
    Fi, T, n, t = setup.F, setup.T, setup.n, setup.t
    pairs, sharp, corners_out = setup.pairs, setup.sharp, setup.corners_out
    if len(Fi) == 0:  # no faces: nothing to refine, every level is the input
        return _unrefined(setup)
    budget = _budget.Budget(setup.levels, scheme, max_memory)
    geo_steps, uv_steps = [], []
    face_parent = np.arange(len(Fi), dtype=np.int64)
    uv_pairs, uv_sharp = np.empty((0, 2), np.int64), np.empty(0)
    uv_corners_out = np.empty(0, np.int64)
    level: Level | None = None
    uvl: Level | None = None
    for s in _walk(setup, budget):
        level, uvl = s.child, s.uv_child
        uv_corners_out = s.uv_corners_in
        S = step_matrix(s.level, s.plan)
        S_uv = step_matrix(s.uvl, s.uv_plan) if uv_mode == "smooth" else _linear_matrix(s.uvl, s.uv_plan)
        pairs, sharp = child_creases(s.level, s.plan)
        uv_pairs, uv_sharp = child_creases(s.uvl, s.uv_plan)
        parent = face_parents(s.offsets)
        face_parent = face_parent[parent]
        mask = faces_out(level.face_sharp)
        geo_steps.append(RefinementStep(s.faces, S, pairs, sharp, mask, corners_out, parent, s.uv_faces, S_uv))
        uv_steps.append(RefinementStep(s.uv_faces, S_uv, uv_pairs, uv_sharp, mask, uv_corners_out, parent))
    if level is None or uvl is None:  # levels == 0: the input, checked
        level = val.checked_level(Fi, n, pairs)
        uv_corners_out = _uv_corners(level.tag(pairs, sharp, setup.face_sharp), T, t, setup.corner)
        geo_faces, uv_faces, sharp_mask = Fi.copy(), T.copy(), faces_out(setup.face_sharp)
    else:
        geo_faces, uv_faces, sharp_mask = level.faces, uvl.faces, faces_out(level.face_sharp)
    uv = Refinement(uv_faces, uv_pairs, uv_sharp, sharp_mask, uv_corners_out, face_parent.copy(), uv_steps, t)
    geo = Refinement(geo_faces, pairs, sharp, sharp_mask, corners_out, face_parent, geo_steps, n, _uv=uv)
    geo._cache["max_memory"] = uv._cache["max_memory"] = max_memory
    return geo


class FaceVaryingLevel(NamedTuple):
    """One level of :func:`subdivide_face_varying_levels`."""

    step: int
    X: np.ndarray  # (n_k, d) refined per-vertex data
    faces: np.ndarray  # (m_k, 3)
    UV: np.ndarray  # (t_k, e) refined per-UV-index data
    uv_faces: np.ndarray  # (m_k, 3), aligned with faces
    face_parent: np.ndarray  # (m_k,) face of the previous level each face came from
    sharp_edges: np.ndarray  # tags of this level
    sharpness: np.ndarray
    sharp_faces: np.ndarray  # (m_k,) bool mask


def subdivide_face_varying_levels(X: np.ndarray, F, UV: np.ndarray, FUV, sharp_edges=None, levels: int = 1, *,
                                  scheme="hybrid", uv_mode="linear", sharpness=None, sharp_faces=None, corners=None,
                                  loop_weights="loop", max_memory=None):
    """The face-varying fast path: yield a :class:`FaceVaryingLevel` per step, no matrix kept.

    ``X (n, d)`` and ``UV (t, e)`` are float64, already validated. The same numbers as
    ``refine(..., uv_faces=FUV)``'s step matrices applied one after the other, bit for bit
    (the stencils are applied directly, as in :func:`hybridsub.subdivide`); only two levels
    are held at a time (the command line's progress bar runs on it).
    """
    setup = _setup(F, FUV, sharp_edges, levels, len(X), len(UV), scheme, uv_mode, sharpness, sharp_faces, corners,
                   loop_weights)
    budget = _budget.Budget(setup.levels, scheme, max_memory, keeps_steps=False)
    for s in _walk(setup, budget):
        X = apply_step(s.level, s.plan, X)
        if uv_mode == "smooth":
            UV = apply_step(s.uvl, s.uv_plan, UV)
        else:
            UV = _linear_apply(s.uvl, s.uv_plan, UV)
        pairs, sharp = child_creases(s.level, s.plan)
        yield FaceVaryingLevel(s.step, X, s.faces, UV, s.uv_faces, face_parents(s.offsets), pairs, sharp,
                               s.child.face_sharp)


def subdivide_face_varying(V: ArrayLike, F: ArrayLike, UV: ArrayLike, FUV: ArrayLike,
                           sharp_edges: ArrayLike | None = None, levels: int = 1, *, scheme: Scheme = "hybrid",
                           uv_mode: UVMode = "linear", sharpness: ArrayLike | None = None,
                           sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
                           loop_weights: LoopWeights = "loop", return_matrix: bool = False,
                           max_memory: MemoryLimit = None) -> tuple:
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
    sharp_edges, levels, sharpness, sharp_faces, corners, loop_weights, max_memory
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
    out_dtype = A.dtype if np.issubdtype(A.dtype, np.floating) else np.float64
    U = np.asarray(UV)
    uv_dtype = U.dtype if np.issubdtype(U.dtype, np.floating) else np.float64
    if return_matrix:
        r = refine_face_varying(F, FUV, sharp_edges, levels, n_vertices=len(Vf), n_uvs=len(UVf), scheme=scheme,
                                uv_mode=uv_mode, sharpness=sharpness, sharp_faces=sharp_faces, corners=corners,
                                loop_weights=loop_weights, max_memory=max_memory)
        V2 = r.geometry.apply(Vf).astype(out_dtype, copy=False)
        UV2 = r.uv.apply(UVf).astype(uv_dtype, copy=False)
        return V2, r.geometry.faces, UV2, r.uv.faces, r.geometry.matrix, r.uv.matrix
    shape = UVf.shape
    last = None
    for last in subdivide_face_varying_levels(Vf, F, UVf.reshape(len(UVf), -1), FUV, sharp_edges, levels,
                                              scheme=scheme, uv_mode=uv_mode, sharpness=sharpness,
                                              sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights,
                                              max_memory=max_memory):
        pass
    if last is None:  # no step ran: copies of the input
        Fi, _ = val.as_faces(F, len(Vf))
        T = as_uv_faces(FUV, len(Fi), len(UVf))
        return Vf.astype(out_dtype, copy=True), Fi.copy(), UVf.astype(uv_dtype, copy=True), T.copy()
    UV2 = last.UV.reshape((len(last.UV),) + shape[1:])
    return (last.X.astype(out_dtype, copy=False), last.faces, UV2.astype(uv_dtype, copy=False), last.uv_faces)


# ---------------------------------------------------------------------------------------
# The step loop.


class _Setup(NamedTuple):
    """Checked and normalised arguments of one face-varying refinement."""

    levels: int
    F: np.ndarray
    T: np.ndarray  # (m, 3) UV faces
    n: int
    t: int
    scheme: str
    pairs: np.ndarray
    sharp: np.ndarray
    face_sharp: np.ndarray
    corner: np.ndarray
    corners_out: np.ndarray
    faces_as_indices: bool
    loop_weights: str

    def faces_out(self, mask):
        return np.flatnonzero(mask) if self.faces_as_indices else mask


def _setup(F, FUV, sharp_edges, levels, n_vertices, n_uvs, scheme, uv_mode, sharpness, sharp_faces, corners,
           loop_weights, uv_name="FUV") -> _Setup:
    levels = val.check_options(scheme, levels, loop_weights)
    if scheme == "sqrt3":
        raise ValueError(
            'scheme="sqrt3" cannot honour UV seams (Kobbelt\'s √3 flips every edge, and a flip across a seam '
            'makes a triangle spanning two UV charts); use scheme="hybrid" (√3 with seams split) or "loop"'
        )
    check_uv_mode(uv_mode)
    Fi, n = val.as_faces(F, n_vertices)
    m = len(Fi)
    if n_uvs is not None:
        n_uvs = val.count(n_uvs, "n_uvs")
    T = as_uv_faces(FUV, m, n_uvs, uv_name)
    t = n_uvs if n_uvs is not None else (int(T.max()) + 1 if T.size else 0)
    pairs, sharp = val.as_sharp_edges(sharp_edges, sharpness, n)
    face_sharp, faces_as_indices = val.as_face_mask(sharp_faces, m)
    corner = val.as_corner_mask(corners, n)
    if scheme == "loop":
        face_sharp[:] = True
    keep = sharp > 0
    return _Setup(levels, Fi, T, n, t, scheme, pairs[keep], sharp[keep], face_sharp, corner, np.flatnonzero(corner),
                  faces_as_indices, loop_weights)


class _Step(NamedTuple):
    step: int
    level: Level  # geometry of level k, and its plan
    plan: StepPlan
    uvl: Level  # UV index mesh of level k, and its plan
    uv_plan: StepPlan
    faces: np.ndarray  # faces of level k + 1
    uv_faces: np.ndarray
    child: Level  # level k + 1
    uv_child: Level
    offsets: np.ndarray  # child offsets of the faces of level k
    uv_corners_in: np.ndarray  # UV corners of level 0 (indices)


def _walk(setup: _Setup, budget=None):
    """Run the steps on the geometry and the UV index mesh side by side; yield a _Step each.

    Each step plans the geometry with seams as forced splits, then the UV index mesh (its
    boundary is the mesh boundary and both sides of every seam) with the geometry's split
    edges as forced splits, so both make the same decisions and emit aligned faces.
    """
    if setup.levels == 0 or len(setup.F) == 0:
        return
    scheme, loop_weights = setup.scheme, setup.loop_weights
    corner = setup.corner
    level = val.checked_level(setup.F, setup.n, setup.pairs).tag(setup.pairs, setup.sharp, setup.face_sharp)
    uvl = _uv_level(level, setup.T, setup.t)
    # UV corners: carried corner tags and irregular UV indices. Both keep their status from
    # level to level, and new UV values are neither (each lies on one new vertex, in one sector).
    uv_fixed = _carried_corners(level, uvl, corner) | _irregular_uv(level, uvl)
    uv_corners_in = np.flatnonzero(uv_fixed)
    for step in range(1, setup.levels + 1):
        seams = (uvl.twin < 0) & (level.twin >= 0)  # the UV mesh is cut exactly along the seams
        plan = plan_step(level, corner, scheme, step, loop_weights, force_split=seams)
        uv_plan = plan_step(uvl, uv_fixed, scheme, step, loop_weights, force_split=plan.hkind == R.EDGE_SPLIT)
        if not np.array_equal(uv_plan.hkind, plan.hkind):
            raise AssertionError("UV index mesh and geometry disagree on split edges")  # pragma: no cover
        if budget is not None:
            budget.check(step, level, plan, also=(uvl, uv_plan))  # before this step allocates anything large
        faces, child, offsets = child_level(level, plan)
        uv_faces, uv_child, _ = child_level(uvl, uv_plan)
        yield _Step(step, level, plan, uvl, uv_plan, faces, uv_faces, child, uv_child, offsets, uv_corners_in)
        corner = np.concatenate([corner, np.zeros(plan.n_new - len(corner), dtype=bool)])
        uv_fixed = np.concatenate([uv_fixed, np.zeros(uv_plan.n_new - len(uv_fixed), dtype=bool)])
        level, uvl = child, uv_child


def _uv_corners(level: Level, T: np.ndarray, t: int, corner: np.ndarray) -> np.ndarray:
    """UV corners of level 0 (indices), for a refinement without steps."""
    uvl = _uv_level(level, T, t)
    return np.flatnonzero(_carried_corners(level, uvl, corner) | _irregular_uv(level, uvl))


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


def _linear_rows(uvl: Level, plan) -> tuple[np.ndarray, np.ndarray, bool]:
    """The UV edges (k, 2) and UV faces (l, 3) of ``uv_mode="linear"``'s new values, in
    ``plan``'s layout (old values, then edge points, then face points), each row sorted; and
    whether one repeats a UV index (a degenerate UV edge or face)."""
    t = uvl.n_vertices
    h = np.flatnonzero(plan.edge_point >= 0)
    h = h[(uvl.twin[h] < 0) | (h < uvl.twin[h])]  # one halfedge per split edge
    fv = uvl.faces.ravel()
    E = np.empty((len(h), 2), np.int64)
    E[plan.edge_point[h] - t] = np.sort(np.stack([fv[h], fv[h - h % 3 + (h % 3 + 1) % 3]], axis=1), axis=1)
    f = np.flatnonzero(plan.face_point >= 0)
    T = np.empty((len(f), 3), np.int64)
    T[plan.face_point[f] - t - len(h)] = np.sort(uvl.faces[f], axis=1)
    return E, T, bool((E[:, 0] == E[:, 1]).any() or (T[:, :2] == T[:, 1:]).any())


def _linear_matrix(uvl: Level, plan) -> sp.csr_matrix:
    """UV matrix of ``uv_mode="linear"``: old values kept, midpoints, centroids (CSR, built
    directly, columns sorted)."""
    t = uvl.n_vertices
    E, T, degenerate = _linear_rows(uvl, plan)
    indptr = np.concatenate([np.arange(t + 1), t + 2 * np.arange(1, len(E) + 1),
                             t + 2 * len(E) + 3 * np.arange(1, len(T) + 1)])
    indices = np.concatenate([np.arange(t), E.ravel(), T.ravel()])
    data = np.concatenate([np.ones(t), np.full(E.size, 0.5), np.full(T.size, 1.0 / 3.0)])
    S = sp.csr_matrix((data, indices, indptr), shape=(plan.n_new, t))
    if degenerate:
        S.sum_duplicates()  # a degenerate UV edge (p, p) gives one entry 1.0
    S.has_sorted_indices = True
    return S


def _linear_apply(uvl: Level, plan, UV: np.ndarray) -> np.ndarray:
    """``_linear_matrix(uvl, plan) @ UV`` without forming it: the same sums in the same order,
    so the same bits (a degenerate UV edge or face goes through the matrix, whose merged
    entries sum differently)."""
    E, T, degenerate = _linear_rows(uvl, plan)
    if degenerate:
        return apply_matrix(_linear_matrix(uvl, plan), UV)
    t, w = uvl.n_vertices, 1.0 / 3.0
    out = np.empty((plan.n_new, UV.shape[1]))
    out[:t] = UV
    out[t:t + len(E)] = 0.5 * UV[E[:, 0]] + 0.5 * UV[E[:, 1]]
    out[t + len(E):] = w * UV[T[:, 0]] + w * UV[T[:, 1]] + w * UV[T[:, 2]]
    return out


# ---------------------------------------------------------------------------------------
# Input checking.


def as_uv_faces(FUV, m: int, n_uvs: int | None, name: str = "FUV") -> np.ndarray:
    """(m, 3) int64 UV faces, checked against the ``m`` faces and ``n_uvs`` UV values; errors
    name the argument (``name``) and the first bad face."""
    A = val.as_array(FUV, name, 3, "face", "m")
    if A.ndim == 1 and A.size == 0 and m == 0:
        A = A.reshape(0, 3)
    if A.dtype == bool or not (np.issubdtype(A.dtype, np.integer) or np.issubdtype(A.dtype, np.floating)):
        raise TypeError(f"{name} must hold integer UV indices, got dtype {A.dtype}")
    if A.ndim != 2 or A.shape[1] != 3 or A.shape[0] != m:
        raise MeshError(f"{name} must have shape ({m}, 3), one row of UV indices per face, got {A.shape}")
    if np.issubdtype(A.dtype, np.floating) and A.size:
        frac = val.not_integral(A)
        if frac.any():
            f = int(np.flatnonzero(frac)[0])
            raise MeshError(f"{name} must hold integer UV indices; face {f} has {A[f].tolist()}")
    T = np.ascontiguousarray(A, dtype=np.int64)
    if T.size:
        neg = (T < 0).any(axis=1)
        if neg.any():
            f = int(np.flatnonzero(neg)[0])
            raise MeshError(f"{name}: face {f} has a negative UV index: {T[f].tolist()}")
        if n_uvs is not None and T.max() >= n_uvs:
            f = int(np.flatnonzero((T >= n_uvs).any(axis=1))[0])
            raise MeshError(f"{name}: face {f} has UV indices {T[f].tolist()}, but there are only {n_uvs} UV values "
                            f"(valid indices 0..{n_uvs - 1})")
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


def _unrefined(setup: _Setup) -> Refinement:
    """No faces: every level is the input."""
    Fi, T, n, t = setup.F, setup.T, setup.n, setup.t
    ident = np.arange(len(Fi), dtype=np.int64)
    mask = setup.faces_out(setup.face_sharp)
    no_pairs, no_sharp, no_corners = np.empty((0, 2), np.int64), np.empty(0), np.empty(0, np.int64)
    geo_steps = [RefinementStep(Fi.copy(), sp.identity(n, format="csr"), setup.pairs, setup.sharp, mask,
                                setup.corners_out, ident, T.copy(), sp.identity(t, format="csr"))
                 for _ in range(setup.levels)]
    uv_steps = [RefinementStep(T.copy(), sp.identity(t, format="csr"), no_pairs, no_sharp, mask, no_corners, ident)
                for _ in range(setup.levels)]
    uv = Refinement(T.copy(), no_pairs, no_sharp, mask, no_corners, ident.copy(), uv_steps, t)
    return Refinement(Fi.copy(), setup.pairs, setup.sharp, mask, setup.corners_out, ident, geo_steps, n, _uv=uv)
