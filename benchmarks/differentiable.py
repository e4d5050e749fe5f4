"""Differentiable subdivision beside ``Refinement.apply``: forward and backward passes.

usage: python benchmarks/differentiable.py [--mesh armadillo] [--levels 3] [--scheme loop]
                                          [--rounds 7] [--frames 16] [--device cpu|cuda]

Refines the mesh once (``/work/shared/meshes/<mesh>.off`` or ``benchmarks/data``), then, in
``--rounds`` rounds, times in turn: ``r.apply(V)`` (its coded steps, from the third call on),
``hybridsub.torch.Subdivide(r)`` forward (no graph) and backward (``torch.autograd.grad`` of
a kept graph, i.e. ``Sᵀ G``) on one frame, float64 and float32 (each against ``r.apply`` of
the same data), and ``--frames`` frames as one ``(B, n, 3)`` batch (forward + backward,
against ``r.apply`` of the frames, forward only), and ``hybridsub.jax.subdivide_fn(r)`` under
``jax.jit`` (forward; ``grad``). Each time is the best of three calls in a round; the ratios
printed are medians over the rounds of the per-round ratios to ``r.apply``'s time (the
machine's other load moves both alike). With ``--device cuda`` the torch rows run on the GPU
(synchronised) and the batch row is compared with the CPU's.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))  # the checkout this folder lives in

import hybridsub  # noqa: E402


def mesh_path(name: str) -> str:
    for folder in ("/work/shared/meshes", os.path.join(HERE, "data"), os.path.join(os.path.dirname(HERE), "tests",
                                                                                   "data")):
        path = os.path.join(folder, f"{name}.off")
        if os.path.exists(path):
            return path
    raise SystemExit(f"no {name}.off in /work/shared/meshes, benchmarks/data or tests/data")


def best(f, sync=lambda: None, n: int = 3) -> float:
    out = []
    for _ in range(n):
        t = time.perf_counter()
        f()
        sync()
        out.append(time.perf_counter() - t)
    return min(out)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mesh", default="armadillo")
    ap.add_argument("--levels", type=int, default=3)
    ap.add_argument("--scheme", default="loop")
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--frames", type=int, default=16)
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--no-jax", action="store_true")
    args = ap.parse_args(argv)

    import torch
    import hybridsub.torch as ht

    import numba
    mesh = hybridsub.read_mesh(mesh_path(args.mesh))
    V, F = mesh.vertices, mesh.faces
    t = time.perf_counter()
    r = hybridsub.refine(F, levels=args.levels, scheme=args.scheme)
    print(f"{args.mesh} x {args.levels} {args.scheme}: {len(V):,} -> {r.n_vertices:,} vertices, "
          f"{sum(s.matrix.nnz for s in r.steps):,} matrix entries in {len(r.steps)} steps "
          f"(refined in {time.perf_counter() - t:.2f} s)")
    print(f"{platform.processor() or platform.machine()}, torch {torch.__version__} ({torch.get_num_threads()} "
          f"threads), Numba {numba.get_num_threads()} threads")
    dev = torch.device(args.device)
    sync = (lambda: torch.cuda.synchronize()) if dev.type == "cuda" else (lambda: None)
    for _ in range(3):
        r.apply(V)  # the coded steps are made on the second call
    V32 = V.astype(np.float32)
    for _ in range(3):
        r.apply(V32)
    rng = np.random.default_rng(0)
    G = rng.standard_normal((r.n_vertices, 3))
    B = args.frames
    VB = np.ascontiguousarray(np.repeat(V[:, None, :], B, axis=1) + 1e-3 * rng.standard_normal((len(V), B, 3)))

    rows: dict[str, list[float]] = {}
    subs = {dt: ht.Subdivide(r, dtype=dt).to(dev) for dt in (torch.float64, torch.float32)}
    cpu64 = subs[torch.float64] if dev.type == "cpu" else ht.Subdivide(r)

    def torch_rows(dt):
        sub = subs[dt]
        X = torch.tensor(V, dtype=dt, device=dev, requires_grad=True)
        Gt = torch.tensor(G, dtype=dt, device=dev)
        with torch.no_grad():
            fwd = best(lambda: sub(X), sync)
        Y = sub(X)
        bwd = best(lambda: torch.autograd.grad(Y, X, Gt, retain_graph=True), sync)
        return fwd, bwd

    def batch_row(sub, device, s):
        X = torch.tensor(VB.transpose(1, 0, 2).copy(), device=device, requires_grad=True)

        def step():
            Y = sub(X)
            (gx,) = torch.autograd.grad(Y.square().sum(), X)
            return gx
        return best(step, s, n=2)

    jax_f = None
    if not args.no_jax:
        import jax
        jax.config.update("jax_enable_x64", True)
        import jax.numpy as jnp
        import hybridsub.jax as hj
        f = hj.subdivide_fn(r)
        jax_f = jax.jit(f)
        jax_g = jax.jit(jax.grad(lambda X, G: jnp.sum(f(X) * G)))
        GJ = jnp.asarray(G)
        XJ = jnp.asarray(V)
        jax_f(XJ).block_until_ready()
        jax_g(XJ, GJ).block_until_ready()

    for k in range(args.rounds):
        ref = best(lambda: r.apply(V))
        ref32 = best(lambda: r.apply(V32))
        ref_b = best(lambda: r.apply(VB), n=2)
        f64, b64 = torch_rows(torch.float64)
        f32, b32 = torch_rows(torch.float32)
        batch = batch_row(subs[torch.float64], dev, sync)
        out = {"r.apply (1 frame, float64)": ref, "Subdivide forward, float64": f64, "Subdivide backward, float64": b64,
               "r.apply (1 frame, float32)": ref32, "Subdivide forward, float32": f32,
               "Subdivide backward, float32": b32,
               f"r.apply ({B} frames)": ref_b, f"Subdivide forward + backward, {B} frames, float64": batch}
        if dev.type == "cuda":
            out[f"Subdivide forward + backward, {B} frames, CPU"] = batch_row(cpu64, torch.device("cpu"), lambda: None)
        if jax_f is not None:
            out["jax.jit(subdivide_fn(r)), float64"] = best(lambda: jax_f(XJ).block_until_ready())
            out["jax.jit(jax.grad(...)), float64"] = best(lambda: jax_g(XJ, GJ).block_until_ready())
        for name, value in out.items():
            rows.setdefault(name, []).append(value)
        print(f"round {k + 1}/{args.rounds}: r.apply {1e3 * ref:.1f} ms, forward {1e3 * f64:.1f} ms, "
              f"backward {1e3 * b64:.1f} ms", flush=True)

    base, base_b = rows["r.apply (1 frame, float64)"], rows[f"r.apply ({B} frames)"]
    print(f"\n| {args.device} | median ms | ratio to r.apply (median of rounds) |\n|---|---:|---:|")
    for name, values in rows.items():
        against = base_b if f"{B} frames" in name else rows["r.apply (1 frame, float32)"] if "float32" in name else base
        if "CPU" in name:
            against = rows[f"Subdivide forward + backward, {B} frames, float64"]
            label = "CPU / GPU"
        else:
            label = ""
        ratio = statistics.median(v / a for v, a in zip(values, against))
        print(f"| {name} | {1e3 * statistics.median(values):.1f} | {ratio:.2f}{' ' + label if label else ''} |")


if __name__ == "__main__":
    main()
