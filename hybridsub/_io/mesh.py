"""Mesh files with their features: OBJ with OpenSubdiv's tags, PLY with tag elements, OFF,
NumPy's NPZ (one array per attribute), and every other format trimesh reads and writes.

OBJ, PLY and OFF are read and written here, vertex for vertex in file order, because crease
and corner tags name vertices by index: a reader that merges or reorders vertices would move
the tags onto the wrong vertices. Other formats (STL, GLB/glTF, 3MF, DAE, …) go through
trimesh; they cannot hold tags. The tag conventions are in ``docs/formats.md``.
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from . import ply as _ply
from .._errors import MeshError
from .._rules.refinement import INFINITE_SHARPNESS

__all__ = ["TaggedMesh", "read_mesh", "write_mesh"]

#: Sharpness written for infinitely sharp creases and corners (OpenSubdiv's convention:
#: a sharpness of 10 or more is infinitely sharp).
INFINITE = INFINITE_SHARPNESS
_OWN_FORMATS = (".obj", ".ply", ".off", ".npz")
#: The arrays of an NPZ mesh file, in the order written (docs/formats.md).
NPZ_ARRAYS = ("vertices", "faces", "sharp_edges", "sharpness", "corners", "sharp_faces", "vertex_colors", "uv",
              "face_uv")


@dataclass(frozen=True, eq=False)
class TaggedMesh:
    """A triangle mesh as read from a file, with its feature tags and attributes.

    Attributes
    ----------
    vertices : (n, 3) float64
        Positions, in file order.
    faces : (m, 3) int64
        Triangles (0-based vertex indices).
    sharp_edges : (k, 2) int64
        Crease edges as vertex pairs (0-based).
    sharpness : (k,) float64
        Their sharpness: ``inf`` for infinitely sharp (a file value ``>= 10``), else semi-sharp.
    corners : (c,) int64
        Corner vertices.
    sharp_faces : (s,) int64
        Faces to be split by Loop's rule in ``"hybrid"`` (hybridsub's own tag).
    vertex_colors : (n, 3 or 4) float64 in [0, 1], or None
        Per-vertex colours (RGB or RGBA).
    uv : (t, 2) float64, or None
        Texture coordinates, indexed by ``face_uv``.
    face_uv : (m, 3) int64, or None
        The ``uv`` index of each face corner (OBJ's ``f v/vt``).
    notes : tuple of str
        What the reader did that a user should know (tags it could not use, vertices it
        welded, polygons it triangulated).
    material_libs : tuple of str
        OBJ's ``mtllib`` files, as absolute paths (the OBJ writer names them relative to the
        file it writes, so a refined OBJ in another folder keeps its textures).
    materials : tuple of str
        OBJ's ``usemtl`` names, in order of first use.
    face_material : (m,) int64, or None
        Index into ``materials`` of each face (-1: before any ``usemtl``); None without materials.

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> m = hybridsub.TaggedMesh(np.eye(3), np.array([[0, 1, 2]]), uv=np.eye(3)[:, :2],
    ...                          face_uv=np.array([[0, 1, 2]]))
    >>> m.has_tags, m.vertex_uv.tolist()
    (False, [[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]])
    """

    vertices: np.ndarray
    faces: np.ndarray
    sharp_edges: np.ndarray = field(default_factory=lambda: np.empty((0, 2), np.int64))
    sharpness: np.ndarray = field(default_factory=lambda: np.empty(0))
    corners: np.ndarray = field(default_factory=lambda: np.empty(0, np.int64))
    sharp_faces: np.ndarray = field(default_factory=lambda: np.empty(0, np.int64))
    vertex_colors: np.ndarray | None = None
    uv: np.ndarray | None = None
    face_uv: np.ndarray | None = None
    notes: tuple = ()
    material_libs: tuple = ()
    materials: tuple = ()
    face_material: np.ndarray | None = None

    @property
    def vertex_uv(self) -> np.ndarray | None:
        """(n, 2) texture coordinates per vertex, or None when there are none or when some
        vertex uses different UVs in different faces (a UV seam)."""
        if self.uv is None or self.face_uv is None:
            return None
        n = len(self.vertices)
        first = np.full(n, -1, np.int64)
        v, t = self.faces.ravel(), self.face_uv.ravel()
        first[v[::-1]] = t[::-1]
        used = first >= 0
        if not np.array_equal(self.uv[first[v]], self.uv[t]):
            return None
        out = np.zeros((n, 2))
        out[used] = self.uv[first[used]]
        return out

    @property
    def has_tags(self) -> bool:
        return bool(len(self.sharp_edges) or len(self.corners) or len(self.sharp_faces))


# ----------------------------------------------------------------------------------------------
# reading

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
        mesh = _read_obj(path, triangulate)
    elif ext == ".ply":
        mesh = _read_ply(path, triangulate)
    elif ext == ".off":
        mesh = _read_off(path, triangulate)
    elif ext == ".npz":
        mesh = _read_npz(path)
    else:
        mesh = _read_trimesh(path, ext)
    if len(mesh.faces) == 0:
        raise MeshError(f"{path}: not a triangle mesh (it has no faces)")
    return mesh


def _polygons(path: str, polys: list, triangulate: bool, what: str = "face"):
    """Triangles of a list of index lists; returns (faces, origin face of each triangle)."""
    sizes = np.fromiter((len(p) for p in polys), np.int64, len(polys))
    if len(polys) and (sizes == 3).all():
        return np.array(polys, dtype=np.int64).reshape(-1, 3), None
    bad = np.flatnonzero(sizes != 3)
    if len(bad) and not triangulate:
        f = int(bad[0])
        raise MeshError(
            f"{path}: {what} {f} has {int(sizes[f])} vertices ({len(bad)} of {len(polys)} faces are not triangles): "
            "hybridsub subdivides triangle meshes; triangulate it first (--triangulate on the command line, "
            "read_mesh(..., triangulate=True) in Python)"
        )
    small = np.flatnonzero(sizes < 3)
    if len(small):
        f = int(small[0])
        raise MeshError(f"{path}: {what} {f} has only {int(sizes[f])} vertices")
    tris, origin = [], []
    for f, p in enumerate(polys):
        for i in range(1, len(p) - 1):
            tris.append((p[0], p[i], p[i + 1]))
            origin.append(f)
    return np.array(tris, dtype=np.int64).reshape(-1, 3), np.array(origin, dtype=np.int64)


def _read_obj(path: str, triangulate: bool) -> TaggedMesh:
    with open(path, encoding="utf-8", errors="replace") as fh:
        text = fh.read().replace("\\\n", " ")
    lines = text.splitlines()
    v_lines, vt_lines, f_lines, tags = [], [], [], []
    mats = _ObjMaterials(path)
    notes: list[str] = []
    ignored: set[str] = set()
    for number, line in enumerate(lines, start=1):
        if line.startswith("v "):
            v_lines.append(line[2:])
        elif line.startswith("f "):
            f_lines.append(line[2:])
        elif line.startswith("vt "):
            vt_lines.append(line[3:])
        else:
            w = line.split()
            if not w or w[0].startswith("#"):
                continue
            key = w[0]
            if key in ("v", "f", "vt"):  # tabs or leading blanks: the careful reader below
                return _read_obj_slow(path, lines, triangulate)
            if key == "t":
                tags.append((number, w[1:]))
            elif key in ("l", "p"):
                ignored.add("lines and points ('l', 'p')")
            elif key in ("mtllib", "usemtl"):
                mats.line(key, line, len(f_lines))
    fast = _obj_fast_faces(f_lines)
    if fast is None:
        return _read_obj_slow(path, lines, triangulate)
    faces, fuv = fast
    v_rows = _fast_table(v_lines) if v_lines else []
    vt_rows = _fast_table(vt_lines)
    if isinstance(vt_rows, np.ndarray):  # 'vt u' alone means v = 0; a third number (w) is not used
        vt_rows = np.pad(vt_rows[:, :2], ((0, 0), (0, 2 - min(vt_rows.shape[1], 2))))
    else:
        vt_rows = [ln.split()[:2] for ln in vt_lines]
    return _obj_finish(path, v_rows, vt_rows, faces, fuv, tags, notes, ignored, triangulate, mats)


def _fast_table(lines):
    """Rows of numbers of equal width as a float array, or the split rows if widths differ."""
    widths = np.fromiter((len(ln.split()) for ln in lines), np.int64, len(lines))
    if len(lines) and (widths == widths[0]).all():
        try:
            return np.array(" ".join(lines).split(), dtype=np.float64).reshape(len(lines), -1)
        except ValueError:
            pass
    return [ln.split() for ln in lines]


def _obj_fast_faces(f_lines):
    """Faces of uniform triangles 'a b c', 'a/t b/t c/t', 'a/t/n …' or 'a//n …' with positive
    indices, parsed in one go; None when the file needs the line-by-line reader."""
    if not f_lines:
        return None
    joined = " ".join(f_lines)
    if "-" in joined:
        return None
    first = f_lines[0].split()
    if len(first) != 3:
        return None
    parts = first[0].split("/")
    has_t = len(parts) > 1 and parts[1] != ""
    k = sum(1 for q in parts if q != "")
    m = len(f_lines)
    try:
        nums = np.array(joined.replace("//", " ").replace("/", " ").split(), dtype=np.int64)
    except ValueError:
        return None
    if nums.size != 3 * k * m or joined.count("/") != 3 * m * (len(parts) - 1):
        return None
    counts = np.fromiter((len(ln.split()) for ln in f_lines), np.int64, m)
    if (counts != 3).any():
        return None
    A = nums.reshape(m, 3, k) - 1
    return np.ascontiguousarray(A[:, :, 0]), (np.ascontiguousarray(A[:, :, 1]) if has_t else None)


def _read_obj_slow(path: str, lines: list, triangulate: bool) -> TaggedMesh:
    v_rows, vt_rows, faces, fuv, tags = [], [], [], [], []
    mats = _ObjMaterials(path)
    notes: list[str] = []
    ignored: set[str] = set()
    nv = nvt = 0
    for number, line in enumerate(lines, start=1):
        w = line.split()
        if not w or w[0].startswith("#"):
            continue
        key = w[0]
        if key == "v":
            v_rows.append(w[1:])
            nv += 1
        elif key == "vt":
            vt_rows.append(w[1:3])
            nvt += 1
        elif key == "f":
            vs, ts = [], []
            try:
                for corner in w[1:]:
                    parts = corner.split("/")
                    i = int(parts[0])
                    vs.append(i - 1 if i > 0 else nv + i)
                    if len(parts) > 1 and parts[1]:
                        j = int(parts[1])
                        ts.append(j - 1 if j > 0 else nvt + j)
            except ValueError:
                raise MeshError(f"{path}: line {number}: cannot read face {line.strip()!r}") from None
            faces.append(vs)
            fuv.append(ts if len(ts) == len(vs) else None)
        elif key == "t":
            tags.append((number, w[1:]))
        elif key in ("l", "p"):
            ignored.add("lines and points ('l', 'p')")
        elif key in ("mtllib", "usemtl"):
            mats.line(key, line, len(faces))
    return _obj_finish(path, v_rows, vt_rows, faces, fuv, tags, notes, ignored, triangulate, mats)


class _ObjMaterials:
    """``mtllib`` and ``usemtl`` lines of an OBJ file, and where each ``usemtl`` starts."""

    def __init__(self, path: str):
        self.folder = os.path.dirname(os.path.abspath(path))
        self.libs: list[str] = []
        self.names: list[str] = []
        self.starts: list[tuple[int, int]] = []  # (first face, material index)

    def line(self, key: str, line: str, n_faces: int) -> None:
        rest = line.strip()[len(key):].strip()  # one name, which may hold blanks
        if not rest:
            return
        if key == "mtllib":
            lib = os.path.normpath(os.path.join(self.folder, rest))
            if lib not in self.libs:
                self.libs.append(lib)
        else:
            if rest not in self.names:
                self.names.append(rest)
            self.starts.append((n_faces, self.names.index(rest)))

    def face_material(self, n_faces: int) -> np.ndarray | None:
        """(n_faces,) index into ``names`` per face as read (-1 before any ``usemtl``)."""
        if not self.names:
            return None
        out = np.full(n_faces, -1, np.int64)
        for first, k in self.starts:
            out[first:] = k
        return out


def _obj_finish(path, v_rows, vt_rows, faces, fuv, tags, notes, ignored, triangulate, mats) -> TaggedMesh:
    if ignored:
        notes.append("ignored " + ", ".join(sorted(ignored)))
    if len(faces) == 0:
        raise MeshError(f"{path}: not a triangle mesh (no 'f' lines)")
    V, colors = _obj_vertices(path, v_rows)
    if isinstance(faces, np.ndarray):
        F, origin = faces, None
    else:
        F, origin = _polygons(path, faces, triangulate)
    uv = face_uv = None
    has_uv = fuv is not None and (isinstance(fuv, np.ndarray) or all(t is not None for t in fuv))
    if len(vt_rows) and has_uv:
        try:
            uv = (np.asarray(vt_rows, dtype=np.float64) if isinstance(vt_rows, np.ndarray) else
                  np.array([r + ["0"] * (2 - len(r)) for r in vt_rows], dtype=np.float64))
        except ValueError:
            raise MeshError(f"{path}: a 'vt' line holds something that is not a number") from None
        face_uv = fuv if isinstance(fuv, np.ndarray) else _polygons(path, fuv, True)[0]
    elif len(vt_rows):
        notes.append("texture coordinates dropped: some faces have none")
    if origin is not None:
        notes.append(f"triangulated {len(faces)} polygons into {len(F)} triangles")
    _check_range(path, F, len(V), "vertex", lambda f: f"face {int(origin[f]) if origin is not None else f}")
    if face_uv is not None and uv is not None:
        _check_range(path, face_uv, len(uv), "texture coordinate", lambda f: f"face {f}")
    edges, sharpness, corners, sharp_faces, tag_notes, boundary_corners = _parse_tags(path, tags, len(V), len(faces))
    if origin is not None and len(sharp_faces):
        sharp_faces = np.flatnonzero(np.isin(origin, sharp_faces))
    if boundary_corners:  # OpenSubdiv's VTX_BOUNDARY_EDGE_AND_CORNER
        extra = np.setdiff1d(boundary_corner_vertices(F), corners)
        corners = np.union1d(corners, extra)
        if len(extra):
            tag_notes.append(f"'interpolateboundary 2': {len(extra)} boundary vertices in a single face "
                             "made corners")
    face_material = mats.face_material(len(faces))
    if face_material is not None and origin is not None:
        face_material = face_material[origin]
    return TaggedMesh(V, F, edges, sharpness, corners, sharp_faces, colors, uv, face_uv,
                      tuple(notes + tag_notes), tuple(mats.libs), tuple(mats.names), face_material)


def _obj_vertices(path, rows):
    if len(rows) == 0:
        return np.empty((0, 3)), None
    widths = {len(r) for r in rows}
    try:
        if isinstance(rows, np.ndarray):
            A = rows
        elif len(widths) == 1:
            A = np.array(rows, dtype=np.float64)
        else:
            width = min(widths)
            A = np.array([r[:width] for r in rows], dtype=np.float64)
    except ValueError:
        raise MeshError(f"{path}: a 'v' line holds something that is not a number") from None
    if A.shape[1] < 3:
        raise MeshError(f"{path}: 'v' lines need three coordinates, found {A.shape[1]}")
    colors = None
    if A.shape[1] in (6, 7):  # x y z r g b [a]: the common vertex-colour extension
        colors = A[:, 3:]
        if colors.max(initial=0) > 1:
            colors = colors / 255.0
    return np.ascontiguousarray(A[:, :3]), colors


def _parse_tags(path, tags, n_vertices, n_faces):
    """OpenSubdiv's ``t name nint/nfloat[/nstring] ints floats strings`` lines."""
    edges, edge_s, corners, corner_s, faces = [], [], [], [], []
    notes, unknown = [], set()
    boundary_corners = False
    for number, w in tags:
        where = f"{path}: line {number}"
        try:
            name = w[0]
            counts = [int(c) for c in w[1].split("/")]
            nint, nfloat = counts[0], counts[1] if len(counts) > 1 else 0
            nstr = counts[2] if len(counts) > 2 else 0
            ints = [int(x) for x in w[2:2 + nint]]
            floats = [float(x) for x in w[2 + nint:2 + nint + nfloat]]
            if len(ints) != nint or len(floats) != nfloat or len(w) < 2 + nint + nfloat + nstr:
                raise ValueError
        except (IndexError, ValueError):
            raise MeshError(f"{where}: cannot read tag {' '.join(['t'] + w)!r} "
                            "(expected 't NAME NINT/NFLOAT/NSTRING ints floats strings')") from None
        if name == "crease":
            if nint % 2 or nint == 0:
                raise MeshError(f"{where}: a crease tag needs vertex pairs, got {nint} indices")
            pairs = nint // 2
            if nfloat not in (1, pairs):
                raise MeshError(f"{where}: a crease tag with {pairs} edges needs 1 or {pairs} sharpness values, "
                                f"got {nfloat}")
            for j in range(pairs):
                edges.append(ints[2 * j:2 * j + 2])
                edge_s.append(floats[j if nfloat > 1 else 0])
        elif name == "corner":
            if nfloat not in (1, nint):
                raise MeshError(f"{where}: a corner tag with {nint} vertices needs 1 or {nint} sharpness values")
            for j, v in enumerate(ints):
                corners.append(v)
                corner_s.append(floats[j if nfloat > 1 else 0])
        elif name in ("sharpface", "sharp_face"):
            faces.extend(ints)
        elif name == "interpolateboundary":
            if ints and ints[0] == 2:
                boundary_corners = True
            elif ints and ints[0] not in (1,):
                notes.append(f"tag 'interpolateboundary {ints[0]}' ignored: boundaries are always "
                             "creases (OpenSubdiv's VTX_BOUNDARY_EDGE_ONLY)")
        else:
            unknown.add(name)
    if unknown:
        notes.append("ignored tags: " + ", ".join(sorted(unknown)))
    E = np.array(edges, dtype=np.int64).reshape(-1, 2)
    s = np.array(edge_s, dtype=np.float64)
    bad = ((E < 0) | (E >= n_vertices)).any(axis=1)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise MeshError(f"{path}: crease tag {j} names vertices {E[j].tolist()}, but the file has "
                        f"{n_vertices} vertices (tags are 0-based: 0..{n_vertices - 1})")
    keep = s > 0
    if not keep.all():
        notes.append(f"{int((~keep).sum())} crease tags with sharpness <= 0 ignored (no crease)")
    E, s = E[keep], np.where(s[keep] >= INFINITE, np.inf, s[keep])
    C = np.array(corners, dtype=np.int64)
    cs = np.array(corner_s, dtype=np.float64)
    bad = (C < 0) | (C >= n_vertices)
    if bad.any():
        raise MeshError(f"{path}: corner tag names vertex {int(C[bad][0])}, but the file has {n_vertices} "
                        f"vertices (0..{n_vertices - 1})")
    semi = (cs > 0) & (cs < INFINITE)
    if semi.any():
        notes.append(f"{int(semi.sum())} corner tags with finite sharpness treated as infinitely sharp "
                     "(hybridsub has no semi-sharp corners)")
    C = np.unique(C[cs > 0])
    S = np.array(faces, dtype=np.int64)
    bad = (S < 0) | (S >= n_faces)
    if bad.any():
        raise MeshError(f"{path}: sharpface tag names face {int(S[bad][0])}, but the file has {n_faces} faces")
    return E, s, C, np.unique(S), notes, boundary_corners


