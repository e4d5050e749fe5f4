"""Command line: ``hybridsub subdivide | batch | compare | info | demo``.

Messages go to stderr (``--quiet`` silences all but errors), ``info`` writes its report to
stdout. Exit codes: 0 success, 1 the input or the run failed (one line naming the problem),
2 bad command line, 130 interrupted.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from dataclasses import dataclass, replace

import numpy as np

from .._version import __version__
from .. import _io
from .._errors import MeshError, OutputTooLargeError
from .._io import example_path
from .._refiner import seam_edges
from .._input import detect_features
from .._io import TaggedMesh
from .report import _edges, mesh_report, predict_levels
from .progress import ProgressBar, refine_by_level
from .._rules.refinement import normalize_sharpness
from .._input import SCHEMES, count_of as _n

SCHEME_NAMES = {"hybrid": "hybrid √3–Loop", "sqrt3": "Kobbelt √3", "loop": "Loop"}


class CLIError(Exception):
    """An error to report in one line (exit code 1)."""


# ----------------------------------------------------------------------------------------------
# features


@dataclass
class Features:
    sharp_edges: np.ndarray
    sharpness: np.ndarray
    sharp_faces: np.ndarray
    corners: np.ndarray
    summary: str

    def tags(self) -> dict:
        return dict(sharp_edges=self.sharp_edges, sharpness=self.sharpness, sharp_faces=self.sharp_faces,
                    corners=self.corners)


def gather_features(a, mesh: TaggedMesh, path: str, scheme: str, default_angle: float | None = None) -> Features:
    """Tags from the file, the tag files and --feature-angle, checked and merged; one-line summary."""
    n, m = len(mesh.vertices), len(mesh.faces)
    pairs, _, cnt = _edges(mesh.faces, n)
    n_boundary = int((cnt == 1).sum())
    explicit = [o for o, v in (("--sharp-edges", a.sharp_edges), ("--sharp-faces", a.sharp_faces),
                               ("--corners", a.corners), ("--feature-angle", a.feature_angle),
                               ("--feature-sharpness", getattr(a, "feature_sharpness", None)))
                if v is not None]
    file_tags = mesh.has_tags and not a.ignore_tags
    if scheme == "sqrt3":
        if explicit:
            raise CLIError(f"{explicit[0]} needs --scheme hybrid or loop: Kobbelt's √3 takes no feature tags")
        why = "Kobbelt's √3 takes no feature tags"
        if file_tags:
            why += f" (the {_io.describe_tags(mesh)} in {path} are not used)"
        bnd = f"; {_n(n_boundary, 'boundary edge')} follow Kobbelt's boundary rule" if n_boundary else ""
        return Features(np.empty((0, 2), np.int64), np.empty(0), np.empty(0, np.int64), np.empty(0, np.int64),
                        f"features: none — {why}{bnd}")
    E, S, C, SF, sources = [], [], [], [], []
    if file_tags:
        E.append(mesh.sharp_edges)
        S.append(mesh.sharpness)
        C.append(mesh.corners)
        SF.append(mesh.sharp_faces)
        sources.append(f"tags in {os.path.basename(path)}")
    if a.sharp_edges is not None:
        e, s = _io.read_edge_file(a.sharp_edges)
        _check_edges(e, pairs, n, a.sharp_edges, path)
        E.append(e)
        S.append(s)
        sources.append(os.path.basename(a.sharp_edges))
    if a.sharp_faces is not None:
        SF.append(_read_indices(a.sharp_faces, "face", "faces", m, path))
        sources.append(os.path.basename(a.sharp_faces))
    if a.corners is not None:
        C.append(_read_indices(a.corners, "vertex", "vertices", n, path))
        sources.append(os.path.basename(a.corners))
    angle = a.feature_angle
    if angle is None and default_angle is not None and not E and not SF and not C:
        angle = default_angle
    s_given = getattr(a, "feature_sharpness", None)
    if angle is None and s_given is not None:
        raise CLIError("--feature-sharpness sets the sharpness of detected creases: give --feature-angle too")
    if angle is not None:
        try:
            feat = detect_features(mesh.vertices, mesh.faces, angle)
        except MeshError as err:
            raise CLIError(f"{path}: {err}") from None
        s_feat = np.inf if s_given is None else float(normalize_sharpness(s_given))
        E.append(feat.sharp_edges)
        S.append(np.full(len(feat.sharp_edges), s_feat))
        if np.isinf(s_feat):
            C.append(feat.corners)
        # semi-sharp: no corner tags, which would pin the vertices while their creases round off
        sources.append(f"dihedral angle > {angle:g}°" + ("" if np.isinf(s_feat) else f", sharpness {s_feat:g}"))
    if not sources:
        if n_boundary:
            what = f"boundary only ({_n(n_boundary, 'boundary edge')} kept as creases)"
        else:
            what = "none (a closed mesh without tags: smooth everywhere)"
        return Features(np.empty((0, 2), np.int64), np.empty(0), np.empty(0, np.int64), np.empty(0, np.int64),
                        f"features: {what}; --feature-angle 30 would detect creases")
    edges, sharp = _merge_edges(np.vstack(E) if E else np.empty((0, 2), np.int64),
                                np.concatenate(S) if S else np.empty(0), n)
    c = np.unique(np.concatenate(C)) if C else np.empty(0, np.int64)
    sf = np.unique(np.concatenate(SF)) if SF else np.empty(0, np.int64)
    parts = [_n(len(edges), "crease")]
    semi = int(np.isfinite(sharp).sum())
    if semi:
        parts[-1] += f" ({semi:,} semi-sharp)"
    parts.append(_n(len(c), "corner"))
    if len(sf):
        parts.append(_n(len(sf), "sharp face"))
    if n_boundary:
        parts.append(f"{_n(n_boundary, 'boundary edge')} (creases too)")
    return Features(edges, sharp, sf, c, f"features: {', '.join(parts)} — from {' + '.join(sources)}")


def _read_indices(list_path: str, noun: str, plural: str, count: int, mesh_path: str) -> np.ndarray:
    """Indices from a text file, each checked against the mesh's ``count`` faces or vertices."""
    idx = _io.read_list_file(list_path, f"{noun} indices")
    bad = (idx < 0) | (idx >= count)
    if bad.any():
        raise CLIError(f"{list_path}: {noun} {int(idx[bad][0])} does not exist: {mesh_path} has {count:,} "
                       f"{plural} (0-based: 0..{count - 1})")
    return idx


