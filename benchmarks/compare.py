#!/usr/bin/env python
"""Side-by-side timings of hybridsub and every installed peer, as one Markdown report.

usage: python benchmarks/compare.py [--quick] [--repeat N] [--budget S] [--rounds R] [--markdown OUT.md]
                                    [--json OUT.json] [--no-build]

What it measures (all in this one run, on this machine; see docs/performance.md):
* per core, then with all cores (benchmarks/per_core.py, interleaved rounds): one animation
  frame through the composite against OpenSubdiv's ``StencilTable::UpdateValues``, forming
  the composite against ``StencilTableFactory::Create``, Loop and √3 against OpenSubdiv and
  CGAL;
* the rows of issue 3's target table: hybridsub against CGAL (√3, Loop), OpenSubdiv (Loop,
  Loop with creases), libigl, trimesh, VTK (pyvista), PyMeshLab, Open3D and gpytoolbox, on
  armadillo (52k faces) and fandisk (30° creases), 3 levels (2 with --quick);
* applying a precomputed composite matrix (one frame, and 100 frames at once) against SciPy's
  ``S @ V`` and against re-running ``subdivide``; the copy floor (``V2.copy(); F2.copy()``);
* the first call in a fresh process with a warm and with an empty Numba cache;
* the peak memory of ``subdivide`` against the size of its output arrays;
* the vertex path (refinement, limit positions and normals) against Adobe Lagrange
  (benchmarks/lagrange_peer.py).

Every timing is the median (and min) of several warm runs: one untimed warm-up call, then
each run prepares its input outside the timed region, times the call alone with the garbage
collector off, and deletes the result before the next run (at most one result is alive).
Peers are timed on their own mesh objects (conversion from NumPy not timed). A peer that
cannot be imported, or a C++ harness that cannot be built, is listed as skipped.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import importlib
import importlib.metadata as _md
import json
import os
import platform
import shlex
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from _bench import FIRST_CALL, HERE, ROOT, Timing, child_env, cpu_name, fresh_process, load, measure, tags  # noqa: E402
import lagrange_peer  # noqa: E402
import per_core  # noqa: E402

import hybridsub  # noqa: E402  (_bench put this checkout's package first)
from hybridsub._io import read_off  # noqa: E402

PEERS = os.path.join(HERE, "peers")


def pair_counts(out) -> tuple:
    V, F = out[0], out[1]
    return (len(V), len(F))


# --------------------------------------------------------------------------- Python peers


@dataclass
class PyPeer:
    """A Python library with a Loop subdivision; ``weights`` is the vertex rule it uses."""

    key: str
    label: str
    dist: str  # distribution whose version the report gives
    weights: str  # "loop" (Loop's beta) or "warren" (Warren's beta); Run.time_py_peers checks it
    prepare: Callable  # (V, F) -> native input
    run: Callable  # (native input, levels) -> native output
    arrays: Callable  # native output -> (V, F) NumPy arrays
    note: str = ""


def _pyvista():
    import pyvista as pv

    return PyPeer(
        "pyvista", "VTK vtkLoopSubdivisionFilter (pyvista)", "vtk", "loop",
        lambda V, F: pv.PolyData.from_regular_faces(V, F),
        lambda m, L: m.subdivide(L, "loop"),
        lambda o: (np.asarray(o.points, np.float64), np.asarray(o.regular_faces)),
        "writes float32 points")


def _pymeshlab():
    import pymeshlab

    def prepare(V, F):
        ms = pymeshlab.MeshSet()
        ms.add_mesh(pymeshlab.Mesh(V, F))
        return ms

    def run(ms, L):  # threshold 0: every edge is split (the default splits only long edges)
        ms.meshing_surface_subdivision_loop(loopweight="Loop", iterations=L, threshold=pymeshlab.PercentageValue(0))
        return ms

    return PyPeer("pymeshlab", "PyMeshLab meshing_surface_subdivision_loop", "pymeshlab", "loop", prepare, run,
                  lambda ms: (ms.current_mesh().vertex_matrix(), ms.current_mesh().face_matrix()),
                  "edits its MeshSet in place; threshold=0%")


def _open3d():
    import open3d as o3d

    return PyPeer(
        "open3d", "Open3D TriangleMesh.subdivide_loop", "open3d", "warren",
        lambda V, F: o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(V), o3d.utility.Vector3iVector(F)),
        lambda m, L: m.subdivide_loop(number_of_iterations=L),
        lambda o: (np.asarray(o.vertices), np.asarray(o.triangles)))


def _igl():
    import igl

    return PyPeer("igl", "libigl igl.loop", "libigl", "warren", lambda V, F: (V, F),
                  lambda a, L: igl.loop(a[0], a[1], L), lambda o: o)


def _trimesh():
    from trimesh.remesh import subdivide_loop

    return PyPeer("trimesh", "trimesh.remesh.subdivide_loop", "trimesh", "loop", lambda V, F: (V, F),
                  lambda a, L: subdivide_loop(a[0], a[1], iterations=L), lambda o: o)


def _gpytoolbox():
    import gpytoolbox

    return PyPeer("gpytoolbox", "gpytoolbox.subdivide(method='loop')", "gpytoolbox", "warren", lambda V, F: (V, F),
                  lambda a, L: gpytoolbox.subdivide(a[0], a[1], method="loop", iters=L), lambda o: o)


PY_PEERS = [_igl, _trimesh, _pyvista, _pymeshlab, _open3d, _gpytoolbox]


def load_py_peers(skipped: dict) -> list:
    peers = []
    for make in PY_PEERS:
        name = make.__name__.lstrip("_")
        try:
            peers.append(make())
        except Exception as e:  # ImportError, or a broken binary wheel (missing shared library)
            skipped[name] = f"cannot import: {type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}"
    return peers


def version(dist: str) -> str:
    try:
        return _md.version(dist)
    except _md.PackageNotFoundError:
        mod = importlib.import_module(dist)
        return getattr(mod, "__version__", "?")


# --------------------------------------------------------------------------- C++ peers


def build_cxx(skipped: dict, rebuild: bool) -> dict:
    """Run peers/build.sh; returns {harness name: binary path} for the ones that exist."""
    if rebuild:
        r = subprocess.run(["bash", os.path.join(PEERS, "build.sh")], capture_output=True, text=True)
        for line in r.stdout.splitlines():
            word, _, rest = line.partition(" ")
            if word in ("skip", "FAIL"):
                name = rest.strip().split(":")[0].split(" ")[0]
                skipped[name] = line.strip() + (" (see build.sh output)" if word == "FAIL" else "")
        if r.returncode and r.stderr:
            print(r.stderr[-2000:], file=sys.stderr)
    found = {}
    for name in ("cgal_subdiv", "osd_loop", "osd_stencils"):
        exe = os.path.join(PEERS, "bin", name)
        if name in skipped:  # the build skipped or failed it: an old binary is not used
            continue
        if os.access(exe, os.X_OK):
            found[name] = exe
        else:
            skipped.setdefault(name, "not built (run benchmarks/peers/build.sh)")
    return found


def run_cxx(argv: list) -> dict:
    r = subprocess.run(argv, capture_output=True, text=True, timeout=3600)
    if r.returncode:
        raise RuntimeError(f"{shlex.join(argv)} failed: {r.stderr.strip()[-500:]}")
    return json.loads(r.stdout)


def cxx_timing(res: dict, key: str = "subdivide") -> Timing:
    t = Timing(res[key]["times"], (res["n_vertices"], res["n_faces"]))
    t.extra = {k: res[k]["median"] for k in ("create", "refine", "interpolate") if k in res}
    t.extra["peak_rss_delta"] = res.get("peak_rss_delta")
    return t


# --------------------------------------------------------------------------- verification


def _mesh_difference():
    """tests/meshcompare.py's order-independent comparison (vertices to 1e-12 × diagonal)."""
    sys.path.insert(0, os.path.join(ROOT, "tests"))
    try:
        from meshcompare import mesh_difference
    finally:
        sys.path.pop(0)
    return mesh_difference


