"""Command line: ``hybridsub subdivide | batch | compare | info | demo | fit | decompose``.

Messages go to stderr (``--quiet`` silences all but errors), ``info`` writes its report to
stdout. Exit codes: 0 success, 1 the input or the run failed (one line naming the problem),
2 bad command line, 130 interrupted. Each command turns its arguments into the pipeline's
:class:`~hybridsub._app.pipeline.FileOptions`; the work is the pipeline's.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

# Only what building the parser needs is imported here, so that `hybridsub --help` and a bad
# command line answer without loading NumPy, SciPy and Numba; each command imports its own.
from .._errors import MeshError
from .._typing import SCHEMES
from .._version import __version__

#: The documentation site (the guide and the API reference); pip does not install docs/.
DOCS_URL = "https://hybridsub.readthedocs.io"


def _file_options(a: argparse.Namespace, **changes):
    """The pipeline's options from a command's arguments (those it has), with ``changes``."""
    import dataclasses

    from .pipeline import FileOptions

    given = {f.name: getattr(a, f.name) for f in dataclasses.fields(FileOptions) if hasattr(a, f.name)}
    return FileOptions(**{**given, **changes})


# ----------------------------------------------------------------------------------------------
# commands


def cmd_subdivide(a) -> int:
    from .pipeline import PipelineError, subdivide_file

    if a.tolerance is not None and a.levels != 1:
        raise PipelineError("--levels and --tolerance exclude each other: --tolerance chooses the levels")
    if not os.path.splitext(a.output)[1]:
        raise PipelineError(f"{a.output}: give the output file an extension (.obj, .ply, .off, .npz, .stl, .glb, …)")
    _writable(a.output, binary=not a.ascii)
    subdivide_file(_file_options(a), a.input, a.output)
    return 0


def cmd_batch(a) -> int:
    from .batch import batch
    from .manifest import status_report
    from .pipeline import PipelineError

    if a.status is not None and (a.inputs or a.output):
        a.batch_parser.error("--status OUTDIR takes no INPUT and no -o")  # exits with 2
    if a.status is None and not (a.inputs and a.output):
        a.batch_parser.error("give INPUTs and -o OUTDIR (or --status OUTDIR)")
    if a.status is not None:
        text, failed = status_report(a.status)
        print(text)
        return 1 if failed else 0
    try:
        s = batch(a.inputs, a.output, levels=a.levels, scheme=a.scheme, feature_angle=a.feature_angle,
                  feature_sharpness=a.feature_sharpness, uv_mode=a.uv_mode, boundary=a.boundary, format=a.format,
                  loop_weights=a.loop_weights, ignore_tags=a.ignore_tags, triangulate=a.triangulate, weld=a.weld,
                  force=a.force, scheduler=a.scheduler, workers=a.workers, verify=a.verify, dry_run=a.dry_run,
                  lock=not a.no_lock, fsync=a.fsync, progress=not a.quiet and sys.stderr.isatty())
    except RuntimeError as e:
        raise PipelineError(str(e)) from None
    if s.dry_run:
        print(s.table(), file=sys.stderr)
        return 0
    lines = s.failure_lines() if a.quiet else [s.table()]
    if lines:
        print("\n".join(lines), file=sys.stderr)
    return 0 if s.ok else 1


def cmd_compare(a) -> int:
    from .figure import compare_panels, render_figure
    from .._input import count_of
    from .pipeline import PipelineError, check_memory, gather_features, load_mesh, predict_file_levels, say

    if not a.output.lower().endswith(".png"):
        raise PipelineError(f"{a.output}: the figure is written as PNG; give a .png file name")
    width, height = _size(a.size)
    view = _view(a.view) if a.view else None
    opts = _file_options(a)
    mesh = load_mesh(opts, a.input)
    feat = gather_features(opts, mesh, a.input)
    say(opts, feat.summary)
    for scheme in ("hybrid", "loop"):
        check_memory(opts, predict_file_levels(mesh, a.levels, scheme, feat, uv=False),
                     f"{count_of(a.levels, 'level')} of {scheme}")
    t = time.perf_counter()
    try:
        panels = compare_panels(mesh.vertices, mesh.faces, a.levels, loop_weights=a.loop_weights, **feat.tags())
    except MeshError as e:
        raise PipelineError(f"{a.input}: {e}") from None
    t1 = time.perf_counter()
    used = render_figure(panels, a.output, width=width, height=height, view=view,
                         title=a.title)
    t2 = time.perf_counter()
    say(opts, "faces: " + ", ".join(f"{p.title.split(',')[0]} {len(p.F):,}" for p in panels))
    say(opts, f"wrote {a.output} ({width}×{height}, view {used[0]:g},{used[1]:g}: reuse with --view "
            f"{used[0]:g},{used[1]:g}) — subdivided in {t1 - t:.2f} s, rendered in {t2 - t1:.2f} s")
    return 0


def _size(text: str) -> tuple[int, int]:
    from .pipeline import PipelineError

    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise PipelineError(f"--size must look like 1600x520, got {text!r}") from None
    if not (64 <= w <= 16000 and 64 <= h <= 16000):
        raise PipelineError(f"--size must be between 64 and 16000 pixels each way, got {text!r}")
    return w, h


def _view(text: str) -> tuple[float, float]:
    from .pipeline import PipelineError

    try:
        az, el = (float(x) for x in text.split(","))
    except ValueError:
        raise PipelineError(f"--view must be AZIMUTH,ELEVATION in degrees, e.g. 225,-35; got {text!r}") from None
    return az, el


def cmd_info(a) -> int:
    import numpy as np

    from .. import _io
    from .._input import count_of
    from .pipeline import load_mesh
    from .report import mesh_report

    opts = _file_options(a)
    mesh = load_mesh(opts, a.input)
    rep = mesh_report(mesh.vertices, mesh.faces)
    valid = not (rep["nonmanifold_edges"] or rep["misoriented_edges"] or rep["degenerate_faces"])
    out = {"file": a.input, "report": {k: v for k, v in rep.items() if k != "bbox"},
           "bbox": rep["bbox"].tolist()}
    lines = [f"{a.input}: {rep['vertices']:,} vertices, {rep['faces']:,} triangles, {rep['edges']:,} edges"]
    lo, hi = rep["bbox"]
    lines.append(f"  size          {' × '.join(f'{x:.4g}' for x in hi - lo)} "
                 f"(from {', '.join(f'{x:.4g}' for x in lo)}), diagonal {np.linalg.norm(hi - lo):.4g}")
    topo = (f"{count_of(rep['components'], 'component')}, Euler characteristic {rep['euler']}"
            + (f", genus {rep['genus']}" if rep["genus"] is not None else ""))
    lines.append(f"  topology      {topo}")
    if rep["boundary_edges"]:
        lines.append(f"  boundary      {count_of(rep['boundary_loops'], 'loop')}, "
                     f"{count_of(rep['boundary_edges'], 'edge')}")
    else:
        lines.append("  boundary      none (closed)")
    problems = _problems(rep)
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
    else:
        _info_subdivide(a, opts, mesh, lines, out)
    return _emit(a, lines, out, 0)


def _problems(rep: dict) -> list[str]:
    """What ``info`` reports as wrong (or merely unusual) with a mesh, from its report."""
    from .._input import count_of

    problems = []
    if rep["nonmanifold_edges"]:
        ex = ", ".join(f"{u}–{w}" for u, w in rep["nonmanifold_edge_examples"])
        problems.append(f"{count_of(rep['nonmanifold_edges'], 'non-manifold edge')} (in 3+ faces; at vertices {ex})")
    if rep["misoriented_edges"]:
        ex = ", ".join(f"{u}–{w}" for u, w in rep["misoriented_edge_examples"])
        problems.append(f"{count_of(rep['misoriented_edges'], 'edge')} with inconsistent orientation (at {ex})")
    if rep["degenerate_faces"]:
        problems.append(count_of(rep["degenerate_faces"], "face") + " repeating a vertex")
    if rep["nonmanifold_vertices"]:
        ex = ", ".join(map(str, rep["nonmanifold_vertex_examples"]))
        problems.append(f"{count_of(rep['nonmanifold_vertices'], 'non-manifold vertex')} (bow-ties, e.g. {ex}; "
                        "allowed)")
    if rep["zero_area_faces"]:
        problems.append(count_of(rep["zero_area_faces"], "zero-area face") + " (allowed)")
    if rep["unreferenced_vertices"]:
        problems.append(count_of(rep["unreferenced_vertices"], "unreferenced vertex") + " (kept, never moved)")
    return problems


def _info_subdivide(a, opts, mesh, lines: list[str], out: dict) -> None:
    """``info``'s lines on a valid mesh: detected features, texture, and what subdivide would make."""
    from .._input import count_of, detect_features
    from .._units import short_bytes
    from .pipeline import gather_features, keeps_uv, predict_file_levels, seams

    angle = a.feature_angle if a.feature_angle is not None else 30.0
    det = detect_features(mesh.vertices, mesh.faces, angle)
    lines.append(f"  detected      {count_of(len(det.sharp_edges), 'crease')} (dihedral > {angle:g}°), "
                 f"{count_of(len(det.corners), 'corner')}")
    out["detected"] = {"angle": angle, "sharp_edges": len(det.sharp_edges), "corners": len(det.corners)}
    if mesh.uv is not None and mesh.face_uv is not None:
        k = len(seams(mesh, a.input))
        lines.append(f"  texture       {count_of(len(mesh.uv), 'UV value')}, {count_of(k, 'seam')} (refined "
                     "face-varying, seams split; --scheme sqrt3 drops UVs)")
        out["texture"] = {"uv_values": len(mesh.uv), "seams": k}
    feat = gather_features(opts, mesh, a.input)
    pred = predict_file_levels(mesh, a.levels, a.scheme, feat, path=a.input)
    out["features"] = feat.summary
    out["levels"] = pred
    lines.append(f"  subdivide     --scheme {a.scheme}: {feat.summary}")
    lines.append("                level        faces     vertices    output      peak memory")
    for p in pred:
        lines.append(f"                {p['level']:>5} {p['faces']:>12,} {p['vertices']:>12,}  "
                     f"{short_bytes(p['output_bytes']):>9}  {short_bytes(p['peak_bytes']):>9}")
    lines.append("                counts are exact; memory is estimated from them (output: float64 positions and")
    lines.append("                int64 faces; peak: hybridsub subdivide making that level, holding it and the one "
                 "before" + (", and the UV index mesh's)" if keeps_uv(mesh, a.scheme) else ")"))
    _info_adaptive(a, mesh, feat, lines, out)