def _check_edges(e, pairs, n, source, path):
    bad = ((e < 0) | (e >= n)).any(axis=1)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise CLIError(f"{source}: edge {j} = ({e[j, 0]}, {e[j, 1]}) names a vertex that {path} does not have "
                       f"({n:,} vertices, 0-based: 0..{n - 1})")
    key = np.minimum(e[:, 0], e[:, 1]) * max(n, 1) + np.maximum(e[:, 0], e[:, 1])
    ekey = pairs[:, 0] * max(n, 1) + pairs[:, 1]
    missing = ~np.isin(key, ekey)
    if missing.any():
        j = int(np.flatnonzero(missing)[0])
        raise CLIError(f"{source}: edge {j} = ({e[j, 0]}, {e[j, 1]}) is not an edge of {path} "
                       f"({int(missing.sum())} such; indices are 0-based)")


def _merge_edges(e, s, n):
    """One entry per undirected edge, keeping the largest sharpness; first-seen order."""
    if not len(e):
        return e.reshape(0, 2).astype(np.int64), s
    key = np.minimum(e[:, 0], e[:, 1]) * max(n, 1) + np.maximum(e[:, 0], e[:, 1])
    uniq, first, inv = np.unique(key, return_index=True, return_inverse=True)
    best = np.zeros(len(uniq))
    np.maximum.at(best, inv.ravel(), s)
    order = np.argsort(first, kind="stable")
    return e[first[order]].astype(np.int64), best[order]


# ----------------------------------------------------------------------------------------------
# commands


def _say(a, *msg) -> None:
    if not getattr(a, "quiet", False):
        print(*msg, file=sys.stderr)


def _load(a, path: str) -> TaggedMesh:
    mesh = _io.read_mesh(path, triangulate=getattr(a, "triangulate", False))
    for note in mesh.notes:
        _say(a, f"note: {path}: {note}")
    if getattr(a, "weld", False):
        mesh, merged, dropped = _io.weld(mesh)
        _say(a, f"note: welded {merged:,} duplicate vertices" + (f", dropped {dropped:,} collapsed faces"
                                                                  if dropped else ""))
    return mesh


