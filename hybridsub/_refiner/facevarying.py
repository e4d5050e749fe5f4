"""Face-varying data (UVs with seams), the public functions: refining an index mesh
``(UV, FUV)`` beside ``(V, F)``. The step loop carries the UV channel (:mod:`.loop`); the UV
index mesh's topology is :mod:`hybridsub._topology.uv`.

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

from typing import Literal, NamedTuple, overload

import numpy as np
import scipy.sparse as sp

from .._input import as_uv_values, as_vertices, open_gate
from .._topology import seam_halfedges
from .._typing import ArrayLike, Boundary, LoopWeights, MemoryLimit, NDArray, NonManifold, Scheme, UVMode
from .fastpath import walk_data
from .refinement import Refinement, refine, refinement_of, without_holes


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
    inp = open_gate(F, levels=0, uv_faces=FUV, uv_name="FUV")
    if not inp.n_faces:
        return np.empty((0, 2), np.int64)
    level = inp.level
    seam = seam_halfedges(level, inp.uv.faces)
    return level.edge_vertices[seam[level.edge_owner]]


def refine_face_varying(F: ArrayLike, FUV: ArrayLike, sharp_edges: ArrayLike | None = None, levels: int = 1, *,
                        n_vertices: int | None = None, n_uvs: int | None = None, scheme: Scheme = "hybrid",
                        uv_mode: UVMode = "linear", sharpness: ArrayLike | None = None,
                        sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
                        loop_weights: LoopWeights = "loop", non_manifold: NonManifold = "raise",
                        max_memory: MemoryLimit = None, uv_interpolation: str | None = None,
                        corner_sharpness: ArrayLike | None = None, boundary: Boundary = "edge_only",
                        holes: ArrayLike | None = None) -> FaceVaryingRefinement:
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
    corner_sharpness, boundary, holes
        As in :func:`hybridsub.refine` (the UV faces of holes are left out with the faces).
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
    uv_interpolation : {"none", "corners_only", "corners_plus1", "corners_plus2", "boundaries", "all"}, optional
        OpenSubdiv's ``FVarLinearInterpolation`` modes (``docs/face_varying.md``); when given
        it replaces ``uv_mode`` (``"linear"`` is ``"all"``, ``"smooth"`` is ``"none"``).

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
    geo = refine(F, sharp_edges, levels, n_vertices=n_vertices, scheme=scheme, sharpness=sharpness,
                 sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights, non_manifold=non_manifold,
                 max_memory=max_memory, uv_faces=FUV, n_uvs=n_uvs, uv_mode=uv_mode,
                 uv_interpolation=uv_interpolation, corner_sharpness=corner_sharpness, boundary=boundary,
                 holes=holes)
    assert geo.uv_refinement is not None  # refine attaches it whenever uv_faces is given
    return FaceVaryingRefinement(geo, geo.uv_refinement)


_Textured = tuple[NDArray[np.floating], NDArray[np.int64], NDArray[np.floating], NDArray[np.int64]]


@overload
def subdivide_face_varying(V: ArrayLike, F: ArrayLike, UV: ArrayLike, FUV: ArrayLike,
                           sharp_edges: ArrayLike | None = None, levels: int = 1, *, scheme: Scheme = ...,
                           uv_mode: UVMode = ..., sharpness: ArrayLike | None = ..., sharp_faces: ArrayLike | None = ...,
                           corners: ArrayLike | None = ..., loop_weights: LoopWeights = ...,
                           return_matrix: Literal[False] = ..., max_memory: MemoryLimit = ...,
                           uv_interpolation: str | None = ..., corner_sharpness: ArrayLike | None = ...,
                           boundary: Boundary = ..., holes: ArrayLike | None = ...) -> _Textured: ...


@overload
def subdivide_face_varying(V: ArrayLike, F: ArrayLike, UV: ArrayLike, FUV: ArrayLike,
                           sharp_edges: ArrayLike | None = None, levels: int = 1, *, scheme: Scheme = ...,
                           uv_mode: UVMode = ..., sharpness: ArrayLike | None = ..., sharp_faces: ArrayLike | None = ...,
                           corners: ArrayLike | None = ..., loop_weights: LoopWeights = ...,
                           return_matrix: Literal[True], max_memory: MemoryLimit = ...,
                           uv_interpolation: str | None = ..., corner_sharpness: ArrayLike | None = ...,
                           boundary: Boundary = ..., holes: ArrayLike | None = ...) -> tuple[NDArray[np.floating], NDArray[np.int64], NDArray[np.floating], NDArray[np.int64],
                                      sp.csr_matrix, sp.csr_matrix]: ...


def subdivide_face_varying(V: ArrayLike, F: ArrayLike, UV: ArrayLike, FUV: ArrayLike,
                           sharp_edges: ArrayLike | None = None, levels: int = 1, *, scheme: Scheme = "hybrid",
                           uv_mode: UVMode = "linear", sharpness: ArrayLike | None = None,
                           sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
                           loop_weights: LoopWeights = "loop", return_matrix: bool = False,
                           max_memory: MemoryLimit = None, uv_interpolation: str | None = None,
                           corner_sharpness: ArrayLike | None = None, boundary: Boundary = "edge_only",
                           holes: ArrayLike | None = None) -> tuple:
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
    corner_sharpness, boundary, holes
        As in :func:`hybridsub.subdivide` (``FUV2`` leaves out the rows of the faces left out).
    scheme : {"hybrid", "loop"}
        ``"hybrid"`` splits seam edges (R4) instead of flipping them, so its geometry differs
        from :func:`subdivide` along seams; ``"loop"`` geometry equals :func:`subdivide`'s.
        ``"sqrt3"`` raises ``ValueError``.
    uv_mode : {"linear", "smooth"}
        ``"linear"`` (default): UVs are interpolated linearly, textures never distort
        (OpenSubdiv ``FVAR_LINEAR_ALL``). ``"smooth"``: UVs are subdivided like positions, UV
        boundaries and seams as creases (OpenSubdiv ``FVAR_LINEAR_NONE``).
    uv_interpolation : {"none", "corners_only", "corners_plus1", "corners_plus2", "boundaries", "all"}, optional
        OpenSubdiv's ``FVarLinearInterpolation`` modes (``docs/face_varying.md``); when given
        it replaces ``uv_mode`` (``"linear"`` is ``"all"``, ``"smooth"`` is ``"none"``).
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
    Vf = as_vertices(A)
    UVf = as_uv_values(UV)
    out_dtype = A.dtype if np.issubdtype(A.dtype, np.floating) else np.float64
    U = np.asarray(UV)
    uv_dtype = U.dtype if np.issubdtype(U.dtype, np.floating) else np.float64
    inp = open_gate(F, sharp_edges, levels, n_vertices=len(Vf), scheme=scheme, sharpness=sharpness,
                    sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights, max_memory=max_memory,
                    uv_faces=FUV, n_uvs=len(UVf), uv_mode=uv_mode, uv_name="FUV",
                    uv_interpolation=uv_interpolation, corner_sharpness=corner_sharpness, boundary=boundary,
                    holes=holes)
    if return_matrix or inp.hole is not None:  # holes: the faces left out through the refinement's face parents
        geo = without_holes(refinement_of(inp), inp.hole)
        uv = geo.uv_refinement
        V2 = geo.apply(Vf).astype(out_dtype, copy=False)
        UV2 = uv.apply(UVf).astype(uv_dtype, copy=False)
        if return_matrix:
            return V2, geo.faces, UV2, uv.faces, geo.matrix, uv.matrix
        return V2, geo.faces, UV2, uv.faces
    last = None
    for last in walk_data(inp, Vf, UVf.reshape(len(UVf), -1)):
        pass
    if last is None:  # no step ran: copies of the input
        return (Vf.astype(out_dtype, copy=True), inp.faces.copy(), UVf.astype(uv_dtype, copy=True),
                inp.uv.faces.copy())
    UV2 = last.UV.reshape((len(last.UV),) + UVf.shape[1:])
    return (last.X.astype(out_dtype, copy=False), last.faces, UV2.astype(uv_dtype, copy=False), last.uv_faces)
