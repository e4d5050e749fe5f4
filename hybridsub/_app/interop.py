"""trimesh in, trimesh out (and pyvista in, pyvista out): ``subdivide_mesh``."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from .. import _input as val
from .._io import METADATA_KEY, classes, kind_of
from .._errors import MeshError
from .._input import detect_features, merge_detected, merge_edges
from .._refiner import Refinement, refine
from .._typing import ArrayLike, Boundary, LoopWeights, NonManifold, Scheme, UVMode

if TYPE_CHECKING:  # pragma: no cover
    import pyvista
    import trimesh


def subdivide_mesh(mesh: trimesh.Trimesh | pyvista.PolyData, levels: int = 1, *, scheme: Scheme = "hybrid",
                   sharp_edges: ArrayLike | None = None, sharpness: ArrayLike | None = None,
                   sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
                   feature_angle: float | None = None, loop_weights: LoopWeights = "loop",
                   weld: bool | None = None, uv_mode: UVMode = "linear",
                   non_manifold: NonManifold = "raise", progress: bool | None = False,
                   holes: ArrayLike | None = None, uv_interpolation: str | None = None,
                   corner_sharpness: ArrayLike | None = None, boundary: Boundary = "edge_only") -> Any:
    """Subdivide a ``trimesh.Trimesh`` or a ``pyvista.PolyData``, carrying its attributes and
    features along; the result is of the type given.

    Per-vertex data — colours, every array in ``mesh.vertex_attributes`` — is refined by the
    refinement matrix (the same affine combinations as the positions; colours are rounded
    back to 8 bits). Per-face data — face colours, every array in ``mesh.face_attributes`` —
    is copied from the input face each new face lies in (``face_parent``). The texture image
    and material are kept. Vertex normals are not carried: trimesh recomputes them from the
    refined surface.

    **Textured meshes.** trimesh stores texture coordinates per vertex, so a textured mesh
    has its vertices duplicated along UV seams. Refined as stored, each seam would be an open
    boundary (a crease, and a crack in the surface). With ``weld`` (the default for a mesh
    with texture coordinates) vertices at exactly the same position are merged for the
    geometry, each vertex copy becomes a UV index (copies with equal UVs and equal data are
    one), and the UVs are refined face-varying (:func:`hybridsub.subdivide_face_varying`):
    the surface stays smooth and closed across seams, the texture keeps its seams. The
    result again has one vertex per (position, UV) pair, so it renders with the same
    material. Per-vertex arrays equal on every copy of a welded vertex follow the surface
    (as above); arrays that differ between copies are per-corner data and follow the UVs.

    Feature tags come from the arguments, from ``feature_angle`` (creases detected by
    dihedral angle, and their corners), or, when neither is given, from
    ``mesh.metadata["hybridsub"]`` — where the result stores its own propagated tags, so that
    subdividing the result again keeps the same features.

    **pyvista.** A triangle ``PolyData`` is refined the same way: point data as per-vertex
    data (through the refinement, like positions; the active normals left out), cell data as
    per-face data (through ``face_parent``), the active texture coordinates as UVs (welded and
    refined face-varying as above), the tags read from and written to ``field_data`` as
    ``sharp_edges`` (k, 2), ``sharpness``, ``corners`` and ``sharp_faces`` (the result also
    holds ``face_parent``). pyvista is optional: ``pip install "hybridsub[pyvista]"``.

    Parameters
    ----------
    mesh : trimesh.Trimesh or pyvista.PolyData
        A triangle mesh, consistently oriented, every edge in one or two faces (after welding,
        if welded). Not modified.
    levels : int
        Number of subdivision steps.
    scheme : {"hybrid", "sqrt3", "loop"}
        ``"sqrt3"`` cannot keep UV seams: with a welded textured mesh it raises ``ValueError``
        (use ``weld=False`` to refine the mesh as stored, seams open).
    sharp_edges, sharpness, sharp_faces, corners, corner_sharpness, boundary
        As for :func:`hybridsub.subdivide`, in ``mesh``'s vertex and face indices (welded
        copies of a corner take its sharpest value).
    feature_angle : float, optional
        Also tag what :func:`hybridsub.detect_features` finds at this dihedral angle (degrees),
        by the rule of :func:`hybridsub.subdivide`: its sharp edges (infinitely sharp, unless
        given in ``sharp_edges``, whose sharpness then wins) and corners.
    loop_weights : {"loop", "warren"}
    weld : bool, optional
        Merge vertices at exactly equal positions (bit for bit, as exporters write both
        copies of a seam vertex) before refining, as described above. Default: True for a
        mesh with per-vertex texture coordinates or with vertices at equal positions (a
        triangle soup, such as ``trimesh.load("part.stl", process=False)``, which would
        otherwise be refined as separate triangles), else False. Two parts that touch at a vertex
        are joined there (a bow-tie, refined as a corner); parts that share an edge or a face
        make the welded mesh invalid, which raises ``MeshError`` — pass ``weld=False`` for
        such a mesh.
    non_manifold : {"raise", "cut"}
        As in :func:`hybridsub.refine`: ``"raise"`` (default) refuses edges in three or more
        faces and inconsistently oriented ones, naming the edge; ``"cut"`` cuts the mesh along
        them (they become creases) and refines the pieces.
    holes : (m,) bool mask or array_like of int, optional
        Faces not rendered that still shape their neighbours (:func:`hybridsub.refine`): the
        result leaves out the faces descending from them (and their face attributes).
    uv_mode : {"linear", "smooth"}
        With a welded mesh: how UVs (and per-corner data) are refined, as in
        :func:`hybridsub.subdivide_face_varying`. ``"linear"`` (default) never distorts the
        texture.
    uv_interpolation : {"none", "corners_only", "corners_plus1", "corners_plus2", "boundaries", "all"}, optional
        OpenSubdiv's face-varying modes, replacing ``uv_mode`` when given (``docs/face_varying.md``).
    progress : bool or None
        Show a progress bar (tqdm: a line on a terminal, a widget in a notebook) per level;
        None: only where stderr is a terminal.

    Returns
    -------
    trimesh.Trimesh or pyvista.PolyData
        The refined mesh (``process=False``: vertex order is hybridsub's index layout; welded,
        it is the UV index layout of ``docs/face_varying.md``: the input's vertices first,
        copies with equal position, UV and data merged).
        ``metadata["hybridsub"]`` holds ``sharp_edges``, ``sharpness``, ``corners``,
        ``sharp_faces`` (indices), ``face_parent``, ``scheme`` and ``levels``, and with
        semi-sharp corners their ``corner_sharpness`` left (each decayed by ``levels``).

    Examples
    --------
    >>> import numpy as np, trimesh, hybridsub
    >>> V, F = hybridsub.load_example()
    >>> mesh = trimesh.Trimesh(V, F, process=False)
    >>> mesh.visual.vertex_colors = np.tile([200, 30, 30, 255], (len(V), 1))
    >>> fine = hybridsub.subdivide_mesh(mesh, levels=2, feature_angle=30)
    >>> len(fine.faces), fine.visual.vertex_colors[0].tolist()
    (123734, [200, 30, 30, 255])
    >>> again = hybridsub.subdivide_mesh(fine)    # the creases travel in fine.metadata
    >>> len(again.metadata["hybridsub"]["sharp_edges"])
    5776
    >>> box = trimesh.creation.box()                       # 8 vertices, 12 faces
    >>> soup = trimesh.Trimesh(box.vertices[box.faces].reshape(-1, 3), np.arange(36).reshape(-1, 3),
    ...                        visual=trimesh.visual.TextureVisuals(uv=np.arange(72).reshape(36, 2) / 72),
    ...                        process=False)                  # every face its own UV triangle
    >>> fine = hybridsub.subdivide_mesh(soup, levels=2)    # welded: one closed surface, UV seams kept
    >>> len(np.unique(fine.vertices, axis=0)), len(fine.vertices), fine.visual.uv.shape
    (146, 228, (228, 2))
    """
    kind = kind_of(mesh)
    if kind == "pyvista":
        from .pyvista_interop import polydata_as_trimesh, trimesh_as_polydata

        uv_name = mesh.point_data.active_texture_coordinates_name
        fine = subdivide_mesh(polydata_as_trimesh(mesh), levels, scheme=scheme, sharp_edges=sharp_edges,
                              sharpness=sharpness, sharp_faces=sharp_faces, corners=corners,
                              feature_angle=feature_angle, loop_weights=loop_weights, weld=weld, uv_mode=uv_mode,
                              non_manifold=non_manifold, progress=progress, holes=holes,
                              uv_interpolation=uv_interpolation, corner_sharpness=corner_sharpness,
                              boundary=boundary)
        return trimesh_as_polydata(fine, uv_name)
    if kind != "trimesh":
        raise TypeError(f"mesh must be a trimesh.Trimesh or a pyvista.PolyData, got {type(mesh).__name__} "
                        "(for a trimesh Scene: trimesh.util.concatenate(scene.dump()) or scene.to_geometry(); for "
                        "arrays: hybridsub.subdivide(V, F, ...))")
    import trimesh

    V = val.as_vertices(np.array(mesh.vertices, dtype=np.float64))
    F = np.array(mesh.faces, dtype=np.int64).reshape(-1, 3)
    n = len(V)
    stored = mesh.metadata.get(METADATA_KEY) if isinstance(mesh.metadata, dict) else None
    if (sharp_edges is None and sharp_faces is None and corners is None and feature_angle is None
            and isinstance(stored, dict) and scheme != "sqrt3"):
        sharp_edges, sharpness = stored.get("sharp_edges"), stored.get("sharpness")
        sharp_faces, corners = stored.get("sharp_faces"), stored.get("corners")
        if corner_sharpness is None and corners is not None:
            corner_sharpness = stored.get("corner_sharpness")
    uv = _vertex_uv(mesh)
    if weld is None:  # a triangle soup (STL loaded with process=False) or a textured mesh's seam copies
        weld = uv is not None or len(np.unique(V, axis=0)) < n
    if not isinstance(weld, (bool, np.bool_)):
        raise TypeError(f"weld must be True, False or None, got {weld!r}")
    data = _vertex_arrays(mesh, n)
    w = _weld(V, F, uv, data) if weld else _Weld.identity(V, F)
    if w.face_varying and scheme == "sqrt3":
        raise ValueError(
            'scheme="sqrt3" cannot keep UV seams (Kobbelt\'s √3 flips every edge, and a flip across a seam makes '
            'a triangle spanning two UV charts); use scheme="hybrid" or "loop", or weld=False to refine the mesh '
            "as stored (its seams open, as boundaries)")

    edges_w, sharp_w, corners_w, csharp_w = _welded_tags(w, n, sharp_edges, sharpness, corners, corner_sharpness,
                                                         feature_angle)

    try:
        r = refine(w.F, edges_w, levels, n_vertices=len(w.V), scheme=scheme, sharpness=sharp_w,
                   sharp_faces=sharp_faces, corners=corners_w, loop_weights=loop_weights,
                   uv_faces=w.FUV if w.face_varying else None, uv_mode=uv_mode,
                   n_uvs=w.n_corners if w.face_varying else None, non_manifold=non_manifold,
                   progress=progress, holes=holes, uv_interpolation=uv_interpolation,
                   corner_sharpness=csharp_w, boundary=boundary)
    except MeshError as e:
        if not w.welded:
            raise
        merged = val.count_of(n - len(w.V), "vertex")
        raise MeshError(f"{e} — in the welded mesh ({merged} at the position of an earlier one merged, vertices "
                        "numbered by first appearance); pass weld=False to subdivide the mesh as stored") from None
    parent = r.face_parent
    out = _Output(r, w)
    visual = _refine_visual(mesh, out, parent, uv)
    vattr = {k: out.vertex_data(a, ("attribute", k)) for k, a in mesh.vertex_attributes.items()
             if ("attribute", k) in data}
    fattr = {k: np.asarray(a)[parent] for k, a in mesh.face_attributes.items()
             if np.ndim(a) >= 1 and len(a) == len(F)}
    sf = np.asarray(r.sharp_faces)
    metadata = dict(mesh.metadata) if isinstance(mesh.metadata, dict) else {}
    edges, sharp_out = out.edges(r.sharp_edges, r.sharpness)
    metadata[METADATA_KEY] = {
        "sharp_edges": edges, "sharpness": sharp_out, "corners": out.vertices_of(r.corners),
        "sharp_faces": np.flatnonzero(sf) if sf.dtype == bool else sf,
        "face_parent": parent, "scheme": scheme, "levels": int(levels),
    }
    if r.corner_sharpness is not None:  # one value per output vertex of each corner
        metadata[METADATA_KEY]["corner_sharpness"] = out.vertex_values_of(r.corners, r.corner_sharpness)
    return trimesh.Trimesh(out.positions(), out.faces, visual=visual, process=False, validate=False,
                           metadata=metadata, vertex_attributes=vattr, face_attributes=fattr)


def _welded_tags(w: _Weld, n: int, sharp_edges, sharpness, corners, corner_sharpness, feature_angle):
    """The caller's tags in the welded vertex numbers (edges, their sharpness, corners, the
    corners' sharpness), and the features detected on the welded mesh merged in by the gate's
    rule (:func:`merge_detected`: the caller's sharpness wins, as in
    :func:`hybridsub.subdivide`; detected corners infinitely sharp); None where there are none."""
    edges_w: np.ndarray | None = None
    sharp_w: np.ndarray | None = None
    corners_w: np.ndarray | None = None
    vs_w: np.ndarray | None = None  # (n_w,) every welded vertex's sharpness, with semi-sharp corners
    if sharp_edges is not None:
        pairs, sharp_w = val.as_sharp_edges(sharp_edges, sharpness, n)
        edges_w = w.geo[pairs]
        same = edges_w[:, 0] == edges_w[:, 1]
        if same.any():
            i = int(np.flatnonzero(same)[0])
            raise MeshError(f"sharp edge {i} = {pairs[i].tolist()} joins two vertices at the same position, which "
                            "welding merges; pass weld=False, or drop that edge")
    elif sharpness is not None and np.size(sharpness):
        raise ValueError("sharpness was given without sharp_edges")
    if corners is not None:
        mask, vs = val.as_corner_sharpness(corners, corner_sharpness, n)
        corners_w = np.unique(w.geo[np.flatnonzero(mask)])
        if vs is not None:
            vs_w = np.zeros(len(w.V))
            np.maximum.at(vs_w, w.geo, vs)  # copies of one corner: its sharpest value
    elif corner_sharpness is not None:
        raise ValueError("corner_sharpness was given without corners")
    if feature_angle is not None:
        feat = detect_features(w.V, w.F, feature_angle)
        nw = len(w.V)
        if edges_w is None:
            edges_w, sharp_w = np.empty((0, 2), np.int64), np.empty(0)
        else:  # copies of one edge welded into one: the caller's own tags, the largest kept
            edges_w, sharp_w = merge_edges(edges_w, sharp_w, nw)
        mask = np.zeros(nw, bool)
        mask[np.empty(0, np.int64) if corners_w is None else corners_w] = True
        edges_w, sharp_w, mask = merge_detected(feat, edges_w, sharp_w, mask, nw)
        corners_w = np.flatnonzero(mask)
        if vs_w is not None:
            vs_w[mask & (vs_w == 0)] = np.inf
    csharp_w = None if vs_w is None or corners_w is None else vs_w[corners_w]
    return edges_w, sharp_w, corners_w, csharp_w


# ---------------------------------------------------------------------------------------
# Welding: the geometric mesh and the UV index mesh of a mesh with duplicated vertices.


class _Weld(NamedTuple):
    V: np.ndarray  # (n_w, 3) welded positions
    F: np.ndarray  # (m, 3) faces on them
    geo: np.ndarray  # (n,) welded vertex of each mesh vertex
    geo_first: np.ndarray  # (n_w,) a mesh vertex at each welded vertex (its first)
    FUV: np.ndarray | None  # (m, 3) corner class (UV index) of each face corner
    corner_first: np.ndarray | None  # (t,) a mesh vertex of each corner class (its first)
    varying: frozenset  # names of per-vertex arrays that differ between copies: per-corner data
    welded: bool
    face_varying: bool  # refine face-varying (UVs, or arrays that differ between copies)

    @property
    def n_corners(self) -> int:
        return 0 if self.corner_first is None else len(self.corner_first)

    @staticmethod
    def identity(V, F) -> _Weld:
        idx = np.arange(len(V), dtype=np.int64)
        return _Weld(V, F, idx, idx, None, None, frozenset(), False, False)


def _weld(V, F, uv, data: dict) -> _Weld:
    n = len(V)
    geo, geo_first = classes([V], n)
    Fg = geo[F]
    degenerate = (Fg[:, 0] == Fg[:, 1]) | (Fg[:, 1] == Fg[:, 2]) | (Fg[:, 2] == Fg[:, 0])
    if degenerate.any():
        f = int(np.flatnonzero(degenerate)[0])
        many = val.count_of(degenerate.sum(), "such face")
        raise MeshError(f"face {f} = {F[f].tolist()} has two corners at the same position (at {V[F[f]].tolist()}), "
                        f"so it collapses when coincident vertices are welded ({many}); "
                        "remove such faces (trimesh: mesh.update_faces(mesh.nondegenerate_faces())), or pass "
                        "weld=False")
    varying = frozenset(k for k, A in data.items() if not _same_on_copies(A, geo, geo_first))
    keys = [geo] + ([uv] if uv is not None else []) + [data[k] for k in sorted(varying)]
    corner, corner_first = classes(keys, n)
    return _Weld(np.ascontiguousarray(V[geo_first]), np.ascontiguousarray(Fg), geo, geo_first,
                 np.ascontiguousarray(corner[F]), corner_first, varying, True, uv is not None or bool(varying))


def _same_on_copies(A: np.ndarray, geo: np.ndarray, geo_first: np.ndarray) -> bool:
    A = np.asarray(A).reshape(len(geo), -1)
    return bool(np.array_equal(A, A[geo_first[geo]], equal_nan=A.dtype.kind in "fc"))


class _Output:
    """The refined mesh in output vertices: welded face-varying, one per fine UV index."""

    def __init__(self, r: Refinement, w: _Weld):
        self.r, self.w = r, w
        self.faces: np.ndarray = r.faces
        self.geo_of: np.ndarray | None = None  # welded fine vertex of each output vertex
        self.uv_r: Refinement | None = r.uv_refinement
        self.corner_first = np.empty(0, np.int64) if w.corner_first is None else w.corner_first
        if r.uv_faces is not None and self.uv_r is not None:
            self.faces = r.uv_faces
            geo_of = np.empty(self.uv_r.n_vertices, np.int64)
            geo_of[: len(self.corner_first)] = w.geo[self.corner_first]  # unused corners keep their vertex
            geo_of[r.uv_faces.ravel()] = r.faces.ravel()
            self.geo_of = geo_of

    def positions(self) -> np.ndarray:
        V2 = self.r.apply(self.w.V)
        return V2 if self.geo_of is None else V2[self.geo_of]

    def vertex_data(self, a, name: tuple) -> np.ndarray:
        """Refine an (n, ...) per-mesh-vertex array: on the surface, or per corner if it varies."""
        A = np.asarray(a)
        if name in self.w.varying and self.uv_r is not None:
            return _refine_vertex_data(self.uv_r, A[self.corner_first])
        out = _refine_vertex_data(self.r, A[self.w.geo_first])
        return out if self.geo_of is None else out[self.geo_of]

    def uv(self, uv: np.ndarray) -> np.ndarray:
        if self.uv_r is not None:
            return self.uv_r.apply(uv[self.corner_first])
        return self.r.apply(uv[self.w.geo_first])

    def vertex_values_of(self, v: np.ndarray, values: np.ndarray) -> np.ndarray:
        """``values`` of the welded vertices ``v``, at the output vertices :meth:`vertices_of` gives."""
        if self.geo_of is None:
            return np.asarray(values, np.float64)
        full = np.zeros(self.r.n_vertices)
        full[np.asarray(v, np.int64)] = values
        return full[self.geo_of[self.vertices_of(v)]]

    def vertices_of(self, v: np.ndarray) -> np.ndarray:
        """Output vertices at the welded vertices ``v`` (every copy)."""
        if self.geo_of is None:
            return np.asarray(v, dtype=np.int64)
        return np.flatnonzero(np.isin(self.geo_of, v))

    def edges(self, pairs: np.ndarray, sharp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Welded vertex pairs as output vertex pairs: one copy of each, an edge of the output."""
        if self.geo_of is None or not len(pairs):
            return pairs, sharp
        G, T = self.r.faces, self.faces
        u, w = G.ravel(), np.roll(G, -1, axis=1).ravel()
        n = self.r.n_vertices
        key = np.minimum(u, w) * n + np.maximum(u, w)
        order = np.argsort(key, kind="stable")
        want = np.minimum(pairs[:, 0], pairs[:, 1]) * n + np.maximum(pairs[:, 0], pairs[:, 1])
        h = order[np.searchsorted(key[order], want)]
        tu, tw = T.ravel(), np.roll(T, -1, axis=1).ravel()
        return np.stack([tu[h], tw[h]], axis=1), sharp


