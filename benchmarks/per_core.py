#!/usr/bin/env python
"""Issue 18's ratios, per core and with all cores: hybridsub against OpenSubdiv's stencil
tables (the animation frame, forming the table) and against the single-threaded C++ peers.

usage: python benchmarks/per_core.py [--rounds R] [--repeat N] [--levels L] [--markdown OUT.md] [--json OUT.json]

Each round runs, one after the other: hybridsub in a fresh process with NUMBA_NUM_THREADS=1,
then OpenSubdiv's harness with one OpenMP thread, then both with every core, then the
single-threaded peers (CGAL's √3, OpenSubdiv's Far Loop); the rounds interleave the
contenders so that a change in the machine's load reaches all of them. Every contender warms
up once per process, then times N runs; the report gives the median and minimum over all
rounds. Single-threaded sections are also timed in process CPU time, which leaves out the
time other processes held the core (the wall time on a shared machine does not). Before
timing, OpenSubdiv's float stencils are checked against ``r.apply`` to 1e-6 × the bounding
box diagonal at 2 levels. Run by compare.py too (its "Per core" section).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

from _bench import HERE, ROOT, child_env, load  # noqa: E402

PEERS_BIN = os.path.join(HERE, "peers", "bin")

# Timed in a child process, so that NUMBA_NUM_THREADS takes effect before Numba starts.
CHILD = r"""
import gc, json, sys, time
import numpy as np
from _bench import load
import hybridsub
levels, repeat = int(sys.argv[1]), int(sys.argv[2])
m = load("armadillo")
V = np.ascontiguousarray(m.V)

def timed(prepare, run):
    inp = prepare(); run(inp); run(inp)  # warm-up: kernels loaded, codes built (apply codes on its 2nd call)
    wall, cpu = [], []
    for _ in range(repeat):
        inp = prepare(); gc.collect(); gc.disable()
        t0, c0 = time.perf_counter(), time.process_time()
        out = run(inp)
        t1, c1 = time.perf_counter(), time.process_time()
        gc.enable(); del out
        wall.append(t1 - t0); cpu.append(c1 - c0)
    return dict(wall=wall, cpu=cpu)

res = {}
for scheme in ("loop", "sqrt3"):
    res[f"subdivide {scheme}"] = timed(lambda: None, lambda _, s=scheme: hybridsub.subdivide(V, m.F, levels=levels, scheme=s))
res["refine loop"] = timed(lambda: None, lambda _: hybridsub.refine(m.F, levels=levels, scheme="loop"))
res["matrix loop"] = timed(lambda: hybridsub.refine(m.F, levels=levels, scheme="loop"), lambda r: r.matrix)
r = hybridsub.refine(m.F, levels=levels, scheme="loop")
res["apply steps"] = timed(lambda: None, lambda _: r.apply(V))
S = r.matrix
res["apply"] = timed(lambda: None, lambda _: r.apply(V))
buf = np.empty((r.n_vertices, 3))
res["apply out"] = timed(lambda: None, lambda _: r.apply(V, out=buf))
frames = np.stack([V + 1e-3 * k for k in range(16)], axis=1)
res["apply 16 frames"] = timed(lambda: None, lambda _: r.apply(frames))
res["scipy S @ V"] = timed(lambda: None, lambda _: S @ V)
res["nnz"] = int(S.nnz)
print(json.dumps(res))
"""

CHECK = r"""
import sys, numpy as np
from _bench import load
import hybridsub
from hybridsub._io import read_off
m = load("armadillo"); levels = int(sys.argv[2])
r = hybridsub.refine(m.F, levels=levels, scheme="loop"); r.matrix
X = r.apply(m.V)
V2, F2 = read_off(sys.argv[1])
from scipy.spatial import cKDTree
diag = float(np.linalg.norm(X.max(0) - X.min(0)))
d = cKDTree(X).query(V2)[0] / diag
print(len(V2) == len(X) and len(F2) == len(r.faces), float(d.max()))
"""


def ours(threads: int, levels: int, repeat: int) -> dict:
    env = child_env(NUMBA_NUM_THREADS=str(threads))
    r = subprocess.run([sys.executable, "-c", CHILD, str(levels), str(repeat)], env=env, capture_output=True,
                       text=True, cwd=HERE)
    if r.returncode:
        raise RuntimeError(f"hybridsub child failed: {r.stderr[-1500:]}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def harness(name: str, args: list) -> dict:
    exe = os.path.join(PEERS_BIN, name)
    r = subprocess.run([exe] + args, capture_output=True, text=True, timeout=3600)
    if r.returncode:
        raise RuntimeError(f"{name} failed: {r.stderr.strip()[-500:]}")
    return json.loads(r.stdout)


def check_stencils(levels: int = 2) -> str:
    """OpenSubdiv's float stencils against ours: counts and the farthest vertex, / diagonal."""
    arm = load("armadillo")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "osd.off")
        harness("osd_stencils", [arm.path, str(levels), "--repeat", "1", "--warmup", "0", "--threads", "1",
                                 "--out", out])
        r = subprocess.run([sys.executable, "-c", CHECK, out, str(levels)], env=child_env(), capture_output=True,
                           text=True, cwd=HERE)
    if r.returncode:
        raise RuntimeError(f"check failed: {r.stderr[-1500:]}")
    same, dmax = r.stdout.split()
    ok = same == "True" and float(dmax) <= 1e-6
    return f"{'agrees' if ok else '**differs**'}: same counts {same}, max distance {float(dmax):.1e} × diagonal (L{levels})"


