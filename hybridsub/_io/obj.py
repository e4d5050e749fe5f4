"""OBJ files with OpenSubdiv's tags (``t crease``, ``t corner``, ``t interpolateboundary``) and
hybridsub's ``t sharpface``, vertex colours, texture coordinates and materials.

Vertices are read and written in file order, since the tags name them by index. Reading has
a fast path (whole columns parsed at once) for files of uniform triangles with positive
indices, and a careful line-by-line reader for everything else (polygons, negative indices,
tabs). The conventions are in ``docs/formats.md``.
"""

from __future__ import annotations

import filecmp
import os
import shutil

import numpy as np

from .._errors import MeshError
from .._input import count_of
from .._topology import group_halfedges, halfedge_ends
from .._version import __version__
from .mesh import INFINITE, TaggedMesh, corner_tags, corner_values, describe_tags, sharpness_from_file, sharpness_to_file, unit_colors
from .tables import MAX_INDEX, check_faces, check_indices, text_rows, triangulate_polygons


# ----------------------------------------------------------------------------------------------
# reading

def read_obj(path: str, triangulate: bool) -> TaggedMesh:
    """Read an OBJ file (see :func:`hybridsub.read_mesh`).

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "t.obj")
    >>> _ = open(path, "w").write("v 0 0 0\\nv 1 0 0\\nv 0 1 0\\nf 1 2 3\\nt corner 1/1/0 2 10\\n")
    >>> m = read_obj(path, False)
    >>> m.faces.tolist(), m.corners.tolist()
    ([[0, 1, 2]], [2])
    """
    with open(path, encoding="utf-8", errors="replace") as fh:
        text = fh.read().replace("\\\n", " ")
    lines = text.splitlines()
    v_lines, vt_lines, f_lines = [], [], []
    extras = _ObjExtras(path)
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
            if w[0] in ("v", "f", "vt"):  # tabs or leading blanks: the careful reader below
                return _read_obj_slow(path, lines, triangulate)
            extras.take(w, line, number, len(f_lines))
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
    return _obj_finish(path, v_rows, vt_rows, faces, fuv, extras, triangulate)


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
    except (ValueError, OverflowError):
        return None
    if not nums.all():  # an index 0: the careful reader names the line
        return None
    if nums.size != 3 * k * m or joined.count("/") != 3 * m * (len(parts) - 1):
        return None
    counts = np.fromiter((len(ln.split()) for ln in f_lines), np.int64, m)
    if (counts != 3).any():
        return None
    A = nums.reshape(m, 3, k) - 1
    return np.ascontiguousarray(A[:, :, 0]), (np.ascontiguousarray(A[:, :, 1]) if has_t else None)


def _read_obj_slow(path: str, lines: list, triangulate: bool) -> TaggedMesh:
    v_rows, vt_rows, faces, fuv = [], [], [], []
    extras = _ObjExtras(path)
    for number, line in enumerate(lines, start=1):
        w = line.split()
        if not w or w[0].startswith("#"):
            continue
        key = w[0]
        if key == "v":
            v_rows.append(w[1:])
        elif key == "vt":
            vt_rows.append(w[1:3])
        elif key == "f":
            vs, ts = _obj_face(path, number, line, w, len(v_rows), len(vt_rows))
            faces.append(vs)
            fuv.append(ts if len(ts) == len(vs) else None)
        else:
            extras.take(w, line, number, len(faces))
    return _obj_finish(path, v_rows, vt_rows, faces, fuv, extras, triangulate)


def _obj_face(path: str, number: int, line: str, w: list, nv: int, nvt: int) -> tuple[list, list]:
    """Vertex and texture indices (0-based) of an 'f' line; negative indices count back from
    the ``nv`` vertices and ``nvt`` texture coordinates read so far."""
    vs, ts = [], []
    try:
        for corner in w[1:]:
            parts = corner.split("/")
            vs.append(_obj_index(int(parts[0]), nv, "vertex"))
            if len(parts) > 1 and parts[1]:
                ts.append(_obj_index(int(parts[1]), nvt, "texture coordinate"))
    except ValueError as e:
        why = f": {e}" if str(e).startswith("OBJ") else ""
        raise MeshError(f"{path}: line {number}: cannot read face {line.strip()!r}{why}") from None
    return vs, ts


