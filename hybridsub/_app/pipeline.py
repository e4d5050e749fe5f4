"""One mesh file subdivided: read → features → refine → write.

The code of ``hybridsub subdivide`` and of every :func:`hybridsub.batch` task (so a batch's
outputs equal the command's byte for byte), and the pieces ``compare``, ``info`` and ``demo``
share with it. It is driven by :class:`FileOptions`, a frozen description of one run: the
command line builds it from its arguments, a batch task from the batch's keyword arguments.
What goes wrong with the input or the run is a :class:`PipelineError`, whose message is the one
line the command prints.
"""

from __future__ import annotations

import os
import sys
import time
from dataclasses import dataclass, field, replace

import numpy as np

from .. import _io
from .._errors import MeshError, OutputTooLargeError
from .._input import count_of, detect_features, merge_edges
from .._io import TaggedMesh
from .._refiner import cgroup_memory_limit, physical_memory, predict_levels, seam_edges
from .._rules import normalize_sharpness
from .._topology import edge_keys, undirected_edges
from .._units import rate, short_bytes
from .progress import ProgressBar, refine_by_level

SCHEME_NAMES = {"hybrid": "hybrid √3–Loop", "sqrt3": "Kobbelt √3", "loop": "Loop"}


class PipelineError(Exception):
    """An error with the input or the run, to report in one line (the command's exit code 1)."""


@dataclass(frozen=True)
class FileOptions:
    """How to subdivide one file: the options of ``hybridsub subdivide``.

    Attributes
    ----------
    levels, scheme, loop_weights
        As for :func:`hybridsub.subdivide`.
    feature_angle, feature_sharpness : float, optional
        Detect creases above this dihedral angle (``--feature-angle``), with this sharpness
        (``--feature-sharpness``; None: infinitely sharp, with corners).
    uv_mode : {"linear", "smooth"}, optional
        How texture coordinates are refined; None: linear, or dropped with a note under ``"sqrt3"``.
    sharp_edges_file, sharp_faces_file, corners_file : str, optional
        Tag lists (``--sharp-edges``, ``--sharp-faces``, ``--corners``), 0-based indices.
    ignore_tags, triangulate, weld, no_tags, ascii
        ``--ignore-tags`` (tags stored in the input), ``--triangulate``, ``--weld`` (on
        reading), ``--no-tags``, ``--ascii`` (on writing).
    non_manifold : {"raise", "cut"}
        ``--non-manifold``: as :func:`hybridsub.subdivide`'s ``non_manifold``.
    boundary : {"edge_only", "edge_and_corner", "none"}
        ``--boundary``: as :func:`hybridsub.subdivide`'s ``boundary``.
    force : bool
        Run even if the memory estimate exceeds the memory at hand (and lift the library's limit).
    quiet : bool
        No messages and no progress bar.
    memory_limit : int, optional
        Bytes this run may use where less than the machine's RAM (a Dask worker's limit).
    tolerance : str, optional
        Adaptive refinement (``--tolerance``): refine until within this distance of the limit
        surface, in mesh units or as ``"0.1%"`` of the bounding-box diagonal; ``levels`` is then
        not used. See :func:`hybridsub.subdivide_adaptive`.
    max_levels : int
        With ``tolerance``: the most levels any face gets (``--max-levels``).

    Examples
    --------
    >>> opts = FileOptions(levels=2, feature_angle=30.0, quiet=True)
    >>> opts.scheme, replace(opts, scheme="loop").scheme
    ('hybrid', 'loop')
    """

    levels: int = 1
    scheme: str = "hybrid"
    feature_angle: float | None = None
    feature_sharpness: float | None = None
    loop_weights: str = "loop"
    uv_mode: str | None = None
    sharp_edges_file: str | None = None
    sharp_faces_file: str | None = None
    corners_file: str | None = None
    ignore_tags: bool = False
    triangulate: bool = False
    weld: bool = False
    non_manifold: str = "raise"
    boundary: str = "edge_only"
    no_tags: bool = False
    ascii: bool = False
    force: bool = False
    quiet: bool = False
    memory_limit: int | None = None
    tolerance: str | None = None
    max_levels: int = 8