def collect(rounds: int, repeat: int, levels: int, log=print, save=None) -> dict:
    """Every contender, ``rounds`` times interleaved; {key: {"wall": [...], "cpu": [...]}}.
    ``save(T)`` is called after every round (what a long run has gathered so far)."""
    arm = load("armadillo")
    cores = os.cpu_count() or 1
    T: dict = {}

    def add(key, wall, cpu=None):
        T.setdefault(key, {"wall": [], "cpu": []})
        T[key]["wall"] += wall
        T[key]["cpu"] += cpu or []

    for k in range(rounds):
        for threads in (1, cores):
            log(f"round {k + 1}/{rounds}: hybridsub and OpenSubdiv stencils, {threads} thread(s) ...")
            res = ours(threads, levels, repeat)
            T["nnz"] = res.pop("nnz")
            for key, t in res.items():
                add(f"ours {key} t{threads}", t["wall"], t["cpu"])
            osd = harness("osd_stencils", [arm.path, str(levels), "--repeat", str(repeat), "--threads", str(threads)])
            T["osd nnz"] = osd["nnz"]
            if threads == 1:
                add("osd update t1", osd["update"]["times"], osd["update_cpu"]["times"])
                add("osd update_double t1", osd["update_double"]["times"], osd["update_double_cpu"]["times"])
                add("osd stencils t1", osd["stencils"]["times"], osd["stencils_cpu"]["times"])
                add("osd refine t1", osd["refine"]["times"])
            add(f"osd update_omp t{threads}", osd["update_omp"]["times"])
        log(f"round {k + 1}/{rounds}: single-threaded peers ...")
        loop = harness("osd_loop", [arm.path, str(levels), "--repeat", str(repeat)])
        add("osd loop t1", loop["subdivide"]["times"])
        cgal = harness("cgal_subdiv", [arm.path, "sqrt3", str(levels), "--repeat", str(repeat)])
        add("cgal sqrt3 t1", cgal["subdivide"]["times"])
        T["cores"] = cores
        if save:
            save(T)
    return T


def _fmt(t: float) -> str:
    return f"{t * 1e3:.1f} ms" if t < 1 else f"{t:.2f} s"


def _stat(v: list) -> str:
    return f"{_fmt(float(np.median(v)))} ({_fmt(min(v))})" if v else "—"