def _obj_index(i: int, count: int, what: str) -> int:
    """The 0-based index of OBJ index ``i`` (from 1; negative: back from the ``count`` read so far)."""
    if i == 0:
        raise ValueError(f"OBJ indices count from 1 (or back from -1); 0 is no {what}")
    if i < 0 and count + i < 0:
        raise ValueError(f"OBJ index {i} counts back past the first {what} ({count} read so far)")
    return i - 1 if i > 0 else count + i


class _ObjExtras:
    """The lines of an OBJ file other than ``v``, ``vt`` and ``f``: tags, ``mtllib`` and
    ``usemtl`` (and where each ``usemtl`` starts), and the kinds of lines ignored."""

    def __init__(self, path: str):
        self.folder = os.path.dirname(os.path.abspath(path))
        self.tags: list[tuple[int, list[str]]] = []  # (line number, words after 't')
        self.ignored: set[str] = set()
        self.libs: list[str] = []
        self.names: list[str] = []
        self.starts: list[tuple[int, int]] = []  # (first face, material index)

    def take(self, w: list[str], line: str, number: int, n_faces: int) -> None:
        """Note line ``number`` (its words ``w``), read after ``n_faces`` faces."""
        key = w[0]
        if key == "t":
            self.tags.append((number, w[1:]))
        elif key in ("l", "p"):
            self.ignored.add("lines and points ('l', 'p')")
        elif key in ("mtllib", "usemtl"):
            self._material(key, line, n_faces)

    def _material(self, key: str, line: str, n_faces: int) -> None:
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


def _obj_finish(path, v_rows, vt_rows, faces, fuv, extras: _ObjExtras, triangulate) -> TaggedMesh:
    notes = ["ignored " + ", ".join(sorted(extras.ignored))] if extras.ignored else []
    if len(faces) == 0:
        raise MeshError(f"{path}: not a triangle mesh (no 'f' lines)")
    V, colors = _obj_vertices(path, v_rows)
    if isinstance(faces, np.ndarray):
        F, origin = faces, None
    else:
        F, origin = triangulate_polygons(path, faces, triangulate)
    uv, face_uv = _obj_uv(path, vt_rows, fuv, notes)
    if origin is not None:
        notes.append(f"triangulated {count_of(len(faces), 'polygon')} into {count_of(len(F), 'triangle')}")
    check_faces(path, F, len(V), origin, base=1)
    if face_uv is not None and uv is not None:
        check_indices(path, face_uv, len(uv), "texture coordinate", lambda f: f"face {f}", base=1)
    edges, sharpness, (corners, corner_s), sharp_faces, tag_notes, boundary_corners, holes = _parse_tags(
        path, extras.tags, len(V), len(faces))
    if origin is not None and len(sharp_faces):
        sharp_faces = np.flatnonzero(np.isin(origin, sharp_faces))
    if origin is not None and len(holes):  # every triangle of a polygon hole is a hole
        holes = np.flatnonzero(np.isin(origin, holes))
    if boundary_corners == "none":  # VTX_BOUNDARY_NONE: the faces at the boundary are holes
        at = np.flatnonzero(np.isin(F, boundary_vertices(F)).any(axis=1))
        if origin is not None:  # the whole polygon, as OpenSubdiv tags the face
            at = np.flatnonzero(np.isin(origin, origin[at]))
        if len(at):
            tag_notes.append(f"'interpolateboundary 0': {count_of(len(np.setdiff1d(at, holes)), 'face')} at the "
                             "boundary made holes (boundary=\"none\")")
        holes = np.union1d(holes, at).astype(np.int64)
    if boundary_corners == "edge_and_corner":  # OpenSubdiv's VTX_BOUNDARY_EDGE_AND_CORNER
        extra = np.setdiff1d(boundary_corner_vertices(F), corners)
        if corner_s is not None:  # all of them infinitely sharp (OpenSubdiv's SharpenBoundaryVertex)
            corner_s = np.concatenate([corner_s, np.full(len(extra), np.inf)])[np.argsort(np.r_[corners, extra])]
        corners = np.union1d(corners, extra)
        if corner_s is not None:
            corner_s[np.isin(corners, boundary_corner_vertices(F))] = np.inf
            corner_s = corner_s if np.isfinite(corner_s).any() else None
        if len(extra):
            tag_notes.append(f"'interpolateboundary 2': {len(extra)} boundary vertices in a single face "
                             "made corners")
    face_material = extras.face_material(len(faces))
    if face_material is not None and origin is not None:
        face_material = face_material[origin]
    return TaggedMesh(V, F, edges, sharpness, corners, sharp_faces, colors, uv, face_uv,
                      tuple(notes + tag_notes), tuple(extras.libs), tuple(extras.names), face_material, corner_s,
                      holes)


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
        colors = unit_colors(A[:, 3:])
    return np.ascontiguousarray(A[:, :3]), colors


