"""Every other format trimesh reads and writes (STL, GLB/glTF, 3MF, DAE, …): geometry, vertex
colours and UVs, no tags. trimesh is imported only when such a file is read or written."""

from __future__ import annotations

from dataclasses import replace
import numpy as np

from .._errors import MeshError
from .mesh import METADATA_KEY, TaggedMesh
from .weld import weld


def trimesh_reads(ext: str) -> bool:
    """Whether trimesh reads files of extension ``ext`` (``".stl"``)."""
    import trimesh

    return ext.lstrip(".") in trimesh.available_formats()


def trimesh_writes(ext: str) -> bool:
    """Whether trimesh writes files of extension ``ext``."""
    import trimesh

    return ext.lstrip(".") in trimesh.exchange.export._mesh_exporters


def read_trimesh(path: str, ext: str) -> TaggedMesh:
    """Read a file of extension ``ext`` through trimesh (see :func:`hybridsub.read_mesh`): STL's
    separate triangles welded, vertices duplicated along UV seams welded (UVs kept per corner).

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "t.stl")
    >>> write_trimesh(path, TaggedMesh(np.eye(3), np.array([[0, 1, 2]])), ".stl")
    >>> read_trimesh(path, ".stl").faces.tolist()
    [[0, 1, 2]]
    """
    import trimesh

    kind = ext.lstrip(".")
    if kind not in trimesh.available_formats():
        raise MeshError(f"{path}: unknown mesh format {ext or '(no extension)'!r}; known: "
                        + ", ".join(sorted(set(trimesh.available_formats()))))
    try:
        loaded = trimesh.load(path, process=False, force="mesh")
    except ImportError as e:  # trimesh guesses the text encoding of a damaged file with an optional module
        raise MeshError(f"{path}: cannot read it as {kind.upper()}: the file is damaged or not {kind.upper()} "
                        f"(trimesh wanted the optional module {e.name or 'it names'} to guess its text "
                        "encoding)") from None
    except Exception as e:  # trimesh raises many kinds of errors on bad files
        raise MeshError(f"{path}: trimesh cannot read it: {type(e).__name__}: {e}") from None
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise MeshError(f"{path}: not a triangle mesh (no faces)")
    notes = []
    mesh = loaded
    if kind == "stl":
        n0 = len(mesh.vertices)
        mesh = mesh.copy()
        mesh.merge_vertices(merge_tex=True, merge_norm=True)
        notes.append(f"welded {n0} STL corners into {len(mesh.vertices)} vertices (STL stores triangles separately)")
    V = np.array(mesh.vertices, dtype=np.float64)
    F = np.array(mesh.faces, dtype=np.int64)
    colors = uv = face_uv = None
    kind_v = getattr(mesh.visual, "kind", None)
    if kind_v == "vertex":
        colors = np.asarray(mesh.visual.vertex_colors, dtype=np.float64) / 255.0
    elif kind_v == "texture" and getattr(mesh.visual, "uv", None) is not None and len(mesh.visual.uv) == len(V):
        # UVs per vertex: vertices are duplicated along UV seams. Welded, the UVs become
        # face-varying and the surface is one piece again.
        uv = np.array(mesh.visual.uv, dtype=np.float64)
        textured, merged, dropped = weld(TaggedMesh(V, F, uv=uv, face_uv=F.copy()))
        if merged:
            notes.append(f"welded {merged} vertices that the file duplicates along UV seams (UVs kept per face "
                         "corner)" + (f"; dropped {dropped} faces that collapsed" if dropped else ""))
            return replace(textured, notes=tuple(notes))
        face_uv = F.copy()
    return TaggedMesh(V, F, vertex_colors=colors, uv=uv, face_uv=face_uv, notes=tuple(notes))


def write_trimesh(path: str, m: TaggedMesh, ext: str) -> None:
    """Write ``m`` through trimesh as format ``ext``: geometry, vertex colours or UVs (a vertex
    per (vertex, UV) pair where the UVs have seams) with the texture of ``m``'s OBJ material
    (GLB embeds its image); tags are not written."""
    import trimesh

    kind = ext.lstrip(".")
    if kind not in trimesh.exchange.export._mesh_exporters:
        raise MeshError(f"{path}: trimesh cannot write {ext or '(no extension)'!r} files; known: "
                        + ", ".join(sorted(trimesh.exchange.export._mesh_exporters)))
    mesh = m.to_trimesh()
    mesh.metadata.pop(METADATA_KEY, None)  # arrays: not for the file's own metadata
    try:
        mesh.export(path)
    except Exception as e:
        raise MeshError(f"{path}: trimesh could not write it: {type(e).__name__}: {e}") from None
