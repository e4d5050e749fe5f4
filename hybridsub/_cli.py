"""Command line: ``hybridsub demo`` and ``hybridsub subdivide IN -o OUT``."""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

from ._errors import MeshError
from ._examples import example_path
from ._features import detect_features
from ._refine import subdivide
from ._validate import SCHEMES


def _load(path: str):
    import trimesh

    if not os.path.exists(path):
        raise FileNotFoundError(f"{path}: no such file")
    mesh = trimesh.load(path, process=False, force="mesh")
    F = np.asarray(mesh.faces)
    if F.ndim != 2 or F.shape[1] != 3 or len(F) == 0:
        raise MeshError(f"{path}: not a triangle mesh")
    return np.asarray(mesh.vertices, dtype=np.float64), F


def _save(path: str, V, F) -> None:
    import trimesh

    d = os.path.dirname(os.path.abspath(path))
    os.makedirs(d, exist_ok=True)
    trimesh.Trimesh(V, F, process=False).export(path)


def _read_edges(path: str) -> np.ndarray:
    E = np.loadtxt(path, dtype=np.int64, ndmin=2, comments="#")
    if E.size and E.shape[1] != 2:
        raise MeshError(f"{path}: expected one edge 'i j' per line, got {E.shape[1]} columns")
    return E.reshape(-1, 2)


def _run(V, F, levels, scheme, feature_angle, sharp_edges_file, loop_weights, quiet):
    sharp, corners, used = None, None, "boundary only"
    if scheme != "sqrt3":
        if sharp_edges_file:
            sharp = _read_edges(sharp_edges_file)
            used = f"{len(sharp)} sharp edges from {sharp_edges_file}"
        elif feature_angle is not None:
            feat = detect_features(V, F, feature_angle)
            sharp, corners = feat.sharp_edges, feat.corners
            used = f"{len(sharp)} sharp edges (dihedral > {feature_angle:g}°), {len(corners)} corners"
    else:
        used = "none (Kobbelt's √3 takes no feature tags)"
    t = time.perf_counter()
    V2, F2 = subdivide(V, F, sharp, levels, scheme=scheme, corners=corners, loop_weights=loop_weights)
    dt = time.perf_counter() - t
    if not quiet:
        print(f"features: {used}", file=sys.stderr)
        print(f"{scheme}, {levels} level(s): {len(F)} -> {len(F2)} faces, {len(V2)} vertices "
              f"in {dt:.2f} s", file=sys.stderr)
    return V2, F2


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="hybridsub", description="Subdivision surfaces that keep their sharp features.")
    sub = ap.add_subparsers(dest="command", required=True)

    d = sub.add_parser("demo", help="subdivide the shipped fandisk example and write the results")
    d.add_argument("-o", "--output", default="hybridsub-demo", help="output folder (default: ./hybridsub-demo)")
    d.add_argument("--levels", type=int, default=2)

    s = sub.add_parser("subdivide", help="subdivide a mesh file (any format trimesh reads)")
    s.add_argument("input")
    s.add_argument("-o", "--output", required=True)
    s.add_argument("--levels", type=int, default=1)
    s.add_argument("--scheme", choices=SCHEMES, default="hybrid")
    s.add_argument("--feature-angle", type=float, default=None,
                   help="tag edges with a dihedral angle above this many degrees as creases")
    s.add_argument("--sharp-edges", default=None, help="text file with one crease 'i j' per line")
    s.add_argument("--loop-weights", choices=("loop", "warren"), default="loop")
    s.add_argument("-q", "--quiet", action="store_true")

    a = ap.parse_args(argv)
    try:
        if a.command == "demo":
            V, F = _load(example_path())
            os.makedirs(a.output, exist_ok=True)
            written = []
            for scheme, angle in (("hybrid", 30.0), ("sqrt3", None), ("loop", 30.0)):
                V2, F2 = _run(V, F, a.levels, scheme, angle, None, "loop", False)
                path = os.path.join(a.output, f"fandisk.{scheme}.L{a.levels}.obj")
                _save(path, V2, F2)
                written.append(path)
            print("wrote " + ", ".join(written))
            return 0
        V, F = _load(a.input)
        V2, F2 = _run(V, F, a.levels, a.scheme, a.feature_angle, a.sharp_edges, a.loop_weights, a.quiet)
        _save(a.output, V2, F2)
        if not a.quiet:
            print(f"wrote {a.output}", file=sys.stderr)
        return 0
    except (MeshError, ValueError, TypeError, FileNotFoundError, OSError) as e:
        print(f"hybridsub: error: {e}", file=sys.stderr)
        return 1