def distances(V, Vref) -> np.ndarray:
    """Distance from each vertex of V to the nearest vertex of Vref, / Vref's bbox diagonal."""
    from scipy.spatial import cKDTree

    diag = float(np.linalg.norm(Vref.max(0) - Vref.min(0))) or 1.0
    return cKDTree(Vref).query(V)[0] / diag


def agreement(V, F, Vref, Fref) -> str:
    """'identical' (1e-12, same triangles), or how far apart the two meshes are."""
    if (len(V), len(F)) != (len(Vref), len(Fref)):
        return f"counts differ: {len(V)}/{len(F)} vs ours {len(Vref)}/{len(Fref)}"
    diff = _mesh_difference()(V, F, Vref, Fref, tol=1e-12)
    if diff is None:
        return "identical (1e-12)"
    d = distances(V, Vref)
    return (f"differs: {int((d > 1e-12).sum()):,} of {len(d):,} vertices off by > 1e-12 "
            f"(max {d.max():.1e} × diagonal)" if d.max() > 1e-12 else f"differs: {diff}")


# --------------------------------------------------------------------------- fresh processes

FIRST_CALL_LABELS = {
    "hybrid": "first call: import + load_example + detect_features + hybrid L1 (README)",
    "every-scheme": "every scheme: import + hybrid, sqrt3, loop (creases) L1",
}


