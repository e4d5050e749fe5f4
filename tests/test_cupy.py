"""hybridsub.cupy without a GPU: the import guard, and the code path run against a stand-in
for CuPy (NumPy arrays, SciPy's CSR matrices) — the matrices made once per source, device
and dtype and reused, the products equal to r.apply, bad input named. On a GPU (CuPy
installed), the same against CuPy itself."""

import sys
import types

import numpy as np
import pytest
import scipy.sparse as sp
from conftest import load_mesh

import hybridsub
import hybridsub.cupy as hc


@pytest.fixture
def stand_in(monkeypatch):
    """A fake ``cupy`` and ``cupyx.scipy.sparse`` in sys.modules; counts the matrices made."""
    made = []

    def csr_matrix(arg, shape):
        made.append(shape)
        data, indices, indptr = arg
        assert indices.dtype == np.int32 and indptr.dtype == np.int32
        return sp.csr_matrix(arg, shape=shape)

    cupy = types.ModuleType("cupy")
    cupy.ndarray = np.ndarray
    cupy.asarray = np.asarray
    cupy.cuda = types.SimpleNamespace(Device=lambda: types.SimpleNamespace(id=0))
    cupyx = types.ModuleType("cupyx")
    cupyx_scipy = types.ModuleType("cupyx.scipy")
    cupyx_sparse = types.ModuleType("cupyx.scipy.sparse")
    cupyx_sparse.csr_matrix = csr_matrix
    cupyx.scipy = cupyx_scipy
    cupyx_scipy.sparse = cupyx_sparse
    for name, module in (("cupy", cupy), ("cupyx", cupyx), ("cupyx.scipy", cupyx_scipy),
                         ("cupyx.scipy.sparse", cupyx_sparse)):
        monkeypatch.setitem(sys.modules, name, module)
    return made


def test_import_guard(monkeypatch):
    monkeypatch.setitem(sys.modules, "cupy", None)  # as if not installed
    V, F = load_mesh("tetrahedron")
    with pytest.raises(ImportError, match=r"hybridsub.cupy needs CuPy and a GPU: pip install cupy-cuda12x"):
        hc.apply(hybridsub.refine(F, levels=1), V)


def test_matrices_kept_and_products(stand_in):
    V, F = load_mesh("octahedron")
    r = hybridsub.refine(F, [[0, 1]], levels=2, sharpness=[1.5])
    want = r.apply(V)
    np.testing.assert_allclose(hc.apply(r, V), want, rtol=0, atol=1e-14)
    assert len(stand_in) == 2  # one per step
    for _ in range(3):  # later frames reuse them
        np.testing.assert_allclose(hc.apply(r, 2 * V), 2 * want, rtol=0, atol=1e-14)
    assert len(stand_in) == 2
    Y = hc.apply(r, V.astype(np.float32))
    assert Y.dtype == np.float32 and len(stand_in) == 4  # float32 copies, once
    assert hc.apply(r, np.arange(6)).dtype == np.float64
    assert hc.apply(r, np.zeros((6, 2, 4))).shape == (r.n_vertices, 2, 4)
    np.testing.assert_allclose(hc.apply(r.matrix, V), want, rtol=0, atol=1e-14)


def test_bad_input(stand_in):
    V, F = load_mesh("tetrahedron")
    r = hybridsub.refine(F, levels=1)
    with pytest.raises(ValueError, match=r"shape \(4, \.\.\.\)"):
        hc.apply(r, np.zeros((3, 3)))
    with pytest.raises(TypeError, match="real numbers"):
        hc.apply(r, np.zeros((4, 3), complex))
    with pytest.raises(TypeError, match="Refinement or a 2-D SciPy sparse matrix"):
        hc.apply(np.eye(4), V)


def test_on_a_gpu():
    cupy = pytest.importorskip("cupy")
    try:
        cupy.cuda.runtime.getDeviceCount()
    except Exception:  # noqa: BLE001 - CuPy without a usable device
        pytest.skip("no GPU")
    V, F = hybridsub.load_example()
    r = hybridsub.refine(F, levels=2)
    np.testing.assert_allclose(hc.apply(r, V).get(), r.apply(V), rtol=0, atol=1e-12)
    X = cupy.asarray(V, dtype=cupy.float32)
    np.testing.assert_allclose(hc.apply(r, X).get(), r.apply(V), rtol=0, atol=1e-4)


def test_matrix_copies_go_with_the_matrix(stand_in):
    V, F = load_mesh("tetrahedron")
    M = hybridsub.refine(F, levels=1).matrix
    hc.apply(M, V)
    hc.apply(M, V)
    assert len(stand_in) == 1 and id(M) in hc._HELD
    key = id(M)
    del M
    assert key not in hc._HELD
