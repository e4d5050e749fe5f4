"""The next level's twins and tags are derived from the parent's (not searched again):
they must equal what a search from scratch finds, on every kind of mesh and step."""

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hybridsub._topology import _kernels as K
from hybridsub import refine
from hybridsub._input.gate import open_gate
from hybridsub._refiner.loop import walk
from hybridsub._refiner.stencils import apply_step, step_matrix
from strategies import tagged_meshes

SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def _levels(V, F, tags, scheme, levels):
    inp = open_gate(F, tags.get("sharp_edges"), levels, n_vertices=len(V), scheme=scheme,
                    sharpness=tags.get("sharpness"), sharp_faces=tags.get("sharp_faces"), corners=tags.get("corners"))
    return [(s.level, s.plan, s.faces, s.child, s.offsets) for s in walk(inp, topology_last=True)]


@SETTINGS
@given(tagged_meshes("any"), st.sampled_from(["hybrid", "loop"]), st.integers(1, 3))
def test_derived_twins_equal_searched_twins(data, scheme, levels):
    V, F, tags = data
    for level, plan, faces, child, offsets in _levels(V, F, tags, scheme, levels):
        twin, _, _, err, _ = K.halfedge_twins(child.faces, child.n_vertices)
        assert err == K.OK
        assert np.array_equal(child.twin, twin)


@SETTINGS
@given(tagged_meshes("any", sharp_faces=False, corners=False), st.integers(1, 4))
def test_derived_twins_equal_searched_twins_sqrt3(data, levels):
    """Kobbelt's boundary: odd steps keep, even steps trisect; all twins still agree."""
    V, F, _ = data
    for level, plan, faces, child, offsets in _levels(V, F, {}, "sqrt3", levels):
        twin, _, _, err, _ = K.halfedge_twins(child.faces, child.n_vertices)
        assert err == K.OK
        assert np.array_equal(child.twin, twin)


@SETTINGS
@given(tagged_meshes("any", sharpness="mixed"), st.integers(1, 3))
def test_derived_tags_equal_propagated_pairs(data, levels):
    """Halfedge sharpness carried by the kernel equals the tags as vertex pairs looked up anew."""
    V, F, tags = data
    steps = _levels(V, F, tags, "hybrid", levels)
    r = refine(F, levels=levels, n_vertices=len(V), **tags)
    for (level, plan, faces, child, offsets), st_ in zip(steps, r.steps):
        expected = np.zeros(3 * len(faces))
        if len(st_.sharp_edges):
            tagged = child.tag(st_.sharp_edges, st_.sharpness, child.face_sharp)
            expected = tagged.hsharp
        got = child.hsharp if child.hsharp is not None else np.zeros(3 * len(faces))
        inner = child.twin >= 0
        assert np.array_equal(got[inner], expected[inner])


@SETTINGS
@given(tagged_meshes("any"), st.sampled_from(["hybrid", "loop", "sqrt3"]), st.integers(1, 3))
def test_direct_application_equals_matrix_bit_for_bit(data, scheme, levels):
    V, F, tags = data
    if scheme == "sqrt3":
        tags = {}
    X = V
    for level, plan, faces, child, offsets in _levels(V, F, tags, scheme, levels):
        Y = apply_step(level, plan, X)
        S = step_matrix(level, plan)
        assert np.array_equal(Y, S @ X)
        for other in (X[:, :2], np.column_stack([X, X[:, 0]])):  # the general path beside the three-column one
            assert np.array_equal(apply_step(level, plan, other), S @ other)
        X = Y


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(tagged_meshes("any"), st.sampled_from(["hybrid", "loop", "sqrt3"]), st.integers(1, 3))
def test_threaded_kernels_equal_serial_bit_for_bit(data, scheme, levels):
    """Small meshes run the serial twins; forcing the threaded ones must change no bit."""
    import hybridsub
    from hybridsub._topology import _kernels as _kernels

    V, F, tags = data
    if scheme == "sqrt3":
        tags = {}
    serial = hybridsub.subdivide(V, F, levels=levels, scheme=scheme, **tags)
    r = hybridsub.refine(F, levels=levels, n_vertices=len(V), scheme=scheme, **tags)
    serial_apply = r.apply(V)
    saved = _kernels.PARALLEL_MIN
    _kernels.PARALLEL_MIN = 0
    try:
        threaded = hybridsub.subdivide(V, F, levels=levels, scheme=scheme, **tags)
        threaded_apply = r.apply(V)
    finally:
        _kernels.PARALLEL_MIN = saved
    assert np.array_equal(serial[0], threaded[0]) and np.array_equal(serial[1], threaded[1])
    assert np.array_equal(serial_apply, threaded_apply)
    assert np.array_equal(serial_apply, serial[0])
