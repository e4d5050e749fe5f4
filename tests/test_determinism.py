"""Determinism: the same input gives the same output bits, run to run, process to process, and
with one or two Numba threads (the kernels may become ``parallel=True``)."""

import hashlib
import os
import subprocess
import sys

import numba
import numpy as np
import pytest

import hybridsub

import strategies as ms
from conftest import load_mesh

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def cases():
    """(name, V, F, kwargs) covering every scheme, tags, semi-sharp creases, boundaries, cuts."""
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, angle=30)
    Vb, Fb = load_mesh("mesh_with_border")
    Vt, Ft = ms.torus(7, 6, np.eye(7, 6, dtype=bool))
    rng = np.random.default_rng(3)
    E = ms.edges_of(Ft)[rng.random(len(ms.edges_of(Ft))) < 0.3]
    Vf, Ff = ms.fan(64, closed=True)
    fin = np.vstack([Ff, [[1, 2, len(Vf)]]])
    Vfin = np.vstack([Vf, [[0.5, 0.5, 1.0]]])
    return [
        ("fandisk-hybrid", V, F, dict(sharp_edges=feat.sharp_edges, corners=feat.corners, levels=2)),
        ("fandisk-sqrt3", V, F, dict(scheme="sqrt3", levels=2)),
        ("border-sqrt3", Vb, Fb, dict(scheme="sqrt3", levels=3)),
        ("border-loop", Vb, Fb, dict(scheme="loop", levels=2, loop_weights="warren")),
        ("torus-semisharp", Vt, Ft, dict(sharp_edges=E, sharpness=rng.uniform(0.1, 2.5, len(E)),
                                         sharp_faces=rng.random(len(Ft)) < 0.3, levels=3)),
        ("fin-cut", Vfin, fin, dict(non_manifold="cut", levels=3)),
    ]


def run(V, F, kw):
    V2, F2, S = hybridsub.subdivide(V, F, return_matrix=True, **kw)
    r = hybridsub.refine(F, n_vertices=len(V), **kw)
    return [V2, F2, S.data, S.indices, S.indptr, r.sharp_edges, r.sharpness, np.asarray(r.sharp_faces),
            r.corners, r.face_parent] + [a for st in r.steps for a in (st.matrix.data, st.matrix.indices)]


def digest(arrays):
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(str((a.dtype.str, a.shape)).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def digests():
    return {name: digest(run(V, F, kw)) for name, V, F, kw in cases()}


def test_run_to_run_identical_bits():
    for name, V, F, kw in cases():
        a, b = run(V, F, kw), run(V.copy(), F.copy(), kw)
        assert len(a) == len(b)
        for x, y in zip(a, b):
            assert x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes(), name


def test_one_or_two_threads_identical_bits():
    before = numba.get_num_threads()
    counts = [t for t in (1, 2) if t <= numba.config.NUMBA_NUM_THREADS]
    try:
        got = {}
        for t in counts:
            numba.set_num_threads(t)
            got[t] = digests()
    finally:
        numba.set_num_threads(before)
    assert all(got[t] == got[counts[0]] for t in counts)


@pytest.mark.slow  # subprocesses: ~4 s; .ci/run runs the slow tests
def test_process_to_process_identical_bits():
    # a fresh interpreter with another hash seed and one Numba thread gives the same bits
    code = ("import sys, json; sys.path.insert(0, 'tests'); import test_determinism as t; "
            "print(json.dumps(t.digests()))")
    env = dict(os.environ, PYTHONHASHSEED="12345", NUMBA_NUM_THREADS="1")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr
    import json

    assert json.loads(out.stdout.strip().splitlines()[-1]) == digests()


@pytest.mark.parametrize("scheme", ["hybrid", "loop", "sqrt3"])
def test_relabelled_input_same_geometry(scheme):
    # not bitwise (the index layout follows the input order), but the same surface
    V, F = ms.icosahedron()
    V2, F2 = ms.relabel(V, F, np.random.default_rng(5))
    a = hybridsub.subdivide(V, F, levels=2, scheme=scheme)[0]
    b = hybridsub.subdivide(V2, F2, levels=2, scheme=scheme)[0]
    assert np.allclose(np.sort(a, axis=0), np.sort(b, axis=0), rtol=0, atol=1e-13)
