"""The input of a limit evaluation: the mesh checked, refined to the level evaluated, and its
tags there per face and vertex (:class:`LimitInput`); with its halfedge level and per-edge
sharpness built (:class:`LimitSetup`) for the general path, over all its faces or only some.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .._input import RefineInput, open_gate
from .._topology import Level, build_level
from .._refiner import refinement_of, walk_to
from .._refiner.refinement import _level_corners, level_holes
from ._vertex_kernels import compact_faces
from .mask_plan import edge_sharpness


def kept_faces(refinement, hole: np.ndarray | None, levels: int) -> np.ndarray | slice:
    """The faces of level ``levels`` of ``refinement`` not descending from a ``hole`` face
    (a mask, or every face)."""
    if hole is None:
        return slice(None)
    return ~level_holes(refinement.steps[:levels], hole)[-1]


@dataclass(frozen=True, eq=False)
class LimitInput:
    """A mesh and its tags, refined to the level its limit is evaluated at (no halfedges yet)."""

    faces: np.ndarray  # (m, 3) int64 faces of the level evaluated
    n_vertices: int
    face_sharp: np.ndarray  # (m,) sharp (Loop) faces; all of them for "loop"
    corner: np.ndarray  # (n,) tagged corners: a mask, or each vertex's sharpness left (float64, local corners)
    pairs: np.ndarray  # (k, 2) tagged edges of the level evaluated
    sharpness: np.ndarray  # (k,)
    n_keep: int  # vertices of the requested level
    same_level: bool  # evaluated at the requested level (else one finer: Kobbelt's parity)
    scheme: str
    out_faces: np.ndarray  # (m_L, 3) the faces of the requested level not descending from a hole
    X: np.ndarray | None = None  # (n, d) the positions at the level evaluated, if refined with them
    refinement: object = None  # the Refinement to the level evaluated, if made
    hole: np.ndarray | None = None  # (m0,) the input's holes (None: none)


@dataclass(frozen=True, eq=False)
class LimitSetup:
    """A mesh and its tags, refined to the level the limit is evaluated at, with its halfedges."""

    level: Level | None  # the level evaluated (None: no faces)
    tagged: np.ndarray
    esharp: np.ndarray
    face_sharp: np.ndarray
    corner: np.ndarray
    refinement: object  # the Refinement to the evaluated level
    n_keep: int  # vertices of the requested level
    same_level: bool  # evaluated at the requested level (else one finer: Kobbelt's parity)
    hole: np.ndarray | None = None  # (m,) the input's holes (None: none)

    def kept_faces(self, levels: int) -> np.ndarray | slice:
        """The faces of level ``levels`` not descending from a hole (a mask, or all)."""
        return kept_faces(self.refinement, self.hole, levels)


def _checked(F, sharp_edges, levels, n_vertices, scheme, sharpness, sharp_faces, corners, loop_weights, positions,
             feature_angle, corner_sharpness, boundary, holes, local_corners) -> tuple[RefineInput, int]:
    """The gate's input, and the level the limit is evaluated at.

    With ``local_corners`` (limit positions and matrices) a semi-sharp corner keeps its
    sharpness left at the level evaluated (``corner`` is then vertex sharpness): its star
    alone is refined until the sharpness is spent (:func:`.local.refine_locally`). Without
    (normals, tangents) the whole mesh is refined uniformly until every sharpness is spent
    (⌈s⌉ levels), so the masks of the level evaluated see none (the old vertices keep their
    indices). Kobbelt's boundary rule alternates: √3 is evaluated where the next step is odd.
    """
    inp = open_gate(F, sharp_edges, levels, n_vertices=n_vertices, scheme=scheme, sharpness=sharpness,
                    sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights, positions=positions,
                    feature_angle=feature_angle, corner_sharpness=corner_sharpness, boundary=boundary, holes=holes)
    l_eval = inp.levels
    if inp.corner_sharpness is not None and not local_corners:
        finite = inp.corner_sharpness[np.isfinite(inp.corner_sharpness)]
        l_eval = max(l_eval, int(np.ceil(finite.max(initial=0.0))))
    l_eval += 1 if scheme == "sqrt3" and l_eval % 2 else 0
    return inp, l_eval


def _face_mask(sharp_faces, m: int, scheme: str) -> np.ndarray:
    fsh = np.asarray(sharp_faces)
    face_sharp = np.zeros(m, dtype=bool)
    if fsh.dtype == bool:
        face_sharp[:] = fsh
    else:
        face_sharp[fsh] = True
    if scheme == "loop":
        face_sharp[:] = True
    return face_sharp


def _corner_mask(inp: RefineInput, l_eval: int, n: int, local_corners: bool) -> np.ndarray:
    """The corners of the level evaluated: a mask, or with ``local_corners`` and semi-sharp
    corners each vertex's sharpness left (float64: inf a corner, 0 none)."""
    at, left = _level_corners(inp, l_eval)
    if local_corners and inp.corner_sharpness is not None:
        corner = np.zeros(n)
        corner[at] = np.inf if left is None else left
        return corner
    corner = np.zeros(n, dtype=bool)
    corner[at] = True
    return corner