def _ram_bytes() -> int | None:
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def _check_memory(a, pred: list[dict], what: str) -> None:
    """Refuse a run whose estimated peak exceeds 80% of the memory at hand: the machine's RAM, or
    ``a.memory_limit`` (bytes) where the caller has less (a batch task: its Dask worker's limit)."""
    if not pred:
        return
    peak = max(p["peak_bytes"] for p in pred)
    ram, owner = _ram_bytes(), "this machine has"
    limit = getattr(a, "memory_limit", None)
    if limit and (not ram or limit < ram):
        ram, owner = limit, "the Dask worker's memory limit is"
    if ram and peak > 0.8 * ram and not a.force:
        raise CLIError(f"{what} would need about {_bytes(peak)} of memory at level {len(pred)} "
                       f"({pred[-1]['faces']:,} faces); {owner} {_bytes(ram)}. Use fewer levels, "
                       "or --force to try anyway")


def _rate(x: float) -> str:
    if x >= 1e6:
        return f"{x / 1e6:.2f} M"
    return f"{x / 1e3:.0f} k" if x >= 1e3 else f"{x:.0f}"


def _bytes(b: float) -> str:
    for unit, div in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if b >= div:
            return f"{b / div:.1f} {unit}"
    return f"{int(b)} B"


def _keeps_uv(mesh: TaggedMesh, scheme: str) -> bool:
    """Whether subdivide refines the mesh's UVs (face-varying); Kobbelt's √3 cannot."""
    return mesh.uv is not None and mesh.face_uv is not None and scheme != "sqrt3"


def _seams(mesh: TaggedMesh, path: str) -> np.ndarray:
    try:
        return seam_edges(mesh.faces, mesh.face_uv)
    except MeshError as e:
        raise CLIError(f"{path}: {e}") from None


def _predict(mesh: TaggedMesh, levels: int, scheme: str, feat: Features, attributes: int = 3, path: str = "",
             uv: bool = True):
    """Exact counts per level of ``subdivide`` (UV seams are split edges for ever, as
    infinitely sharp creases are); the UV index mesh roughly doubles the peak memory.
    ``uv=False``: the mesh without its UVs (``compare``)."""
    edges, sharpness = feat.sharp_edges, feat.sharpness
    uv = uv and _keeps_uv(mesh, scheme)
    if uv and scheme == "hybrid":
        seams = _seams(mesh, path)
        edges = np.vstack([edges, seams])
        sharpness = np.concatenate([sharpness, np.full(len(seams), np.inf)])
    pred = predict_levels(mesh.faces, len(mesh.vertices), levels, scheme=scheme, sharp_edges=edges,
                          sharpness=sharpness, sharp_faces=feat.sharp_faces, attributes=attributes)
    if uv:
        for p in pred:
            p["peak_bytes"] *= 2
    return pred


def cmd_subdivide(a) -> int:
    if not os.path.splitext(a.output)[1]:
        raise CLIError(f"{a.output}: give the output file an extension (.obj, .ply, .off, .npz, .stl, .glb, …)")
    subdivide_file(a, a.input, a.output)
    return 0


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


def subdivide_file(a, src: str, dst: str, write_to: str | None = None) -> FileResult:
    """``hybridsub subdivide SRC -o DST`` with the options in ``a``: read, gather the features,
    refine, write. ``write_to`` is the file actually written (the batch's temporary name, with
    DST's extension); messages name DST."""
    t0 = time.perf_counter()
    mesh = _load(a, src)
    feat = gather_features(a, mesh, src, a.scheme)
    t_read = time.perf_counter() - t0
    _say(a, feat.summary)
    out, seconds = _subdivide(a, mesh, feat, a.levels, a.scheme, src)
    rate = f" ({_rate(len(out.faces) / seconds)} faces/s)" if seconds > 0 and a.levels else ""
    _say(a, f"{SCHEME_NAMES[a.scheme]}, {_n(a.levels, 'level')}: {len(mesh.faces):,} → {len(out.faces):,} faces, "
            f"{len(out.vertices):,} vertices in {seconds:.2f} s{rate}")
    if a.no_tags:
        out = replace(out, sharp_edges=np.empty((0, 2), np.int64), sharpness=np.empty(0),
                      corners=np.empty(0, np.int64), sharp_faces=np.empty(0, np.int64))
    t = time.perf_counter()
    dropped = _io.write(write_to or dst, out, binary=not a.ascii)
    dt = time.perf_counter() - t
    kept = _io.describe_tags(out)
    if dropped:
        _say(a, f"wrote {dst} in {dt:.2f} s — {os.path.splitext(dst)[1].lower()} files cannot hold the {dropped}; "
                "write .obj or .ply to keep them")
    else:
        _say(a, f"wrote {dst} in {dt:.2f} s" + (f" with its {kept}" if kept else ""))
    if out.materials and os.path.splitext(dst)[1].lower() != ".obj":
        _say(a, f"note: the materials of {os.path.basename(src)} ('mtllib', 'usemtl') are kept in .obj output only")
    summary = feat.summary.removeprefix("features: ")
    return FileResult(len(mesh.faces), len(out.faces), len(out.vertices), summary, list(mesh.notes), t_read,
                      seconds, dt)


