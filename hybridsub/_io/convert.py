"""Meshes of other libraries as :class:`TaggedMesh`: a ``trimesh.Trimesh`` (its tags in
``metadata["hybridsub"]``) and a ``pyvista.PolyData`` (its tags in ``field_data``), for
``write_mesh(path, mesh)``. Neither library is imported unless such an object is passed."""

from __future__ import annotations

from typing import Any

import numpy as np

from .._errors import MeshError
from .mesh import METADATA_KEY, TaggedMesh, as_tagged

#: The tag names both conventions use (``TaggedMesh.tag_arrays``).
TAG_NAMES = ("sharp_edges", "sharpness", "corners", "sharp_faces", "corner_sharpness")


def kind_of(obj: Any) -> str | None:
    """``"trimesh"``, ``"pyvista"`` or None, by the object's class (nothing is imported).

    >>> kind_of(np.eye(3)) is None
    True
    """
    for cls in type(obj).__mro__:
        top = cls.__module__.split(".")[0]
        if top == "trimesh" and cls.__name__ == "Trimesh":
            return "trimesh"
        if top == "pyvista" and cls.__name__ == "PolyData":
            return "pyvista"
    return None


def from_trimesh(mesh) -> TaggedMesh:
    """A ``trimesh.Trimesh`` with its tags (``metadata["hybridsub"]``), vertex colours and
    per-vertex UVs as a TaggedMesh.

    >>> import trimesh
    >>> t = trimesh.Trimesh(np.eye(3), [[0, 1, 2]], process=False, metadata={"hybridsub": {"corners": [1]}})
    >>> from_trimesh(t).corners.tolist()
    [1]
    """
    stored = mesh.metadata.get(METADATA_KEY) if isinstance(mesh.metadata, dict) else None
    tags = {k: stored.get(k) for k in TAG_NAMES} if isinstance(stored, dict) else {}
    colors = uv = None
    kind = getattr(mesh.visual, "kind", None)
    if kind == "vertex":
        colors = np.asarray(mesh.visual.vertex_colors)
    elif kind == "texture" and getattr(mesh.visual, "uv", None) is not None \
            and len(mesh.visual.uv) == len(mesh.vertices):
        uv = np.asarray(mesh.visual.uv, dtype=np.float64)
    return as_tagged(np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces, np.int64).reshape(-1, 3),
                     vertex_colors=colors, uv=uv, **tags)


def from_pyvista(poly) -> TaggedMesh:
    """A triangle ``pyvista.PolyData`` with its tags (``field_data``), colours (point data
    ``"colors"``, ``"RGB"`` or ``"RGBA"``) and active texture coordinates as a TaggedMesh."""
    F = triangles_of(poly)
    fd = poly.field_data
    tags = {k: np.asarray(fd[k]) for k in TAG_NAMES if k in fd.keys()}
    if "sharp_edges" in tags:
        tags["sharp_edges"] = tags["sharp_edges"].reshape(-1, 2)
    colors = next((np.asarray(poly.point_data[k]) for k in ("colors", "RGB", "RGBA") if k in poly.point_data.keys()),
                  None)
    tc = poly.active_texture_coordinates
    uv = None if tc is None else np.asarray(tc, np.float64)
    return as_tagged(np.asarray(poly.points, np.float64), F, vertex_colors=colors, uv=uv, **tags)


def triangles_of(poly) -> np.ndarray:
    """The (m, 3) faces of a ``pyvista.PolyData``; MeshError naming the first other polygon."""
    if poly.n_cells == 0 or poly.faces.size == 0:
        return np.empty((0, 3), np.int64)
    if not poly.is_all_triangles:
        sizes = np.array([len(f) for f in poly.irregular_faces])
        f = int(np.flatnonzero(sizes != 3)[0])
        raise MeshError(f"the PolyData's face {f} has {int(sizes[f])} vertices: hybridsub subdivides triangle "
                        "meshes; triangulate it first (poly.triangulate())")
    return np.asarray(poly.regular_faces, np.int64).reshape(-1, 3)