def first_calls(repeat: int, cold_runs: int) -> list:
    """Wall time of `python -c CODE` (interpreter start included) with a warm and an empty cache."""
    tmp = tempfile.gettempdir()
    rows = [("python -c pass (interpreter start)", Timing([fresh_process("pass", tmp) for _ in range(repeat)]), None)]
    with tempfile.TemporaryDirectory(prefix="hybridsub-numba-") as cache:
        imports = Timing([fresh_process("import hybridsub", cache) for _ in range(repeat)])
    rows.append(("import hybridsub", imports, None))
    for key, code in FIRST_CALL.items():
        with tempfile.TemporaryDirectory(prefix="hybridsub-numba-warm-") as warm_dir:
            fresh_process(code, warm_dir)  # fills the cache
            warm = Timing([fresh_process(code, warm_dir) for _ in range(repeat)])
        times = []
        for _ in range(cold_runs):
            with tempfile.TemporaryDirectory(prefix="hybridsub-numba-cold-") as cold_dir:
                times.append(fresh_process(code, cold_dir))
        rows.append((FIRST_CALL_LABELS[key], warm, Timing(times)))
    return rows


MEMORY_CHILD = r"""
import json, resource, sys, tracemalloc
from _bench import load, tags
import hybridsub
name, variant, levels = sys.argv[1], sys.argv[2], int(sys.argv[3])

def status(key):  # bytes
    for line in open("/proc/self/status"):
        if line.startswith(key + ":"):
            return int(line.split()[1]) * 1024

tiny = load("icosahedron")
edges, kw = tags(tiny, variant)
hybridsub.subdivide(tiny.V, tiny.F, edges, levels=levels, **kw)  # loads the kernels: their memory is not the call's
m = load(name)
edges, kw = tags(m, variant)
try:
    with open("/proc/self/clear_refs", "w") as fh:
        fh.write("5")  # resets VmHWM to the current RSS
    method = "VmHWM after a reset (/proc/self/clear_refs) minus VmRSS before the call"
except OSError:
    method = "ru_maxrss after minus VmRSS before the call (peak not reset: an upper bound)"
rss0 = status("VmRSS")
V2, F2 = hybridsub.subdivide(m.V, m.F, edges, levels=levels, **kw)
high = status("VmHWM") if method.startswith("VmHWM") else resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
peak = high - rss0
out = V2.nbytes + F2.nbytes
del V2, F2
tracemalloc.start()
V2, F2 = hybridsub.subdivide(m.V, m.F, edges, levels=levels, **kw)
traced = tracemalloc.get_traced_memory()[1]
tracemalloc.stop()
print(json.dumps(dict(peak_rss=peak, traced=traced, output=out, method=method)))
"""


def peak_memory(mesh: str, variant: str, levels: int) -> dict:
    """Peak RSS growth of one subdivide call in a fresh process (see MEMORY_CHILD)."""
    r = subprocess.run([sys.executable, "-c", MEMORY_CHILD, mesh, variant, str(levels)], env=child_env(),
                       capture_output=True, text=True)
    if r.returncode:
        raise RuntimeError(f"memory child failed: {r.stderr[-1000:]}")
    return json.loads(r.stdout.strip().splitlines()[-1])