def _subdivide(a, mesh: TaggedMesh, feat: Features, levels: int, scheme: str, path: str):
    """Refine mesh with its attributes, level by level, with the progress bar."""
    cols = [mesh.vertices]
    vc = mesh.vertex_colors
    if vc is not None:
        cols.append(vc)
    uv_mode = getattr(a, "uv_mode", None)
    keep_uv = _keeps_uv(mesh, scheme)
    if mesh.uv is not None and not keep_uv:
        if uv_mode is not None:
            raise CLIError("--uv-mode needs --scheme hybrid or loop: Kobbelt's √3 flips every edge, and a flip "
                           f"across a UV seam makes a triangle spanning two UV charts ({path} has UVs)")
        _say(a, f"note: texture coordinates dropped: Kobbelt's √3 cannot keep UV seams (use --scheme hybrid "
                "to keep them)")
    X = np.hstack(cols)
    pred = _predict(mesh, levels, scheme, feat, attributes=X.shape[1], path=path)
    _check_memory(a, pred, f"{levels} levels of {scheme}")
    bar = ProgressBar([p["faces"] for p in pred], scheme, enabled=not a.quiet and sys.stderr.isatty())
    uv_args = dict(uv=mesh.uv, face_uv=mesh.face_uv, uv_mode=uv_mode or "linear") if keep_uv else {}
    try:
        res = refine_by_level(X, mesh.faces, levels, scheme=scheme, loop_weights=a.loop_weights,
                              on_level=bar.update, max_memory="none" if a.force else None, **uv_args, **feat.tags())
    except MeshError as e:
        raise CLIError(f"{path}: {e}") from None
    except OutputTooLargeError as e:  # the library's memory limit (HYBRIDSUB_MAX_MEMORY); --force lifts it
        raise CLIError(f"{path}: {e}, or pass --force") from None
    except MemoryError:
        raise CLIError(f"out of memory refining {path} ({levels} levels of {scheme}); use fewer levels") from None
    finally:
        bar.close()
    Y = res.X
    V = np.ascontiguousarray(Y[:, :3])
    k = 3
    colors = uv = face_uv = None
    if vc is not None:
        colors = np.clip(Y[:, k:k + vc.shape[1]], 0, 1)
        k += vc.shape[1]
    if keep_uv:
        uv, face_uv = res.uv, res.face_uv
    sf = res.sharp_faces
    fm = None if mesh.face_material is None else mesh.face_material[res.face_parent]
    out = TaggedMesh(V, res.faces, res.sharp_edges, res.sharpness, res.corners,
                     np.flatnonzero(sf) if sf.dtype == bool else sf, colors, uv, face_uv,
                     material_libs=mesh.material_libs, materials=mesh.materials, face_material=fm)
    return out, res.seconds


def cmd_batch(a) -> int:
    import logging

    from .batch import batch

    # Dask logs a lost scheduler as tracebacks; the command says what happened in one line.
    logging.getLogger("distributed").setLevel(logging.CRITICAL)
    try:
        s = batch(a.inputs, a.output, levels=a.levels, scheme=a.scheme, feature_angle=a.feature_angle,
                  feature_sharpness=a.feature_sharpness, uv_mode=a.uv_mode, format=a.format,
                  loop_weights=a.loop_weights, ignore_tags=a.ignore_tags, triangulate=a.triangulate, weld=a.weld, force=a.force, scheduler=a.scheduler, workers=a.workers, verify=a.verify,
                  progress=not a.quiet and sys.stderr.isatty())
    except RuntimeError as e:
        raise CLIError(str(e)) from None
    lines = s.failure_lines() if a.quiet else [s.table()]
    if lines:
        print("\n".join(lines), file=sys.stderr)
    return 0 if s.ok else 1