def refine_for_limit(F, sharp_edges, levels, n_vertices, scheme, sharpness, sharp_faces, corners, loop_weights,
                     positions=None, feature_angle=None, corner_sharpness=None, boundary="edge_only",
                     holes=None, local_corners=False) -> LimitInput:
    """Check the input and refine it to the level evaluated, as a :class:`Refinement`
    (``refinement``; see :class:`LimitInput`).

    >>> import numpy as np
    >>> li = refine_for_limit(np.array([[0, 1, 2]]), None, 1, None, "sqrt3", None, None, None, "loop")
    >>> li.same_level, li.n_keep, li.n_vertices                  # √3 is evaluated at even levels
    (False, 4, 10)
    """
    inp, l_eval = _checked(F, sharp_edges, levels, n_vertices, scheme, sharpness, sharp_faces, corners, loop_weights,
                           positions, feature_angle, corner_sharpness, boundary, holes, local_corners)
    levels = inp.levels
    r = refinement_of(dataclasses.replace(inp, levels=l_eval))
    faces = np.ascontiguousarray(r.faces, dtype=np.int64)
    out = r.steps[levels - 1].faces if levels else inp.faces
    return LimitInput(faces, r.n_vertices, _face_mask(r.sharp_faces, len(faces), scheme),
                      _corner_mask(inp, l_eval, r.n_vertices, local_corners), np.asarray(r.sharp_edges, np.int64).reshape(-1, 2),
                      np.asarray(r.sharpness, np.float64), r.steps[levels - 1].n_vertices if levels else inp.n_vertices,
                      l_eval == levels, scheme, out[kept_faces(r, inp.hole, levels)], refinement=r, hole=inp.hole)


def walk_for_limit(V: np.ndarray, F, sharp_edges, levels, scheme, sharpness, sharp_faces, corners, loop_weights,
                   feature_angle=None, corner_sharpness=None, boundary="edge_only", holes=None,
                   local_corners=False) -> LimitInput:
    """Check the input and refine it with its positions ``V`` (n, 3) float64 to the level
    evaluated, no matrix formed (``X``; see :class:`LimitInput`).

    >>> import numpy as np
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> li = walk_for_limit(V, np.array([[0, 1, 2]]), None, 1, "sqrt3", None, None, None, "loop")
    >>> li.same_level, li.n_keep, li.X.shape, len(li.out_faces)
    (False, 4, (10, 3), 3)
    """
    inp, l_eval = _checked(F, sharp_edges, levels, len(V), scheme, sharpness, sharp_faces, corners, loop_weights, V,
                           feature_angle, corner_sharpness, boundary, holes, local_corners)
    levels = inp.levels
    w = walk_to(dataclasses.replace(inp, levels=l_eval), V, levels)
    out = w.kept_faces if w.kept_hole is None else w.kept_faces[~w.kept_hole]
    n = len(w.X)
    return LimitInput(np.ascontiguousarray(w.faces, dtype=np.int64), n, _face_mask(w.face_sharp, len(w.faces), scheme),
                      _corner_mask(inp, l_eval, n, local_corners), np.asarray(w.sharp_edges, np.int64).reshape(-1, 2),
                      np.asarray(w.sharpness, np.float64), w.kept_n_vertices, l_eval == levels, scheme, out, X=w.X,
                      hole=inp.hole)


def with_halfedges(li: LimitInput) -> LimitSetup:
    """``li`` with its halfedge level and per-edge sharpness."""
    if len(li.faces) == 0:
        return LimitSetup(None, None, None, li.face_sharp, li.corner, li.refinement, li.n_keep, li.same_level, li.hole)
    level = build_level(li.faces, li.n_vertices)
    tagged, esharp = edge_sharpness(level, li.pairs, li.sharpness, li.scheme)
    return LimitSetup(level, tagged, esharp, li.face_sharp, li.corner, li.refinement, li.n_keep, li.same_level,
                      li.hole)


def local_setup(li: LimitInput, faces: np.ndarray, degree: np.ndarray) -> tuple[LimitSetup, np.ndarray, np.ndarray]:
    """The faces ``faces`` (a mask) of ``li`` apart, as a setup of their own vertices.

    Returns the setup, the vertices it numbers 0, 1, … (their ids in ``li``) and the number
    of every vertex of ``li`` there (−1: not in it). ``degree`` (n,): the number of faces of
    each vertex in ``li``. The tags kept are those of edges with an end at a vertex all of
    whose faces are kept: the classification, masks and local refinement of exactly those
    vertices are the ones of the whole level, which is all the caller may use.
    """
    F, used, local = compact_faces(li.faces, faces, li.n_vertices)
    n = len(used)
    whole = np.bincount(F.ravel(), minlength=n) == degree[used]
    lp = local[li.pairs] if len(li.pairs) else np.zeros((0, 2), np.int64)
    keep = (lp >= 0).all(axis=1) & whole[np.maximum(lp, 0)].any(axis=1)
    level = build_level(F, n)
    tagged, esharp = edge_sharpness(level, lp[keep], li.sharpness[keep], li.scheme)
    setup = LimitSetup(level, tagged, esharp, li.face_sharp[faces], li.corner[used], li.refinement, n, True)
    return setup, used, local


def setup_limit(F, sharp_edges, levels, n_vertices, scheme, sharpness, sharp_faces, corners, loop_weights,
                positions=None, feature_angle=None, corner_sharpness=None, boundary="edge_only",
                holes=None, local_corners=False) -> LimitSetup:
    """:func:`refine_for_limit` with its halfedges over every face (see :class:`LimitSetup`).

    >>> import numpy as np
    >>> s = setup_limit(np.array([[0, 1, 2]]), None, 1, None, "sqrt3", None, None, None, "loop")
    >>> s.same_level, s.n_keep, s.level.n_vertices                 # √3 is evaluated at even levels
    (False, 4, 10)
    """
    return with_halfedges(refine_for_limit(F, sharp_edges, levels, n_vertices, scheme, sharpness, sharp_faces, corners,
                                           loop_weights, positions, feature_angle, corner_sharpness, boundary, holes,
                                           local_corners))