@dataclass
class FileFeatures:
    """The tags a run refines with, gathered from every source, and its one-line summary."""

    sharp_edges: np.ndarray
    sharpness: np.ndarray
    sharp_faces: np.ndarray
    corners: np.ndarray
    summary: str
    corner_sharpness: np.ndarray | None = None  # beside corners, None: all infinitely sharp

    @staticmethod
    def none(summary: str) -> FileFeatures:
        return FileFeatures(np.empty((0, 2), np.int64), np.empty(0), np.empty(0, np.int64), np.empty(0, np.int64),
                            summary)

    def tags(self) -> dict:
        t = dict(sharp_edges=self.sharp_edges, sharpness=self.sharpness, sharp_faces=self.sharp_faces,
                 corners=self.corners)
        if self.corner_sharpness is not None:
            t["corner_sharpness"] = self.corner_sharpness
        return t


@dataclass
class FileResult:
    """What :func:`subdivide_file` made, for the batch manifest."""

    faces_in: int
    faces_out: int
    vertices_out: int
    features: str  # the feature summary, as the command prints it
    notes: list[str]  # what the reader did (from TaggedMesh.notes)
    seconds_read: float
    seconds_refine: float
    seconds_write: float


def say(opts: FileOptions, *msg) -> None:
    """A message on stderr, unless ``opts.quiet``."""
    if not opts.quiet:
        print(*msg, file=sys.stderr)


def load_mesh(opts: FileOptions, path: str) -> TaggedMesh:
    """Read ``path`` (``triangulate``, ``weld``), saying what the reader did."""
    mesh = _io.read_mesh(path, triangulate=opts.triangulate)
    for note in mesh.notes:
        say(opts, f"note: {path}: {note}")
    if opts.weld:
        mesh, merged, dropped = _io.weld(mesh)
        say(opts, f"note: welded {merged:,} duplicate vertices" + (f", dropped {dropped:,} collapsed faces"
                                                                    if dropped else ""))
    return mesh


# ----------------------------------------------------------------------------------------------
# features


@dataclass
class _Sources:
    """Tags collected from each source, before merging, and the names of the sources."""

    edges: list = field(default_factory=list)
    sharpness: list = field(default_factory=list)
    corners: list = field(default_factory=list)
    corner_sharpness: list = field(default_factory=list)  # beside each of corners (inf: infinite)
    sharp_faces: list = field(default_factory=list)
    names: list = field(default_factory=list)

    def add_corners(self, c, s=None) -> None:
        c = np.asarray(c, np.int64)
        self.corners.append(c)
        self.corner_sharpness.append(np.full(len(c), np.inf) if s is None else np.asarray(s, np.float64))


def gather_features(opts: FileOptions, mesh: TaggedMesh, path: str) -> FileFeatures:
    """Tags from the file, the tag files and the feature angle, checked and merged; one-line
    summary. Creases are detected only when ``opts.feature_angle`` asks (every command alike)."""
    n = len(mesh.vertices)
    edges = undirected_edges(mesh.faces, n)
    n_boundary = int((edges.count == 1).sum())
    file_tags = mesh.has_tags and not opts.ignore_tags
    if opts.scheme == "sqrt3":
        return _sqrt3_features(opts, mesh, path, file_tags, n_boundary)
    src = _Sources()
    if file_tags:
        src.edges.append(mesh.sharp_edges)
        src.sharpness.append(mesh.sharpness)
        src.add_corners(mesh.corners, mesh.corner_sharpness)
        src.sharp_faces.append(mesh.sharp_faces)
        src.names.append(f"tags in {os.path.basename(path)}")
    _read_tag_files(opts, mesh, path, edges.pairs, src)
    angle = opts.feature_angle
    if angle is None and opts.feature_sharpness is not None:
        raise PipelineError("--feature-sharpness sets the sharpness of detected creases: give --feature-angle too")
    if angle is not None:
        _add_detected(mesh, path, angle, opts.feature_sharpness, src)
    if not src.names:
        if n_boundary:
            what = f"boundary only ({count_of(n_boundary, 'boundary edge')} kept as creases)"
        else:
            what = "none (a closed mesh without tags: smooth everywhere)"
        return FileFeatures.none(f"features: {what}; --feature-angle 30 would detect creases")
    return _merged(src, n, n_boundary)