def _read_off(path: str, triangulate: bool) -> TaggedMesh:
    with open(path, encoding="utf-8", errors="replace") as fh:
        lines = [ln.split("#", 1)[0].split() for ln in fh]
    lines = [w for w in lines if w]
    if not lines or not lines[0][0].endswith("OFF"):
        raise MeshError(f"{path}: not an OFF file (it must start with 'OFF')")
    head = lines[0]
    colored = "C" in head[0]
    rest = head[1:] if len(head) > 1 else lines[1]
    body = lines[1:] if len(head) > 1 else lines[2:]
    try:
        nv, nf = int(rest[0]), int(rest[1])
    except (IndexError, ValueError):
        raise MeshError(f"{path}: the OFF header needs vertex and face counts") from None
    if len(body) < nv + nf:
        raise MeshError(f"{path}: the file ends early: the header promises {nv} vertices and {nf} faces")
    try:
        vrows = body[:nv]
        width = min(len(r) for r in vrows) if nv else 3
        A = np.array([r[:width] for r in vrows], dtype=np.float64).reshape(nv, -1)
        polys = [[int(x) for x in r[1:1 + int(r[0])]] for r in body[nv:nv + nf]]
    except ValueError:
        raise MeshError(f"{path}: a vertex or face line holds something that is not a number") from None
    V = np.ascontiguousarray(A[:, :3])
    colors = None
    if colored and A.shape[1] >= 6:
        colors = A[:, 3:7]
        if colors.max(initial=0) > 1:
            colors = colors / 255.0
    F, origin = _polygons(path, polys, triangulate)
    _check_range(path, F, nv, "vertex", lambda f: f"face {int(origin[f]) if origin is not None else f}")
    notes = (f"triangulated {nf} polygons into {len(F)} triangles",) if origin is not None else ()
    return TaggedMesh(V, F, vertex_colors=colors, notes=notes)


