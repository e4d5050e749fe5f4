"""Mesh files with their features: read and written by extension. OBJ with OpenSubdiv's tags,
PLY with tag elements, OFF and NumPy's NPZ (one array per attribute) have a module each here;
every other format trimesh reads and writes goes through :mod:`.trimesh_formats`.

OBJ, PLY and OFF are read and written vertex for vertex in file order, because crease and
corner tags name vertices by index: a reader that merges or reorders vertices would move the
tags onto the wrong vertices. Other formats (STL, GLB/glTF, 3MF, DAE, …) cannot hold tags. The
tag conventions are in ``docs/formats.md``.
"""

from __future__ import annotations

import contextlib
import os
import uuid
import warnings

from numpy.typing import ArrayLike

from .._errors import MeshError
from .mesh import TaggedMesh, as_tagged, check_read, describe_tags
from .npz import read_npz, write_npz
from .obj import read_obj, write_obj
from .off import read_off_mesh, write_off
from .ply import read_ply_mesh, write_ply_mesh
from .trimesh_formats import read_trimesh, write_trimesh


def read_mesh(path: str | os.PathLike, *, triangulate: bool = False) -> TaggedMesh:
    """Read a triangle mesh and its feature tags from a file.

    OBJ (with OpenSubdiv's ``t crease`` / ``t corner`` tags), PLY (with ``edge``, ``corner``
    and ``sharp_face`` elements), OFF and NPZ (NumPy arrays named as the attributes of
    :class:`TaggedMesh`) are read by hybridsub, keeping every vertex where the file has it;
    any other format trimesh reads (STL, GLB, glTF, 3MF, …) is read through trimesh (STL's
    separate triangles are welded into one surface, and so are the vertices a textured glTF
    duplicates along its UV seams, its UVs kept per face corner).

    Parameters
    ----------
    path : str or path-like
        The file; its extension chooses the format.
    triangulate : bool
        Split polygons with more than three vertices into triangle fans. By default a polygon
        is an error, since triangulating changes the subdivision surface. (NPZ files hold
        triangles only.)

    Returns
    -------
    TaggedMesh

    Raises
    ------
    FileNotFoundError
        No such file.
    MeshError
        The file cannot be read as a triangle mesh; the message says why (which face, which line).

    Examples
    --------
    >>> import hybridsub, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "tet.obj")
    >>> V = [[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]]
    >>> F = [[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]]
    >>> hybridsub.write_mesh(path, V, F, sharp_edges=[[0, 1]], corners=[3])
    >>> m = hybridsub.read_mesh(path)
    >>> m.sharp_edges.tolist(), m.sharpness.tolist(), m.corners.tolist()
    ([[0, 1]], [inf], [3])
    """
    path = os.fspath(path)
    if not os.path.exists(path):
        raise FileNotFoundError(f"{path}: no such file")
    if os.path.isdir(path):
        raise MeshError(f"{path}: is a directory, not a mesh file")
    ext = os.path.splitext(path)[1].lower()
    if ext == ".obj":
        mesh = read_obj(path, triangulate)
    elif ext == ".ply":
        mesh = read_ply_mesh(path, triangulate)
    elif ext == ".off":
        mesh = read_off_mesh(path, triangulate)
    elif ext == ".npz":
        mesh = read_npz(path)
    else:
        mesh = read_trimesh(path, ext)
    return check_read(path, mesh)



