"""The data model of mesh files: :class:`TaggedMesh` (a triangle mesh with its feature tags and
attributes, vertices in file order), the checks that turn arrays into one, and the tag
conventions every format shares (a file sharpness of 10 or more is infinitely sharp).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._errors import MeshError
from .._input import as_corner_mask, as_corner_sharpness, as_face_mask, as_faces, as_sharp_edges, as_vertices, count_of, tag_counts
from .._rules import INFINITE_SHARPNESS

#: Key of ``Trimesh.metadata`` under which hybridsub keeps a mesh's tags (``subdivide_mesh``'s
#: results, ``TaggedMesh.to_trimesh``; read back by ``subdivide_mesh`` and ``write_mesh``).
METADATA_KEY = "hybridsub"

#: Sharpness written for infinitely sharp creases and corners (OpenSubdiv's convention:
#: a sharpness of 10 or more is infinitely sharp).
INFINITE = INFINITE_SHARPNESS


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
    corner_sharpness : (c,) float64, or None
        The sharpness of each of ``corners`` (OBJ's ``t corner v/s``; ``inf``: infinitely
        sharp); None: all infinitely sharp. Pass it to ``corner_sharpness=``.
    holes : (h,) int64
        Faces not rendered that still shape their neighbours (OBJ's ``t hole``; pass them to
        ``holes=``).

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
    corner_sharpness: np.ndarray | None = None  # (c,) float64 beside corners (inf: infinite), None: all infinite
    holes: np.ndarray = field(default_factory=lambda: np.empty(0, np.int64))

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

    def __repr__(self) -> str:
        extra = [what for what, there in (("vertex colours", self.vertex_colors is not None),
                                          ("UVs", self.uv is not None), ("materials", bool(self.materials))) if there]
        return (f"<TaggedMesh: {count_of(len(self.vertices), 'vertex')}, {count_of(len(self.faces), 'triangle')}; "
                f"{tag_counts(self.sharp_edges, self.corners, self.sharp_faces)}"
                + "".join(f"; {e}" for e in extra) + ">")

    @property
    def has_tags(self) -> bool:
        return bool(len(self.sharp_edges) or len(self.corners) or len(self.sharp_faces) or len(self.holes))

    def tag_arrays(self) -> dict:
        """The tags as arrays by name: ``sharp_edges`` (k, 2), ``sharpness`` (k,) (``inf``:
        infinitely sharp), ``corners``, ``sharp_faces`` — what :meth:`to_trimesh` stores in
        ``metadata["hybridsub"]`` and :meth:`to_pyvista` in ``field_data``."""
        out = {"sharp_edges": np.asarray(self.sharp_edges, np.int64).reshape(-1, 2),
               "sharpness": np.asarray(self.sharpness, np.float64),
               "corners": np.asarray(self.corners, np.int64), "sharp_faces": np.asarray(self.sharp_faces, np.int64)}
        if self.corner_sharpness is not None:  # semi-sharp corners: their sharpness beside them
            out["corner_sharpness"] = np.asarray(self.corner_sharpness, np.float64)
        return out

    def to_trimesh(self):
        """This mesh as a ``trimesh.Trimesh`` (``process=False``), its tags in
        ``metadata["hybridsub"]`` (where :func:`hybridsub.subdivide_mesh` and
        :func:`hybridsub.write_mesh` look for them), vertex colours or UVs as its visual (a
        vertex per (vertex, UV) pair where the UVs have seams; the tags then name the first
        copy of each vertex, and the vertex count differs from ``len(self.vertices)``).

        Examples
        --------
        >>> import numpy as np, hybridsub
        >>> m = hybridsub.TaggedMesh(np.eye(3), np.array([[0, 1, 2]]), corners=np.array([2]))
        >>> t = m.to_trimesh()
        >>> t.faces.tolist(), t.metadata["hybridsub"]["corners"].tolist()
        ([[0, 1, 2]], [2])
        """
        import trimesh

        visual = None
        V, F, tags = self.vertices, self.faces, self.tag_arrays()
        if self.vertex_colors is not None:
            visual = trimesh.visual.ColorVisuals(vertex_colors=color_bytes(self.vertex_colors))
        elif self.vertex_uv is not None:
            visual = trimesh.visual.TextureVisuals(uv=self.vertex_uv, material=_material(self))
        elif self.uv is not None and self.face_uv is not None:  # UV seams: one vertex per (vertex, UV) pair
            corner, first = _pair_classes(F.ravel(), self.face_uv.ravel())
            copy_of = np.full(len(V), -1, np.int64)
            copy_of[F.ravel()[first][::-1]] = np.arange(len(first))[::-1]  # first copy of each vertex
            tags["sharp_edges"] = copy_of[tags["sharp_edges"]]
            tags["corners"] = copy_of[tags["corners"]]
            V, F = V[F.ravel()[first]], corner.reshape(-1, 3)
            visual = trimesh.visual.TextureVisuals(uv=self.uv[self.face_uv.ravel()[first]], material=_material(self))
        return trimesh.Trimesh(V, F, visual=visual, process=False, metadata={METADATA_KEY: tags})

    def to_pyvista(self):
        """This mesh as a ``pyvista.PolyData`` (pyvista is optional: ``pip install
        "hybridsub[pyvista]"``): colours as point data ``"colors"`` (8-bit), UVs as the active
        texture coordinates (a vertex per (vertex, UV) pair where they have seams), the tags
        in ``field_data`` as ``sharp_edges`` (k, 2), ``sharpness``, ``corners`` and
        ``sharp_faces`` (see docs/formats.md).

        Examples
        --------
        >>> import numpy as np, hybridsub
        >>> m = hybridsub.TaggedMesh(np.eye(3), np.array([[0, 1, 2]]), corners=np.array([2]))
        >>> p = m.to_pyvista()                                       # doctest: +SKIP
        >>> p.n_cells, p.field_data["corners"].tolist()              # doctest: +SKIP
        (1, [2])
        """
        import pyvista as pv

        t = self.to_trimesh()
        poly = pv.PolyData.from_regular_faces(np.asarray(t.vertices, np.float64), np.asarray(t.faces, np.int64))
        kind = getattr(t.visual, "kind", None)
        if kind == "vertex":
            poly.point_data["colors"] = np.asarray(t.visual.vertex_colors, np.uint8)
        elif kind == "texture" and getattr(t.visual, "uv", None) is not None:
            poly.active_texture_coordinates = np.asarray(t.visual.uv, np.float64)
        for k, a in t.metadata[METADATA_KEY].items():
            if np.size(a):  # pyvista refuses empty arrays: an absent tag means none
                poly.field_data[k] = a
        return poly


def _pair_classes(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Classes of equal (a, b) pairs numbered by first appearance: (class of each pair, first
    pair of each class).

    >>> [x.tolist() for x in _pair_classes(np.array([5, 1, 5]), np.array([0, 2, 0]))]
    [[0, 1, 0], [0, 1]]
    """
    keys = a.astype(np.int64) * (int(b.max(initial=0)) + 1) + b
    _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return rank[inverse.ravel()], first[order]


