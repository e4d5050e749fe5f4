"""Refinement.apply on coded stencils (issue 18): the bits of subdivide before the composite
matrix is formed, the bits of ``matrix @ X`` after, on every kernel path."""

import numba
import numpy as np
import pytest
import scipy.sparse as sp

import hybridsub
from hybridsub._refiner import _simd
from hybridsub._refiner import stencils as _stencils
from hybridsub._topology import _kernels as _topo_kernels

CASES = {  # scheme, with the fandisk's features or semi-sharp creases (more distinct weights)
    "hybrid": dict(scheme="hybrid", features=True),
    "loop": dict(scheme="loop", features=True),
    "loop-semisharp": dict(scheme="loop", features=True, sharpness=True),
    "sqrt3": dict(scheme="sqrt3"),
}


def _refinement(name, levels=2):
    V, F = hybridsub.load_example()
    kw = dict(scheme=CASES[name]["scheme"])
    if CASES[name].get("features"):
        feat = hybridsub.detect_features(V, F)
        kw["sharp_edges"] = feat.sharp_edges
        if CASES[name].get("sharpness"):
            kw["sharpness"] = 0.5 + (np.arange(len(feat.sharp_edges)) % 7) * 0.4
    V2, _ = hybridsub.subdivide(V, F, levels=levels, **kw)
    edges = kw.pop("sharp_edges", None)
    return V, V2, hybridsub.refine(F, edges, levels, **kw)


def _step_product(r, X):
    for st in r.steps:
        X = st.matrix @ X
    return X


@pytest.mark.parametrize("threaded", [False, True])
@pytest.mark.parametrize("name", list(CASES))
def test_apply_keeps_the_bits_of_both_paths(monkeypatch, name, threaded):
    monkeypatch.setattr(_topo_kernels, "PARALLEL_MIN", 0 if threaded else 10**12)
    V, V2, r = _refinement(name)
    X = np.random.default_rng(1).normal(size=(len(V), 7))
    assert np.array_equal(r.apply(V), V2)  # before the composite: subdivide's bits
    assert np.array_equal(r.apply(X), _step_product(r, X))
    assert np.array_equal(r.apply(X[:, :1]), _step_product(r, X[:, :1]))
    S = r.matrix
    assert np.array_equal(r.apply(V), S @ V)  # after: the composite product's bits
    assert np.array_equal(r.apply(X), S @ X)
    odd = X[:, :3].copy()  # one frame, an odd number of rows left for the pairwise kernel
    sub = sp.csr_matrix(S[:-1])
    C = _stencils.coded_stencils(sub)
    assert np.array_equal(_stencils.apply_coded(C, odd), sub @ odd)


def test_frames_batched_equal_frames_one_by_one():
    V, _, r = _refinement("hybrid")
    frames = np.stack([V + 0.01 * k for k in range(4)], axis=1)  # (n, 4, 3)
    r.matrix
    got = r.apply(frames)
    assert got.shape == (r.n_vertices, 4, 3)
    for k in range(4):
        assert np.array_equal(got[:, k], r.apply(frames[:, k]))


def test_codes_decode_to_the_weights_and_tell_signed_zeros_apart():
    _, _, r = _refinement("loop-semisharp", levels=1)
    S = r.steps[0].matrix
    C = _stencils.coded_stencils(S)
    assert C.codes.dtype == np.uint16 and C.indices.dtype == np.uint16  # fandisk: 6,475 columns
    assert np.array_equal(C.weights[C.codes].view(np.int64), S.data.view(np.int64))
    assert len(C.weights) == len(np.unique(S.data))
    Z = sp.csr_matrix((np.array([0.0, -0.0, 0.5]), np.array([0, 1, 1]), np.array([0, 2, 3])), shape=(2, 2))
    CZ = _stencils.coded_stencils(Z)
    assert len(CZ.weights) == 3 and np.array_equal(CZ.weights[CZ.codes].view(np.int64), Z.data.view(np.int64))