def _read_ply(path: str, triangulate: bool) -> TaggedMesh:
    el = _ply.read_ply(path)
    if "vertex" not in el:
        raise MeshError(f"{path}: the PLY file has no 'vertex' element")
    vd = el["vertex"].data
    if not all(k in vd for k in "xyz"):
        raise MeshError(f"{path}: the PLY 'vertex' element has no x, y, z properties")
    V = np.column_stack([np.asarray(vd[k], dtype=np.float64) for k in "xyz"]).reshape(-1, 3)
    n = len(V)
    colors = None
    if all(k in vd for k in ("red", "green", "blue")):
        cols = [vd[k] for k in ("red", "green", "blue", "alpha") if k in vd]
        scale = 255.0 if np.asarray(cols[0]).dtype.kind in "iu" else 1.0
        colors = np.column_stack(cols).astype(np.float64) / scale
    fd = el["face"].data if "face" in el else {}
    key = next((k for k in ("vertex_indices", "vertex_index") if k in fd), None)
    if key is None:
        raise MeshError(f"{path}: not a triangle mesh (no 'face' element with vertex_indices)")
    idx = fd[key]
    polys = idx if isinstance(idx, list) else np.asarray(idx)
    if isinstance(polys, np.ndarray) and polys.ndim == 2 and polys.shape[1] == 3:
        F, origin = polys.astype(np.int64), None
    else:
        F, origin = _polygons(path, [list(map(int, p)) for p in polys], triangulate)
    _check_range(path, F, n, "vertex", lambda f: f"face {int(origin[f]) if origin is not None else f}")
    uv = face_uv = None
    names = next(((a, b) for a, b in (("s", "t"), ("u", "v"), ("texture_u", "texture_v"))
                  if a in vd and b in vd), None)
    if names:
        uv = np.column_stack([np.asarray(vd[k], dtype=np.float64) for k in names])
        face_uv = F.copy()
    elif "texcoord" in fd and origin is None and np.ndim(fd["texcoord"]) == 2 and np.shape(fd["texcoord"])[1] == 6:
        uv = np.asarray(fd["texcoord"], dtype=np.float64).reshape(-1, 2)
        face_uv = np.arange(len(uv), dtype=np.int64).reshape(-1, 3)
    notes = [f"triangulated {len(polys)} polygons into {len(F)} triangles"] if origin is not None else []
    E = np.empty((0, 2), np.int64)
    s = np.empty(0)
    tag = "crease" if "crease" in el else "edge" if "edge" in el else None
    if tag:
        ed = el[tag].data
        if not ("vertex1" in ed and "vertex2" in ed):
            raise MeshError(f"{path}: the PLY '{tag}' element needs vertex1 and vertex2 properties")
        E = np.column_stack([np.asarray(ed["vertex1"]), np.asarray(ed["vertex2"])]).astype(np.int64).reshape(-1, 2)
        sk = next((k for k in ("crease", "sharpness") if k in ed), None)
        s = np.asarray(ed[sk], dtype=np.float64) if sk else np.full(len(E), np.inf)
        bad = ((E < 0) | (E >= n)).any(axis=1)
        if bad.any():
            j = int(np.flatnonzero(bad)[0])
            raise MeshError(f"{path}: {tag} {j} names vertices {E[j].tolist()}, but there are {n} vertices")
        keep = s > 0
        E, s = E[keep], np.where(s[keep] >= INFINITE, np.inf, s[keep])
    C = np.empty(0, np.int64)
    if "corner" in el:
        cd = el["corner"].data
        ck = next((k for k in ("vertex", "vertex_index") if k in cd), None)
        if ck is None:
            raise MeshError(f"{path}: the PLY 'corner' element needs a 'vertex' property")
        C = np.asarray(cd[ck], dtype=np.int64)
        if "sharpness" in cd:
            C = C[np.asarray(cd["sharpness"]) > 0]
        if ((C < 0) | (C >= n)).any():
            raise MeshError(f"{path}: a corner names vertex {int(C[(C < 0) | (C >= n)][0])}, but there are {n}")
        C = np.unique(C)
    S = np.empty(0, np.int64)
    if "sharp_face" in el:
        S = np.asarray(el["sharp_face"].data.get("face", np.empty(0)), dtype=np.int64)
        nf = len(polys)
        if ((S < 0) | (S >= nf)).any():
            raise MeshError(f"{path}: a sharp_face names face {int(S[(S < 0) | (S >= nf)][0])}, but there are {nf}")
        S = np.flatnonzero(np.isin(origin, S)) if origin is not None else np.unique(S)
    return TaggedMesh(np.ascontiguousarray(V), np.ascontiguousarray(F), E, s, C, S, colors, uv, face_uv,
                      tuple(notes))