def cmd_compare(a) -> int:
    from .figure import compare_panels, render_figure

    if not a.output.lower().endswith(".png"):
        raise CLIError(f"{a.output}: the figure is written as PNG; give a .png file name")
    width, height = _size(a.size)
    view = _view(a.view) if a.view else None
    mesh = _load(a, a.input)
    feat = gather_features(a, mesh, a.input, "hybrid", default_angle=30.0)
    _say(a, feat.summary)
    for scheme in ("hybrid", "loop"):
        _check_memory(a, _predict(mesh, a.levels, scheme, feat, uv=False), f"{a.levels} levels of {scheme}")
    t = time.perf_counter()
    try:
        panels = compare_panels(mesh.vertices, mesh.faces, a.levels, loop_weights=a.loop_weights, **feat.tags())
    except MeshError as e:
        raise CLIError(f"{a.input}: {e}") from None
    t1 = time.perf_counter()
    used = render_figure(panels, a.output, width=width, height=height, view=view,
                         title=a.title)
    t2 = time.perf_counter()
    _say(a, "faces: " + ", ".join(f"{p.title.split(',')[0]} {len(p.F):,}" for p in panels))
    _say(a, f"wrote {a.output} ({width}×{height}, view {used[0]:g},{used[1]:g}: reuse with --view "
            f"{used[0]:g},{used[1]:g}) — subdivided in {t1 - t:.2f} s, rendered in {t2 - t1:.2f} s")
    return 0


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise CLIError(f"--size must look like 1600x520, got {text!r}") from None
    if not (64 <= w <= 16000 and 64 <= h <= 16000):
        raise CLIError(f"--size must be between 64 and 16000 pixels each way, got {text!r}")
    return w, h


def _view(text: str) -> tuple[float, float]:
    try:
        az, el = (float(x) for x in text.split(","))
    except ValueError:
        raise CLIError(f"--view must be AZIMUTH,ELEVATION in degrees, e.g. 225,-35; got {text!r}") from None
    return az, el


def cmd_info(a) -> int:
    mesh = _load(a, a.input)
    V, F = mesh.vertices, mesh.faces
    rep = mesh_report(V, F)
    valid = not (rep["nonmanifold_edges"] or rep["misoriented_edges"] or rep["degenerate_faces"])
    out = {"file": a.input, "report": {k: v for k, v in rep.items() if k != "bbox"},
           "bbox": rep["bbox"].tolist()}
    lines = [f"{a.input}: {rep['vertices']:,} vertices, {rep['faces']:,} triangles, {rep['edges']:,} edges"]
    lo, hi = rep["bbox"]
    lines.append(f"  size          {' × '.join(f'{x:.4g}' for x in hi - lo)} "
                 f"(from {', '.join(f'{x:.4g}' for x in lo)}), diagonal {np.linalg.norm(hi - lo):.4g}")
    topo = (f"{_n(rep['components'], 'component')}, Euler characteristic {rep['euler']}"
            + (f", genus {rep['genus']}" if rep["genus"] is not None else ""))
    lines.append(f"  topology      {topo}")
    if rep["boundary_edges"]:
        lines.append(f"  boundary      {_n(rep['boundary_loops'], 'loop')}, {_n(rep['boundary_edges'], 'edge')}")
    else:
        lines.append("  boundary      none (closed)")
    problems = []
    if rep["nonmanifold_edges"]:
        ex = ", ".join(f"{u}–{w}" for u, w in rep["nonmanifold_edge_examples"])
        problems.append(f"{_n(rep['nonmanifold_edges'], 'non-manifold edge')} (in 3+ faces; at vertices {ex})")
    if rep["misoriented_edges"]:
        ex = ", ".join(f"{u}–{w}" for u, w in rep["misoriented_edge_examples"])
        problems.append(f"{_n(rep['misoriented_edges'], 'edge')} with inconsistent orientation (at {ex})")
    if rep["degenerate_faces"]:
        problems.append(_n(rep["degenerate_faces"], "face") + " repeating a vertex")
    if rep["nonmanifold_vertices"]:
        ex = ", ".join(map(str, rep["nonmanifold_vertex_examples"]))
        problems.append(f"{_n(rep['nonmanifold_vertices'], 'non-manifold vertex')} (bow-ties, e.g. {ex}; "
                        "allowed)")
    if rep["zero_area_faces"]:
        problems.append(_n(rep["zero_area_faces"], "zero-area face") + " (allowed)")
    if rep["unreferenced_vertices"]:
        problems.append(_n(rep["unreferenced_vertices"], "unreferenced vertex") + " (kept, never moved)")
    lines.append("  checks        " + ("; ".join(problems) if problems else "edge-manifold, consistently oriented"))
    hist = rep["valence"]
    lines.append("  valence       " + "  ".join(f"{k}:{v:,}" for k, v in sorted(hist.items())))
    if mesh.has_tags:
        lines.append(f"  tags in file  {_io.describe_tags(mesh)}")
    out["tags_in_file"] = {"sharp_edges": len(mesh.sharp_edges), "corners": len(mesh.corners),
                           "sharp_faces": len(mesh.sharp_faces)}
    if not valid:
        lines.append("  subdivide     refuses this mesh: fix the problems above first")
        out["levels"] = None
        return _emit(a, lines, out, 0)
    angle = a.feature_angle if a.feature_angle is not None else 30.0
    det = detect_features(V, F, angle)
    lines.append(f"  detected      {_n(len(det.sharp_edges), 'crease')} (dihedral > {angle:g}°), "
                 f"{_n(len(det.corners), 'corner')}")
    out["detected"] = {"angle": angle, "sharp_edges": len(det.sharp_edges), "corners": len(det.corners)}
    if mesh.uv is not None and mesh.face_uv is not None:
        k = len(_seams(mesh, a.input))
        lines.append(f"  texture       {_n(len(mesh.uv), 'UV value')}, {_n(k, 'seam')} (refined face-varying, "
                     "seams split; --scheme sqrt3 drops UVs)")
        out["texture"] = {"uv_values": len(mesh.uv), "seams": k}
    feat = gather_features(a, mesh, a.input, a.scheme)
    pred = _predict(mesh, a.levels, a.scheme, feat, path=a.input)
    out["features"] = feat.summary
    out["levels"] = pred
    lines.append(f"  subdivide     --scheme {a.scheme}: {feat.summary}")
    lines.append("                level        faces     vertices    output      peak memory")
    for p in pred:
        lines.append(f"                {p['level']:>5} {p['faces']:>12,} {p['vertices']:>12,}  "
                     f"{_bytes(p['output_bytes']):>9}  {_bytes(p['peak_bytes']):>9}")
    lines.append("                counts are exact; memory is estimated from them (output: float64 positions and")
    lines.append("                int64 faces; peak: hybridsub subdivide making that level, holding it and the one before"
                 + (", and the UV index mesh's)" if _keeps_uv(mesh, a.scheme) else ")"))
    return _emit(a, lines, out, 0)


