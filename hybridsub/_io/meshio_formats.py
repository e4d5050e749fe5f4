"""Formats neither hybridsub nor trimesh reads, through meshio (VTK, VTU, XDMF, Gmsh, Medit,
Abaqus, …): triangles, with the tags as cells of their own where the format holds mixed cells
— creases as ``line`` cells, corners as ``vertex`` cells, each with cell data
``"sharpness"`` (10 = infinitely sharp), sharp faces as triangle cell data ``"sharp_face"``
(1 = sharp) and holes as ``"hole"`` (1 = a face not rendered, ``holes=``). meshio is
imported only when such a file is read or written."""

from __future__ import annotations

import contextlib
import io
import re

import numpy as np

from .._errors import MeshError
from .._input import count_of
from .mesh import INFINITE, TaggedMesh, color_bytes, corner_tags, corner_values, describe_tags, sharpness_from_file, sharpness_to_file
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
    mesh, said = _meshio_read(path)
    P = np.asarray(mesh.points, dtype=np.float64)
    if P.ndim != 2 or P.shape[1] not in (2, 3):
        raise MeshError(f"{path}: points of shape {P.shape}; a surface mesh needs 2 or 3 coordinates")
    V = np.pad(P, ((0, 0), (0, 3 - P.shape[1])))
    polys, sharp_face, hole, pairs, psharp, corners, csharp, notes = [], [], [], [], [], [], [], []
    _check_cells(path, mesh, len(V))
    for i, block in enumerate(mesh.cells):
        try:
            data = {k: np.asarray(v[i], np.float64).reshape(len(block.data), -1) for k, v in mesh.cell_data.items()}
        except (ValueError, TypeError, IndexError):
            raise MeshError(f"{path}: the cell data of the {block.type} cells does not match the cells (one value "
                            "per cell)") from None
        if block.type in _VOLUME:
            raise MeshError(f"{path}: holds {block.type} cells, a volume mesh; hybridsub subdivides surfaces "
                            "(extract the boundary first: pyvista's extract_surface())")
        if block.type in _SURFACE:
            polys += [list(map(int, c)) for c in block.data]
            sf = data.get("sharp_face")
            sharp_face.append(np.zeros(len(block.data), bool) if sf is None else sf[:, 0] > 0)
            hole.append(_hole_marks(path, block, data.get("hole"), sum(len(h) for h in hole)))
        elif block.type == "line" and "sharpness" in data:
            pairs.append(np.asarray(block.data, np.int64))
            psharp.append(data["sharpness"][:, 0].astype(np.float64))
        elif block.type == "vertex" and "sharpness" in data:
            corners.append(np.asarray(block.data, np.int64)[:, 0])
            csharp.append(data["sharpness"][:, 0])
        else:
            notes.append(f"skipped {len(block.data)} {block.type} cells")
    F, origin = triangulate_polygons(path, polys, triangulate)
    mask = np.concatenate(sharp_face) if sharp_face else np.zeros(0, bool)
    sf = np.flatnonzero(mask[origin] if origin is not None else mask)
    hmask = np.concatenate(hole) if hole else np.zeros(0, bool)
    H = np.flatnonzero(hmask[origin] if origin is not None else hmask)
    E = np.concatenate(pairs) if pairs else np.empty((0, 2), np.int64)
    s = np.concatenate(psharp) if psharp else np.empty(0)
    if np.isnan(s).any():
        j = int(np.flatnonzero(np.isnan(s))[0])
        raise MeshError(f"{path}: crease (line cell) {j} has sharpness nan")
    E, s = E[s > 0], sharpness_from_file(s[s > 0])
    C, Cs = corner_tags(np.concatenate(corners), np.concatenate(csharp)) if corners else (np.empty(0, np.int64), None)
    colors = uv = face_uv = None
    pd = mesh.point_data
    if "colors" in pd:
        c = np.asarray(pd["colors"])
        colors = c / 255.0 if c.dtype.kind in "iu" else c.astype(np.float64)
        if colors.ndim != 2 or len(colors) != len(V):
            raise MeshError(f"{path}: point data 'colors' of shape {c.shape} for {len(V)} points")
    if "uv" in pd:
        uv = np.asarray(pd["uv"], np.float64)
        if uv.ndim != 2 or uv.shape[0] != len(V) or uv.shape[1] < 2:
            raise MeshError(f"{path}: point data 'uv' of shape {uv.shape} for {len(V)} points")
        uv, face_uv = uv[:, :2], F.copy()
    if origin is not None:
        notes.append(f"triangulated {len(polys)} polygons into {len(F)} triangles")
    notes += said
    return TaggedMesh(V, F, E, s, C, sf.astype(np.int64), colors, uv, face_uv, tuple(notes), corner_sharpness=Cs,
                      holes=H.astype(np.int64))


