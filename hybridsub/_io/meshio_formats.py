"""Formats neither hybridsub nor trimesh reads, through meshio (VTK, VTU, XDMF, Gmsh, Medit,
Abaqus, …): triangles, with the tags as cells of their own where the format holds mixed cells
— creases as ``line`` cells, corners as ``vertex`` cells, each with cell data
``"sharpness"`` (10 = infinitely sharp), sharp faces as triangle cell data ``"sharp_face"``
(1 = sharp). meshio is imported only when such a file is read or written."""

from __future__ import annotations

import numpy as np

from .._errors import MeshError
from .mesh import INFINITE, TaggedMesh, color_bytes, describe_tags, sharpness_from_file, sharpness_to_file
from .tables import triangulate_polygons

_SURFACE = {"triangle", "quad", "polygon"}
_VOLUME = {"tetra", "hexahedron", "wedge", "pyramid", "tetra10", "hexahedron20", "hexahedron27", "wedge15"}


def meshio_knows(ext: str) -> bool:
    """Whether meshio reads and writes files of extension ``ext`` (e.g. ``".vtu"``)."""
    import meshio

    return ext in meshio.extension_to_filetypes


def read_meshio(path: str, triangulate: bool) -> TaggedMesh:
    """Read a file through meshio (see :func:`hybridsub.read_mesh`).

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "t.vtu")
    >>> write_meshio(path, TaggedMesh(np.eye(3), np.array([[0, 1, 2]]), corners=np.array([1])))
    ''
    >>> m = read_meshio(path, False)
    >>> m.faces.tolist(), m.corners.tolist()
    ([[0, 1, 2]], [1])
    """
    import meshio

    try:
        mesh = meshio.read(path)
    except Exception as e:  # meshio raises many kinds of errors on bad files
        raise MeshError(f"{path}: meshio cannot read it: {type(e).__name__}: {e}") from None
    P = np.asarray(mesh.points, dtype=np.float64)
    if P.ndim != 2 or P.shape[1] not in (2, 3):
        raise MeshError(f"{path}: points of shape {P.shape}; a surface mesh needs 2 or 3 coordinates")
    V = np.pad(P, ((0, 0), (0, 3 - P.shape[1])))
    polys, sharp_face, pairs, psharp, corners, notes = [], [], [], [], [], []
    for i, block in enumerate(mesh.cells):
        data = {k: np.asarray(v[i]).reshape(len(block.data), -1) for k, v in mesh.cell_data.items()}
        if block.type in _VOLUME:
            raise MeshError(f"{path}: holds {block.type} cells, a volume mesh; hybridsub subdivides surfaces "
                            "(extract the boundary first: pyvista's extract_surface())")
        if block.type in _SURFACE:
            polys += [list(map(int, c)) for c in block.data]
            sf = data.get("sharp_face")
            sharp_face.append(np.zeros(len(block.data), bool) if sf is None else sf[:, 0] > 0)
        elif block.type == "line" and "sharpness" in data:
            pairs.append(np.asarray(block.data, np.int64))
            psharp.append(data["sharpness"][:, 0].astype(np.float64))
        elif block.type == "vertex" and "sharpness" in data:
            corners.append(np.asarray(block.data, np.int64)[data["sharpness"][:, 0] > 0, 0])
        else:
            notes.append(f"skipped {len(block.data)} {block.type} cells")
    F, origin = triangulate_polygons(path, polys, triangulate)
    mask = np.concatenate(sharp_face) if sharp_face else np.zeros(0, bool)
    sf = np.flatnonzero(mask[origin] if origin is not None else mask)
    E = np.concatenate(pairs) if pairs else np.empty((0, 2), np.int64)
    s = sharpness_from_file(np.concatenate(psharp)) if psharp else np.empty(0)
    C = np.unique(np.concatenate(corners)) if corners else np.empty(0, np.int64)
    colors = uv = face_uv = None
    pd = mesh.point_data
    if "colors" in pd:
        c = np.asarray(pd["colors"])
        colors = c / 255.0 if c.dtype.kind in "iu" else c.astype(np.float64)
    if "uv" in pd:
        uv, face_uv = np.asarray(pd["uv"], np.float64)[:, :2], F.copy()
    if origin is not None:
        notes.append(f"triangulated {len(polys)} polygons into {len(F)} triangles")
    return TaggedMesh(V, F, E, s, C, sf.astype(np.int64), colors, uv, face_uv, tuple(notes))


def write_meshio(path: str, m: TaggedMesh) -> str:
    """Write ``m`` through meshio; returns a description of the tags the format could not hold
    ('' if none): a format without mixed cells or cell data gets the triangles alone."""
    import meshio

    cells = [("triangle", m.faces)]
    sharp = [np.zeros(len(m.faces))]
    sf = np.zeros(len(m.faces), np.uint8)
    sf[m.sharp_faces] = 1
    marks = [sf]
    if len(m.sharp_edges):
        cells.append(("line", m.sharp_edges))
        sharp.append(sharpness_to_file(m.sharpness))
        marks.append(np.zeros(len(m.sharp_edges), np.uint8))
    if len(m.corners):
        cells.append(("vertex", np.asarray(m.corners).reshape(-1, 1)))
        sharp.append(np.full(len(m.corners), INFINITE))
        marks.append(np.zeros(len(m.corners), np.uint8))
    point_data = {}
    if m.vertex_colors is not None:
        point_data["colors"] = color_bytes(m.vertex_colors)
    if m.vertex_uv is not None:
        point_data["uv"] = m.vertex_uv
    tagged = meshio.Mesh(m.vertices, cells, point_data=point_data,
                         cell_data={"sharpness": sharp, "sharp_face": marks})
    try:
        tagged.write(path)
        return ""
    except Exception:  # the format cannot hold lines, vertices or cell data: triangles alone
        pass
    try:
        meshio.Mesh(m.vertices, [("triangle", m.faces)]).write(path)
    except Exception as e:
        raise MeshError(f"{path}: meshio could not write it: {type(e).__name__}: {e}") from None
    return describe_tags(m)