def _sqrt3_features(opts, mesh, path, file_tags, n_boundary) -> FileFeatures:
    """Kobbelt's √3 takes no tags: refuse tag options, say what is not used."""
    explicit = [o for o, v in (("--sharp-edges", opts.sharp_edges_file), ("--sharp-faces", opts.sharp_faces_file),
                               ("--corners", opts.corners_file), ("--feature-angle", opts.feature_angle),
                               ("--feature-sharpness", opts.feature_sharpness))
                if v is not None]
    if explicit:
        raise PipelineError(f"{explicit[0]} needs --scheme hybrid or loop: Kobbelt's √3 takes no feature tags")
    why = "Kobbelt's √3 takes no feature tags"
    if file_tags:
        why += f" (the {_io.describe_tags(mesh)} in {path} are not used)"
    bnd = f"; {count_of(n_boundary, 'boundary edge')} follow Kobbelt's boundary rule" if n_boundary else ""
    return FileFeatures.none(f"features: none — {why}{bnd}")


def _read_tag_files(opts: FileOptions, mesh: TaggedMesh, path: str, pairs: np.ndarray, src: _Sources) -> None:
    n, m = len(mesh.vertices), len(mesh.faces)
    if opts.sharp_edges_file is not None:
        e, s = _io.read_edge_file(opts.sharp_edges_file)
        _check_edges(e, pairs, n, opts.sharp_edges_file, path)
        src.edges.append(e)
        src.sharpness.append(s)
        src.names.append(os.path.basename(opts.sharp_edges_file))
    if opts.sharp_faces_file is not None:
        src.sharp_faces.append(_read_indices(opts.sharp_faces_file, "face", "faces", m, path))
        src.names.append(os.path.basename(opts.sharp_faces_file))
    if opts.corners_file is not None:
        src.add_corners(_read_indices(opts.corners_file, "vertex", "vertices", n, path))
        src.names.append(os.path.basename(opts.corners_file))


def _add_detected(mesh: TaggedMesh, path: str, angle: float, sharpness: float | None, src: _Sources) -> None:
    try:
        feat = detect_features(mesh.vertices, mesh.faces, angle)
    except MeshError as err:
        raise PipelineError(f"{path}: {err}") from None
    s_feat = np.inf if sharpness is None else float(normalize_sharpness(sharpness))
    src.edges.append(feat.sharp_edges)
    src.sharpness.append(np.full(len(feat.sharp_edges), s_feat))
    if np.isinf(s_feat):
        src.add_corners(feat.corners)
    # semi-sharp: no corner tags, which would pin the vertices while their creases round off
    src.names.append(f"dihedral angle > {angle:g}°" + ("" if np.isinf(s_feat) else f", sharpness {s_feat:g}"))


def _merged(src: _Sources, n: int, n_boundary: int) -> FileFeatures:
    edges, sharp = merge_edges(np.vstack(src.edges) if src.edges else np.empty((0, 2), np.int64),
                               np.concatenate(src.sharpness) if src.sharpness else np.empty(0), n)
    c, cs = (_io.corner_tags(np.concatenate(src.corners), np.concatenate(src.corner_sharpness)) if src.corners
             else (np.empty(0, np.int64), None))
    sf = np.unique(np.concatenate(src.sharp_faces)) if src.sharp_faces else np.empty(0, np.int64)
    parts = [count_of(len(edges), "crease")]
    semi = int(np.isfinite(sharp).sum())
    if semi:
        parts[-1] += f" ({semi:,} semi-sharp)"
    parts.append(count_of(len(c), "corner"))
    if cs is not None:
        parts[-1] += f" ({int(np.isfinite(cs).sum()):,} semi-sharp)"
    if len(sf):
        parts.append(count_of(len(sf), "sharp face"))
    if n_boundary:
        parts.append(f"{count_of(n_boundary, 'boundary edge')} (creases too)")
    return FileFeatures(edges, sharp, sf, c, f"features: {', '.join(parts)} — from {' + '.join(src.names)}", cs)


def _read_indices(list_path: str, noun: str, plural: str, count: int, mesh_path: str) -> np.ndarray:
    """Indices from a text file, each checked against the mesh's ``count`` faces or vertices."""
    idx = _io.read_list_file(list_path, f"{noun} indices")
    bad = (idx < 0) | (idx >= count)
    if bad.any():
        raise PipelineError(f"{list_path}: {noun} {int(idx[bad][0])} does not exist: {mesh_path} has {count:,} "
                            f"{plural} (0-based: 0..{count - 1})")
    return idx