def _info_adaptive(a, mesh, feat, lines: list[str], out: dict) -> None:
    """``info``'s adaptive lines: with ``--tolerance``, what adaptive refinement makes."""
    import warnings

    import numpy as np

    from .._surface.adaptive import AdaptiveWarning, adaptive_result

    if a.tolerance is None:
        lines.append("  adaptive      add --tolerance TOL (e.g. 0.1%) to see what adaptive refinement would make")
        return
    t = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AdaptiveWarning)
        res = adaptive_result(mesh.vertices, mesh.faces, tolerance=a.tolerance, max_levels=a.max_levels,
                              scheme=a.scheme, loop_weights=a.loop_weights, **feat.tags())
    seconds = time.perf_counter() - t
    counts = np.bincount(res.refinement.face_level)
    reached = "reached" if res.error <= res.tolerance else f"NOT reached in {a.max_levels} levels"
    lines.append(f"  adaptive      --tolerance {a.tolerance} = {res.tolerance:.4g}: {len(res.refinement.faces):,} faces, "
                 f"{len(res.positions):,} vertices, error {res.error:.4g} ({reached}), {seconds:.1f} s")
    lines.append("                faces per level: " + "  ".join(f"{j}:{c:,}" for j, c in enumerate(counts) if c))
    out["adaptive"] = {"tolerance": res.tolerance, "faces": len(res.refinement.faces),
                       "vertices": len(res.positions), "error": res.error,
                       "faces_per_level": counts.tolist(), "seconds": seconds}