def _material(m: TaggedMesh):
    """The first material of ``m``'s OBJ material libraries as a trimesh material (its
    texture image loaded), or None: what lets GLB output embed the texture."""
    import trimesh

    for lib in m.material_libs:
        try:
            with open(lib, "rb") as fh:
                mats = trimesh.exchange.obj.parse_mtl(fh.read(), resolver=trimesh.resolvers.FilePathResolver(lib))
        except (OSError, ValueError):
            continue
        for name in list(m.materials) + list(mats):
            if name in mats:
                keep = ("image", "diffuse", "ambient", "specular", "glossiness")
                kw = {k: v for k, v in mats[name].items() if k in keep}
                return trimesh.visual.material.SimpleMaterial(name=name, **kw)
    return None


def check_read(path: str, mesh: TaggedMesh) -> TaggedMesh:
    """``mesh`` as read from ``path`` by any reader, checked once where every format can go wrong
    alike: faces present, three finite coordinates per vertex, every index in range (faces, tags,
    UVs), the counts that belong together equal (one sharpness per crease, one colour per vertex,
    one UV triple per face), every number finite where it must be. Every reader's output comes
    through here, so a damaged file that a reader let through is refused with the file's name.

    >>> check_read("t.off", TaggedMesh(np.array([[0, 0, 0], [1, 0, np.nan], [0, 1, 0]]), np.array([[0, 1, 2]])))
    Traceback (most recent call last):
    ...
    hybridsub._errors.MeshError: t.off: vertex 1 has a non-finite coordinate (nan): every coordinate must be a finite number
    >>> check_read("t.vtk", TaggedMesh(np.eye(3), np.array([[0, 1, 999999999999]])))
    Traceback (most recent call last):
    ...
    hybridsub._errors.MeshError: t.vtk: face 0 refers to vertex 999999999999, but there are only 3 (valid 0..2)
    """
    V, F = mesh.vertices, mesh.faces
    if F.ndim != 2 or F.shape[1] != 3 or F.dtype.kind not in "iu":
        raise MeshError(f"{path}: the faces were read as {F.dtype} of shape {F.shape}, not triangles of vertex "
                        "indices: the file is damaged")
    if len(F) == 0:
        raise MeshError(f"{path}: not a triangle mesh (it has no faces)")
    if V.ndim != 2 or V.shape[1] != 3:
        k = V.shape[1] if V.ndim == 2 else 1
        raise MeshError(f"{path}: the vertices have {k} coordinate{'s' * (k != 1)}; a vertex needs three (x y z)")
    finite = np.isfinite(V).all(axis=1)
    if not finite.all():
        i = int(np.flatnonzero(~finite)[0])
        bad = V[i][~np.isfinite(V[i])][0]
        raise MeshError(f"{path}: vertex {i} has a non-finite coordinate ({bad}): every coordinate must be a finite "
                        "number" + (f" ({int((~finite).sum()):,} such vertices)" if (~finite).sum() > 1 else ""))
    n, m = len(V), len(F)
    _in_range(path, F, n, "face", "vertex")
    E, s = mesh.sharp_edges, mesh.sharpness
    if E.ndim != 2 or E.shape[1] != 2 or E.dtype.kind not in "iu":
        raise MeshError(f"{path}: the creases were read as {E.dtype} of shape {E.shape}, not vertex pairs")
    _in_range(path, E, n, "crease", "vertex")
    if s.shape != (len(E),):
        raise MeshError(f"{path}: {count_of(len(E), 'crease')} but {s.size} sharpness values")
    bad = np.isnan(s) | (s <= 0)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise MeshError(f"{path}: crease {j} {E[j].tolist()} has sharpness {s[j]}: a crease's sharpness is a "
                        "positive number (10 or more: infinitely sharp)")
    _in_range(path, np.asarray(mesh.corners).reshape(-1, 1), n, "corner", "vertex")
    _in_range(path, np.asarray(mesh.sharp_faces).reshape(-1, 1), m, "sharp face", "face")
    c = mesh.vertex_colors
    if c is not None:
        if c.ndim != 2 or c.shape[0] != n or c.shape[1] not in (3, 4):
            raise MeshError(f"{path}: vertex colours of shape {c.shape}, for {count_of(n, 'vertex')} (one RGB or "
                            "RGBA colour per vertex)")
        if not np.isfinite(c).all():
            i = int(np.flatnonzero(~np.isfinite(c).all(axis=1))[0])
            raise MeshError(f"{path}: vertex {i} has a non-finite colour {c[i].tolist()}")
    if (mesh.uv is None) != (mesh.face_uv is None):
        raise MeshError(f"{path}: texture coordinates without their face indices (or the reverse)")
    if mesh.uv is not None:
        T, FT = mesh.uv, mesh.face_uv
        if T.ndim != 2 or T.shape[1] != 2:
            raise MeshError(f"{path}: texture coordinates of shape {T.shape}; a UV is two numbers")
        if FT.shape != F.shape or FT.dtype.kind not in "iu":
            raise MeshError(f"{path}: UV indices of shape {FT.shape} for {count_of(m, 'face')}")
        _in_range(path, FT, len(T), "face", "UV")
        if not np.isfinite(T).all():
            i = int(np.flatnonzero(~np.isfinite(T).all(axis=1))[0])
            raise MeshError(f"{path}: texture coordinate {i} is not finite ({T[i].tolist()})")
    fm = mesh.face_material
    if fm is not None and (fm.shape != (m,) or (m and (fm.min() < -1 or fm.max() >= len(mesh.materials)))):
        raise MeshError(f"{path}: the faces' materials do not match the {count_of(len(mesh.materials), 'material')}")
    return mesh


