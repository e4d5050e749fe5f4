#!/usr/bin/env python
"""Throughput of ``hybridsub batch``: meshes/s and output faces/s on local Dask clusters; the
client's cost of a rerun against the number of inputs; the per-task overhead.

usage: python benchmarks/batch_throughput.py [--workers 1 2] [--formats obj npz] [--meshes 200]
                                             [--copies 40] [--levels 2] [--markdown OUT.md]
                                             [--collections generated fandisk armadillo]
       python benchmarks/batch_throughput.py --rerun 1000 10000 100000
       python benchmarks/batch_throughput.py --overhead 400 [--workers 1 2]

``--rerun N…``: for each N, N one-byte inputs and their outputs, a manifest recording all of
them done (as a run leaves it), then ``hybridsub.batch`` on them in a fresh process: its wall
time (walk, manifest queries, two ``stat`` per input; no cluster is started, as there is
nothing to do) and its peak resident memory above what the process held before the call
(``VmHWM`` reset through ``/proc/self/clear_refs``), each per input, and their
extrapolation to 10⁶ inputs.

``--overhead N``: N tetrahedra (4 faces, one level: the mesh work is ~nothing) subdivided by a
batch on a started, warmed cluster of 1 and 2 workers, against the same files subdivided in
a loop in this process (``pipeline.subdivide_file``): meshes/s, and the per-task overhead,
(batch wall × workers − loop time) / N, what a task costs beyond its mesh; the part of it
inside the task (the records' ``seconds.total`` summed, less the loop); and, for scale, N bare
Dask tasks (``client.map`` of the identity) on the same cluster.

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
import subprocess
import sys
import tempfile
import time

import numpy as np
from _bench import DATA, cpu_name

import hybridsub
from hybridsub._app.batch import local_cluster
from hybridsub._app.manifest import Manifest
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
    m = Manifest(os.path.join(outdir, "out"), readonly=True)
    recs = list(m.records())
    m.close()
    parts = {k: sum(r["seconds"][k] for r in recs) for k in ("read", "refine", "write", "total")}
    assert s.done == len(recs)
    return dict(start=start, seconds=s.seconds, faces=s.output_faces, parts=parts)


# ----------------------------------------------------------------------------------------------
# the client's cost of a rerun, and the per-task overhead


def done_collection(root: str, n: int) -> tuple[str, str]:
    """``root/in`` with n one-byte inputs in folders of 1,000, ``root/out`` with their outputs and a
    manifest that records them all done with ``batch``'s default options."""
    from hybridsub._app.batch import batch_options, options_key
    from hybridsub._app.manifest import Manifest

    key = options_key(batch_options(3, "hybrid", None, None, "loop", "obj", False, False, False, None),
                      hybridsub.__version__)
    src, out = os.path.join(root, "in"), os.path.join(root, "out")
    m = None
    rows, names = [], []
    for i in range(n):
        sub = f"d{i // 1000:04d}"
        if i % 1000 == 0:
            os.makedirs(os.path.join(src, sub))
            os.makedirs(os.path.join(out, sub))
            m = m or Manifest(out)
        path = os.path.join(src, sub, f"m{i:07d}.obj")
        with open(path, "w") as fh:
            fh.write("v")
        with open(os.path.join(out, sub, f"m{i:07d}.obj"), "w") as fh:
            fh.write("vv")
        names.append((path, f"{sub}/m{i:07d}"))
        rows.append({"input": path, "options_key": key, "status": "done", "output": f"{sub}/m{i:07d}.obj",
                     "input_size": 1, "input_mtime_ns": os.stat(path).st_mtime_ns, "output_size": 2,
                     "output_sha256": "0" * 64, "input_sha256": "0" * 64, "faces_in": 4, "faces_out": 16,
                     "vertices_out": 10, "features": "none", "notes": [], "reason": "new", "run": "bench",
                     "seconds": {"read": 0.001, "refine": 0.001, "write": 0.001, "total": 0.003},
                     "worker": "tcp://127.0.0.1:40000", "finished": "2026-12-01T00:00:00.000+00:00"})
        if len(rows) == 10000:
            m.take_names(names)
            m.record(rows)
            rows, names = [], []
    m.take_names(names)
    m.record(rows)
    m.close()
    return src, out


def _rss_peak_kb() -> int:
    with open("/proc/self/status") as fh:
        return next(int(line.split()[1]) for line in fh if line.startswith("VmHWM:"))


def _rss_kb() -> int:
    with open("/proc/self/status") as fh:
        return next(int(line.split()[1]) for line in fh if line.startswith("VmRSS:"))


def rerun_child(src: str, out: str) -> None:
    """In a fresh process: one batch over ``src`` into ``out``, all done: its seconds and peak memory."""
    import distributed  # noqa: F401 (imported before the measurement, as the batch imports it)

    before = _rss_kb()
    with open("/proc/self/clear_refs", "w") as fh:
        fh.write("5")  # VmHWM := VmRSS
    t, c = time.perf_counter(), os.times()
    s = hybridsub.batch(src, out)
    sec, c2 = time.perf_counter() - t, os.times()
    cpu = c2.user + c2.system - c.user - c.system
    print(json.dumps(dict(n=s.total, skipped=s.skipped, seconds=sec, cpu=cpu, peak_kb=_rss_peak_kb() - before,
                          cluster=s.cluster)))


def speed_reference() -> float:
    """Seconds for 10⁶ turns of an empty Python loop now (about 0.02 s on an idle core): how much
    the machine's other load slows Python code down at the moment."""
    t = time.perf_counter()
    for _ in range(1_000_000):
        pass
    return time.perf_counter() - t