def _emit(a, lines, out, code) -> int:
    if a.json:
        print(json.dumps(out, indent=1, default=lambda o: o.tolist() if hasattr(o, "tolist") else str(o)))
    else:
        print("\n".join(lines))
    return code


def cmd_demo(a) -> int:
    import dataclasses

    from .. import _io
    from .._input import count_of
    from .pipeline import SCHEME_NAMES, FileOptions, gather_features, refine_mesh

    src = _io.example_path()
    os.makedirs(a.output, exist_ok=True)
    written = []
    mesh = _io.read_mesh(src)
    opts = FileOptions(levels=a.levels, feature_angle=30.0, quiet=a.quiet)
    print(f"hybridsub demo: fandisk ({len(mesh.faces):,} triangles, shipped with the package), "
          f"{count_of(a.levels, 'level')} of each scheme")
    for scheme in ("hybrid", "sqrt3", "loop"):
        run = dataclasses.replace(opts, scheme=scheme, feature_angle=None if scheme == "sqrt3" else 30.0)
        out, seconds = refine_mesh(run, mesh, gather_features(run, mesh, src), src)
        path = os.path.join(a.output, f"fandisk.{scheme}.L{a.levels}.obj")
        _io.write(path, out)
        slow = " (includes compiling the Numba kernels: first run only, they are cached)" if (
            not written and seconds > 2) else ""
        print(f"  {SCHEME_NAMES[scheme]:<15} {len(out.faces):>9,} faces in {seconds:.2f} s → {path}{slow}")
        written.append(path)
    fig = os.path.join(a.output, "fandisk_compare.png")
    try:
        from .figure import compare_panels, render_figure

        feat = gather_features(opts, mesh, src)
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


