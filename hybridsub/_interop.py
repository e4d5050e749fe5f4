"""trimesh in, trimesh out: ``subdivide_mesh``."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ._features import detect_features
from ._refine import refine
from ._typing import ArrayLike, LoopWeights, Scheme

if TYPE_CHECKING:  # pragma: no cover
    import trimesh

#: Key of ``Trimesh.metadata`` under which ``subdivide_mesh`` stores the propagated tags.
METADATA_KEY = "hybridsub"


def subdivide_mesh(mesh: trimesh.Trimesh, levels: int = 1, *, scheme: Scheme = "hybrid",
                   sharp_edges: ArrayLike | None = None, sharpness: ArrayLike | None = None,
                   sharp_faces: ArrayLike | None = None, corners: ArrayLike | None = None,
                   feature_angle: float | None = None, loop_weights: LoopWeights = "loop") -> trimesh.Trimesh:
    """Subdivide a ``trimesh.Trimesh``, carrying its attributes and features along.

    Per-vertex data — colours, texture coordinates stored per vertex, every array in
    ``mesh.vertex_attributes`` — is refined by the refinement matrix (the same affine
    combinations as the positions; colours are rounded back to 8 bits). Per-face data — face
    colours, every array in ``mesh.face_attributes`` — is copied from the input face each new
    face lies in (``face_parent``). The texture image and material are kept. Vertex normals
    are not carried: trimesh recomputes them from the refined surface.

    Feature tags come from the arguments, from ``feature_angle`` (creases detected by
    dihedral angle, and their corners), or, when neither is given, from
    ``mesh.metadata["hybridsub"]`` — where the result stores its own propagated tags, so that
    subdividing the result again keeps the same features.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        A triangle mesh, consistently oriented, every edge in one or two faces. Not modified.
    levels : int
        Number of subdivision steps.
    scheme : {"hybrid", "sqrt3", "loop"}
    sharp_edges, sharpness, sharp_faces, corners
        As for :func:`hybridsub.subdivide`, in ``mesh``'s vertex and face indices.
    feature_angle : float, optional
        Also tag every edge whose dihedral angle exceeds this many degrees as a crease, and
        vertices with three or more creases as corners.
    loop_weights : {"loop", "warren"}

    Returns
    -------
    trimesh.Trimesh
        The refined mesh (``process=False``: vertex order is hybridsub's index layout).
        ``metadata["hybridsub"]`` holds ``sharp_edges``, ``sharpness``, ``corners``,
        ``sharp_faces`` (indices), ``face_parent``, ``scheme`` and ``levels``.

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
    """
    import trimesh

    if not isinstance(mesh, trimesh.Trimesh):
        raise TypeError(f"mesh must be a trimesh.Trimesh, got {type(mesh).__name__} "
                        "(for a Scene: trimesh.util.concatenate(scene.dump()) or scene.to_geometry())")
    V = np.array(mesh.vertices, dtype=np.float64)
    F = np.array(mesh.faces, dtype=np.int64)
    stored = mesh.metadata.get(METADATA_KEY) if isinstance(mesh.metadata, dict) else None
    if (sharp_edges is None and sharp_faces is None and corners is None and feature_angle is None
            and isinstance(stored, dict) and scheme != "sqrt3"):
        sharp_edges, sharpness = stored.get("sharp_edges"), stored.get("sharpness")
        sharp_faces, corners = stored.get("sharp_faces"), stored.get("corners")
    if feature_angle is not None:
        feat = detect_features(V, F, feature_angle)
        if sharp_edges is None:
            sharp_edges, sharpness = feat.sharp_edges, None
        else:
            E = np.asarray(sharp_edges, dtype=np.int64).reshape(-1, 2)
            s = np.full(len(E), np.inf) if sharpness is None else np.asarray(sharpness, dtype=np.float64)
            sharp_edges = np.vstack([E, feat.sharp_edges])
            sharpness = np.concatenate([s, np.full(len(feat.sharp_edges), np.inf)])
        if corners is None:
            corners = feat.corners
        else:
            c = np.asarray(corners)
            c = np.flatnonzero(c) if c.dtype == bool else c.astype(np.int64).ravel()
            corners = np.union1d(c, feat.corners)
    r = refine(F, sharp_edges, levels, n_vertices=len(V), scheme=scheme, sharpness=sharpness,
               sharp_faces=sharp_faces, corners=corners, loop_weights=loop_weights)
    V2 = r.apply(V)
    parent = r.face_parent

    visual = _refine_visual(mesh, r, parent)
    vattr = {k: _refine_vertex_data(r, a) for k, a in mesh.vertex_attributes.items()
             if np.ndim(a) >= 1 and len(a) == len(V) and np.asarray(a).dtype.kind in "biuf"}
    fattr = {k: np.asarray(a)[parent] for k, a in mesh.face_attributes.items()
             if np.ndim(a) >= 1 and len(a) == len(F)}
    sf = np.asarray(r.sharp_faces)
    metadata = dict(mesh.metadata) if isinstance(mesh.metadata, dict) else {}
    metadata[METADATA_KEY] = {
        "sharp_edges": r.sharp_edges, "sharpness": r.sharpness, "corners": r.corners,
        "sharp_faces": np.flatnonzero(sf) if sf.dtype == bool else sf,
        "face_parent": parent, "scheme": scheme, "levels": int(levels),
    }
    return trimesh.Trimesh(V2, r.faces, visual=visual, process=False, validate=False, metadata=metadata,
                           vertex_attributes=vattr, face_attributes=fattr)


def _refine_vertex_data(r, a) -> np.ndarray:
    A = np.asarray(a)
    out = r.apply(A)
    if A.dtype.kind in "iu":
        info = np.iinfo(A.dtype)
        return np.clip(np.round(out), info.min, info.max).astype(A.dtype)
    if A.dtype.kind == "b":
        return out >= 0.5
    return out


def _refine_visual(mesh, r, parent) -> Any:
    import trimesh

    vis = mesh.visual
    kind = getattr(vis, "kind", None)
    if kind == "vertex":
        return trimesh.visual.ColorVisuals(vertex_colors=_refine_vertex_data(r, vis.vertex_colors))
    if kind == "face":
        return trimesh.visual.ColorVisuals(face_colors=np.asarray(vis.face_colors)[parent])
    if kind == "texture":
        uv = getattr(vis, "uv", None)
        if uv is not None and len(uv) == len(mesh.vertices):
            return trimesh.visual.TextureVisuals(uv=r.apply(np.asarray(uv, dtype=np.float64)),
                                                 material=vis.material)
        return trimesh.visual.TextureVisuals(material=vis.material)
    return None