def _check_edges(e, pairs, n, source, path) -> None:
    """Every edge of a tag file is an edge of the mesh at ``path`` (``pairs``: its edges, sorted)."""
    bad = ((e < 0) | (e >= n)).any(axis=1)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise PipelineError(f"{source}: edge {j} = ({e[j, 0]}, {e[j, 1]}) names a vertex that {path} does not "
                            f"have ({n:,} vertices, 0-based: 0..{n - 1})")
    missing = ~np.isin(edge_keys(e[:, 0], e[:, 1], n), edge_keys(pairs[:, 0], pairs[:, 1], n))
    if missing.any():
        j = int(np.flatnonzero(missing)[0])
        raise PipelineError(f"{source}: edge {j} = ({e[j, 0]}, {e[j, 1]}) is not an edge of {path} "
                            f"({int(missing.sum())} such; indices are 0-based)")


# ----------------------------------------------------------------------------------------------
# sizes and memory


def check_memory(opts: FileOptions, pred: list[dict], what: str) -> None:
    """Refuse a run whose estimated peak exceeds 80% of the memory at hand: the machine's RAM or a
    smaller cgroup limit, or
    ``opts.memory_limit`` (bytes) where the caller has less (a batch task: its Dask worker's
    limit). ``opts.force`` skips the check."""
    if not pred:
        return
    peak = max(p["peak_bytes"] for p in pred)
    ram = physical_memory()
    owner = "this process's cgroup (container, Slurm job) allows" if ram and ram == cgroup_memory_limit() \
        else "this machine has"
    limit = opts.memory_limit
    if limit and (not ram or limit < ram):
        ram, owner = limit, "the Dask worker's memory limit is"
    if ram and peak > 0.8 * ram and not opts.force:
        raise PipelineError(f"{what} would need about {short_bytes(peak)} of memory at level {len(pred)} "
                            f"({pred[-1]['faces']:,} faces); {owner} {short_bytes(ram)}. Use fewer levels, "
                            "or --force to try anyway")


def keeps_uv(mesh: TaggedMesh, scheme: str) -> bool:
    """Whether subdivide refines the mesh's UVs (face-varying); Kobbelt's √3 cannot."""
    return mesh.uv is not None and mesh.face_uv is not None and scheme != "sqrt3"


def seams(mesh: TaggedMesh, path: str) -> np.ndarray:
    """The UV seams of ``mesh`` (read from ``path``) as vertex pairs."""
    try:
        return seam_edges(mesh.faces, mesh.face_uv)
    except MeshError as e:
        raise PipelineError(f"{path}: {e}") from None


def predict_file_levels(mesh: TaggedMesh, levels: int, scheme: str, feat: FileFeatures, attributes: int = 3,
                        path: str = "", uv: bool = True) -> list[dict]:
    """Exact counts per level of ``subdivide`` (UV seams are split edges for ever, as
    infinitely sharp creases are); the UV index mesh roughly doubles the peak memory.
    ``uv=False``: the mesh without its UVs (``compare``)."""
    edges, sharpness = feat.sharp_edges, feat.sharpness
    uv = uv and keeps_uv(mesh, scheme)
    if uv and scheme == "hybrid":
        found = seams(mesh, path)
        edges = np.vstack([edges, found])
        sharpness = np.concatenate([sharpness, np.full(len(found), np.inf)])
    pred = predict_levels(mesh.faces, len(mesh.vertices), levels, scheme=scheme, sharp_edges=edges,
                          sharpness=sharpness, sharp_faces=feat.sharp_faces, attributes=attributes)
    if uv:
        for p in pred:
            p["peak_bytes"] *= 2
    return pred


# ----------------------------------------------------------------------------------------------
# refining and writing


