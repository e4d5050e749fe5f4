#!/usr/bin/env python
"""Throughput of ``hybridsub batch``: meshes/s and output faces/s on local Dask clusters.

usage: python benchmarks/batch_throughput.py [--workers 1 2] [--formats obj npz] [--meshes 200]
                                             [--copies 40] [--levels 2] [--markdown OUT.md]
                                             [--collections generated fandisk armadillo]

Collections (written as OBJ into a temporary folder):

- ``generated``: ``--meshes`` CAD-like meshes of 1,100 to 5,500 faces — toothed prisms (gears)
  with sharp rims and teeth, and tori — subdivided with ``--feature-angle 30``;
- ``fandisk``: ``--copies`` copies of fandisk (12,946 faces), the package's CAD example, and
- ``armadillo``: ``--copies // 5`` copies of armadillo (52,000 faces, benchmarks/data).

For each collection, output format and worker count: a fresh ``LocalCluster`` (its start is
timed on its own), one untimed warm-up batch on two meshes (each worker imports hybridsub and
loads the Numba cache), then ``hybridsub.batch`` into an empty folder, timed. The baseline
runs the same per-mesh function (``pipeline.subdivide_file``, what each task runs) in a loop in
this process, without Dask. Needs the ``batch`` extra (Dask).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import time

import numpy as np
from _bench import DATA, cpu_name

import hybridsub
from hybridsub._app.batch import local_cluster
from hybridsub._app.manifest import MANIFEST
from hybridsub._app.pipeline import FileOptions, subdivide_file


def gear(teeth: int, layers: int, rng) -> tuple[np.ndarray, np.ndarray]:
    """A closed prism over a star-shaped outline (4 vertices per tooth), side walls in
    ``layers`` rings, caps as fans around a centre vertex: sharp rims and tooth edges."""
    n = 4 * teeth
    ang = 2 * np.pi * (np.arange(n) + 0.5 * rng.random(n) * 0.2) / n
    r = np.where(np.arange(n) % 4 < 2, 1.0, 0.8 + 0.05 * rng.random())
    z = np.linspace(0, 0.2 + 0.3 * rng.random(), layers + 1)
    ring = np.stack([r * np.cos(ang), r * np.sin(ang)], axis=1)
    V = np.vstack([np.column_stack([ring, np.full(n, h)]) for h in z] + [[[0, 0, z[0]], [0, 0, z[-1]]]])
    F = []
    i = np.arange(n)
    j = (i + 1) % n
    for k in range(layers):
        a, b = k * n + i, k * n + j
        c, d = (k + 1) * n + j, (k + 1) * n + i
        F += [np.column_stack([a, b, c]), np.column_stack([a, c, d])]
    bottom, top = len(V) - 2, len(V) - 1
    F += [np.column_stack([np.full(n, bottom), j, i]), np.column_stack([np.full(n, top), layers * n + i,
                                                                         layers * n + j])]
    return V, np.vstack(F).astype(np.int64)


def torus(nu: int, nv: int, rng) -> tuple[np.ndarray, np.ndarray]:
    u = 2 * np.pi * np.arange(nu) / nu
    v = 2 * np.pi * np.arange(nv) / nv
    U, W = np.meshgrid(u, v, indexing="ij")
    R, r = 2.0, 0.5 + 0.4 * rng.random()
    V = np.stack([(R + r * np.cos(W)) * np.cos(U), (R + r * np.cos(W)) * np.sin(U), r * np.sin(W)], axis=2)
    V = V.reshape(-1, 3) + 0.002 * rng.standard_normal((nu * nv, 3))
    I, J = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a, b = I * nv + J, ((I + 1) % nu) * nv + J
    c, d = ((I + 1) % nu) * nv + (J + 1) % nv, I * nv + (J + 1) % nv
    F = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return V, F


def make_collections(root: str, meshes: int, copies: int) -> dict[str, str]:
    rng = np.random.default_rng(2026)
    gen = os.path.join(root, "generated")
    for k in range(meshes):
        if k % 2:
            V, F = gear(int(rng.integers(20, 41)), int(rng.integers(6, 17)), rng)
        else:
            V, F = torus(int(rng.integers(30, 60)), int(rng.integers(20, 40)), rng)
        hybridsub.write_mesh(os.path.join(gen, f"{k // 50:02d}", f"m{k:04d}.obj"), V, F)
    out = {"generated": gen}
    for name, path, n in (("fandisk", None, copies), ("armadillo", os.path.join(DATA, "armadillo.off"),
                                                      max(1, copies // 5))):
        if path is None:
            V, F = hybridsub.load_example()
        else:
            mesh = hybridsub.read_mesh(path)
            V, F = mesh.vertices, mesh.faces
        d = os.path.join(root, name)
        hybridsub.write_mesh(os.path.join(d, f"{name}-000.obj"), V, F)
        for k in range(1, n):
            shutil.copy(os.path.join(d, f"{name}-000.obj"), os.path.join(d, f"{name}-{k:03d}.obj"))
        out[name] = d
    return out


def input_faces(folder: str) -> tuple[int, int]:
    files = [os.path.join(r, f) for r, _, fs in os.walk(folder) for f in fs]
    return len(files), sum(len(hybridsub.read_mesh(f).faces) for f in files)


def baseline(folder: str, outdir: str, fmt: str, levels: int) -> tuple[float, int, dict]:
    """The per-mesh function of a batch task in a loop here: seconds, output faces, and the
    sums of its read, refine and write times."""
    a = FileOptions(levels=levels, scheme="hybrid", feature_angle=30.0, loop_weights="loop", quiet=True)
    files = sorted(os.path.join(r, f) for r, _, fs in os.walk(folder) for f in fs)
    subdivide_file(a, files[0], os.path.join(outdir, f"warm.{fmt}"))  # Numba's cache, as a worker's first task
    t = time.perf_counter()
    faces, parts = 0, dict(read=0.0, refine=0.0, write=0.0)
    for k, f in enumerate(files):
        r = subdivide_file(a, f, os.path.join(outdir, f"{k}.{fmt}"))
        faces += r.faces_out
        parts["read"] += r.seconds_read
        parts["refine"] += r.seconds_refine
        parts["write"] += r.seconds_write
    return time.perf_counter() - t, faces, parts


def run_batch(folder: str, outdir: str, fmt: str, levels: int, workers: int, warm: list[str]) -> dict:
    t = time.perf_counter()
    cluster, client = local_cluster(workers)  # the cluster batch(workers=N) starts
    with cluster, client:
        start = time.perf_counter() - t
        hybridsub.batch(warm, os.path.join(outdir, "warm"), scheduler=client, levels=levels, feature_angle=30,
                        format=fmt)
        s = hybridsub.batch(folder, os.path.join(outdir, "out"), scheduler=client, levels=levels, feature_angle=30,
                            format=fmt)
    assert s.failed == 0 and s.skipped == 0, s.table()
    with open(os.path.join(outdir, "out", MANIFEST)) as fh:
        recs = [json.loads(line) for line in fh]
    parts = {k: sum(r["seconds"][k] for r in recs) for k in ("read", "refine", "write", "total")}
    assert s.done == len(recs)
    return dict(start=start, seconds=s.seconds, faces=s.output_faces, parts=parts)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--formats", nargs="+", default=["obj", "npz"], choices=["obj", "ply", "npz"])
    ap.add_argument("--meshes", type=int, default=200, help="generated meshes (default 200)")
    ap.add_argument("--copies", type=int, default=40, help="copies of fandisk; armadillo gets a fifth (default 40)")
    ap.add_argument("--levels", type=int, default=2)
    ap.add_argument("--collections", nargs="+", default=["generated", "fandisk", "armadillo"],
                    choices=["generated", "fandisk", "armadillo"])
    ap.add_argument("--markdown", metavar="OUT.md", help="also write the table as Markdown")
    a = ap.parse_args(argv)
    root = tempfile.mkdtemp(prefix="hybridsub-batch-bench-")
    rows = []
    try:
        cols = make_collections(os.path.join(root, "in"), a.meshes, a.copies)
        print(f"# hybridsub batch throughput, {time.strftime('%Y-%m-%d')}, {cpu_name()}, "
              f"{len(os.sched_getaffinity(0))} cores, Python {sys.version.split()[0]}, hybridsub "
              f"{hybridsub.__version__}, levels {a.levels}, hybrid, --feature-angle 30")
        for name, folder in cols.items():
            if name not in a.collections:
                continue
            n, fin = input_faces(folder)
            files = sorted(os.path.join(r, f) for r, _, fs in os.walk(folder) for f in fs)
            for fmt in a.formats:
                out = os.path.join(root, "base")
                os.makedirs(out)
                sec, faces, parts = baseline(folder, out, fmt, a.levels)
                shutil.rmtree(out)
                rows.append(dict(collection=name, meshes=n, in_faces=fin, fmt=fmt, how="in-process loop",
                                 start=0.0, seconds=sec, faces=faces, parts=parts))
                print(_line(rows[-1]), flush=True)
                for w in a.workers:
                    out = os.path.join(root, f"w{w}")
                    r = run_batch(folder, out, fmt, a.levels, w, files[:2])
                    shutil.rmtree(out)
                    rows.append(dict(collection=name, meshes=n, in_faces=fin, fmt=fmt,
                                     how=f"{w} worker{'s' if w > 1 else ''}", **r))
                    print(_line(rows[-1]), flush=True)
    finally:
        shutil.rmtree(root, ignore_errors=True)
    if a.markdown:
        with open(a.markdown, "w") as fh:
            fh.write(_markdown(rows))
    return 0


def _line(r: dict) -> str:
    p = r["parts"]
    parts = f"  summed: read {p['read']:.1f} s, refine {p['refine']:.1f} s, write {p['write']:.1f} s"
    start = f"  (cluster start {r['start']:.1f} s)" if r["start"] else ""
    return (f"{r['collection']:10s} {r['meshes']:4d} meshes {r['in_faces']:>10,} faces  {r['fmt']}  "
            f"{r['how']:17s} {r['seconds']:7.2f} s  {r['meshes'] / r['seconds']:7.1f} meshes/s  "
            f"{r['faces'] / r['seconds'] / 1e6:5.2f} M faces/s{start}{parts}")


def _markdown(rows: list[dict]) -> str:
    out = ["| collection | meshes | output faces | format | run | wall | meshes/s | output faces/s | "
           "read / refine / write, summed over the meshes |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        p = r["parts"]
        parts = f"{p['read']:.1f} / {p['refine']:.1f} / {p['write']:.1f} s"
        out.append(f"| {r['collection']} | {r['meshes']} | {r['faces']:,} | {r['fmt']} | {r['how']} | "
                   f"{r['seconds']:.2f} s | {r['meshes'] / r['seconds']:.1f} | "
                   f"{r['faces'] / r['seconds'] / 1e6:.2f} M | {parts} |")
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    sys.exit(main())
