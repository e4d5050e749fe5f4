"""The input gate: one call's mesh, tags and options, checked once and frozen.

Every public entry point that refines (``refine``, ``subdivide``, the face-varying functions,
the limit functions, the command line through them) passes its arguments through
:func:`open_gate` and hands the resulting :class:`RefineInput` down; nothing below
re-validates what the gate checked. The gate converts arrays into fresh ones (the caller's are
never written to), merges detected features into the tags, cuts a non-manifold mesh when asked
to, and builds the checked, tagged level 0 (errors name the face, edge or index at fault).

>>> import numpy as np
>>> inp = open_gate([[0, 1, 2], [0, 2, 3]], levels=2, sharp_edges=[[0, 2]])
>>> inp.levels, inp.n_vertices, inp.sharp_edges.tolist(), inp.level.n_edges
(2, 4, [[0, 2]], 5)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._topology import Cut, Level, checked_level, cut_non_manifold, duplicate_faces_error, map_sharp_edges, uv_start
from . import arrays as val
from .features import Features, check_angle, features_of_level, merge_detected


@dataclass(frozen=True, eq=False)
class UVInput:
    """Face-varying data of a call: UV faces aligned row by row with the faces, and the UV
    index mesh of level 0 (:func:`hybridsub._topology.uv.uv_start`)."""

    faces: np.ndarray  # (m, 3) int64 UV index of each face corner
    n_uvs: int
    mode: str  # one of arrays.UV_INTERPOLATIONS ("all": linear, "none": smooth)
    level: Level | None = None  # the UV index mesh (None until the geometry's level exists)
    corner: np.ndarray | None = None  # (t,) bool: UV indices kept as corners


@dataclass(frozen=True, eq=False)
class Uncut:
    """The caller's mesh and tags, where ``non_manifold="cut"`` refines a cut copy of it."""

    faces: np.ndarray
    n_vertices: int
    sharp_edges: np.ndarray
    sharpness: np.ndarray
    corner: np.ndarray


@dataclass(frozen=True, eq=False)
class RefineInput:
    """A checked description of one refinement: what the step loop refines.

    ``faces``, ``n_vertices``, the tags and ``level`` describe the mesh refined: the caller's,
    or with ``cut`` its cut copy (``uncut`` then keeps the caller's). ``sharp_edges`` holds
    creases with sharpness > 0 only (normalised: ``inf`` for infinitely sharp);
    ``face_sharp`` is all True for ``"loop"``.
    """

    faces: np.ndarray  # (m, 3) int64
    n_vertices: int
    levels: int
    scheme: str
    loop_weights: str
    sharp_edges: np.ndarray  # (k, 2) int64
    sharpness: np.ndarray  # (k,) float64, > 0
    face_sharp: np.ndarray  # (m,) bool
    corner: np.ndarray  # (n,) bool
    faces_as_indices: bool  # the caller gave sharp faces as indices (results give them back so)
    level: Level  # level 0: checked and tagged
    max_memory: object
    uv: UVInput | None = None
    cut: Cut | None = None
    uncut: Uncut | None = None
    # (n,) float64 sharpness of every vertex (inf: a corner, 0: none) where some corner is
    # semi-sharp, else None (``corner`` then says it all); ``corner`` is ``corner_sharpness > 0``
    corner_sharpness: np.ndarray | None = None
    boundary: str = "edge_only"  # VtxBoundaryInterpolation; "edge_and_corner" is in ``corner`` already
    # (m,) bool: faces not rendered — the caller's holes and, with ``boundary="none"``, the faces
    # at the boundary (None: none)
    hole: np.ndarray | None = None

    @property
    def n_faces(self) -> int:
        return self.faces.shape[0]

    @property
    def n_coarse(self) -> int:
        """Vertices of the caller's mesh (those of the cut copy's refinement matrices' columns)."""
        return self.uncut.n_vertices if self.uncut is not None else self.n_vertices

    def faces_out(self, mask: np.ndarray) -> np.ndarray:
        """A sharp-face mask in the form the caller gave sharp faces (mask or indices)."""
        return np.flatnonzero(mask) if self.faces_as_indices else mask


_SQRT3_TAGS = ('scheme="sqrt3" is Kobbelt\'s √3 without feature tags; to keep sharp edges, sharp faces or '
               'corners use scheme="hybrid" (√3 on smooth faces, Loop on sharp ones)')