def _obj_uv(path, vt_rows, fuv, notes):
    """(uv, face_uv) of the file, or (None, None) where some face has no texture coordinates."""
    has_uv = fuv is not None and (isinstance(fuv, np.ndarray) or all(t is not None for t in fuv))
    if len(vt_rows) and has_uv:
        try:
            uv = (np.asarray(vt_rows, dtype=np.float64) if isinstance(vt_rows, np.ndarray) else
                  np.array([r + ["0"] * (2 - len(r)) for r in vt_rows], dtype=np.float64))
        except ValueError:
            raise MeshError(f"{path}: a 'vt' line holds something that is not a number") from None
        return uv, (fuv if isinstance(fuv, np.ndarray) else triangulate_polygons(path, fuv, True)[0])
    if len(vt_rows):
        notes.append("texture coordinates dropped: some faces have none")
    return None, None


def _tag_values(where: str, w: list[str]) -> tuple[str, list[int], list[float]]:
    """Name, integers and floats of the tag line ``t`` + ``w``."""
    try:
        name = w[0]
        counts = [int(c) for c in w[1].split("/")]
        nint, nfloat = counts[0], counts[1] if len(counts) > 1 else 0
        nstr = counts[2] if len(counts) > 2 else 0
        ints = [int(x) for x in w[2:2 + nint]]
        floats = [float(x) for x in w[2 + nint:2 + nint + nfloat]]
        if len(ints) != nint or len(floats) != nfloat or len(w) < 2 + nint + nfloat + nstr:
            raise ValueError
        if any(abs(i) > MAX_INDEX for i in ints):
            raise MeshError(f"{where}: tag {' '.join(['t'] + w[:2])!r} holds an index too large for any mesh")
        if any(f != f for f in floats):
            raise MeshError(f"{where}: tag {' '.join(['t'] + w[:2])!r} holds a sharpness that is not a number (nan)")
    except (IndexError, ValueError) as e:
        if isinstance(e, MeshError):
            raise
        raise MeshError(f"{where}: cannot read tag {' '.join(['t'] + w)!r} "
                        "(expected 't NAME NINT/NFLOAT/NSTRING ints floats strings')") from None
    return name, ints, floats


def _parse_tags(path, tags, n_vertices, n_faces):
    """OpenSubdiv's ``t name nint/nfloat[/nstring] ints floats strings`` lines."""
    edges, edge_s, corners, corner_s, faces, holes = [], [], [], [], [], []
    notes, unknown = [], set()
    boundary_corners = None  # boundary= the file asks for, where not "edge_only"
    for number, w in tags:
        where = f"{path}: line {number}"
        name, ints, floats = _tag_values(where, w)
        nint, nfloat = len(ints), len(floats)
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
        elif name == "hole":  # OpenSubdiv's face holes: 0-based face indices
            holes.extend(ints)
        elif name == "interpolateboundary":  # OpenSubdiv's Sdc VtxBoundaryInterpolation: 0 none, 1, 2
            if ints and ints[0] in (0, 2):
                boundary_corners = "none" if ints[0] == 0 else "edge_and_corner"
            elif ints and ints[0] != 1:
                notes.append(f"tag 'interpolateboundary {ints[0]}' ignored: OpenSubdiv knows 0 (none), 1 (edge "
                             "only) and 2 (edge and corner)")
        else:
            unknown.add(name)
    if unknown:
        notes.append("ignored tags: " + ", ".join(sorted(unknown)))
    E, s = _tag_creases(path, edges, edge_s, n_vertices, notes)
    C, Cs = _tag_corners(path, corners, corner_s, n_vertices)
    S = np.array(faces, dtype=np.int64)
    bad = (S < 0) | (S >= n_faces)
    if bad.any():
        raise MeshError(f"{path}: sharpface tag names face {int(S[bad][0])}, but the file has {n_faces} faces")
    H = np.array(holes, dtype=np.int64)
    bad = (H < 0) | (H >= n_faces)
    if bad.any():
        raise MeshError(f"{path}: hole tag names face {int(H[bad][0])}, but the file has {n_faces} faces")
    return E, s, (C, Cs), np.unique(S), notes, boundary_corners, np.unique(H)


