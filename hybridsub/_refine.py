"""Refinement: the step loop, and the objects that hold its results.

A :class:`Refinement` is what ``refine`` returns: connectivity, tags and refinement
matrices, computed from topology and tags alone. Its :meth:`Refinement.apply` refines any
per-vertex data with them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from . import _validate as val
from ._errors import MeshError
from ._stencils import step_matrix
from ._topology import build_level, child_creases, child_faces, plan_step


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
    """

    faces: np.ndarray
    matrix: sp.csr_matrix
    sharp_edges: np.ndarray
    sharpness: np.ndarray
    sharp_faces: np.ndarray
    corners: np.ndarray
    face_parent: np.ndarray

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

    @property
    def n_vertices(self) -> int:
        return self.steps[-1].n_vertices if self.steps else self.n_coarse

    @property
    def matrix(self) -> sp.csr_matrix:
        """Composite refinement matrix ``S_L ⋯ S_1`` (n_fine × n_coarse), computed once."""
        if "matrix" not in self._cache:
            S = sp.identity(self.n_coarse, format="csr", dtype=np.float64)
            for st in self.steps:
                S = st.matrix @ S
            S = sp.csr_matrix(S)
            S.sort_indices()
            self._cache["matrix"] = S
        return self._cache["matrix"]

    def apply(self, X) -> np.ndarray:
        """Refine per-vertex data: positions, UVs, colours, any (n_coarse, ...) array.

        Floating-point data keeps its dtype (computed in float64); other data comes back as
        float64. The step matrices are applied one after the other, which is cheaper than the
        composite when the matrix has not been formed.

        Examples
        --------
        >>> import numpy as np, hybridsub
        >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]]); F = np.array([[0, 1, 2]])
        >>> r = hybridsub.refine(F, levels=1)
        >>> r.apply(V).shape
        (7, 3)
        """
        A = np.asarray(X)
        if A.ndim == 0 or A.shape[0] != self.n_coarse:
            raise MeshError(f"data must have one row per coarse vertex ({self.n_coarse}), got shape {A.shape}")
        out_dtype = A.dtype if np.issubdtype(A.dtype, np.floating) else np.float64
        Y = np.asarray(A, dtype=np.float64).reshape(self.n_coarse, -1)
        if "matrix" in self._cache:
            Y = self._cache["matrix"] @ Y
        else:
            for st in self.steps:
                Y = st.matrix @ Y
        return np.ascontiguousarray(Y.reshape((Y.shape[0],) + A.shape[1:]), dtype=out_dtype)


def refine(F, sharp_edges=None, levels=1, *, n_vertices=None, scheme="hybrid", sharpness=None,
           sharp_faces=None, corners=None, loop_weights="loop") -> Refinement:
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
        infinite, ``<= 0`` no crease).
    sharp_faces : (m,) bool mask or array_like of int, optional
        Faces refined by Loop's 1-to-4 split (``"hybrid"``).
    corners : array_like of int, optional
        Vertices that never move.
    loop_weights : {"loop", "warren"}
        Smooth vertex weights in Loop regions.

    Returns
    -------
    Refinement
        ``faces``, ``matrix``, tags, ``face_parent``, ``steps`` and ``apply``.

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])   # tetrahedron
    >>> r = hybridsub.refine(F, levels=2, scheme="sqrt3")
    >>> r.faces.shape, r.matrix.shape
    ((36, 3), (20, 4))
    """
    levels = val.check_options(scheme, levels, loop_weights)
    Fi, n = val.as_faces(F, n_vertices)
    m = len(Fi)
    pairs, sharp = val.as_sharp_edges(sharp_edges, sharpness, n)
    face_sharp, faces_as_indices = val.as_face_mask(sharp_faces, m)
    corner = val.as_corner_mask(corners, n)
    if scheme == "sqrt3" and (len(pairs) or face_sharp.any() or corner.any()):
        raise ValueError(
            'scheme="sqrt3" is Kobbelt\'s √3 without feature tags; to keep sharp edges, sharp faces or '
            'corners use scheme="hybrid" (√3 on smooth faces, Loop on sharp ones)'
        )
    if scheme == "loop":
        face_sharp[:] = True
    keep = sharp > 0
    pairs, sharp = pairs[keep], sharp[keep]

    def faces_out(mask):
        return np.flatnonzero(mask) if faces_as_indices else mask

    corners_out = np.flatnonzero(corner)
    steps = []
    face_parent = np.arange(m, dtype=np.int64)
    faces = Fi
    if levels > 0 and m:
        level = build_level(Fi, n)
        for step in range(1, levels + 1):
            tagged = np.zeros(level.n_edges)
            if len(pairs):
                eid = level.find_edges(pairs)
                if step == 1 and (eid < 0).any():
                    j = int(np.flatnonzero(eid < 0)[0])
                    raise MeshError(f"sharp edge {j} = {pairs[j].tolist()} is not an edge of the mesh")
                np.maximum.at(tagged, eid, sharp)
            plan = plan_step(level, tagged, face_sharp, corner, scheme, step, loop_weights)
            S = step_matrix(level, plan)
            faces, parent = child_faces(level, plan)
            pairs, sharp = child_creases(level, plan, tagged)
            face_sharp = plan.face_sharp[parent]
            corner = np.concatenate([corner, np.zeros(plan.n_new - len(corner), dtype=bool)])
            face_parent = face_parent[parent]
            steps.append(RefinementStep(faces, S, pairs, sharp, faces_out(face_sharp), corners_out, parent))
            if step < levels:
                level = build_level(faces, plan.n_new)
    elif levels > 0:  # no faces: nothing to refine, every level is the input
        for _ in range(levels):
            steps.append(RefinementStep(Fi.copy(), sp.identity(n, format="csr"), pairs, sharp,
                                        faces_out(face_sharp), corners_out, np.arange(m, dtype=np.int64)))
    return Refinement(faces if steps else Fi.copy(), pairs, sharp, faces_out(face_sharp), corners_out,
                      face_parent, steps, n)


def subdivide(V, F, sharp_edges=None, levels=1, *, scheme="hybrid", sharpness=None, sharp_faces=None,
              corners=None, loop_weights="loop", return_matrix=False, feature_angle=None):
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
        Sharpness per crease (semi-sharp creases); default infinitely sharp.
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

    Returns
    -------
    V2 : (n', 3) ndarray
        Refined positions, in the dtype of ``V`` if it is floating-point, else float64.
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
    A = np.asarray(V)
    Vf = val.as_vertices(A)
    if feature_angle is not None:  # automatic features (docs/features.md)
        from ._features import merge_detected
        sharp_edges, sharpness, corners = merge_detected(Vf, F, feature_angle, sharp_edges, sharpness, corners)
    r = refine(F, sharp_edges, levels, n_vertices=len(Vf), scheme=scheme, sharpness=sharpness,
               sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights)
    out_dtype = A.dtype if np.issubdtype(A.dtype, np.floating) else np.float64
    V2 = r.apply(Vf).astype(out_dtype, copy=False)
    if return_matrix:
        return V2, r.faces, r.matrix
    return V2, r.faces