_SQRT3_UV = ('scheme="sqrt3" cannot honour UV seams (Kobbelt\'s √3 flips every edge, and a flip across a seam '
             'makes a triangle spanning two UV charts); use scheme="hybrid" (√3 with seams split) or "loop"')


def open_gate(F, sharp_edges=None, levels=1, *, n_vertices=None, scheme="hybrid", sharpness=None,
              sharp_faces=None, corners=None, loop_weights="loop", non_manifold="raise", max_memory=None,
              uv_faces=None, n_uvs=None, uv_mode="linear", uv_name="uv_faces", positions=None,
              feature_angle=None, corner_sharpness=None, boundary="edge_only", holes=None,
              uv_interpolation=None) -> RefineInput:
    """Check one refinement's arguments (those of :func:`hybridsub.refine`) and describe it.

    ``positions`` ((n, 3) float64, already checked) and ``feature_angle`` add the features
    :func:`hybridsub.detect_features` finds to the tags; ``uv_name`` is the name errors give
    the UV faces. ``corner_sharpness`` gives the corners' sharpness (semi-sharp corners decay by
    one a level); ``boundary`` is OpenSubdiv's boundary interpolation (``docs/scheme.md``);
    ``holes`` (a face mask or indices) the faces whose descendants the results leave out (the
    refinement itself is unchanged); ``uv_interpolation`` one of OpenSubdiv's six face-varying
    modes (``docs/face_varying.md``; ``uv_mode``'s "linear" and "smooth" are "all" and "none").
    Raises ``MeshError``, ``TypeError`` or ``ValueError`` naming the problem.
    """
    levels = val.check_options(scheme, levels, loop_weights)
    if uv_faces is None and n_uvs is not None:
        raise ValueError("n_uvs was given without uv_faces")
    cut_asked = val.check_non_manifold(non_manifold) == "cut"
    if uv_faces is not None and scheme == "sqrt3":
        raise ValueError(_SQRT3_UV)
    uv_mode = val.check_uv_interpolation(uv_interpolation, uv_mode)
    Fi, n = val.as_faces(F, n_vertices)
    uv = None
    if uv_faces is not None:
        n_uvs = val.count(n_uvs, "n_uvs") if n_uvs is not None else None
        T = val.as_uv_faces(uv_faces, len(Fi), n_uvs, uv_name)
        uv = UVInput(T, n_uvs if n_uvs is not None else (int(T.max()) + 1 if T.size else 0), uv_mode)
    pairs, sharp = val.as_sharp_edges(sharp_edges, sharpness, n)
    face_sharp, faces_as_indices = val.as_face_mask(sharp_faces, len(Fi))
    corner, vsharp = val.as_corner_sharpness(corners, corner_sharpness, n)
    boundary = val.check_boundary(boundary)
    hole = val.as_hole_mask(holes, len(Fi))  # the cut keeps the faces and their order
    level = None
    if feature_angle is not None:  # on the input's level, which then serves the refinement too
        angle = check_angle("feature_angle", feature_angle)
        if cut_asked:
            feat, level = _features_after_cut(positions, Fi, n, pairs, sharp, angle)
        else:
            level = checked_level(Fi, n, pairs)
            feat = features_of_level(positions, level, angle)
        pairs, sharp, corner = merge_detected(feat, pairs, sharp, corner, n)
        if vsharp is not None:  # detected corners are infinitely sharp
            vsharp = np.where(corner & (vsharp == 0), np.inf, vsharp)
    if scheme == "sqrt3" and (len(pairs) or face_sharp.any() or corner.any()):
        raise ValueError(_SQRT3_TAGS)
    if scheme == "loop":
        face_sharp[:] = True
    common = dict(levels=levels, scheme=scheme, loop_weights=loop_weights, face_sharp=face_sharp,
                  faces_as_indices=faces_as_indices, max_memory=max_memory, boundary=boundary)
    cut = _cut(Fi, n, pairs, sharp) if cut_asked else None
    if cut is None:
        keep = sharp > 0
        if level is None:
            level = checked_level(Fi, n, pairs)
        level = level.tag(pairs[keep], sharp[keep], face_sharp)
        corner, vsharp, holes = _boundary_tags(level, boundary, corner, vsharp)
        return RefineInput(Fi, n, sharp_edges=pairs[keep], sharpness=sharp[keep], corner=corner, level=level,
                           uv=_with_uv_level(uv, level, corner), corner_sharpness=vsharp, hole=_holes(hole, holes), **common)
    cpairs, csharp = map_sharp_edges(cut, Fi, pairs, sharp, n)
    ccorner = corner[cut.origin]
    if scheme != "sqrt3":  # sqrt3 takes no tags: its pieces follow Kobbelt's boundary rule
        ccorner = ccorner | cut.corner
    keep, kept = csharp > 0, sharp > 0
    level = checked_level(cut.faces, cut.n_vertices, cpairs).tag(cpairs[keep], csharp[keep], face_sharp)
    cvsharp = None if vsharp is None else np.where(ccorner & (vsharp[cut.origin] == 0), np.inf, vsharp[cut.origin])
    ccorner, cvsharp, holes = _boundary_tags(level, boundary, ccorner, cvsharp)
    return RefineInput(cut.faces, cut.n_vertices, sharp_edges=cpairs[keep], sharpness=csharp[keep],
                       corner=ccorner, level=level, uv=_with_uv_level(uv, level, ccorner), cut=cut,
                       uncut=Uncut(Fi, n, pairs[kept], sharp[kept], corner), corner_sharpness=cvsharp,
                       hole=_holes(hole, holes), **common)