def _tag_creases(path, edges, edge_s, n_vertices, notes):
    """Crease tags as (pairs, sharpness); those of sharpness <= 0 are left out."""
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
    return E[keep], sharpness_from_file(s[keep])


def _tag_corners(path, corners, corner_s, n_vertices):
    """Corner tags as sorted vertices and their sharpness (None: all infinite); those of
    sharpness <= 0 are left out (:func:`corner_tags`)."""
    C = np.array(corners, dtype=np.int64)
    cs = np.array(corner_s, dtype=np.float64)
    bad = (C < 0) | (C >= n_vertices)
    if bad.any():
        raise MeshError(f"{path}: corner tag names vertex {int(C[bad][0])}, but the file has {n_vertices} "
                        f"vertices (0..{n_vertices - 1})")
    return corner_tags(C, cs)


def boundary_vertices(F: np.ndarray) -> np.ndarray:
    """Vertices on a boundary edge (an edge in one face).

    >>> boundary_vertices(np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 4]])).tolist()
    [1, 2, 3, 4]
    """
    if not len(F):
        return np.empty(0, np.int64)
    u, w = halfedge_ends(F)
    g = group_halfedges(u, w)
    bnd = g.sizes[g.group] == 1
    return np.unique(np.concatenate([u[bnd], w[bnd]]))


def boundary_corner_vertices(F: np.ndarray) -> np.ndarray:
    """Boundary vertices that lie in a single face: OpenSubdiv's EDGE_AND_CORNER corners.

    >>> boundary_corner_vertices(np.array([[0, 1, 2], [0, 2, 3]])).tolist()
    [1, 3]
    """
    u, w = halfedge_ends(F)
    g = group_halfedges(u, w)
    bnd = g.sizes[g.group] == 1
    nface = np.bincount(F.ravel(), minlength=int(F.max()) + 1)
    cand = np.unique(np.concatenate([u[bnd], w[bnd]]))
    return cand[nface[cand] == 1]


# ----------------------------------------------------------------------------------------------
# writing

def write_obj(path: str, m: TaggedMesh, folder: str | None = None) -> None:
    """Write ``m`` as OBJ: OpenSubdiv's tags (``t crease 2/1/0 i j s``, ``t corner 1/1/0 v s``,
    0-based, ``s = 10`` for infinitely sharp), ``t sharpface``, colours, UVs and materials
    (named from, and copied into, ``folder``: the folder the file will live in, by default
    that of ``path``; a file written under a temporary name elsewhere and moved passes it).

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "t.obj")
    >>> write_obj(path, TaggedMesh(np.eye(3), np.array([[0, 1, 2]]), corners=np.array([2])))
    >>> open(path).read().splitlines()[-2:]
    ['f 1 2 3', 't corner 1/1/0 2 10.0']
    """
    parts = [f"# hybridsub {__version__}: {len(m.vertices):,} vertices, {len(m.faces):,} triangles"
             + (f"; {describe_tags(m)}" if m.has_tags else "") + "\n",
             "# tags: OpenSubdiv's convention, 0-based vertex indices, sharpness 10 = infinitely sharp\n"]
    if m.vertex_colors is not None:
        parts += text_rows("v ", np.hstack([m.vertices, m.vertex_colors[:, :3]]), "%r")
    else:
        parts += text_rows("v ", m.vertices, "%r")
    folder = os.path.abspath(folder) if folder is not None else os.path.dirname(os.path.abspath(path))
    parts += [f"mtllib {name}\n" for name in _material_libs_for(m.material_libs, folder)]
    if m.uv is not None and m.face_uv is not None:
        parts += text_rows("vt ", m.uv, "%r")
        rows, fmt = np.stack([m.faces + 1, m.face_uv + 1], axis=2).reshape(-1, 6), "%d/%d"
    else:
        rows, fmt = m.faces + 1, "%d"
    if m.face_material is None or not m.materials:
        parts += text_rows("f ", rows, fmt)
    else:  # one usemtl line per run of faces with one material (children follow their parents)
        fm = np.asarray(m.face_material)
        cut = np.flatnonzero(np.r_[True, fm[1:] != fm[:-1]]).tolist() + [len(fm)]
        for a, b in zip(cut[:-1], cut[1:]):
            if fm[a] >= 0:
                parts.append(f"usemtl {m.materials[fm[a]]}\n")
            parts += text_rows("f ", rows[a:b], fmt)
    parts += _tag_lines(m)
    with open(path, "w") as fh:
        fh.writelines(parts)


