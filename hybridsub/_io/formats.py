"""Mesh files with their features: read and written by extension. OBJ with OpenSubdiv's tags,
PLY with tags in header comments, OFF and NumPy's NPZ (one array per attribute) have a module
each here; meshio's formats (VTK, VTU, XDMF, …; not STL) go through :mod:`.meshio_formats`,
every other format trimesh reads and writes through :mod:`.trimesh_formats`. ``write_mesh``
also takes a trimesh or pyvista mesh (:mod:`.convert`).

OBJ, PLY and OFF are read and written vertex for vertex in file order, because crease and
corner tags name vertices by index: a reader that merges or reorders vertices would move the
tags onto the wrong vertices. trimesh's formats (STL, GLB/glTF, 3MF, DAE, …) cannot hold tags. The
tag conventions are in ``docs/formats.md``.
"""

from __future__ import annotations

import contextlib
import os
import uuid
import warnings
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._errors import MeshError
from .mesh import TaggedMesh, as_tagged, check_read, describe_tags
from .npz import read_npz, write_npz
from .obj import read_obj, write_obj
from .off import read_off_mesh, write_off
from .ply import read_ply_mesh, write_ply_mesh
from .convert import from_pyvista, from_trimesh, kind_of
from .meshio_formats import meshio_knows, read_meshio, write_meshio
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
    try:
        mesh = _read_format(path, ext, triangulate)
    except (MeshError, OSError, ImportError):
        raise
    except MemoryError:
        raise MeshError(f"{path}: not enough memory to read it ({os.path.getsize(path):,} bytes)") from None
    except Exception as e:  # a damaged file the reader's own checks missed: still one error naming the file
        raise MeshError(f"{path}: cannot be read as {ext.lstrip('.').upper() or 'a mesh'}: the file is damaged "
                        f"({type(e).__name__}: {e})") from None
    return check_read(path, mesh)


def _read_format(path: str, ext: str, triangulate: bool) -> TaggedMesh:
    """The reader of ``ext``'s format applied to ``path``."""
    if ext == ".obj":
        return read_obj(path, triangulate)
    if ext == ".ply":
        return read_ply_mesh(path, triangulate)
    if ext == ".off":
        return read_off_mesh(path, triangulate)
    if ext == ".npz":
        return read_npz(path)
    if _through_meshio(path):
        return read_meshio(path, triangulate)
    return read_trimesh(path, ext)