# --------------------------------------------------------------------------- report helpers


def fmt_t(t: float | None) -> str:
    if t is None:
        return "—"
    if t >= 1:
        return f"{t:.2f} s"
    if t >= 1e-3:
        return f"{t * 1e3:.1f} ms"
    return f"{t * 1e6:.0f} µs"


def fmt_mb(b: float) -> str:
    return f"{b / 2**20:.1f} MB"


def machine_lines(args, versions: dict, load_at_start) -> list:
    mem = "?"
    try:
        with open("/proc/meminfo") as fh:
            mem = f"{int(fh.readline().split()[1]) / 2**20:.0f} GiB"
    except OSError:
        pass
    try:
        rev = subprocess.run(["git", "-C", ROOT, "describe", "--always", "--dirty"], capture_output=True,
                             text=True).stdout.strip() or "?"
    except OSError:
        rev = "?"
    threads = {k: os.environ[k] for k in ("OMP_NUM_THREADS", "NUMBA_NUM_THREADS", "OPENBLAS_NUM_THREADS")
               if k in os.environ}
    return [
        f"- date: {_dt.datetime.now(_dt.timezone.utc).strftime('%Y-%m-%d %H:%M UTC')}",
        f"- machine: {cpu_name()}, {os.cpu_count()} logical CPUs, {mem} RAM, {platform.system()} {platform.release()}",
        f"- load average (1, 5, 15 min) at start: {' '.join(f'{x:.2f}' for x in load_at_start)}; "
        f"at end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}",
        f"- Python {platform.python_version()}, NumPy {np.__version__}, SciPy {version('scipy')}, "
        f"Numba {version('numba')}",
        f"- hybridsub {hybridsub.__version__} from `{os.path.dirname(hybridsub.__file__)}` (git {rev})",
        "- peers: " + (", ".join(f"{k} {v}" for k, v in versions.items()) or "none"),
        f"- threads: {threads or 'library defaults'}; command: `{shlex.join(['python'] + sys.argv)}`",
        f"- method: median (min) of up to {args.repeat} warm runs after one warm-up; at most one result alive; "
        f"peers timed on their own mesh objects; budget {args.budget:.0f} s per contender",
    ]


def table(header: list, rows: list) -> list:
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return out


# --------------------------------------------------------------------------- the run


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