def _read_npz(path: str) -> TaggedMesh:
    import zipfile

    if not zipfile.is_zipfile(path):
        raise MeshError(f"{path}: not an NPZ file (NumPy's savez writes a zip archive; this is not one)")
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (zipfile.BadZipFile, OSError, EOFError, ValueError) as e:
        raise MeshError(f"{path}: not a readable NPZ file ({type(e).__name__}: {e})") from None
    missing = [k for k in ("vertices", "faces") if k not in arrays]
    if missing:
        raise MeshError(f"{path}: an NPZ mesh needs arrays 'vertices' and 'faces'; it has no {missing[0]!r} "
                        f"(it holds {', '.join(repr(k) for k in sorted(arrays)) or 'nothing'})")
    F = arrays["faces"]
    if F.ndim != 2 or F.shape[1] != 3:
        raise MeshError(f"{path}: 'faces' must have shape (m, 3) (triangles), got {F.shape}")
    if "face_uv" in arrays and "uv" not in arrays:
        raise MeshError(f"{path}: 'face_uv' needs a 'uv' array")
    try:
        mesh = as_tagged(*(arrays.get(k) for k in NPZ_ARRAYS))
    except (MeshError, TypeError) as e:
        raise MeshError(f"{path}: {e}") from None
    ignored = sorted(set(arrays) - set(NPZ_ARRAYS))
    notes = (f"ignored arrays: {', '.join(ignored)}",) if ignored else ()
    return replace(mesh, notes=notes)