def _in_range(path: str, A: np.ndarray, n: int, row: str, what: str) -> None:
    """MeshError naming the first row of ``A`` (called ``row``) that names a ``what`` outside 0..n-1."""
    if A.size == 0:
        return
    bad = ((A < 0) | (A >= n)).any(axis=1)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        i = int(A[j][(A[j] < 0) | (A[j] >= n)][0])
        valid = f"valid 0..{n - 1}" if n else "there are none"
        raise MeshError(f"{path}: {row} {j} refers to {what} {i}, but there are only {n} ({valid})")


def sharpness_from_file(s: np.ndarray) -> np.ndarray:
    """Sharpness as read from a file: ``>= 10`` becomes ``inf``.

    >>> sharpness_from_file(np.array([2.5, 10.0, 12.0])).tolist()
    [2.5, inf, inf]
    """
    return np.where(s >= INFINITE, np.inf, s)


def corner_tags(C, s) -> tuple[np.ndarray, np.ndarray | None]:
    """Corner tags read from a file, vertex ``C[j]`` of sharpness ``s[j]`` (``>= 10``:
    infinite): the sorted corners of sharpness > 0 (a vertex listed twice takes its sharpest
    value) and their sharpness, or None where every one is infinitely sharp.

    >>> C, s = corner_tags(np.array([4, 2, 3]), np.array([10.0, 0.5, 0.0]))
    >>> C.tolist(), s.tolist()
    ([2, 4], [0.5, inf])
    """
    C = np.asarray(C, np.int64).reshape(-1)
    s = sharpness_from_file(np.asarray(s, np.float64).reshape(-1))
    keep = s > 0
    C, s = C[keep], s[keep]
    order = np.lexsort((-s, C))
    C, s = C[order], s[order]
    first = np.ones(len(C), bool)
    first[1:] = C[1:] != C[:-1]
    C, s = C[first], s[first]
    return C, (s if np.isfinite(s).any() else None)


