"""The fast path: ``subdivide`` and the level-by-level generators, positions (and UVs) refined
by applying each step's stencils directly, no matrix formed and only two levels held.

The numbers are those of the step matrices applied one after the other, bit for bit
(:mod:`.stencils` walks the same rows in the same order).

>>> import numpy as np
>>> V = np.array([[0., 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
>>> [out.X.shape for out in subdivide_levels(V, [[0, 1, 2], [0, 2, 3]], levels=2)]
[(10, 3), (28, 3)]
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Literal, overload

import numpy as np
import scipy.sparse as sp

from .._input import RefineInput, as_vertices, open_gate
from .._topology import child_creases, face_parents
from .._typing import ArrayLike, Boundary, LoopWeights, MemoryLimit, NDArray, NonManifold, Scheme
from .budget import Budget
from .linear_uv import linear_uv_apply
from .loop import walk
from .refinement import refinement_of, without_holes
from .stencils import apply_step


Positions = NDArray[np.floating]
Faces = NDArray[np.int64]


@overload
def subdivide(V: ArrayLike, F: ArrayLike, sharp_edges: ArrayLike | None = None, levels: int = 1, *,
              scheme: Scheme = ..., sharpness: ArrayLike | None = ..., sharp_faces: ArrayLike | None = ...,
              corners: ArrayLike | None = ..., loop_weights: LoopWeights = ..., return_matrix: Literal[False] = ...,
              feature_angle: float | None = ..., non_manifold: NonManifold = ...,
              max_memory: MemoryLimit = ..., progress: bool | None = ..., corner_sharpness: ArrayLike | None = ...,
              boundary: Boundary = ..., holes: ArrayLike | None = ...) -> tuple[Positions, Faces]: ...


@overload
def subdivide(V: ArrayLike, F: ArrayLike, sharp_edges: ArrayLike | None = None, levels: int = 1, *,
              scheme: Scheme = ..., sharpness: ArrayLike | None = ..., sharp_faces: ArrayLike | None = ...,
              corners: ArrayLike | None = ..., loop_weights: LoopWeights = ..., return_matrix: Literal[True],
              feature_angle: float | None = ..., non_manifold: NonManifold = ...,
              max_memory: MemoryLimit = ..., progress: bool | None = ..., corner_sharpness: ArrayLike | None = ...,
              boundary: Boundary = ..., holes: ArrayLike | None = ...) -> tuple[Positions, Faces, sp.csr_matrix]: ...


def subdivide(V: ArrayLike, F: ArrayLike | None = None, sharp_edges: ArrayLike | None = None, levels: int = 1, *,
              scheme: Scheme = "hybrid", sharpness: ArrayLike | None = None, sharp_faces: ArrayLike | None = None,
              corners: ArrayLike | None = None, loop_weights: LoopWeights = "loop", return_matrix: bool = False,
              feature_angle: float | None = None, non_manifold: NonManifold = "raise",
              max_memory: MemoryLimit = None, progress: bool | None = False,
              corner_sharpness: ArrayLike | None = None, boundary: Boundary = "edge_only",
              holes: ArrayLike | None = None,
              ) -> tuple[Positions, Faces] | tuple[Positions, Faces, sp.csr_matrix]:
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
    corner_sharpness : (c,) array_like of float, optional
        Sharpness of each of ``corners`` (default ``inf``): semi-sharp corners, as
        :func:`refine` (OpenSubdiv's vertex sharpness).
    boundary : {"edge_only", "edge_and_corner", "none"}
        OpenSubdiv's boundary interpolation; see :func:`refine` and ``docs/scheme.md``.
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
    progress : bool or None
        Show a progress bar per level (tqdm: a line on stderr, a widget in a notebook); None:
        only where stderr is a terminal.
    holes : (m,) bool mask or array_like of int, optional
        Faces not rendered that still shape their neighbours: ``V2`` is as without holes
        (every vertex kept), ``F2`` leaves out the faces descending from a hole; see
        :func:`refine`.

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
    Vf, out_dtype = as_vertices(V, return_dtype=True)  # (a mesh object: a TypeError naming subdivide_mesh)
    if F is None:
        raise TypeError("subdivide(V, F, ...) needs the faces F (an (m, 3) array of vertex indices)")
    inp = open_gate(F, sharp_edges, levels, n_vertices=len(Vf), scheme=scheme, sharpness=sharpness,
                    sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights, non_manifold=non_manifold,
                    max_memory=max_memory, positions=Vf, feature_angle=feature_angle,
                    corner_sharpness=corner_sharpness, boundary=boundary, holes=holes)
    if return_matrix or inp.cut is not None or inp.hole is not None:  # a cut mesh's positions: S_1 @ D
        r = without_holes(refinement_of(inp, progress), inp.hole)
        V2 = r.apply(Vf).astype(out_dtype, copy=False)
        return (V2, r.faces, r.matrix) if return_matrix else (V2, r.faces)
    X, faces = _last_level(inp, Vf, progress)
    if faces is None:  # no step ran: copies of the input
        return Vf.astype(out_dtype, copy=True), inp.faces.copy()
    return X.astype(out_dtype, copy=False), faces


def _last_level(inp: RefineInput, X: np.ndarray, progress: bool | None) -> tuple[np.ndarray, np.ndarray | None]:
    """The positions and faces of the last level (faces None if no step ran), holding as
    little at once as the steps allow: each step refines the data before it emits its faces,
    the last one drops its vertex weights and tags first, and nothing keeps the levels before."""
    data = [X]

    def refine(level, plan):
        data[0] = apply_step(level, plan, data[0])

    faces = None
    for s in walk(inp, Budget(inp.levels, inp.scheme, inp.max_memory, keeps_steps=False), topology_last=False,
                  progress=progress, data_first=refine):
        faces = s.faces
        del s
    return data[0], faces


@dataclass(frozen=True, eq=False)
class LevelOutput:
    """One level of :func:`walk_data`."""

    step: int
    X: np.ndarray  # (n_k, d) refined per-vertex data
    faces: np.ndarray  # (m_k, 3)
    face_parent: np.ndarray | None  # (m_k,) face of the previous level each face came from
    sharp_edges: np.ndarray | None  # tags of this level (these four None unless tags=True)
    sharpness: np.ndarray | None
    sharp_faces: np.ndarray | None  # (m_k,) bool mask
    UV: np.ndarray | None = None  # (t_k, e) refined per-UV-index data, with face-varying data
    uv_faces: np.ndarray | None = None  # (m_k, 3), aligned with faces


def walk_data(inp: RefineInput, X: np.ndarray, UV: np.ndarray | None = None, tags: bool = True,
              progress: bool | None = False) -> Iterator[LevelOutput]:
    """Refine ``X (n, d)`` (and with ``inp.uv``, ``UV (t, e)``), both float64, step by step.

    Tags and face parents come with each level unless ``tags=False`` (always with UVs).
    """
    budget = Budget(inp.levels, inp.scheme, inp.max_memory, keeps_steps=False)
    for s in walk(inp, budget, topology_last=tags, progress=progress):
        X = apply_step(s.level, s.plan, X)
        if s.uv is not None:
            if inp.uv.mode != "all":
                UV = apply_step(s.uv.level, s.uv.plan, UV)
            else:
                UV = linear_uv_apply(s.uv.level, s.uv.plan, UV)
        if not tags and s.uv is None:
            out = LevelOutput(s.step, X, s.faces, None, None, None, None)
        else:
            pairs, sharp = child_creases(s.level, s.plan)
            uv_faces = s.uv.faces if s.uv is not None else None
            out = LevelOutput(s.step, X, s.faces, face_parents(s.offsets), pairs, sharp, s.child.face_sharp, UV,
                              uv_faces)
        del s  # the step's plan is not held while the next step is planned
        yield out
        del out


@dataclass(frozen=True, eq=False)
class WalkedLevel:
    """The last level of :func:`walk_to`, and the faces of the level it was asked to keep."""

    X: np.ndarray  # (n, d) the data at the last level
    faces: np.ndarray  # (m, 3) the last level's faces
    face_sharp: np.ndarray  # (m,) bool sharp faces of the last level
    sharp_edges: np.ndarray  # (k, 2) its tagged creases
    sharpness: np.ndarray  # (k,)
    kept_faces: np.ndarray  # (m_at, 3) the faces of level ``at``
    kept_hole: np.ndarray | None  # (m_at,) which of them descend from a hole (None: no holes)
    kept_n_vertices: int  # vertices of level ``at``


def walk_to(inp: RefineInput, X: np.ndarray, at: int) -> WalkedLevel:
    """Refine ``X`` (n, d) float64 through ``inp.levels`` steps without forming matrices; the
    last level with its tags, and the faces of level ``at`` (≤ ``inp.levels``).

    The numbers are those of :meth:`Refinement.apply` before its matrix is formed, bit for bit.

    >>> import numpy as np
    >>> from hybridsub._input import open_gate
    >>> inp = open_gate(np.array([[0, 1, 2]]), [[0, 1]], 2, scheme="loop")
    >>> w = walk_to(inp, np.eye(3), 1)
    >>> w.X.shape, len(w.faces), len(w.kept_faces), len(w.sharp_edges)
    ((15, 3), 16, 4, 0)
    """
    faces, face_sharp, pairs, sharp = inp.faces, inp.face_sharp, inp.sharp_edges, inp.sharpness
    hole = inp.hole
    kept, kept_hole, kept_n = faces, hole, inp.n_vertices
    topology = inp.scheme == "hybrid" or hole is not None  # the last face tags and parents
    for s in walk(inp, Budget(inp.levels, inp.scheme, inp.max_memory, keeps_steps=False), topology_last=topology):
        X = apply_step(s.level, s.plan, X)
        faces = s.faces
        if s.step == inp.levels:
            pairs, sharp = child_creases(s.level, s.plan)
        face_sharp = s.child.face_sharp if s.child is not None else np.full(len(faces), inp.scheme == "loop")
        if hole is not None:
            hole = hole[face_parents(s.offsets)]
        if s.step == at:
            kept, kept_hole, kept_n = faces, hole, s.plan.n_new
        del s
    return WalkedLevel(X, faces, face_sharp, pairs, sharp, kept, kept_hole, kept_n)


def subdivide_levels(X, F, sharp_edges=None, levels=1, *, scheme="hybrid", sharpness=None, sharp_faces=None,
                     corners=None, loop_weights="loop", tags=True, max_memory=None,
                     non_manifold="raise", corner_sharpness=None, boundary="edge_only",
                     holes=None) -> Iterator[LevelOutput]:
    """Subdivide level by level without forming matrices; yield a :class:`LevelOutput` per step.

    The fast path behind :func:`subdivide`, for callers that want each level as it is done
    (the command line's progress bar) or the propagated tags with the positions. ``X`` is
    any (n, d) per-vertex data, already validated as float64. With ``tags=False`` neither
    tags nor face parents are computed (nor the last level's twins). ``max_memory`` and
    ``non_manifold`` as in :func:`subdivide` (with ``"cut"`` the levels are those of the cut mesh);
    ``corner_sharpness``, ``boundary`` and ``holes`` too, except that every level is yielded whole
    (the caller drops the faces of holes, and ``boundary="none"``'s, through the face parents).
    """
    inp = open_gate(F, sharp_edges, levels, n_vertices=len(X), scheme=scheme, sharpness=sharpness,
                    sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights, max_memory=max_memory,
                    non_manifold=non_manifold, corner_sharpness=corner_sharpness, boundary=boundary, holes=holes)
    yield from walk_data(inp, X if inp.cut is None else X[inp.cut.origin], tags=tags)


def subdivide_face_varying_levels(X: np.ndarray, F, UV: np.ndarray, FUV, sharp_edges=None, levels: int = 1, *,
                                  scheme="hybrid", uv_mode="linear", sharpness=None, sharp_faces=None, corners=None,
                                  loop_weights="loop", max_memory=None, non_manifold="raise", corner_sharpness=None,
                                  boundary="edge_only", uv_interpolation=None) -> Iterator[LevelOutput]:
    """The face-varying fast path: yield a :class:`LevelOutput` (with ``UV`` and ``uv_faces``)
    per step, no matrix kept.

    ``X (n, d)`` and ``UV (t, e)`` are float64, already validated. The same numbers as
    ``refine(..., uv_faces=FUV)``'s step matrices applied one after the other, bit for bit;
    only two levels are held at a time (the command line's progress bar runs on it).
    """
    inp = open_gate(F, sharp_edges, levels, n_vertices=len(X), scheme=scheme, sharpness=sharpness,
                    sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights, max_memory=max_memory,
                    uv_faces=FUV, n_uvs=len(UV), uv_mode=uv_mode, uv_name="FUV", non_manifold=non_manifold,
                    corner_sharpness=corner_sharpness, boundary=boundary, uv_interpolation=uv_interpolation)
    yield from walk_data(inp, X if inp.cut is None else X[inp.cut.origin], UV)