def test_too_many_distinct_weights_fall_back_to_csr(monkeypatch):
    V, V2, r = _refinement("loop-semisharp")
    monkeypatch.setattr(_stencils, "MAX_CODES", 8)
    assert _stencils.coded_stencils(r.steps[0].matrix) is None
    assert np.array_equal(r.apply(V), V2)  # the steps as plain CSR: the same bits
    assert not any(isinstance(S, _stencils.CodedStencils) for S in r._stencils())
    monkeypatch.undo()
    wide = sp.random(40, 70000, density=1e-3, format="csr", random_state=0)  # > 65,536 columns
    C = _stencils.coded_stencils(wide)
    assert C is not None and C.indices.dtype == wide.indices.dtype
    X = np.random.default_rng(0).normal(size=(70000, 3))
    assert np.array_equal(_stencils.apply_coded(C, X), wide @ X)


def test_apply_into_a_buffer():
    V, V2, r = _refinement("hybrid")
    out = np.full((r.n_vertices, 3), np.nan)
    assert r.apply(V, out=out) is out and np.array_equal(out, V2)
    r.matrix
    assert r.apply(V, out=out) is out and np.array_equal(out, r.matrix @ V)
    frames = np.stack([V, 2 * V], axis=1)
    buf = np.empty((r.n_vertices, 2, 3))
    assert np.array_equal(r.apply(frames, out=buf), r.apply(frames))
    with pytest.raises(ValueError, match="shape"):
        r.apply(V, out=np.empty((r.n_vertices, 2)))
    with pytest.raises(TypeError, match="float64"):
        r.apply(V, out=np.empty((r.n_vertices, 3), np.float32))
    with pytest.raises(TypeError, match="complex"):
        r.apply(V + 1j, out=np.empty((r.n_vertices, 3)))
    F = np.array([[0, 1, 2]])
    r0 = hybridsub.refine(F, levels=0)
    X = np.eye(3)
    assert np.array_equal(r0.apply(X, out=np.empty((3, 3))), X)


def test_one_thread_and_all_give_the_same_bits(monkeypatch, tmp_path):
    monkeypatch.setattr(_topo_kernels, "PARALLEL_MIN", 0)  # every kernel on its threaded twin
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F)
    try:
        assert hybridsub.set_threads(1) == 1
        one = hybridsub.subdivide(V, F, feat.sharp_edges, levels=2, corners=feat.corners)
        r1 = hybridsub.refine(F, feat.sharp_edges, 2, corners=feat.corners)
        a1 = r1.apply(V), r1.matrix, r1.apply(V)
        hybridsub.set_threads(None)
        every = hybridsub.subdivide(V, F, feat.sharp_edges, levels=2, corners=feat.corners)
        r2 = hybridsub.refine(F, feat.sharp_edges, 2, corners=feat.corners)
        a2 = r2.apply(V), r2.matrix, r2.apply(V)
    finally:
        hybridsub.set_threads(None)
    assert all(np.array_equal(x, y) for x, y in zip(one, every))
    assert np.array_equal(a1[0], a2[0]) and np.array_equal(a1[2], a2[2]) and (a1[1] != a2[1]).nnz == 0
    with pytest.raises(ValueError, match="between 1 and"):
        hybridsub.set_threads(0)
    with pytest.raises(TypeError):
        hybridsub.set_threads(1.5)
    from hybridsub._app.cli import main
    src, out = tmp_path / "tet.off", tmp_path / "o.off"
    src.write_text("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n")
    assert main(["--threads", "1", "subdivide", str(src), "-o", str(out), "--levels", "1", "-q"]) == 0
    assert out.exists()
    import numba
    assert numba.get_num_threads() == 1
    hybridsub.set_threads(None)


def test_steps_read_each_level_in_order():
    """The coded steps renumber every level between two steps in the order the next step
    first reads it (its gathers then walk that level almost in sequence), same bits."""
    V, V2, r = _refinement("loop", levels=3)
    r.apply(V)
    assert np.array_equal(r.apply(V), V2)  # coded, in read order
    for C in r._stencils()[1:]:
        first = np.full(C.shape[1], len(C.indices))
        np.minimum.at(first, C.indices.astype(np.int64), np.arange(len(C.indices)))
        assert np.all(np.diff(first) >= 0)