def _vertex_uv(mesh) -> np.ndarray | None:
    vis = mesh.visual
    if getattr(vis, "kind", None) != "texture":
        return None
    uv = getattr(vis, "uv", None)
    if uv is None or len(uv) != len(mesh.vertices):
        return None
    U = np.array(uv, dtype=np.float64)
    bad = ~np.isfinite(U).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise MeshError(f"mesh.visual.uv[{i}] is not finite: {U[i].tolist()} ({int(bad.sum())} such vertices)")
    return U


def _vertex_arrays(mesh, n: int) -> dict:
    """Per-vertex arrays carried to the result: numeric vertex attributes and vertex colours."""
    out = {("attribute", k): np.asarray(a) for k, a in mesh.vertex_attributes.items()
           if np.ndim(a) >= 1 and len(a) == n and np.asarray(a).dtype.kind in "biuf"}
    if getattr(mesh.visual, "kind", None) == "vertex":
        out[_COLORS] = np.asarray(mesh.visual.vertex_colors)
    return out


_COLORS = ("visual", "vertex_colors")  # key of the vertex colours among the per-vertex arrays


def _refine_vertex_data(r, a) -> np.ndarray:
    A = np.asarray(a)
    out = r.apply(A)
    if A.dtype.kind in "iu":
        info = np.iinfo(A.dtype)
        return np.clip(np.round(out), info.min, info.max).astype(A.dtype)
    if A.dtype.kind == "b":
        return out >= 0.5
    return out


def _refine_visual(mesh, out: _Output, parent, uv) -> Any:
    import trimesh

    vis = mesh.visual
    kind = getattr(vis, "kind", None)
    if kind == "vertex":
        return trimesh.visual.ColorVisuals(vertex_colors=out.vertex_data(vis.vertex_colors, _COLORS))
    if kind == "face":
        return trimesh.visual.ColorVisuals(face_colors=np.asarray(vis.face_colors)[parent])
    if kind == "texture":
        if uv is not None:
            return trimesh.visual.TextureVisuals(uv=out.uv(uv), material=vis.material)
        return trimesh.visual.TextureVisuals(material=vis.material)
    return None
