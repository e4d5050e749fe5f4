"""Property-based fuzzing of the public API: every valid mesh gets a correct result, every
invalid one the documented exception with a message — never an IndexError, a Numba error or
a crash.

Two profiles: ``FAST`` runs in the default ``python -m pytest`` (CI); ``LONG`` runs the same
properties with many more examples behind the ``slow`` marker: ``python -m pytest -m slow``
(``HYBRIDSUB_FUZZ_EXAMPLES=N`` sets its number of examples).
"""

import os
import warnings

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import hybridsub
from hybridsub import MeshError, OutputTooLargeError

import strategies as ms

_QUIET = [HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much]
FAST = settings(max_examples=40, deadline=None, suppress_health_check=_QUIET)
LONG = settings(max_examples=int(os.environ.get("HYBRIDSUB_FUZZ_EXAMPLES", "1000")), deadline=None,
                suppress_health_check=_QUIET)

SCHEMES = ["hybrid", "loop", "sqrt3"]
DOCUMENTED = (MeshError, TypeError, ValueError, OutputTooLargeError)


def levels_for(m, scheme):
    """1 or 2 levels, keeping the output below about 5000 faces."""
    return 2 if m * (6 * 4 if scheme != "sqrt3" else 9) <= 5000 else 1


# ----------------------------------------------------------------- valid meshes


@st.composite
def valid_cases(draw):
    scheme = draw(st.sampled_from(SCHEMES))
    if scheme == "sqrt3":
        V, F = draw(ms.with_unused_vertices(ms.meshes("any")))
        tags = {}
    else:
        V, F, tags = draw(ms.tagged_meshes())
        if draw(st.booleans()):
            V = np.vstack([V, [[3.0, -2.0, 1.0]]])  # a vertex no face uses
    return scheme, V, F, tags


def check_valid(scheme, V, F, tags):
    levels = levels_for(len(F), scheme)
    before = [np.array(a, copy=True) for a in [V, F] + list(tags.values())]
    V2, F2, S = hybridsub.subdivide(V, F, levels=levels, scheme=scheme, return_matrix=True, **tags)
    # the caller's arrays are untouched
    for a, b in zip(before, [V, F] + list(tags.values())):
        assert np.array_equal(a, b)
    # the core's invariants
    ms.check_mesh(V2, F2)
    assert S.shape == (len(V2), len(V))
    assert np.allclose(S @ V, V2, rtol=0, atol=1e-12)
    assert np.allclose(np.asarray(S.sum(axis=1)).ravel(), 1.0, rtol=0, atol=1e-12)
    assert S.data.min() >= 0
    assert ms.euler(len(V2), F2) == ms.euler(len(V), F)
    unused = np.setdiff1d(np.arange(len(V)), F)
    assert np.array_equal(V2[unused], V[unused])
    # the budget's estimate (what refine checks against the memory limit) bounds what was made
    from hybridsub._input.gate import open_gate
    from hybridsub._refiner import budget as _budget
    from hybridsub._topology import plan_step

    r = hybridsub.refine(F, levels=levels, scheme=scheme, n_vertices=len(V), **tags)
    assert r.n_vertices == len(V2) and np.array_equal(r.faces, F2)
    nnz = sum(s.matrix.nnz for s in r.steps)
    inp = open_gate(F, tags.get("sharp_edges"), levels, scheme=scheme, sharpness=tags.get("sharpness"),
                    sharp_faces=tags.get("sharp_faces"), corners=tags.get("corners"), n_vertices=len(V))
    if inp.n_faces:
        est = _budget.estimate(_budget.counts_of(inp.level, plan_step(inp.level, inp.corner, scheme, 1, "loop")),
                               scheme, 1, inp.levels)
        assert est.faces >= len(F2) and est.vertices >= len(V2) and est.nnz >= nnz, (est, len(F2), len(V2), nnz)
    # non_manifold="cut" on a valid mesh changes nothing, bit for bit
    V3, F3, S3 = hybridsub.subdivide(V, F, levels=levels, scheme=scheme, return_matrix=True,
                                     non_manifold="cut", **tags)
    assert np.array_equal(V3, V2) and np.array_equal(F3, F2) and (S3 != S).nnz == 0


@FAST
@given(valid_cases())
def test_valid_meshes(case):
    check_valid(*case)


@pytest.mark.slow
@LONG
@given(valid_cases())
def test_valid_meshes_long(case):
    check_valid(*case)


# ----------------------------------------------------------------- broken input