def _hole_marks(path: str, block, marks, first: int) -> np.ndarray:
    """The ``hole`` cell data of a block of surface cells as a mask: each value 0 or 1 (a
    MeshError names the first other one; ``first``: the block's first face number)."""
    if marks is None:
        return np.zeros(len(block.data), bool)
    v = marks[:, 0]
    bad = ~((v == 0) | (v == 1))
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise MeshError(f"{path}: the 'hole' cell data of {block.type} cell {j} (face {first + j}) is {v[j]}; "
                        "give 1 for a hole, 0 for a face rendered")
    return v == 1


def _meshio_read(path: str):
    """``meshio.read(path)`` and what meshio said on the way (its warnings, as notes). On a file
    it cannot read, meshio prints the reason and calls ``sys.exit(1)``: that ``SystemExit`` (and
    any other exception) is answered here with one MeshError naming the file and meshio's reason;
    so are cells of types meshio does not know, which it would drop.
    meshio's messages go to stdout and stderr; they are caught while it reads, so they become
    the error or the notes instead of lines on the caller's terminal."""
    import meshio

    out = io.StringIO()
    failed = None
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
            mesh = meshio.read(path)
    except SystemExit:  # meshio's own "Couldn't read file … as vtk"
        failed = ""
    except MemoryError:
        failed = "it declares more data than fits in memory"
    except Exception as e:  # meshio raises many kinds of errors on bad files
        failed = f"{type(e).__name__}: {e}"
    text = " ".join(out.getvalue().split())  # rich wraps long lines: messages are told apart by their prefix
    said = [m.strip() for m in re.split(r"(?=\b(?:Warning|Error): )", text) if m.strip()]
    said = [m.removeprefix("Warning: ") for m in said if not m.startswith("Error: Couldn't read file")]
    if failed is not None:
        reason = "; ".join(x for x in [*said, failed] if x and not x.startswith("Error: Couldn't read"))
        raise MeshError(f"{path}: meshio cannot read it" + (f" ({reason})" if reason else " (the file is damaged)"))
    dropped = _dropped_cells(path, mesh)
    if dropped:  # meshio leaves them out: read on, the surface would have holes where they were
        types = sorted({m.group(1) for s in said for m in re.finditer(r"cannot handle \(type (-?\d+)\)", s)}, key=int)
        kinds = f" (VTK cell type{'s' * (len(types) > 1)} {', '.join(types)})" if types else ""
        raise MeshError(f"{path}: {count_of(dropped, 'cell')} of a type meshio cannot read{kinds}: they would be "
                        "left out without a word, and the surface would have holes there")
    return mesh, [f"meshio: {s}" for s in said if "only meant for debugging" not in s]


def _dropped_cells(path: str, mesh) -> int:
    """How many cells the file declares beyond those meshio returned (meshio skips cells of
    types it does not know, saying so only on the terminal): VTK's ``CELL_TYPES n``, VTU's
    ``NumberOfCells``; 0 for other formats or when the declaration is not found."""
    ext = path.lower().rsplit(".", 1)[-1]
    if ext not in ("vtk", "vtu"):
        return 0
    with open(path, "rb") as fh:
        raw = fh.read()
    pattern = rb"CELL_TYPES\s+(\d+)" if ext == "vtk" else rb"NumberOfCells\s*=\s*[\"'](\d+)"
    declared = sum(int(m.group(1)) for m in re.finditer(pattern, raw))
    got = sum(len(b.data) for b in mesh.cells)
    return max(0, declared - got) if declared else 0