def _tag_lines(m: TaggedMesh) -> list[str]:
    parts = []
    s = sharpness_to_file(m.sharpness)
    if len(m.sharp_edges):
        E = m.sharp_edges.tolist()
        parts.append("".join(f"t crease 2/1/0 {a} {b} {float(x)!r}\n" for (a, b), x in zip(E, s.tolist())))
    if len(m.corners):
        parts.append("".join(f"t corner 1/1/0 {v} {float(x)!r}\n"
                             for v, x in zip(m.corners.tolist(), corner_values(m).tolist())))
    S = m.sharp_faces.tolist()
    for i in range(0, len(S), 16):  # OpenSubdiv's reader takes lines of at most 255 characters
        chunk = S[i:i + 16]
        parts.append(f"t sharpface {len(chunk)}/0/0 " + " ".join(map(str, chunk)) + "\n")
    H = np.asarray(getattr(m, "holes", np.empty(0, np.int64))).tolist()
    for i in range(0, len(H), 16):
        chunk = H[i:i + 16]
        parts.append(f"t hole {len(chunk)}/0/0 " + " ".join(map(str, chunk)) + "\n")
    return parts


def _material_libs_for(libs: tuple, folder: str) -> list[str]:
    """The ``mtllib`` names of an OBJ written in ``folder``. A library in another folder is
    copied beside the file, with the texture images it names by relative path, so that the
    folder is complete and every loader finds the texture (trimesh, for one, does not follow
    ``../``); where a different file already has the name, or the library is missing, the
    line names the library relative to the new file instead."""
    out = []
    for lib in libs:
        if os.path.dirname(lib) == folder or not os.path.isfile(lib):
            out.append(_relative(lib, folder))
            continue
        target = os.path.join(folder, os.path.basename(lib))
        if not _free_or_same(lib, target):
            out.append(_relative(lib, folder))
            continue
        os.makedirs(folder, exist_ok=True)
        shutil.copyfile(lib, target)
        for ref in _mtl_images(lib):
            src = os.path.normpath(os.path.join(os.path.dirname(lib), ref))
            dst = os.path.normpath(os.path.join(folder, ref))
            if os.path.isabs(ref) or not dst.startswith(folder + os.sep) or not os.path.isfile(src):
                continue
            if _free_or_same(src, dst):
                os.makedirs(os.path.dirname(dst), exist_ok=True)
                shutil.copyfile(src, dst)
        out.append(os.path.basename(lib))
    return out


def _free_or_same(src: str, dst: str) -> bool:
    return not os.path.exists(dst) or (os.path.isfile(dst) and filecmp.cmp(src, dst, shallow=False))


def _mtl_images(lib: str) -> list[str]:
    """The files a material library names (``map_Kd``, ``bump``, …: the last word of the line)."""
    names = []
    with open(lib, encoding="utf-8", errors="replace") as fh:
        for line in fh:
            w = line.split()
            if len(w) >= 2 and (w[0].lower().startswith("map_") or w[0].lower() in ("bump", "disp", "decal", "refl")):
                names.append(w[-1])
    return names


def _relative(path: str, folder: str) -> str:
    try:
        return os.path.relpath(path, folder)
    except ValueError:  # another drive (Windows)
        return path