def _read_trimesh(path: str, ext: str) -> TaggedMesh:
    import trimesh

    kind = ext.lstrip(".")
    if kind not in trimesh.available_formats():
        raise MeshError(f"{path}: unknown mesh format {ext or '(no extension)'!r}; known: "
                        + ", ".join(sorted(set(trimesh.available_formats()))))
    try:
        loaded = trimesh.load(path, process=False, force="mesh")
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


def _check_range(path, F, n, what, name):
    if F.size == 0:
        return
    bad = ((F < 0) | (F >= n)).any(axis=1)
    if bad.any():
        f = int(np.flatnonzero(bad)[0])
        raise MeshError(f"{path}: {name(f)} refers to {what} index {int(F[f][(F[f] < 0) | (F[f] >= n)][0])}, "
                        f"but there are only {n} (valid 0..{n - 1})")


def boundary_corner_vertices(F: np.ndarray) -> np.ndarray:
    """Boundary vertices that lie in a single face: OpenSubdiv's EDGE_AND_CORNER corners."""
    he = np.stack([F, np.roll(F, -1, axis=1)], axis=2).reshape(-1, 2)
    key = np.sort(he, axis=1)
    _, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    bnd = he[cnt[inv.ravel()] == 1]
    nface = np.bincount(F.ravel(), minlength=int(F.max()) + 1)
    cand = np.unique(bnd.ravel())
    return cand[nface[cand] == 1]