def _tolerance(text: str) -> str:
    value = text.strip()
    try:
        x = float(value[:-1]) if value.endswith("%") else float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a positive number or a percentage such as 0.1%, got {text!r}") \
            from None
    if not (x > 0 and x != float("inf")):
        raise argparse.ArgumentTypeError(f"must be positive and finite, got {text!r}")
    return value


def _tolerance_options(p, help_text: str) -> None:
    p.add_argument("--tolerance", type=_tolerance, metavar="TOL", help=help_text)
    p.add_argument("--max-levels", type=_levels, default=8, metavar="L",
                   help="with --tolerance: the most levels any face gets (default: 8)")


def _uv_option(p) -> None:
    p.add_argument("--uv-mode", choices=("linear", "smooth"),
                   help="texture coordinates (OBJ vt, PLY s t): linear (default) interpolates them, seams kept, "
                        "the texture undistorted; smooth subdivides them like the positions")
    p.add_argument("--uv-interpolation", dest="uv_mode",
                   choices=("none", "corners_only", "corners_plus1", "corners_plus2", "boundaries", "all"),
                   help="OpenSubdiv's face-varying modes (FVarLinearInterpolation): what is kept linear at UV "
                        "seams and boundaries; all = --uv-mode linear, none = --uv-mode smooth")


def _scheme_option(p) -> None:
    p.add_argument("--scheme", choices=SCHEMES, default="hybrid",
                   help="hybrid (default): √3 on smooth faces, Loop on sharp ones; sqrt3: Kobbelt; loop")


