"""``pyvista.PolyData`` for :func:`hybridsub.subdivide_mesh`: a triangle PolyData as the
``trimesh.Trimesh`` that ``subdivide_mesh`` refines, and its result back as a PolyData.

Point data becomes per-vertex attributes (refined by the refinement matrix, as positions are),
cell data per-face attributes (copied from each new face's input face, ``face_parent``), the
active texture coordinates the UVs (refined face-varying at seams), ``field_data`` the tags
(``sharp_edges`` (k, 2), ``sharpness``, ``corners``, ``sharp_faces``). pyvista is imported only
when a PolyData is passed."""

from __future__ import annotations

import numpy as np

from .._io import METADATA_KEY, TAG_NAMES, triangles_of


def polydata_as_trimesh(poly):
    """The Trimesh ``subdivide_mesh`` refines for ``poly``: point and cell data as vertex and
    face attributes, texture coordinates as UVs, field-data tags in its metadata. Normals are
    left out (recomputed from the refined surface, as trimesh does)."""
    import trimesh

    F = triangles_of(poly)
    V = np.array(poly.points, dtype=np.float64)
    pd, cd, fd = poly.point_data, poly.cell_data, poly.field_data
    tc = pd.active_texture_coordinates_name if hasattr(pd, "active_texture_coordinates_name") else None
    normals = pd.active_normals_name if hasattr(pd, "active_normals_name") else None
    skip = {tc, normals, "Normals"}
    vattr = {k: np.asarray(pd[k]) for k in pd.keys()
             if k not in skip and np.asarray(pd[k]).dtype.kind in "biuf" and len(pd[k]) == len(V)}
    fattr = {k: np.asarray(cd[k]) for k in cd.keys() if k not in ("Normals",) and len(cd[k]) == poly.n_cells}
    visual = None
    if tc is not None:
        visual = trimesh.visual.TextureVisuals(uv=np.asarray(pd[tc], dtype=np.float64)[:, :2])
    tags = {k: np.asarray(fd[k]) for k in TAG_NAMES if k in fd.keys()}
    if "sharp_edges" in tags:
        tags["sharp_edges"] = tags["sharp_edges"].reshape(-1, 2)
    metadata = {METADATA_KEY: tags} if tags else {}
    return trimesh.Trimesh(V, F, visual=visual, vertex_attributes=vattr, face_attributes=fattr, process=False,
                           validate=False, metadata=metadata)


def trimesh_as_polydata(mesh, uv_name: str | None):
    """``subdivide_mesh``'s result as a PolyData: attributes as point and cell data, UVs as the
    active texture coordinates (named ``uv_name``), the tags and ``face_parent`` in field data."""
    import pyvista as pv

    out = pv.PolyData.from_regular_faces(np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces, np.int64))
    for k, a in mesh.vertex_attributes.items():
        out.point_data[k] = np.asarray(a)
    for k, a in mesh.face_attributes.items():
        out.cell_data[k] = np.asarray(a)
    uv = getattr(mesh.visual, "uv", None) if getattr(mesh.visual, "kind", None) == "texture" else None
    if uv is not None:
        out.point_data[uv_name or "TCoords"] = np.asarray(uv, np.float64)
        out.point_data.active_texture_coordinates_name = uv_name or "TCoords"
    for k, a in mesh.metadata.get(METADATA_KEY, {}).items():
        if (k in TAG_NAMES or k == "face_parent") and np.size(a):  # pyvista refuses empty arrays
            out.field_data[k] = np.asarray(a)
    return out