# ----------------------------------------------------------------------------------------------
# writing

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


def as_tagged(vertices, faces, sharp_edges=None, sharpness=None, corners=None, sharp_faces=None,
              vertex_colors=None, uv=None, face_uv=None) -> TaggedMesh:
    """Check and convert write_mesh's arguments into a TaggedMesh (fresh arrays)."""
    from .. import _input as val

    V = val.as_vertices(vertices)
    F, _ = val.as_faces(faces, len(V))
    E, s = val.as_sharp_edges(sharp_edges, sharpness, len(V))
    keep = s > 0
    E, s = E[keep], s[keep]
    C = np.flatnonzero(val.as_corner_mask(corners, len(V)))
    S = np.flatnonzero(val.as_face_mask(sharp_faces, len(F))[0])
    colors = None
    if vertex_colors is not None:
        c = np.asarray(vertex_colors)
        if c.ndim != 2 or c.shape[0] != len(V) or c.shape[1] not in (3, 4):
            raise MeshError(f"vertex_colors must have shape ({len(V)}, 3 or 4), got {c.shape}")
        colors = c.astype(np.float64) / (255.0 if c.dtype.kind in "iu" else 1.0)
    T = FT = None
    if uv is not None:
        T = np.array(uv, dtype=np.float64)
        if T.ndim != 2 or T.shape[1] != 2:
            raise MeshError(f"uv must have shape (t, 2), got {T.shape}")
        if face_uv is None:
            if len(T) != len(V):
                raise MeshError(f"uv without face_uv must have one row per vertex ({len(V)}), got {len(T)}")
            FT = F.copy()
        else:
            FT = np.array(face_uv, dtype=np.int64)
            if FT.shape != F.shape:
                raise MeshError(f"face_uv must have the shape of faces {F.shape}, got {FT.shape}")
            if FT.size and (FT.min() < 0 or FT.max() >= len(T)):
                raise MeshError(f"face_uv holds an index outside 0..{len(T) - 1}")
    return TaggedMesh(V.copy() if V is vertices else V, F, E, s, C, S, colors, T, FT)


def write(path: str, mesh: TaggedMesh, *, binary: bool = True) -> str:
    """Write ``mesh``; returns a description of the tags the format could not hold ('' if none)."""
    d = os.path.dirname(os.path.abspath(path))
    os.makedirs(d, exist_ok=True)
    ext = os.path.splitext(path)[1].lower()
    if ext == ".obj":
        _write_obj(path, mesh)
        return ""
    if ext == ".ply":
        _write_ply(path, mesh, binary)
        return ""
    if ext == ".npz":
        _write_npz(path, mesh)
        return ""
    if ext == ".off":
        _write_off(path, mesh)
    else:
        _write_trimesh(path, mesh, ext)
    return describe_tags(mesh)


def describe_tags(mesh: TaggedMesh) -> str:
    parts = []
    if len(mesh.sharp_edges):
        parts.append(f"{len(mesh.sharp_edges):,} creases")
    if len(mesh.corners):
        parts.append(f"{len(mesh.corners):,} corners")
    if len(mesh.sharp_faces):
        parts.append(f"{len(mesh.sharp_faces):,} sharp faces")
    return ", ".join(parts)