def write_mesh(path: str | os.PathLike, vertices: ArrayLike | Any, faces: ArrayLike | None = None, *,
               sharp_edges: ArrayLike | None = None, sharpness: ArrayLike | None = None,
               corners: ArrayLike | None = None, sharp_faces: ArrayLike | None = None,
               vertex_colors: ArrayLike | None = None, uv: ArrayLike | None = None,
               face_uv: ArrayLike | None = None, binary: bool = True,
               corner_sharpness: ArrayLike | None = None, holes: ArrayLike | None = None) -> None:
    """Write a triangle mesh with its feature tags: arrays, or a mesh object in one line.

    OBJ gets OpenSubdiv's tags (``t crease 2/1/0 i j s``, ``t corner 1/1/0 v s``, ``t hole``,
    0-based, ``s = 10`` for infinitely sharp) and ``t sharpface``; PLY gets ``crease`` (vertex1,
    vertex2, sharpness), ``corner``, ``sharp_face`` and ``hole`` header comments (which every
    PLY reader skips); NPZ one array per attribute (the names of :class:`TaggedMesh`'s, ``inf``
    for infinitely sharp); meshio's formats (VTK, VTU, XDMF) creases as ``line`` cells and
    corners as ``vertex`` cells with cell data ``sharpness``, sharp faces and holes as triangle
    cell data ``sharp_face`` and ``hole`` (see docs/formats.md); OFF, meshio's other formats and
    the formats trimesh writes (STL, GLB, …) hold geometry only, and a ``UserWarning`` says which
    tags (holes among them) were dropped. No format holds ``boundary=``: it is an option of the
    refinement, not of the mesh.

    ``write_mesh(path, mesh)`` writes a ``trimesh.Trimesh`` (its tags from
    ``metadata["hybridsub"]``, as :func:`hybridsub.subdivide_mesh` leaves them), a
    ``pyvista.PolyData`` (tags from ``field_data``) or a :class:`TaggedMesh`, with its colours
    or UVs; tag arguments given as well replace the stored ones.

    Parameters
    ----------
    path : str or path-like
        The file; its extension chooses the format. Missing folders are created.
    vertices : (n, 3) array_like of float, or trimesh.Trimesh, pyvista.PolyData or TaggedMesh
    faces : (m, 3) array_like of int
        Required with vertex arrays; not with a mesh object.
    sharp_edges : (k, 2) array_like of int, optional
    sharpness : (k,) array_like of float, optional
        Default ``inf``; written as 10 (OpenSubdiv's infinitely sharp).
    corners, sharp_faces : array_like of int, optional
        Vertex indices, face indices (boolean masks are accepted too).
    corner_sharpness : (c,) array_like of float, optional
        Sharpness of each of ``corners`` (default ``inf``, written as 10): OBJ's ``t corner``
        value, PLY's ``corner`` comment, NPZ's ``corner_sharpness``, meshio's cell data.
    holes : array_like of int or (m,) bool mask, optional
        Faces not rendered that still shape their neighbours (``holes=`` of
        :func:`hybridsub.subdivide`): OBJ's ``t hole``, PLY's ``hole`` comment, NPZ's
        ``holes``, meshio's ``hole`` cell data.
    vertex_colors : (n, 3 or 4) array_like, optional
        Floats in [0, 1] or integers in 0..255.
    uv : (n, 2) or (t, 2) array_like of float, optional
        Texture coordinates: per vertex, or indexed by ``face_uv``.
    face_uv : (m, 3) array_like of int, optional
    binary : bool
        PLY only: binary (default) or ASCII.

    Examples
    --------
    >>> import hybridsub, tempfile, os, trimesh
    >>> V, F = hybridsub.load_example()
    >>> feat = hybridsub.detect_features(V, F, angle=30)
    >>> path = os.path.join(tempfile.mkdtemp(), "fandisk.obj")
    >>> hybridsub.write_mesh(path, V, F, sharp_edges=feat.sharp_edges, corners=feat.corners)
    >>> len(hybridsub.read_mesh(path).sharp_edges)
    722
    >>> fine = hybridsub.subdivide_mesh(trimesh.Trimesh(V, F, process=False), feature_angle=30)
    >>> hybridsub.write_mesh(path, fine)                  # a result with its tags, in one line
    >>> len(hybridsub.read_mesh(path).sharp_edges)
    1444
    """
    mesh = _as_mesh(vertices, faces, sharp_edges, sharpness, corners, sharp_faces, vertex_colors, uv, face_uv,
                    corner_sharpness, holes)
    dropped = write(os.fspath(path), mesh, binary=binary)
    if dropped:
        warnings.warn(f"{os.fspath(path)}: this format cannot hold {dropped}; write .obj or .ply to keep them",
                      UserWarning, stacklevel=2)



def _as_mesh(vertices, faces, sharp_edges, sharpness, corners, sharp_faces, vertex_colors, uv, face_uv,
             corner_sharpness=None, holes=None) -> TaggedMesh:
    """write_mesh's arguments as a TaggedMesh: arrays, or a mesh object and optional tags."""
    kind = "tagged" if isinstance(vertices, TaggedMesh) else kind_of(vertices)
    if kind is None:
        if faces is None:
            raise TypeError("write_mesh(path, vertices, faces, ...) needs faces, or write_mesh(path, mesh) a "
                            f"trimesh.Trimesh, pyvista.PolyData or hybridsub.TaggedMesh; got {type(vertices).__name__}")
        return as_tagged(vertices, faces, sharp_edges, sharpness, corners, sharp_faces, vertex_colors, uv, face_uv,
                         corner_sharpness, holes)
    if faces is not None:
        raise TypeError(f"write_mesh(path, mesh) takes no faces: the {type(vertices).__name__} has its own")
    if vertex_colors is not None or uv is not None or face_uv is not None:
        raise TypeError("write_mesh(path, mesh): colours and UVs come from the mesh; pass arrays to set them")
    m = vertices if kind == "tagged" else from_trimesh(vertices) if kind == "trimesh" else from_pyvista(vertices)
    if sharp_edges is None and sharpness is None and corners is None and sharp_faces is None \
            and corner_sharpness is None and holes is None:
        return m
    tags = m.tag_arrays()
    if sharp_edges is not None or sharpness is not None:
        tags["sharp_edges"], tags["sharpness"] = sharp_edges, sharpness
    if corners is not None or corner_sharpness is not None:
        tags["corners"] = tags["corners"] if corners is None else corners
        tags["corner_sharpness"] = corner_sharpness
    tags["sharp_faces"] = tags["sharp_faces"] if sharp_faces is None else sharp_faces
    tags["holes"] = m.holes if holes is None else holes
    checked = as_tagged(m.vertices, m.faces, **tags)
    return replace(m, sharp_edges=checked.sharp_edges, sharpness=checked.sharpness, corners=checked.corners,
                   sharp_faces=checked.sharp_faces, corner_sharpness=checked.corner_sharpness, holes=checked.holes)