def _tag_options(p, *, scheme=True, input_opts=True, tag_files=True) -> None:
    if scheme:
        _scheme_option(p)
    g = p.add_argument_group("features (merged when several are given)")
    g.add_argument("--feature-angle", type=_angle, metavar="DEG",
                   help="tag edges whose dihedral angle exceeds DEG degrees as creases")
    g.add_argument("--feature-sharpness", type=_sharpness, metavar="S",
                   help="sharpness of the creases --feature-angle finds (default: inf, sharp for ever; "
                        "S > 0: semi-sharp, sharp for S levels, then rounding off; no corner tags)")
    if tag_files:
        g.add_argument("--sharp-edges", metavar="FILE", dest="sharp_edges_file",
                       help="crease edges: 'i j' or 'i j sharpness' per line, 0-based")
        g.add_argument("--sharp-faces", metavar="FILE", dest="sharp_faces_file",
                       help="faces split by Loop's rule: face indices, 0-based")
        g.add_argument("--corners", metavar="FILE", dest="corners_file",
                       help="corner vertices: vertex indices, 0-based")
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
               f"Documentation (the guide and the API reference): {DOCS_URL}")
    ap.add_argument("--version", action="version", version=f"hybridsub {__version__}")
    ap.add_argument("--threads", type=_positive, metavar="N",
                    help="threads for the kernels (default: every core); the output does not depend on it")
    sub = ap.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for add in (_add_subdivide, _add_batch, _add_compare, _add_info, _add_demo, _add_fit, _add_decompose,
                _add_warmup):
        add(sub)
    return ap


def _add_subdivide(sub) -> None:
    s = sub.add_parser("subdivide", help="subdivide a mesh file, keeping its features",
                       description="Subdivide a triangle mesh (OBJ, PLY, OFF, STL, GLB, VTK, VTU, … anything trimesh "
                                   "or meshio reads). Creases and corners stored in the file are used and "
                                   "written back, propagated, when the output is OBJ, PLY, NPZ or a meshio "
                                   "format (VTK, VTU, …).")
    s.add_argument("input", metavar="IN")
    s.add_argument("-o", "--output", metavar="OUT", required=True, help="output file; its extension picks the format")
    s.add_argument("--levels", type=_levels, default=1, help="subdivision steps (default: 1)")
    _tolerance_options(s, "refine adaptively instead of --levels: only where the mesh is farther than TOL from "
                          "the limit surface, until it is within TOL everywhere (mesh units, or '0.1%%' of the "
                          "bounding-box diagonal); see docs/adaptive.md")
    _tag_options(s)
    _uv_option(s)
    s.add_argument("--non-manifold", choices=("raise", "cut"), default="raise", dest="non_manifold",
                   help="edges in three or more faces, or inconsistently oriented: refuse (raise, the default) or cut "
                        "the mesh along them (cut; the pieces meet at creases)")
    _boundary_option(s)
    s.add_argument("--no-tags", action="store_true", help="do not write crease/corner tags into OUT")
    s.add_argument("--ascii", action="store_true", help="PLY output in ASCII instead of binary")
    s.add_argument("--force", action="store_true", help="run even if the memory estimate exceeds this machine's RAM")
    s.add_argument("-q", "--quiet", action="store_true", help="no progress bar, no messages (errors still shown)")
    s.set_defaults(func=cmd_subdivide)


def _add_batch(sub) -> None:
    b = sub.add_parser("batch", help="subdivide many mesh files on Dask; a rerun skips what is done",
                       description="Subdivide every mesh of INPUTS (files, folders walked for mesh files, glob "
                                   "patterns — quote them) into OUTDIR, one Dask task per mesh, with the code of "
                                   "'subdivide'. A manifest (OUTDIR/hybridsub-manifest.sqlite) records each mesh as "
                                   "it finishes; running the same command again skips what is done and redoes the "
                                   "rest; --status OUTDIR reports it. Needs Dask: pip install 'hybridsub[batch]'. "
                                   "See docs/batch.md.",
                       epilog="Exit codes: 0 every mesh done or skipped, 1 some mesh failed (listed, and in the "
                              "manifest) or the batch could not run, 2 bad command line, 130 interrupted.")
    b.add_argument("inputs", metavar="INPUT", nargs="*", help="mesh files, folders and glob patterns")
    b.add_argument("-o", "--output", metavar="OUTDIR",
                   help="output folder; outputs mirror the inputs' names below their folder or pattern")
    b.add_argument("--levels", type=_levels, default=1, help="subdivision steps (default: 1)")
    b.add_argument("--format", choices=("obj", "ply", "npz"), default="obj",
                   help="output format (default: obj); all three keep the tags")
    _tag_options(b, tag_files=False)
    _uv_option(b)
    _boundary_option(b)
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
    b.add_argument("--dry-run", action="store_true",
                   help="only say what would be done, redone and skipped: no cluster, nothing written")
    b.add_argument("--status", metavar="OUTDIR",
                   help="report the manifest of OUTDIR (meshes done and failed, the failures' messages) and exit")
    b.add_argument("--no-lock", action="store_true",
                   help="do not lock OUTDIR against a second batch (for file systems without locks: run one batch "
                        "per OUTDIR)")
    b.add_argument("--fsync", action="store_true",
                   help="flush each output and manifest update to the disk (survives a power loss; slower)")
    b.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no table; failures still listed")
    b.set_defaults(func=cmd_batch, batch_parser=b)