def _scipy_product(A, B):
    D = sp.csr_matrix(A @ B)
    D.sort_indices()
    return D


def _same_csr(C, D):
    return (C.shape == D.shape and np.array_equal(C.indptr, D.indptr) and np.array_equal(C.indices, D.indices)
            and np.array_equal(C.data.view(np.int64), D.data.view(np.int64)))


@pytest.mark.parametrize("threaded", [False, True])
@pytest.mark.parametrize("name", ["hybrid", "loop-semisharp", "sqrt3"])
def test_composite_is_scipys_product_to_the_bit(monkeypatch, name, threaded):
    monkeypatch.setattr(_topo_kernels, "PARALLEL_MIN", 0 if threaded else 10**12)
    _, _, r = _refinement(name, levels=3)
    S = sp.identity(r.n_coarse, format="csr")
    for st in r.steps:
        C = _stencils.product(st.matrix, S)
        S = _scipy_product(st.matrix, S)
        assert _same_csr(C, S) and C.has_sorted_indices
    assert _same_csr(r.matrix, S)


def test_product_drops_the_sums_that_cancel_as_scipy():
    A = sp.csr_matrix(np.array([[1.0, -1.0, 0.0], [0.5, 0.0, 2.0], [0.0, 0.0, 0.0], [-0.0, 1.0, 0.0]]))
    B = sp.csr_matrix(np.array([[1.0, 3.0, 0.0, 1e-300], [1.0, 2.0, 0.0, 1e-300], [0.0, 0.0, 4.0, -0.0]]))
    C = _stencils.product(A, B)
    assert _same_csr(C, _scipy_product(A, B))
    assert C[0].nnz == 1  # column 0 and the tiny column cancel exactly: dropped, as SciPy drops them


@numba.njit
def _lanes_after(first, w, x4):
    acc = _simd.madd4(_simd.vzero(), 1.0, first, np.uintp(0))
    acc = _simd.madd4(acc, w, x4, np.uintp(0))
    return _simd.lane(acc, 0), _simd.lane(acc, 1), _simd.lane(acc, 2), _simd.lane(acc, 3)


def test_vector_lanes_multiply_then_add_as_the_scalar_code():
    """A fused multiply-add would keep the product's low bits: (1 + 2⁻³⁰)² − its rounding is
    2⁻⁶⁰, not the 0 the scalar code gives."""
    w = x = 1.0 + 2.0**-30
    p = w * x
    assert _lanes_after(np.full(4, -p), w, np.full(4, x)) == (0.0, 0.0, 0.0, 0.0)
    assert _lanes_after(np.arange(4.0), 0.5, np.arange(4.0, 8.0)) == (2.0, 3.5, 5.0, 6.5)


@pytest.mark.parametrize("far", [False, True])
def test_the_levels_prefetch_decision_changes_no_bit(monkeypatch, far):
    """Prefetching is decided once per level (``Level.far_apart``) for its topology, data and
    matrix product; forced either way it is a hint only: the same faces and the same bits."""
    from hybridsub._topology.level import Level

    V, V2, r = _refinement("loop-semisharp")
    monkeypatch.setattr(Level, "far_apart", property(lambda self: far))
    _, _, forced = _refinement("loop-semisharp")
    X = np.random.default_rng(2).normal(size=(len(V), 3))
    assert np.array_equal(forced.faces, r.faces)
    assert np.array_equal(forced.apply(X), _step_product(r, X))
    assert _same_csr(forced.matrix, r.matrix)


def test_far_apart_tells_shuffled_faces_from_ordered_ones():
    from hybridsub._topology import build_level

    V, F = hybridsub.load_example()
    F = hybridsub.refine(F, levels=4, scheme="loop").faces  # > 32k faces, written in order
    assert not build_level(F, int(F.max()) + 1).far_apart
    shuffled = F[np.random.default_rng(0).permutation(len(F))]
    assert build_level(shuffled, int(F.max()) + 1).far_apart