def subdivide_file(opts: FileOptions, src: str, dst: str, write_to: str | None = None) -> FileResult:
    """``hybridsub subdivide SRC -o DST`` with ``opts``: read, gather the features, refine,
    write. ``write_to`` is the file actually written (the batch's temporary name, with DST's
    extension); messages name DST."""
    t0 = time.perf_counter()
    mesh = load_mesh(opts, src)
    feat = gather_features(opts, mesh, src)
    t_read = time.perf_counter() - t0
    say(opts, feat.summary)
    if opts.tolerance is not None:
        out, seconds, line = adaptive_mesh(opts, mesh, feat, src)
        say(opts, line)
    else:
        out, seconds = refine_mesh(opts, mesh, feat, src)
        speed = f" ({rate(len(out.faces) / seconds)} faces/s)" if seconds > 0 and opts.levels else ""
        say(opts, f"{SCHEME_NAMES[opts.scheme]}, {count_of(opts.levels, 'level')}: {len(mesh.faces):,} → "
                  f"{len(out.faces):,} faces, {len(out.vertices):,} vertices in {seconds:.2f} s{speed}")
    if opts.no_tags:
        out = replace(out, sharp_edges=np.empty((0, 2), np.int64), sharpness=np.empty(0),
                      corners=np.empty(0, np.int64), sharp_faces=np.empty(0, np.int64))
    t = time.perf_counter()
    dropped = _io.write(write_to or dst, out, binary=not opts.ascii, folder=os.path.dirname(os.path.abspath(dst)))
    dt = time.perf_counter() - t
    kept = _io.describe_tags(out)
    if dropped:
        say(opts, f"wrote {dst} in {dt:.2f} s — {os.path.splitext(dst)[1].lower()} files cannot hold the "
                  f"{dropped}; write .obj or .ply to keep them")
    else:
        say(opts, f"wrote {dst} in {dt:.2f} s" + (f" with its {kept}" if kept else ""))
    if out.materials and os.path.splitext(dst)[1].lower() != ".obj":
        say(opts, f"note: the materials of {os.path.basename(src)} ('mtllib', 'usemtl') are kept in .obj output "
                  "only")
    summary = feat.summary.removeprefix("features: ")
    return FileResult(len(mesh.faces), len(out.faces), len(out.vertices), summary, list(mesh.notes), t_read,
                      seconds, dt)


def refine_mesh(opts: FileOptions, mesh: TaggedMesh, feat: FileFeatures, path: str) -> tuple[TaggedMesh, float]:
    """Refine ``mesh`` (read from ``path``) with its attributes, ``opts.levels`` levels of
    ``opts.scheme``, with the progress bar; returns the refined mesh and the seconds it took."""
    levels, scheme = opts.levels, opts.scheme
    cols = [mesh.vertices]
    vc = mesh.vertex_colors
    if vc is not None:
        cols.append(vc)
    keep_uv = keeps_uv(mesh, scheme)
    if mesh.uv is not None and not keep_uv:
        if opts.uv_mode is not None:
            raise PipelineError("--uv-mode needs --scheme hybrid or loop: Kobbelt's √3 flips every edge, and a "
                                f"flip across a UV seam makes a triangle spanning two UV charts ({path} has UVs)")
        say(opts, "note: texture coordinates dropped: Kobbelt's √3 cannot keep UV seams (use --scheme hybrid "
                  "to keep them)")
    X = np.hstack(cols)
    pred = predict_file_levels(mesh, levels, scheme, feat, attributes=X.shape[1], path=path)
    check_memory(opts, pred, f"{count_of(levels, 'level')} of {scheme}")
    bar = ProgressBar([p["faces"] for p in pred], scheme, enabled=not opts.quiet and sys.stderr.isatty())
    uv_args = dict(uv=mesh.uv, face_uv=mesh.face_uv, uv_mode=opts.uv_mode or "linear") if keep_uv else {}
    try:
        res = refine_by_level(X, mesh.faces, levels, scheme=scheme, loop_weights=opts.loop_weights,
                              on_level=bar.update, max_memory="none" if opts.force else None, **uv_args,
                              non_manifold=opts.non_manifold, boundary=opts.boundary,
                              holes=mesh.holes if len(mesh.holes) else None, **feat.tags())
    except MeshError as e:  # the library's advice in the command line's words
        raise PipelineError(f"{path}: " + str(e).replace('pass non_manifold="cut"', "pass --non-manifold cut")
                            .replace('with non_manifold="cut"', "with --non-manifold cut")) from None
    except OutputTooLargeError as e:  # the library's memory limit (HYBRIDSUB_MAX_MEMORY); --force lifts it
        raise PipelineError(f"{path}: {e}, or pass --force") from None
    except MemoryError:
        raise PipelineError(f"out of memory refining {path} ({count_of(levels, 'level')} of {scheme}); use fewer levels") from None
    finally:
        bar.close()
    return _refined_mesh(mesh, res, vc, keep_uv, scheme), res.seconds


