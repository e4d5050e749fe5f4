"""Refinement: the step loop, and the objects that hold its results.

A :class:`Refinement` is what ``refine`` returns: connectivity, tags and refinement
matrices, computed from topology and tags alone. Its :meth:`Refinement.apply` refines any
per-vertex data with them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from . import budget as _budget
from . import repair as _repair
from .._input import arrays as val
from .._input.features import merge_detected
from .stencils import apply_matrix, apply_step, step_matrix
from .._topology.level import child_creases, child_level, face_parents, plan_step
from .._typing import ArrayLike, LoopWeights, MemoryLimit, NDArray, NonManifold, Scheme, UVMode


@dataclass(frozen=True, eq=False)
class RefinementStep:
    """One subdivision step: level k → k + 1.

    Attributes
    ----------
    faces : (m', 3) int64
        Faces of level k + 1.
    matrix : scipy.sparse.csr_matrix, (n', n)
        The step's refinement matrix, ``V_{k+1} = matrix @ V_k``.
    sharp_edges : (k', 2) int64
        Tagged creases of level k + 1 (boundary edges are creases implicitly, not listed).
    sharpness : (k',) float64
        Their sharpness (``inf``: infinitely sharp).
    sharp_faces : (m',) bool or int64 indices
        Sharp faces of level k + 1, in the form they were given (mask or indices).
    corners : int64
        Corner vertices (the same indices at every level).
    face_parent : (m',) int64
        The face of level k each face of level k + 1 was emitted by.
    uv_faces : (m', 3) int64 or None
        With ``refine(..., uv_faces=...)``: the UV index of each corner of ``faces`` (row by
        row); else None.
    uv_matrix : scipy.sparse.csr_matrix or None
        With ``uv_faces``: the step's UV matrix, ``UV_{k+1} = uv_matrix @ UV_k``; else None.
    """

    faces: np.ndarray
    matrix: sp.csr_matrix
    sharp_edges: np.ndarray
    sharpness: np.ndarray
    sharp_faces: np.ndarray
    corners: np.ndarray
    face_parent: np.ndarray
    uv_faces: np.ndarray | None = None
    uv_matrix: sp.csr_matrix | None = None

    @property
    def n_vertices(self) -> int:
        """Number of vertices of level k + 1."""
        return self.matrix.shape[0]


@dataclass(frozen=True, eq=False)
class Refinement:
    """The result of :func:`hybridsub.refine`: connectivity, tags and matrices of L steps.

    Attributes
    ----------
    faces : (m_L, 3) int64
        Faces of the finest level.
    sharp_edges, sharpness, sharp_faces, corners
        Tags of the finest level, in the forms they were given.
    face_parent : (m_L,) int64
        The input face each output face lies in.
    steps : list of RefinementStep
        The individual steps, coarsest first.
    n_vertices : int
        Number of vertices of the finest level.
    n_coarse : int
        Number of vertices of the input.
    uv_faces : (m_L, 3) int64 or None
        With ``refine(..., uv_faces=FUV)``: the UV index of each corner of ``faces``, row by
        row (``FUV`` refined); else None.
    uv_matrix : scipy.sparse.csr_matrix or None
        With ``uv_faces``: the composite UV matrix (t_L × t), ``UV2 = uv_matrix @ UV``;
        else None.
    """

    faces: np.ndarray
    sharp_edges: np.ndarray
    sharpness: np.ndarray
    sharp_faces: np.ndarray
    corners: np.ndarray
    face_parent: np.ndarray
    steps: list
    n_coarse: int
    _cache: dict = field(default_factory=dict, repr=False)
    _uv: Refinement | None = field(default=None, repr=False)  # the UV index mesh's refinement

    @property
    def n_vertices(self) -> int:
        return self.steps[-1].n_vertices if self.steps else self.n_coarse

    @property
    def uv_faces(self) -> np.ndarray | None:
        return None if self._uv is None else self._uv.faces

    @property
    def uv_matrix(self) -> sp.csr_matrix | None:
        """Composite UV matrix ``S_uv,L ⋯ S_uv,1`` (t_L × t), computed once; None without UVs."""
        return None if self._uv is None else self._uv.matrix

    @property
    def matrix(self) -> sp.csr_matrix:
        """Composite refinement matrix ``S_L ⋯ S_1`` (n_fine × n_coarse), computed once."""
        if "matrix" not in self._cache:
            S = sp.identity(self.n_coarse, format="csr", dtype=np.float64)
            for st in self.steps:
                _budget.check_product(st.matrix, S, self._cache.get("max_memory"))  # size guard
                S = st.matrix @ S
            S = sp.csr_matrix(S)
            S.sort_indices()
            self._cache["matrix"] = S
        return self._cache["matrix"]

    def apply(self, X: ArrayLike) -> np.ndarray:
        """Refine per-vertex data: positions, UVs, colours, any (n_coarse, ...) array.

        Floating-point data keeps its dtype (computed in float64); other data comes back as
        float64; complex data stays complex. The result is always a new array, also with no
        steps. The step matrices are applied one after the other, which is cheaper than the
        composite when the matrix has not been formed.

        Examples
        --------
        >>> import numpy as np, hybridsub
        >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]]); F = np.array([[0, 1, 2]])
        >>> r = hybridsub.refine(F, levels=1)
        >>> r.apply(V).shape
        (7, 3)
        """
        A, out_dtype, work = val.as_data(X, self.n_coarse)  # dtypes, shapes, never a view
        Y = np.asarray(A, dtype=work).reshape(self.n_coarse, int(np.prod(A.shape[1:], dtype=np.int64)))
        if work == np.complex128:  # real and imaginary parts side by side
            Y = np.concatenate([Y.real, Y.imag], axis=1)
        if not self.steps:
            Y = Y.copy()
        elif "matrix" in self._cache:
            Y = apply_matrix(self._cache["matrix"], Y)
        else:
            for st in self.steps:
                Y = apply_matrix(st.matrix, Y)
        if work == np.complex128:
            k = Y.shape[1] // 2
            Y = Y[:, :k] + 1j * Y[:, k:]
        return np.ascontiguousarray(Y.reshape((Y.shape[0],) + A.shape[1:]), dtype=out_dtype)


def refine(F: ArrayLike, sharp_edges: ArrayLike | None = None, levels: int = 1, *, n_vertices: int | None = None,
           scheme: Scheme = "hybrid", sharpness: ArrayLike | None = None, sharp_faces: ArrayLike | None = None,
           corners: ArrayLike | None = None, loop_weights: LoopWeights = "loop",
           non_manifold: NonManifold = "raise", max_memory: MemoryLimit = None, uv_faces: ArrayLike | None = None,
           n_uvs: int | None = None, uv_mode: UVMode = "linear") -> Refinement:
    """Refine a mesh's connectivity and tags; positions are not needed.

    Parameters
    ----------
    F : (m, 3) array_like of int
        Triangles, consistently oriented, every edge in one or two faces.
    sharp_edges : (k, 2) array_like of int, optional
        Crease edges as vertex pairs, either orientation.
    levels : int
        Number of subdivision steps (0 gives the input back).
    n_vertices : int, optional
        Number of vertices; default ``F.max() + 1``. Vertices no face uses stay where they are.
    scheme : {"hybrid", "sqrt3", "loop"}
        See ``docs/scheme.md``.
    sharpness : (k,) array_like of float, optional
        Sharpness of each crease (default ``inf``; finite values are semi-sharp, ``>= 10`` is
        infinite, ``0`` no crease; negative or NaN is an error).
    sharp_faces : (m,) bool mask or array_like of int, optional
        Faces refined by Loop's 1-to-4 split (``"hybrid"``).
    corners : array_like of int, optional
        Vertices that never move.
    loop_weights : {"loop", "warren"}
        Smooth vertex weights in Loop regions.
    non_manifold : {"raise", "cut"}
        What to do with edges in three or more faces, and edges whose two faces run along them
        in the same direction (inconsistent orientation). ``"raise"`` (default): a
        ``MeshError`` naming the edge. ``"cut"``: cut the mesh along them — each vertex of such
        an edge gets one copy per sector of faces around it, so the cut edges become boundary
        edges (creases) of the pieces; its vertices become corners, except one on exactly two
        cut edges, which stays a crease vertex. In ``"hybrid"`` and ``"loop"`` the copies stay
        together at every level; in ``"sqrt3"`` each piece has Kobbelt's boundary. The output
        has vertices ``0 .. n-1`` (the input's), then the extra copies (in order of input
        vertex), then the new points; ``matrix``, ``steps[0].matrix`` and ``apply`` take the
        input's ``n`` vertices. Duplicate faces are an error either way. See ``docs/errors.md``.
    max_memory : int, float or str, optional
        Refuse (``OutputTooLargeError``) if the refinement is estimated to need more bytes than
        this (e.g. ``8e9``, ``"8G"``, ``"none"``). Default: :func:`hybridsub.set_memory_limit`,
        else the environment variable ``HYBRIDSUB_MAX_MEMORY``, else 80 % of the physical memory.
    uv_faces : (m, 3) array_like of int, optional
        Face-varying data (UVs with seams): the UV index of each face corner, row ``f`` for
        face ``f`` (OBJ's ``f v/vt``). The UV index mesh is refined beside the geometry:
        ``uv_faces`` and ``uv_matrix`` of the result and of each step. Seams (interior edges
        whose faces disagree on the UV indices) are split, never flipped, so in ``"hybrid"``
        the geometry differs from the refinement without ``uv_faces`` along seams;
        ``"sqrt3"`` raises ``ValueError``. See :func:`hybridsub.refine_face_varying` and
        ``docs/face_varying.md``.
    n_uvs : int, optional
        Number of UV values; default ``uv_faces.max() + 1``.
    uv_mode : {"linear", "smooth"}
        With ``uv_faces``: ``"linear"`` (default) interpolates UVs linearly, ``"smooth"``
        applies the scheme's rules to the UV index mesh (its boundary and seams as creases).

    Returns
    -------
    Refinement
        ``faces``, ``matrix``, tags, ``face_parent``, ``steps`` and ``apply``; with
        ``uv_faces`` also ``uv_faces`` and ``uv_matrix``.

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])   # tetrahedron
    >>> r = hybridsub.refine(F, levels=2, scheme="sqrt3")
    >>> r.faces.shape, r.matrix.shape
    ((36, 3), (20, 4))
    >>> FUV = np.arange(12).reshape(4, 3)      # UVs: every face its own chart, every edge a seam
    >>> r = hybridsub.refine(F, levels=1, uv_faces=FUV)
    >>> r.faces.shape, r.uv_faces.shape, r.matrix.shape, r.uv_matrix.shape
    ((24, 3), (24, 3), (14, 4), (28, 12))
    """
    budget = _budget.Budget(val.check_options(scheme, levels, loop_weights), scheme, max_memory)
    if uv_faces is None and n_uvs is not None:
        raise ValueError("n_uvs was given without uv_faces")
    if val.check_non_manifold(non_manifold) == "cut":  # cut, refine the cut mesh, compose
        return _repair.refine_cut(refine, F, sharp_edges, levels, n_vertices=n_vertices, scheme=scheme,
                                  sharpness=sharpness, sharp_faces=sharp_faces, corners=corners,
                                  loop_weights=loop_weights, max_memory=max_memory,
                                  uv=dict(uv_faces=uv_faces, n_uvs=n_uvs, uv_mode=uv_mode))
    if uv_faces is not None:  # the face-varying step loop (seams split), in _facevarying
        from .facevarying import refine_with_uvs

        return refine_with_uvs(F, uv_faces, sharp_edges, levels, n_vertices=n_vertices, n_uvs=n_uvs, scheme=scheme,
                               uv_mode=uv_mode, sharpness=sharpness, sharp_faces=sharp_faces, corners=corners,
                               loop_weights=loop_weights, max_memory=max_memory)
    check_uv_mode(uv_mode)
    levels, Fi, n, pairs, sharp, face_sharp, faces_as_indices, corner = _prepare(
        F, sharp_edges, levels, n_vertices, scheme, sharpness, sharp_faces, corners, loop_weights)

    def faces_out(mask):
        return np.flatnonzero(mask) if faces_as_indices else mask

    corners_out = np.flatnonzero(corner)
    steps = []
    face_parent = np.arange(len(Fi), dtype=np.int64)
    if len(Fi) == 0:  # nothing to refine: every level is the input
        steps = [RefinementStep(Fi.copy(), sp.identity(n, format="csr"), pairs, sharp, faces_out(face_sharp),
                                corners_out, face_parent) for _ in range(levels)]
    for level, plan, faces, child, offsets in _walk(Fi, n, levels, scheme, pairs, sharp, face_sharp, corner,
                                                    loop_weights, topology_last=True, budget=budget):
        pairs, sharp = child_creases(level, plan)
        parent = face_parents(offsets)
        face_parent = face_parent[parent]
        steps.append(RefinementStep(faces, step_matrix(level, plan), pairs, sharp, faces_out(child.face_sharp),
                                    corners_out, parent))
    last = steps[-1] if steps else None
    r = Refinement(last.faces if last else Fi.copy(), pairs, sharp,
                   last.sharp_faces if last else faces_out(face_sharp), corners_out, face_parent, steps, n)
    r._cache["max_memory"] = max_memory  # the composite matrix honours the same limit
    return r


UV_MODES = ("linear", "smooth")


def check_uv_mode(uv_mode) -> str:
    if not isinstance(uv_mode, str) or uv_mode not in UV_MODES:
        raise ValueError(f"uv_mode must be one of {UV_MODES}, got {uv_mode!r}")
    return uv_mode


def _prepare(F, sharp_edges, levels, n_vertices, scheme, sharpness, sharp_faces, corners, loop_weights):
    """Validate and normalise refine's arguments."""
    levels = val.check_options(scheme, levels, loop_weights)
    Fi, n = val.as_faces(F, n_vertices)
    pairs, sharp = val.as_sharp_edges(sharp_edges, sharpness, n)
    face_sharp, faces_as_indices = val.as_face_mask(sharp_faces, len(Fi))
    corner = val.as_corner_mask(corners, n)
    if scheme == "sqrt3" and (len(pairs) or face_sharp.any() or corner.any()):
        raise ValueError(
            'scheme="sqrt3" is Kobbelt\'s √3 without feature tags; to keep sharp edges, sharp faces or '
            'corners use scheme="hybrid" (√3 on smooth faces, Loop on sharp ones)'
        )
    if scheme == "loop":
        face_sharp[:] = True
    if levels == 0 or len(Fi) == 0:  # topology and tags get the same answer at every level count
        val.checked_level(Fi, n, pairs)
    keep = sharp > 0
    return levels, Fi, n, pairs[keep], sharp[keep], face_sharp, faces_as_indices, corner


def _walk(Fi, n, levels, scheme, pairs, sharp, face_sharp, corner, loop_weights, topology_last, budget=None):
    """Run the steps; yield (level, plan, child faces, child level, child offsets) for each.

    The child level of the last step (its twins and tags) is built only if
    ``topology_last``. ``budget`` (a ``_budget.Budget``) may refuse before a step allocates.
    """
    if levels == 0 or len(Fi) == 0:
        return
    level = val.checked_level(Fi, n, pairs).tag(pairs, sharp, face_sharp)  # named topology errors
    for step in range(1, levels + 1):
        plan = plan_step(level, corner, scheme, step, loop_weights)
        if budget is not None:
            budget.check(step, level, plan)  # before this step allocates anything large
        faces, child, offsets = child_level(level, plan, want_topology=topology_last or step < levels)
        yield level, plan, faces, child, offsets
        corner = np.concatenate([corner, np.zeros(plan.n_new - len(corner), dtype=bool)])
        level = child


def subdivide(V: ArrayLike, F: ArrayLike, sharp_edges: ArrayLike | None = None, levels: int = 1, *,
              scheme: Scheme = "hybrid", sharpness: ArrayLike | None = None, sharp_faces: ArrayLike | None = None,
              corners: ArrayLike | None = None, loop_weights: LoopWeights = "loop", return_matrix: bool = False,
              feature_angle: float | None = None, non_manifold: NonManifold = "raise",
              max_memory: MemoryLimit = None,
              ) -> tuple[NDArray[np.floating], NDArray[np.int64]] | tuple[NDArray[np.floating], NDArray[np.int64],
                                                                          sp.csr_matrix]:
    """Subdivide a triangle mesh, keeping its sharp features.

    Parameters
    ----------
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, 3) array_like of int
        Triangles, consistently oriented, every edge in one or two faces.
    sharp_edges : (k, 2) array_like of int, optional
        Crease edges (vertex pairs, either orientation). Boundary edges are creases anyway
        (``"hybrid"``, ``"loop"``).
    levels : int
        Number of subdivision steps.
    scheme : {"hybrid", "sqrt3", "loop"}
        ``"hybrid"``: √3 on smooth faces, Loop on sharp faces, creases split and never flipped;
        ``"sqrt3"``: Kobbelt's √3 with his boundary rule, no tags; ``"loop"``: Loop with creases.
    sharpness : (k,) array_like of float, optional
        Sharpness per crease: ``inf`` (default) or ``>= 10`` infinitely sharp, ``0 < s < 10``
        semi-sharp (``docs/semisharp.md``), ``0`` no crease; negative or NaN is an error.
    sharp_faces : (m,) bool mask or array_like of int, optional
        Faces split 1-to-4 by Loop's rule.
    corners : array_like of int, optional
        Vertices that never move (vertices with three or more creases are corners anyway).
    loop_weights : {"loop", "warren"}
        Smooth vertex weights in Loop regions.
    return_matrix : bool
        Also return the composite refinement matrix S (``V2 == S @ V``).
    feature_angle : float, optional
        Also tag what :func:`hybridsub.detect_features` finds at this dihedral angle (degrees):
        its sharp edges (infinitely sharp, unless given in ``sharp_edges``) and corners.
    non_manifold : {"raise", "cut"}
        ``"cut"`` cuts the mesh along edges in three or more faces and along inconsistently
        oriented edges instead of raising; see :func:`refine`.
    max_memory : int, float or str, optional
        Memory limit in bytes for this call; see :func:`refine` and ``docs/errors.md``.

    Returns
    -------
    V2 : (n', 3) ndarray
        Refined positions, in the dtype of ``V`` if it is floating-point, else float64 (always
        computed in float64; a new array, also for ``levels=0``). Vertices no face uses are
        kept and do not move.
    F2 : (m', 3) int64 ndarray
        Refined faces.
    S : scipy.sparse.csr_matrix, (n', n)
        Only with ``return_matrix=True``.

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    >>> V2, F2 = hybridsub.subdivide(V, F, levels=2)
    >>> V2.shape, F2.shape
    ((20, 3), (36, 3))
    >>> V2, F2, S = hybridsub.subdivide(V, F, sharp_edges=[[0, 1]], return_matrix=True)
    >>> bool(np.allclose(S @ V, V2))
    True
    >>> V, F = hybridsub.load_example()
    >>> V2, F2 = hybridsub.subdivide(V, F, levels=1, feature_angle=30)   # creases found and kept
    """
    Vf, out_dtype = val.as_vertices(V, return_dtype=True)
    if feature_angle is not None:  # automatic features (docs/features.md)
        sharp_edges, sharpness, corners = merge_detected(Vf, F, feature_angle, sharp_edges, sharpness, corners)
    if return_matrix or val.check_non_manifold(non_manifold) == "cut":
        r = refine(F, sharp_edges, levels, n_vertices=len(Vf), scheme=scheme, sharpness=sharpness,
                   sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights,
                   non_manifold=non_manifold, max_memory=max_memory)
        V2 = r.apply(Vf).astype(out_dtype, copy=False)
        return (V2, r.faces, r.matrix) if return_matrix else (V2, r.faces)
    last = None
    for last in subdivide_levels(Vf, F, sharp_edges, levels, scheme=scheme, sharpness=sharpness,
                                 sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights, tags=False,
                                 max_memory=max_memory):
        pass
    if last is None:  # no step ran: copies of the input
        return Vf.astype(out_dtype, copy=True), val.as_faces(F, len(Vf))[0].copy()
    return last.X.astype(out_dtype, copy=False), last.faces


@dataclass(frozen=True, eq=False)
class LevelOutput:
    """One level of :func:`subdivide_levels`."""

    step: int
    X: np.ndarray  # (n_k, d) refined data
    faces: np.ndarray  # (m_k, 3)
    face_parent: np.ndarray | None  # (m_k,) face of the previous level each face came from
    sharp_edges: np.ndarray | None  # tags of this level (these four None unless tags=True)
    sharpness: np.ndarray | None
    sharp_faces: np.ndarray | None  # (m_k,) bool mask


def subdivide_levels(X, F, sharp_edges=None, levels=1, *, scheme="hybrid", sharpness=None, sharp_faces=None,
                     corners=None, loop_weights="loop", tags=True, max_memory=None):
    """Subdivide level by level without forming matrices; yield a :class:`LevelOutput` per step.

    The fast path behind :func:`subdivide`, for callers that want each level as it is done
    (the command line's progress bar) or the propagated tags with the positions. ``X`` is
    any (n, d) per-vertex data, already validated as float64. With ``tags=False`` neither
    tags nor face parents are computed (nor the last level's twins). ``max_memory`` as in :func:`subdivide`.
    """
    levels, Fi, n, pairs, sharp, face_sharp, _, corner = _prepare(
        F, sharp_edges, levels, len(X), scheme, sharpness, sharp_faces, corners, loop_weights)
    budget = _budget.Budget(levels, scheme, max_memory, keeps_steps=False)
    for k, (level, plan, faces, child, offsets) in enumerate(
            _walk(Fi, n, levels, scheme, pairs, sharp, face_sharp, corner, loop_weights, topology_last=tags,
                  budget=budget), 1):
        X = apply_step(level, plan, X)
        if tags:
            pairs, sharp = child_creases(level, plan)
            yield LevelOutput(k, X, faces, face_parents(offsets), pairs, sharp, child.face_sharp)
        else:
            yield LevelOutput(k, X, faces, None, None, None, None)