def check_writable(path: str, *, binary: bool = True) -> None:
    """MeshError naming ``path`` if a mesh cannot be written in its format (an unknown extension,
    a format of points or of flat drawings, a missing optional module): found by writing a
    small tetrahedron under the same extension in a temporary folder, so that a command can
    refuse before the work rather than after it.

    >>> check_writable("out.xyz")
    Traceback (most recent call last):
    ...
    hybridsub._errors.MeshError: out.xyz: cannot write a mesh in this format (trimesh could not write it: ValueError: object must be PointCloud)
    """
    import tempfile

    tet = TaggedMesh(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]),
                     np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]))
    with tempfile.TemporaryDirectory() as d:
        try:
            _write_format(os.path.join(d, "probe" + _full_ext(path)), tet, os.path.splitext(path)[1].lower(), binary, d)
        except MeshError as e:
            reason = str(e).split(": ", 1)[1] if ": " in str(e) else str(e)
            raise MeshError(f"{path}: cannot write a mesh in this format ({reason})") from None
        except OSError:  # the temporary folder's trouble, not the format's: the real write will say
            return
        except (ImportError, ValueError, TypeError) as e:
            raise MeshError(f"{path}: cannot write a mesh in this format ({type(e).__name__}: {e})") from None


def _full_ext(path: str) -> str:
    """The extension with a compression suffix kept (``.vol.gz``), as the writers choose by."""
    ext = _meshio_ext(path)
    return ext if ext.endswith(".gz") else os.path.splitext(path)[1]


def write(path: str, mesh: TaggedMesh, *, binary: bool = True, folder: str | None = None) -> str:
    """Write ``mesh`` (the format by the extension of ``path``, missing folders created); returns
    a description of the tags the format could not hold ('' if none). ``folder``: where the
    file will live, if it is written under a temporary name elsewhere (an OBJ names and copies
    its material library and textures there).

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
    # (the whole name kept at the end, so that double extensions such as .vol.gz still choose the format)
    tmp = os.path.join(d, f".partial.{uuid.uuid4().hex[:12]}.{os.path.basename(path)}")
    try:
        dropped = _write_format(tmp, mesh, ext, binary, d if folder is None else folder)
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


def _write_format(path: str, mesh: TaggedMesh, ext: str, binary: bool, folder: str) -> str:
    """Write ``mesh`` to ``path`` as format ``ext`` (an OBJ's materials named from ``folder``); returns
    the tags the format cannot hold."""
    if ext == ".obj":
        write_obj(path, mesh, folder)
        return ""
    if ext == ".ply":
        write_ply_mesh(path, mesh, binary)
        return ""
    if ext == ".npz":
        write_npz(path, mesh)
        return ""
    if ext == ".off":
        write_off(path, mesh)
    elif _through_meshio(path):
        return write_meshio(path, mesh)
    else:
        write_trimesh(path, mesh, ext)
    return describe_tags(mesh)


def _through_meshio(path: str) -> bool:
    """Whether hybridsub reads and writes ``path`` through meshio: every format meshio knows
    but STL, which trimesh reads (and welds) itself. (trimesh hands VTK, VTU, XDMF, … to meshio
    as well, but with the triangles alone: read directly, the tag cells come along.)"""
    ext = _meshio_ext(path)
    return ext != ".stl" and meshio_knows(ext)


def _meshio_ext(path: str) -> str:
    """The extension meshio would choose the format by (``.vol.gz`` is one)."""
    name = os.path.basename(path).lower()
    two = "." + ".".join(name.split(".")[-2:]) if name.count(".") >= 2 else ""
    return two if two.endswith(".gz") else os.path.splitext(name)[1]