def corner_values(m: TaggedMesh) -> np.ndarray:
    """The sharpness of each of ``m.corners`` as written to a file (10: infinitely sharp)."""
    if m.corner_sharpness is None:
        return np.full(len(m.corners), INFINITE)
    return sharpness_to_file(np.asarray(m.corner_sharpness, np.float64))


def sharpness_to_file(s: np.ndarray) -> np.ndarray:
    """Sharpness as written to a file: ``inf`` becomes 10.

    >>> sharpness_to_file(np.array([2.5, np.inf])).tolist()
    [2.5, 10.0]
    """
    return np.where(np.isinf(s), INFINITE, s)


def unit_colors(colors: np.ndarray) -> np.ndarray:
    """Colours read from a text file in [0, 1]: divided by 255 where any exceeds 1.

    >>> unit_colors(np.array([[255.0, 0.0, 51.0]])).tolist()
    [[1.0, 0.0, 0.2]]
    """
    return colors / 255.0 if colors.max(initial=0) > 1 else colors


def color_bytes(colors: np.ndarray) -> np.ndarray:
    """Colours in [0, 1] as 8-bit integers (rounded, clipped to 0..255).

    >>> color_bytes(np.array([[0.0, 0.5, 1.2]])).tolist()
    [[0, 128, 255]]
    """
    return np.clip(np.round(colors * 255), 0, 255).astype(np.uint8)


def as_tagged(vertices, faces, sharp_edges=None, sharpness=None, corners=None, sharp_faces=None,
              vertex_colors=None, uv=None, face_uv=None, corner_sharpness=None, holes=None) -> TaggedMesh:
    """Check and convert write_mesh's arguments into a TaggedMesh (fresh arrays; creases of
    sharpness 0 left out, masks turned into indices, integer colours scaled to [0, 1]).

    >>> m = as_tagged(np.eye(3), [[0, 1, 2]], corners=[False, True, False])
    >>> m.corners.tolist(), m.sharp_edges.shape
    ([1], (0, 2))
    """
    V = as_vertices(vertices)
    F, _ = as_faces(faces, len(V))
    E, s = as_sharp_edges(sharp_edges, sharpness, len(V))
    keep = s > 0
    E, s = E[keep], s[keep]
    mask, vs = as_corner_sharpness(corners, corner_sharpness, len(V))
    C = np.flatnonzero(mask)
    Cs = None if vs is None else vs[C]
    S = np.flatnonzero(as_face_mask(sharp_faces, len(F))[0])
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
    H = np.flatnonzero(as_face_mask(holes, len(F), "holes")[0])
    return TaggedMesh(V.copy() if V is vertices else V, F, E, s, C, S, colors, T, FT, corner_sharpness=Cs, holes=H)


def describe_tags(mesh: TaggedMesh) -> str:
    """The tags of ``mesh`` in words ('' when it has none).

    Examples
    --------
    >>> import numpy as np
    >>> m = TaggedMesh(np.eye(3), np.array([[0, 1, 2]]), sharp_edges=np.array([[0, 1]]), corners=np.array([2]))
    >>> describe_tags(m)
    '1 crease, 1 corner'
    """
    parts = []
    if len(mesh.sharp_edges):
        parts.append(count_of(len(mesh.sharp_edges), "crease"))
    if len(mesh.corners):
        parts.append(count_of(len(mesh.corners), "corner"))
    if len(mesh.sharp_faces):
        parts.append(count_of(len(mesh.sharp_faces), "sharp face"))
    if len(mesh.holes):
        parts.append(count_of(len(mesh.holes), "hole"))
    return ", ".join(parts)