def _emit(a, lines, out, code) -> int:
    if a.json:
        print(json.dumps(out, indent=1, default=lambda o: o.tolist() if hasattr(o, "tolist") else str(o)))
    else:
        print("\n".join(lines))
    return code


def cmd_demo(a) -> int:
    src = example_path()
    os.makedirs(a.output, exist_ok=True)
    written = []
    mesh = _io.read_mesh(src)
    ns = argparse.Namespace(sharp_edges=None, sharp_faces=None, corners=None, feature_angle=30.0,
                            ignore_tags=False, quiet=a.quiet, loop_weights="loop", force=False)
    print(f"hybridsub demo: fandisk ({len(mesh.faces):,} triangles, shipped with the package), "
          f"{_n(a.levels, 'level')} of each scheme")
    for scheme in ("hybrid", "sqrt3", "loop"):
        ns.feature_angle = None if scheme == "sqrt3" else 30.0
        feat = gather_features(ns, mesh, src, scheme)
        out, seconds = _subdivide(ns, mesh, feat, a.levels, scheme, src)
        path = os.path.join(a.output, f"fandisk.{scheme}.L{a.levels}.obj")
        _io.write(path, out)
        slow = " (includes compiling the Numba kernels: first run only, they are cached)" if (
            not written and seconds > 2) else ""
        print(f"  {SCHEME_NAMES[scheme]:<15} {len(out.faces):>9,} faces in {seconds:.2f} s → {path}{slow}")
        written.append(path)
    fig = os.path.join(a.output, "fandisk_compare.png")
    try:
        from .figure import compare_panels, render_figure

        ns.feature_angle = 30.0
        feat = gather_features(ns, mesh, src, "hybrid")
        render_figure(compare_panels(mesh.vertices, mesh.faces, a.levels, **feat.tags()), fig)
        print(f"  comparison figure → {fig}")
        written.append(fig)
    except ImportError:
        print("  (no comparison figure: it needs matplotlib — python -m pip install 'hybridsub[plot]')")
    print(f"wrote {len(written)} files to {os.path.abspath(a.output)}; creases and "
          "corners are kept as OBJ tags ('t crease', 't corner')")
    return 0


# ----------------------------------------------------------------------------------------------
# parser


def _levels(text: str) -> int:
    try:
        k = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a non-negative integer, got {text!r}") from None
    if k < 0:
        raise argparse.ArgumentTypeError(f"must be a non-negative integer, got {k}")
    return k


