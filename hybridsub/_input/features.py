"""Sharp-feature detection from geometry: creases by dihedral angle, corners; and the two rules
that merge tags from several places: :func:`merge_edges` (every source alike, the largest
sharpness wins: the command line's file tags, tag files and detected creases) and
:func:`merge_detected` (detected features added to a caller's tags, the caller's win:
``feature_angle=`` of the library)."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._topology import Level, checked_level
from . import arrays as val
from .arrays import count_of
from .._topology import edge_keys
from .._typing import ArrayLike


class Features(NamedTuple):
    """Features found on a mesh.

    Attributes
    ----------
    sharp_edges : (k, 2) int64
        Interior edges whose dihedral angle exceeds the threshold, in edge order (each
        edge once, in the orientation of its first face).
    boundary_edges : (b, 2) int64
        Boundary edges (creases in ``"hybrid"`` and ``"loop"`` anyway).
    corners : (c,) int64
        Sorted vertex indices: vertices with three or more sharp or boundary edges, and
        vertices where a crease line (two sharp or boundary edges) turns by more than
        ``corner_angle``.
    """

    sharp_edges: np.ndarray
    boundary_edges: np.ndarray
    corners: np.ndarray

    def __repr__(self) -> str:
        return (f"Features({count_of(len(self.sharp_edges), 'sharp edge')}, "
                f"{count_of(len(self.boundary_edges), 'boundary edge')}, {count_of(len(self.corners), 'corner')})")


def check_angle(name: str, a) -> float:
    """An angle option in degrees, checked: a number in [0, 180]."""
    try:
        a = float(a)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a number of degrees, got {a!r}") from None
    if not 0 <= a <= 180:
        raise ValueError(f"{name} must be in [0, 180] degrees, got {a}")
    return a


def detect_features(V: ArrayLike, F: ArrayLike, angle: float = 30.0, *,
                    corner_angle: float | None = 45.0) -> Features:
    """Find crease edges (dihedral angle above ``angle`` degrees) and corners.

    Parameters
    ----------
    V : (n, 3) array_like of float
        Vertex positions.
    F : (m, 3) array_like of int
        Triangles, consistently oriented, every edge in one or two faces.
    angle : float
        An interior edge is sharp when the angle between the normals of its two faces (its
        dihedral angle; 0 for a flat edge) exceeds this, in degrees.
    corner_angle : float or None
        A vertex on exactly two feature edges (sharp or boundary) is a corner when the crease
        line turns there by more than this, in degrees: the angle between the two edges'
        directions, 0 on a straight line. A crease that bends sharply is a corner, not a
        crease vertex (the crease rule would round it off). ``None``: no such corners.

    Returns
    -------
    Features
        ``sharp_edges``, ``boundary_edges``, ``corners``.

    Notes
    -----
    Degenerate faces (zero area) have no normal; their edges are not reported as creases.
    Vertices with three or more feature edges are corners whatever their angles (the
    scheme's own rule). The edges are those of the mesh as :func:`hybridsub.refine` sees
    them (the same halfedge tables), so they can be passed on as they are.

    Examples
    --------
    >>> import hybridsub
    >>> V, F = hybridsub.load_example()
    >>> feat = hybridsub.detect_features(V, F, angle=30)
    >>> len(feat.sharp_edges), len(feat.boundary_edges), len(feat.corners)
    (722, 0, 23)
    """
    Vf = val.as_vertices(V)
    Fi, n = val.as_faces(F, len(Vf))
    angle = check_angle("angle", angle)
    if corner_angle is not None:
        corner_angle = check_angle("corner_angle", corner_angle)
    return features_of_level(Vf, checked_level(Fi, n), angle, corner_angle)


def features_of_level(V: np.ndarray, level: Level, angle: float, corner_angle: float | None = 45.0) -> Features:
    """:func:`detect_features` on checked input: ``V`` (n, 3) float64 and the mesh's level
    (its faces, twins and edge numbering), angles in degrees already checked.

    Examples
    --------
    >>> import hybridsub
    >>> from hybridsub._topology import checked_level
    >>> V, F = hybridsub.load_example()
    >>> len(features_of_level(V, checked_level(F, len(V)), 30.0).sharp_edges)
    722
    """
    if level.n_faces == 0:
        empty = np.empty((0, 2), np.int64)
        return Features(empty, empty.copy(), np.empty(0, np.int64))
    Vf, Fi, n = V, level.faces, level.n_vertices
    ev = level.edge_vertices
    owner = level.edge_owner
    twin = level.twin[owner]
    interior = twin >= 0
    tri = Vf[Fi]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normal, axis=1)
    ok = length > 0
    normal = np.divide(normal, length[:, None], out=np.zeros_like(normal), where=ok[:, None])
    fa = owner[interior] // 3
    fb = twin[interior] // 3
    cos = np.einsum("ij,ij->i", normal[fa], normal[fb])
    sharp = np.zeros(len(ev), dtype=bool)
    sharp[interior] = (cos < np.cos(np.radians(angle))) & ok[fa] & ok[fb]
    feature = sharp | ~interior
    creases = ev[feature]
    count = np.bincount(creases.ravel(), minlength=n)
    corner = count >= 3
    if corner_angle is not None and len(creases):
        # Turning angle at vertices with exactly two feature edges: the angle between the
        # directions in and out, i.e. 180° minus the angle between the two edges at v.
        ends = creases.ravel()
        other = creases[:, ::-1].ravel()
        two = count[ends] == 2
        v, w = ends[two], other[two]
        d = Vf[w] - Vf[v]
        d = d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), np.finfo(float).tiny)
        order = np.argsort(v, kind="stable")
        v, d = v[order], d[order]  # each vertex twice, consecutive
        c = np.einsum("ij,ij->i", d[0::2], d[1::2])  # cos of the angle between the edges
        turn = 180.0 - np.degrees(np.arccos(np.clip(c, -1.0, 1.0)))
        corner[v[0::2][turn > corner_angle]] = True
    return Features(ev[sharp], ev[~interior], np.flatnonzero(corner))


def merge_detected(feat: Features, pairs: np.ndarray, sharpness: np.ndarray, corner: np.ndarray,
                   n_vertices: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Add detected features to checked tags (the caller's take precedence).

    Detected sharp edges that the caller already tagged (``pairs`` (k, 2) with ``sharpness``)
    keep the caller's sharpness; the others are infinitely sharp. Corners are the union (a new
    (n,) mask). Returns ``(pairs, sharpness, corner)``.

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> V, F = hybridsub.load_example()
    >>> feat = detect_features(V, F, 30)
    >>> pairs, s, corner = merge_detected(feat, feat.sharp_edges[:1], np.array([2.0]), np.zeros(len(V), bool), len(V))
    >>> len(pairs), s[:2].tolist(), int(corner.sum())
    (722, [2.0, inf], 23)
    """
    found = feat.sharp_edges
    if len(pairs):
        found = found[~np.isin(edge_keys(found[:, 0], found[:, 1], n_vertices),
                               edge_keys(pairs[:, 0], pairs[:, 1], n_vertices))]
    corner = corner.copy()
    corner[feat.corners] = True
    return (np.concatenate([pairs, found]), np.concatenate([sharpness, np.full(len(found), np.inf)]), corner)


def merge_edges(edges: np.ndarray, sharpness: np.ndarray, n_vertices: int) -> tuple[np.ndarray, np.ndarray]:
    """One entry per undirected edge of ``edges`` (k, 2), keeping its largest ``sharpness``, in
    the order of first appearance (either orientation counts as the same edge).

    Examples
    --------
    >>> import numpy as np
    >>> e, s = merge_edges(np.array([[0, 1], [2, 1], [1, 0]]), np.array([2.0, np.inf, 5.0]), 3)
    >>> e.tolist(), s.tolist()
    ([[0, 1], [2, 1]], [5.0, inf])
    """
    if not len(edges):
        return edges.reshape(0, 2).astype(np.int64), sharpness
    key = edge_keys(edges[:, 0], edges[:, 1], n_vertices)
    uniq, first, inv = np.unique(key, return_index=True, return_inverse=True)
    best = np.zeros(len(uniq))
    np.maximum.at(best, inv.ravel(), sharpness)
    order = np.argsort(first, kind="stable")
    return edges[first[order]].astype(np.int64), best[order]
