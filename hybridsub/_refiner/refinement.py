"""Refinement matrices: ``refine``, and the objects that hold its results.

A :class:`Refinement` is what ``refine`` returns: connectivity, tags and refinement
matrices, computed from topology and tags alone by the step loop (:mod:`.loop`). Its
:meth:`Refinement.apply` refines any per-vertex data with them.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from .._input import RefineInput, as_data, count_of, open_gate, tag_counts, writable
from .._topology import build_level, child_creases, face_parents
from typing import TYPE_CHECKING

from .._typing import ArrayLike, Boundary, LoopWeights, MemoryLimit, NonManifold, Scheme, UVMode
from .budget import Budget, check_product
from .chart import vertex_origins
from .loop import Step, walk
from .linear_uv import linear_uv_matrix
from .stencils import CodedStencils, apply_coded, apply_matrix, coded_stencils, in_read_order, product, step_matrix

if TYPE_CHECKING:
    from .._fit.multires import MultiresDetails


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
    holes : (m',) bool or None
        With ``refine(..., holes=...)``: the faces of level k + 1 descending from a hole. A step
        holds the whole level its matrix refines (as OpenSubdiv's ``TopologyLevel`` does, with
        ``IsFaceHole``); the :class:`Refinement`'s own ``faces`` leave the holes out. Else None.
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
    _far_apart: bool = field(default=False, repr=False)  # level k's Level.far_apart
    holes: np.ndarray | None = None

    @property
    def n_vertices(self) -> int:
        """Number of vertices of level k + 1."""
        return self.matrix.shape[0]

    def __repr__(self) -> str:
        uv = f"; {count_of(self.uv_matrix.shape[0], 'UV value')}" if self.uv_matrix is not None else ""
        return (f"<RefinementStep: from {count_of(self.matrix.shape[1], 'vertex')}: {count_of(len(self.faces), 'face')}, "
                f"{count_of(self.n_vertices, 'vertex')}; {tag_counts(self.sharp_edges, self.corners, self.sharp_faces)}"
                f"{uv}>")


@dataclass(frozen=True, eq=False)
class Refinement:
    """The result of :func:`hybridsub.refine`: connectivity, tags and matrices of L steps.

    Attributes
    ----------
    faces : (m_L, 3) int64
        Faces of the finest level (with ``holes``: those not descending from a hole).
    sharp_edges, sharpness, sharp_faces, corners
        Tags of the finest level, in the forms they were given (sharp faces as a mask or
        indices of ``faces``).
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
    uv_refinement : Refinement or None
        With ``uv_faces``: the UV index mesh's own refinement (see
        :func:`hybridsub.refine_face_varying`); else None.
    max_memory : int, float, str or None
        The memory limit of the call, which forming ``matrix`` honours too.
    face_level, vertex_level : (m_L,) and (n_L,) int64 or None
        From :func:`hybridsub.refine_adaptive`: the level of each output face and vertex (each
        vertex sits where the uniform refinement of its level puts it); None from ``refine``.
    corner_sharpness : (c,) float64 or None
        With semi-sharp corners (``corner_sharpness=``): the sharpness each of ``corners`` has
        left at the finest level (each level takes one off; ``corners`` lists those still
        sharp); None when every corner is infinitely sharp.
    """

    faces: np.ndarray
    sharp_edges: np.ndarray
    sharpness: np.ndarray
    sharp_faces: np.ndarray
    corners: np.ndarray
    face_parent: np.ndarray
    steps: list
    n_coarse: int
    max_memory: MemoryLimit = field(default=None, repr=False)  # the limit forming ``matrix`` honours
    uv_refinement: Refinement | None = field(default=None, repr=False)  # the UV index mesh's, with uv_faces
    coarse_faces: np.ndarray | None = field(default=None, repr=False)  # the input's faces (for vertex_origin)
    face_level: np.ndarray | None = field(default=None, repr=False)  # adaptive refinement: each face's level
    vertex_level: np.ndarray | None = field(default=None, repr=False)  # and each vertex's
    _cache: dict = field(default_factory=dict, repr=False)
    corner_sharpness: np.ndarray | None = field(default=None, repr=False)  # semi-sharp corners' sharpness left

    @property
    def n_vertices(self) -> int:
        return self.steps[-1].n_vertices if self.steps else self.n_coarse

    def __repr__(self) -> str:
        uv = "" if self.uv_refinement is None else f"; UVs: {count_of(self.uv_refinement.n_vertices, 'value')}"
        return (f"<Refinement: {count_of(len(self.steps), 'level')} from {count_of(self.n_coarse, 'vertex')}: "
                f"{count_of(len(self.faces), 'face')}, {count_of(self.n_vertices, 'vertex')}; "
                f"{tag_counts(self.sharp_edges, self.corners, self.sharp_faces)}{uv}>")

    @property
    def uv_faces(self) -> np.ndarray | None:
        return None if self.uv_refinement is None else self.uv_refinement.faces

    @property
    def uv_matrix(self) -> sp.csr_matrix | None:
        """Composite UV matrix ``S_uv,L ⋯ S_uv,1`` (t_L × t), computed once; None without UVs."""
        return None if self.uv_refinement is None else self.uv_refinement.matrix

    @property
    def matrix(self) -> sp.csr_matrix:
        """Composite refinement matrix ``S_L ⋯ S_1`` (n_fine × n_coarse), computed once."""
        if "matrix" not in self._cache:
            S = sp.identity(self.n_coarse, format="csr", dtype=np.float64)
            for st in self.steps:
                check_product(st.matrix, S, self.max_memory)  # size guard
                S = product(st.matrix, S, st._far_apart)
            self._cache["matrix"] = S
        return self._cache["matrix"]

    @property
    def vertex_origin(self) -> tuple[np.ndarray, np.ndarray]:
        """Where each vertex of the finest level lies over the input: ``(face, bary)``.

        ``face`` (n_L,) int64 is an input face containing the vertex's parameter and ``bary``
        (n_L, 3) its barycentric coordinates over ``F[face]``, in the chart where the two faces
        of every edge form a rhombus of equilateral triangles: old vertices keep their place,
        edge points sit at midpoints (Kobbelt's boundary trisection at thirds), face points at
        centroids. A vertex on several input faces is reported on the one its first face (in
        face order) descends from. ``hybridsub.LimitSurface(...).evaluate(*r.vertex_origin)``
        equals ``hybridsub.limit_positions(..., levels=L)``. Vertices no face uses: face −1.
        Not available after ``non_manifold="cut"`` (``ValueError``).

        Examples
        --------
        >>> import numpy as np, hybridsub
        >>> r = hybridsub.refine(np.array([[0, 1, 2]]), levels=1, scheme="loop")
        >>> face, bary = r.vertex_origin
        >>> face.tolist(), bary[3:].round(3).tolist()          # the three edge midpoints
        ([0, 0, 0, 0, 0, 0], [[0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]])
        """
        if "origin" not in self._cache:
            if self.coarse_faces is None:
                raise ValueError('vertex_origin is not available for a refinement with non_manifold="cut"')
            self._cache["origin"] = vertex_origins(self.coarse_faces, self.n_coarse, self.steps,
                                                   lambda F, n: build_level(F, n).twin)
        face, bary = self._cache["origin"]
        return face.copy(), bary.copy()

    def apply(self, X: ArrayLike, out: np.ndarray | None = None) -> np.ndarray:
        """Refine per-vertex data: positions, UVs, colours, any (n_coarse, ...) array.

        Floating-point data keeps its dtype (computed in float64); other data comes back as
        float64; complex data stays complex. The result is always a new array, also with no
        steps, unless ``out`` is given: a C-contiguous float64 array of the result's shape
        (real data only), written and returned — an animation reusing one buffer per frame
        saves allocating (and the system's zeroing of) fresh memory every frame. Once ``matrix``
        has been formed, ``apply`` multiplies by it (one pass over the data, the product
        ``matrix @ X`` to the bit); before, by the step matrices one after the other
        (``subdivide``'s result to the bit). From the second call on, either is held with its
        distinct weights stored once (a 2-byte code an entry, see ``docs/performance.md``), and
        the steps with each level between two numbered as the next reads it: the same bits
        faster; frames batched as ``(n, f, 3)`` or ``(n, 3 f)`` share one pass over it.

        Examples
        --------
        >>> import numpy as np, hybridsub
        >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]]); F = np.array([[0, 1, 2]])
        >>> r = hybridsub.refine(F, levels=1)
        >>> r.apply(V).shape
        (7, 3)
        >>> buf = np.empty((7, 3)); r.apply(V, out=buf) is buf
        True
        """
        A, out_dtype, work = as_data(X, self.n_coarse)  # dtypes, shapes, never a view
        k = int(np.prod(A.shape[1:], dtype=np.int64))
        Y = writable(np.asarray(A, dtype=work).reshape(self.n_coarse, k))
        if out is not None:
            dest = _output_buffer(out, (self.n_vertices,) + A.shape[1:], work)
            if not self.steps:
                dest[...] = Y
            for i, S in enumerate(stencils := self._stencils()):
                last = dest if i == len(stencils) - 1 else None
                Y = apply_coded(S, Y, last) if isinstance(S, CodedStencils) else apply_matrix(S, Y, last)
            return out
        if work == np.complex128:  # real and imaginary parts side by side
            Y = np.concatenate([Y.real, Y.imag], axis=1)
        if not self.steps:
            Y = Y.copy()
        for S in self._stencils():
            Y = apply_coded(S, Y) if isinstance(S, CodedStencils) else apply_matrix(S, Y)
        if work == np.complex128:
            k = Y.shape[1] // 2
            Y = Y[:, :k] + 1j * Y[:, k:]
        return np.ascontiguousarray(Y.reshape((Y.shape[0],) + A.shape[1:]), dtype=out_dtype)

    def _stencils(self) -> list:
        """What :meth:`apply` multiplies by: the composite once formed, else the steps; from the
        second call on, coded where the weights allow (coding costs a few frames, so data
        refined once is multiplied by the plain matrices, with the same bits)."""
        key = "coded matrix" if "matrix" in self._cache else "coded steps"
        mats = [self._cache["matrix"]] if key == "coded matrix" else [st.matrix for st in self.steps]
        if key not in self._cache:
            if not self._cache.pop("uncoded " + key, False):
                self._cache["uncoded " + key] = True
                return mats
            self._cache[key] = [coded_stencils(S) or S for S in in_read_order(mats)]
        return self._cache[key]

    def decompose(self, X: ArrayLike, *, frames: bool | None = None) -> tuple[np.ndarray, "MultiresDetails"]:
        """Reverse subdivision: coarse data and per-level details of finest-level data ``X``.

        Level by level from the finest, the coarser data is the least-squares fit
        ``argmin ||S c − X_{k+1}||`` through the step's matrix (Samavati & Bartels; the sparse
        factor of ``SᵀS`` is kept on this object and reused), and the step's details are
        ``X_{k+1} − S c``. Creases are respected: ``S`` holds their rules. Data that is a
        refinement (``X = r.apply(V)``) gives ``V`` back and zero details. See
        ``docs/fitting.md``.

        Parameters
        ----------
        X : (n_vertices, ...) array_like of real numbers
            Data on the finest level (positions, colours, ...).
        frames : bool, optional
            Write the details in local frames (tangent, bitangent, normal of the refined
            coarser level at each vertex), so that editing the coarse data carries them along.
            Default: for three-column data (positions).

        Returns
        -------
        coarse : (n_coarse, ...) float64
        details : MultiresDetails
            One (n_{k+1}, c) array per step, coarsest first; pass both to :meth:`reconstruct`.

        Examples
        --------
        >>> import numpy as np, hybridsub
        >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
        >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
        >>> r = hybridsub.refine(F, levels=2)
        >>> coarse, details = r.decompose(r.apply(V))
        >>> bool(np.allclose(coarse, V)), bool(details.norms().max() < 1e-12)
        (True, True)
        """
        from .._fit.multires import decompose  # the one call up a layer: see docs/architecture.md
        return decompose(self.steps, self.n_coarse, self._cache, X, frames)

    def reconstruct(self, coarse: ArrayLike, details: "MultiresDetails") -> np.ndarray:
        """Finest-level data from coarse data and :meth:`decompose`'s details.

        ``reconstruct(*decompose(X)) == X`` to rounding. With details in local frames, edited
        coarse positions carry the details along (each frame is computed on the edited mesh).
        Details made by another refinement (other faces, scheme, weights or tags, even of the
        same sizes) are refused: they carry a fingerprint of the refinement that made them.

        Examples
        --------
        >>> import numpy as np, hybridsub
        >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
        >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
        >>> r = hybridsub.refine(F, levels=1)
        >>> X = r.apply(V) + 0.01 * np.arange(r.n_vertices)[:, None]
        >>> coarse, details = r.decompose(X)
        >>> bool(np.abs(r.reconstruct(coarse, details) - X).max() < 1e-12)
        True
        """
        from .._fit.multires import reconstruct
        return reconstruct(self.steps, self.n_coarse, coarse, details, self._cache)


def _output_buffer(out, shape: tuple, work) -> np.ndarray:
    """``out`` of :meth:`Refinement.apply` as the (rows, k) array the last product writes."""
    if not isinstance(out, np.ndarray) or out.dtype != np.float64 or not out.flags.c_contiguous \
            or not out.flags.writeable:
        raise TypeError("out must be a writeable C-contiguous float64 numpy array")
    if out.shape != shape:
        raise ValueError(f"out must have shape {shape}, got {out.shape}")
    if work != np.float64:
        raise TypeError("out is for real data; complex data needs a new array (call apply without out)")
    return out.reshape(shape[0], -1)


def refine(F: ArrayLike, sharp_edges: ArrayLike | None = None, levels: int = 1, *, n_vertices: int | None = None,
           scheme: Scheme = "hybrid", sharpness: ArrayLike | None = None, sharp_faces: ArrayLike | None = None,
           corners: ArrayLike | None = None, loop_weights: LoopWeights = "loop",
           non_manifold: NonManifold = "raise", max_memory: MemoryLimit = None, uv_faces: ArrayLike | None = None,
           n_uvs: int | None = None, uv_mode: UVMode = "linear", progress: bool | None = False,
           corner_sharpness: ArrayLike | None = None, boundary: Boundary = "edge_only",
           holes: ArrayLike | None = None, uv_interpolation: str | None = None) -> Refinement:
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
    corner_sharpness : (c,) array_like of float, optional
        Sharpness of each of ``corners`` (default ``inf``): a corner of sharpness s stays a
        corner for ⌊s⌋ levels and blends into its smooth or crease rule at the level where
        it decays (OpenSubdiv's vertex sharpness); ``>= 10`` is infinite, ``0`` no corner.
    boundary : {"edge_only", "edge_and_corner", "none"}
        OpenSubdiv's boundary interpolation: ``"edge_only"`` (default) the boundary is a
        crease; ``"edge_and_corner"`` also makes each boundary vertex in only one face a
        corner; ``"none"`` refines as ``"edge_only"`` but leaves the faces descending from
        input faces with a vertex on the boundary out of ``faces`` (OpenSubdiv's holes; the
        vertices and matrices keep them). See ``docs/scheme.md``.
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
    progress : bool or None
        Show a progress bar per level (tqdm: a line on stderr, a widget in a notebook); None:
        only where stderr is a terminal.
    holes : (m,) bool mask or array_like of int, optional
        Faces that are not rendered but still shape their neighbours (OpenSubdiv's face holes,
        OBJ's ``t hole``): the matrices are those without holes, and the faces descending from
        a hole (through ``face_parent``) are left out of ``faces``. Every vertex is kept, also
        one only holes use (as OpenSubdiv does). See ``docs/usage.md``.

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
    inp = open_gate(F, sharp_edges, levels, n_vertices=n_vertices, scheme=scheme, sharpness=sharpness,
                    sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights, non_manifold=non_manifold,
                    max_memory=max_memory, uv_faces=uv_faces, n_uvs=n_uvs, uv_mode=uv_mode,
                    corner_sharpness=corner_sharpness, boundary=boundary, holes=holes,
                    uv_interpolation=uv_interpolation)
    return without_holes(refinement_of(inp, progress), inp.hole)


def level_holes(steps, hole: np.ndarray) -> list[np.ndarray]:
    """The hole mask of every level, input first: a face is a hole when the face that emitted
    it (``face_parent``) is one."""
    out = [hole]
    for st in steps:
        out.append(out[-1][st.face_parent])
    return out


def kept_faces(sharp_faces: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """A sharp-face mask or index list of a level, for the faces ``keep`` leaves (indices
    renumbered in the kept faces' order)."""
    sharp_faces = np.asarray(sharp_faces)
    if sharp_faces.dtype == bool:
        return sharp_faces[keep]
    new = np.cumsum(keep) - 1
    return new[sharp_faces[keep[sharp_faces]]].astype(np.int64)


def without_holes(r: Refinement, hole: np.ndarray | None) -> Refinement:
    """``r`` with the faces descending from a hole left out of ``faces``, ``face_parent``,
    ``sharp_faces``, ``face_level`` and the UV faces; every step gets its level's ``holes``
    mask and keeps its whole level. Vertices, matrices and tags are unchanged."""
    if hole is None:
        return r
    masks = level_holes(r.steps, hole)
    steps = [dataclasses.replace(st, holes=h) for st, h in zip(r.steps, masks[1:])]
    keep = ~masks[-1]
    uv = r.uv_refinement
    if uv is not None:
        uv = dataclasses.replace(uv, faces=uv.faces[keep], face_parent=uv.face_parent[keep],
                                 sharp_faces=kept_faces(uv.sharp_faces, keep), _cache={})
    return dataclasses.replace(r, faces=r.faces[keep], face_parent=r.face_parent[keep],
                               sharp_faces=kept_faces(r.sharp_faces, keep), steps=steps, uv_refinement=uv,
                               face_level=None if r.face_level is None else r.face_level[keep], _cache={})


def _level_corners(inp: RefineInput, k: int) -> tuple[np.ndarray, np.ndarray | None]:
    """The corners still sharp at level ``k`` and, with semi-sharp ones, their sharpness left."""
    if inp.corner_sharpness is None:
        return np.flatnonzero(inp.corner), None
    left = inp.corner_sharpness - k  # inf stays inf
    c = np.flatnonzero(left > 0)
    return c, left[c]


def refinement_of(inp: RefineInput, progress: bool | None = False) -> Refinement:
    """The :class:`Refinement` of a checked input: every step's matrix, faces and tags."""
    if inp.n_faces == 0:  # nothing to refine: every level is the input
        return _compose_cut(inp, _unrefined(inp))
    budget = Budget(inp.levels, inp.scheme, inp.max_memory)
    uv_corners = np.flatnonzero(inp.uv.corner) if inp.uv is not None else None
    steps, uv_steps = [], []
    face_parent = np.arange(inp.n_faces, dtype=np.int64)
    pairs, sharp, mask = inp.sharp_edges, inp.sharpness, inp.faces_out(inp.face_sharp)
    uv_pairs, uv_sharp = np.empty((0, 2), np.int64), np.empty(0)
    corner_left = None
    for s in walk(inp, budget, progress=progress):
        corners, corner_left = _level_corners(inp, s.step)
        parent = face_parents(s.offsets)
        face_parent = face_parent[parent]
        pairs, sharp = child_creases(s.level, s.plan)
        mask = inp.faces_out(s.child.face_sharp)
        uv_faces = uv_matrix = None
        if s.uv is not None:
            uv_faces, uv_matrix = s.uv.faces, _uv_step_matrix(inp, s)
            uv_pairs, uv_sharp = child_creases(s.uv.level, s.uv.plan)
            uv_steps.append(RefinementStep(uv_faces, uv_matrix, uv_pairs, uv_sharp, mask, uv_corners, parent))
        steps.append(RefinementStep(s.faces, step_matrix(s.level, s.plan), pairs, sharp, mask, corners, parent,
                                    uv_faces, uv_matrix, s.level.far_apart))
    uv = None
    if inp.uv is not None:
        uv_faces = uv_steps[-1].faces if uv_steps else inp.uv.faces.copy()
        uv = Refinement(uv_faces, uv_pairs, uv_sharp, mask, uv_corners, face_parent.copy(), uv_steps,
                        inp.uv.n_uvs, inp.max_memory)
    faces = steps[-1].faces if steps else inp.faces.copy()
    if not steps:
        corners, corner_left = _level_corners(inp, 0)
    r = Refinement(faces, pairs, sharp, mask, corners, face_parent, steps, inp.n_vertices, inp.max_memory, uv,
                   coarse_faces=inp.faces if inp.cut is None else None, corner_sharpness=corner_left)
    return _compose_cut(inp, r)


def _uv_step_matrix(inp: RefineInput, s: Step) -> sp.csr_matrix:
    """The UV matrix of one step: the scheme's (``"smooth"``) or linear interpolation."""
    if inp.uv.mode != "all":
        return step_matrix(s.uv.level, s.uv.plan)
    return linear_uv_matrix(s.uv.level, s.uv.plan)


def _unrefined(inp: RefineInput) -> Refinement:
    """No faces: every level is the input (and with UVs, the UV index mesh likewise)."""
    n, levels = inp.n_vertices, inp.levels
    ident = np.arange(inp.n_faces, dtype=np.int64)
    mask = inp.faces_out(inp.face_sharp)
    corners = np.flatnonzero(inp.corner)
    uv = uv_faces = None
    if inp.uv is not None:
        uv_faces, t = inp.uv.faces, inp.uv.n_uvs
        no_pairs, no_sharp, no_corners = np.empty((0, 2), np.int64), np.empty(0), np.empty(0, np.int64)
        uv_steps = [RefinementStep(uv_faces.copy(), sp.identity(t, format="csr"), no_pairs, no_sharp, mask,
                                   no_corners, ident) for _ in range(levels)]
        uv = Refinement(uv_faces.copy(), no_pairs, no_sharp, mask, no_corners, ident.copy(), uv_steps, t,
                        inp.max_memory)
    steps = [RefinementStep(inp.faces.copy(), sp.identity(n, format="csr"), inp.sharp_edges, inp.sharpness, mask,
                            corners, ident, None if uv is None else uv_faces.copy(),
                            None if uv is None else sp.identity(inp.uv.n_uvs, format="csr"))
             for _ in range(levels)]
    faces = steps[-1].faces if steps else inp.faces.copy()
    return Refinement(faces, inp.sharp_edges, inp.sharpness, mask, corners, ident, steps, n, inp.max_memory, uv,
                      coarse_faces=inp.faces if inp.cut is None else None)


def _compose_cut(inp: RefineInput, r: Refinement) -> Refinement:
    """With ``non_manifold="cut"``: the cut copy's refinement, taking the caller's vertices.

    The first step's matrix is composed with the duplication ``D`` (``D[c, v] = 1`` when
    ``c`` is a copy of ``v``); without steps, the caller's mesh and tags come back as given.
    """
    if inp.cut is None:
        return r
    given = inp.uncut
    if not r.steps:
        return dataclasses.replace(r, faces=given.faces.copy(), sharp_edges=given.sharp_edges,
                                   sharpness=given.sharpness, corners=np.flatnonzero(given.corner),
                                   n_coarse=given.n_vertices, _cache={})
    n_cut = inp.n_vertices
    D = sp.csr_matrix((np.ones(n_cut), inp.cut.origin, np.arange(n_cut + 1)), shape=(n_cut, given.n_vertices))
    first = r.steps[0]
    S = sp.csr_matrix(first.matrix @ D)
    S.sum_duplicates()
    S.sort_indices()
    steps = [dataclasses.replace(first, matrix=S)] + list(r.steps[1:])
    return dataclasses.replace(r, steps=steps, n_coarse=given.n_vertices, _cache={})