def _check_cells(path: str, mesh, n: int) -> None:
    """MeshError naming the first cell that refers to a point outside 0..n-1 (meshio returns
    such cells as the file has them)."""
    for block in mesh.cells:
        if block.type.startswith("polyhedron"):  # a volume cell: refused below
            continue
        A = np.asarray(block.data)
        if A.size == 0:
            continue
        if A.dtype.kind not in "iu":
            raise MeshError(f"{path}: the {block.type} cells hold point indices of type {A.dtype}")
        A = A.reshape(len(A), -1)
        bad = ((A < 0) | (A >= n)).any(axis=1)
        if bad.any():
            j = int(np.flatnonzero(bad)[0])
            i = int(A[j][(A[j] < 0) | (A[j] >= n)][0])
            valid = f"valid 0..{n - 1}" if n else "there are none"
            raise MeshError(f"{path}: {block.type} cell {j} refers to point {i}, but there are only {n} ({valid})")


#: The meshio formats that keep the tag cells and their cell data through a write and a read
#: (checked for VTK and VTU in tests/test_damaged_files.py); every other meshio format is written
#: as triangles alone, and the tags are reported dropped (Medit's .mesh, for one, writes the
#: line cells but not their sharpness, so the creases would be lost without a word).
TAGGED_FORMATS = (".vtk", ".vtu", ".xdmf", ".xmf")


def write_meshio(path: str, m: TaggedMesh) -> str:
    """Write ``m`` through meshio; returns a description of the tags the format could not hold
    ('' if none): a format not in ``TAGGED_FORMATS`` gets the triangles alone."""
    import meshio

    point_data = {}
    if m.vertex_colors is not None:
        point_data["colors"] = color_bytes(m.vertex_colors)
    if m.vertex_uv is not None:
        point_data["uv"] = m.vertex_uv
    name = path.lower()
    if m.has_tags and name.endswith(TAGGED_FORMATS):
        cells = [("triangle", m.faces)]
        sharp = [np.zeros(len(m.faces))]
        sf = np.zeros(len(m.faces), np.uint8)
        sf[m.sharp_faces] = 1
        marks = [sf]
        hf = np.zeros(len(m.faces), np.uint8)
        hf[m.holes] = 1
        holes = [hf]
        if len(m.sharp_edges):
            cells.append(("line", m.sharp_edges))
            sharp.append(sharpness_to_file(m.sharpness))
            marks.append(np.zeros(len(m.sharp_edges), np.uint8))
            holes.append(np.zeros(len(m.sharp_edges), np.uint8))
        if len(m.corners):
            cells.append(("vertex", np.asarray(m.corners).reshape(-1, 1)))
            sharp.append(corner_values(m))
            marks.append(np.zeros(len(m.corners), np.uint8))
            holes.append(np.zeros(len(m.corners), np.uint8))
        cell_data = {"sharpness": sharp, "sharp_face": marks}
        if len(m.holes):
            cell_data["hole"] = holes
        tagged = meshio.Mesh(m.vertices, cells, point_data=point_data, cell_data=cell_data)
        _meshio_write(path, tagged)
        return ""
    try:
        _meshio_write(path, meshio.Mesh(m.vertices, [("triangle", m.faces)], point_data=point_data))
    except MeshError:
        if not point_data:
            raise
        _meshio_write(path, meshio.Mesh(m.vertices, [("triangle", m.faces)]))  # a format without point data
    return describe_tags(m)


def _meshio_write(path: str, mesh) -> None:
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            mesh.write(path)
    except Exception as e:
        raise MeshError(f"{path}: meshio could not write it: {type(e).__name__}: {e}") from None