def _angle(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an angle in degrees, got {text!r}") from None
    if not 0 <= x <= 180:
        raise argparse.ArgumentTypeError(f"must be between 0 and 180 degrees, got {x:g}")
    return x


def _sharpness(text: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number (inf: infinitely sharp), got {text!r}") from None
    if not x > 0:
        raise argparse.ArgumentTypeError(f"must be greater than 0, got {x:g}")
    return x


def _positive(text: str) -> int:
    try:
        k = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {text!r}") from None
    if k < 1:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {k}")
    return k


def _uv_option(p) -> None:
    p.add_argument("--uv-mode", choices=("linear", "smooth"),
                   help="texture coordinates (OBJ vt, PLY s t): linear (default) interpolates them, seams kept, "
                        "the texture undistorted; smooth subdivides them like the positions")


def _tag_options(p, *, scheme=True, input_opts=True, tag_files=True) -> None:
    if scheme:
        p.add_argument("--scheme", choices=SCHEMES, default="hybrid",
                       help="hybrid (default): √3 on smooth faces, Loop on sharp ones; sqrt3: Kobbelt; loop")
    g = p.add_argument_group("features (merged when several are given)")
    g.add_argument("--feature-angle", type=_angle, metavar="DEG",
                   help="tag edges whose dihedral angle exceeds DEG degrees as creases")
    g.add_argument("--feature-sharpness", type=_sharpness, metavar="S",
                   help="sharpness of the creases --feature-angle finds (default: inf, sharp for ever; "
                        "S > 0: semi-sharp, sharp for S levels, then rounding off; no corner tags)")
    if tag_files:
        g.add_argument("--sharp-edges", metavar="FILE",
                       help="crease edges: 'i j' or 'i j sharpness' per line, 0-based")
        g.add_argument("--sharp-faces", metavar="FILE", help="faces split by Loop's rule: face indices, 0-based")
        g.add_argument("--corners", metavar="FILE", help="corner vertices: vertex indices, 0-based")
    g.add_argument("--ignore-tags", action="store_true", help="ignore crease/corner tags stored in the input file")
    if input_opts:
        g = p.add_argument_group("input")
        g.add_argument("--triangulate", action="store_true",
                       help="split polygons into triangle fans instead of refusing them")
        g.add_argument("--weld", action="store_true", help="merge vertices at identical positions first")
    p.add_argument("--loop-weights", choices=("loop", "warren"), default="loop",
                   help="smooth vertex weights in Loop regions (default: loop)")


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="hybridsub",
        description="Subdivision surfaces that keep their sharp features: hybrid √3–Loop, Kobbelt √3, "
                    "Loop with creases.",
        epilog="Exit codes: 0 success, 1 the input or the run failed, 2 bad command line. "
               "See docs/usage.md and docs/formats.md.")
    ap.add_argument("--version", action="version", version=f"hybridsub {__version__}")
    sub = ap.add_subparsers(dest="command", required=True, metavar="COMMAND")

    s = sub.add_parser("subdivide", help="subdivide a mesh file, keeping its features",
                       description="Subdivide a triangle mesh (OBJ, PLY, OFF, STL, GLB, … anything trimesh reads). "
                                   "Creases and corners stored in OBJ/PLY files are used and written back, "
                                   "propagated, when the output is OBJ or PLY.")
    s.add_argument("input", metavar="IN")
    s.add_argument("-o", "--output", metavar="OUT", required=True, help="output file; its extension picks the format")
    s.add_argument("--levels", type=_levels, default=3, help="subdivision steps (default: 3)")
    _tag_options(s)
    _uv_option(s)
    s.add_argument("--no-tags", action="store_true", help="do not write crease/corner tags into OUT")
    s.add_argument("--ascii", action="store_true", help="PLY output in ASCII instead of binary")
    s.add_argument("--force", action="store_true", help="run even if the memory estimate exceeds this machine's RAM")
    s.add_argument("-q", "--quiet", action="store_true", help="no progress bar, no messages (errors still shown)")
    s.set_defaults(func=cmd_subdivide)

    b = sub.add_parser("batch", help="subdivide many mesh files on Dask; a rerun skips what is done",
                       description="Subdivide every mesh of INPUTS (files, folders walked for mesh files, glob "
                                   "patterns — quote them) into OUTDIR, one Dask task per mesh, with the code of "
                                   "'subdivide'. A manifest (OUTDIR/hybridsub-manifest.jsonl) records each mesh as "
                                   "it finishes; running the same command again skips what is done and redoes the "
                                   "rest. Needs Dask: pip install 'hybridsub[batch]'. See docs/batch.md.",
                       epilog="Exit codes: 0 every mesh done or skipped, 1 some mesh failed (listed, and in the "
                              "manifest) or the batch could not run, 2 bad command line, 130 interrupted.")
    b.add_argument("inputs", metavar="INPUT", nargs="+", help="mesh files, folders and glob patterns")
    b.add_argument("-o", "--output", metavar="OUTDIR", required=True,
                   help="output folder; outputs mirror the inputs' names below their folder or pattern")
    b.add_argument("--levels", type=_levels, default=3, help="subdivision steps (default: 3)")
    b.add_argument("--format", choices=("obj", "ply", "npz"), default="obj",
                   help="output format (default: obj); all three keep the tags")
    _tag_options(b, tag_files=False)
    _uv_option(b)
    g = b.add_argument_group("Dask").add_mutually_exclusive_group()
    g.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on an existing cluster, e.g. tcp://10.0.0.5:8786 (default: start a local one)")
    g.add_argument("--workers", type=_positive, metavar="N",
                   help="processes of the local cluster (default: one per core)")
    b.add_argument("--verify", action="store_true",
                   help="before skipping a mesh done earlier, compare the SHA-256 of its input and output with "
                        "the manifest's")
    b.add_argument("--force", action="store_true",
                   help="run meshes whose memory estimate exceeds 80%% of their worker's memory limit")
    b.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no table; failures still listed")
    b.set_defaults(func=cmd_batch)

    c = sub.add_parser("compare", help="render input, √3, hybrid and Loop side by side into a PNG",
                       description="The paper's figures 4–6: the input with its sharp edges in red (semi-sharp in "
                                   "orange), Kobbelt √3, hybrid and Loop, same view, flat shaded, face counts "
                                   "under each. Without tags or feature options, creases are detected at 30°.")
    c.add_argument("input", metavar="IN")
    c.add_argument("-o", "--output", metavar="FIG.png", required=True)
    c.add_argument("--levels", type=_levels, default=2, help="subdivision steps (default: 2)")
    _tag_options(c, scheme=False)
    c.add_argument("--view", metavar="AZ,EL", help="turntable view in degrees (default: chosen to show the creases)")
    c.add_argument("--size", default="1600x520", metavar="WxH", help="figure size in pixels (default: 1600x520)")
    c.add_argument("--title", help="a title above the panels")
    c.add_argument("--force", action="store_true", help="run even if the memory estimate exceeds this machine's RAM")
    c.add_argument("-q", "--quiet", action="store_true")
    c.set_defaults(func=cmd_compare)

    i = sub.add_parser("info", help="counts, boundary, defects, valences, features, what subdivide would produce",
                       description="Describe a mesh: counts, boundary loops, non-manifold edges and vertices, "
                                   "orientation, valence histogram, detected features, and the faces, vertices "
                                   "and memory of each level subdivide would produce with the same options.")
    i.add_argument("input", metavar="IN")
    i.add_argument("--levels", type=_levels, default=3, help="levels to predict (default: 3)")
    _tag_options(i)
    i.add_argument("--json", action="store_true", help="machine-readable output")
    i.set_defaults(func=cmd_info, quiet=False)

    d = sub.add_parser("demo", help="subdivide the shipped fandisk example with each scheme and draw the comparison",
                       description="Runs without arguments: writes fandisk subdivided by each scheme (OBJ with "
                                   "crease tags) and the comparison figure, and says where.")
    d.add_argument("-o", "--output", default="hybridsub-demo", help="output folder (default: ./hybridsub-demo)")
    d.add_argument("--levels", type=_levels, default=2, help="subdivision steps (default: 2)")
    d.add_argument("-q", "--quiet", action="store_true", help="only the list of files written")
    d.set_defaults(func=cmd_demo)
    return ap


def main(argv=None) -> int:
    ap = build_parser()
    a = ap.parse_args(argv)
    try:
        return a.func(a)
    except CLIError as e:
        msg = str(e)
    except BrokenPipeError:  # `hybridsub info big.ply | head`: the reader left, nothing to report
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except OSError as e:  # FileNotFoundError from read_mesh carries its message; the OS's carry a filename
        msg = f"{e.filename}: {e.strerror}" if e.filename and e.strerror else str(e)
    except (MeshError, ValueError, TypeError, ImportError) as e:
        msg = str(e)
    except MemoryError:
        msg = "out of memory; use fewer levels"
    except KeyboardInterrupt:
        print("\nhybridsub: interrupted", file=sys.stderr)
        return 130
    print(f"hybridsub: error: {msg}", file=sys.stderr)
    return 1