def rerun_scaling(root: str, sizes: list[int]) -> list[dict]:
    rows = []
    for n in sizes:
        d = os.path.join(root, f"rerun-{n}")
        t = time.perf_counter()
        src, out = done_collection(d, n)
        made = time.perf_counter() - t
        res = subprocess.run([sys.executable, __file__, "--rerun-child", src, out], capture_output=True, text=True,
                             check=True)
        r = json.loads(res.stdout.strip().splitlines()[-1])
        assert r["n"] == r["skipped"] == n and not r["cluster"], r
        rows.append(r)
        print(f"rerun, all done: {n:>9,} inputs  wall {r['seconds']:7.2f} s = {r['seconds'] / n * 1e6:6.1f} µs/input"
              f"  cpu {r['cpu'] / n * 1e6:6.1f} µs/input  peak +{r['peak_kb'] / 1024:6.1f} MiB = "
              f"{r['peak_kb'] * 1024 / n:7.1f} B/input   (made in {made:.0f} s; load {os.getloadavg()[0]:.1f}, "
              f"empty loop {speed_reference():.3f} s)", flush=True)
        shutil.rmtree(d)
    big = rows[-1]
    slope = ""
    if len(rows) > 1:
        a = rows[0]
        per_kb = (big["peak_kb"] - a["peak_kb"]) / (big["n"] - a["n"])
        slope = f"; memory by its growth from {a['n']:,}: {(a['peak_kb'] + per_kb * (1e6 - a['n'])) / 1024:.0f} MiB"
    print(f"10⁶ inputs, extrapolated from {big['n']:,} (per-input figures times 10⁶): wall "
          f"{big['seconds'] / big['n'] * 1e6:.0f} s, cpu {big['cpu'] / big['n'] * 1e6:.0f} s, "
          f"{big['peak_kb'] / 1024 / big['n'] * 1e6:.0f} MiB{slope}")
    return rows


def tetrahedra(root: str, n: int) -> str:
    d = os.path.join(root, "tiny")
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    F = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    for k in range(n):
        hybridsub.write_mesh(os.path.join(d, f"{k // 1000:03d}", f"t{k:06d}.obj"), V + 0.01 * k, F)
    return d


def overhead(root: str, n: int, workers: list[int]) -> list[dict]:
    folder = tetrahedra(root, n)
    files = sorted(os.path.join(r, f) for r, _, fs in os.walk(folder) for f in fs)
    a = FileOptions(levels=1, scheme="hybrid", loop_weights="loop", quiet=True)
    base = os.path.join(root, "loop")
    os.makedirs(base)
    subdivide_file(a, files[0], os.path.join(base, "warm.obj"))
    t = time.perf_counter()
    for k, f in enumerate(files):
        subdivide_file(a, f, os.path.join(base, f"{k}.obj"))
    loop = time.perf_counter() - t
    print(f"tetrahedra, 1 level: in-process loop {loop / n * 1e3:.2f} ms/mesh", flush=True)
    rows = []
    for w in workers:
        cluster, client = local_cluster(w)
        with cluster, client:
            hybridsub.batch(files[:2 * w], os.path.join(root, f"warm{w}"), scheduler=client, levels=1)
            recs = []
            s = hybridsub.batch(folder, os.path.join(root, f"out{w}"), scheduler=client, levels=1,
                                on_result=recs.append)
            t = time.perf_counter()
            client.gather(client.map(_identity, range(n), pure=False))  # Dask's own round trip, nothing else
            plain = time.perf_counter() - t
        assert s.done == n, s.table()
        per_task = (s.seconds * w - loop) / n
        in_task = (sum(r["seconds"]["total"] for r in recs) - loop) / n
        rows.append(dict(workers=w, n=n, seconds=s.seconds, rate=n / s.seconds, overhead_ms=per_task * 1e3,
                         loop_ms=loop / n * 1e3, in_task_ms=in_task * 1e3, plain_ms=plain * w / n * 1e3))
        print(f"tetrahedra, 1 level: {w} worker{'s' if w > 1 else ''}  {n} meshes in {s.seconds:.2f} s  "
              f"{n / s.seconds:6.1f} meshes/s  per-task overhead {per_task * 1e3:.2f} ms, of which in the task "
              f"(checksums, marker, rename) {in_task * 1e3:.2f} ms; a bare Dask task: {plain * w / n * 1e3:.2f} ms  "
              f"(load {os.getloadavg()[0]:.1f}, empty loop {speed_reference():.3f} s)", flush=True)
    return rows


def _identity(x):
    return x


def main(argv=None) -> int:
    if argv is None and len(sys.argv) == 4 and sys.argv[1] == "--rerun-child":
        rerun_child(sys.argv[2], sys.argv[3])
        return 0
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rerun", type=int, nargs="+", metavar="N", help="the rerun's cost for N inputs, all done")
    ap.add_argument("--overhead", type=int, metavar="N", help="per-task overhead on N tetrahedra")
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
    if a.rerun or a.overhead:
        print(f"# hybridsub batch, {time.strftime('%Y-%m-%d')}, {cpu_name()}, {len(os.sched_getaffinity(0))} cores, "
              f"load {os.getloadavg()[0]:.1f}, Python {sys.version.split()[0]}, hybridsub {hybridsub.__version__}")
        try:
            if a.rerun:
                rerun_scaling(root, a.rerun)
            if a.overhead:
                overhead(root, a.overhead, a.workers)
        finally:
            shutil.rmtree(root, ignore_errors=True)
        return 0
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