def adaptive_mesh(opts: FileOptions, mesh: TaggedMesh, feat: FileFeatures,
                  path: str) -> tuple[TaggedMesh, float, str]:
    """Adaptive refinement of ``mesh`` to ``opts.tolerance``: the refined mesh (positions at
    the limit, colours by the refinement's matrix, tags), the seconds it took, and the line
    that says what it made. Texture coordinates are refined with ``--scheme loop`` and dropped
    (with a note) otherwise."""
    import warnings

    from .._surface.adaptive import AdaptiveWarning, adaptive_result

    keep_uv = mesh.uv is not None and mesh.face_uv is not None and opts.scheme == "loop"
    if mesh.uv is not None and not keep_uv:
        if opts.uv_mode is not None:
            raise PipelineError(f"--uv-mode with --tolerance needs --scheme loop ({path} has UVs): the hybrid splits "
                                "UV seams where it flips other edges, a surface the tolerance is not measured on, "
                                "and Kobbelt's √3 flips every edge")
        say(opts, "note: texture coordinates dropped: to a tolerance they are refined with --scheme loop (the hybrid "
                  "splits UV seams, a surface the tolerance is not measured on; √3 flips every edge)")
    uv_args = dict(uv_faces=mesh.face_uv, n_uvs=len(mesh.uv), uv_mode=opts.uv_mode or "linear") if keep_uv else {}
    t = time.perf_counter()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", AdaptiveWarning)
            res = adaptive_result(mesh.vertices, mesh.faces, tolerance=opts.tolerance, max_levels=opts.max_levels,
                                  scheme=opts.scheme, loop_weights=opts.loop_weights, boundary=opts.boundary,
                                  holes=mesh.holes if len(mesh.holes) else None,
                                  non_manifold=opts.non_manifold, max_memory="none" if opts.force else None,
                                  **uv_args, **feat.tags())
    except MeshError as e:
        raise PipelineError(f"{path}: {e}") from None
    except ValueError as e:
        raise PipelineError(f"{path}: {e}") from None
    seconds = time.perf_counter() - t
    for w in caught:
        say(opts, f"warning: {w.message}")
    r = res.refinement
    colors = None
    if mesh.vertex_colors is not None:
        colors = np.clip(r.apply(mesh.vertex_colors), 0, 1)
    sf = np.asarray(r.sharp_faces)
    sf = (np.flatnonzero(sf) if sf.dtype == bool else sf) if opts.scheme == "hybrid" else np.empty(0, np.int64)
    fm = None if mesh.face_material is None else mesh.face_material[r.face_parent]
    uv = face_uv = None
    if keep_uv:
        uv, face_uv = r.uv_refinement.apply(mesh.uv), r.uv_faces
    out = TaggedMesh(res.positions, r.faces, r.sharp_edges, r.sharpness, r.corners, sf, colors, uv, face_uv,
                     material_libs=mesh.material_libs, materials=mesh.materials, face_material=fm)
    counts = np.bincount(r.face_level)
    per = ", ".join(f"{c:,} at {j}" for j, c in enumerate(counts) if c)
    line = (f"{SCHEME_NAMES[opts.scheme]}, adaptive to {res.tolerance:.4g}: {len(mesh.faces):,} → {len(r.faces):,} "
            f"faces ({per}), {len(res.positions):,} vertices, error {res.error:.4g}, in {seconds:.2f} s")
    return out, seconds, line


def _refined_mesh(mesh: TaggedMesh, res, vc, keep_uv: bool, scheme: str) -> TaggedMesh:
    """The refined positions, colours, UVs, tags and materials as a :class:`TaggedMesh`. Sharp
    faces only where the scheme tells them apart (``"hybrid"``): Loop splits every face alike."""
    Y = res.X
    V = np.ascontiguousarray(Y[:, :3])
    colors = uv = face_uv = None
    if vc is not None:
        colors = np.clip(Y[:, 3:3 + vc.shape[1]], 0, 1)
    if keep_uv:
        uv, face_uv = res.uv, res.face_uv
    sf = res.sharp_faces if scheme == "hybrid" else np.empty(0, np.int64)
    fm = None if mesh.face_material is None else mesh.face_material[res.face_parent]
    return TaggedMesh(V, res.faces, res.sharp_edges, res.sharpness, res.corners,
                      np.flatnonzero(sf) if sf.dtype == bool else sf, colors, uv, face_uv,
                      material_libs=mesh.material_libs, materials=mesh.materials, face_material=fm,
                      corner_sharpness=res.corner_sharpness)
