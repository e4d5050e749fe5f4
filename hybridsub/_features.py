"""Sharp-feature detection from geometry: creases by dihedral angle, corners."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import _validate as val
from ._topology import build_level


class Features(NamedTuple):
    """Features found on a mesh.

    Attributes
    ----------
    sharp_edges : (k, 2) int64
        Interior edges whose dihedral angle exceeds the threshold.
    boundary_edges : (b, 2) int64
        Boundary edges (creases in ``"hybrid"`` and ``"loop"`` anyway).
    corners : (c,) int64
        Vertices with three or more sharp or boundary edges.
    """

    sharp_edges: np.ndarray
    boundary_edges: np.ndarray
    corners: np.ndarray


def detect_features(V, F, angle: float = 30.0) -> Features:
    """Find crease edges (dihedral angle above ``angle`` degrees) and corners.

    The dihedral angle of an edge is the angle between the normals of its two faces
    (0 for a flat edge). Degenerate faces (zero area) have no normal; their edges are not
    reported as creases.

    Examples
    --------
    >>> import hybridsub
    >>> V, F = hybridsub.load_example()
    >>> feat = hybridsub.detect_features(V, F, angle=30)
    >>> len(feat.sharp_edges), len(feat.boundary_edges)
    (722, 0)
    """
    Vf = val.as_vertices(V)
    Fi, n = val.as_faces(F, len(Vf))
    if not 0 <= float(angle) <= 180:
        raise ValueError(f"angle must be in [0, 180] degrees, got {angle}")
    level = build_level(Fi, n)
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
    creases = ev[sharp | ~interior]
    count = np.bincount(creases.ravel(), minlength=n)
    return Features(ev[sharp], ev[~interior], np.flatnonzero(count >= 3))