class Run:
    """One benchmark run: the meshes, every timing (``T``), the output checks and what was skipped."""

    def __init__(self, args):
        self.args = args
        self.L = 2 if args.quick else 3
        self.R, self.B = args.repeat, args.budget
        self.load_at_start = os.getloadavg()
        self.skipped: dict = {}
        self.T: dict = {}  # contender key -> Timing
        self.verify: list = []  # (contender key, what was compared, result)
        self.arm, self.fan, self.border = load("armadillo"), load("fandisk"), load("mesh_with_border")
        self.py_peers = load_py_peers(self.skipped)
        self.cxx = build_cxx(self.skipped, rebuild=not args.no_build)
        self.versions = {p.dist: version(p.dist) for p in self.py_peers}
        if any(p.key == "pyvista" for p in self.py_peers):
            self.versions["pyvista"] = version("pyvista")

    def ours(self, mesh, variant, weights="loop", levels=None):
        """hybridsub.subdivide of (V, F), a variant of _bench.VARIANTS (30° creases where tagged)."""
        edges, kw = tags(mesh, variant)
        kw.update(levels=levels or self.L, loop_weights=weights)
        return lambda inp: hybridsub.subdivide(inp[0], inp[1], edges, **kw)

    def contenders(self) -> dict:
        arm, fan, ours = self.arm, self.fan, self.ours
        return {
            "ours sqrt3 arm": (arm, ours(arm, "sqrt3")),
            "ours loop arm": (arm, ours(arm, "loop")),
            "ours loop-warren arm": (arm, ours(arm, "loop", weights="warren")),
            "ours hybrid fan": (fan, ours(fan, "hybrid")),
            "ours sqrt3 fan": (fan, ours(fan, "sqrt3")),
            "ours loop-creases fan": (fan, ours(fan, "loop+creases")),
        }

    def time_ours(self):
        for key, (mesh, fn) in self.contenders().items():
            log(f"timing {key} (L{self.L}) ...")
            self.T[key] = measure(lambda m=mesh: (m.V, m.F), fn, repeat=self.R, budget=self.B, counts=pair_counts)

    def _cxx_peer(self, key, argv, check_argv, check_mesh, ours_fn, what):
        """Time a C++ harness (its own process, same method), then check its output at a low level."""
        log(f"timing {key} ...")
        try:
            self.T[key] = cxx_timing(run_cxx(argv + ["--repeat", str(self.R), "--warmup", "1"]))
            with tempfile.TemporaryDirectory() as tmp:
                out = os.path.join(tmp, "out.off")
                run_cxx(check_argv + ["--repeat", "1", "--warmup", "0", "--out", out])
                V2, F2 = read_off(out)
            ref = ours_fn((check_mesh.V, check_mesh.F))
            self.verify.append((key, what, agreement(V2, F2, ref[0], ref[1])))
        except Exception as e:  # a harness failing is reported, the rest of the run goes on
            self.skipped[key] = f"failed: {e}"

    def time_cxx(self):
        arm, fan, L = self.arm, self.fan, str(self.L)
        if "cgal_subdiv" in self.cxx:
            exe = self.cxx["cgal_subdiv"]
            for scheme in ("sqrt3", "loop"):
                self._cxx_peer(f"cgal {scheme} arm", [exe, arm.path, scheme, L], [exe, arm.path, scheme, "1"], arm,
                               self.ours(arm, scheme, levels=1), f"armadillo L1 vs ours {scheme}")
        if "osd_loop" in self.cxx:
            exe = self.cxx["osd_loop"]
            self._cxx_peer("osd loop arm", [exe, arm.path, L], [exe, arm.path, "1"], arm,
                           self.ours(arm, "loop", levels=1), "armadillo L1 vs ours loop")
            with tempfile.TemporaryDirectory() as tmp:
                creases = os.path.join(tmp, "fandisk-creases.txt")
                np.savetxt(creases, fan.creases, fmt="%d")
                self._cxx_peer("osd loop-creases fan", [exe, fan.path, L, "--creases", creases],
                               [exe, fan.path, "2", "--creases", creases], fan,
                               self.ours(fan, "loop+creases", levels=2),
                               f"fandisk L2, {len(fan.creases)} creases vs ours loop + creases")

    def time_py_peers(self):
        """Same measure() as ours, on each peer's own mesh object; outputs checked on fandisk and a boundary."""
        arm = self.arm
        for p in self.py_peers:
            key = f"{p.key} loop arm"
            log(f"timing {key} ...")
            try:
                self.T[key] = measure(lambda p=p: p.prepare(arm.V, arm.F), lambda m, p=p: p.run(m, self.L),
                                      repeat=self.R, budget=self.B, counts=lambda o, p=p: pair_counts(p.arrays(o)))
                for mesh, what in ((self.fan, "fandisk L1"), (self.border, "mesh_with_border L1 (boundary)")):
                    V2, F2 = p.arrays(p.run(p.prepare(mesh.V, mesh.F), 1))
                    ref = hybridsub.subdivide(mesh.V, mesh.F, levels=1, scheme="loop", loop_weights=p.weights)
                    self.verify.append((key, f"{what} vs ours loop_weights={p.weights!r}",
                                        agreement(np.asarray(V2, np.float64), np.asarray(F2, np.int64), *ref)))
            except Exception as e:
                self.skipped[p.key] = f"failed: {type(e).__name__}: {e}"

    def time_apply(self) -> list:
        """r.apply(X) with the composite matrix formed, against S @ X and re-running subdivide."""
        rows = []
        for label, mesh, variant, rerun in (("armadillo loop", self.arm, "loop", "ours loop arm"),
                                            ("fandisk hybrid", self.fan, "hybrid", "ours hybrid fan")):
            log(f"timing composite matrix, {label} ...")
            edges, kw = tags(mesh, variant)
            t0 = time.perf_counter()
            r = hybridsub.refine(mesh.F, edges, self.L, **kw)
            S = r.matrix
            pre = time.perf_counter() - t0
            for frames in (1, 100) if label.startswith("fandisk") else (1,):
                # frames as one (n, 3 × frames) array; re-running subdivide = frames × its median
                def data(frames=frames, V=mesh.V):
                    return V if frames == 1 else np.hstack([V + 1e-3 * k for k in range(frames)])

                ours = measure(data, r.apply, repeat=self.R, budget=self.B)
                floor = measure(data, lambda X, S=S: S @ X, repeat=self.R, budget=self.B)
                rows.append((label, frames, S.shape, S.nnz, pre, ours, floor, self.T[rerun].median * frames))
            del r, S
        return rows

    def time_copy_floor(self) -> list:
        """V2.copy(); F2.copy() of each output, against the subdivide that made it."""
        rows = []
        for key, (mesh, fn) in self.contenders().items():
            if key in ("ours loop-warren arm", "ours loop-creases fan"):  # same sizes as a row kept
                continue
            out = fn((mesh.V, mesh.F))
            cp = measure(lambda out=out: out, lambda o: (o[0].copy(), o[1].copy()), repeat=self.R, budget=self.B)
            rows.append((key, out[0].nbytes + out[1].nbytes, cp, self.T[key]))
            del out
        return rows

    def memory(self) -> list:
        log("measuring peak memory in fresh processes ...")
        rows = []
        for mesh, variant in (("armadillo", "sqrt3"), ("armadillo", "loop"), ("fandisk", "hybrid")):
            label = f"{mesh} {variant}"
            try:
                rows.append((label, peak_memory(mesh, variant, self.L)))
            except Exception as e:
                self.skipped[f"memory {label}"] = str(e)
        return rows

    # ------------------------------------------------------------------ report

    def check_note(self, key: str) -> str:
        """What the output checks of this contender found different from ours."""
        return "; ".join(f"{what.split(' vs ')[0]}: {res}" for k, what, res in self.verify
                         if k == key and not res.startswith("identical"))

    def ratio_row(self, work, ours_key, peer_label, peer_key, target, note=""):
        o, p = self.T.get(ours_key), self.T.get(peer_key)
        note = "; ".join(filter(None, [note, self.check_note(peer_key)]))
        tgt = f"≤ {target}" if target else "—"
        if o is None or p is None:
            ours = [fmt_t(o.median), fmt_t(o.min)] if o else ["—", "—"]
            return [work, *ours, peer_label, "skipped", "—", "—", tgt, "skipped", note]
        ratio = o.median / p.median
        ok = "—" if target is None else ("pass" if ratio <= target else "**fail**")
        runs = f" ({p.runs} run{'s' if p.runs > 1 else ''})" if p.runs < self.R else ""
        if o.counts and p.counts and o.counts != p.counts:
            note = "; ".join(filter(None, [note, f"outputs differ: ours {o.counts[1]:,} faces, peer {p.counts[1]:,}"]))
        return [work, fmt_t(o.median), fmt_t(o.min), peer_label, fmt_t(p.median) + runs, fmt_t(p.min), f"{ratio:.3f}",
                tgt, ok, note]

    def subdivision_rows(self) -> list:
        L = self.L
        arm_w = f"armadillo 52k faces × L{L}"
        fan_w = f"fandisk 13k faces, 30° creases × L{L}"
        row = self.ratio_row
        rows = [
            row(f"sqrt3, {arm_w}", "ours sqrt3 arm", "CGAL Sqrt3_subdivision", "cgal sqrt3 arm", 0.25),
            row(f"loop, {arm_w}", "ours loop arm", "OpenSubdiv Far Loop (refine + interpolate)", "osd loop arm", 0.33),
            row(f"loop (Warren weights), {arm_w}", "ours loop-warren arm", "libigl igl.loop", "igl loop arm", 0.1,
                "igl uses Warren's weights: ours with loop_weights='warren'"),
            row(f"loop, {arm_w}", "ours loop arm", "CGAL Loop_subdivision", "cgal loop arm", None),
        ]
        for p in self.py_peers:
            if p.key != "igl":
                warren = p.weights == "warren"
                rows.append(row(f"loop{' (Warren weights)' if warren else ''}, {arm_w}",
                                "ours loop-warren arm" if warren else "ours loop arm", p.label, f"{p.key} loop arm",
                                None, p.note))
        rows += [
            row(f"hybrid, {fan_w}", "ours hybrid fan", "OpenSubdiv Far Loop, same creases", "osd loop-creases fan",
                0.33, "different schemes (hybrid splits smooth faces 1→3)"),
            row(f"hybrid, {fan_w}", "ours hybrid fan", "ours sqrt3, same mesh", "ours sqrt3 fan", 1.5),
            row(f"loop + creases, {fan_w}", "ours loop-creases fan", "OpenSubdiv Far Loop, same creases",
                "osd loop-creases fan", None, "the same output"),
        ]
        return rows

    def per_core(self) -> list:
        """Issue 18's tables (benchmarks/per_core.py): per core first, then all cores."""
        needed = ("osd_stencils", "osd_loop", "cgal_subdiv")
        if any(not os.access(os.path.join(PEERS, "bin", n), os.X_OK) for n in needed):
            self.skipped["per core"] = "needs osd_stencils, osd_loop and cgal_subdiv built"
            return []
        try:
            check = per_core.check_stencils()
            T = per_core.collect(self.args.rounds, 2 if self.args.quick else 3, self.L, log)
        except Exception as e:
            self.skipped["per core"] = f"failed: {e}"
            return []
        return ["## Per core, then all cores (issue 18)", ""] + per_core.report(T, check, self.L) + [""]

    def report(self, apply_rows, floor_rows, starts, mem_rows, core_rows=(), lagrange_rows=()) -> str:
        L, T = self.L, self.T
        md = [f"# hybridsub performance — `benchmarks/compare.py`{' --quick' if self.args.quick else ''}", ""]
        md += machine_lines(self.args, self.versions, self.load_at_start) + [""]
        md += list(core_rows)

        md += ["## Subdivision: ours against the peers", ""]
        md += table(["work", "ours median", "ours min", "peer", "peer median", "peer min", "ours / peer", "target", "",
                     "notes"], self.subdivision_rows())
        osd = [(k, T[k]) for k in ("osd loop arm", "osd loop-creases fan") if k in T]
        if osd:
            md += ["", "OpenSubdiv's parts (medians): " + "; ".join(
                f"{k}: create {fmt_t(t.extra['create'])}, refine {fmt_t(t.extra['refine'])}, "
                f"interpolate {fmt_t(t.extra['interpolate'])}" for k, t in osd)]

        if lagrange_rows:
            md += [""] + list(lagrange_rows)

        md += ["", "## Applying the precomputed composite matrix (animation frames)", ""]
        rows = []
        for label, frames, shape, nnz, pre, o, floor, rerun in apply_rows:
            rows.append([f"{label} L{L}, {frames} frame{'s' if frames > 1 else ''}",
                         f"{shape[0]:,}×{shape[1]:,}, nnz {nnz:,}", fmt_t(pre), fmt_t(o.median), fmt_t(floor.median),
                         f"{o.median / floor.median:.2f}",
                         fmt_t(rerun) + (f" ({frames} × median)" if frames > 1 else ""),
                         f"{o.median / rerun:.4f}", "≤ 0.1", "pass" if o.median / rerun <= 0.1 else "**fail**"])
        md += table(["work", "S", "refine + matrix (once)", "r.apply(X)", "S @ X (SciPy floor)", "apply / floor",
                     "re-running subdivide", "apply / re-run", "target", ""], rows)

        md += ["", "## The copy floor: `V2.copy(); F2.copy()` of the output", ""]
        rows = [[k.replace("ours ", "").replace(" arm", ", armadillo").replace(" fan", ", fandisk") + f" L{L}",
                 fmt_mb(nb), fmt_t(cp.median), fmt_t(o.median), f"{o.median / cp.median:.1f}", "≤ 10",
                 "pass" if o.median / cp.median <= 10 else "**fail**"] for k, nb, cp, o in floor_rows]
        md += table(["output", "V2 + F2", "copy", "subdivide", "subdivide / copy", "target", ""], rows)

        md += ["", "## First call in a fresh process (`python -c CODE`, wall time, interpreter start included)", ""]
        rows = []
        for label, warm, cold in starts:
            first = label.startswith("first call")
            rows.append([label, fmt_t(warm.median), fmt_t(warm.min), fmt_t(cold.median) if cold else "—",
                         "≤ 2 s" if first else "—", ("pass" if warm.median <= 2 else "**fail**") if first else ""])
        md += table(["code", "warm cache median", "warm min", "empty cache (compile)", "target (warm)", ""], rows)
        md += ["", "Warm: `NUMBA_CACHE_DIR` is a temporary directory filled by one earlier run of the same code; "
                   "empty: a fresh temporary directory, so every kernel used is compiled."]

        md += ["", f"## Peak memory of `subdivide` (L{L}, fresh process)", ""]
        rows = [[label, fmt_mb(m["output"]), fmt_mb(m["peak_rss"]), f"{m['peak_rss'] / m['output']:.2f}",
                 fmt_mb(m["traced"]), "≤ 3", "pass" if m["peak_rss"] / m["output"] <= 3 else "**fail**"]
                for label, m in mem_rows]
        md += table(["work", "output arrays", "peak RSS growth", "peak / output", "tracemalloc peak", "target", ""],
                    rows)
        if mem_rows:
            md += ["", f"Method: {mem_rows[0][1]['method']}, around one call after the kernels were loaded on a tiny "
                       "mesh. tracemalloc sees NumPy's allocations only (not Numba's NRT), so it is a lower bound."]
        cxx_mem = [(k, t.extra["peak_rss_delta"]) for k, t in T.items() if (t.extra.get("peak_rss_delta") or -1) > 0]
        if cxx_mem:
            md += ["C++ peers, peak RSS growth of their warm-up call (same method): "
                   + "; ".join(f"{k}: {fmt_mb(v)}" for k, v in cxx_mem)]

        md += ["", "## Checks of the peers' outputs", ""]
        md += table(["peer", "check", "result"], [list(v) for v in self.verify]) if self.verify else ["(none ran)"]
        md += ["", "## Skipped", ""]
        md += [f"- {k}: {v}" for k, v in self.skipped.items()] or ["(nothing)"]
        return "\n".join(md) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="2 levels instead of 3, 3 runs, 10 s budget: a smoke run")
    ap.add_argument("--repeat", type=int, default=None, help="timed runs per contender (default 7, --quick 3)")
    ap.add_argument("--budget", type=float, default=None,
                    help="seconds per contender; a slower one gets fewer runs (default 60, --quick 10)")
    ap.add_argument("--markdown", metavar="OUT.md", help="also write the report here")
    ap.add_argument("--json", metavar="OUT.json", help="write every raw timing here")
    ap.add_argument("--no-build", action="store_true", help="do not run peers/build.sh (use what is in peers/bin)")
    ap.add_argument("--rounds", type=int, default=None, help="interleaved rounds of the per-core tables (default 3, "
                    "--quick 1)")
    args = ap.parse_args(argv)
    args.repeat = args.repeat or (3 if args.quick else 7)
    args.budget = args.budget or (10.0 if args.quick else 60.0)
    args.rounds = args.rounds or (1 if args.quick else 3)

    run = Run(args)
    core_rows = run.per_core()  # first: the tables issue 18 reads, on the quietest part of the run
    run.time_ours()
    run.time_cxx()
    run.time_py_peers()
    apply_rows = run.time_apply()
    floor_rows = run.time_copy_floor()
    log("timing first calls in fresh processes ...")
    starts = first_calls(repeat=max(3, min(args.repeat, 5)), cold_runs=1 if args.quick else 2)
    mem_rows = run.memory()
    log("timing the vertex path against Adobe Lagrange ...")
    lag_rows, why = lagrange_peer.run_section(run.L, args.repeat, args.budget)
    if why:
        run.skipped["lagrange"] = why

    text = run.report(apply_rows, floor_rows, starts, mem_rows, core_rows, lag_rows)
    print(text)
    if args.markdown:
        with open(args.markdown, "w") as fh:
            fh.write(text)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"levels": run.L, "repeat": args.repeat, "skipped": run.skipped, "checks": run.verify,
                       "timings": {k: dict(times=t.times, counts=t.counts, extra=t.extra) for k, t in run.T.items()},
                       "first_call": {label: dict(warm=w.times, cold=c.times if c else None) for label, w, c in starts},
                       "memory": dict(mem_rows)}, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