def write_mesh(path: str | os.PathLike, vertices: ArrayLike, faces: ArrayLike, *, sharp_edges: ArrayLike | None = None,
               sharpness: ArrayLike | None = None, corners: ArrayLike | None = None,
               sharp_faces: ArrayLike | None = None, vertex_colors: ArrayLike | None = None,
               uv: ArrayLike | None = None, face_uv: ArrayLike | None = None, binary: bool = True) -> None:
    """Write a triangle mesh with its feature tags.

    OBJ gets OpenSubdiv's tags (``t crease 2/1/0 i j s``, ``t corner 1/1/0 v s``, 0-based,
    ``s = 10`` for infinitely sharp) and ``t sharpface``; PLY gets ``crease`` (vertex1, vertex2,
    sharpness), ``corner`` and ``sharp_face`` elements; NPZ one array per attribute (the names
    of :class:`TaggedMesh`'s, ``inf`` for infinitely sharp); OFF and every other format trimesh writes
    (STL, GLB, …) hold geometry only, and a ``UserWarning`` says which tags were dropped.

    Parameters
    ----------
    path : str or path-like
        The file; its extension chooses the format. Missing folders are created.
    vertices : (n, 3) array_like of float
    faces : (m, 3) array_like of int
    sharp_edges : (k, 2) array_like of int, optional
    sharpness : (k,) array_like of float, optional
        Default ``inf``; written as 10 (OpenSubdiv's infinitely sharp).
    corners, sharp_faces : array_like of int, optional
        Vertex indices, face indices (boolean masks are accepted too).
    vertex_colors : (n, 3 or 4) array_like, optional
        Floats in [0, 1] or integers in 0..255.
    uv : (n, 2) or (t, 2) array_like of float, optional
        Texture coordinates: per vertex, or indexed by ``face_uv``.
    face_uv : (m, 3) array_like of int, optional
    binary : bool
        PLY only: binary (default) or ASCII.

    Examples
    --------
    >>> import hybridsub, tempfile, os
    >>> V, F = hybridsub.load_example()
    >>> feat = hybridsub.detect_features(V, F, angle=30)
    >>> path = os.path.join(tempfile.mkdtemp(), "fandisk.obj")
    >>> hybridsub.write_mesh(path, V, F, sharp_edges=feat.sharp_edges, corners=feat.corners)
    >>> len(hybridsub.read_mesh(path).sharp_edges)
    722
    """
    mesh = as_tagged(vertices, faces, sharp_edges, sharpness, corners, sharp_faces, vertex_colors, uv, face_uv)
    dropped = write(os.fspath(path), mesh, binary=binary)
    if dropped:
        warnings.warn(f"{os.fspath(path)}: this format cannot hold {dropped}; write .obj or .ply to keep them",
                      UserWarning, stacklevel=2)



def write(path: str, mesh: TaggedMesh, *, binary: bool = True) -> str:
    """Write ``mesh`` (the format by the extension of ``path``, missing folders created); returns
    a description of the tags the format could not hold ('' if none).

    The file is written under a temporary name in the same folder and renamed onto ``path``
    when complete, so a failed write (a full disk, a file-size limit, an unknown format) leaves
    no partial file, and an existing ``path`` stays as it was; the error names ``path``.

    Examples
    --------
    >>> import numpy as np, os, tempfile
    >>> m = TaggedMesh(np.eye(3), np.array([[0, 1, 2]]), corners=np.array([2]))
    >>> d = tempfile.mkdtemp()
    >>> write(os.path.join(d, "t.obj"), m), write(os.path.join(d, "t.stl"), m)
    ('', '1 corner')
    >>> sorted(os.listdir(d))
    ['t.obj', 't.stl']
    """
    d = os.path.dirname(os.path.abspath(path))
    os.makedirs(d, exist_ok=True)
    ext = os.path.splitext(path)[1].lower()
    # a fresh name beside the destination (same folder: the rename is atomic, relative links hold)
    tmp = os.path.join(d, f".{os.path.basename(path)}.{uuid.uuid4().hex[:12]}.partial{ext}")
    try:
        dropped = _write_format(tmp, mesh, ext, binary)
        os.replace(tmp, path)
    except BaseException as e:
        with contextlib.suppress(OSError):
            os.remove(tmp)
        if isinstance(e, OSError) and e.strerror and e.filename != path:
            raise OSError(e.errno, e.strerror, path) from None  # the caller's name, not the temporary one
        if isinstance(e, MeshError):
            raise MeshError(str(e).replace(tmp, path)) from None
        raise
    return dropped


def _write_format(path: str, mesh: TaggedMesh, ext: str, binary: bool) -> str:
    """Write ``mesh`` to ``path`` as format ``ext``; returns the tags the format cannot hold."""
    if ext == ".obj":
        write_obj(path, mesh)
        return ""
    if ext == ".ply":
        write_ply_mesh(path, mesh, binary)
        return ""
    if ext == ".npz":
        write_npz(path, mesh)
        return ""
    if ext == ".off":
        write_off(path, mesh)
    else:
        write_trimesh(path, mesh, ext)
    return describe_tags(mesh)
