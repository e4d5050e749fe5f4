"""``hybridsub warmup``: compile every kernel ahead, for images, CI and clusters.

A kernel is compiled on the first call that needs it and cached on disk (Numba's cache:
``NUMBA_CACHE_DIR``, else ``__pycache__``), so without a warm-up the first call of each kind
waits for its kernels. :func:`warm_up` makes one small call of every kind (each scheme and
tag, one thread and all threads, values and matrices, UVs, limits, the limit surface, fitting,
multiresolution, adaptive refinement), so that afterwards no call compiles.

>>> from hybridsub._app.warmup import JOBS
>>> "limit surface" in dict(JOBS)
True
"""

from __future__ import annotations

import sys
import time
import warnings
from collections.abc import Callable

import numpy as np


def _mesh(levels: int = 0):
    import hybridsub

    V, F = hybridsub.load_example()
    if levels:
        r = hybridsub.refine(F, levels=levels, scheme="loop")
        return r.apply(V), r.faces
    return V, F


def _tags(V, F):
    import hybridsub

    feat = hybridsub.detect_features(V, F, angle=30)
    sharpness = 0.5 + (np.arange(len(feat.sharp_edges)) % 5) * 0.6  # semi-sharp and infinitely sharp
    return feat.sharp_edges, sharpness, feat.corners


def _small():
    """An octahedron refined twice (128 faces), its equator a crease with a corner: the
    kernels of the limit surface and of fitting compile the same on it as on any mesh."""
    import hybridsub

    V = np.array([[1.0, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
    F = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [1, 0, 5], [2, 1, 5], [3, 2, 5], [0, 3, 5]])
    equator = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    r = hybridsub.refine(F, equator, levels=2, scheme="loop")
    return r.apply(V), r.faces, r.sharp_edges, r.corners if len(r.corners) else np.array([0])


def _refinement(V, F, threads: int | None) -> None:
    import hybridsub

    hybridsub.set_threads(threads)
    edges, sharpness, corners = _tags(V, F)
    for scheme in ("hybrid", "sqrt3", "loop"):
        tagged = () if scheme == "sqrt3" else (dict(sharp_edges=edges, corners=corners),
                                                dict(sharp_edges=edges, sharpness=sharpness))
        for kw in (dict(), *tagged):
            V2, _ = hybridsub.subdivide(V, F, levels=2, scheme=scheme, **kw)
            r = hybridsub.refine(F, levels=2, scheme=scheme, **kw)
            r.apply(V)
            r.apply(np.stack([V, V], axis=1))  # frames
            r.matrix  # noqa: B018 - the composite product
            r.apply(V[:, :1])
    hybridsub.subdivide(V, F, levels=1, scheme="loop", loop_weights="warren")
    hybridsub.set_threads()


def _one_thread() -> None:
    V, F = _mesh()
    _refinement(V, F, 1)


def _threads() -> None:
    import numba

    if numba.config.NUMBA_NUM_THREADS > 1:
        V, F = _mesh(1)  # above the size where kernels run on threads
        _refinement(V, F, None)


def _uvs() -> None:
    import hybridsub

    V, F = _mesh()
    UV = V[:, :2].copy()
    for scheme in ("hybrid", "loop"):  # √3 flips every edge: no UV seams to keep
        for uv_mode in ("linear", "smooth"):
            hybridsub.subdivide_face_varying(V, F, UV, F, levels=2, scheme=scheme, uv_mode=uv_mode)


def _limits() -> None:
    import numba

    import hybridsub

    V, F = _mesh()
    edges, sharpness, corners = _tags(V, F)
    for scheme in ("hybrid", "sqrt3", "loop"):
        kw = dict(scheme=scheme) if scheme == "sqrt3" else dict(scheme=scheme, sharp_edges=edges, corners=corners)
        hybridsub.limit_positions(V, F, levels=1, **kw)
        hybridsub.limit_normals(V, F, levels=1, **kw)
        hybridsub.limit_matrix(F, levels=1, **kw)
    if numba.config.NUMBA_NUM_THREADS > 1:  # the vertex lane's threaded twin: above 65,536 vertices
        hybridsub.limit_mesh(V, F, edges, levels=2, scheme="loop", corners=corners)


def _surface() -> None:
    import hybridsub

    V, F, edges, corners = _small()
    rng = np.random.default_rng(0)
    for n in (50, 1500):  # few points on one thread, many on all
        face = rng.integers(0, len(F), n)
        bary = rng.dirichlet(np.ones(3), n)
        points = V[rng.integers(0, len(V), n)] + 0.05 * rng.normal(size=(n, 3))
        for scheme in ("hybrid", "sqrt3", "loop"):
            tags = {} if scheme == "sqrt3" else dict(sharp_edges=edges, corners=corners)
            surface = hybridsub.LimitSurface(V, F, scheme=scheme, **tags)
            surface.evaluate(face, bary)
            surface.evaluate(face, bary, derivatives=True)
            surface.normals(face, bary)
            surface.evaluation_matrix(face, bary)
            surface.project(points[:20])


def _fitting() -> None:
    import hybridsub

    V, F, edges, corners = _small()
    target = hybridsub.subdivide(V, F, edges, levels=1, corners=corners)[0]
    hybridsub.fit(F, target, edges, corners=corners, V0=V, levels=1, max_iterations=2)
    hybridsub.fit(F, target[::4], edges, corners=corners, V0=V, scheme="loop", max_iterations=1)  # the limit surface
    r = hybridsub.refine(F, edges, levels=2, corners=corners)
    coarse, details = r.decompose(r.apply(V))
    r.reconstruct(coarse, details)


def _adaptive() -> None:
    import hybridsub

    V, F, edges, corners = _small()
    for scheme in ("hybrid", "sqrt3", "loop"):
        tags = {} if scheme == "sqrt3" else dict(sharp_edges=edges, corners=corners)
        hybridsub.refine_adaptive(F, where=np.arange(len(F) // 4), levels=2, scheme=scheme, **tags)
        hybridsub.subdivide_adaptive(V, F, tolerance="1%", max_levels=2, scheme=scheme, **tags)


#: What ``hybridsub warmup`` runs, in order: (what, call).
JOBS: list[tuple[str, Callable[[], None]]] = [
    ("refinement, one thread", _one_thread),
    ("refinement, all threads", _threads),
    ("texture coordinates", _uvs),
    ("limit positions and normals", _limits),
    ("limit surface", _surface),
    ("fitting and multiresolution", _fitting),
    ("adaptive refinement", _adaptive),
]


def warm_up(quiet: bool = False) -> float:
    """Run every job of :data:`JOBS`; returns the seconds taken. Progress on stderr."""
    from .. import _compile_ahead
    from .._jit import _CompileNotice

    _CompileNotice.said = True  # compiling is what was asked for: no notice
    _compile_ahead.switch_off()  # and all of it: no helper for one job
    start = time.perf_counter()
    for what, job in JOBS:
        t = time.perf_counter()
        with warnings.catch_warnings():  # what the small calls warn of (a fit with few points) is not news
            warnings.simplefilter("ignore")
            job()
        if not quiet:
            print(f"  {what}: {time.perf_counter() - t:.1f} s", file=sys.stderr, flush=True)
    return time.perf_counter() - start