def check_broken(case: ms.Broken):
    kw = dict(case.kwargs)
    try:
        hybridsub.subdivide(case.V, case.F, **kw)
    except DOCUMENTED as e:
        assert isinstance(e, case.error), f"{case.what}: {type(e).__name__}: {e}"
        assert case.match in str(e), f"{case.what}: {e!r} lacks {case.match!r}"
        assert len(str(e)) > 20
    else:
        raise AssertionError(f"{case.what}: no error")
    # refine takes no positions: the same faces and tags give the same answer
    if case.what[0] != "V":
        with pytest.raises(case.error) as ei:
            hybridsub.refine(case.F, n_vertices=len(case.V), **kw)
        assert case.match in str(ei.value)


@FAST
@given(ms.broken_inputs())
def test_broken_inputs(case):
    check_broken(case)


@pytest.mark.slow
@LONG
@given(ms.broken_inputs())
def test_broken_inputs_long(case):
    check_broken(case)


def check_garbage(data):
    """Arbitrary small arrays of any dtype as V, F and tags: a documented exception or a result."""
    dtypes = st.sampled_from([np.int8, np.int32, np.int64, np.uint8, np.uint64, np.float16, np.float32,
                              np.float64, np.bool_, np.complex64])
    shapes = st.tuples(st.integers(0, 6), st.integers(0, 5)) | st.tuples(st.integers(0, 8))

    def array(dtype, shape):
        rng = np.random.default_rng(data.draw(ms.seeds))
        x = rng.integers(-2, 7, size=shape).astype(np.float64)
        if np.issubdtype(dtype, np.floating):
            x[rng.random(shape) < 0.05] = rng.choice([np.nan, np.inf, 0.5])
        return x.astype(dtype)

    V = array(data.draw(dtypes), data.draw(shapes))
    F = array(data.draw(dtypes), data.draw(shapes))
    kw = {}
    for name in ("sharp_edges", "sharpness", "sharp_faces", "corners"):
        if data.draw(st.booleans()):
            kw[name] = array(data.draw(dtypes), data.draw(shapes))
    kw["levels"] = data.draw(st.sampled_from([0, 1, 2, -1, 1.5]))
    kw["scheme"] = data.draw(st.sampled_from(SCHEMES))
    kw["non_manifold"] = data.draw(st.sampled_from(["raise", "cut"]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no silent casts (complex → real, NaN → int) on the way
        try:
            V2, F2 = hybridsub.subdivide(V, F, **kw)
        except DOCUMENTED as e:
            assert str(e)
            return
    ms.check_mesh(V2.astype(np.float64), F2)


@FAST
@given(st.data())
def test_garbage_never_escapes_as_another_exception(data):
    check_garbage(data)


@pytest.mark.slow
@LONG
@given(st.data())
def test_garbage_never_escapes_as_another_exception_long(data):
    check_garbage(data)


# ----------------------------------------------------------------- non-manifold and flipped meshes


def check_cut(V, F, scheme, tagged):
    valid = ms.is_edge_manifold(F) and ms.is_consistently_oriented(F)
    if not valid:
        with pytest.raises(MeshError, match=r"shared by \d+ faces|in the same direction"):
            hybridsub.subdivide(V, F, scheme=scheme)
    tags = {}
    if tagged and scheme != "sqrt3":
        E = ms.edges_of(F)
        tags = dict(sharp_edges=E[:: max(1, len(E) // 5)], sharp_faces=np.arange(0, len(F), 4), corners=[0])
    levels = levels_for(len(F), scheme)
    V2, F2, S = hybridsub.subdivide(V, F, levels=levels, scheme=scheme, non_manifold="cut",
                                    return_matrix=True, **tags)
    ms.check_mesh(V2, F2)
    assert S.shape == (len(V2), len(V))
    assert np.allclose(S @ V, V2, rtol=0, atol=1e-12)
    assert np.allclose(np.asarray(S.sum(axis=1)).ravel(), 1.0, rtol=0, atol=1e-12)
    r = hybridsub.refine(F, levels=levels, scheme=scheme, non_manifold="cut", n_vertices=len(V), **tags)
    assert np.array_equal(r.apply(V), V2)  # step by step, as subdivide does
    assert sp.issparse(r.matrix) and r.matrix.shape == S.shape


@FAST
@given(ms.non_manifold_meshes(), st.sampled_from(SCHEMES), st.booleans())
def test_cut_non_manifold(mesh, scheme, tagged):
    check_cut(*mesh, scheme, tagged)


@pytest.mark.slow
@LONG
@given(ms.non_manifold_meshes(max_fins=6), st.sampled_from(SCHEMES), st.booleans())
def test_cut_non_manifold_long(mesh, scheme, tagged):
    check_cut(*mesh, scheme, tagged)