def _holes(asked: np.ndarray | None, at_boundary: np.ndarray | None) -> np.ndarray | None:
    """The faces not rendered: the caller's holes and those ``boundary="none"`` makes."""
    if at_boundary is None:
        return asked
    return at_boundary if asked is None else asked | at_boundary


def _boundary_tags(level: Level, boundary: str, corner: np.ndarray, vsharp: np.ndarray | None):
    """OpenSubdiv's boundary interpolation on level 0: (corner, corner sharpness, hole faces).

    ``"edge_and_corner"``: a boundary vertex in one face only becomes an infinitely sharp
    corner; ``"none"``: the refinement is ``"edge_only"``'s, and the faces with a vertex on
    the boundary are holes (left out of the output faces, as OpenSubdiv tags them).
    """
    if boundary == "edge_only" or level.n_faces == 0:
        return corner, vsharp, None
    on_boundary = np.zeros(level.n_vertices, dtype=bool)
    open_h = np.flatnonzero(level.twin < 0)
    on_boundary[level.faces.reshape(-1)[open_h]] = True
    if boundary == "none":
        return corner, vsharp, on_boundary[level.faces].any(axis=1)
    lone = on_boundary & (np.bincount(level.faces.reshape(-1), minlength=level.n_vertices) == 1)
    if not lone.any():
        return corner, vsharp, None
    corner = corner | lone
    if vsharp is not None:
        vsharp = np.where(lone, np.inf, vsharp)
    return corner, vsharp, None


def _with_uv_level(uv: UVInput | None, level: Level, corner: np.ndarray) -> UVInput | None:
    if uv is None or level.n_faces == 0:
        return uv
    uvl, uv_corner = uv_start(level, uv.faces, uv.n_uvs, corner, uv.mode)
    return UVInput(uv.faces, uv.n_uvs, uv.mode, uvl, uv_corner)


def _features_after_cut(V, Fi, n, pairs, sharp, angle) -> tuple[Features, Level | None]:
    """``feature_angle=`` under ``non_manifold="cut"``: features found on the cut mesh (each
    copy at its vertex's position), as input vertex indices, since the input itself may have no
    consistent orientation to measure angles by; and the input's level when nothing is cut."""
    cut = _cut(Fi, n, pairs, sharp)
    if cut is None:
        level = checked_level(Fi, n, pairs)
        return features_of_level(V, level, angle), level
    o = cut.origin
    f = features_of_level(V[o], checked_level(cut.faces, cut.n_vertices), angle)
    return Features(o[f.sharp_edges], o[f.boundary_edges], np.unique(o[f.corners])), None


def _cut(Fi: np.ndarray, n: int, pairs: np.ndarray, sharp: np.ndarray) -> Cut | None:
    """The non-manifold cut of ``Fi``, or None when there is nothing to cut."""
    dup = duplicate_faces_error(Fi)
    if dup is not None:
        raise dup
    creased = np.zeros(n, dtype=bool)
    creased[pairs[sharp > 0].ravel()] = True
    return cut_non_manifold(Fi, n, creased)