def _boundary_option(p) -> None:
    p.add_argument("--boundary", choices=("edge_only", "edge_and_corner", "none"), default="edge_only",
                   help="OpenSubdiv's boundary interpolation: the boundary is a crease (edge_only, the default); its "
                        "vertices in one face are corners too (edge_and_corner); or as edge_only with the faces at "
                        "the boundary left out (none)")


def _add_compare(sub) -> None:
    c = sub.add_parser("compare", help="render input, √3, hybrid and Loop side by side into a PNG",
                       description="The paper's figures 4–6: the input with its sharp edges in red (semi-sharp in "
                                   "orange), Kobbelt √3, hybrid and Loop, same view, flat shaded, face counts "
                                   "under each. Creases are those of the file's tags and the feature options, as in 'subdivide' "
                                   "(--feature-angle 30 detects them).")
    c.add_argument("input", metavar="IN")
    c.add_argument("-o", "--output", metavar="FIG.png", required=True)
    c.add_argument("--levels", type=_levels, default=1, help="subdivision steps (default: 1)")
    _tag_options(c, scheme=False)
    c.add_argument("--view", metavar="AZ,EL", help="turntable view in degrees (default: chosen to show the creases)")
    c.add_argument("--size", default="1600x520", metavar="WxH", help="figure size in pixels (default: 1600x520)")
    c.add_argument("--title", help="a title above the panels")
    c.add_argument("--force", action="store_true", help="run even if the memory estimate exceeds this machine's RAM")
    c.add_argument("-q", "--quiet", action="store_true")
    c.set_defaults(func=cmd_compare)


def _add_info(sub) -> None:
    i = sub.add_parser("info", help="counts, boundary, defects, valences, features, what subdivide would produce",
                       description="Describe a mesh: counts, boundary loops, non-manifold edges and vertices, "
                                   "orientation, valence histogram, detected features, and the faces, vertices "
                                   "and memory of each level subdivide would produce with the same options.")
    i.add_argument("input", metavar="IN")
    i.add_argument("--levels", type=_levels, default=1, help="levels to predict (default: 1)")
    _tolerance_options(i, "also run adaptive refinement to TOL (mesh units or '0.1%%' of the diagonal) and report "
                          "the faces it makes per level beside the uniform levels")
    _tag_options(i)
    i.add_argument("--json", action="store_true", help="machine-readable output")
    i.set_defaults(func=cmd_info, quiet=False)


def _add_demo(sub) -> None:
    d = sub.add_parser("demo", help="subdivide the shipped fandisk example with each scheme and draw the comparison",
                       description="Runs without arguments: writes fandisk subdivided by each scheme (OBJ with "
                                   "crease tags) and the comparison figure, and says where.")
    d.add_argument("-o", "--output", default="hybridsub-demo", help="output folder (default: ./hybridsub-demo)")
    d.add_argument("--levels", type=_levels, default=1, help="subdivision steps (default: 1)")
    d.add_argument("-q", "--quiet", action="store_true", help="only the list of files written")
    d.set_defaults(func=cmd_demo)


# ----------------------------------------------------------------------------------------------
# fit and decompose (issue 15): the work is in _app/fit_command.py