def _rows(prefix: str, A: np.ndarray, fmt: str) -> list[str]:
    """Format rows of A as text lines, in chunks (one % per chunk is fast in CPython)."""
    if A.size == 0:
        return []
    row = prefix + " ".join([fmt] * (A.shape[1] // fmt.count("%"))) + "\n"
    out, chunk = [], 65536
    for s in range(0, len(A), chunk):
        block = A[s:s + chunk]
        out.append((row * len(block)) % tuple(block.ravel().tolist()))
    return out


def _write_obj(path: str, m: TaggedMesh) -> None:
    from .._version import __version__

    parts = [f"# hybridsub {__version__}: {len(m.vertices):,} vertices, {len(m.faces):,} triangles"
             + (f"; {describe_tags(m)}" if m.has_tags else "") + "\n",
             "# tags: OpenSubdiv's convention, 0-based vertex indices, sharpness 10 = infinitely sharp\n"]
    if m.vertex_colors is not None:
        parts += _rows("v ", np.hstack([m.vertices, m.vertex_colors[:, :3]]), "%r")
    else:
        parts += _rows("v ", m.vertices, "%r")
    folder = os.path.dirname(os.path.abspath(path))
    parts += [f"mtllib {_relative(lib, folder)}\n" for lib in m.material_libs]
    if m.uv is not None and m.face_uv is not None:
        parts += _rows("vt ", m.uv, "%r")
        rows, fmt = np.stack([m.faces + 1, m.face_uv + 1], axis=2).reshape(-1, 6), "%d/%d"
    else:
        rows, fmt = m.faces + 1, "%d"
    if m.face_material is None or not m.materials:
        parts += _rows("f ", rows, fmt)
    else:  # one usemtl line per run of faces with one material (children follow their parents)
        fm = np.asarray(m.face_material)
        cut = np.flatnonzero(np.r_[True, fm[1:] != fm[:-1]]).tolist() + [len(fm)]
        for a, b in zip(cut[:-1], cut[1:]):
            if fm[a] >= 0:
                parts.append(f"usemtl {m.materials[fm[a]]}\n")
            parts += _rows("f ", rows[a:b], fmt)
    s = np.where(np.isinf(m.sharpness), INFINITE, m.sharpness)
    if len(m.sharp_edges):
        E = m.sharp_edges.tolist()
        parts.append("".join(f"t crease 2/1/0 {a} {b} {float(x)!r}\n" for (a, b), x in zip(E, s.tolist())))
    if len(m.corners):
        parts.append("".join(f"t corner 1/1/0 {v} {INFINITE!r}\n" for v in m.corners.tolist()))
    S = m.sharp_faces.tolist()
    for i in range(0, len(S), 16):  # OpenSubdiv's reader takes lines of at most 255 characters
        chunk = S[i:i + 16]
        parts.append(f"t sharpface {len(chunk)}/0/0 " + " ".join(map(str, chunk)) + "\n")
    with open(path, "w") as fh:
        fh.writelines(parts)


def _relative(path: str, folder: str) -> str:
    try:
        return os.path.relpath(path, folder)
    except ValueError:  # another drive (Windows)
        return path


def _write_off(path: str, m: TaggedMesh) -> None:
    parts = []
    if m.vertex_colors is not None:
        rgba = np.hstack([m.vertex_colors[:, :3], m.vertex_colors[:, 3:4] if m.vertex_colors.shape[1] == 4
                          else np.ones((len(m.vertices), 1))])
        parts.append(f"COFF\n{len(m.vertices)} {len(m.faces)} 0\n")
        parts += _rows("", np.hstack([m.vertices, rgba]), "%r")
    else:
        parts.append(f"OFF\n{len(m.vertices)} {len(m.faces)} 0\n")
        parts += _rows("", m.vertices, "%r")
    parts += _rows("3 ", m.faces, "%d")
    with open(path, "w") as fh:
        fh.writelines(parts)


def _write_npz(path: str, m: TaggedMesh) -> None:
    """What np.savez writes (an uncompressed zip of .npy members), with fixed member dates so
    that the same mesh always gives the same bytes."""
    import zipfile

    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED, allowZip64=True) as z:
        for name in NPZ_ARRAYS:
            A = getattr(m, name)
            if A is None:
                continue
            info = zipfile.ZipInfo(f"{name}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.external_attr = 0o644 << 16
            with z.open(info, "w", force_zip64=True) as fh:
                np.lib.format.write_array(fh, np.ascontiguousarray(A), allow_pickle=False)


def _write_ply(path: str, m: TaggedMesh, binary: bool) -> None:
    from .._version import __version__

    vertex = [("x", "f8", m.vertices[:, 0]), ("y", "f8", m.vertices[:, 1]), ("z", "f8", m.vertices[:, 2])]
    if m.vertex_colors is not None:
        c = np.clip(np.round(m.vertex_colors * 255), 0, 255).astype(np.uint8)
        vertex += [(k, "u1", c[:, i]) for i, k in enumerate(("red", "green", "blue", "alpha")[:c.shape[1]])]
    face = [("vertex_indices", "i4", m.faces.astype(np.int32))]
    vuv = m.vertex_uv
    if vuv is not None:
        vertex += [("s", "f4", vuv[:, 0]), ("t", "f4", vuv[:, 1])]
    elif m.uv is not None:
        face.append(("texcoord", "f4", m.uv[m.face_uv].reshape(-1, 6)))
    elements = [("vertex", vertex), ("face", face)]
    if len(m.sharp_edges):
        s = np.where(np.isinf(m.sharpness), INFINITE, m.sharpness)
        # Not named "edge": trimesh turns an 'edge' element into a path and fails on extra properties.
        elements.append(("crease", [("vertex1", "i4", m.sharp_edges[:, 0]), ("vertex2", "i4", m.sharp_edges[:, 1]),
                                    ("sharpness", "f8", s)]))
    if len(m.corners):
        elements.append(("corner", [("vertex", "i4", m.corners), ("sharpness", "f8",
                                                                 np.full(len(m.corners), INFINITE))]))
    if len(m.sharp_faces):
        elements.append(("sharp_face", [("face", "i4", m.sharp_faces)]))
    _ply.write_ply(path, elements, binary=binary, comments=(
        f"hybridsub {__version__}",
        "crease: 0-based vertex1 vertex2 and sharpness (10 = infinitely sharp); corner: vertex, sharpness",
    ))


def _write_trimesh(path: str, m: TaggedMesh, ext: str) -> None:
    import trimesh

    kind = ext.lstrip(".")
    if kind not in trimesh.exchange.export._mesh_exporters:
        raise MeshError(f"{path}: trimesh cannot write {ext or '(no extension)'!r} files; known: "
                        + ", ".join(sorted(trimesh.exchange.export._mesh_exporters)))
    visual: Any = None
    V, F = m.vertices, m.faces
    if m.vertex_colors is not None:
        visual = trimesh.visual.ColorVisuals(vertex_colors=np.clip(np.round(m.vertex_colors * 255), 0, 255)
                                             .astype(np.uint8))
    elif m.vertex_uv is not None:
        visual = trimesh.visual.TextureVisuals(uv=m.vertex_uv)
    elif m.uv is not None and m.face_uv is not None:  # UV seams: one vertex per (vertex, UV index) pair
        corner, first = classes([F.ravel(), m.face_uv.ravel()], F.size)
        V, F = V[F.ravel()[first]], corner.reshape(-1, 3)
        visual = trimesh.visual.TextureVisuals(uv=m.uv[m.face_uv.ravel()[first]])
    mesh = trimesh.Trimesh(V, F, visual=visual, process=False)
    try:
        mesh.export(path)
    except Exception as e:
        raise MeshError(f"{path}: trimesh could not write it: {type(e).__name__}: {e}") from None


# ----------------------------------------------------------------------------------------------
# small text files for the command line

def read_index_file(path: str, columns: int, what: str) -> list[list[float]]:
    """Whitespace-separated numbers, '#' comments; (k, columns) float array (k rows)."""
    if not os.path.exists(path):
        raise FileNotFoundError(f"{path}: no such file")
    rows = []
    with open(path, encoding="utf-8", errors="replace") as fh:
        for number, line in enumerate(fh, start=1):
            w = line.split("#", 1)[0].replace(",", " ").split()
            if not w:
                continue
            if columns and len(w) not in (columns, columns + 1):
                raise MeshError(f"{path}: line {number}: expected {what}, got {line.strip()!r}")
            try:
                rows.append([float(x) for x in w])
            except ValueError:
                raise MeshError(f"{path}: line {number}: expected {what}, got {line.strip()!r}") from None
    return rows


def read_edge_file(path: str) -> tuple[np.ndarray, np.ndarray]:
    """``i j`` or ``i j sharpness`` per line (0-based); returns pairs and sharpness (inf default)."""
    rows = read_index_file(path, 2, "'i j' or 'i j sharpness'")
    E = np.array([r[:2] for r in rows], dtype=np.float64).reshape(-1, 2)
    s = np.array([r[2] if len(r) > 2 else np.inf for r in rows], dtype=np.float64)
    if (E != np.round(E)).any():
        raise MeshError(f"{path}: vertex indices must be integers")
    bad = np.isnan(s) | (s < 0)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise MeshError(f"{path}: edge {j} = ({int(E[j, 0])}, {int(E[j, 1])}) has sharpness {s[j]:g}; give 0 for "
                        "no crease, > 0 for a crease (>= 10 or inf: infinitely sharp)")
    s = np.where(s >= INFINITE, np.inf, s)
    return E.astype(np.int64), s


def read_list_file(path: str, what: str) -> np.ndarray:
    """Indices, any number per line (0-based)."""
    if not os.path.exists(path):
        raise FileNotFoundError(f"{path}: no such file")
    with open(path, encoding="utf-8", errors="replace") as fh:
        words = [w for line in fh for w in line.split("#", 1)[0].replace(",", " ").split()]
    try:
        A = np.array([float(w) for w in words], dtype=np.float64)
    except ValueError:
        raise MeshError(f"{path}: expected {what} (integers), found {next(w for w in words if not _isnum(w))!r}") \
            from None
    if (A != np.round(A)).any():
        raise MeshError(f"{path}: {what} must be integers")
    return A.astype(np.int64)


def _isnum(w: str) -> bool:
    try:
        float(w)
        return True
    except ValueError:
        return False


def classes(arrays: list, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows equal in every one of ``arrays`` (each with ``n`` rows), as classes numbered by
    first appearance: (class of each row, first row of each class). Positions compare
    exactly (-0.0 equals 0.0)."""
    lab = np.zeros(n, np.int64)
    for A in arrays:
        A = np.ascontiguousarray(A).reshape(n, -1)
        if A.dtype.kind == "f":
            A = A + 0.0
        _, inv = np.unique(A, axis=0, return_inverse=True)
        _, lab = np.unique(lab * (int(inv.max(initial=0)) + 1) + inv.ravel(), return_inverse=True)
        lab = lab.ravel()
    _, first, inv = np.unique(lab, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")
    rank = np.empty(len(order), np.int64)
    rank[order] = np.arange(len(order))
    return rank[inv.ravel()], first[order]


def weld(mesh: TaggedMesh) -> tuple[TaggedMesh, int, int]:
    """Merge vertices at identical positions (first occurrence keeps its place); faces that
    collapse are dropped. UV indices that end up on one vertex with equal UVs are merged too
    (so that only real UV seams remain). Returns the mesh, the number of vertices merged
    away, and the number of faces dropped."""
    V = mesh.vertices
    new, keep_v = classes([V], len(V))
    F = new[mesh.faces]
    ok = (F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0])
    fmap = np.cumsum(ok) - 1
    E = new[mesh.sharp_edges]
    eok = E[:, 0] != E[:, 1]
    S = mesh.sharp_faces[ok[mesh.sharp_faces]] if len(mesh.sharp_faces) else mesh.sharp_faces
    uv, face_uv = mesh.uv, mesh.face_uv
    if uv is not None and face_uv is not None:
        t = face_uv[ok].ravel()
        corner, first = classes([F[ok].ravel(), uv[t]], len(t))
        uv, face_uv = uv[t[first]], corner.reshape(-1, 3)
    out = replace(
        mesh, vertices=V[keep_v], faces=F[ok], sharp_edges=E[eok], sharpness=mesh.sharpness[eok],
        corners=np.unique(new[mesh.corners]), sharp_faces=fmap[S],
        vertex_colors=None if mesh.vertex_colors is None else mesh.vertex_colors[keep_v], uv=uv, face_uv=face_uv,
    )
    return out, len(V) - len(keep_v), int((~ok).sum())