def report(T: dict, check: str, levels: int) -> list:
    """Markdown lines: the per-core table, then the all-cores one."""
    c = T["cores"]

    def row(work, ours_key, peer, peer_key, target, clock="wall"):
        o, p = T.get(ours_key, {}).get(clock), T.get(peer_key, {}).get(clock)
        if not o or not p:
            return [work, _stat(o or []), peer, _stat(p or []), "—", target]
        return [work, _stat(o), peer, _stat(p), f"{np.median(o) / np.median(p):.2f}", target]

    hdr = ["work (armadillo, Loop unless said, × %d)" % levels, "ours median (min)", "peer", "peer median (min)",
           "ratio of medians", "target"]
    one = [
        row("one frame, composite formed: `r.apply(V)`", "ours apply t1", "Far `StencilTable::UpdateValues`, float",
            "osd update t1", "≤ 1.0", "cpu"),
        row("one frame into a buffer: `r.apply(V, out=buf)`", "ours apply out t1", "the same", "osd update t1",
            "≤ 1.0", "cpu"),
        row("one frame, same", "ours apply out t1", "`StencilTableReal<double>::UpdateValues`",
            "osd update_double t1", "—", "cpu"),
        row("per frame of 16 batched `(n, 16, 3)`", "ours apply 16 frames t1", "UpdateValues × 16, float",
            "osd update t1", "—", "cpu"),
        row("one frame, composite not formed (the steps)", "ours apply steps t1", "UpdateValues, float",
            "osd update t1", "—", "cpu"),
        row("composite matrix: `r.matrix` after `refine`", "ours matrix loop t1", "`StencilTableFactory::Create`",
            "osd stencils t1", "≤ 0.5", "cpu"),
        row("Loop `subdivide`", "ours subdivide loop t1", "OpenSubdiv Far refine + interpolate", "osd loop t1",
            "≤ 0.33"),
        row("√3 `subdivide`", "ours subdivide sqrt3 t1", "CGAL `Sqrt3_subdivision`", "cgal sqrt3 t1", "≤ 0.15"),
    ]
    for r in one:  # 16 frames: per frame
        if r[0].startswith("per frame") and r[1] != "—":
            v = [t / 16 for t in T["ours apply 16 frames t1"]["cpu"]]
            p = T["osd update t1"]["cpu"]
            r[1], r[4] = _stat(v), f"{np.median(v) / np.median(p):.2f}"
    allc = [
        row("one frame: `r.apply(V)`", f"ours apply t{c}", f"Osd `OmpEvaluator::EvalStencils`, {c} threads, float",
            f"osd update_omp t{c}", "—"),
        row("one frame into a buffer", f"ours apply out t{c}", "the same", f"osd update_omp t{c}", "—"),
        row("composite matrix", f"ours matrix loop t{c}", "`StencilTableFactory::Create` (serial)", "osd stencils t1",
            "—"),
        row("Loop `subdivide`", f"ours subdivide loop t{c}", "OpenSubdiv Far (serial)", "osd loop t1", "—"),
        row("√3 `subdivide`", f"ours subdivide sqrt3 t{c}", "CGAL (serial)", "cgal sqrt3 t1", "—"),
    ]
    md = ["### Per core: hybridsub on one thread (`NUMBA_NUM_THREADS=1`), the peers single-threaded", ""]
    md += _table(hdr, one)
    md += ["", "Frames and the composite matrix: process CPU time (one thread; the time this process held the "
               "core); subdivide rows: wall time. ",
           f"Stencils: {T.get('nnz', 0):,} non-zeros ours, {T.get('osd nnz', 0):,} OpenSubdiv's; OpenSubdiv's "
           f"float stencils against `r.apply`: {check}.", ""]
    md += [f"### All cores: hybridsub with {c} threads (wall time)", ""]
    md += _table(hdr, allc)
    scale = [f"{k.replace('ours ', '')}: {_stat(v['wall'])}" for k, v in T.items()
             if isinstance(v, dict) and k.startswith("ours") and k.endswith("t1") and v["wall"]]
    md += ["", "Our one-thread wall times, for scale: " + "; ".join(scale) + "."]
    return md


def _table(header, rows) -> list:
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    return out + ["| " + " | ".join(str(x) for x in r) + " |" for r in rows]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds (default 3)")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per contender per round (default 3)")
    ap.add_argument("--levels", type=int, default=3)
    ap.add_argument("--markdown", metavar="OUT.md")
    ap.add_argument("--json", metavar="OUT.json")
    args = ap.parse_args(argv)
    missing = [n for n in ("osd_stencils", "osd_loop", "cgal_subdiv") if not os.access(os.path.join(PEERS_BIN, n), os.X_OK)]
    if missing:
        print(f"build the peers first (benchmarks/peers/build.sh): missing {missing}", file=sys.stderr)
        return 2
    log = lambda s: print(s, file=sys.stderr, flush=True)  # noqa: E731
    check = check_stencils()
    def save(T):
        if args.json:
            with open(args.json, "w") as fh:
                json.dump(T, fh, indent=1)

    T = collect(args.rounds, args.repeat, args.levels, log, save)
    md = "\n".join(report(T, check, args.levels)) + "\n"
    print(md)
    if args.markdown:
        with open(args.markdown, "w") as fh:
            fh.write(md)
    save(T)
    return 0


if __name__ == "__main__":
    sys.path.insert(0, ROOT)
    sys.exit(main())