def _writable(path: str, binary: bool = True) -> None:
    """Refuse an output format that cannot hold a mesh (``-o out.xyz``) before the work, not after."""
    from .. import _io

    _io.check_writable(path, binary=binary)


def cmd_fit(a) -> int:
    from .fit_command import fit_file

    _writable(a.output)
    return fit_file(a.control, a.target, a.output, levels=a.levels, scheme=a.scheme, smoothness=a.smoothness,
                    max_iterations=a.max_iterations, tol=a.tol, quiet=a.quiet)


def cmd_decompose(a) -> int:
    from .fit_command import decompose_file

    _writable(a.output)
    return decompose_file(a.coarse, a.fine, a.output, levels=a.levels, scheme=a.scheme, quiet=a.quiet)


def _add_fit(sub) -> None:
    f = sub.add_parser("fit", help="fit a control mesh's subdivision surface to points (a scan, a dense mesh)",
                       description="Fit the control positions of CONTROL (its connectivity and tags kept) so that "
                                   "its limit surface, or its level-L mesh with --levels, is closest to the "
                                   "points of TARGET (a mesh's vertices, or .xyz/.txt/.csv/.npy points). "
                                   "Writes the fitted control mesh with its tags. See docs/fitting.md.")
    f.add_argument("control", help="control mesh with its tags (its positions are the start)")
    f.add_argument("target", help="target points: a mesh file or a point file")
    f.add_argument("-o", "--output", required=True, help="fitted control mesh (OBJ, PLY, NPZ keep the tags)")
    f.add_argument("--levels", type=_levels, default=None, help="fit the level-L mesh (default: the limit surface)")
    _scheme_option(f)
    f.add_argument("--smoothness", type=float, default=0.0, help="fairness weight (default 0)")
    f.add_argument("--max-iterations", type=int, default=50)
    f.add_argument("--tol", type=float, default=1e-12)
    f.add_argument("-q", "--quiet", action="store_true", help="no progress messages")
    f.set_defaults(func=cmd_fit)


def _add_decompose(sub) -> None:
    d = sub.add_parser("decompose", help="reverse subdivision: coarse positions and details of a refined mesh",
                       description="FINE is level L of COARSE's refinement (same numbering, e.g. written by "
                                   "`hybridsub subdivide`, then edited). Writes COARSE's mesh with the "
                                   "least-squares coarse positions to OUTPUT and the details (local frames) to "
                                   "OUTPUT's stem + .details.npz. See docs/fitting.md.")
    d.add_argument("coarse", help="the coarse mesh with its tags")
    d.add_argument("fine", help="the refined (and edited) mesh")
    d.add_argument("-o", "--output", required=True)
    d.add_argument("--levels", type=_levels, required=True, help="levels between COARSE and FINE")
    _scheme_option(d)
    d.add_argument("-q", "--quiet", action="store_true")
    d.set_defaults(func=cmd_decompose)


def cmd_warmup(a) -> int:
    from .warmup import warm_up

    if not a.quiet:
        print("hybridsub: compiling every kernel ahead (once per machine and install)", file=sys.stderr)
    seconds = warm_up(quiet=a.quiet)
    if not a.quiet:
        print(f"hybridsub: kernels ready in {seconds:.1f} s; later calls compile nothing", file=sys.stderr)
    return 0


def _add_warmup(sub) -> None:
    w = sub.add_parser("warmup", help="compile every kernel ahead (for images, CI and clusters)",
                       description="Runs one small call of every kind, so that Numba compiles and caches every "
                                   "kernel now (NUMBA_CACHE_DIR, else __pycache__) and no later call waits for it.")
    w.add_argument("-q", "--quiet", action="store_true", help="no progress messages")
    w.set_defaults(func=cmd_warmup)


def main(argv=None) -> int:
    ap = build_parser()
    a = ap.parse_args(argv)
    from .pipeline import PipelineError  # after parsing: --help and usage errors load nothing heavy

    try:
        if a.threads is not None:
            from .._jit import set_threads

            set_threads(a.threads)
        return a.func(a)
    except PipelineError as e:
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
